"""``thermal_viscous``: Coulomb friction plus viscous friction that falls as the joint warms:
``coulomb tanh(wm / smoothing) + (viscous + viscous_temperature (T - reference_temperature)) wm``.

The lubricant of a harmonic drive thins as it warms: Raviola et al. 2021 measure the viscous
friction of UR joints falling by 17-20 % from a cold start to the warm joint, and the framework
doc names thermal effects as its next step. ``T`` is the joint temperature (deg C, the
controller's ``joint_temperatures``); without one the model is evaluated at
``reference_temperature`` (the term vanishes). Linear in ``coulomb``, ``viscous`` and
``viscous_temperature`` (columns ``[sign, wm, wm (T - T_ref)]``); ``viscous_temperature`` is
negative for friction that falls as the joint warms.

Units (motor side): ``coulomb`` N m, ``viscous`` N m s/rad, ``viscous_temperature``
N m s/(rad K), ``reference_temperature`` deg C, ``smoothing`` rad/s.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from kinergy.arrays import Array
from kinergy.friction.model import FrictionModel
from kinergy.friction.viscous_coulomb import sign

__all__ = ["MODEL", "REFERENCE_TEMPERATURE", "warming"]


#: the reference temperature fits start from, deg C (a UR joint a few degrees above room)
REFERENCE_TEMPERATURE = 25.0


def warming(p: Mapping[str, float], wm: Array, temperature: Array | None) -> Array:
    """``T - reference_temperature`` (K), shape like ``wm``; zeros without a temperature."""
    if temperature is None:
        return np.zeros_like(np.asarray(wm, dtype=float))
    return np.broadcast_to(temperature - p["reference_temperature"], np.shape(wm)).astype(float)


def _torque(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    viscous = p["viscous"] + p["viscous_temperature"] * warming(p, wm, temperature)
    return p["coulomb"] * sign(wm, p["smoothing"]) + viscous * wm


def _columns(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    return np.column_stack([sign(wm, p["smoothing"]), wm, wm * warming(p, wm, temperature)])


MODEL = FrictionModel(
    name="thermal_viscous",
    parameters=(
        "coulomb",
        "viscous",
        "viscous_temperature",
        "reference_temperature",
        "smoothing",
    ),
    torque=_torque,
    linear=("coulomb", "viscous", "viscous_temperature"),
    columns=_columns,
    bounds={"viscous_temperature": (-np.inf, np.inf)},
    shape_defaults={"reference_temperature": REFERENCE_TEMPERATURE},
    needs_temperature=True,
    citation="Raviola et al. 2021 (viscous friction of UR joints falls 17-20 % as they warm)",
    units={
        "coulomb": "N m",
        "viscous": "N m s/rad",
        "viscous_temperature": "N m s/(rad K)",
        "reference_temperature": "°C",
        "smoothing": "rad/s",
    },
)
