"""Friction models of a joint drive (motor side): one module per model and a registry.

Each model (:class:`~kinergy.friction.model.FrictionModel`) is a name, its parameters, its torque,
its regressor columns where it is linear in some parameters, bounds and a citation. Robot files
choose a model per joint by name; :data:`~kinergy.friction.registry.MODELS` lists them.
"""

from kinergy.friction.model import FrictionModel
from kinergy.friction.registry import (
    MODELS,
    check_friction,
    friction_columns,
    friction_torque,
    get_model,
    linear_values,
    start_parameters,
    with_linear_parameters,
)
from kinergy.friction.standstill import OPTIONAL_PARAMETERS, STILL_RATE, hold_standstill

__all__ = [
    "MODELS",
    "OPTIONAL_PARAMETERS",
    "STILL_RATE",
    "FrictionModel",
    "check_friction",
    "friction_columns",
    "friction_torque",
    "get_model",
    "hold_standstill",
    "linear_values",
    "start_parameters",
    "with_linear_parameters",
]
