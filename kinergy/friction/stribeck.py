"""``stribeck``: Coulomb friction that starts from a higher static level at rest and falls to the
Coulomb level over the Stribeck speed, plus viscous friction:
``(coulomb + (static - coulomb) exp(-(wm / stribeck_speed)^2)) tanh(wm / smoothing) + viscous wm``."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from kinergy.arrays import Array
from kinergy.friction.model import FrictionModel
from kinergy.friction.viscous_coulomb import sign


def _bump(p: Mapping[str, float], wm: Array) -> Array:
    return np.exp(-((wm / p["stribeck_speed"]) ** 2))


def _torque(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    level = p["coulomb"] + (p["static"] - p["coulomb"]) * _bump(p, wm)
    return level * sign(wm, p["smoothing"]) + p["viscous"] * wm


def _columns(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    s, bump = sign(wm, p["smoothing"]), _bump(p, wm)
    return np.column_stack([s * (1.0 - bump), s * bump, wm])


MODEL = FrictionModel(
    name="stribeck",
    parameters=("coulomb", "static", "stribeck_speed", "viscous", "smoothing"),
    torque=_torque,
    linear=("coulomb", "static", "viscous"),
    columns=_columns,
    positive=frozenset({"stribeck_speed"}),
    shape_defaults={"stribeck_speed": 10.0},
    citation="Stribeck (Olsson et al. 1998, eq 8)",
    units={
        "coulomb": "N m",
        "static": "N m",
        "stribeck_speed": "rad/s",
        "viscous": "N m s/rad",
        "smoothing": "rad/s",
    },
)
