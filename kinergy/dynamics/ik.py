"""Analytic inverse kinematics of UR arms: the eight branches and the ``2 pi`` choices.

A UR arm (UR3e, UR5e, UR10e, UR16e, CB3) has standard DH parameters with
``alpha = (pi/2, 0, 0, pi/2, -pi/2, 0)``, ``a = (0, a2, a3, 0, 0, 0)`` and
``d = (d1, 0, 0, d4, d5, d6)``: joints 2-4 turn about parallel axes and the wrist centre is offset
by ``d4`` from their plane. A flange pose ``T`` (frame 0) then has up to eight joint solutions,
found in closed form from the geometry of that chain:

1. the point ``p5 = p6 - d6 z6`` (origin of frame 5) lies ``d4`` off the arm's plane, whose normal
   is ``z1 = (sin q1, -cos q1, 0)``: ``r sin(q1 - phi) = d4`` with ``(r, phi)`` the polar form of
   ``p5``'s x and y, two solutions for q1 (the *shoulder* branch);
2. ``z6 . z1 = cos q5``: two solutions for q5 (the *wrist* branch);
3. ``z1`` seen from frame 6 is ``(cos q6 sin q5, -sin q6 sin q5, cos q5)``: q6 (undetermined at the
   wrist singularity ``sin q5 = 0``, where a hint is used);
4. frame 4's origin seen from frame 1 is ``(a2 c2 + a3 c23, a2 s2 + a3 s23, d4)``: a planar
   two-link arm, two solutions for q3 (the *elbow* branch), then q2, and q4 from the sum
   ``q2 + q3 + q4`` that frame 4's x axis gives.

Branches are numbered ``4 shoulder + 2 wrist + elbow`` (0-7). Each solution is returned in
``(-pi, pi]``; a UR joint's range of +-2 pi holds two values of each angle, which
:func:`wrap_near` and :func:`wrap_choices` choose between. :func:`nearest_solution` is the UR
controller's choice for a pose target: the solution, over the branches and the ``2 pi`` shifts
within the joint limits, closest to the current joints (URScript's ``get_inverse_kin(x, qnear)``).
Other 6R arms have no closed form here: :func:`ur_geometry` says so in one line.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot

__all__ = [
    "BRANCHES",
    "URGeometry",
    "branch_of",
    "ik_branches",
    "joint_limits",
    "nearest_solution",
    "ur_geometry",
    "wrap_choices",
    "wrap_near",
]


#: number of closed-form branches of a UR arm (shoulder x wrist x elbow)
BRANCHES = 8

_UR_ALPHA = np.array([np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0])
_TOL = 1e-9


@dataclass(frozen=True)
class URGeometry:
    """The DH lengths of a UR arm (m), its joint offsets (rad), and the constant transforms
    around the chain: ``base`` (frame 0 in the base frame) and ``flange`` (in frame 6)."""

    d1: float
    a2: float
    a3: float
    d4: float
    d5: float
    d6: float
    offset: Array
    base: Array
    flange: Array


def ur_geometry(robot: Robot) -> URGeometry:
    """The UR geometry of ``robot``.

    Raises
    ------
    KinergyError
        The robot is not a six-joint arm with UR's DH structure (see the module docstring).
    """
    joints = robot.joints
    d = np.array([j.d for j in joints])
    a = np.array([j.a for j in joints])
    alpha = np.array([j.alpha for j in joints])
    ur_like = (
        robot.convention == "dh"
        and robot.n == 6
        and np.allclose(alpha, _UR_ALPHA, atol=1e-9)
        and np.allclose(a[[0, 3, 4, 5]], 0.0, atol=1e-12)
        and np.allclose(d[[1, 2]], 0.0, atol=1e-12)
        and abs(a[1]) > 0.0
        and abs(a[2]) > 0.0
    )
    if not ur_like:
        raise KinergyError(
            f"{robot.name}: inverse kinematics of pose targets needs a UR arm (six joints, "
            "standard DH with alpha = (pi/2, 0, 0, pi/2, -pi/2, 0)); use joint targets"
        )
    return URGeometry(
        d1=float(d[0]),
        a2=float(a[1]),
        a3=float(a[2]),
        d4=float(d[3]),
        d5=float(d[4]),
        d6=float(d[5]),
        offset=np.array([j.offset for j in joints]),
        base=np.asarray(robot.base),
        flange=np.asarray(robot.flange),
    )


def _hom(rot_z: Array, d: float, alpha: float) -> Array:
    """Batched DH transforms ``Rz(theta) Tz(d) Rx(alpha)`` (a = 0) for angles (N,)."""
    c, s = np.cos(rot_z), np.sin(rot_z)
    ca, sa = np.cos(alpha), np.sin(alpha)
    out = np.zeros((*rot_z.shape, 4, 4))
    out[..., 0, 0], out[..., 0, 1], out[..., 0, 2] = c, -s * ca, s * sa
    out[..., 1, 0], out[..., 1, 1], out[..., 1, 2] = s, c * ca, -c * sa
    out[..., 2, 1], out[..., 2, 2], out[..., 2, 3] = sa, ca, d
    out[..., 3, 3] = 1.0
    return out


def _inverse(t: Array) -> Array:
    """Inverse of homogeneous transforms (..., 4, 4)."""
    out = np.zeros_like(t)
    rt = np.swapaxes(t[..., :3, :3], -1, -2)
    out[..., :3, :3] = rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", rt, t[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def _wrap(angle: Array) -> Array:
    """Angles into (-pi, pi]."""
    return np.asarray(np.pi - np.mod(np.pi - angle, 2.0 * np.pi))


def _wrist(g: URGeometry, t: Array, q1: Array, sign5: float, hint6: Array) -> tuple[Array, ...]:
    """q5 and q6 (steps 2 and 3) for poses ``t`` (N, 4, 4) of frame 6 and shoulder angles q1."""
    z1 = np.stack([np.sin(q1), -np.cos(q1), np.zeros_like(q1)], axis=-1)
    c5 = np.einsum("ni,ni->n", t[:, :3, 2], z1)
    ok = np.abs(c5) <= 1.0 + 1e-9
    q5 = sign5 * np.arccos(np.clip(c5, -1.0, 1.0))
    s5 = np.sin(q5)
    x = np.einsum("ni,ni->n", t[:, :3, 0], z1)
    y = np.einsum("ni,ni->n", t[:, :3, 1], z1)
    singular = np.abs(s5) < 1e-10
    safe = np.where(singular, 1.0, s5)
    q6 = np.where(singular, hint6, np.arctan2(-y / safe, x / safe))
    return q5, q6, ok


def _arm(
    g: URGeometry, t: Array, q1: Array, q5: Array, q6: Array, elbow: float
) -> tuple[Array, Array, Array, NDArray[np.bool_]]:
    """q2, q3, q4 (step 4): the planar arm from frame 1 to frame 4, and where it reaches."""
    t14 = (
        _inverse(_hom(q1, g.d1, np.pi / 2))
        @ t
        @ _inverse(_hom(q6, g.d6, 0.0))
        @ _inverse(_hom(q5, g.d5, -np.pi / 2))
    )
    x, y = t14[:, 0, 3], t14[:, 1, 3]
    c3 = (x**2 + y**2 - g.a2**2 - g.a3**2) / (2.0 * g.a2 * g.a3)
    ok = np.abs(c3) <= 1.0 + 1e-9
    q3 = elbow * np.arccos(np.clip(c3, -1.0, 1.0))
    q2 = np.arctan2(y, x) - np.arctan2(g.a3 * np.sin(q3), g.a2 + g.a3 * np.cos(q3))
    q234 = np.arctan2(t14[:, 1, 0], t14[:, 0, 0])
    return np.asarray(q2, dtype=float), q3, np.asarray(q234 - q2 - q3, dtype=float), ok


def ik_branches(
    g: URGeometry,
    flange: ArrayLike,
    *,
    hint6: ArrayLike | None = None,
    branches: ArrayLike | None = None,
) -> Array:
    """Joint solutions of flange poses, all eight branches or the ones asked for.

    Parameters
    ----------
    g : URGeometry
    flange : array_like, shape (N, 4, 4) or (4, 4)
        Flange poses in the robot's base frame.
    hint6 : array_like, shape (N,) or scalar, optional
        q6 where the wrist is singular (``sin q5 = 0``: only q4 + q6 is fixed), rad; default 0.
    branches : array_like of int, shape (B,), optional
        The branches to solve (0-7); default all eight. A sampled straight line needs one.

    Returns
    -------
    ndarray, shape (N, B, 6) or (B, 6)
        Joint angles (rad, each in (-pi, pi]), in the order of ``branches`` (branch
        ``4 shoulder + 2 wrist + elbow``); NaN rows where a branch cannot reach the pose.
    """
    f = np.asarray(flange, dtype=float)
    single = f.ndim == 2
    f = f.reshape(-1, 4, 4)
    wanted = np.arange(BRANCHES) if branches is None else np.asarray(branches, dtype=int)
    if np.any((wanted < 0) | (wanted >= BRANCHES)):
        raise KinergyError(f"inverse kinematics: branches are 0-7, got {wanted.tolist()}")
    t = _inverse(g.base) @ f @ _inverse(g.flange)  # frame 6 in frame 0
    big_n = t.shape[0]
    hint = np.broadcast_to(np.asarray(0.0 if hint6 is None else hint6, dtype=float), (big_n,))
    hint = hint + g.offset[5]
    p5 = t[:, :3, 3] - g.d6 * t[:, :3, 2]
    r = np.hypot(p5[:, 0], p5[:, 1])
    phi = np.arctan2(p5[:, 1], p5[:, 0])
    ratio = g.d4 / np.maximum(r, 1e-300)
    reach1 = np.abs(ratio) <= 1.0 + 1e-9
    beta = np.arcsin(np.clip(ratio, -1.0, 1.0))
    out = np.full((big_n, wanted.size, 6), np.nan)
    for column, b in enumerate(wanted):
        shoulder, wrist, elbow = int(b) // 4, (int(b) // 2) % 2, int(b) % 2
        q1 = phi + beta if shoulder == 0 else phi + np.pi - beta
        q5, q6, ok5 = _wrist(g, t, q1, 1.0 - 2.0 * wrist, hint)
        q2, q3, q4, ok3 = _arm(g, t, q1, q5, q6, 1.0 - 2.0 * elbow)
        theta = np.stack([q1, q2, q3, q4, q5, q6], axis=1)
        ok = reach1 & ok5 & ok3
        out[:, column] = np.where(ok[:, None], _wrap(theta - g.offset), np.nan)
    return out[0] if single else out


def joint_limits(robot: Robot) -> tuple[Array, Array]:
    """Lower and upper joint angles, rad, shape (n,) each."""
    lim = np.array([j.limits.position for j in robot.joints])
    return lim[:, 0], lim[:, 1]


def wrap_near(q: ArrayLike, ref: ArrayLike, lo: ArrayLike, hi: ArrayLike) -> Array:
    """Each angle shifted by a multiple of ``2 pi`` to the value closest to ``ref`` within
    ``[lo, hi]`` (broadcast; NaN where no shift fits). The pose does not change."""
    q, ref = np.broadcast_arrays(np.asarray(q, dtype=float), np.asarray(ref, dtype=float))
    centred = q + 2.0 * np.pi * np.round((ref - q) / (2.0 * np.pi))
    values = wrap_choices(centred, lo, hi, most=2)
    dist = np.abs(values - ref[..., None])
    dist = np.where(np.isnan(dist), np.inf, dist)
    pick = np.argmin(dist, axis=-1)
    out = np.take_along_axis(values, pick[..., None], axis=-1)[..., 0]
    return np.asarray(out)


def wrap_choices(q: ArrayLike, lo: ArrayLike, hi: ArrayLike, *, most: int = 3) -> Array:
    """The values ``q + 2 pi m`` within ``[lo, hi]``, for |m| <= ``most``.

    Returns
    -------
    ndarray, shape (..., 2 most + 1)
        NaN where a shift falls outside the limits.
    """
    q = np.asarray(q, dtype=float)
    m = np.arange(-most, most + 1) * 2.0 * np.pi
    values = q[..., None] + m
    lo_ = np.asarray(lo, dtype=float)[..., None]
    hi_ = np.asarray(hi, dtype=float)[..., None]
    return np.where((values >= lo_ - 1e-9) & (values <= hi_ + 1e-9), values, np.nan)


def nearest_solution(
    robot: Robot, g: URGeometry, flange: ArrayLike, qnear: ArrayLike
) -> tuple[Array, int]:
    """The UR controller's solution for a flange pose: over the eight branches and the ``2 pi``
    shifts within the joint limits, the joints closest to ``qnear`` (Euclidean, rad).

    Parameters
    ----------
    robot : Robot
    g : URGeometry
    flange : array_like, shape (4, 4)
        The flange pose in the base frame.
    qnear : array_like, shape (6,)
        The joints to be near (the current joints, or URScript's ``qnear``), rad.

    Returns
    -------
    q : ndarray, shape (6,)
    branch : int

    Raises
    ------
    KinergyError
        No branch reaches the pose within the joint limits (the message is completed by the
        caller with the program line).
    """
    qn = np.asarray(qnear, dtype=float)
    lo, hi = joint_limits(robot)
    sols = ik_branches(g, flange, hint6=qn[5])  # (8, 6)
    shifted = wrap_near(sols, qn, lo, hi)
    dist = np.linalg.norm(shifted - qn, axis=1)
    dist = np.where(np.isnan(dist), np.inf, dist)
    b = int(np.argmin(dist))
    if not np.isfinite(dist[b]):
        reach = np.any(~np.isnan(sols[:, 0]))
        raise KinergyError(
            "the pose is out of reach of the arm"
            if not reach
            else "no solution for the pose lies within the joint limits"
        )
    return shifted[b], b


def branch_of(g: URGeometry, q: ArrayLike, flange: ArrayLike) -> int:
    """The branch (0-7) whose solution of ``flange`` (the pose of ``q``) equals ``q`` up to
    ``2 pi`` shifts: the configuration of a joint target."""
    qq = np.asarray(q, dtype=float)
    sols = ik_branches(g, flange, hint6=qq[5])
    diff = np.abs(_wrap(sols - qq))
    err = np.where(np.isnan(diff), np.inf, diff).max(axis=1)
    return int(np.argmin(err))
