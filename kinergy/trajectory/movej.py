"""UR's joint-space move, ``movej``: synchronised trapezoidal speed profiles.

For each move from waypoint ``w_k`` to ``w_{k+1}`` the joint with the longest travel
``D = max_j |w_{k+1,j} - w_{k,j}|`` runs a trapezoidal speed profile with the given speed ``v``
and acceleration ``a`` (a triangle when ``D < v^2 / a``); every other joint follows the same
profile scaled by its own travel, so all joints start and stop together. This is what the UR
controller plans (checked in the tests against the target profile a UR3e controller logged for
one movej, the AURT project's ``AllJoints_MoveJ_Target.csv``) and the "linear interpolation with
continuous acceleration blend" named in the UR5e doc, section 2.

Blending: with a blend radius ``r`` (rad, on the leading joint; UR specifies a TCP radius in m,
which depends on the tool, so kinergy works in joint space) the next move starts before the
current one has stopped, when the current move's leading joint is within ``r`` of the waypoint;
the two profiles are added, so position and speed stay continuous. The overlap is capped at the
current move's deceleration and the next move's acceleration phase, so speeds never exceed the
larger of the two moves' speeds.

This module is the one place that plans the profile. Its building blocks broadcast over leading
axes, so the optimiser (:mod:`kinergy.optimize`) plans and samples many candidate programs in
one call: :func:`trapezoid_timing` (a move's duration, ramp and peak speed), :func:`blend_starts`
(when each move starts), :func:`trapezoid` (one profile at given times) and
:func:`sample_moves` (the joint motion of whole programs).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy import checks
from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.trajectory.motion import CONTROLLER_DT, Motion, sample_times

__all__ = [
    "MovejPlan",
    "blend_starts",
    "check_waypoints",
    "movej",
    "per_move",
    "plan_movej",
    "sample_moves",
    "trapezoid",
    "trapezoid_timing",
]


@dataclass(frozen=True)
class MovejPlan:
    """The timing of a movej program.

    Attributes
    ----------
    waypoints : ndarray, shape (K + 1, n)
        rad.
    start : ndarray, shape (K,)
        Start time of each move, s.
    duration : ndarray, shape (K,)
        Duration of each move on its own, s.
    ramp : ndarray, shape (K,)
        Acceleration (= deceleration) time of each move, s.
    peak : ndarray, shape (K,)
        Peak speed of each move's leading joint, rad/s.
    acceleration : ndarray, shape (K,)
        Acceleration of each move's leading joint, rad/s^2.
    """

    waypoints: Array
    start: Array
    duration: Array
    ramp: Array
    peak: Array
    acceleration: Array

    @property
    def total_time(self) -> float:
        """Time from the first move's start to the last move's end, s."""
        if self.start.size == 0:
            return 0.0
        return float(np.max(self.start + self.duration))

    def sample(self, t: ArrayLike) -> tuple[Array, Array, Array]:
        """Joint angles, speeds and accelerations at times ``t`` (s, from the program start).

        Returns three arrays of shape (len(t), n).
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        q, qd, qdd = sample_moves(
            self.waypoints,
            t[None, :],
            self.start[None, :],
            self.duration[None, :],
            self.ramp[None, :],
            self.peak[None, :],
            self.acceleration[None, :],
        )
        return q[0], qd[0], qdd[0]


def trapezoid(
    tau: ArrayLike, duration: ArrayLike, ramp: ArrayLike, peak: ArrayLike, acc: ArrayLike
) -> tuple[Array, Array, Array]:
    """Distance, speed and acceleration of trapezoidal profiles at local times ``tau``.

    Parameters
    ----------
    tau : array_like
        Time since the move's start, s; clipped to ``[0, duration]`` (at rest before and after).
    duration, ramp, peak, acc : array_like
        The profile (:func:`trapezoid_timing`): s, s, rad/s, rad/s^2; broadcast against ``tau``.

    Returns
    -------
    s, sd, sdd : ndarray
        rad, rad/s, rad/s^2 of the leading joint, the broadcast shape.
    """
    duration = np.asarray(duration, dtype=float)
    ramp = np.asarray(ramp, dtype=float)
    peak = np.asarray(peak, dtype=float)
    acc = np.asarray(acc, dtype=float)
    tau = np.clip(tau, 0.0, duration)
    up = tau < ramp
    down = tau > duration - ramp
    rest = duration - tau
    s = np.where(
        up,
        0.5 * acc * tau**2,
        np.where(
            down,
            peak * (duration - ramp) - 0.5 * acc * rest**2,
            0.5 * acc * ramp**2 + peak * (tau - ramp),
        ),
    )
    sd = np.where(up, acc * tau, np.where(down, acc * rest, peak))
    sdd = np.where(up, acc, np.where(down, -acc, 0.0))
    sdd = np.where((tau <= 0.0) | (tau >= duration), 0.0, sdd)
    return s, sd, sdd


