"""Coupled (differential) joints as transmissions (nursing doc sections 2.2, 3.1 and 4.1).

A differential bevel-gear joint turns two motors into two joint motions, pitch and rotation. This
module holds what is particular to such joints: their internal dynamics (nursing eqs 4-11), the
joint torques from the motor currents (eq 21 with the coupling), which joints are pitch or
rotation, and Makkar's friction (eq 13) moved between the motor side and the joint side.

Coupling conventions
--------------------
kinergy's robot files write a coupled joint as motor inputs ``phi = C @ q`` with, for the nursing
arm's (pitch, rotation) pairs, ``C = [[1, 1], [1, -1]]`` (nursing eq 3 with q1 = rotation and
q2 = pitch). Power balance ``tau . qd = T . phi'`` gives the joint torques from the input-gear
torques ``T`` (n times the motor torques) as ``tau = C^T T``::

    tau_pitch = T1 + T2,        tau_rotation = T1 - T2                    (kinergy, eq 9)

The doc's eqs 17-18 print the other pairing (pitch ``T1 - T2``, rotation ``T1 + T2``); that is
eq 9 with motor 2's current counted with the opposite sign (a mirrored mounting).
:func:`coupled_torques` takes ``mirrored=True`` for the doc's pairing; everything else goes
through the robot's own coupling matrix (:func:`joint_torques_from_current`), so the sign
follows the robot file.

Joint side and motor side
-------------------------
A robot file's friction is per motor (motor side). Moving joint ``j`` alone at speed ``v`` turns
each of its ``k`` motors at ``|N_mj| v`` (``N = diag(n) C``, :func:`motor_share`); if they have the
same friction ``f`` and the same ``|N_mj| = n``, the joint-side friction is ``k n f(n v)``. For
Makkar's model that is Makkar's model again, with ``gamma1, gamma4`` times ``k n``,
``gamma2, gamma3, gamma5`` times ``n`` and ``gamma6`` times ``k n^2`` (:func:`makkar_joint_side`,
:func:`makkar_motor_side`). On the nursing arm k = 2 and n = 3060; pitch and rotation of one pair
then have the same curve, since both turn both motors at ``n |v|`` (the twin cannot tell them
apart; the real joint could, through the differential's own friction).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy.arrays import Array
from kinergy.drives.electrics import friction_torques, torque_constants
from kinergy.drives.transmission import transmission_matrix
from kinergy.errors import KinergyError
from kinergy.friction.makkar import MODEL as MAKKAR
from kinergy.friction.makkar import PARAMETERS as MAKKAR_PARAMETERS
from kinergy.model.robot import Robot

__all__ = [
    "coupled_joint_dynamics",
    "coupled_torques",
    "joint_friction",
    "joint_kind",
    "joint_side_makkar",
    "joint_torques_from_current",
    "makkar_joint_side",
    "makkar_motor_side",
    "motor_share",
    "torque_from_current",
]


def coupled_joint_dynamics(
    q2: ArrayLike,
    qdd: ArrayLike,
    *,
    j1: float,
    j2: float,
    j3: float,
    jh: float,
    m3: float,
    r_h: float,
    m_he: float,
    r_he: float,
    g: float = 9.81,
) -> Array:
    """Generalised forces of one differential joint on its own (nursing eqs 4-11).

    ``Q = J qdd + G`` with ``J = [[J11, J12], [J12, J22]]``, ``J11 = J1 + J2 + J3``,
    ``J12 = J1 - J2``, ``J22 = J1 + J2 + J_H + m3 r_H^2`` and ``G = [0, m_He g r_He sin q2]``.

    Parameters
    ----------
    q2 : array_like, shape (N,)
        Pitch angle, rad.
    qdd : array_like, shape (N, 2)
        ``[q1'', q2'']`` (rotation, pitch), rad/s^2.
    j1, j2, j3, jh : float
        Inertias of the two input branches, bevel gear 3 and the rod H, kg m^2 (nursing Table 2).
    m3, r_h, m_he, r_he : float
        Mass of bevel gear 3 (kg) and its radius about the rod axis (m); mass of the rotating
        parts (kg) and the distance of their centroid (m).

    Returns
    -------
    ndarray, shape (N, 2)
        ``[Q1, Q2]``, N m.
    """
    j = np.array([[j1 + j2 + j3, j1 - j2], [j1 - j2, j1 + j2 + jh + m3 * r_h**2]])
    qdd = np.asarray(qdd, dtype=float)
    out = qdd @ j.T
    out[..., 1] += m_he * g * r_he * np.sin(np.asarray(q2, dtype=float))
    return out


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
        constant (N m/A). The doc's robot: n = 3060, eta = 0.82, K_m = 0.0293
        (:data:`kinergy.experiments.nursing_doc.DOC_EQ21`).

    Examples
    --------
    >>> round(float(torque_from_current(1.0, n=3060.0, eta=0.82, km=0.0293)), 3)
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

    Parameters
    ----------
    qd : array_like, shape (N, n) or (n,)
        Joint speeds, rad/s.
    qdd : array_like, shape like ``qd``, optional
        Joint accelerations, rad/s^2 (for friction held through standstill).
    """
    v = np.atleast_2d(np.asarray(qd, dtype=float))
    n_mat = transmission_matrix(robot)
    wm = v @ n_mat.T
    dwm = None if qdd is None else np.atleast_2d(np.asarray(qdd, dtype=float)) @ n_mat.T
    return np.asarray(friction_torques(robot, wm, np.zeros_like(wm), dwm) @ n_mat, dtype=float)


