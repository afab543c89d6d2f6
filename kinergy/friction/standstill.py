"""Friction held through standstill: a stopped UR joint stays in stiction.

Every model takes an optional ``standstill`` (motor side, rad/s; default 0, off): while the motor
turns slower than that and accelerates less than :data:`STILL_RATE` times that per second (it has
stopped, not passing through zero speed on a reversal), the friction keeps the value it had when
the joint last moved, scaled by ``holding`` (default 1; the position loop lets part of the torque
relax, as real UR joints do), instead of following the speed's noise through zero. A run of
motion in one direction shorter than :data:`MIN_RUN` samples (a zero-phase speed filter's
overshoot when a joint stops abruptly) does not set that value. It needs samples in time order.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array

__all__ = [
    "MIN_RUN",
    "OPTIONAL_PARAMETERS",
    "OPTIONAL_UNITS",
    "STILL_RATE",
    "hold",
    "hold_standstill",
    "sustained",
]


#: optional parameters of every model and their defaults
OPTIONAL_PARAMETERS = {"standstill": 0.0, "holding": 1.0}
#: ... and their units
OPTIONAL_UNITS = {"standstill": "rad/s", "holding": "1"}
#: a motor is stopped when |wm| < standstill and |dwm| < STILL_RATE * standstill (1/s)
STILL_RATE = 100.0
#: a run of motion shorter than this many samples does not set the held friction
MIN_RUN = 5


def hold_standstill(columns: Array, moving: NDArray[np.bool_]) -> Array:
    """Rows where ``moving`` is False take the last moving row's values (zeros before the first).

    columns : (N, k); moving : (N,) bool, in time order.
    """
    index = np.where(moving, np.arange(moving.size), -1)
    np.maximum.accumulate(index, out=index)
    padded = np.vstack([np.zeros((1, columns.shape[1])), columns])
    return padded[index + 1]


def hold(params: Mapping[str, float], columns: Array, wm: Array, dwm: Array | None) -> Array:
    """``columns`` (N, k) with the standstill hold of ``params`` applied (unchanged when off)."""
    threshold = params.get("standstill", 0.0)
    if threshold <= 0.0:
        return columns
    moving = np.abs(wm) >= threshold
    stopped = ~moving
    if dwm is not None:
        stopped &= np.abs(np.asarray(dwm, dtype=float)) < STILL_RATE * threshold
    held = params.get("holding", 1.0) * hold_standstill(columns, sustained(moving, wm))
    return np.where(stopped[:, None], held, columns)


def sustained(moving: NDArray[np.bool_], wm: Array, min_run: int = MIN_RUN) -> NDArray[np.bool_]:
    """``moving`` (N,) without its runs in one direction (sign of ``wm``, (N,)) shorter than
    ``min_run`` samples."""
    label = np.where(moving, np.sign(wm), 0.0)
    edges = np.concatenate([[0], np.flatnonzero(np.diff(label)) + 1, [label.size]])
    lengths = np.diff(edges)  # of each run of one label
    return moving & np.repeat(lengths >= min_run, lengths)
