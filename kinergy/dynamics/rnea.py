"""Rigid-body inverse and forward dynamics, batched over samples.

The link (rigid-body) part of the arm's dynamics, framework eq 1 without friction::

    M(q) qdd + C(q, qd) qd + g(q) = tau - J(q)^T h

``tau`` are joint-side torques (N m); ``h = [f; m]`` is the wrench the flange exerts on its
environment (N, N m about the flange origin, base-frame coordinates). Drive inertia and friction
(UR5e eq 2's second term, eqs 11-16) are added by :mod:`kinergy.drives`.

Every function vectorises over samples: inputs of shape ``(n,)`` or ``(N, n)``; the loop runs over
the joints only.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.dynamics.chain import (
    check_state,
    contiguous_state,
    gravity_in_frame0,
    kernel_data,
    output_array,
)
from kinergy.dynamics.kinematics import jacobian, joint_axes
from kinergy.dynamics.launch import rnea_into
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot

__all__ = ["forward_dynamics", "gravity_torque", "mass_matrix", "rnea"]


def _check_wrench(wrench: ArrayLike | None, rows: int, single: bool) -> Array | None:
    if wrench is None:
        return None
    w = np.asarray(wrench, dtype=float)
    expected = (6,) if single else (rows, 6)
    if w.shape == (6,) and not single:
        w = np.broadcast_to(w, (rows, 6))
    if w.shape != expected and w.shape != (rows, 6):
        raise KinergyError(f"wrench: expected shape {expected}, got {w.shape}")
    if not np.all(np.isfinite(w)):
        raise KinergyError("wrench: not finite")
    return w.reshape(rows, 6)


def rnea(
    robot: Robot,
    q: ArrayLike,
    qd: ArrayLike | None = None,
    qdd: ArrayLike | None = None,
    *,
    wrench: ArrayLike | None = None,
    gravity: ArrayLike | None = None,
    out: Array | None = None,
    threads: int | None = None,
) -> Array:
    """Rigid-body joint torques by the recursive Newton-Euler algorithm (UR5e eqs 1, 3-6).

    Parameters
    ----------
    robot : Robot
        Link inertials and the payload, if any, are used; drives are not.
    q, qd, qdd : array_like, shape (n,) or (N, n)
        Joint angles (rad), speeds (rad/s), accelerations (rad/s^2); ``None`` means zero.
    wrench : array_like, shape (6,) or (N, 6), optional
        ``h = [fx, fy, fz, mx, my, mz]`` that the flange exerts on the environment (N, N m about
        the flange origin, base-frame coordinates); adds ``J^T h`` (framework eq 1).
    gravity : array_like, shape (3,), optional
        Overrides ``robot.gravity`` (base frame, m/s^2); ``[0, 0, 0]`` for no gravity.
    out : ndarray, shape like ``q``, optional
        C-contiguous float64 array the torques are written to (no allocation).
    threads : int, optional
        numba threads for this call (:func:`kinergy.dynamics.threads.kernel_threads`).

    Returns
    -------
    ndarray, shape like ``q``
        Joint torques ``f_link`` of UR5e eq 2, N m (``out`` when given).

    Examples
    --------
    >>> import numpy as np, kinergy
    >>> ur5e = kinergy.load_robot("ur5e")
    >>> tau = kinergy.rnea(ur5e, np.zeros(6))
    >>> round(float(tau[1]), 2)   # shoulder holding the stretched-out arm against gravity
    -59.76
    """
    single, s = check_state(robot, q=q, qd=qd, qdd=qdd)
    data = kernel_data(robot)
    rows = s["q"].shape[0]
    g0 = gravity_in_frame0(robot, gravity)
    w = _check_wrench(wrench, rows, single)
    tau = output_array(out, (rows, robot.n), single)
    state = contiguous_state(s)
    rnea_into(data, state, tau, data.ends[2] if g0 is None else g0, threads)
    if w is not None:  # the flange's wrench through the flange Jacobian, tau += J^T h
        tau += np.einsum("kji,kj->ki", jacobian(robot, state[0]), w)
    if out is not None:
        return out
    return tau[0] if single else tau


def gravity_torque(robot: Robot, q: ArrayLike) -> Array:
    """Gravity torques g(q), N m, shape like ``q``."""
    return rnea(robot, q)


def mass_matrix(robot: Robot, q: ArrayLike) -> Array:
    """Joint-space mass matrix M(q) of the links, kg m^2.

    Computed from the link Jacobians, ``M = sum_j m_j Jv_j^T Jv_j + Jw_j^T R_j I_j R_j^T Jw_j``
    (Jv_j at link j's centre of mass), independently of :func:`rnea`.

    Parameters
    ----------
    q : array_like, shape (n,) or (N, n)

    Returns
    -------
    ndarray, shape (n, n) or (N, n, n)
    """
    single, s = check_state(robot, q=q)
    chain, body = kernel_data(robot).chain, kernel_data(robot).inertials
    z, o, link = joint_axes(chain, s["q"])  # (N, n, 3), (N, n, 3), (N, n, 4, 4)
    n = robot.n
    rot = link[..., :3, :3]
    com = np.einsum("bjik,jk->bji", rot, body.com) + link[..., :3, 3]  # (N, n, 3)
    lower = np.tril(np.ones((n, n)))  # link j moves with joints i <= j
    # jv[b, j, i] = z_i x (c_j - o_i) for i <= j
    jv = np.cross(z[:, None, :, :], com[:, :, None, :] - o[:, None, :, :]) * lower[None, :, :, None]
    jw = np.broadcast_to(z[:, None, :, :], jv.shape) * lower[None, :, :, None]
    inertia_world = rot @ body.inertia_com[None] @ np.swapaxes(rot, -1, -2)  # (N, n, 3, 3)
    m = np.einsum("j,bjik,bjlk->bil", body.mass, jv, jv)
    m += np.einsum("bjik,bjkl,bjml->bim", jw, inertia_world, jw)
    return m[0] if single else m


def forward_dynamics(
    robot: Robot,
    q: ArrayLike,
    qd: ArrayLike,
    tau: ArrayLike,
    *,
    wrench: ArrayLike | None = None,
) -> Array:
    """Joint accelerations from torques: ``qdd = M^-1 (tau - C qd - g - J^T h)``, rad/s^2.

    Parameters
    ----------
    q, qd, tau : array_like, shape (n,) or (N, n)
        rad, rad/s, N m (joint side, rigid-body part).
    wrench : array_like, shape (6,) or (N, 6), optional
        As in :func:`rnea`.

    Returns
    -------
    ndarray, shape like ``q``
    """
    single, s = check_state(robot, q=q, qd=qd, tau=tau)
    bias = rnea(robot, s["q"], s["qd"], None, wrench=wrench)
    m = mass_matrix(robot, s["q"])
    qdd = np.asarray(np.linalg.solve(m, (s["tau"] - bias)[..., None])[..., 0], dtype=float)
    return qdd[0] if single else qdd
