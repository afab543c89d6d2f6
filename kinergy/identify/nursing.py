"""The coupled-drive nursing arm's identification (nursing doc sections 3-4).

Two experiments, each with its own processing:

1. **Friction** (section 4.1, eqs 17-21). One joint moves back and forth at constant speed, at a
   ladder of speeds, the others still, in a pose where gravity on it does not change (its axis
   vertical). At constant speed the joint needs no inertial torque, so the torque from the motor
   currents (eq 21, ``T = n eta K_m I``) is friction plus what does not depend on the direction of
   motion (gravity, modelling error). Friction is odd in the speed and the rest even (eq 19), so
   ``tau_f(v) = (T(v) - T(-v)) / 2`` and the modelling error ``tau_n = (T(v) + T(-v)) / 2``
   (eq 20). Makkar's friction model (eq 13) is fitted to ``tau_f`` by particle swarm optimisation
   with a constriction factor (the doc's method; :mod:`kinergy.identify.pso`) or by deterministic
   least squares, with R^2 as the doc reports it (0.931 rotation, 0.927 pitch).
2. **Inertial parameters** (section 4.2, eqs 22-26). A periodic Fourier excitation (eq 22; the
   doc's Table 6) runs for several periods; the currents are low-pass filtered (Butterworth,
   15 Hz; the doc's "4 dB ripple" cannot apply to a Butterworth filter, which has none) and every
   signal is averaged over the periods (eq 24); the joint torques from the currents, less
   friction and the coupled joints' internal inertia (eq 25), are regressed on the minimal (base)
   parameter set (eq 16; 36 parameters for the nursing arm, as the doc's Table 3) by ridge
   regression on standardised columns, trained on the first 70 % and tested on the last 30 %
   (per-joint RMSE, eq 26, Table 8).

Coupling conventions
--------------------
kinergy's robot files write a coupled joint as motor inputs ``phi = C @ q`` with, for the nursing
arm's (pitch, rotation) pairs, ``C = [[1, 1], [1, -1]]`` (nursing eq 3 with q1 = rotation and
q2 = pitch). Power balance ``tau . qd = T . phi'`` gives the joint torques from the input-gear
torques ``T`` (n times the motor torques) as ``tau = C^T T``::

    tau_pitch = T1 + T2,        tau_rotation = T1 - T2                    (kinergy, eq 9)

The doc's eqs 17-18 print the other pairing (pitch ``T1 - T2``, rotation ``T1 + T2``); that is
eq 9 with motor 2's current counted with the opposite sign (a mirrored mounting).
:func:`coupled_torques` takes ``mirrored=True`` for the doc's pairing; everything else here goes
through the robot's own coupling matrix (:func:`joint_torques_from_current`), so the sign
follows the robot file.

Joint side and motor side
-------------------------
A robot file's friction is per motor (motor side). Moving joint ``j`` alone at speed ``v`` turns
each of its ``k`` motors at ``|N_mj| v`` (``N = diag(n) C``); if they have the same friction
``f`` and the same ``|N_mj| = n``, the joint-side friction is ``k n f(n v)``. For Makkar's model
that is Makkar's model again, with ``gamma1, gamma4`` times ``k n``, ``gamma2, gamma3, gamma5``
times ``n`` and ``gamma6`` times ``k n^2`` (:func:`makkar_joint_side`, :func:`makkar_motor_side`).
On the nursing arm k = 2 and n = 3060; pitch and rotation of one pair then have the same curve,
since both turn both motors at ``n |v|`` (the twin cannot tell them apart; the real joint could,
through the differential's own friction).
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.optimize
from numpy.typing import ArrayLike, NDArray

from kinergy.drives.electrics import friction_torques, torque_constants
from kinergy.drives.transmission import reflected_inertia, transmission_matrix
from kinergy.dynamics.chain import make_chain
from kinergy.dynamics.kinematics import joint_axes
from kinergy.dynamics.regressor import BaseParameters, base_parameters, inertial_parameters
from kinergy.dynamics.regressor import regressor as full_regressor
from kinergy.errors import KinergyError
from kinergy.friction.registry import get_model
from kinergy.identify.metrics import r_squared, rmse
from kinergy.identify.preprocess import IdentData, lowpass
from kinergy.identify.pso import particle_swarm
from kinergy.identify.result import (
    DriveEstimate,
    Fit,
    IdentificationResult,
    friction_entry,
    validation_metrics,
)
from kinergy.jsonable import OPTIONAL
from kinergy.model.robot import Friction, Link, Robot, Source
from kinergy.trajectory.fourier import fourier_motion
from kinergy.trajectory.motion import Motion

__all__ = [
    "BASE_FREQUENCY",
    "DOC_EQ21",
    "DOC_FRICTION_R2",
    "DOC_TABLE4",
    "DOC_TABLE6",
    "DOC_TABLE8",
    "FILTER_CUTOFF",
    "FrictionPoints",
    "FrictionRun",
    "MakkarFit",
    "RidgeFit",
    "back_and_forth_motion",
    "constant_speed_runs",
    "coupled_torques",
    "cycle_average",
    "default_speeds",
    "find_period",
    "fit_makkar_lsq",
    "fit_makkar_pso",
    "friction_points",
    "identify_nursing",
    "joint_friction",
    "joint_kind",
    "joint_side_makkar",
    "joint_torques_from_current",
    "makkar",
    "makkar_joint_side",
    "makkar_motor_side",
    "odd_even_friction",
    "ridge_minimal",
    "table6_motion",
    "torque_from_current",
    "vertical_axis_pose",
]

Array = NDArray[np.float64]

#: Eq 21's constants for the doc's robot: total reduction n, efficiency eta, K_m (N m/A)
DOC_EQ21 = {"n": 3060.0, "eta": 0.82, "km": 0.0293}
#: Table 4, joint side (N m, rad/s): gamma1..gamma6 of the rotation and the pitch motion
DOC_TABLE4 = {
    "rotation": (32.36, 9.94, 5.25, 30.54, 10.77, 2.68),
    "pitch": (39.1, 8.65, 6.54, 10.04, 19.71, 3.05),
}
#: R^2 of the doc's friction fits (section 4.1, conclusion 2)
DOC_FRICTION_R2 = {"rotation": 0.931, "pitch": 0.927}
#: Table 8: RMSE between measured and predicted joint torques, N m (printed "N m^2"), joints 1-6
DOC_TABLE8 = (14.372, 11.982, 6.934, 5.557, 3.932, 3.152)
#: Table 6: excitation coefficients a_l, b_l (rows joints 1-6, columns l = 1..3, rad/s) and q0 (rad)
DOC_TABLE6 = {
    "a": (
        (0.204, -0.004, -0.201),
        (0.163, -0.106, -0.056),
        (-0.106, 0.038, 0.067),
        (0.058, -0.007, -0.050),
        (-0.071, 0.051, 0.019),
        (0.031, -0.021, 0.019),
    ),
    "b": (
        (0.139, -0.440, 0.247),
        (0.208, 0.074, -0.119),
        (-0.255, -0.055, 0.122),
        (0.038, -0.225, 0.137),
        (-0.325, 0.017, 0.097),
        (-0.086, -0.196, 0.159),
    ),
    "q0": (0.002, 0.328, -0.386, -0.045, -0.453, -0.208),
}
#: eq 22's base frequency, rad/s (a 10 s period)
BASE_FREQUENCY = 0.2 * np.pi
#: the doc's low-pass cutoff for the motor currents, Hz
FILTER_CUTOFF = 15.0

_MAKKAR = get_model("makkar").parameters  # ("gamma1", ..., "gamma6")
_RATES = (1, 2, 4)  # gamma2, gamma3, gamma5: the parameters the model is not linear in
_GAINS = (0, 3, 5)  # gamma1, gamma4, gamma6


# ---------------------------------------------------------------------------------------------
# Torques from currents (eq 21) and the coupling


def torque_from_current(
    current: ArrayLike, *, n: ArrayLike, eta: ArrayLike, km: ArrayLike
) -> Array:
    """Nursing eq 21: torque at the input bevel gear, ``T = n eta K_m I`` (N m).

    Parameters
    ----------
    current : array_like, shape (...,) or (N, m)
        Motor currents, A.
    n, eta, km : array_like, broadcastable to ``current``
        Total reduction from motor to input gear, transmission efficiency (0-1], motor torque
        constant (N m/A). The doc's robot: n = 3060, eta = 0.82, K_m = 0.0293 (:data:`DOC_EQ21`).

    Examples
    --------
    >>> round(float(torque_from_current(1.0, **DOC_EQ21)), 3)
    73.52
    """
    return np.asarray(
        np.asarray(n, dtype=float)
        * np.asarray(eta, dtype=float)
        * np.asarray(km, dtype=float)
        * np.asarray(current, dtype=float),
        dtype=float,
    )


def coupled_torques(t1: ArrayLike, t2: ArrayLike, *, mirrored: bool = False) -> tuple[Array, Array]:
    """Pitch and rotation torques of one coupled joint from its two input-gear torques.

    kinergy's convention (``phi = [[1, 1], [1, -1]] @ [q_pitch, q_rot]``, power balance, eq 9):
    ``tau_pitch = T1 + T2``, ``tau_rot = T1 - T2``. ``mirrored=True`` counts motor 2's torque
    with the opposite sign, which gives the doc's eqs 17-18 as printed: ``tau_pitch = T1 - T2``,
    ``tau_rot = T1 + T2``.

    Returns
    -------
    tau_pitch, tau_rot : ndarray
        N m, shape of the broadcast inputs.
    """
    a = np.asarray(t1, dtype=float)
    b = np.asarray(t2, dtype=float)
    if mirrored:
        b = -b
    return a + b, a - b


def joint_torques_from_current(robot: Robot, current: ArrayLike, *, eta: float = 1.0) -> Array:
    """Joint torques from motor currents through eq 21 and the robot's coupling (N m).

    ``tau = C^T T`` with ``T = n eta K_m I`` per motor (``n`` = ``gear_ratio``, ``K_m`` =
    ``torque_constant``), i.e. ``eta`` times :func:`kinergy.drives.transmission.joint_torque` of
    ``k_t I``. A coupled pair gives ``tau_pitch = T1 + T2``, ``tau_rot = T1 - T2`` (module
    docstring). The twin has no efficiency (its losses are in its friction): ``eta = 1`` there.

    Parameters
    ----------
    current : array_like, shape (N, n) or (n,)
        Motor currents, A.

    Returns
    -------
    ndarray, shape like ``current``
    """
    i = np.asarray(current, dtype=float)
    ratios = np.array([j.drive.gear_ratio for j in robot.joints])
    t_in = torque_from_current(i, n=ratios, eta=eta, km=torque_constants(robot))
    assert robot.coupling is not None
    return np.asarray(t_in @ robot.coupling, dtype=float)


def joint_friction(robot: Robot, qd: ArrayLike, qdd: ArrayLike | None = None) -> Array:
    """Joint-side friction of the motors' models, ``N^T f(N qd)`` (N m), shape (N, n).

    Exact for any motion of coupled joints (where the doc's eq 25 subtracts a per-joint curve,
    exact only when one joint of a pair moves). Load-dependent models (``power_flow``) are
    evaluated with zero load.
    """
    v = np.atleast_2d(np.asarray(qd, dtype=float))
    n_mat = transmission_matrix(robot)
    wm = v @ n_mat.T
    dwm = None if qdd is None else np.atleast_2d(np.asarray(qdd, dtype=float)) @ n_mat.T
    return np.asarray(friction_torques(robot, wm, np.zeros_like(wm), dwm) @ n_mat, dtype=float)


def joint_kind(robot: Robot, joint: int) -> str:
    """``"pitch"`` (its motors turn the same way), ``"rotation"`` (opposite ways) or
    ``"single"`` (one motor)."""
    assert robot.coupling is not None
    col = robot.coupling[:, joint]
    nz = col[np.abs(col) > 0]
    if nz.size <= 1:
        return "single"
    return "pitch" if np.all(np.sign(nz) == np.sign(nz[0])) else "rotation"


def _motor_share(robot: Robot, joint: int) -> tuple[float, int, NDArray[np.int_]]:
    """``(n, k, motors)``: the common ``|N_mj|`` of joint ``joint``'s ``k`` motors."""
    col = transmission_matrix(robot)[:, joint]
    motors = np.flatnonzero(np.abs(col) > 0)
    ratios = np.abs(col[motors])
    if motors.size == 0 or not np.allclose(ratios, ratios[0], rtol=1e-9):
        raise KinergyError(
            f"joint {joint + 1} ({robot.joints[joint].name}): its motors turn at different "
            "ratios; a joint-side friction curve cannot be split between them"
        )
    return float(ratios[0]), int(motors.size), motors


