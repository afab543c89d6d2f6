"""``viscous_coulomb``: ``viscous * wm + coulomb * tanh(wm / smoothing)`` (framework Table 1,
one friction source per joint)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from kinergy.arrays import Array
from kinergy.friction.model import FrictionModel


def sign(wm: Array, smoothing: float) -> Array:
    """The smoothed sign ``tanh(wm / smoothing)`` every Coulomb term uses."""
    return np.tanh(wm / smoothing)


def _torque(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    return p["viscous"] * wm + p["coulomb"] * sign(wm, p["smoothing"])


def columns(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None = None
) -> Array:
    """``[wm, tanh(wm / smoothing)]``, (N, 2): the viscous and Coulomb columns."""
    return np.column_stack([wm, sign(wm, p["smoothing"])])


MODEL = FrictionModel(
    name="viscous_coulomb",
    parameters=("viscous", "coulomb", "smoothing"),
    torque=_torque,
    linear=("viscous", "coulomb"),
    columns=columns,
    citation="framework Table 1",
    units={"viscous": "N m s/rad", "coulomb": "N m", "smoothing": "rad/s"},
    line=lambda p: (p["coulomb"], p["viscous"]),
)
