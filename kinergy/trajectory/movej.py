"""UR's joint-space move, ``movej``: synchronised trapezoidal speed profiles.

For each move from waypoint ``w_k`` to ``w_{k+1}`` the joint with the longest travel
``D = max_j |w_{k+1,j} - w_{k,j}|`` runs a trapezoidal speed profile with the given speed ``v``
and acceleration ``a`` (a triangle when ``D < v^2 / a``); every other joint follows the same
profile scaled by its own travel, so all joints start and stop together. This is what the UR
controller plans (checked against its logged target profile in the tests:
``../shared/datasets/ur3e-aurt/AllJoints_MoveJ_Target.csv``) and the "linear interpolation with
continuous acceleration blend" named in the UR5e doc, section 2.

Blending: with a blend radius ``r`` (rad, on the leading joint; UR specifies a TCP radius in m,
which depends on the tool, so kinergy works in joint space) the next move starts before the
current one has stopped, when the current move's leading joint is within ``r`` of the waypoint;
the two profiles are added, so position and speed stay continuous. The overlap is capped at the
current move's deceleration and the next move's acceleration phase, so speeds never exceed the
larger of the two moves' speeds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy.errors import KinergyError
from kinergy.trajectory.motion import Motion

__all__ = ["MovejPlan", "movej", "plan_movej"]

Array = NDArray[np.float64]


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
        w = self.waypoints
        q = np.broadcast_to(w[0], (t.size, w.shape[1])).copy()
        qd = np.zeros_like(q)
        qdd = np.zeros_like(q)
        for k in range(self.start.size):
            delta = w[k + 1] - w[k]
            travel = float(np.max(np.abs(delta)))
            if travel == 0.0:
                continue
            s, sd, sdd = _trapezoid(
                t - self.start[k],
                self.duration[k],
                self.ramp[k],
                self.peak[k],
                self.acceleration[k],
            )
            scale = delta / travel
            q += s[:, None] * scale
            qd += sd[:, None] * scale
            qdd += sdd[:, None] * scale
        return q, qd, qdd


def _trapezoid(
    tau: Array, duration: float, ramp: float, peak: float, acc: float
) -> tuple[Array, Array, Array]:
    """Distance, speed and acceleration of a trapezoidal profile at local times ``tau``."""
    tau = np.clip(tau, 0.0, duration)
    s = np.empty_like(tau)
    sd = np.empty_like(tau)
    sdd = np.zeros_like(tau)
    up = tau < ramp
    down = tau > duration - ramp
    mid = ~(up | down)
    s[up] = 0.5 * acc * tau[up] ** 2
    sd[up] = acc * tau[up]
    sdd[up] = acc
    s[mid] = 0.5 * acc * ramp**2 + peak * (tau[mid] - ramp)
    sd[mid] = peak
    rest = duration - tau[down]
    travel = peak * (duration - ramp)
    s[down] = travel - 0.5 * acc * rest**2
    sd[down] = acc * rest
    sdd[down] = -acc
    # at rest before the start and after the end
    sdd[(tau <= 0.0) | (tau >= duration)] = 0.0
    return s, sd, sdd


def _per_move(value: ArrayLike, moves: int, name: str) -> Array:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(moves, float(arr))
    if arr.shape != (moves,):
        raise KinergyError(
            f"{name}: expected one value or {moves} (one per move), got shape {arr.shape}"
        )
    if name == "blend":
        if np.any(arr < 0.0) or not np.all(np.isfinite(arr)):
            raise KinergyError(f"blend: must be finite and >= 0, got {arr.tolist()}")
    elif np.any(arr <= 0.0) or not np.all(np.isfinite(arr)):
        raise KinergyError(f"{name}: must be finite and > 0, got {arr.tolist()}")
    return arr


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
    w = np.asarray(waypoints, dtype=float)
    if w.ndim != 2 or w.shape[0] < 2:
        raise KinergyError(f"waypoints: expected shape (K + 1, n) with K >= 1, got {w.shape}")
    if not np.all(np.isfinite(w)):
        raise KinergyError("waypoints: not finite")
    moves = w.shape[0] - 1
    v = _per_move(speed, moves, "speed")
    a = _per_move(acceleration, moves, "acceleration")
    r = _per_move(blend, moves, "blend")
    travel = np.max(np.abs(np.diff(w, axis=0)), axis=1)
    triangle = travel < v**2 / a
    peak = np.where(triangle, np.sqrt(a * travel), v)
    ramp = peak / a
    duration = np.where(travel > 0.0, np.where(triangle, 2.0 * ramp, travel / v + v / a), 0.0)
    start = np.zeros(moves)
    for k in range(1, moves):
        overlap = 0.0
        if r[k - 1] > 0.0 and travel[k - 1] > 0.0 and travel[k] > 0.0:
            # time before the end at which the leading joint is r from the waypoint (deceleration)
            overlap = min(np.sqrt(2.0 * r[k - 1] / a[k - 1]), ramp[k - 1], ramp[k])
        start[k] = start[k - 1] + duration[k - 1] - overlap
    return MovejPlan(w, start, duration, ramp, peak, a)


def movej(
    waypoints: ArrayLike,
    *,
    speed: ArrayLike,
    acceleration: ArrayLike,
    dt: float = 0.002,
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
    if not (np.isfinite(dt) and dt > 0.0):
        raise KinergyError(f"dt: must be > 0, got {dt}")
    plan = plan_movej(waypoints, speed=speed, acceleration=acceleration, blend=blend)
    steps = int(np.ceil(plan.total_time / dt - 1e-9))
    t = np.arange(steps + 1) * dt
    q, qd, qdd = plan.sample(t)
    return Motion(t.astype(float), q, qd, qdd)