def makkar_joint_side(gamma_motor: ArrayLike, ratio: float, motors: int) -> Array:
    """Joint-side Makkar parameters of ``motors`` equal motors turning at ``ratio`` times the
    joint speed (module docstring): ``gamma1, gamma4 * k n``, rates ``* n``, ``gamma6 * k n^2``."""
    g = np.asarray(gamma_motor, dtype=float).copy()
    g[[0, 3]] *= motors * ratio
    g[list(_RATES)] *= ratio
    g[5] *= motors * ratio**2
    return g


def makkar_motor_side(gamma_joint: ArrayLike, ratio: float, motors: int) -> Array:
    """Inverse of :func:`makkar_joint_side`."""
    g = np.asarray(gamma_joint, dtype=float).copy()
    g[[0, 3]] /= motors * ratio
    g[list(_RATES)] /= ratio
    g[5] /= motors * ratio**2
    return g


def joint_side_makkar(robot: Robot, joint: int) -> Array | None:
    """The robot's own Makkar curve of ``joint`` on the joint side (:func:`makkar_joint_side`),
    shape (6,); None unless its motors all have the same Makkar friction at the same ratio."""
    try:
        ratio, k, motors = _motor_share(robot, joint)
    except KinergyError:
        return None
    frictions = [robot.joints[m].drive.friction for m in motors]
    if any(f.model != "makkar" for f in frictions):
        return None
    g = np.array([frictions[0].params[name] for name in _MAKKAR])
    if any(not np.allclose([f.params[name] for name in _MAKKAR], g) for f in frictions[1:]):
        return None
    return makkar_joint_side(g, ratio, k)


# ---------------------------------------------------------------------------------------------
# The constant-speed back-and-forth experiment (section 4.1)


def vertical_axis_pose(
    robot: Robot, joint: int, q: ArrayLike | None = None, *, seed: int = 0
) -> tuple[Array, float]:
    """A pose in which joint ``joint``'s axis is parallel to gravity, so gravity exerts no torque
    about it however it turns (the doc's pose for the friction runs, Figure 6).

    When ``q`` (default zeros) does not already have it, the joints before ``joint`` are chosen
    by least squares on ``z_j x g / |g|`` within their limits, from ``q`` and 8 seeded starts;
    of the vertical poses found, the one farthest from the joint limits. ``joint`` and the joints
    after it keep ``q``'s values. Some axes can never be vertical (the nursing arm's joint 2 is
    always horizontal): the tilt says so, and :func:`friction_points` still cancels gravity by
    pairing equal positions.

    Returns
    -------
    q : ndarray, shape (n,)
        rad.
    tilt : float
        Angle left between the axis and gravity, rad (0 when reached).
    """
    n = robot.n
    q_start = np.zeros(n) if q is None else np.asarray(q, dtype=float).copy()
    g = np.asarray(robot.gravity, dtype=float)
    g_norm = float(np.linalg.norm(g))
    if g_norm == 0.0:
        return q_start, 0.0
    g_hat = g / g_norm  # the axes are in the frame gravity is given in (robot.base applied)
    chain = make_chain(robot)
    lo = np.array([max(jt.limits.position[0], -np.pi) for jt in robot.joints])
    hi = np.array([min(jt.limits.position[1], np.pi) for jt in robot.joints])

    def tilt_of(x: Array) -> Array:
        z, _, _ = joint_axes(chain, x[None, :])
        return np.cross(z[0, joint], g_hat)

    best = q_start
    best_norm = float(np.linalg.norm(tilt_of(q_start)))
    if joint > 0 and best_norm > 1e-12:
        rng = np.random.default_rng(seed)
        starts = [np.clip(q_start[:joint], lo[:joint], hi[:joint])]
        starts += [rng.uniform(lo[:joint], hi[:joint]) for _ in range(8)]
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


