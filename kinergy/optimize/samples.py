"""A robot program as a batched function of its moves' timing: the samples the optimiser
evaluates.

The optimiser's variables are, per move, its duration ``t_k`` and ramp fraction ``f_k`` (the share
of the move spent accelerating and braking: ``f = 2 tau / t``); :func:`settings` and
:func:`durations` convert them to and from URScript's ``v`` and ``a`` (the profile of
:mod:`kinergy.trajectory.movej`, the one trapezoid planner). For a resolved
:class:`~kinergy.trajectory.program_path.ProgramPath` (movej, movel, movep, blends, events of
fixed time), :func:`sample_path_programs` plans B programs
(:func:`kinergy.trajectory.program_motion.schedule_profiles`), samples them at quadrature nodes and
runs the drive model (:func:`kinergy.predict.drive_state`, the one forward path) over every sample
with the load the program has set there (:func:`drive_by_payload`). Inside the optimiser the
energy is a quadrature, not a fixed-step sum: Gauss-Legendre nodes on every piece between the
moves' switching times (start, end of ramp, start of braking, end) while a move runs, and one node
per event (the arm at rest, its power constant), so it is a smooth function of the decision
variables (a fixed ``dt`` grid makes it a staircase in them, which stalls gradient methods) at a
few hundred model evaluations per program. A 500 Hz re-simulation takes the same form
(:func:`samples_at` with :func:`grid_weights`), so an objective
(:mod:`kinergy.optimize.objectives`) is written once for both.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import ParamSpec, TypeVar

import numpy as np
from numpy.typing import NDArray
from threadpoolctl import threadpool_limits

from kinergy.arrays import Array
from kinergy.dynamics.threads import kernel_threads
from kinergy.model.robot import Robot
from kinergy.predict import DriveState, drive_by_payload  # its home is the one forward path
from kinergy.trajectory.movej import trapezoid_timing
from kinergy.trajectory.program_motion import (
    LineTables,
    Schedule,
    payload_index,
    sample_path,
    schedule_profiles,
)
from kinergy.trajectory.program_path import ProgramPath

__all__ = [
    "ProgramSamples",
    "drive_by_payload",
    "durations",
    "grid_weights",
    "path_schedule",
    "piece_nodes",
    "sample_path_programs",
    "samples_at",
    "serial",
    "settings",
]

Mask = NDArray[np.bool_]

#: Gauss-Legendre quadrature: sub-intervals per piece and nodes per sub-interval (the 500 Hz
#: re-simulation makes the final figures)
_SUB = 2
_ORDER = 4
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(_ORDER)

_P = ParamSpec("_P")
_R = TypeVar("_R")


def serial(func: Callable[_P, _R]) -> Callable[_P, _R]:
    """Decorate a public entry point: its dynamics run on the calling thread only
    (:func:`kinergy.dynamics.threads.kernel_threads`; small batches evaluated many times run
    faster serially), and so does its linear algebra (BLAS on one thread, restored after).

    The BLAS thread count changes the result: a threaded BLAS splits some sums over its threads,
    whose partial sums add in another order, and the solver's path (SLSQP) follows the last bit.
    Its default is one thread per core of the host (and what an earlier caller left in force in
    the process): the same placement came out 196.0703 J on two BLAS threads and 196.0856 J on
    one. On one thread the answer is the same whatever the host's core count, in any process and
    any worker (a BLAS built for another processor may still differ in the last bits)."""

    @functools.wraps(func)
    def wrapper(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        with kernel_threads(1), threadpool_limits(limits=1, user_api="blas"):
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


def piece_nodes(
    lo: Array, hi: Array, *, sub: int = _SUB, order: int = _ORDER
) -> tuple[Array, Array, Mask]:
    """Gauss-Legendre nodes and weights over pieces ``[lo, hi]``, plus the ends of every piece
    nudged inside it (weight 0, for the limit checks at the switching times).

    Parameters
    ----------
    lo, hi : ndarray, shape (B, P)
        Where each piece of each program starts and ends, s.
    sub, order : int
        Sub-intervals per piece and Gauss-Legendre nodes per sub-interval.

    Returns
    -------
    times, weights : ndarray, shape (B, M)
        s; the weights integrate over the pieces.
    valid : ndarray of bool, shape (B, M)
        Whether the node lies in a piece of non-zero width: a node of an empty piece sits on a
        switching time, where rounding can put it in two phases at once (the braking of one move
        and the start of the next).
    """
    gauss_x, gauss_w = (
        (_GAUSS_X, _GAUSS_W) if order == _ORDER else np.polynomial.legendre.leggauss(order)
    )
    width = (hi - lo) / sub
    centre = lo[..., None] + (np.arange(sub) + 0.5) * width[..., None]  # (B, P, SUB)
    half = 0.5 * width[..., None, None]
    t = centre[..., None] + half * gauss_x  # (B, P, SUB, ORDER)
    w = np.broadcast_to(half * gauss_w, t.shape)
    eps = 1e-9 * np.maximum(hi - lo, 0.0)
    ends = np.stack([lo + eps, hi - eps], axis=-1)  # (B, P, 2)
    big_b = lo.shape[0]
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
    qd, qdd : ndarray, shape (B * M, n), optional
        The joint speeds (rad/s) and accelerations (rad/s^2) at every sample.
    """

    t: Array
    weights: Array
    move: NDArray[np.intp]
    inside: Mask
    drive: DriveState = field(repr=False)
    qd: Array | None = field(default=None, repr=False)
    qdd: Array | None = field(default=None, repr=False)

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
    rates: tuple[Array, Array] | None = None,
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
    rates : tuple of ndarray, shape (B * M, n) each, optional
        The joint speeds and accelerations at the samples.
    """
    inside = (times[:, :, None] >= start[:, None, :]) & (times[:, :, None] <= end[:, None, :])
    if valid is not None:
        inside &= valid[:, :, None]
    qd, qdd = (None, None) if rates is None else rates
    return ProgramSamples(times, weights, _move_of(times, start), inside, drive, qd, qdd)


def grid_weights(t: Array) -> Array:
    """Trapezoid-rule weights of samples at times ``t`` (N,), s: ``sum(w x) = int x dt``."""
    weights = np.zeros_like(t)
    steps = np.diff(t)
    weights[:-1] += 0.5 * steps
    weights[1:] += 0.5 * steps
    return weights


def path_schedule(path: ProgramPath, t: Array, f: Array) -> Schedule:
    """B programs on ``path`` given their moves' durations ``t`` (s) and ramp fractions ``f``,
    shape (B, K) (:func:`settings`)."""
    v, a, ramp = settings(path.travel, t, f)
    return schedule_profiles(path, t, ramp, v, a)


def _nodes(path: ProgramPath, sched: Schedule) -> tuple[Array, Array, NDArray[np.bool_]]:
    """The quadrature of B programs: Gauss-Legendre nodes on every piece between the moves'
    switching times (start, end of ramp, start of braking, end) where a move runs, and one node
    per event of non-zero time (the arm at rest there, its load fixed: the power is constant),
    weighted by its time. Times, weights and valid nodes, shape (B, M) each."""
    end = sched.start + sched.duration
    breaks = np.sort(
        np.concatenate([sched.start, sched.start + sched.ramp, end - sched.ramp, end], axis=1),
        axis=1,
    )
    lo, hi = breaks[:, :-1], breaks[:, 1:]
    mid = 0.5 * (lo + hi)
    running = np.any(
        (mid[:, :, None] > sched.start[:, None, :]) & (mid[:, :, None] < end[:, None, :]), axis=2
    )
    keep = np.any(running & (hi - lo > 1e-12), axis=0)  # the same pieces in every program
    times, weights, valid = piece_nodes(lo[:, keep], hi[:, keep], sub=_SUB)
    timed = path.event_time > 0.0
    if np.any(timed):
        at_rest = sched.event_start[:, timed] + 0.5 * path.event_time[timed]
        times = np.concatenate([times, at_rest], axis=1)
        weights = np.concatenate(
            [weights, np.broadcast_to(path.event_time[timed], at_rest.shape)], axis=1
        )
        valid = np.concatenate([valid, np.ones(at_rest.shape, dtype=bool)], axis=1)
    return times, weights, valid


def _samples(
    robot: Robot,
    path: ProgramPath,
    sched: Schedule,
    times: Array,
    weights: Array,
    valid: NDArray[np.bool_] | None,
    tables: LineTables | None = None,
) -> ProgramSamples:
    q, qd, qdd = (
        x.reshape(-1, path.q0.size) for x in sample_path(robot, path, sched, times, tables=tables)
    )
    load = payload_index(path, sched, times).reshape(-1)
    drive = drive_by_payload(path.robots, load, q, qd, qdd)
    end = sched.start + sched.duration
    return samples_at(times, weights, sched.start, end, drive, valid, (qd, qdd))


def sample_path_programs(
    robot: Robot,
    path: ProgramPath,
    t: Array,
    f: Array,
    *,
    tables: LineTables | None = None,
) -> ProgramSamples:
    """B programs on ``path`` at the quadrature nodes, with the drive model.

    Parameters
    ----------
    robot : Robot
    path : ProgramPath
    t, f : ndarray, shape (B, K)
        Each program's move durations (s) and ramp fractions.
    tables : LineTables, optional
        Lone tool moves sampled from their tables
        (:func:`kinergy.trajectory.program_motion.line_tables`).

    Returns
    -------
    ProgramSamples
        Gauss-Legendre nodes between every program's switching times while a move runs, one
        node per event (:func:`_nodes`); events count to the move before them.
    """
    sched = path_schedule(path, t, f)
    times, weights, valid = _nodes(path, sched)
    return _samples(robot, path, sched, times, weights, valid, tables)
