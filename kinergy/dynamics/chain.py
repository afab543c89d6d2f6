"""What every dynamics algorithm needs from a robot: constant joint geometry, link inertials,
and validated joint-state arrays.

Both DH conventions are written as one chain: link frame i is
``F_i = F_{i-1} · P_i · Rz(q_i) · C_i`` with constant transforms

- ``dh``:  ``P_i = I``,  ``C_i = Rz(offset_i) · Tz(d_i) · Tx(a_i) · Rx(alpha_i)``
- ``mdh``: ``P_i = Rx(alpha_{i-1}) · Tx(a_{i-1}) · Rz(offset_i) · Tz(d_i)``,  ``C_i = I``

(:mod:`kinergy.model.frames`; for ``mdh`` Rz(q) commutes with Rz(offset) Tz(d)). Joint i turns about the z axis
of ``F_{i-1} · P_i``. Frame 0 sits at ``robot.base`` in the base frame.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass
from typing import TypeGuard

import numpy as np
from numpy.typing import ArrayLike

from kinergy import checks
from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.model.frames import robot_transforms
from kinergy.model.robot import Robot, inertia_matrix

__all__ = [
    "Chain",
    "KernelData",
    "LinkInertials",
    "check_state",
    "contiguous_state",
    "gravity_in_frame0",
    "kernel_data",
    "kernel_geometry",
    "link_inertials",
    "make_chain",
    "output_array",
    "z_first",
]


@dataclass(frozen=True)
class Chain:
    """Constant geometry of a robot's joints.

    Attributes
    ----------
    pre, post : ndarray, shape (n, 4, 4)
        ``P_i`` and ``C_i`` of the module docstring.
    axis : ndarray, shape (n, 3)
        Joint axis direction in link frame i (``R_C^T e_z``).
    point : ndarray, shape (n, 3)
        A point of the joint axis in link frame i (``-R_C^T p_C``).
    base, flange : ndarray, shape (4, 4)
        Pose of frame 0 in the base frame; pose of the flange in frame n.
    gravity0 : ndarray, shape (3,)
        Gravity in frame 0, m/s^2.
    """

    pre: Array
    post: Array
    axis: Array
    point: Array
    base: Array
    flange: Array
    gravity0: Array


def make_chain(robot: Robot) -> Chain:
    """Constant geometry of ``robot`` (a few 4x4 products; cheap): ``P_i`` and ``C_i`` of
    :func:`kinergy.model.frames.robot_transforms`."""
    pre, post = robot_transforms(robot)
    rc = post[:, :3, :3]
    pc = post[:, :3, 3]
    axis = rc[:, 2, :]  # R_C^T e_z = third row of R_C
    point = -np.einsum("nji,nj->ni", rc, pc)
    gravity0 = robot.base[:3, :3].T @ robot.gravity
    return Chain(pre, post, axis, point, robot.base, np.asarray(robot.flange), gravity0)


_E1 = np.diag([1.0, 1.0, 0.0])  # Rz(q) = cos q E1 + sin q E2 + E3
_E2 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
_E3 = np.diag([0.0, 0.0, 1.0])


def kernel_geometry(chain: Chain) -> tuple[Array, Array, Array, Array, Array, Array, Array, Array]:
    """Constants for :mod:`kinergy.dynamics._kernels`: ``(A, B, C, pa, pb, pc, axis, axis_v)``
    with the pose of F_i in F_{i-1} ``R_i = c A_i + s B_i + C_i``, ``p_i = c pa_i + s pb_i + pc_i``
    and the motion subspace ``S_i = (axis_i, point_i x axis_i)``."""
    rp, pp = chain.pre[:, :3, :3], chain.pre[:, :3, 3]
    rc, pc = chain.post[:, :3, :3], chain.post[:, :3, 3]
    a, b, c = (rp @ e @ rc for e in (_E1, _E2, _E3))
    pa = np.einsum("nij,nj->ni", rp, (_E1 @ pc.T).T)
    pb = np.einsum("nij,nj->ni", rp, (_E2 @ pc.T).T)
    pcc = pp + np.einsum("nij,nj->ni", rp, (_E3 @ pc.T).T)
    axis_v = np.cross(chain.point, chain.axis)
    return tuple(np.ascontiguousarray(x) for x in (a, b, c, pa, pb, pcc, chain.axis, axis_v))  # type: ignore[return-value]


def z_first(geo: tuple[Array, ...]) -> bool:
    """Whether every link pose of :func:`kernel_geometry`'s ``geo`` is ``Rz(q)`` first, then a
    constant transform (standard DH: ``pre`` is the identity): exactly, ``B = E2 A``, ``A`` and
    ``B`` without a third row, ``C`` with only its third, and the same for ``pa, pb, pc``. The
    kernels then form each pose from four products per column (``_kernels._link_pose``)."""
    a, b, c, pa, pb, pc = geo[:6]
    return bool(
        not np.any(a[:, 2])
        and not np.any(b[:, 2])
        and not np.any(c[:, :2])
        and np.array_equal(b[:, 0], -a[:, 1])
        and np.array_equal(b[:, 1], a[:, 0])
        and not np.any(pa[:, 2])
        and not np.any(pb[:, 2])
        and not np.any(pc[:, :2])
        and np.array_equal(pb[:, 0], -pa[:, 1])
        and np.array_equal(pb[:, 1], pa[:, 0])
    )


@dataclass(frozen=True)
class LinkInertials:
    """Rigid-body data of every link in its own frame, the payload merged into the last link.

    Attributes
    ----------
    mass : ndarray, shape (n,)
        kg.
    com : ndarray, shape (n, 3)
        m, link frame.
    inertia_com : ndarray, shape (n, 3, 3)
        About the centre of mass, link-frame axes, kg m^2.
    """

    mass: Array
    com: Array
    inertia_com: Array

    @property
    def first_moment(self) -> Array:
        """m c, shape (n, 3), kg m."""
        return self.mass[:, None] * self.com

    @property
    def inertia_origin(self) -> Array:
        """Inertia about the link frame origin, shape (n, 3, 3) (parallel-axis theorem)."""
        c = self.com
        shift = np.einsum("ni,ni->n", c, c)[:, None, None] * np.eye(3) - np.einsum(
            "ni,nj->nij", c, c
        )
        return self.inertia_com + self.mass[:, None, None] * shift


def _parallel(mass: float, com: Array, about: Array) -> Array:
    d = com - about
    return mass * (float(d @ d) * np.eye(3) - np.outer(d, d))


def link_inertials(robot: Robot, *, include_payload: bool = True) -> LinkInertials:
    """Masses, centres of mass and inertias of the links; the payload (if any) merged rigidly
    into the last link, expressed in its frame through ``robot.flange``."""
    mass = np.array([j.link.mass for j in robot.joints])
    com = np.array([j.link.com for j in robot.joints])
    inertia = np.array([inertia_matrix(j.link.inertia) for j in robot.joints])
    payload = robot.payload
    if include_payload and payload is not None and payload.mass > 0.0:
        rot, pos = robot.flange[:3, :3], robot.flange[:3, 3]
        pcom = rot @ payload.com + pos
        pin = rot @ inertia_matrix(payload.inertia) @ rot.T
        m_l, c_l, i_l = mass[-1], com[-1], inertia[-1]
        m_t = m_l + payload.mass
        c_t = (m_l * c_l + payload.mass * pcom) / m_t
        inertia[-1] = i_l + _parallel(m_l, c_l, c_t) + pin + _parallel(payload.mass, pcom, c_t)
        mass[-1], com[-1] = m_t, c_t
    return LinkInertials(mass, com, inertia)


def _is_float_array(value: object) -> TypeGuard[Array]:
    return type(value) is np.ndarray and value.dtype == np.float64


def _all_finite(arr: Array) -> bool:
    """Whether every entry is finite. A sample's few entries: one dot product (nan or inf in,
    nan or inf out; checked entry by entry only when it is not, as large finite values can
    overflow it), 4x faster than ``isfinite().all()``; a batch: ``isfinite`` (a long dot
    product may wait for BLAS threads on a busy machine)."""
    if arr.size > 64:
        return bool(np.isfinite(arr).all())
    flat = arr.ravel()
    return math.isfinite(float(flat.dot(flat))) or bool(np.isfinite(arr).all())


def _as_float_array(name: str, value: ArrayLike) -> Array:
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise KinergyError(f"{name}: must be numbers, shape (n,) or (N, n)") from None


def check_state(robot: Robot, **arrays: ArrayLike | None) -> tuple[bool, dict[str, Array]]:
    """Validate joint-state arrays at the public boundary.

    Each array must have shape ``(n,)`` (one sample) or ``(N, n)`` (a batch), all the same,
    finite. ``None`` entries become zeros.

    Returns
    -------
    single : bool
        True when the inputs were one sample (results are squeezed back to that rank).
    out : dict of str to ndarray, shape (N, n)
    """
    n = robot.n
    shape: tuple[int, ...] | None = None
    out: dict[str, Array] = {}
    for name, value in arrays.items():
        if value is None:
            continue
        arr = value if _is_float_array(value) else _as_float_array(name, value)
        if arr.ndim not in (1, 2) or arr.shape[-1] != n:
            raise KinergyError(
                f"{name}: expected shape ({n},) or (N, {n}) for {robot.name}, got {arr.shape}"
            )
        if shape is not None and arr.shape != shape:
            raise KinergyError(f"{name}: shape {arr.shape} differs from the other inputs' {shape}")
        shape = arr.shape
        if not _all_finite(arr):
            idx = np.argwhere(~np.isfinite(arr))[0]
            where = (
                f"sample {idx[0]}, joint {idx[-1] + 1}" if arr.ndim == 2 else f"joint {idx[0] + 1}"
            )
            raise KinergyError(f"{name}: not finite ({arr[tuple(idx)]}) at {where}")
        out[name] = arr
    if shape is None:
        raise KinergyError("no joint-state array given")
    single = len(shape) == 1
    rows = 1 if single else shape[0]
    for name, value in arrays.items():
        if value is None:
            out[name] = np.zeros((rows, n))
        elif single:
            out[name] = out[name][None, :]
    return single, out


@dataclass(frozen=True)
class KernelData:
    """What the compiled kernels (:mod:`kinergy.dynamics._kernels`) need of a robot, built once
    per robot (:func:`kernel_data`).

    Attributes
    ----------
    chain : Chain
    inertials : LinkInertials
        The payload merged into the last link.
    geo : tuple of 8 ndarray
        :func:`kernel_geometry` of the chain.
    ends : tuple of 3 ndarray
        ``(base_rot, flange_pos, g0)``: (3, 3) frame 0 in the base frame, (3,) flange origin in
        frame n (m), (3,) gravity in frame 0 (m/s^2).
    body : tuple of 3 ndarray
        ``(mass, first, inertia)``: (n,) kg, (n, 3) ``m c`` kg m, (n, 3, 3) about the link
        origins kg m^2; the payload merged into the last link.
    z_first : bool
        :func:`z_first` of ``geo``.
    """

    chain: Chain
    inertials: LinkInertials
    geo: tuple[Array, Array, Array, Array, Array, Array, Array, Array]
    ends: tuple[Array, Array, Array]
    body: tuple[Array, Array, Array]
    z_first: bool = False


#: one KernelData per robot; a robot is immutable, and dropping it drops its entry
_KERNEL_DATA: weakref.WeakKeyDictionary[Robot, KernelData] = weakref.WeakKeyDictionary()


def kernel_data(robot: Robot) -> KernelData:
    """The robot's :class:`KernelData`, built on first use and cached (the geometry costs a few
    hundred microseconds; a kernel call on one sample a few)."""
    data = _KERNEL_DATA.get(robot)
    if data is None:
        chain = make_chain(robot)
        body = link_inertials(robot)
        geo = kernel_geometry(chain)
        data = KernelData(
            chain,
            body,
            geo,
            tuple(  # type: ignore[arg-type]
                np.ascontiguousarray(x, dtype=float)
                for x in (chain.base[:3, :3], chain.flange[:3, 3], chain.gravity0)
            ),
            tuple(  # type: ignore[arg-type]
                np.ascontiguousarray(x, dtype=float)
                for x in (body.mass, body.first_moment, body.inertia_origin)
            ),
            z_first(geo),
        )
        _KERNEL_DATA[robot] = data
    return data


def contiguous_state(s: dict[str, Array]) -> tuple[Array, Array, Array]:
    """``(q, qd, qdd)`` of :func:`check_state`'s output, C-contiguous, for the kernels."""
    return (
        np.ascontiguousarray(s["q"]),
        np.ascontiguousarray(s["qd"]),
        np.ascontiguousarray(s["qdd"]),
    )