def back_and_forth_motion(
    robot: Robot,
    joint: int,
    speeds: ArrayLike | None = None,
    *,
    travel: float = 0.5,
    max_time: float = 2.0,
    acceleration: float = 2.0,
    dwell: float = 0.2,
    dt: float = 0.002,
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
    n = robot.n
    if not 0 <= joint < n:
        raise KinergyError(f"joint index {joint} out of range for {robot.name} ({n} joints)")
    for name, value in (
        ("travel", travel),
        ("max_time", max_time),
        ("acceleration", acceleration),
        ("dt", dt),
    ):
        if not (np.isfinite(value) and value > 0):
            raise KinergyError(f"{name} must be > 0, got {value}")
    if not (np.isfinite(dwell) and dwell >= 0):
        raise KinergyError(f"dwell must be >= 0, got {dwell}")
    v_all = default_speeds(robot, joint) if speeds is None else np.asarray(speeds, dtype=float)
    limit = robot.joints[joint].limits.speed
    if v_all.ndim != 1 or v_all.size == 0 or not np.all((v_all > 0) & np.isfinite(v_all)):
        raise KinergyError("speeds must be a non-empty list of positive numbers (rad/s)")
    if np.any(v_all > limit * (1.0 + 1e-9)):
        raise KinergyError(
            f"joint {joint + 1} ({robot.joints[joint].name}): speed {v_all.max():g} rad/s "
            f"exceeds its limit {limit:g} rad/s"
        )
    tilt = 0.0
    if pose is None:
        pose_arr, tilt = vertical_axis_pose(robot, joint)
    else:
        pose_arr = np.asarray(pose, dtype=float)
        if pose_arr.shape != (n,):
            raise KinergyError(f"pose must have {n} angles, got shape {pose_arr.shape}")
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
    qd_j = np.concatenate(pieces)
    lo, hi = robot.joints[joint].limits.position
    if excursion > hi - lo:
        raise KinergyError(
            f"joint {joint + 1} ({robot.joints[joint].name}): the runs travel {excursion:.3g} rad "
            f"but its range is {hi - lo:.3g} rad; reduce travel or max_time"
        )
    start = float(np.clip(pose_arr[joint] - excursion / 2.0, lo, hi - excursion))
    q_j = start + np.concatenate([[0.0], np.cumsum(0.5 * dt * (qd_j[1:] + qd_j[:-1]))])
    big_n = qd_j.size
    t = np.asarray(dt * np.arange(big_n), dtype=np.float64)
    q = np.tile(pose_arr, (big_n, 1))
    qd = np.zeros((big_n, n))
    qdd = np.zeros((big_n, n))
    q[:, joint], qd[:, joint] = q_j, qd_j
    qdd[:, joint] = np.gradient(qd_j, dt)
    qdd[np.abs(qdd) < 1e-9 * acceleration] = 0.0
    pose_out = pose_arr.copy()
    pose_out[joint] = start + excursion / 2.0
    return FrictionRun(
        motion=Motion(t, q, qd, qdd),
        joint=joint,
        speeds=v_all.copy(),
        forward=np.array(forward, dtype=np.int_),
        backward=np.array(backward, dtype=np.int_),
        pose=pose_out,
        tilt=tilt,
    )


def odd_even_friction(
    speed_levels: ArrayLike, torque_forward: ArrayLike, torque_backward: ArrayLike
) -> tuple[Array, Array]:
    """Eqs 19-20: friction as the odd part, modelling error as the even part.

    ``tau_f(v) = (T(v) - T(-v)) / 2`` and ``tau_n(v) = (T(v) + T(-v)) / 2``, where ``T(v)`` is the
    torque moving at ``+v`` and ``T(-v)`` at ``-v`` (same positions). Works per level (means) or
    per sample.

    Parameters
    ----------
    speed_levels : array_like, shape (L,)
        ``v`` > 0, rad/s (checked; the results are ``tau_f(v)``, ``tau_n(v)`` at these speeds).
    torque_forward, torque_backward : array_like, shape (L,) or (L, ...)
        ``T(v)`` and ``T(-v)``, N m.

    Returns
    -------
    friction, error : ndarray, shape like the torques
        ``tau_f(v)`` and ``tau_n(v)``, N m.
    """
    v = np.asarray(speed_levels, dtype=float)
    fwd = np.asarray(torque_forward, dtype=float)
    bwd = np.asarray(torque_backward, dtype=float)
    if fwd.shape != bwd.shape or fwd.shape[:1] != v.shape[:1] or v.ndim != 1:
        raise KinergyError(
            f"odd/even split: speeds {v.shape} and torques {fwd.shape}, {bwd.shape} do not match"
        )
    if not np.all(v > 0):
        raise KinergyError("odd/even split: speed levels must be > 0 (T(v) moves at +v)")
    return 0.5 * (fwd - bwd), 0.5 * (fwd + bwd)


@dataclass(frozen=True, eq=False)
class FrictionPoints:
    """Friction of one joint from back-and-forth runs (joint side).

    Attributes
    ----------
    joint : int
    speeds, friction, error : ndarray, shape (L,)
        Speed levels (rad/s), the odd part (friction) and the even part (modelling error and
        gravity) of the level means, N m.
    sample_speeds, sample_friction : ndarray, shape (M,)
        The odd part per forward sample (paired with the backward sample at the same position):
        the scatter the doc's Figure 8 plots.
    """

    joint: int
    speeds: Array
    friction: Array
    error: Array
    sample_speeds: Array
    sample_friction: Array


def friction_points(
    position: ArrayLike,
    torque: ArrayLike,
    speeds: ArrayLike,
    forward: ArrayLike,
    backward: ArrayLike,
    *,
    joint: int = 0,
    trim: int = 10,
) -> FrictionPoints:
    """Odd and even parts of one joint's torque over its constant-speed runs (eqs 19-20).

    Each forward sample is paired with the backward run's torque at the same position (linear
    interpolation), so position-dependent torques (gravity) cancel in the odd part even when the
    axis is not vertical.

    Parameters
    ----------
    position, torque : array_like, shape (N,)
        The joint's angle (rad; the real motion) and torque (N m).
    speeds : array_like, shape (L,)
        rad/s.
    forward, backward : array_like of int, shape (L, 2)
        ``[start, stop)`` of each level's runs at ``+v`` and ``-v``.
    trim : int
        Samples dropped at both ends of each run (the real motion's lag, filter transients).
    """
    q = np.asarray(position, dtype=float)
    tau = np.asarray(torque, dtype=float)
    v = np.asarray(speeds, dtype=float)
    fwd_idx = np.asarray(forward, dtype=int)
    bwd_idx = np.asarray(backward, dtype=int)
    levels, s_v, s_f, mean_f, mean_b = [], [], [], [], []
    for k, speed in enumerate(v):
        f0, f1 = fwd_idx[k, 0] + trim, fwd_idx[k, 1] - trim
        b0, b1 = bwd_idx[k, 0] + trim, bwd_idx[k, 1] - trim
        if f1 - f0 < 2 or b1 - b0 < 2:
            continue
        qf, tf = q[f0:f1], tau[f0:f1]
        qb, tb = q[b0:b1][::-1], tau[b0:b1][::-1]  # increasing positions
        inside = (qf >= qb[0]) & (qf <= qb[-1])
        if inside.sum() < 2:
            continue
        tb_at = np.interp(qf[inside], qb, tb)
        odd, _ = odd_even_friction(np.full(inside.sum(), speed), tf[inside], tb_at)
        levels.append(speed)
        mean_f.append(float(np.mean(tf[inside])))
        mean_b.append(float(np.mean(tb_at)))
        s_v.append(np.full(odd.size, speed))
        s_f.append(odd)
    if not levels:
        raise KinergyError(
            f"joint {joint + 1}: no forward and backward constant-speed runs over the same positions"
        )
    lv = np.array(levels)
    fric, err = odd_even_friction(lv, np.array(mean_f), np.array(mean_b))
    return FrictionPoints(joint, lv, fric, err, np.concatenate(s_v), np.concatenate(s_f))


def constant_speed_runs(
    qd: ArrayLike,
    qdd: ArrayLike,
    *,
    min_speed: float = 1e-3,
    acc_tol: float = 0.05,
    min_samples: int = 20,
    rtol: float = 0.01,
) -> tuple[Array, NDArray[np.int_], NDArray[np.int_]]:
    """Find the back-and-forth runs in one joint's commanded speed (for logs without run indices).

    A run is a maximal stretch where ``|qd| > min_speed`` with one sign and ``|qdd| < acc_tol``
    (rad/s^2), at least ``min_samples`` long. Each run at ``+v`` is paired with the next run at
    ``-v`` whose speed is within ``rtol``.

    Returns
    -------
    speeds : ndarray, shape (L,)
    forward, backward : ndarray of int, shape (L, 2)
        As :class:`FrictionRun`'s.
    """
    v = np.asarray(qd, dtype=float)
    a = np.asarray(qdd, dtype=float)
    steady = (np.abs(v) > min_speed) & (np.abs(a) < acc_tol)
    sign = np.where(steady, np.sign(v), 0).astype(int)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], sign, [0]])))
    runs: list[tuple[int, int, float]] = []
    for a0, a1 in itertools.pairwise(edges):
        if sign[a0] != 0 and a1 - a0 >= min_samples and np.all(sign[a0:a1] == sign[a0]):
            runs.append((int(a0), int(a1), float(np.median(v[a0:a1]))))
    speeds: list[float] = []
    forward: list[tuple[int, int]] = []
    backward: list[tuple[int, int]] = []
    used: set[int] = set()
    for i, (s, e, speed) in enumerate(runs):
        if speed <= 0:
            continue
        for j in range(i + 1, len(runs)):
            s2, e2, speed2 = runs[j]
            if j not in used and speed2 < 0 and abs(abs(speed2) - speed) <= rtol * speed:
                used.add(j)
                speeds.append(speed)
                forward.append((s, e))
                backward.append((s2, e2))
                break
    return (
        np.array(speeds),
        np.array(forward, dtype=np.int_).reshape(-1, 2),
        np.array(backward, dtype=np.int_).reshape(-1, 2),
    )


