"""The constant-speed back-and-forth friction experiment (nursing section 4.1, Figure 6).

One joint moves back and forth at constant speed, at a ladder of speeds, the others still, in a
pose where gravity on it does not change (its axis vertical). At constant speed the joint needs
no inertial torque, so the torque from the motor currents (nursing eq 21) is friction plus what
does not depend on the direction of motion; the odd part over the two directions is friction
(eqs 19-20, :mod:`kinergy.identification.friction_points`). This module designs the runs:

- :func:`vertical_axis_pose`: a pose in which the moving joint's axis is parallel to gravity;
- :func:`default_speeds`: the speed ladder;
- :func:`back_and_forth_motion`: the commanded motion with the sample ranges of every
  constant-speed part (:class:`FrictionRun`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.optimize
from numpy.typing import ArrayLike, NDArray

from kinergy import checks
from kinergy.arrays import Array
from kinergy.dynamics.chain import make_chain
from kinergy.dynamics.kinematics import joint_axes
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.trajectory.motion import CONTROLLER_DT, Motion

__all__ = ["FrictionRun", "back_and_forth_motion", "default_speeds", "vertical_axis_pose"]

#: ``x -> z_j(x) x g_hat``: the moving joint's axis crossed with gravity's direction, shape (3,)
_TiltFunction = Callable[[Array], Array]

#: seeded random starts of the search for a vertical axis (besides the given pose)
_POSE_STARTS = 8


def _tilt_function(robot: Robot, joint: int, g_hat: Array) -> _TiltFunction:
    """``x -> z_joint(x) x g_hat``, shape (3,): zero when joint ``joint``'s axis is vertical."""
    chain = make_chain(robot)

    def tilt_of(x: Array) -> Array:
        z, _, _ = joint_axes(chain, x[None, :])
        return np.cross(z[0, joint], g_hat)

    return tilt_of


def _vertical_candidates(
    tilt_of: _TiltFunction, q_start: Array, joint: int, lo: Array, hi: Array, seed: int
) -> list[tuple[float, float, Array]]:
    """``(tilt norm, -room to the limits, pose)`` found by least squares on the joints before
    ``joint`` from ``q_start`` and :data:`_POSE_STARTS` seeded starts within the limits."""
    rng = np.random.default_rng(seed)
    starts = [np.clip(q_start[:joint], lo[:joint], hi[:joint])]
    starts += [rng.uniform(lo[:joint], hi[:joint]) for _ in range(_POSE_STARTS)]
    found = []
    for x0 in starts:

        def resid(u: Array) -> Array:
            x = q_start.copy()
            x[:joint] = u
            return tilt_of(x)

        sol = scipy.optimize.least_squares(
            resid, x0, bounds=(lo[:joint], hi[:joint] + 1e-12), xtol=1e-14, ftol=1e-14
        )
        cand = q_start.copy()
        cand[:joint] = sol.x
        room = np.minimum(sol.x - lo[:joint], hi[:joint] - sol.x) / (hi - lo)[:joint]
        found.append((float(np.linalg.norm(tilt_of(cand))), -float(room.min()), cand))
    return found


def vertical_axis_pose(
    robot: Robot, joint: int, q: ArrayLike | None = None, *, seed: int = 0
) -> tuple[Array, float]:
    """A pose in which joint ``joint``'s axis is parallel to gravity, so gravity exerts no torque
    about it however it turns (the doc's pose for the friction runs, Figure 6).

    When ``q`` (default zeros) does not already have it, the joints before ``joint`` are chosen
    by least squares on ``z_j x g / |g|`` within their limits, from ``q`` and 8 seeded starts;
    of the vertical poses found, the one farthest from the joint limits. ``joint`` and the joints
    after it keep ``q``'s values. Some axes can never be vertical (the nursing arm's joint 2 is
    always horizontal): the tilt says so, and
    :func:`kinergy.identification.friction_points.friction_points` still cancels gravity by pairing
    equal positions.

    Returns
    -------
    q : ndarray, shape (n,)
        rad.
    tilt : float
        Angle left between the axis and gravity, rad (0 when reached).
    """
    q_start = np.zeros(robot.n) if q is None else np.asarray(q, dtype=float).copy()
    g = np.asarray(robot.gravity, dtype=float)
    g_norm = float(np.linalg.norm(g))
    if g_norm == 0.0:
        return q_start, 0.0
    # the axes are in the frame gravity is given in (robot.base applied)
    tilt_of = _tilt_function(robot, joint, g / g_norm)
    best = q_start
    best_norm = float(np.linalg.norm(tilt_of(q_start)))
    if joint > 0 and best_norm > 1e-12:
        lo = np.array([max(jt.limits.position[0], -np.pi) for jt in robot.joints])
        hi = np.array([min(jt.limits.position[1], np.pi) for jt in robot.joints])
        found = _vertical_candidates(tilt_of, q_start, joint, lo, hi, seed)
        # vertical poses first, then the one farthest from the joint limits
        found.sort(key=lambda c: (round(c[0], 9), c[1]))
        if found[0][0] < best_norm:
            best_norm, _, best = found[0]
    return best, float(np.arcsin(min(best_norm, 1.0)))


