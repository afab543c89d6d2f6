"""The constant transforms of a serial chain under kinergy's two conventions, and the way back
from joint axes to modified-DH parameters.

``dh`` (standard Denavit-Hartenberg): frame i = frame i-1 · Rz(q_i + offset_i) · Tz(d_i) · Tx(a_i)
· Rx(alpha_i). ``mdh`` (Craig's modified DH): frame i = frame i-1 · Rx(alpha_{i-1}) · Tx(a_{i-1}) ·
Rz(q_i + offset_i) · Tz(d_i); a robot file stores a_{i-1} and alpha_{i-1} with joint i. The dynamics
(:mod:`kinergy.dynamics.chain`), the URDF reader and the exports all place links with these.

:func:`mdh_frames` and :func:`mdh_parameters` go the other way, from joint axes given in a common
frame (a URDF's, at q = 0) to Craig's frames and parameters, without approximation: ``z_i`` along
the axis, so that ``q`` keeps its sign; ``x_i`` along the common normal from axis i to axis i+1.
For intersecting axes ``x_i`` is ``z_i x z_{i+1}``; for parallel axes the common normal is not
unique and the one through the previous frame's foot point is taken (``d = 0`` where it is
free). Frame 0 coincides with frame 1 at q = 0 (``a_0 = alpha_0 = d_1 = offset_1 = 0``).

Poses in files are ``xyz`` and fixed-axis roll-pitch-yaw ``rpy`` (URDF's convention):
:func:`rpy_matrix` and :func:`matrix_rpy`.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from kinergy.arrays import Array
from kinergy.model.robot import Robot

__all__ = [
    "PARALLEL_TOLERANCE",
    "dh_transform",
    "joint_transforms",
    "matrix_rpy",
    "mdh_frames",
    "mdh_parameters",
    "mdh_transform",
    "robot_transforms",
    "rpy_matrix",
]

#: Consecutive axes closer than this to parallel (|sin| of the angle between them) are treated as
#: parallel. URDF files often write pi/2 as 1.5708 (3.7e-6 rad off); taking such axes as skew would
#: put the common normal kilometres away and ruin the numerics of every algorithm.
PARALLEL_TOLERANCE = 1e-5


def rpy_matrix(rpy: Any) -> np.ndarray:
    """Rotation (3, 3) from fixed-axis roll, pitch, yaw in rad (URDF's ``rpy``): ``Rz(y) Ry(p) Rx(r)``."""
    from scipy.spatial.transform import Rotation  # heavy (0.2 s): imported on first use

    return np.asarray(Rotation.from_euler("xyz", [float(v) for v in rpy]).as_matrix())


def matrix_rpy(rot: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw (rad, shape (3,)) of a rotation matrix, the inverse of :func:`rpy_matrix`
    (pitch in [-pi/2, pi/2]; at the gimbal lock one of the angles is set to 0, and the angles
    still give back ``rot``)."""
    from scipy.spatial.transform import Rotation  # heavy (0.2 s): imported on first use

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # scipy's gimbal-lock notice
        return np.asarray(Rotation.from_matrix(rot).as_euler("xyz"))


def mdh_transform(a: float, alpha: float, offset: float, d: float) -> Array:
    """``Rx(alpha) · Tx(a) · Rz(offset) · Tz(d)``, shape (4, 4): frame i in frame i-1 at q_i = 0.

    Parameters
    ----------
    a, d : float
        a_{i-1} and d_i, m.
    alpha, offset : float
        alpha_{i-1} and offset_i, rad.
    """
    ca, sa, ct, st = np.cos(alpha), np.sin(alpha), np.cos(offset), np.sin(offset)
    return np.array(
        [
            [ct, -st, 0.0, a],
            [ca * st, ca * ct, -sa, -sa * d],
            [sa * st, sa * ct, ca, ca * d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def dh_transform(a: float, alpha: float, offset: float, d: float) -> Array:
    """``Rz(offset) · Tz(d) · Tx(a) · Rx(alpha)``, shape (4, 4): standard DH frame i in frame i-1
    at q_i = 0.

    Parameters
    ----------
    a, d : float
        a_i and d_i, m.
    alpha, offset : float
        alpha_i and offset_i, rad.
    """
    ca, sa, ct, st = np.cos(alpha), np.sin(alpha), np.cos(offset), np.sin(offset)
    return np.array(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0.0, sa, ca, d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def joint_transforms(convention: str, rows: Array) -> tuple[Array, Array]:
    """The constant transforms of a chain: link frame i is ``F_{i-1} · P_i · Rz(q_i) · C_i``.

    ``dh``: ``P_i = I``, ``C_i`` = :func:`dh_transform`; ``mdh``: ``P_i`` = :func:`mdh_transform`,
    ``C_i = I`` (:func:`kinergy.dynamics.chain.make_chain` builds its chain from them).
    Joint i turns about the z axis of ``F_{i-1} · P_i``.

    Parameters
    ----------
    convention : {'dh', 'mdh'}
    rows : ndarray, shape (n, 4)
        ``(a, alpha, offset, d)`` of each joint as the robot stores them (m, rad).

    Returns
    -------
    pre, post : ndarray, shape (n, 4, 4)
        ``P_i`` and ``C_i``.
    """
    n = len(rows)
    pre = np.tile(np.eye(4), (n, 1, 1))
    post = np.tile(np.eye(4), (n, 1, 1))
    for i, (a, alpha, offset, d) in enumerate(rows):
        if convention == "dh":
            post[i] = dh_transform(a, alpha, offset, d)
        else:
            pre[i] = mdh_transform(a, alpha, offset, d)
    return pre, post


def robot_transforms(robot: Robot) -> tuple[Array, Array]:
    """:func:`joint_transforms` of ``robot``'s joints: ``P_i`` and ``C_i``, each (n, 4, 4)."""
    rows = np.array([(j.a, j.alpha, j.offset, j.d) for j in robot.joints])
    return joint_transforms(robot.convention, rows)


def _closest_points(p1: Array, z1: Array, p2: Array, z2: Array) -> tuple[Array, Array]:
    """Feet of the common normal of two non-parallel lines ``p + t z`` (unit ``z``)."""
    w = p1 - p2
    b, d1, e = z1 @ z2, z1 @ w, z2 @ w
    denom = 1.0 - b * b
    return p1 + (b * e - d1) / denom * z1, p2 + (e - b * d1) / denom * z2


def _perpendicular(z: Array, guess: Array) -> Array:
    """A unit vector perpendicular to unit ``z``: ``guess`` made perpendicular, else a root axis."""
    for candidate in (guess, np.eye(3)[0], np.eye(3)[1]):
        v = candidate - z * (z @ candidate)
        norm = np.linalg.norm(v)
        if norm > 1e-6:
            return v / norm
    raise AssertionError("unreachable: x and y cannot both be parallel to z")


def mdh_frames(axes: Array, points: Array) -> Array:
    """Modified-DH frames for joint axes given in a common frame, at q = 0.

    Parameters
    ----------
    axes : ndarray, shape (n, 3)
        Unit direction of each joint axis; becomes the frame's z axis (positive q turns the
        same way as in the source description).
    points : ndarray, shape (n, 3)
        A point on each axis, m.

    Returns
    -------
    ndarray, shape (n, 4, 4)
        Pose of MDH frame i (i = 1..n) in the common frame: origin on axis i, x along the common
        normal to axis i+1 (pointing towards it, so a_i >= 0). Parallel axes: the normal through
        the previous foot point (the first axis: through ``points[0]``). Intersecting or collinear
        axes: x is ``z_i x z_{i+1}`` or carried over from the previous frame. The last frame's
        origin is the previous normal's foot on the last axis and its x that normal's direction.
    """
    n = len(axes)
    frames = np.tile(np.eye(4), (n, 1, 1))
    foot = np.asarray(points[0], dtype=float)  # where the previous common normal meets axis i
    x_prev = np.eye(3)[0]
    for i in range(n):
        z = axes[i]
        origin = foot
        if i + 1 < n:
            z_next, p_next = axes[i + 1], points[i + 1]
            normal = np.cross(z, z_next)
            sin = np.linalg.norm(normal)
            if sin > PARALLEL_TOLERANCE:
                origin, foot = _closest_points(points[i], z, p_next, z_next)
                x = normal / sin
                if x @ (foot - origin) < 0.0:
                    x = -x
            else:
                v = p_next - origin
                v = v - z * (z @ v)
                dist = np.linalg.norm(v)
                x = v / dist if dist > 1e-12 else _perpendicular(z, x_prev)
                foot = origin + v
        else:
            x = _perpendicular(z, x_prev)
        frames[i, :3, 0] = x
        frames[i, :3, 1] = np.cross(z, x)
        frames[i, :3, 2] = z
        frames[i, :3, 3] = origin
        x_prev = x
    return frames


def mdh_parameters(frames: Array) -> Array:
    """MDH parameters joining consecutive frames; frame 0 is taken equal to frame 1.

    Parameters
    ----------
    frames : ndarray, shape (n, 4, 4)
        MDH frames 1..n at q = 0 (from :func:`mdh_frames`), in any common frame.

    Returns
    -------
    ndarray, shape (n, 4)
        Rows ``(a_{i-1}, alpha_{i-1}, offset_i, d_i)`` (m, rad, rad, m) such that
        ``frames[i] = frames[i-1] · mdh_transform(*row_i)``; the first row is zeros.
    """
    n = len(frames)
    params = np.zeros((n, 4))
    for i in range(1, n):
        rel = np.linalg.solve(frames[i - 1], frames[i])
        alpha = np.arctan2(-rel[1, 2], rel[2, 2])
        offset = np.arctan2(-rel[0, 1], rel[0, 0])
        d = -np.sin(alpha) * rel[1, 3] + np.cos(alpha) * rel[2, 3]
        params[i] = (rel[0, 3], alpha, offset, d)
    params[np.abs(params) < 1e-14] = 0.0
    return params
