"""A movej program as a batched function of its timing: the samples the optimiser evaluates.

The optimiser's variables are, per move, its duration ``t_k`` and ramp fraction ``f_k`` (the share
of the move spent accelerating and braking: ``f = 2 tau / t``); :func:`settings` and
:func:`durations` convert them to and from URScript's ``v`` and ``a``, with the profile of
:mod:`kinergy.trajectory.movej` (the one movej planner).

:func:`sample_programs` samples B programs at once at quadrature nodes and runs the drive model
(:func:`kinergy.predict.drive_state`, the one forward path) over all of them in one call. Inside
the optimiser the energy is a quadrature, not a fixed-step sum: Gauss-Legendre nodes on every
piece between the profiles' switching times (start, end of ramp, start of braking, end), so it is
a smooth function of the decision variables (a fixed ``dt`` grid makes it a staircase in them,
which stalls gradient methods) at a few hundred model evaluations per program.
:func:`motion_samples` gives a 500 Hz re-simulation the same form (trapezoid weights), so an
objective (:mod:`kinergy.optimize.objectives`) is written once for both.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import ParamSpec, TypeVar

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.dynamics.threads import kernel_threads
from kinergy.model.robot import Robot
from kinergy.predict import DriveState, drive_state
from kinergy.trajectory.movej import MovejPlan, blend_starts, sample_moves, trapezoid_timing

__all__ = [
    "ProgramSamples",
    "durations",
    "grid_weights",
    "motion_samples",
    "quadrature_nodes",
    "sample_programs",
    "samples_at",
    "serial",
    "settings",
]

Mask = NDArray[np.bool_]

#: Gauss-Legendre quadrature: sub-intervals per piece and nodes per sub-interval
_SUB = 4
_ORDER = 4
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(_ORDER)

_P = ParamSpec("_P")
_R = TypeVar("_R")


def serial(func: Callable[_P, _R]) -> Callable[_P, _R]:
    """Decorate a public entry point: its dynamics run on the calling thread only
    (:func:`kinergy.dynamics.threads.kernel_threads`; small batches evaluated many times run
    faster serially)."""

    @functools.wraps(func)
    def wrapper(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        with kernel_threads(1):
            return func(*args, **kwargs)

    return wrapper


def settings(travel: Array, t: Array, f: Array) -> tuple[Array, Array, Array]:
    """Peak speed, acceleration and ramp time of trapezoids of travel ``D`` (rad), duration ``t``
    (s) and ramp fraction ``f`` (broadcast): ``v = D / (t - tau)``, ``a = v / tau``,
    ``tau = f t / 2``. Moves of zero travel get ``v = a = 0``."""
    ramp = 0.5 * f * t
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.where(travel > 0.0, travel / (t - ramp), 0.0)
        a = np.where(travel > 0.0, v / ramp, 0.0)
    return v, a, ramp


def durations(travel: Array, v: Array, a: Array) -> tuple[Array, Array]:
    """Duration (s) and ramp fraction of movej moves at speed ``v`` (rad/s) and acceleration
    ``a`` (rad/s^2), broadcast: the inverse of :func:`settings` (a triangle when ``D < v^2 / a``;
    :func:`kinergy.trajectory.movej.trapezoid_timing`). Moves of zero travel: ``t = 0, f = 1``."""
    t, ramp, _ = trapezoid_timing(travel, v, a)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(t > 0.0, 2.0 * ramp / t, 1.0)
    return t, f


def quadrature_nodes(
    breaks: Array, *, sub: int = _SUB, order: int = _ORDER
) -> tuple[Array, Array, Mask]:
    """Gauss-Legendre nodes and weights over the pieces between sorted breakpoints, plus the ends
    of every piece nudged inside it (weight 0, for the limit checks at the switching times).

    Parameters
    ----------
    breaks : ndarray, shape (B, P)
        Sorted switching times of each program, s.
    sub, order : int
        Sub-intervals per piece and Gauss-Legendre nodes per sub-interval.

    Returns
    -------
    times, weights : ndarray, shape (B, M)
        s; the weights integrate over ``[breaks[:, 0], breaks[:, -1]]``.
    valid : ndarray of bool, shape (B, M)
        Whether the node lies in a piece of non-zero width: a node of an empty piece sits on a
        switching time, where rounding can put it in two phases at once (the braking of one move
        and the start of the next).
    """
    gauss_x, gauss_w = (
        (_GAUSS_X, _GAUSS_W) if order == _ORDER else np.polynomial.legendre.leggauss(order)
    )
    lo, hi = breaks[:, :-1], breaks[:, 1:]  # (B, P - 1)
    width = (hi - lo) / sub
    centre = lo[..., None] + (np.arange(sub) + 0.5) * width[..., None]  # (B, P-1, SUB)
    half = 0.5 * width[..., None, None]
    t = centre[..., None] + half * gauss_x  # (B, P-1, SUB, ORDER)
    w = np.broadcast_to(half * gauss_w, t.shape)
    eps = 1e-9 * np.maximum(hi - lo, 0.0)
    ends = np.stack([lo + eps, hi - eps], axis=-1)  # (B, P-1, 2)
    big_b = breaks.shape[0]
    times = np.concatenate([t.reshape(big_b, -1), ends.reshape(big_b, -1)], axis=1)
    weights = np.concatenate([w.reshape(big_b, -1), np.zeros((big_b, ends[0].size))], axis=1)
    wide = (hi - lo) > 1e-9
    valid = np.concatenate(
        [
            np.broadcast_to(wide[..., None, None], t.shape).reshape(big_b, -1),
            np.broadcast_to(wide[..., None], ends.shape).reshape(big_b, -1),
        ],
        axis=1,
    )
    return times, weights, valid


@dataclass(frozen=True, eq=False)
class ProgramSamples:
    """B movej programs sampled at M times each, and the drive model at every sample.

    Attributes
    ----------
    t : ndarray, shape (B, M)
        Sample times, s from each program's start.
    weights : ndarray, shape (B, M)
        Integration weights, s: ``sum(weights * x)`` is ``int x dt`` over the program.
    move : ndarray of int, shape (B, M)
        The move each sample belongs to: the last one started at or before it (moves partition
        the program, a blend's overlap counts to the later move).
    inside : ndarray of bool, shape (B, M, K)
        Whether a sample lies within a move's own span ``[start_k, start_k + t_k]`` (under blends
        a sample can lie in two).
    drive : DriveState
        The drive model at every sample, arrays of shape (B * M, n), program by program.
    """

    t: Array
    weights: Array
    move: NDArray[np.intp]
    inside: Mask
    drive: DriveState = field(repr=False)

    @property
    def moves(self) -> int:
        return int(self.inside.shape[2])

    def integrate(self, values: Array) -> tuple[Array, Array]:
        """``int x dt`` of a per-sample quantity, shape (B * M,) or (B, M): per program (B,) and
        per move (B, K) (the per-move parts add up to the total)."""
        weighted = self.weights * np.reshape(values, self.t.shape)
        total = np.sum(weighted, axis=1)
        parts = np.stack(
            [np.sum(np.where(self.move == k, weighted, 0.0), axis=1) for k in range(self.moves)],
            axis=1,
        )
        return total, parts

    def move_max(self, values: Array) -> Array:
        """The largest of a per-sample quantity (>= 0), shape (B * M,) or (B, M), within each
        move's span: shape (B, K) (0 for a move with no sample)."""
        per_sample = np.reshape(values, self.t.shape)
        return np.asarray(np.max(np.where(self.inside, per_sample[:, :, None], 0.0), axis=1))