# ---------------------------------------------------------------------------------------------
# Makkar's friction model (eq 13) and its fits


def makkar(gamma: ArrayLike, speed: ArrayLike) -> Array:
    """Eq 13: ``g1 (tanh(g2 v) - tanh(g3 v)) + g4 tanh(g5 v) + g6 v``.

    Parameters
    ----------
    gamma : array_like, shape (6,) or (P, 6)
    speed : array_like, shape (M,)

    Returns
    -------
    ndarray, shape (M,) or (P, M)
    """
    g = np.asarray(gamma, dtype=float)
    v = np.asarray(speed, dtype=float)
    gg = np.atleast_2d(g)[:, :, None]
    out = (
        gg[:, 0] * (np.tanh(gg[:, 1] * v) - np.tanh(gg[:, 2] * v))
        + gg[:, 3] * np.tanh(gg[:, 4] * v)
        + gg[:, 5] * v
    )
    return out[0] if g.ndim == 1 else out


def _canonical(gamma: Array) -> Array:
    """Swap ``gamma2 <-> gamma3`` (negating ``gamma1``) so that ``gamma2 >= gamma3``: the two give
    the same curve; the canonical form has the Stribeck hump as a positive ``gamma1``."""
    g = np.asarray(gamma, dtype=float).copy()
    if g[1] < g[2]:
        g[1], g[2] = g[2], g[1]
        g[0] = -g[0]
    return g


@dataclass(frozen=True, eq=False)
class MakkarFit:
    """A fitted Makkar curve (eq 13) on the joint side.

    Attributes
    ----------
    gamma : ndarray, shape (6,)
        ``gamma1..gamma6`` (N m, s/rad, s/rad, N m, s/rad, N m s/rad), ``gamma2 >= gamma3``.
    r2, rmse : float
        Of the fitted curve against the points it was fitted to.
    method : str
        ``"pso"`` or ``"lsq"``.
    history : ndarray
        PSO: best mean squared error per iteration (the doc's Figure 7); LSQ: empty.
    """

    gamma: Array
    r2: float
    rmse: float
    method: str
    history: Array

    @property
    def params(self) -> dict[str, float]:
        """``{"gamma1": ..., "gamma6": ...}``."""
        return {name: float(x) for name, x in zip(_MAKKAR, self.gamma, strict=True)}


def _check_points(speeds: ArrayLike, friction: ArrayLike) -> tuple[Array, Array]:
    v = np.asarray(speeds, dtype=float).reshape(-1)
    f = np.asarray(friction, dtype=float).reshape(-1)
    if v.shape != f.shape or v.size < 6:
        raise KinergyError(
            f"Makkar fit: need at least 6 (speed, friction) points of equal count, got {v.size} and {f.size}"
        )
    if not (np.all(np.isfinite(v)) and np.all(np.isfinite(f))) or np.max(np.abs(v)) == 0:
        raise KinergyError("Makkar fit: speeds and friction must be finite, speeds not all zero")
    return v, f


def _rate_bounds(v: Array) -> tuple[float, float]:
    """Rates that bend the curve inside the data: ``tanh(gamma v)`` from 0.1 at the fastest point to
    10 at the slowest."""
    a = np.abs(v[v != 0])
    return 0.1 / float(a.max()), 10.0 / float(a.min())


def _gains(rates: Array, v: Array, f: Array, positive: bool = True) -> tuple[Array, Array]:
    """Variable projection: the best ``gamma1, gamma4, gamma6`` for each row of ``rates`` (P, 3) =
    ``(gamma2, gamma3, gamma5)`` by linear least squares (non-negative with ``positive``), and the
    mean squared error (P,)."""
    cols = np.stack(
        [
            np.tanh(rates[:, 0:1] * v) - np.tanh(rates[:, 1:2] * v),
            np.tanh(rates[:, 2:3] * v),
            np.broadcast_to(v, (rates.shape[0], v.size)),
        ],
        axis=2,
    )  # (P, M, 3)
    scale = np.sqrt(np.einsum("pmk,pmk->pk", cols, cols)) + 1e-300
    cs = cols / scale[:, None, :]
    if positive:
        xs = np.array([scipy.optimize.nnls(c, f)[0] for c in cs])
    else:
        ata = np.einsum("pmk,pml->pkl", cs, cs) + 1e-12 * np.eye(3)
        xs = np.linalg.solve(ata, np.einsum("pmk,m->pk", cs, f)[..., None])[..., 0]
    x = xs / scale
    mse = np.mean((np.einsum("pmk,pk->pm", cols, x) - f) ** 2, axis=1)
    return x, mse


def _assemble(gains: Array, rates: Array) -> Array:
    g = np.empty((rates.shape[0], 6))
    g[:, list(_GAINS)] = gains
    g[:, list(_RATES)] = rates
    return g


def _fit_result(gamma: Array, v: Array, f: Array, method: str, history: Array) -> MakkarFit:
    g = _canonical(gamma)
    pred = makkar(g, v)
    return MakkarFit(
        gamma=g,
        r2=float(r_squared(f[:, None], pred[:, None])[0]),
        rmse=float(rmse(f[:, None], pred[:, None])[0]),
        method=method,
        history=history,
    )


def _polish(gamma: Array, v: Array, f: Array, max_nfev: int = 2000, positive: bool = True) -> Array:
    """Local least squares on all six parameters from ``gamma``; the better of start and result.

    Unknowns ``[g1, log(g2/g3), log g3, g4, log g5, g6]`` with the exact Jacobian: Levenberg-
    Marquardt, or with ``positive`` a trust-region solve with ``g1, g4, g6 >= 0`` and
    ``g2 >= g3`` (Makkar's parameters are all positive; his model's hump then rises, not dips)
    and ``g1 <= 10 max|f|``: with ``g2 -> g3`` and ``g1 -> inf`` the hump tends to a finite shape
    (``g1 (g2 - g3) v / cosh^2(g3 v)``) that noisy data may prefer, and the bound keeps ``g1``
    from running off along it.
    """
    g0 = _canonical(gamma)
    g0[list(_RATES)] = np.maximum(np.abs(g0[list(_RATES)]), 1e-9)
    if positive:
        g0[list(_GAINS)] = np.maximum(g0[list(_GAINS)], 0.0)
    p0 = np.array(
        [g0[0], np.log(g0[1] / g0[2]), np.log(g0[2]), g0[3], np.log(g0[4]), g0[5]], dtype=float
    )

    def decode(p: Array) -> Array:
        l3 = np.clip(p[2], -50.0, 50.0)
        return np.array(
            [
                p[0],
                np.exp(np.clip(l3 + p[1], -50.0, 50.0)),
                np.exp(l3),
                p[3],
                np.exp(np.clip(p[4], -50.0, 50.0)),
                p[5],
            ]
        )

    def jac(p: Array) -> Array:
        g = decode(p)
        t2, t3, t5 = np.tanh(g[1] * v), np.tanh(g[2] * v), np.tanh(g[4] * v)
        d2 = g[0] * (1.0 - t2**2) * g[1] * v  # d f / d log g2
        d3 = -g[0] * (1.0 - t3**2) * g[2] * v  # d f / d log g3
        return np.column_stack([t2 - t3, d2, d2 + d3, t5, g[3] * (1.0 - t5**2) * g[4] * v, v])

    def resid(p: Array) -> Array:
        return np.asarray(makkar(decode(p), v) - f)

    tol = {"xtol": 1e-15, "ftol": 1e-15, "gtol": 1e-15, "max_nfev": max_nfev}
    if positive:
        lower = np.array([0.0, 0.0, -np.inf, 0.0, -np.inf, 0.0])
        upper = np.full(6, np.inf)
        upper[0] = 10.0 * max(float(np.max(np.abs(f))), 1e-300)
        g0[0] = min(g0[0], upper[0])
        p0[0] = g0[0]
        p0 = np.clip(p0, lower + 1e-12 * np.maximum(np.abs(p0), 1.0), upper * (1.0 - 1e-12))
        sol = scipy.optimize.least_squares(
            resid, p0, jac=jac, bounds=(lower, upper), method="trf", x_scale="jac", **tol
        )
    else:
        sol = scipy.optimize.least_squares(resid, p0, jac=jac, method="lm", x_scale="jac", **tol)
    g = decode(sol.x)
    better = np.sum((makkar(g, v) - f) ** 2) <= np.sum((makkar(g0, v) - f) ** 2)
    return g if better else g0