@dataclass(frozen=True, eq=False)
class FrictionRun:
    """A constant-speed back-and-forth experiment for one joint.

    Attributes
    ----------
    motion : Motion
        The commanded motion (all joints; only ``joint`` moves).
    joint : int
        The moving joint, 0-based.
    speeds : ndarray, shape (L,)
        Speed levels, rad/s (> 0).
    forward, backward : ndarray of int, shape (L, 2)
        ``[start, stop)`` sample indices of each level's constant-speed part moving at ``+v``
        and at ``-v``; the backward part covers the forward part's positions in reverse.
    pose : ndarray, shape (n,)
        The still joints' angles (and the centre of ``joint``'s travel), rad.
    tilt : float
        Angle between the moving joint's axis and gravity, rad.
    """

    motion: Motion
    joint: int
    speeds: Array
    forward: NDArray[np.int_]
    backward: NDArray[np.int_]
    pose: Array
    tilt: float


def default_speeds(robot: Robot, joint: int, *, levels: int = 15, slowest: float = 0.01) -> Array:
    """``levels`` speeds from ``slowest`` to the joint's speed limit, geometrically spaced (rad/s):
    Makkar's model bends at low speed, where an even ladder (the doc's 1, 1.5, 2, ... deg/s) puts
    few points."""
    top = robot.joints[joint].limits.speed
    if not 0.0 < slowest < top:
        raise KinergyError(
            f"slowest speed must be between 0 and joint {joint + 1}'s limit {top:g} rad/s, got {slowest:g}"
        )
    return np.geomspace(slowest, top, levels)


def _check_options(robot: Robot, joint: int, **options: float) -> None:
    """The joint index, ``dwell >= 0`` and every other option ``> 0`` (finite)."""
    if not 0 <= joint < robot.n:
        raise KinergyError(f"joint index {joint} out of range for {robot.name} ({robot.n} joints)")
    for name, value in options.items():
        checks.number(value, name, **({"ge": 0.0} if name == "dwell" else {"gt": 0.0}))


def _speed_levels(robot: Robot, joint: int, speeds: ArrayLike | None) -> Array:
    """``speeds`` (default :func:`default_speeds`) checked: positive, within the speed limit."""
    v_all = default_speeds(robot, joint) if speeds is None else np.asarray(speeds, dtype=float)
    limit = robot.joints[joint].limits.speed
    if v_all.ndim != 1 or v_all.size == 0 or not np.all((v_all > 0) & np.isfinite(v_all)):
        raise KinergyError("speeds must be a non-empty list of positive numbers (rad/s)")
    if np.any(v_all > limit * (1.0 + 1e-9)):
        raise KinergyError(
            f"joint {joint + 1} ({robot.joints[joint].name}): speed {v_all.max():g} rad/s "
            f"exceeds its limit {limit:g} rad/s"
        )
    return v_all


def _run_pose(robot: Robot, joint: int, pose: ArrayLike | None) -> tuple[Array, float]:
    """The still joints' pose (default :func:`vertical_axis_pose`) and the axis' tilt, rad."""
    if pose is None:
        return vertical_axis_pose(robot, joint)
    pose_arr = np.asarray(pose, dtype=float)
    if pose_arr.shape != (robot.n,):
        raise KinergyError(f"pose must have {robot.n} angles, got shape {pose_arr.shape}")
    return pose_arr, 0.0


