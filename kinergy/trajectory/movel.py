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
with ``Jdot qd`` a central difference of ``J`` along ``qd``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from kinergy.dynamics.ik import URGeometry, ik_branches
from kinergy.dynamics.poses import tcp_jacobian
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot

__all__ = ["ToolSegment", "joints_on_path", "tool_motion", "tool_segment"]

Array = NDArray[np.float64]

#: step of the central difference of the Jacobian along qd, s
_JDOT_STEP = 1e-5


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
    shift = end[:3, 3] - start[:3, 3]
    turn = Rotation.from_matrix(start[:3, :3].T @ end[:3, :3]).as_rotvec()
    length = float(max(np.linalg.norm(shift), np.linalg.norm(turn)))
    return ToolSegment(start, end, shift, turn, length)


def _skew_exp(axis: Array) -> Array:
    """Rotation matrices of rotation vectors (..., 3) -> (..., 3, 3)."""
    flat = axis.reshape(-1, 3)
    return Rotation.from_rotvec(flat).as_matrix().reshape(*axis.shape[:-1], 3, 3)


def tool_motion(
    segments: list[ToolSegment], s: Array, sd: Array, sdd: Array
) -> tuple[Array, Array, Array]:
    """TCP pose, twist and its derivative of superposed tool segments.

    Parameters
    ----------
    segments : list of ToolSegment, length G
        Consecutive segments (each starts where the previous ends).
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
    samples = s.shape[0]
    rot = np.broadcast_to(segments[0].start[:3, :3], (samples, 3, 3)).copy()
    pos = np.broadcast_to(segments[0].start[:3, 3], (samples, 3)).copy()
    vel = np.zeros((samples, 3))
    acc = np.zeros((samples, 3))
    omega = np.zeros((samples, 3))
    alpha = np.zeros((samples, 3))
    for g, seg in enumerate(segments):
        if seg.length <= 0.0:
            continue
        frac, fd, fdd = s[:, g] / seg.length, sd[:, g] / seg.length, sdd[:, g] / seg.length
        pos += frac[:, None] * seg.shift
        vel += fd[:, None] * seg.shift
        acc += fdd[:, None] * seg.shift
        axis = rot @ seg.turn  # this segment's axis in the base frame, (S, 3)
        alpha += axis * fdd[:, None] + np.cross(omega, axis) * fd[:, None]
        omega = omega + axis * fd[:, None]
        rot = rot @ _skew_exp(frac[:, None] * seg.turn)
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
    q = ik_branches(geometry, flange, hint6=ref[:, 5])[:, branch]
    if np.any(np.isnan(q)):
        raise KinergyError("the straight line leaves the arm's reach in its configuration")
    q = _nearest_shift(q, ref)
    jac = tcp_jacobian(robot, q, tcp)
    cond = np.linalg.cond(jac)
    if np.any(cond > 1e8):
        raise KinergyError("the straight line passes a singularity of the arm")
    qd = np.linalg.solve(jac, twist[..., None])[..., 0]
    h = _JDOT_STEP
    jdot_qd = (
        np.einsum("sij,sj->si", tcp_jacobian(robot, q + h * qd, tcp), qd)
        - np.einsum("sij,sj->si", tcp_jacobian(robot, q - h * qd, tcp), qd)
    ) / (2.0 * h)
    qdd = np.linalg.solve(jac, (accel - jdot_qd)[..., None])[..., 0]
    return q, np.asarray(qd, dtype=float), np.asarray(qdd, dtype=float)
