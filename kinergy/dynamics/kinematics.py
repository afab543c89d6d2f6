"""Batched forward kinematics and the geometric Jacobian.

All functions take joint angles of shape ``(n,)`` or ``(N, n)`` (rad) and return arrays with the
same leading rank. Poses are 4x4 homogeneous transforms in the robot's base frame.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.dynamics.chain import Chain, check_state, kernel_data
from kinergy.model.robot import Robot

__all__ = [
    "axes_jacobian",
    "axes_jacobian_rate",
    "flange_pose",
    "jacobian",
    "joint_axes",
    "link_poses",
    "rot_z_batch",
    "tool_axes",
]


def rot_z_batch(q: Array) -> Array:
    """Rotations about z by angles ``q``, shape (N,) -> (N, 3, 3)."""
    c, s = np.cos(q), np.sin(q)
    out = np.zeros((*q.shape, 3, 3))
    out[..., 0, 0] = c
    out[..., 0, 1] = -s
    out[..., 1, 0] = s
    out[..., 1, 1] = c
    out[..., 2, 2] = 1.0
    return out


def _poses(chain: Chain, q: Array) -> tuple[Array, Array]:
    """Joint frames ``F_{i-1} P_i Rz(q_i)`` and link frames ``F_i`` in the base frame.

    q : (N, n). Returns two arrays of shape (N, n, 4, 4).
    """
    big_n, n = q.shape
    joint = np.empty((big_n, n, 4, 4))
    link = np.empty((big_n, n, 4, 4))
    current = np.broadcast_to(chain.base, (big_n, 4, 4))
    rz = np.zeros((big_n, 4, 4))
    rz[:, 3, 3] = 1.0
    for i in range(n):
        rz[:, :3, :3] = rot_z_batch(q[:, i])
        joint[:, i] = (current @ chain.pre[i]) @ rz
        link[:, i] = joint[:, i] @ chain.post[i]
        current = link[:, i]
    return joint, link


def link_poses(robot: Robot, q: ArrayLike) -> Array:
    """Pose of every link frame (DH or MDH frame i, i = 1..n) in the base frame.

    Parameters
    ----------
    robot : Robot
    q : array_like, shape (n,) or (N, n)
        Joint angles, rad.

    Returns
    -------
    ndarray, shape (n, 4, 4) or (N, n, 4, 4)
    """
    single, s = check_state(robot, q=q)
    _, link = _poses(kernel_data(robot).chain, s["q"])
    return link[0] if single else link


def flange_pose(robot: Robot, q: ArrayLike) -> Array:
    """Pose of the flange in the base frame, shape (4, 4) or (N, 4, 4)."""
    single, s = check_state(robot, q=q)
    chain = kernel_data(robot).chain
    _, link = _poses(chain, s["q"])
    out = link[:, -1] @ chain.flange
    return out[0] if single else out


def joint_axes(chain: Chain, q: Array) -> tuple[Array, Array, Array]:
    """Axis directions ``z`` (N, n, 3), axis points ``o`` (N, n, 3) and link frames (N, n, 4, 4)."""
    joint, link = _poses(chain, q)
    return joint[..., :3, 2], joint[..., :3, 3], link


def axes_jacobian(z: Array, o: Array, tip: Array) -> Array:
    """Geometric Jacobian of a point from the joint axes: column i is ``[z_i x (tip - o_i); z_i]``.

    Parameters
    ----------
    z, o : ndarray, shape (N, n, 3)
        Axis directions and axis points (:func:`joint_axes`), base frame.
    tip : ndarray, shape (N, 3)
        The point, base frame, m.

    Returns
    -------
    ndarray, shape (N, 6, n)
    """
    jv = np.cross(z, tip[:, None, :] - o)
    return np.concatenate([np.swapaxes(jv, 1, 2), np.swapaxes(z, 1, 2)], axis=1)


def axes_jacobian_rate(z: Array, o: Array, tip: Array, qd: Array) -> Array:
    """``Jdot qd``, the velocity-product part of the point's acceleration
    (``[a; alpha] = J qdd + Jdot qd``), in closed form from the joint axes.

    Axis ``z_i`` and its point ``o_i`` are fixed in link ``i - 1``, so ``dz_i/dt = w_{i-1} x z_i``
    and ``do_i/dt`` is link ``i - 1``'s velocity at ``o_i``, with ``w_{i-1} = sum_{j<i} z_j qd_j``;
    differentiating the columns of :func:`axes_jacobian` gives
    ``Jdot qd = sum_i qd_i [dz_i/dt x (tip - o_i) + z_i x (v_tip - do_i/dt); dz_i/dt]``.

    Parameters
    ----------
    z, o : ndarray, shape (N, n, 3)
    tip : ndarray, shape (N, 3)
    qd : ndarray, shape (N, n)
        Joint speeds, rad/s.

    Returns
    -------
    ndarray, shape (N, 6)
        m/s^2 and rad/s^2.
    """
    spin = z * qd[..., None]  # (N, n, 3): each joint's share of the angular velocity
    w_before = np.cumsum(spin, axis=1) - spin  # w_{i-1}
    moment = np.cross(spin, o)  # qd_j z_j x o_j
    o_rate = np.cross(w_before, o) - (np.cumsum(moment, axis=1) - moment)
    tip_rate = np.cross(spin.sum(axis=1), tip) - moment.sum(axis=1)
    z_rate = np.cross(w_before, z)
    lin = np.cross(z_rate, tip[:, None, :] - o) + np.cross(z, tip_rate[:, None, :] - o_rate)
    return np.concatenate(
        [np.einsum("nij,ni->nj", lin, qd), np.einsum("nij,ni->nj", z_rate, qd)], axis=1
    )


def tool_axes(
    robot: Robot, q: ArrayLike, tool: ArrayLike | None = None
) -> tuple[Array, Array, Array]:
    """The joint axes and a tool point of joint angles, base frame: what :func:`axes_jacobian`
    and :func:`axes_jacobian_rate` are made of.

    Parameters
    ----------
    robot : Robot
    q : array_like, shape (n,) or (N, n)
        Joint angles, rad.
    tool : array_like, shape (4, 4), optional
        The tool frame in the flange frame (URScript's ``set_tcp``); default the flange itself.

    Returns
    -------
    z, o : ndarray, shape (N, n, 3)
        Axis directions and axis points (:func:`joint_axes`).
    tip : ndarray, shape (N, 3)
        The tool point, m.
    """
    _, s = check_state(robot, q=q)
    chain = kernel_data(robot).chain
    z, o, link = joint_axes(chain, s["q"])
    end = chain.flange if tool is None else chain.flange @ np.asarray(tool, dtype=float)
    return z, o, (link[:, -1] @ end)[:, :3, 3]


def jacobian(robot: Robot, q: ArrayLike, tool: ArrayLike | None = None) -> Array:
    """Geometric Jacobian of the flange (or of a tool point) in the base frame.

    ``[v; w] = J qd`` with ``v`` the linear velocity of the flange origin (m/s) and ``w`` the
    angular velocity (rad/s), both in base-frame coordinates.

    Parameters
    ----------
    robot : Robot
    q : array_like, shape (n,) or (N, n)
        Joint angles, rad.
    tool : array_like, shape (4, 4), optional
        A tool frame in the flange frame whose origin ``v`` is the velocity of; default the
        flange.

    Returns
    -------
    ndarray, shape (6, n) or (N, 6, n)
    """
    out = axes_jacobian(*tool_axes(robot, q, tool))
    return out[0] if np.ndim(q) == 1 else out