def _refine(starts: list[Array], v: Array, f: Array, positive: bool) -> Array:
    """Polish every start (:func:`_polish`); then, since two ``tanh`` steps of similar rate can
    trade places at a cost of ~1e-6 of the curve's variance (a near-symmetry of Makkar's model
    with its own local minima), polish the three best again from their rates permuted; return
    the best of all, polished to convergence."""

    def sse(g: Array) -> float:
        return float(np.sum((makkar(g, v) - f) ** 2))

    found = [_polish(g, v, f, 200, positive) for g in starts]
    found.sort(key=sse)
    for g in found[:3]:
        rates = np.abs(g[list(_RATES)])
        for perm in ((2, 1, 0), (0, 2, 1), (1, 2, 0)):
            r = rates[list(perm)][None, :]
            found.append(
                _polish(_assemble(_gains(r, v, f, positive)[0], r)[0], v, f, 200, positive)
            )
    return _polish(min(found, key=sse), v, f, 4000, positive)


def fit_makkar_pso(
    speeds: ArrayLike,
    friction: ArrayLike,
    *,
    particles: int = 30,
    iterations: int = 200,
    variable_projection: bool = True,
    positive: bool = True,
    polish: bool = False,
    rng: np.random.Generator | int | None = 0,
) -> MakkarFit:
    """Fit Makkar's model (eq 13) by particle swarm optimisation with a constriction factor.

    The objective is the mean squared difference between the measured and the modelled friction
    (section 4.1). The doc lets six-dimensional particles search all of ``gamma1..gamma6``
    (``variable_projection=False``: rates searched on a log scale in :func:`_rate_bounds`'s range,
    ``gamma3`` as a fraction of ``gamma2``, ``gamma1 in [0, 5 F]``, ``gamma4 in [0, 2 F]``,
    ``gamma6 in [0, 2 F / V]`` with ``F``, ``V`` the largest |friction| and |speed|). That swarm
    now and then settles where the Stribeck hump is switched off (R^2 0.978 on the twin's curve,
    for 1 seed in 20). By default the particles search only the three rates ``gamma2, gamma3,
    gamma5`` and each particle's ``gamma1, gamma4, gamma6`` follow by linear least squares,
    non-negative with ``positive`` (variable projection, G. Golub and V. Pereyra, SIAM J. Numer.
    Anal. 10(2), 1973; particles whose ``gamma1`` exceeds ``10 F`` count as infeasible, see
    :func:`_polish`), which finds the curve every time. ``polish=True`` ends with local
    least squares from the swarm's best (:func:`_refine`; as SciPy's ``differential_evolution``
    polishes): the swarm finds the curve, but Makkar's parameters lie along flat valleys, and
    only a polish pins them down.

    Parameters
    ----------
    speeds, friction : array_like, shape (M,)
        rad/s and N m (joint side), both signs allowed; at least 6 points.
    particles, iterations : int
        Swarm size and iterations (the doc: 200 iterations).
    positive : bool
        Keep every parameter >= 0 and ``gamma2 >= gamma3`` (Makkar's model as published; the
        doc's Table 4). The curve then extrapolates beyond the fastest point as
        ``gamma4 + gamma6 v``, never with a steep negative slope.
    rng : numpy.random.Generator or int, optional
        Seed of the swarm.

    Returns
    -------
    MakkarFit
        ``method = "pso"``; ``history`` is the swarm's best mean squared error per iteration.
    """
    v, f = _check_points(speeds, friction)
    r_lo, r_hi = np.log(_rate_bounds(v))
    big_f = float(np.max(np.abs(f))) or 1.0
    big_v = float(np.max(np.abs(v)))

    def rates_of(u: Array) -> Array:
        r = np.exp(r_lo + u * (r_hi - r_lo))
        if positive:  # the swarm searches gamma3 as a fraction of gamma2
            r[:, 1] = r[:, 0] * u[:, 1]
        return r

    if variable_projection:

        def objective(u: Array) -> Array:
            gains, mse = _gains(rates_of(u), v, f, positive)
            if positive:  # gamma1 <= 10 max|f|, as in _polish
                return np.where(gains[:, 0] <= 10.0 * big_f, mse, np.inf)
            return mse

        res = particle_swarm(
            objective, np.zeros(3), np.ones(3), particles=particles, iterations=iterations, rng=rng
        )
        rates = rates_of(res.x[None, :])
        gamma = _assemble(_gains(rates, v, f, positive)[0], rates)[0]
    else:
        low = 0.0 if positive else -1.0

        def decode(u: Array) -> Array:
            g = np.empty_like(u)
            g[:, 0] = 5.0 * big_f * u[:, 0]
            g[:, 1] = np.exp(r_lo + u[:, 1] * (r_hi - r_lo))
            g[:, 2] = g[:, 1] * u[:, 2]
            g[:, 3] = 2.0 * big_f * u[:, 3]
            g[:, 4] = np.exp(r_lo + u[:, 4] * (r_hi - r_lo))
            g[:, 5] = 2.0 * big_f / big_v * u[:, 5]
            return g

        def objective(u: Array) -> Array:
            return np.asarray(np.mean((makkar(decode(u), v) - f) ** 2, axis=1))

        lower = np.array([low, 0.0, 0.0, low, 0.0, low])
        res = particle_swarm(
            objective, lower, np.ones(6), particles=particles, iterations=iterations, rng=rng
        )
        gamma = decode(res.x[None, :])[0]
    if polish:
        gamma = _refine([gamma], v, f, positive)
    return _fit_result(gamma, v, f, "pso", res.history)


def fit_makkar_lsq(
    speeds: ArrayLike,
    friction: ArrayLike,
    *,
    positive: bool = True,
    grid: int = 16,
    starts: int = 8,
) -> MakkarFit:
    """Fit Makkar's model (eq 13) by deterministic least squares.

    The model is linear in ``gamma1, gamma4, gamma6`` for fixed rates ``gamma2, gamma3, gamma5``:
    those are solved in closed form (non-negative with ``positive``) over a ``grid``-point
    logarithmic grid of each rate (in :func:`_rate_bounds`'s range, ``gamma2 > gamma3``). The
    grid's local minima, best first (up to ``starts``), are polished on all six parameters, and
    again from their rates permuted (:func:`_refine`); the best is kept. No randomness.

    Parameters
    ----------
    speeds, friction : array_like, shape (M,)
        rad/s and N m, both signs allowed; at least 6 points.
    positive : bool
        As :func:`fit_makkar_pso`'s.

    Returns
    -------
    MakkarFit
        ``method = "lsq"``.
    """
    from scipy.ndimage import minimum_filter

    v, f = _check_points(speeds, friction)
    lo, hi = _rate_bounds(v)
    axis = np.geomspace(lo, hi, grid)
    combos = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    valid = np.flatnonzero(combos[:, 0] > combos[:, 1])
    gains = np.zeros((combos.shape[0], 3))
    mse = np.full(combos.shape[0], np.inf)
    gains[valid], mse[valid] = _gains(combos[valid], v, f, positive)
    cube = mse.reshape(grid, grid, grid)
    local = np.flatnonzero((cube <= minimum_filter(cube, size=3, mode="nearest")).reshape(-1))
    local = local[np.isfinite(mse[local])]
    order = [int(k) for k in local[np.argsort(mse[local])][:starts]]
    order += [int(k) for k in np.argsort(mse)[: starts - len(order)] if k not in order]

    starts_ = [_assemble(gains[k : k + 1], combos[k : k + 1])[0] for k in order]
    return _fit_result(_refine(starts_, v, f, positive), v, f, "lsq", np.zeros(0))


# ---------------------------------------------------------------------------------------------
# Excitation, cycle averaging (eq 24), ridge regression of the minimal set


def table6_motion(
    robot: Robot, *, periods: int = 10, dt: float = 0.002
) -> tuple[Motion, Array, list[str]]:
    """The doc's excitation (eq 22 with Table 6, ``w_f = 0.2 pi``, N = 3), inside the limits.

    A joint whose angles or speeds would leave the robot's limits has its harmonics scaled down
    (about ``q0``) until they fit; the notes say which and by how much.

    Returns
    -------
    motion : Motion
        ``periods`` periods of 10 s at ``dt``.
    scale : ndarray, shape (n,)
        Factor applied to each joint's coefficients (1 = as printed).
    notes : list of str
    """
    if robot.n != 6:
        raise KinergyError(f"Table 6's excitation is for 6 joints; {robot.name} has {robot.n}")
    a = np.array(DOC_TABLE6["a"])
    b = np.array(DOC_TABLE6["b"])
    q0 = np.array(DOC_TABLE6["q0"])
    one = fourier_motion(q0, a, b, base_frequency=BASE_FREQUENCY, periods=1, dt=min(dt, 0.01))
    scale = np.ones(6)
    notes = []
    for j, joint in enumerate(robot.joints):
        lo, hi = joint.limits.position
        if not lo < q0[j] < hi:
            raise KinergyError(
                f"Table 6's q0 = {q0[j]:g} rad of joint {j + 1} is outside {joint.name}'s range"
            )
        swing = one.q[:, j] - q0[j]
        room = min(
            (hi - q0[j]) / max(float(swing.max()), 1e-12),
            (q0[j] - lo) / max(float(-swing.min()), 1e-12),
            joint.limits.speed / float(np.abs(one.qd[:, j]).max()),
        )
        if room < 1.0:
            scale[j] = 0.98 * room
            notes.append(
                f"joint {j + 1} ({joint.name}): Table 6's trajectory leaves its limits; "
                f"coefficients scaled by {scale[j]:.3f}"
            )
    motion = fourier_motion(
        q0,
        a * scale[:, None],
        b * scale[:, None],
        base_frequency=BASE_FREQUENCY,
        periods=periods,
        dt=dt,
    )
    return motion, scale, notes


