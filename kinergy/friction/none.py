"""``none``: no friction (an ideal drive)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from kinergy.arrays import Array
from kinergy.friction.model import FrictionModel


def _torque(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    return np.zeros_like(wm)


def _columns(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    return np.zeros((wm.size, 0))


MODEL = FrictionModel(name="none", parameters=(), torque=_torque, columns=_columns)
