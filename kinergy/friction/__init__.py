"""Friction models of a joint drive (motor side): one module per model and a registry.

Each model (:class:`~kinergy.friction.model.FrictionModel`) is a name, its parameters, its torque,
its regressor columns where it is linear in some parameters, bounds and a citation, and the
operations on them (torque, columns, linear values, checks). Robot files choose a model per joint
by name; :data:`~kinergy.friction.registry.MODELS` lists them and
:func:`~kinergy.friction.registry.get_model` resolves a name.
"""

from kinergy.friction.model import FrictionModel
from kinergy.friction.registry import MODELS, get_model
from kinergy.friction.standstill import OPTIONAL_PARAMETERS, STILL_RATE, hold_standstill

__all__ = [
    "MODELS",
    "OPTIONAL_PARAMETERS",
    "STILL_RATE",
    "FrictionModel",
    "get_model",
    "hold_standstill",
]
