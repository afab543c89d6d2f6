"""Which samples of a log are used, and on which time grid.

A sample is used where the robot runs (RTDE's ``robot_mode`` 7, RUNNING: powered, brakes
released, under control) and its safety system lets it move (``safety_mode`` 1 NORMAL or 2
REDUCED), where the log has those columns. ``runtime_state`` leaves no sample out: a program
stopped or paused leaves the arm holding still under control, whose torques and currents are
as valid as those of a motion (its holding torque is the gravity the model predicts).
Irregular time stamps are resampled to a uniform grid.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.io.fields import ROBOT_RUNNING, SAFETY_MOVING
from kinergy.io.log import Log
from kinergy.io.segments import segment_bounds

__all__ = [
    "STATE",
    "resample",
    "running",
    "running_range",
    "running_runs",
    "uniform_grid",
    "used_bounds",
]

#: per-sample state that decides which samples are used (and the recorder's reconnections)
STATE = ("robot_mode", "safety_mode", "segment")


def running(log: Log) -> NDArray[np.bool_]:
    """Per sample of ``log``, whether the robot runs there (module docstring); all True when
    the log has neither ``robot_mode`` nor ``safety_mode``."""
    keep = np.ones(len(log), dtype=bool)
    if "robot_mode" in log:
        keep &= log["robot_mode"] == ROBOT_RUNNING
    if "safety_mode" in log:
        keep &= np.isin(log["safety_mode"], SAFETY_MOVING)
    return keep


def running_runs(log: Log) -> list[tuple[int, int]]:
    """The runs of consecutive samples (start, stop) where the robot runs (:func:`running`), in
    order: each is prepared on its own, as a segment is (nothing is filtered across a stop)."""
    keep = running(log)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], keep.astype(int), [0]])))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def running_range(log: Log) -> slice:
    """The longest run of consecutive samples where the robot runs (:func:`running_runs`; all
    of them when the log has neither column).

    Raises
    ------
    KinergyError
        No sample is left.
    """
    runs = running_runs(log)
    if not runs:
        raise KinergyError(
            f"{log.path}: no sample where the robot runs (robot_mode 7, safety_mode 1 or 2)"
        )
    a, b = max(runs, key=lambda ab: ab[1] - ab[0])
    return slice(a, b)


def uniform_grid(t: Array, *, tolerance: float = 0.01) -> tuple[float, int] | None:
    """The uniform grid irregular time stamps ``t`` (N,) are resampled to, as its period (s)
    and size (the grid is ``t[0] + period * arange(size)``); None when every period is within
    ``tolerance`` of the median (the log is kept as is)."""
    step = np.diff(t)
    dt = float(np.median(step))
    if np.max(np.abs(step - dt)) <= tolerance * dt:
        return None
    return dt, int(np.floor((t[-1] - t[0]) / dt + 1e-9)) + 1


def resample(log: Log, grid: Array) -> Log:
    """``log``'s signals at the times ``grid`` (linear interpolation; a row depends only on the
    two samples around it)."""
    signals = {}
    for name, x in log.signals.items():
        if x.ndim == 1:
            signals[name] = np.interp(grid, log.t, x)
        else:
            signals[name] = np.column_stack(
                [np.interp(grid, log.t, x[:, k]) for k in range(x.shape[1])]
            )
    return Log(log.path, grid, signals)


def used_bounds(state: Log, cuts: Sequence[int] = ()) -> list[tuple[int, int]]:
    """The runs of samples (start, stop) of a log each prepared on its own: its segments (a time
    gap or a ``segment`` change, :func:`kinergy.io.segments.segment_bounds`) cut where the robot
    does not run (:func:`running`) and at ``cuts``, in order.

    Parameters
    ----------
    state : Log
        The log's time stamps and its :data:`STATE` columns (those it has).
    cuts : sequence of int
        Samples that begin a new run (where the logged payload changes).

    Raises
    ------
    KinergyError
        No sample where the robot runs.
    """
    keep = running(state)
    out: list[tuple[int, int]] = []
    starts = np.zeros(len(keep) + 1, dtype=bool)
    starts[[c for c in cuts if 0 < c < len(keep)]] = True
    for a, b in segment_bounds(state.t, state.signals.get("segment")):
        edges = np.flatnonzero(np.diff(np.concatenate([[0], keep[a:b].astype(int), [0]])))
        for x, y in zip(edges[::2] + a, edges[1::2] + a, strict=True):
            inner = [int(x), *(int(c) for c in np.flatnonzero(starts[x + 1 : y]) + x + 1), int(y)]
            out += list(itertools.pairwise(inner))
    if not out:
        raise KinergyError(
            f"{state.path}: no sample where the robot runs (robot_mode 7, safety_mode 1 or 2)"
        )
    return out