def cycle_average(
    t: ArrayLike, signals: ArrayLike | Mapping[str, ArrayLike], period: float
) -> tuple[Array, Any]:
    """Eq 24: the mean over whole periods, sample by sample within the period.

    ``x_bar(k) = 1/N_j sum_i x_i(k)``, ``k`` the sample within a period, ``i`` the period. The
    whole periods from ``t[0]`` are used (a trailing part is dropped); when ``period`` is not a
    whole number of samples the signals are first interpolated (linearly) onto a grid that is.

    Parameters
    ----------
    t : array_like, shape (N,)
        Uniform time stamps, s.
    signals : array_like, shape (N, ...), or a mapping of names to such arrays
    period : float
        s.

    Returns
    -------
    t_one : ndarray, shape (K,)
        Time within one period (from ``t[0]``), s.
    averaged : ndarray, shape (K, ...), or a dict of them
    """
    tt = np.asarray(t, dtype=float)
    if tt.ndim != 1 or tt.size < 2:
        raise KinergyError("cycle averaging needs at least 2 time stamps")
    dt = float(np.median(np.diff(tt)))
    if not (np.isfinite(period) and period > 2 * dt):
        raise KinergyError(f"period must be longer than two samples, got {period}")
    k = round(period / dt)
    cycles = int(np.floor((tt[-1] - tt[0] + dt) / period + 1e-9))  # whole periods of samples
    if cycles < 1:
        raise KinergyError(
            f"the signals last {tt[-1] - tt[0]:.4g} s: not one whole period of {period:g} s"
        )
    exact = abs(k * dt - period) <= 1e-9 * period and np.allclose(np.diff(tt), dt, rtol=1e-6)
    grid = tt[0] + np.arange(cycles * k) * (period / k)

    def average(x: ArrayLike) -> Array:
        arr = np.asarray(x, dtype=float)
        if arr.shape[0] != tt.size:
            raise KinergyError(f"a signal has {arr.shape[0]} samples, the time {tt.size}")
        if exact and arr.shape[0] >= cycles * k:
            on_grid = arr[: cycles * k]
        else:
            flat = arr.reshape(tt.size, -1)
            on_grid = np.column_stack(
                [np.interp(grid, tt, flat[:, c]) for c in range(flat.shape[1])]
            ).reshape((grid.size, *arr.shape[1:]))
        return np.asarray(on_grid.reshape((cycles, k, *arr.shape[1:])).mean(axis=0))

    t_one = grid[:k] - tt[0]
    if isinstance(signals, Mapping):
        return t_one, {name: average(x) for name, x in signals.items()}
    return t_one, average(signals)


def find_period(
    t: ArrayLike, x: ArrayLike, *, min_period: float = 1.0, tol: float = 1e-3
) -> float | None:
    """The period of a repeated motion, or None when it does not repeat at least twice.

    The smallest shift ``T >= min_period`` with ``mean |x(t + T) - x(t)|^2 <= tol * var(x)``
    (summed over columns), refined to the best shift within the first dip; computed for every
    shift at once with FFTs.

    Parameters
    ----------
    t : array_like, shape (N,)
        Uniform time stamps, s.
    x : array_like, shape (N, n)
        E.g. joint angles.
    """
    tt = np.asarray(t, dtype=float)
    arr = np.asarray(x, dtype=float).reshape(tt.size, -1)
    arr = arr - arr.mean(axis=0)
    big_n = tt.size
    var = float(np.sum(arr.var(axis=0)))
    if big_n < 8 or var == 0.0:
        return None
    dt = float(np.median(np.diff(tt)))
    size = 1 << int(np.ceil(np.log2(2 * big_n)))
    spec = np.fft.rfft(arr, size, axis=0)
    corr = np.fft.irfft(np.abs(spec) ** 2, size, axis=0)[:big_n].sum(axis=1)  # sum_i x_i x_{i+k}
    sq = np.sum(arr**2, axis=1)
    head = np.concatenate([[0.0], np.cumsum(sq)])  # head[m] = sum_{i<m} x_i^2
    lags = np.arange(big_n)
    count = big_n - lags
    tail = head[-1] - head[lags]  # sum_{i>=k} x_i^2
    mismatch = (tail + head[count] - 2.0 * corr) / np.maximum(count, 1)
    first = max(1, int(np.ceil(min_period / dt)))
    last = big_n // 2  # at least two periods
    if first >= last:
        return None
    good = np.flatnonzero(mismatch[first:last] <= tol * var)
    if good.size == 0:
        return None
    k0 = first + int(good[0])
    k1 = k0
    while k1 + 1 < last and mismatch[k1 + 1] <= tol * var:
        k1 += 1
    k = k0 + int(np.argmin(mismatch[k0 : k1 + 1]))
    return float(k * dt)


@dataclass(frozen=True, eq=False)
class RidgeFit:
    """Ridge regression of the minimal (base) inertial parameter set.

    Attributes
    ----------
    base : BaseParameters
        The minimal set (:func:`kinergy.dynamics.regressor.base_parameters`).
    coef : ndarray, shape (b,)
        Base parameters in physical units (de-standardised): ``tau ~ Y_b coef + intercept``.
    intercept : float
        Constant of the standardised regression (N m, every joint); 0 for an exact model.
    alpha : float
        Chosen ridge weight (on unit-variance columns, per sample).
    alphas, gcv : ndarray
        The candidates and their generalised cross-validation scores.
    split : int
        Samples (time steps) used for training: ``[0, split)``; testing ``[split, N)``.
    rmse_test, rmse_train, r2_test : ndarray, shape (n,)
        Per joint, eq 26 (N m) and R^2.
    predicted : ndarray, shape (N, n)
        Predicted joint torques over all samples, N m.
    condition : float
        Condition number of the standardised training regressor.
    """

    base: BaseParameters
    coef: Array
    intercept: float
    alpha: float
    alphas: Array
    gcv: Array
    split: int
    rmse_test: Array
    rmse_train: Array
    r2_test: Array
    predicted: Array
    condition: float