def output_array(out: Array | None, shape: tuple[int, ...], single: bool) -> Array:
    """A fresh array of ``shape`` (batch first), or ``out`` checked and viewed so.

    ``out`` must be a writeable C-contiguous float64 array of ``shape``, or of ``shape[1:]``
    when the inputs were one sample (``single``).

    Raises
    ------
    KinergyError
        ``out`` of another shape, type or layout.
    """
    if out is None:
        return np.empty(shape)
    expected = shape[1:] if single else shape
    if (
        not isinstance(out, np.ndarray)
        or out.shape != expected
        or out.dtype != np.float64
        or not out.flags.c_contiguous
        or not out.flags.writeable
    ):
        got = out.shape if isinstance(out, np.ndarray) else type(out).__name__
        raise KinergyError(
            f"out: expected a writeable C-contiguous float64 array of shape {expected}, got {got}"
        )
    return out.reshape(shape)


def gravity_in_frame0(robot: Robot, gravity: ArrayLike | None) -> Array | None:
    """Gravity in frame 0 for a ``gravity`` override (base frame, m/s^2), shape (3,); None for
    none (the kernels then use the robot's).

    Raises
    ------
    KinergyError
        Not 3 finite numbers.
    """
    if gravity is None:
        return None
    g = checks.vector(gravity, "gravity", length=3)
    return np.ascontiguousarray(robot.base[:3, :3].T @ g)