def _move_of(t: Array, start: Array) -> NDArray[np.intp]:
    """Index of the last move started at or before each time: t (B, M), start (B, K)."""
    started = t[:, :, None] >= start[:, None, :]
    return np.maximum(np.sum(started, axis=2) - 1, 0)


def samples_at(
    times: Array,
    weights: Array,
    start: Array,
    end: Array,
    drive: DriveState,
    valid: Mask | None = None,
) -> ProgramSamples:
    """:class:`ProgramSamples` of B programs at given times.

    Parameters
    ----------
    times, weights : ndarray, shape (B, M)
        Sample times (s) and integration weights (s).
    start, end : ndarray, shape (B, K)
        When each move starts and ends, s.
    drive : DriveState
        The drive model at the samples, arrays of shape (B * M, n).
    valid : ndarray of bool, shape (B, M), optional
        Samples that count for the moves' spans (default all).
    """
    inside = (times[:, :, None] >= start[:, None, :]) & (times[:, :, None] <= end[:, None, :])
    if valid is not None:
        inside &= valid[:, :, None]
    return ProgramSamples(times, weights, _move_of(times, start), inside, drive)


def sample_programs(
    robot: Robot, waypoints: Array, blends: Array, t: Array, f: Array
) -> ProgramSamples:
    """B movej programs through ``waypoints`` at the quadrature nodes, with the drive model.

    Parameters
    ----------
    robot : Robot
    waypoints : ndarray, shape (K + 1, n)
        rad.
    blends : ndarray, shape (K,)
        Joint-space blend radii, rad.
    t, f : ndarray, shape (B, K)
        Each program's move durations (s) and ramp fractions.

    Returns
    -------
    ProgramSamples
        Gauss-Legendre nodes between every program's switching times (:func:`quadrature_nodes`).
    """
    travel = np.max(np.abs(np.diff(waypoints, axis=0)), axis=1)
    v, a, ramp = settings(travel, t, f)
    start = blend_starts(travel, blends, t, a, ramp)
    end = start + t
    breaks = np.sort(np.concatenate([start, start + ramp, end - ramp, end], axis=1), axis=1)
    times, weights, valid = quadrature_nodes(breaks)  # (B, M)
    q, qd, qdd = sample_moves(waypoints, times, start, t, ramp, v, a)
    n = waypoints.shape[1]
    state = drive_state(robot, q.reshape(-1, n), qd.reshape(-1, n), qdd.reshape(-1, n))
    return samples_at(times, weights, start, end, state, valid)


def grid_weights(t: Array) -> Array:
    """Trapezoid-rule weights of samples at times ``t`` (N,), s: ``sum(w x) = int x dt``."""
    weights = np.zeros_like(t)
    steps = np.diff(t)
    weights[:-1] += 0.5 * steps
    weights[1:] += 0.5 * steps
    return weights


def motion_samples(t: Array, plan: MovejPlan, drive: DriveState) -> ProgramSamples:
    """One program sampled on a time grid (a 500 Hz re-simulation) as :class:`ProgramSamples`.

    Parameters
    ----------
    t : ndarray, shape (N,)
        Sample times, s (trapezoid weights).
    plan : MovejPlan
        The program's plan (move starts and durations).
    drive : DriveState
        The drive model at the samples, arrays of shape (N, n).
    """
    start = plan.start[None, :]
    return samples_at(t[None, :], grid_weights(t)[None, :], start, start + plan.duration, drive)