def joint_kind(robot: Robot, joint: int) -> str:
    """``"pitch"`` (its motors turn the same way), ``"rotation"`` (opposite ways) or
    ``"single"`` (one motor); ``joint`` is 0-based."""
    assert robot.coupling is not None
    col = robot.coupling[:, joint]
    nz = col[np.abs(col) > 0]
    if nz.size <= 1:
        return "single"
    return "pitch" if np.all(np.sign(nz) == np.sign(nz[0])) else "rotation"


def motor_share(robot: Robot, joint: int) -> tuple[float, int, NDArray[np.int_]]:
    """``(n, k, motors)``: the common ratio ``n = |N_mj|`` at which the ``k`` motors (0-based
    indices ``motors``) of joint ``joint`` turn when it moves alone (module docstring).

    Raises
    ------
    KinergyError
        The joint's motors turn at different ratios (no common joint-side friction curve).
    """
    col = transmission_matrix(robot)[:, joint]
    motors = np.flatnonzero(np.abs(col) > 0)
    ratios = np.abs(col[motors])
    if motors.size == 0 or not np.allclose(ratios, ratios[0], rtol=1e-9):
        raise KinergyError(
            f"joint {joint + 1} ({robot.joints[joint].name}): its motors turn at different "
            "ratios; a joint-side friction curve cannot be split between them"
        )
    return float(ratios[0]), int(motors.size), motors


def _makkar_side_factors(ratio: float, motors: int) -> Array:
    """Joint-side over motor-side Makkar parameters, shape (6,): ``gamma1, gamma4``: ``k n``; the
    rates ``gamma2, gamma3, gamma5``: ``n``; ``gamma6``: ``k n^2`` (module docstring)."""
    kn = motors * ratio
    return np.array([kn, ratio, ratio, kn, ratio, motors * ratio**2])


def makkar_joint_side(gamma_motor: ArrayLike, ratio: float, motors: int) -> Array:
    """Joint-side Makkar parameters (nursing eq 13) of ``motors`` equal motors turning at
    ``ratio`` times the joint speed: ``gamma1, gamma4 * k n``, rates ``* n``, ``gamma6 * k n^2``.

    Parameters
    ----------
    gamma_motor : array_like, shape (6,)
        Motor side: N m, s/rad, s/rad, N m, s/rad, N m s/rad.

    Returns
    -------
    ndarray, shape (6,)
        Joint side, same units.
    """
    return np.asarray(gamma_motor, dtype=float) * _makkar_side_factors(ratio, motors)


def makkar_motor_side(gamma_joint: ArrayLike, ratio: float, motors: int) -> Array:
    """Inverse of :func:`makkar_joint_side`: joint-side ``gamma`` (6,) to the motor side (6,)."""
    return np.asarray(gamma_joint, dtype=float) / _makkar_side_factors(ratio, motors)


def joint_side_makkar(robot: Robot, joint: int) -> Array | None:
    """The robot's own Makkar curve of ``joint`` on the joint side (:func:`makkar_joint_side`),
    shape (6,); None unless its motors all have the same Makkar friction at the same ratio."""
    try:
        ratio, k, motors = motor_share(robot, joint)
    except KinergyError:
        return None
    frictions = [robot.joints[m].drive.friction for m in motors]
    if any(f.model is not MAKKAR for f in frictions):
        return None
    g = np.array([frictions[0].params[name] for name in MAKKAR_PARAMETERS])
    if any(
        not np.allclose([f.params[name] for name in MAKKAR_PARAMETERS], g) for f in frictions[1:]
    ):
        return None
    return makkar_joint_side(g, ratio, k)