def _speed_profile(
    v_all: Array, *, travel: float, max_time: float, acceleration: float, dwell: float, dt: float
) -> tuple[Array, list[tuple[int, int]], list[tuple[int, int]], float]:
    """The moving joint's speed, sample by sample (rad/s), from rest: per level a trapezoid
    forward, a dwell, the same backward, a dwell. Returns the speeds, the forward and backward
    constant-speed ``[start, stop)`` ranges and the largest excursion (rad)."""
    kd = round(dwell / dt)
    pieces: list[Array] = [np.zeros(kd + 1)]
    forward: list[tuple[int, int]] = []
    backward: list[tuple[int, int]] = []
    excursion = 0.0
    at = kd + 1
    for v in v_all:
        kr = max(1, round(v / acceleration / dt))
        kc = max(2, round(min(travel / v, max_time) / dt))
        k = np.arange(1, 2 * kr + kc + 1)
        profile = v * np.minimum(np.minimum(k / kr, 1.0), (2 * kr + kc - k) / kr)
        excursion = max(excursion, v * dt * (kr + kc))
        for sign, store in ((1.0, forward), (-1.0, backward)):
            store.append((at + kr - 1, at + kr + kc))  # samples at speed v: k = kr .. kr + kc
            pieces += [sign * profile, np.zeros(kd)]
            at += profile.size + kd
    return np.concatenate(pieces), forward, backward, excursion


def _joint_motion(
    robot: Robot, joint: int, pose: Array, qd_j: Array, start: float, dt: float, acc: float
) -> Motion:
    """All joints at ``pose`` but ``joint``, which starts at ``start`` and moves at ``qd_j``
    (positions by the trapezoidal rule, so they are exact for the piecewise-linear speed)."""
    q_j = start + np.concatenate([[0.0], np.cumsum(0.5 * dt * (qd_j[1:] + qd_j[:-1]))])
    big_n = qd_j.size
    t = np.asarray(dt * np.arange(big_n), dtype=np.float64)
    q = np.tile(pose, (big_n, 1))
    qd = np.zeros((big_n, robot.n))
    qdd = np.zeros((big_n, robot.n))
    q[:, joint], qd[:, joint] = q_j, qd_j
    qdd[:, joint] = np.gradient(qd_j, dt)
    qdd[np.abs(qdd) < 1e-9 * acc] = 0.0
    return Motion(t, q, qd, qdd)


def back_and_forth_motion(
    robot: Robot,
    joint: int,
    speeds: ArrayLike | None = None,
    *,
    travel: float = 0.5,
    max_time: float = 2.0,
    acceleration: float = 2.0,
    dwell: float = 0.2,
    dt: float = CONTROLLER_DT,
    pose: ArrayLike | None = None,
) -> FrictionRun:
    """The doc's friction experiment (section 4.1, Figure 6) for one joint.

    For each speed ``v``: from rest, ramp to ``+v`` at ``acceleration``, hold it over ``travel``
    rad (or ``max_time`` s, whichever is shorter), ramp down, wait ``dwell`` s; then the same
    backwards to the start, and wait again. All joints but ``joint`` hold ``pose`` (default:
    :func:`vertical_axis_pose`, so gravity exerts no torque on ``joint``). Phase boundaries fall
    on samples, and speeds are integrated exactly, so each level's backward constant-speed part
    passes the forward part's positions in reverse.

    Parameters
    ----------
    robot : Robot
    joint : int
        0-based.
    speeds : array_like, shape (L,), optional
        rad/s, each in (0, speed limit]; default :func:`default_speeds`.
    travel, max_time, acceleration, dwell, dt : float
        rad, s, rad/s^2, s, s.
    pose : array_like, shape (n,), optional
        rad.

    Returns
    -------
    FrictionRun

    Raises
    ------
    KinergyError
        A bad joint index or speed; a travel that does not fit the joint's range.
    """
    timing = {"max_time": max_time, "acceleration": acceleration, "dwell": dwell, "dt": dt}
    _check_options(robot, joint, travel=travel, **timing)
    v_all = _speed_levels(robot, joint, speeds)
    pose_arr, tilt = _run_pose(robot, joint, pose)
    qd_j, forward, backward, excursion = _speed_profile(v_all, travel=travel, **timing)
    lo, hi = robot.joints[joint].limits.position
    if excursion > hi - lo:
        raise KinergyError(
            f"joint {joint + 1} ({robot.joints[joint].name}): the runs travel {excursion:.3g} rad "
            f"but its range is {hi - lo:.3g} rad; reduce travel or max_time"
        )
    start = float(np.clip(pose_arr[joint] - excursion / 2.0, lo, hi - excursion))
    pose_out = pose_arr.copy()
    pose_out[joint] = start + excursion / 2.0
    return FrictionRun(
        motion=_joint_motion(robot, joint, pose_arr, qd_j, start, dt, acceleration),
        joint=joint,
        speeds=v_all.copy(),
        forward=np.array(forward, dtype=np.int_),
        backward=np.array(backward, dtype=np.int_),
        pose=pose_out,
        tilt=tilt,
    )
