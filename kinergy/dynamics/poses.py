"""Tool poses as URScript writes them: ``p[x, y, z, rx, ry, rz]`` and 4x4 transforms.

A URScript pose is a position (m) and a rotation vector (axis times angle, rad) in the robot's
base frame; :func:`pose_matrix` and :func:`pose_vector` convert between it and the homogeneous
transform that :mod:`kinergy.dynamics.kinematics` uses (rotation vectors through
:class:`scipy.spatial.transform.Rotation`). :func:`tcp_pose` is the tool centre point of joint
angles (the flange pose times the TCP offset that ``set_tcp`` sets) and :func:`tcp_jacobian`
its geometric Jacobian.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from kinergy.arrays import Array
from kinergy.dynamics.kinematics import flange_pose, jacobian
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot

__all__ = [
    "pose_matrix",
    "pose_vector",
    "rotation_about_z",
    "tcp_jacobian",
    "tcp_pose",
]


def pose_matrix(pose: ArrayLike) -> Array:
    """Homogeneous transforms from URScript poses.

    Parameters
    ----------
    pose : array_like, shape (..., 6)
        ``[x, y, z, rx, ry, rz]``: position (m) and rotation vector (rad).

    Returns
    -------
    ndarray, shape (..., 4, 4)
    """
    p = np.asarray(pose, dtype=float)
    if p.shape[-1:] != (6,):
        raise KinergyError(f"a pose has 6 numbers [x, y, z, rx, ry, rz], got shape {p.shape}")
    flat = p.reshape(-1, 6)
    out = np.zeros((flat.shape[0], 4, 4))
    out[:, :3, :3] = Rotation.from_rotvec(flat[:, 3:]).as_matrix()
    out[:, :3, 3] = flat[:, :3]
    out[:, 3, 3] = 1.0
    return out.reshape(*p.shape[:-1], 4, 4)


def pose_vector(transform: ArrayLike) -> Array:
    """URScript poses ``[x, y, z, rx, ry, rz]`` (m, rad; rotation angle in [0, pi]) of
    homogeneous transforms, shape (..., 4, 4) -> (..., 6)."""
    t = np.asarray(transform, dtype=float)
    flat = t.reshape(-1, 4, 4)
    rotvec = Rotation.from_matrix(flat[:, :3, :3]).as_rotvec()
    return np.concatenate([flat[:, :3, 3], rotvec], axis=1).reshape(*t.shape[:-2], 6)


def rotation_about_z(transform: ArrayLike, angle: ArrayLike) -> Array:
    """Transforms turned by ``angle`` (rad) about their own z axis (a tool's symmetry axis):
    ``T Rz(angle)``, broadcast, shape (..., 4, 4)."""
    t = np.asarray(transform, dtype=float)
    a = np.asarray(angle, dtype=float)
    rz = np.zeros((*a.shape, 4, 4))
    rz[..., 0, 0] = rz[..., 1, 1] = np.cos(a)
    rz[..., 1, 0] = np.sin(a)
    rz[..., 0, 1] = -rz[..., 1, 0]
    rz[..., 2, 2] = rz[..., 3, 3] = 1.0
    return np.asarray(t @ rz)


def tcp_pose(robot: Robot, q: ArrayLike, tcp: ArrayLike | None = None) -> Array:
    """Pose of the tool centre point in the base frame: the flange pose times ``tcp``.

    Parameters
    ----------
    robot : Robot
    q : array_like, shape (n,) or (N, n)
        Joint angles, rad.
    tcp : array_like, shape (4, 4), optional
        The TCP in the flange frame (URScript's ``set_tcp``); default the flange itself.

    Returns
    -------
    ndarray, shape (4, 4) or (N, 4, 4)
    """
    flange = flange_pose(robot, q)
    return flange if tcp is None else np.asarray(flange @ np.asarray(tcp, dtype=float))


def tcp_jacobian(robot: Robot, q: ArrayLike, tcp: ArrayLike | None = None) -> Array:
    """Geometric Jacobian of the tool centre point: ``[v; w] = J qd`` with ``v`` the TCP's
    velocity (m/s) and ``w`` the angular velocity (rad/s), base frame.

    Returns
    -------
    ndarray, shape (6, n) or (N, 6, n)
        Column i is ``[z_i x (p - o_i); z_i]``, ``p`` the TCP (the flange Jacobian with its
        linear rows moved to the TCP: ``v_tcp = v + w x r``).
    """
    return jacobian(robot, q, tcp)
