"""The friction models by name: where a family's name (a robot file's ``model = "power_flow"``,
an option's ``--friction power_flow``) resolves, once, into its
:class:`~kinergy.friction.model.FrictionModel`.

To add a model: write a module beside the others that defines ``MODEL = FrictionModel(...)``
(:mod:`kinergy.friction.model`) and list it in :data:`MODELS` below.
"""

from __future__ import annotations

from kinergy.errors import Code, KinergyError
from kinergy.friction import (
    directional_power_law,
    load_coulomb,
    load_thermal_power_law,
    makkar,
    motor_reducer,
    none,
    power_flow,
    power_law,
    stribeck,
    thermal_viscous,
    viscous_coulomb,
)
from kinergy.friction.model import FrictionModel

__all__ = ["MODELS", "get_model"]


#: every friction model, by the name robot files use
MODELS: dict[str, FrictionModel] = {
    m.MODEL.name: m.MODEL
    for m in (
        none,
        viscous_coulomb,
        motor_reducer,
        power_flow,
        makkar,
        stribeck,
        power_law,
        directional_power_law,
        load_coulomb,
        thermal_viscous,
        load_thermal_power_law,
    )
}


def get_model(name: str | FrictionModel) -> FrictionModel:
    """The model called ``name`` (a model is returned as it is).

    Raises
    ------
    KinergyError
        An unknown name, in one line listing the known ones (code ``UNKNOWN_CHOICE``).
    """
    if isinstance(name, FrictionModel):
        return name
    try:
        return MODELS[name]
    except (KeyError, TypeError):
        known = ", ".join(sorted(MODELS))
        raise KinergyError(
            f"unknown friction model {name!r} (known: {known})", Code.UNKNOWN_CHOICE
        ) from None