def trapezoid_timing(
    travel: ArrayLike, speed: ArrayLike, acceleration: ArrayLike
) -> tuple[Array, Array, Array]:
    """Duration, ramp time and peak speed of moves of leading-joint ``travel`` at URScript's
    ``v`` and ``a`` (broadcast): a trapezoid, or a triangle when ``D < v^2 / a``.

    Parameters
    ----------
    travel : array_like
        Leading-joint travel ``D``, rad; a move of zero travel lasts 0 s.
    speed, acceleration : array_like
        ``v`` (rad/s) and ``a`` (rad/s^2).

    Returns
    -------
    duration, ramp, peak : ndarray
        ``D / v + v / a`` (trapezoid) or ``2 sqrt(D / a)`` (triangle), s; ``peak / a``, s;
        ``v`` or ``sqrt(a D)``, rad/s.
    """
    travel = np.asarray(travel, dtype=float)
    v = np.asarray(speed, dtype=float)
    a = np.asarray(acceleration, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        triangle = travel < v**2 / a
        peak = np.where(triangle, np.sqrt(a * travel), v)
        ramp = peak / a
        duration = np.where(travel > 0.0, np.where(triangle, 2.0 * ramp, travel / v + v / a), 0.0)
    return duration, ramp, peak


def blend_starts(
    travel: Array,
    blend: Array,
    duration: Array,
    acceleration: Array,
    ramp: Array,
    *,
    linked: NDArray[np.bool_] | None = None,
    gaps: Array | None = None,
) -> Array:
    """Start time of every move (s) under kinergy's blending rule (see the module docstring).

    Parameters
    ----------
    travel, blend : ndarray, shape (K,)
        Leading-joint travel and blend radius of each move, rad (or any unit, the same for both:
        a tool move's path length in m).
    duration, acceleration, ramp : ndarray, shape (..., K)
        Each move's profile (:func:`trapezoid_timing`), s, rad/s^2, s; leading axes are
        independent programs.
    linked : ndarray of bool, shape (K,), optional
        Whether move k may blend into move k + 1 at all (default: every pair); a program's
        moves of different kinds, or with an event between them, do not.
    gaps : ndarray, shape (K,), optional
        Fixed time at rest before each move (events: sleeps, I/O), s; default 0.

    Returns
    -------
    ndarray, shape (..., K)
        The next move starts when the current one's leading joint is within ``r`` of its target,
        at most the shorter of the two ramps before the current move's end (after the gap, when
        there is one: then no blend).
    """
    start = np.zeros_like(duration)
    links = np.ones(travel.size, dtype=bool) if linked is None else linked
    gap = np.zeros(travel.size) if gaps is None else gaps
    if travel.size:
        start[..., 0] = gap[0]
    for k in range(1, duration.shape[-1]):
        overlap = np.zeros(duration.shape[:-1])
        if links[k - 1] and blend[k - 1] > 0.0 and travel[k - 1] > 0.0 and travel[k] > 0.0:
            # a radius beyond the move's travel blends no more than the travel itself (the ramp
            # caps it first), and 2 r of a huge r would overflow
            radius = min(blend[k - 1], travel[k - 1])
            overlap = np.minimum(
                np.minimum(np.sqrt(2.0 * radius / acceleration[..., k - 1]), ramp[..., k - 1]),
                ramp[..., k],
            )
        start[..., k] = start[..., k - 1] + duration[..., k - 1] - overlap + gap[k]
    return start


def sample_moves(
    waypoints: Array,
    t: Array,
    start: Array,
    duration: Array,
    ramp: Array,
    peak: Array,
    acceleration: Array,
) -> tuple[Array, Array, Array]:
    """Joint motion of B movej programs through the same waypoints, each at its own times.

    Parameters
    ----------
    waypoints : ndarray, shape (K + 1, n)
        rad.
    t : ndarray, shape (B, M)
        Sample times of each program, s from its start.
    start, duration, ramp, peak, acceleration : ndarray, shape (B, K)
        Each program's moves (:func:`trapezoid_timing`, :func:`blend_starts`).

    Returns
    -------
    q, qd, qdd : ndarray, shape (B, M, n)
        rad, rad/s, rad/s^2: the sum of every move's profile along its direction.
    """
    delta = np.diff(waypoints, axis=0)
    travel = np.max(np.abs(delta), axis=1)
    q = np.broadcast_to(waypoints[0], (*t.shape, waypoints.shape[1])).copy()
    qd = np.zeros_like(q)
    qdd = np.zeros_like(q)
    for k in range(travel.size):
        if travel[k] == 0.0:
            continue
        s, sd, sdd = trapezoid(
            t - start[:, k : k + 1],
            duration[:, k : k + 1],
            ramp[:, k : k + 1],
            peak[:, k : k + 1],
            acceleration[:, k : k + 1],
        )
        unit = delta[k] / travel[k]
        q += s[..., None] * unit
        qd += sd[..., None] * unit
        qdd += sdd[..., None] * unit
    return q, qd, qdd


def check_waypoints(waypoints: ArrayLike) -> Array:
    """``waypoints`` as a finite float array of shape (K + 1, n) with K >= 1, rad.

    Raises
    ------
    KinergyError
        Another shape, or values that are not finite.
    """
    w = np.asarray(waypoints, dtype=float)
    if w.ndim != 2 or w.shape[0] < 2:
        raise KinergyError(f"waypoints: expected shape (K + 1, n) with K >= 1, got {w.shape}")
    if not np.all(np.isfinite(w)):
        raise KinergyError("waypoints: not finite")
    return w


def per_move(value: ArrayLike, moves: int, name: str) -> Array:
    """One setting per move: a scalar repeated ``moves`` times or an array of shape (K,).

    Raises
    ------
    KinergyError
        Any other shape.
    """
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(moves, float(arr))
    if arr.shape != (moves,):
        raise KinergyError(
            f"{name}: expected one value or {moves} (one per move), got shape {arr.shape}"
        )
    return arr


def _setting(value: ArrayLike, moves: int, name: str) -> Array:
    """A per-move setting of the planner: finite, > 0 (``blend``: >= 0)."""
    arr = per_move(value, moves, name)
    if name == "blend":
        return checks.vector(arr, name, ge=0.0)
    return checks.vector(arr, name, gt=0.0)


def plan_movej(
    waypoints: ArrayLike,
    *,
    speed: ArrayLike,
    acceleration: ArrayLike,
    blend: ArrayLike = 0.0,
) -> MovejPlan:
    """Plan a movej program through ``waypoints``.

    Parameters
    ----------
    waypoints : array_like, shape (K + 1, n)
        Start pose followed by the K targets, rad.
    speed, acceleration : float or array_like, shape (K,)
        Leading-joint speed (rad/s) and acceleration (rad/s^2), as URScript's ``v`` and ``a``,
        for all moves or per move.
    blend : float or array_like, shape (K,)
        Blend radius on the leading joint at the end of each move, rad (the last is ignored).

    Returns
    -------
    MovejPlan
    """
    w = check_waypoints(waypoints)
    moves = w.shape[0] - 1
    v = _setting(speed, moves, "speed")
    a = _setting(acceleration, moves, "acceleration")
    r = _setting(blend, moves, "blend")
    travel = np.max(np.abs(np.diff(w, axis=0)), axis=1)
    duration, ramp, peak = trapezoid_timing(travel, v, a)
    start = blend_starts(travel, r, duration, a, ramp)
    return MovejPlan(w, start, duration, ramp, peak, a)


def movej(
    waypoints: ArrayLike,
    *,
    speed: ArrayLike,
    acceleration: ArrayLike,
    dt: float = CONTROLLER_DT,
    blend: ArrayLike = 0.0,
) -> Motion:
    """A movej program sampled every ``dt`` seconds (UR's controller runs at 500 Hz: 0.002 s).

    Parameters
    ----------
    waypoints : array_like, shape (K + 1, n)
        Start pose followed by the targets, rad.
    speed, acceleration : float or array_like, shape (K,)
        rad/s and rad/s^2, as URScript's ``movej(q, a, v)``.
    dt : float
        Sample period, s.
    blend : float or array_like, shape (K,)
        Blend radius on the leading joint, rad (see the module docstring).

    Returns
    -------
    Motion
        From t = 0 to the first sample at or after the end; the arm is at rest at the last
        waypoint from the end on.

    Examples
    --------
    >>> import numpy as np
    >>> m = movej([[0.0, 0.0], [1.0, -0.5]], speed=1.0, acceleration=2.0, dt=0.01)
    >>> round(m.duration, 2), m.q[-1].tolist()
    (1.5, [1.0, -0.5])
    """
    dt = checks.number(dt, "dt", gt=0.0)
    plan = plan_movej(waypoints, speed=speed, acceleration=acceleration, blend=blend)
    k = int(np.argmax(plan.duration)) if plan.duration.size else 0
    longest = (
        f"move {k + 1} alone {plan.duration[k]:.4g} s at v = "
        f"{per_move(speed, plan.duration.size, 'speed')[k]:.4g} rad/s"
        if plan.duration.size
        else ""
    )
    t = sample_times(plan.total_time, dt, longest)
    q, qd, qdd = plan.sample(t)
    return Motion(t, q, qd, qdd)