def ridge_minimal(
    robot: Robot,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    tau: ArrayLike,
    *,
    split: float = 0.7,
    alphas: ArrayLike | None = None,
    base: BaseParameters | None = None,
    center: bool = True,
) -> RidgeFit:
    """Ridge regression of the minimal parameter set on standardised data (section 4.2, eq 16).

    Rows are (sample, joint): ``tau[k, j] = Y_b[k, j, :] @ pi_b``. The first ``split`` of the
    samples (in time) train, the rest test. Each column of the training regressor is
    standardised (zero mean, unit variance over the training rows; the target centred), as the
    doc's "once standardised" and scikit-learn's ``Ridge`` do, and the ridge problem ::

        min_beta  1/m |y_c - X_s beta|^2 + alpha |beta|^2

    is solved in closed form from one SVD of ``X_s`` for every candidate ``alpha``. ``alpha`` is
    chosen by generalised cross-validation (Golub, Heath, Wahba, Technometrics 21(2), 1979),
    ``GCV = m RSS / (m - df)^2`` with ``df`` the effective number of parameters: no
    scikit-learn needed. The coefficients are mapped back to physical base parameters,
    ``pi_b = beta / sigma``, with the intercept ``mean(y) - mu . pi_b``. As ``alpha -> 0`` the
    solution is the ordinary least-squares one (with an intercept; ``center=False`` leaves the
    columns uncentred and fits no intercept).

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity for the regressor.
    q, qd, qdd : array_like, shape (N, n)
        rad, rad/s, rad/s^2.
    tau : array_like, shape (N, n)
        Joint torques the links need (N m): measured less friction and drive inertia (eq 25).
    split : float
        Training share, in (0, 1]. With 1 the test metrics are those of the training data.
    alphas : array_like, optional
        Candidate ridge weights; default ``logspace(-12, 0, 49)``.
    base : BaseParameters, optional
        Default :func:`base_parameters` of ``robot``.

    Returns
    -------
    RidgeFit
    """
    qq = np.asarray(q, dtype=float)
    y3 = np.asarray(tau, dtype=float)
    big_n, n = qq.shape
    if y3.shape != (big_n, n) or n != robot.n:
        raise KinergyError(f"ridge: q {qq.shape} and tau {y3.shape} must both be (N, {robot.n})")
    if not 0.0 < split <= 1.0:
        raise KinergyError(f"split must be in (0, 1], got {split}")
    base = base or base_parameters(robot)
    cand = np.logspace(-12, 0, 49) if alphas is None else np.asarray(alphas, dtype=float)
    if cand.ndim != 1 or cand.size == 0 or np.any(cand < 0):
        raise KinergyError("alphas must be a non-empty list of numbers >= 0")
    n_train = max(1, round(split * big_n))
    if n_train * n < base.size + 1:
        raise KinergyError(f"ridge: {n_train * n} training rows for {base.size} base parameters")
    y_all = base.regressor(full_regressor(robot, qq, qd, qdd))  # (N, n, b)
    x_tr = y_all[:n_train].reshape(-1, base.size)
    y_tr = y3[:n_train].reshape(-1)
    m = x_tr.shape[0]
    mu = x_tr.mean(axis=0) if center else np.zeros(base.size)
    sigma = x_tr.std(axis=0) if center else np.sqrt(np.mean(x_tr**2, axis=0))
    sigma[sigma <= 1e-12 * max(float(sigma.max()), 1e-300)] = 1.0
    y_mean = float(y_tr.mean()) if center else 0.0
    xs = (x_tr - mu) / sigma
    yc = y_tr - y_mean
    u, s, vt = np.linalg.svd(xs, full_matrices=False)
    uty = u.T @ yc
    outside = float(yc @ yc - uty @ uty)  # the part of y no column reaches
    gcv = np.empty(cand.size)
    for i, alpha in enumerate(cand):
        lam = alpha * m
        shrink = lam / (s**2 + lam)
        rss = max(outside, 0.0) + float(np.sum((shrink * uty) ** 2))
        df = float(np.sum(s**2 / (s**2 + lam)))
        gcv[i] = m * rss / max(m - df, 1e-12) ** 2
    best = int(np.argmin(gcv))
    lam = cand[best] * m
    beta = vt.T @ (s / (s**2 + lam) * uty)
    coef = beta / sigma
    intercept = y_mean - float(mu @ coef)
    predicted = y_all @ coef + intercept
    test = slice(n_train, big_n) if n_train < big_n else slice(0, big_n)
    return RidgeFit(
        base=base,
        coef=coef,
        intercept=intercept,
        alpha=float(cand[best]),
        alphas=cand,
        gcv=gcv,
        split=n_train,
        rmse_test=rmse(y3[test], predicted[test]),
        rmse_train=rmse(y3[:n_train], predicted[:n_train]),
        r2_test=r_squared(y3[test], predicted[test]),
        predicted=predicted,
        condition=float(s[0] / s[-1]) if s[-1] > 0 else float("inf"),
    )


# ---------------------------------------------------------------------------------------------
# The whole procedure on logs


def _moving_joint(data: IdentData, still: float = 1e-3, share: float = 0.1) -> int | None:
    """The one joint that moves in a log, else None: max |qd_cmd| above ``still`` rad/s and above
    ``share`` of the fastest joint's (a measured, filtered speed is never exactly still)."""
    peak = np.max(np.abs(data.qd_cmd), axis=0)
    moving = np.flatnonzero(peak > max(still, share * float(peak.max())))
    return int(moving[0]) if moving.size == 1 else None


def _excitation_arrays(
    robot: Robot,
    data: IdentData,
    *,
    eta: float,
    period: float | None,
    cutoff: float | None,
) -> tuple[dict[str, Array], dict[str, Any]]:
    """Filtered (Butterworth), cycle-averaged (eq 24) motion and joint torques from currents."""
    assert data.current is not None
    current = data.current
    fs = 1.0 / data.dt
    note: dict[str, Any] = {"path": data.path, "samples": len(data)}
    if cutoff is not None and cutoff < fs / 2.0:
        current = lowpass(current, fs, cutoff)
        note["cutoff"] = cutoff
    found = period if period is not None else find_period(data.t, data.q_cmd)
    signals = {"q": data.q, "qd": data.qd, "qdd": data.qdd, "current": current}
    if found is not None and (data.t[-1] - data.t[0]) >= 2 * found - 1.5 * data.dt:
        _, signals = cycle_average(data.t, signals, found)
        note["period"] = found
        note["cycles"] = int(np.floor((data.t[-1] - data.t[0] + data.dt) / found + 1e-9))
    else:
        note["period"] = None
    signals["tau"] = joint_torques_from_current(robot, signals["current"], eta=eta)
    return signals, note


@dataclass(frozen=True)
class NursingJoint(DriveEstimate):
    """A joint's drive from the nursing method; ``identified``: its friction came from runs."""

    identified: bool = False


@dataclass(frozen=True)
class NursingFit(Fit):
    """The nursing method's fit: friction per joint run and per motor group, the ridge
    regression of the links and its base parameters, and the links kept from the model."""

    friction_runs: tuple[dict[str, Any], ...] | list[dict[str, Any]] = ()
    friction_motors: tuple[dict[str, Any], ...] | list[dict[str, Any]] = ()
    ridge: dict[str, Any] | None = field(default=None, metadata=OPTIONAL)
    base_parameters: list[dict[str, Any]] | None = field(default=None, metadata=OPTIONAL)
    links_kept: list[int] | None = field(default=None, metadata=OPTIONAL)


