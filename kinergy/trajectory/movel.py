"""UR's tool-space moves, ``movel`` and ``movep``: the tool on straight lines.

A ``movel`` from tool pose ``A`` to ``B`` moves the tool centre point on the straight line from
``A``'s to ``B``'s position and turns it about the one fixed axis that takes ``A``'s orientation to
``B``'s (``R(s) = R_A exp(s [u]x)``, ``u`` the rotation vector of ``R_A^T R_B``), both on one
trapezoidal profile along the path: URScript's ``v`` and ``a`` (m/s, m/s^2) apply to the path
length ``L = max(|p_B - p_A|, |u|)`` (the position's metres or, for a move that mostly turns the
tool, the rotation's radians), as :func:`kinergy.trajectory.movej.trapezoid_timing` plans it.

Blends (``r`` > 0 between tool moves, ``movep``'s via points) follow kinergy's blending rule
(:func:`kinergy.trajectory.movej.blend_starts`): the next segment starts while the current one
brakes, and the two segments' displacements add up: positions as a sum, orientations as the
ordered product ``R_A exp(s_1 u_1) exp(s_2 u_2) ...``, so the pose is exact at every target
that is not blended and continuous (speed included) through every blend.

The joints follow from the analytic inverse kinematics (:mod:`kinergy.dynamics.ik`) in the branch
the move starts in, every sample shifted by ``2 pi`` to the value nearest a reference (the
straight joint-space interpolation of the segments' end joints); their speeds and accelerations
from the tool's twist through the TCP Jacobian: ``qd = J^-1 V``, ``qdd = J^-1 (A - Jdot qd)``
with ``Jdot qd`` in closed form (:func:`kinergy.dynamics.kinematics.axes_jacobian_rate`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from kinergy.arrays import Array
from kinergy.dynamics.ik import URGeometry, ik_branches
from kinergy.dynamics.kinematics import axes_jacobian, axes_jacobian_rate, tool_axes
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot

__all__ = [
    "ToolSegment",
    "joints_on_path",
    "segment_arrays",
    "tool_motion",
    "tool_segment",
]


#: the largest 1-norm condition number of the TCP Jacobian on a straight line; above it the line
#: passes (too near) a singularity
_MAX_COND = 1e8


@dataclass(frozen=True, eq=False)
class ToolSegment:
    """A straight tool move from ``start`` to ``end`` (TCP poses in the base frame, (4, 4)).

    Attributes
    ----------
    start, end : ndarray, shape (4, 4)
    shift : ndarray, shape (3,)
        Position change, m.
    turn : ndarray, shape (3,)
        Rotation vector of ``R_start^T R_end`` (in the start's frame), rad.
    length : float
        ``max(|shift|, |turn|)``: the path length the profile runs over (m, or rad).
    """

    start: Array
    end: Array
    shift: Array
    turn: Array
    length: float


def tool_segment(start: Array, end: Array) -> ToolSegment:
    """The straight tool move between two TCP poses (4, 4)."""
    shift, turn, length = segment_arrays(start[None], end[None])
    return ToolSegment(start, end, shift[0], turn[0], float(length[0]))


def segment_arrays(start: Array, end: Array) -> tuple[Array, Array, Array]:
    """Straight tool moves between TCP poses ``start`` and ``end`` (P, 4, 4), batched: their
    position changes (P, 3), rotation vectors in the start's frame (P, 3) and path lengths (P,)
    (:class:`ToolSegment`)."""
    shift = end[:, :3, 3] - start[:, :3, 3]
    relative = np.swapaxes(start[:, :3, :3], 1, 2) @ end[:, :3, :3]
    turn = Rotation.from_matrix(relative).as_rotvec()
    length = np.maximum(np.linalg.norm(shift, axis=1), np.linalg.norm(turn, axis=1))
    return shift, turn, length


def _rotations(rotvec: Array) -> Array:
    """Rotation matrices of rotation vectors (..., 3) -> (..., 3, 3)."""
    flat = rotvec.reshape(-1, 3)
    return Rotation.from_rotvec(flat).as_matrix().reshape(*rotvec.shape[:-1], 3, 3)


def tool_motion(
    start: Array, shift: Array, turn: Array, length: Array, s: Array, sd: Array, sdd: Array
) -> tuple[Array, Array, Array]:
    """TCP pose, twist and its derivative of superposed straight tool segments.

    Parameters
    ----------
    start : ndarray, shape (S, 4, 4) or (4, 4)
        The first segment's start pose (per sample, or one for all).
    shift, turn : ndarray, shape (S, G, 3) or (G, 3)
        Each segment's position change (m) and rotation vector (in its start's frame, rad)
        (:class:`ToolSegment`); consecutive: each starts where the previous ends.
    length : ndarray, shape (S, G) or (G,)
        Each segment's path length (:attr:`ToolSegment.length`).
    s, sd, sdd : ndarray, shape (S, G)
        Each segment's distance along its path (0 to ``length``), speed and acceleration at S
        samples (m, m/s, m/s^2 or rad, rad/s, rad/s^2).

    Returns
    -------
    pose : ndarray, shape (S, 4, 4)
    twist : ndarray, shape (S, 6)
        TCP velocity (m/s) and angular velocity (rad/s), base frame.
    accel : ndarray, shape (S, 6)
        Their time derivatives.
    """
    samples, groups = s.shape
    start = np.broadcast_to(start, (samples, 4, 4))
    shift = np.broadcast_to(shift, (samples, groups, 3))
    turn = np.broadcast_to(turn, (samples, groups, 3))
    length = np.broadcast_to(length, (samples, groups))
    rot = start[:, :3, :3].copy()
    pos = start[:, :3, 3].copy()
    vel, acc, omega, alpha = (np.zeros((samples, 3)) for _ in range(4))
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(length > 0.0, 1.0 / length, 0.0)
    for g in range(groups):
        frac, fd, fdd = (np.nan_to_num(x[:, g] * scale[:, g])[:, None] for x in (s, sd, sdd))
        pos += frac * shift[:, g]
        vel += fd * shift[:, g]
        acc += fdd * shift[:, g]
        axis = np.einsum("sij,sj->si", rot, turn[:, g])  # the segment's axis, base frame
        alpha += axis * fdd + np.cross(omega, axis) * fd
        omega = omega + axis * fd
        rot = rot @ _rotations(frac * turn[:, g])
    pose = np.zeros((samples, 4, 4))
    pose[:, :3, :3] = rot
    pose[:, :3, 3] = pos
    pose[:, 3, 3] = 1.0
    return pose, np.hstack([vel, omega]), np.hstack([acc, alpha])


def _nearest_shift(q: Array, ref: Array) -> Array:
    """``q`` shifted by multiples of ``2 pi`` to the values nearest ``ref`` (broadcast)."""
    return np.asarray(q + 2.0 * np.pi * np.round((ref - q) / (2.0 * np.pi)))


def joints_on_path(
    robot: Robot,
    geometry: URGeometry,
    tcp: Array,
    branch: int,
    pose: Array,
    twist: Array,
    accel: Array,
    ref: Array,
) -> tuple[Array, Array, Array]:
    """Joint angles, speeds and accelerations that put the TCP on a sampled tool motion.

    Parameters
    ----------
    robot : Robot
    geometry : URGeometry
        :func:`kinergy.dynamics.ik.ur_geometry` of ``robot``.
    tcp : ndarray, shape (4, 4)
        The TCP in the flange frame.
    branch : int
        The inverse-kinematics branch the move runs in (0-7).
    pose, twist, accel : ndarray, shapes (S, 4, 4), (S, 6), (S, 6)
        :func:`tool_motion`.
    ref : ndarray, shape (S, 6)
        Joints each sample is shifted nearest to (by ``2 pi``), rad.

    Returns
    -------
    q, qd, qdd : ndarray, shape (S, 6)

    Raises
    ------
    KinergyError
        A sample out of the branch's reach or at a singularity (the caller names the line).
    """
    flange = pose @ np.linalg.inv(tcp)
    q = ik_branches(geometry, flange, hint6=ref[:, 5], branches=[branch])[:, 0]
    if np.any(np.isnan(q)):
        raise KinergyError("the straight line leaves the arm's reach in its configuration")
    q = _nearest_shift(q, ref)
    z, o, tip = tool_axes(robot, q, tcp)
    jac = axes_jacobian(z, o, tip)
    try:
        inv: Array = np.asarray(np.linalg.inv(jac), dtype=float)
    except np.linalg.LinAlgError:
        inv = np.full_like(jac, np.inf)
    cond = _norm1(jac) * _norm1(inv)
    if not np.all(cond <= _MAX_COND):
        raise KinergyError("the straight line passes a singularity of the arm")
    qd = np.einsum("sij,sj->si", inv, twist)
    qdd = np.einsum("sij,sj->si", inv, accel - axes_jacobian_rate(z, o, tip, qd))
    return q, qd, qdd


def _norm1(m: Array) -> Array:
    """1-norms (largest column sum of magnitudes) of matrices (S, 6, 6) -> (S,)."""
    return np.asarray(np.abs(m).sum(axis=-2).max(axis=-1))