def identify_nursing(
    robot: Robot,
    datas: Sequence[IdentData],
    *,
    eta: float = 1.0,
    fit: str = "lsq",
    period: float | None = None,
    cutoff: float | None = FILTER_CUTOFF,
    split: float = 0.7,
    alphas: ArrayLike | None = None,
    trim: int = 10,
    seed: int = 0,
) -> IdentificationResult:
    """The nursing doc's identification (sections 4.1-4.2) from prepared logs.

    Logs in which one joint moves (the others stay below a tenth of its peak speed) with
    back-and-forth constant-speed runs are friction runs (:func:`back_and_forth_motion`); the
    others are excitation runs.

    1. Friction: per run, the joint torques from the currents (eq 21 and the coupling,
       :func:`joint_torques_from_current`), the constant-speed runs
       (:func:`constant_speed_runs`) and the odd part (:func:`friction_points`, eqs 19-20); per
       joint a Makkar curve (eq 13, joint side); per group of coupled motors one curve fitted to
       all its joints' points, split onto the motors (:func:`makkar_motor_side`). Motors without
       runs keep the model's friction.
    2. Links: per excitation log, currents low-pass filtered (Butterworth, ``cutoff`` Hz; the doc's
       15 Hz) and every signal averaged over the periods (eq 24; ``period`` s, found by
       :func:`find_period` when None); joint torques less the identified friction
       (:func:`joint_friction`) and the drives' reflected inertia (eq 25 with the coupled joint's
       internal inertia, eq 10) regressed on the minimal set by :func:`ridge_minimal` (the
       first ``split`` in time trains, the rest tests; several excitation logs are joined in
       order, each reduced to one averaged period when it repeats). The links written back are
       the standard parameters closest to the model's with the identified base parameters
       (:func:`kinergy.identify.full.standard_from_base`); a link that is not physical keeps
       the model's data, with a warning (``fit["links_kept"]``).

    Parameters
    ----------
    robot : Robot
        The starting model (kinematics, coupling, gear ratios, torque constants, rotor inertias).
    datas : sequence of IdentData
        Prepared logs with ``actual_current``.
    eta : float
        Eq 21's efficiency (the twin: 1; the doc's robot: 0.82).
    fit : {"lsq", "pso"}
        Makkar fit (:func:`fit_makkar_lsq` or :func:`fit_makkar_pso`).
    period, cutoff, split, alphas :
        See above; ``cutoff=None`` skips the filter.
    trim : int
        Samples dropped at each end of a constant-speed run.
    seed : int
        Seed of the swarm (``fit="pso"``).

    Returns
    -------
    IdentificationResult
        ``method = "nursing"``. ``fit["friction_runs"]``: per joint with runs, its ``kind``
        (pitch/rotation/single), ``levels``, joint-side ``gamma`` with ``r2`` (levels) and
        ``r2_samples``; ``fit["friction_motors"]``: per motor group the pooled fit;
        ``fit["ridge"]``: ``alpha``, ``rmse_test``/``rmse_train``/``r2_test`` per joint (N m),
        ``torque_std_test`` (the spread of the regressed torques on the test part, N m, to read
        the RMSE against), ``intercept``, ``condition``, ``split``, ``logs``;
        ``fit["base_parameters"]``; ``fit["torque"]``, ``fit["current"]`` (the returned robot's
        :func:`validation_metrics` on all logs); ``warnings``.

    Raises
    ------
    KinergyError
        No logs, a log without ``actual_current``, an unknown ``fit``.
    """
    if not datas:
        raise KinergyError("no log to identify from")
    if fit not in ("lsq", "pso"):
        raise KinergyError(f"unknown Makkar fit {fit!r} (known: lsq, pso)")
    for d in datas:
        if d.current is None:
            raise KinergyError(f"{d.path}: the nursing method needs actual_current")
    n = robot.n
    warnings: list[str] = []
    fit_out: dict[str, Any] = {
        "samples": int(sum(len(d) for d in datas)),
        "logs": tuple(d.path for d in datas),
        "lag": tuple(d.lag for d in datas),
    }

    # 1. friction runs
    runs: dict[int, list[FrictionPoints]] = {}
    excitation: list[IdentData] = []
    for d in datas:
        j = _moving_joint(d)
        speeds, fwd, bwd = (
            (np.zeros(0), None, None)
            if j is None
            else constant_speed_runs(d.qd_cmd[:, j], d.qdd_cmd[:, j])
        )
        if j is None or speeds.size == 0:
            excitation.append(d)
            continue
        assert d.current is not None and fwd is not None and bwd is not None
        tau = joint_torques_from_current(robot, d.current, eta=eta)
        runs.setdefault(j, []).append(
            friction_points(d.q[:, j], tau[:, j], speeds, fwd, bwd, joint=j, trim=trim)
        )

    def fitter(v: Array, f: Array) -> MakkarFit:
        if fit == "pso":
            return fit_makkar_pso(v, f, rng=seed)
        return fit_makkar_lsq(v, f)

    per_joint_fits: list[dict[str, Any]] = []
    pooled: dict[int, tuple[Array, Array, MakkarFit]] = {}
    for j in sorted(runs):
        pts = runs[j]
        v = np.concatenate([p.speeds for p in pts])
        f = np.concatenate([p.friction for p in pts])
        sv = np.concatenate([p.sample_speeds for p in pts])
        sf = np.concatenate([p.sample_friction for p in pts])
        if v.size < 6:
            warnings.append(
                f"joint {j + 1} ({robot.joints[j].name}): {v.size} speed levels, Makkar's model "
                "needs at least 6; its motors keep the model's friction"
            )
            continue
        mf = fitter(v, f)
        per_joint_fits.append(
            {
                "joint": j + 1,
                "name": robot.joints[j].name,
                "kind": joint_kind(robot, j),
                "levels": int(v.size),
                "gamma": mf.gamma.tolist(),
                "r2": mf.r2,
                "r2_samples": float(r_squared(sf[:, None], makkar(mf.gamma, sv)[:, None])[0]),
                "error_mean": float(np.mean(np.concatenate([p.error for p in pts]))),
            }
        )
        pooled[j] = (v, f, mf)
    fit_out["friction_runs"] = per_joint_fits

    # one curve per group of coupled motors, from all its joints' points
    n_mat = transmission_matrix(robot)
    new_friction: dict[int, Friction] = {}
    motor_fits: list[dict[str, Any]] = []
    done: set[int] = set()
    for j in sorted(pooled):
        if j in done:
            continue
        ratio, k, motors = _motor_share(robot, j)
        group = [
            jj
            for jj in sorted(pooled)
            if set(np.flatnonzero(np.abs(n_mat[:, jj]) > 0)) == set(motors)
        ]
        shares = [_motor_share(robot, jj)[:2] for jj in group]
        if any(not np.isclose(r, ratio) or kk != k for r, kk in shares):
            group = [j]
        done.update(group)
        if len(group) == 1:
            mf = pooled[j][2]
        else:
            mf = fitter(
                np.concatenate([pooled[jj][0] for jj in group]),
                np.concatenate([pooled[jj][1] for jj in group]),
            )
        g_motor = makkar_motor_side(mf.gamma, ratio, k)
        for m in motors:
            old = robot.joints[m].drive.friction.params
            params = {name: float(x) for name, x in zip(_MAKKAR, g_motor, strict=True)}
            params.update({key: old[key] for key in ("standstill", "holding") if key in old})
            new_friction[int(m)] = Friction("makkar", params)
        motor_fits.append(
            {
                "motors": [int(m) + 1 for m in motors],
                "joints": [jj + 1 for jj in group],
                "gamma_joint_side": mf.gamma.tolist(),
                "r2": mf.r2,
            }
        )
    fit_out["friction_motors"] = motor_fits
    for m in range(n):
        if m not in new_friction:
            warnings.append(
                f"motor {m + 1} ({robot.joints[m].name}): no friction run; kept the model's friction"
            )
    staged = robot.with_joints(
        [
            dataclasses.replace(jt, drive=dataclasses.replace(jt.drive, friction=new_friction[m]))
            if m in new_friction
            else jt
            for m, jt in enumerate(robot.joints)
        ]
    )

    # 2. links from the excitation logs
    identified = staged
    if excitation:
        parts, notes = [], []
        for d in excitation:
            sig, note = _excitation_arrays(staged, d, eta=eta, period=period, cutoff=cutoff)
            parts.append(sig)
            notes.append(note)
        q = np.vstack([p["q"] for p in parts])
        qd = np.vstack([p["qd"] for p in parts])
        qdd = np.vstack([p["qdd"] for p in parts])
        tau = np.vstack([p["tau"] for p in parts])
        tau_links = tau - joint_friction(staged, qd) - qdd @ reflected_inertia(staged).T
        rf = ridge_minimal(staged, q, qd, qdd, tau_links, split=split, alphas=alphas)
        fit_out["ridge"] = {
            "alpha": rf.alpha,
            "intercept": rf.intercept,
            "condition": rf.condition,
            "split": split,
            "rows_train": rf.split,
            "rmse_test": rf.rmse_test.tolist(),
            "rmse_train": rf.rmse_train.tolist(),
            "r2_test": rf.r2_test.tolist(),
            "torque_std_test": np.std(tau_links[rf.split :], axis=0).tolist()
            if rf.split < len(tau_links)
            else np.std(tau_links, axis=0).tolist(),
            "logs": notes,
        }
        fit_out["base_parameters"] = [
            {"name": name, "value": float(x)}
            for name, x in zip(rf.base.expressions(), rf.coef, strict=True)
        ]
        identified = _write_links(staged, rf, warnings, fit_out)
    else:
        warnings.append(
            "no excitation log (every log moves one joint): link data kept from the model"
        )
    sources = dict(identified.sources)
    if new_friction:
        sources["friction"] = Source("identified", "kinergy identify (nursing, eqs 13, 17-21)")
    if excitation and len(fit_out.get("links_kept", [])) < n:
        for cat in ("mass", "com", "inertia"):
            sources[cat] = Source("identified", "kinergy identify (nursing, eqs 16, 22-26, ridge)")
    identified = dataclasses.replace(identified, sources=sources)
    fit_out.update(vars(validation_metrics(identified, datas)))
    fit_out["warnings"] = tuple(warnings)
    joints_out = tuple(
        NursingJoint(
            name=jt.name,
            rotor_inertia=jt.drive.rotor_inertia,
            motor_inertia=jt.drive.motor_inertia,
            torque_constant=jt.drive.torque_constant,
            friction=friction_entry(jt),
            identified=m in new_friction,
        )
        for m, jt in enumerate(identified.joints)
    )
    return IdentificationResult(identified, "nursing", joints_out, NursingFit(**fit_out))


def _write_links(robot: Robot, rf: RidgeFit, warnings: list[str], fit: dict[str, Any]) -> Robot:
    """Links with the identified base parameters: the standard parameters closest to the model's
    (:func:`kinergy.identify.full.standard_from_base`); a link that is not physical keeps the
    model's data, with a warning."""
    from kinergy.identify.physical import link_consistency, parameter_scale, standard_from_base

    pi0 = inertial_parameters(robot)
    payload = pi0 - inertial_parameters(robot, include_payload=False)
    pi = standard_from_base(rf.base, rf.coef, pi0, scale=parameter_scale(robot))
    links = (pi - payload).reshape(-1, 10)
    problems = link_consistency(pi - payload)
    fit["links_kept"] = [j + 1 for j, p in enumerate(problems) if p is not None]
    joints = []
    for j, (jt, row, problem) in enumerate(zip(robot.joints, links, problems, strict=True)):
        if problem is not None:
            warnings.append(f"link {j + 1} ({jt.name}): {problem}; kept the model's link data")
            joints.append(jt)
            continue
        m = float(row[0])
        c = row[1:4] / m
        ixx, ixy, iyy, ixz, iyz, izz = row[4:10]
        i_o = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        i_c = i_o - m * (float(c @ c) * np.eye(3) - np.outer(c, c))  # parallel-axis theorem
        inertia = np.array([i_c[0, 0], i_c[1, 1], i_c[2, 2], i_c[0, 1], i_c[1, 2], i_c[0, 2]])
        try:
            link = Link(mass=m, com=c, inertia=inertia)
        except KinergyError as err:
            warnings.append(f"link {j + 1} ({jt.name}): {err}; kept the model's link data")
            joints.append(jt)
            continue
        joints.append(dataclasses.replace(jt, link=link))
    return robot.with_joints(joints)
