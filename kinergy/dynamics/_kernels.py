"""Compiled inner loops of the recursive Newton-Euler algorithm and of the regressor.

The public functions (:func:`kinergy.dynamics.rnea.rnea`,
:func:`kinergy.dynamics.regressor.regressor`) validate their inputs and call these kernels
(numba). The benchmark in ``benchmarks/bench_dynamics.py`` shows why: a numpy version vectorised
over samples ran at about 3.6 us per sample (RNEA) and 35 us (regressor) for the UR5e, slower
than Pinocchio called from Python; these loops run at a fraction of a microsecond.

Lanes: the samples are taken :data:`LANES` at a time (a block), and every quantity of the
algorithm is an array whose last axis runs over the block's samples, e.g. ``omega`` (n, 3, lanes).
Each step is a short loop over that last axis with the same arithmetic for every sample, which
LLVM turns into SIMD instructions: RNEA three times and the regressor 1.5 times faster than one
sample at a time on this kind of machine (``benchmarks/README.md``). The sines and cosines of the joint angles are computed here
(:func:`_sincos`) rather than by calls to the C library, which would stop that; they agree with
``np.sin``/``np.cos`` to a few units in the last place (``tests/test_dynamics.py``).

Geometry (see :mod:`kinergy.dynamics.chain`): the pose of link frame F_i in F_{i-1} is
``R_i = c A_i + s B_i + C_i`` and ``p_i = c pa_i + s pb_i + pc_i`` with ``c, s = cos q_i, sin q_i``.
Joint i's motion subspace in F_i is ``S_i = (axis_i, axis_v_i)`` (angular, linear parts).
Spatial quantities are (angular, linear) pairs expressed at the origin of F_i; gravity enters as a
fictitious upward acceleration of the base (UR5e section 3.1).

Argument groups (tuples, so each kernel's signature stays short):

- ``geo = (A, B, C, pa, pb, pc, axis, axis_v)``: :func:`kinergy.dynamics.chain.kernel_geometry`;
- ``body = (mass, first, inertia)``: (n,), (n, 3) ``m c``, (n, 3, 3) about the link origins;
- ``g0``: (3,) gravity in frame 0; ``state = (q, qd, qdd)``: (N, n) each;
- ``z_first``: :func:`kinergy.dynamics.chain.z_first`, a constant of each compiled entry point:
  the ``*_dh`` functions are the same code for chains whose joints turn first (standard DH),
  which form each link pose with fewer products (a run-time flag in the loop made it slower).
  Each pair is made by one factory (:func:`_rnea_kernel`, :func:`_regressor_kernel`) closing
  over the flag, so numba compiles and caches one function per chain type without a wrapper
  that would inline the whole kernel once more (a third of the compile time).

Compile time: every helper is inlined into its caller (``inline="always"``: LLVM vectorises the
lanes only across one function, measured 1.7x slower otherwise), and numba's inliner copies the
callee's code per call site, so a fresh compile of the RNEA takes about 10 s of processor time
and the regressor 15 s; :mod:`kinergy.dynamics.launch` compiles only the kernel a call needs.

The public functions fill rows ``lo:hi`` and release the GIL, so
:mod:`kinergy.dynamics.launch` runs them on several threads at once. All stay
``fastmath=False``: a fresh compile and the on-disk cache must give the same bits. A wrench at
the flange is not theirs: :func:`kinergy.dynamics.rnea.rnea` adds ``J^T h``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numba import njit

from kinergy.arrays import Array

__all__ = [
    "LANES",
    "regressor_gradient_rows",
    "regressor_rows",
    "regressor_rows_dh",
    "rnea_rows",
    "rnea_rows_dh",
]

#: samples computed side by side (a block; a shorter last block is padded with zeros): RNEA
#: takes 0.13 us per sample with 32, 0.27 with 16 and 0.10 with 64, whose one-sample call costs
#: half as much again (benchmarks/README.md)
LANES = 32
#: pi/2 in three parts of at most 32 significant bits (n * part exact for |n| < 2**21)
_HALF_PI = (1.5707963267341256, 6.077100506303966e-11, 2.0222662487959506e-21)
_TWO_OVER_PI = 0.6366197723675814
#: above this |angle| (rad) a block's sines and cosines come from the C library
_REDUCE_MAX = 1e5


@njit(cache=True, fastmath=False, inline="always")
def _sincos(x: Array, cs: Array) -> None:
    """``cos`` and ``sin`` of every lane of ``x`` (lanes,) into ``cs`` (2, lanes).

    ``x = n pi/2 + r`` with ``|r| <= pi/4`` (Cody-Waite reduction in three parts), then the
    Taylor series of sin and cos of ``r`` to the terms ``r^17 / 17!`` and ``r^18 / 18!`` (the
    next terms are below 1e-19 on ``|r| <= pi/4``), the quadrant ``n mod 4`` swapping and
    negating them. A block with an angle beyond :data:`_REDUCE_MAX` (or not finite) uses the C
    library's ``cos`` and ``sin`` instead.
    """
    largest = 0.0
    for b in range(LANES):
        largest = max(largest, abs(x[b]))
    if not largest <= _REDUCE_MAX:
        for b in range(LANES):
            cs[0, b], cs[1, b] = np.cos(x[b]), np.sin(x[b])
        return
    p1, p2, p3 = _HALF_PI
    for b in range(LANES):
        n = np.floor(x[b] * _TWO_OVER_PI + 0.5)
        r = ((x[b] - n * p1) - n * p2) - n * p3
        z = r * r
        sp = z * (1.0 / 6227020800 + z * (-1.0 / 1307674368000 + z * (1.0 / 355687428096000)))
        sp = z * (-1.0 / 5040 + z * (1.0 / 362880 + z * (-1.0 / 39916800 + sp)))
        sp = r + r * z * (-1.0 / 6 + z * (1.0 / 120 + sp))
        cp = z * (1.0 / 479001600 + z * (-1.0 / 87178291200 + z * (1.0 / 20922789888000)))
        cp = z * (1.0 / 40320 + z * (-1.0 / 3628800 + cp - z * z * z * (1.0 / 6402373705728000)))
        cp = 1.0 + z * (-0.5 + z * (1.0 / 24 + z * (-1.0 / 720 + cp)))
        k = np.int64(n) & 3
        s = cp if k & 1 else sp
        c = sp if k & 1 else cp
        cs[0, b] = -c if k == 1 or k == 2 else c
        cs[1, b] = -s if k >= 2 else s


@njit(cache=True, fastmath=False, inline="always")
def _cross(a: Array, b: Array, out: Array) -> None:
    """``out = a x b``, each (3, lanes)."""
    for k in range(LANES):
        x = a[1, k] * b[2, k] - a[2, k] * b[1, k]
        y = a[2, k] * b[0, k] - a[0, k] * b[2, k]
        z = a[0, k] * b[1, k] - a[1, k] * b[0, k]
        out[0, k], out[1, k], out[2, k] = x, y, z


@njit(cache=True, fastmath=False, inline="always")
def _rot_t(rot: Array, x: Array, out: Array) -> None:
    """``out = R^T x``: rot (3, 3, lanes), x and out (3, lanes)."""
    for r in range(3):
        for b in range(LANES):
            out[r, b] = rot[0, r, b] * x[0, b] + rot[1, r, b] * x[1, b] + rot[2, r, b] * x[2, b]


@njit(cache=True, fastmath=False, inline="always")
def _rot(rot: Array, x: Array, out: Array) -> None:
    """``out = R x``: rot (3, 3, lanes), x and out (3, lanes)."""
    for r in range(3):
        for b in range(LANES):
            out[r, b] = rot[r, 0, b] * x[0, b] + rot[r, 1, b] * x[1, b] + rot[r, 2, b] * x[2, b]


@njit(cache=True, fastmath=False, inline="always")
def _link_pose(geo, i: int, cs: Array, rot: Array, pos: Array, z_first: bool) -> None:
    """Pose of F_i in F_{i-1} at ``c, s = cs`` (2, lanes): fills rot[i] (3, 3, lanes) and
    pos[i] (3, lanes).

    ``z_first`` (a compile-time constant): every joint turns first, ``R_i = Rz(q) M_i`` (standard
    DH; :func:`kinergy.dynamics.chain.z_first`), so ``M_i``'s rows 0-1 are ``A_i``'s and row 2 is
    ``C_i``'s and the rotation takes 12 products instead of 27, with the same bits (the general
    form adds exact zeros)."""
    a_mat, b_mat, c_mat, pa, pb, pc = geo[0], geo[1], geo[2], geo[3], geo[4], geo[5]
    if z_first:
        for k in range(3):
            m0, m1, m2 = a_mat[i, 0, k], a_mat[i, 1, k], c_mat[i, 2, k]
            for b in range(LANES):
                rot[i, 0, k, b] = cs[0, b] * m0 - cs[1, b] * m1
                rot[i, 1, k, b] = cs[1, b] * m0 + cs[0, b] * m1
                rot[i, 2, k, b] = m2
        p0, p1, p2 = pa[i, 0], pa[i, 1], pc[i, 2]
        for b in range(LANES):
            pos[i, 0, b] = cs[0, b] * p0 - cs[1, b] * p1
            pos[i, 1, b] = cs[1, b] * p0 + cs[0, b] * p1
            pos[i, 2, b] = p2
    else:
        for r in range(3):
            u, v, w = pa[i, r], pb[i, r], pc[i, r]
            for b in range(LANES):
                pos[i, r, b] = cs[0, b] * u + cs[1, b] * v + w
            for k in range(3):
                u, v, w = a_mat[i, r, k], b_mat[i, r, k], c_mat[i, r, k]
                for b in range(LANES):
                    rot[i, r, k, b] = cs[0, b] * u + cs[1, b] * v + w


@njit(cache=True, fastmath=False, inline="always")
def _motion_pass(geo, g0, x, cs, rot, frames, work, z_first) -> None:
    """Forward recursion for a block ``x = (q, qd, qdd)`` (3, n, lanes): fills rot
    (n, 3, 3, lanes) and ``frames``' pos, omega, vel, alpha and classical linear acceleration
    acl (n, 3, lanes) in F_i. ``work`` is scratch space of shape (9, 3, lanes)."""
    axis, axis_v = geo[6], geo[7]
    pos, omega, vel, alpha, acl = frames[0], frames[1], frames[2], frames[3], frames[4]
    w_p, v_p, al_p, ac_p, t1 = work[0], work[1], work[2], work[3], work[4]
    t2, sw, sv, ac = work[5], work[6], work[7], work[8]
    for r in range(3):
        for b in range(LANES):
            w_p[r, b], v_p[r, b], al_p[r, b], ac_p[r, b] = 0.0, 0.0, 0.0, -g0[r]
    for i in range(x.shape[1]):
        qd, qdd = x[1, i], x[2, i]
        _sincos(x[0, i], cs)
        _link_pose(geo, i, cs, rot, pos, z_first)
        # t1 = v_p + w_p x p ; t2 = ac_p + al_p x p   (spatial transform, parent coordinates)
        _cross(w_p, pos[i], t1)
        _cross(al_p, pos[i], t2)
        for r in range(3):
            ax, av = axis[i, r], axis_v[i, r]
            for b in range(LANES):
                t1[r, b] += v_p[r, b]
                t2[r, b] += ac_p[r, b]
                sw[r, b] = ax * qd[b]
                sv[r, b] = av * qd[b]
        # rotate into F_i with R^T, add the joint's own motion
        _rot_t(rot[i], w_p, omega[i])
        _rot_t(rot[i], t1, vel[i])
        _rot_t(rot[i], al_p, alpha[i])
        _rot_t(rot[i], t2, ac)
        for r in range(3):
            ax, av = axis[i, r], axis_v[i, r]
            for b in range(LANES):
                omega[i, r, b] += sw[r, b]
                vel[i, r, b] += sv[r, b]
                alpha[i, r, b] += ax * qdd[b]
                ac[r, b] += av * qdd[b]
        # velocity-product terms: v_i x_m (S_i qd_i)
        _cross(omega[i], sw, t1)
        for r in range(3):
            for b in range(LANES):
                alpha[i, r, b] += t1[r, b]
        _cross(omega[i], sv, t1)
        _cross(vel[i], sw, t2)
        for r in range(3):
            for b in range(LANES):
                ac[r, b] += t1[r, b] + t2[r, b]
                w_p[r, b], v_p[r, b] = omega[i, r, b], vel[i, r, b]
                al_p[r, b], ac_p[r, b] = alpha[i, r, b], ac[r, b]
        _cross(omega[i], vel[i], t1)
        for r in range(3):
            for b in range(LANES):
                acl[i, r, b] = ac[r, b] + t1[r, b]


@njit(cache=True, fastmath=False, inline="always")
def _inertia_times(inertia: Array, x: Array, out: Array) -> None:
    """``out = I x`` (3, lanes) with a link's inertia (3, 3) about its origin."""
    for r in range(3):
        i0, i1, i2 = inertia[r, 0], inertia[r, 1], inertia[r, 2]
        for b in range(LANES):
            out[r, b] = i0 * x[0, b] + i1 * x[1, b] + i2 * x[2, b]


@njit(cache=True, fastmath=False, inline="always")
def _link_wrench(body, i, frames, work) -> None:
    """Link i's wrench at its origin (UR5e eqs 5-6): force = m acl + alpha x h + w x (w x h),
    moment = I alpha + w x (I w) + h x acl, into frames' force[i], moment[i]."""
    mass, first, inertia = body
    omega, alpha, acl, force, moment = frames[1], frames[3], frames[4], frames[5], frames[6]
    t1, t2, iw, h = work[0], work[1], work[2], work[3]
    m = mass[i]
    for r in range(3):
        for b in range(LANES):
            h[r, b] = first[i, r]
    _cross(alpha[i], h, t1)
    _cross(omega[i], h, t2)
    _cross(omega[i], t2, iw)
    for r in range(3):
        for b in range(LANES):
            force[i, r, b] = m * acl[i, r, b] + t1[r, b] + iw[r, b]
    _inertia_times(inertia[i], omega[i], t1)
    _cross(omega[i], t1, t2)
    _cross(h, acl[i], iw)
    _inertia_times(inertia[i], alpha[i], moment[i])
    for r in range(3):
        for b in range(LANES):
            moment[i, r, b] += t2[r, b] + iw[r, b]


@njit(cache=True, fastmath=False, inline="always")
def _backward_pass(geo, rot, frames, tau, work) -> None:
    """Joint torques ``tau`` (n, lanes) from the link wrenches, each carried into its parent."""
    axis, axis_v = geo[6], geo[7]
    pos, force, moment = frames[0], frames[5], frames[6]
    t1, t2, iw = work[0], work[1], work[2]
    for i in range(rot.shape[0] - 1, -1, -1):
        a0, a1, a2 = axis[i, 0], axis[i, 1], axis[i, 2]
        v0, v1, v2 = axis_v[i, 0], axis_v[i, 1], axis_v[i, 2]
        for b in range(LANES):
            acc = moment[i, 0, b] * a0 + moment[i, 1, b] * a1 + moment[i, 2, b] * a2
            tau[i, b] = acc + force[i, 0, b] * v0 + force[i, 1, b] * v1 + force[i, 2, b] * v2
        if i > 0:
            _rot(rot[i], force[i], t1)
            _rot(rot[i], moment[i], t2)
            _cross(pos[i], t1, iw)
            for r in range(3):
                for b in range(LANES):
                    force[i - 1, r, b] += t1[r, b]
                    moment[i - 1, r, b] += t2[r, b] + iw[r, b]


@njit(cache=True, fastmath=False, inline="always")
def _scratch(n: int):
    """Scratch space of one block: ``x`` (3, n, lanes) (q, qd, qdd), ``cs`` (2, lanes),
    ``rot`` (n, 3, 3, lanes), ``frames`` (7, n, 3, lanes) (pos, omega, vel, alpha, acl, force,
    moment), ``work`` (9, 3, lanes)."""
    x = np.zeros((3, n, LANES))
    frames = np.empty((7, n, 3, LANES))
    return x, np.empty((2, LANES)), np.empty((n, 3, 3, LANES)), frames, np.zeros((9, 3, LANES))


@njit(cache=True, fastmath=False, inline="always")
def _load(rows: Array, k0: int, out: Array) -> None:
    """``out[i, b] = rows[k0 + b, i]`` (m, lanes) for m = rows' columns, zero in the lanes
    past the last row."""
    m = min(LANES, rows.shape[0] - k0)
    for i in range(out.shape[0]):
        for b in range(m):
            out[i, b] = rows[k0 + b, i]
        out[i, m:] = 0.0


@njit(cache=True, fastmath=False, inline="always")
def _load_state(state, k0: int, x: Array) -> None:
    """``x`` (3, n, lanes) from rows ``k0 ..`` of ``state = (q, qd, qdd)`` (:func:`_load`); the
    three may differ in type (a read-only one), so they are taken apart, not indexed."""
    q, qd, qdd = state
    _load(q, k0, x[0])
    _load(qd, k0, x[1])
    _load(qdd, k0, x[2])


def _rnea_kernel(z_first: bool) -> Callable[..., None]:
    """The RNEA entry point for chains with (``z_first``) or without joints that turn first
    (:func:`_link_pose`): ``z_first`` is a constant of the compiled code, not an argument."""

    @njit(cache=True, fastmath=False, nogil=True)
    def rnea_rows(lo, hi, geo, g0, body, state, tau) -> None:
        """Fill rows lo:hi of ``tau`` (N, n) with the joint torques of ``state``."""
        n = tau.shape[1]
        x, cs, rot, frames, work = _scratch(n)
        tb = np.empty((n, LANES))
        for k0 in range(lo, hi, LANES):
            _load_state(state, k0, x)
            _motion_pass(geo, g0, x, cs, rot, frames, work, z_first)
            for i in range(n):
                _link_wrench(body, i, frames, work)
            _backward_pass(geo, rot, frames, tb, work)
            for b in range(min(LANES, hi - k0)):
                for i in range(n):
                    tau[k0 + b, i] = tb[i, b]

    return rnea_rows


@njit(cache=True, fastmath=False, inline="always")
def _carry_axes(j, rot, pos, sax, work) -> None:
    """Carry the axes ``sax = (angular, linear)`` (2, n, 3, lanes) of joints 0..j-1 from F_{j-1}
    into F_j: ``w' = R^T w``, ``v' = R^T (v + w x p)``."""
    t1, t2 = work[0], work[1]
    for i in range(j):
        _cross(sax[0, i], pos[j], t2)
        for r in range(3):
            for b in range(LANES):
                t2[r, b] += sax[1, i, r, b]
                t1[r, b] = sax[0, i, r, b]
        _rot_t(rot[j], t1, sax[0, i])
        _rot_t(rot[j], t2, sax[1, i])


@njit(cache=True, fastmath=False, inline="always")
def _wrench_matrix(w: Array, al: Array, ac: Array, kmat: Array) -> None:
    """``K`` (6, 10, lanes) with link wrench (moment; force) ``= K pi`` (module docstring of
    :func:`regressor_rows`) from w, alpha, acl (3, lanes); only the non-zero entries are
    written."""
    k = kmat
    for b in range(LANES):
        wx, wy, wz = w[0, b], w[1, b], w[2, b]
        ax, ay, az = al[0, b], al[1, b], al[2, b]
        # mass: force = acl
        k[3, 0, b], k[4, 0, b], k[5, 0, b] = ac[0, b], ac[1, b], ac[2, b]
        # first moment h: moment = h x acl = -[acl]x h; force = ([alpha]x + [w]x[w]x) h
        k[0, 2, b], k[0, 3, b] = ac[2, b], -ac[1, b]
        k[1, 1, b], k[1, 3, b] = -ac[2, b], ac[0, b]
        k[2, 1, b], k[2, 2, b] = ac[1, b], -ac[0, b]
        k[3, 1, b], k[3, 2, b], k[3, 3, b] = -(wy * wy + wz * wz), wx * wy - az, wx * wz + ay
        k[4, 1, b], k[4, 2, b], k[4, 3, b] = wx * wy + az, -(wx * wx + wz * wz), wy * wz - ax
        k[5, 1, b], k[5, 2, b], k[5, 3, b] = wx * wz - ay, wy * wz + ax, -(wx * wx + wy * wy)
        # inertia about the origin: moment = L(alpha) + [w]x L(w), I w = L(w) [Ixx Ixy Iyy Ixz Iyz Izz]
        k[0, 4, b], k[1, 4, b], k[2, 4, b] = ax, wx * wz, -wx * wy
        k[0, 5, b], k[1, 5, b], k[2, 5, b] = ay - wx * wz, ax + wy * wz, wx * wx - wy * wy
        k[0, 6, b], k[1, 6, b], k[2, 6, b] = -wy * wz, ay, wx * wy
        k[0, 7, b], k[1, 7, b], k[2, 7, b] = az + wx * wy, wz * wz - wx * wx, ax - wy * wz
        k[0, 8, b], k[1, 8, b], k[2, 8, b] = wy * wy - wz * wz, az - wx * wy, ay + wx * wz
        k[0, 9, b], k[1, 9, b], k[2, 9, b] = wy * wz, -wx * wz, az


@njit(cache=True, fastmath=False, inline="always")
def _regressor_block(j, sax, kmat, y, k0, m, clear) -> None:
    """Columns ``10 j .. 10 j + 9`` of the regressor of samples ``k0 .. k0 + m - 1`` (the first m
    lanes) in ``y`` (., n, 10 n): joint i's row is ``(X_{j<-i} S_i) . K_j`` for i <= j (K_j's structural
    zeros skipped), zero below (written only if ``clear``: 20 % of the time)."""
    c0 = 10 * j
    ang, lin = sax[0], sax[1]
    for i in range(j + 1):
        for b in range(m):
            acc = lin[i, 0, b] * kmat[3, 0, b] + lin[i, 1, b] * kmat[4, 0, b]
            y[k0 + b, i, c0] = acc + lin[i, 2, b] * kmat[5, 0, b]
        for c in range(1, 4):
            for b in range(m):
                acc = ang[i, 0, b] * kmat[0, c, b] + ang[i, 1, b] * kmat[1, c, b]
                acc += ang[i, 2, b] * kmat[2, c, b] + lin[i, 0, b] * kmat[3, c, b]
                acc += lin[i, 1, b] * kmat[4, c, b] + lin[i, 2, b] * kmat[5, c, b]
                y[k0 + b, i, c0 + c] = acc
        for c in range(4, 10):
            for b in range(m):
                acc = ang[i, 0, b] * kmat[0, c, b] + ang[i, 1, b] * kmat[1, c, b]
                y[k0 + b, i, c0 + c] = acc + ang[i, 2, b] * kmat[2, c, b]
    for i in range(j + 1, y.shape[1] if clear else 0):
        for b in range(m):
            for c in range(10):
                y[k0 + b, i, c0 + c] = 0.0


@njit(cache=True, fastmath=False, inline="always")
def _regressor_scratch(n: int, own_y: bool):
    """Scratch space of :func:`_regressor_lanes` for n joints: :func:`_scratch`'s, the carried
    axes ``sax`` (2, n, 3, lanes), ``K`` (6, 10, lanes) and, if ``own_y``, a regressor of its own
    (lanes, n, 10 n)."""
    kmat = np.zeros((6, 10, LANES))  # only its non-zero entries are ever written
    y = np.zeros((LANES if own_y else 0, n, 10 * n))
    return _scratch(n), np.empty((2, n, 3, LANES)), kmat, y


@njit(cache=True, fastmath=False, inline="always")
def _regressor_lanes(geo, g0, y, k0, m, clear, scratch, z_first) -> None:
    """The regressor of the block in ``scratch``'s ``x`` into rows ``k0 .. k0 + m - 1`` of ``y``
    (:func:`regressor_rows`), from its first m lanes."""
    (x, cs, rot, frames, work), sax, kmat, _ = scratch
    axis, axis_v = geo[6], geo[7]
    _motion_pass(geo, g0, x, cs, rot, frames, work, z_first)
    for j in range(x.shape[1]):
        _carry_axes(j, rot, frames[0], sax, work)
        for r in range(3):
            for b in range(LANES):
                sax[0, j, r, b], sax[1, j, r, b] = axis[j, r], axis_v[j, r]
        _wrench_matrix(frames[1, j], frames[3, j], frames[4, j], kmat)
        _regressor_block(j, sax, kmat, y, k0, m, clear)


def _regressor_kernel(z_first: bool) -> Callable[..., None]:
    """The regressor entry point for chains with (``z_first``) or without joints that turn
    first, as :func:`_rnea_kernel`.

    It fills rows lo:hi of ``y`` (N, n, 10 n) with the regressor in the parameter order
    ``[m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``; the structurally zero entries are written
    if ``clear`` (any contents on entry), else left as they are (zeros on entry).

    Link j's wrench (moment; force) at the origin of F_j is linear in its parameters,
    ``wrench_j = K_j pi_j`` with::

        moment = h x acl + I alpha + w x (I w),   force = m acl + alpha x h + w x (w x h)

    and joint i's torque is ``S_i . X_{i<-j}^T wrench_j = (X_{j<-i} S_i) . K_j pi_j`` summed over
    j >= i: each joint axis is carried out to the links it moves instead of carrying every link's
    ten wrench columns back to each joint.
    """

    @njit(cache=True, fastmath=False, nogil=True)
    def regressor_rows(lo, hi, geo, g0, state, y, clear) -> None:
        """Fill rows lo:hi of ``y`` (N, n, 10 n) with the regressor of ``state``."""
        scratch = _regressor_scratch(y.shape[1], False)
        x = scratch[0][0]
        for k0 in range(lo, hi, LANES):
            _load_state(state, k0, x)
            _regressor_lanes(geo, g0, y, k0, min(LANES, hi - k0), clear, scratch, z_first)

    return regressor_rows


@njit(cache=True, fastmath=False, inline="always")
def _weighted(geo, g0, weights, k0, scratch, out) -> None:
    """``out[b] = sum(weights[k0 + b] * Y_b)`` (lanes,) for the block in ``scratch``'s ``x``."""
    y = scratch[3]
    _regressor_lanes(geo, g0, y, 0, LANES, False, scratch, False)
    for b in range(min(LANES, weights.shape[0] - k0)):
        w, yb = weights[k0 + b], y[b]
        acc = 0.0
        for i in range(yb.shape[0]):
            for c in range(yb.shape[1]):
                acc += w[i, c] * yb[i, c]
        out[b] = acc


@njit(cache=True, fastmath=False, inline="always")
def _gradient_step(p: int, n: int) -> tuple[int, int, float]:
    """Step p (0 .. 5 n - 1) of :func:`regressor_gradient_rows`: ``(kind, joint, sign)``, five
    per joint: q up, q down, qd up, qd down, qdd up."""
    j, r = p // 5, p % 5
    return r // 2, j, -1.0 if r % 2 and r < 4 else 1.0


@njit(cache=True, fastmath=False, nogil=True)
def regressor_gradient_rows(lo, hi, geo, g0, state, weights, step_q, sens) -> None:
    """Rows lo:hi of ``sens`` (3, N, n): the derivatives of ``f = sum(weights[k] * Y_k)`` in
    every sample's ``q``, ``qd`` and ``qdd``.

    ``Y`` is linear in ``qdd`` and a quadratic in ``qd``, so a unit forward step in ``qdd`` and
    a central unit step in ``qd`` give their derivatives up to rounding; ``q`` takes a central
    step of ``step_q`` rad (error ``O(step_q^2)``). A whole block takes each step at once.
    """
    n = state[0].shape[1]
    scratch = _regressor_scratch(n, True)
    x = scratch[0][0]
    # f at the block, then up (and down, for q and qd) a step in each (kind, joint)
    values = np.empty((1 + 5 * n, LANES))
    steps = (step_q, 1.0, 1.0)
    for k0 in range(lo, hi, LANES):
        _load_state(state, k0, x)
        x0 = x.copy()
        for p in range(1 + 5 * n):
            x[:] = x0
            if p > 0:
                kind, j, sign = _gradient_step(p - 1, n)
                x[kind, j] += sign * steps[kind]
            _weighted(geo, g0, weights, k0, scratch, values[p])
        for b in range(min(LANES, hi - k0)):
            for j in range(n):
                for kind in range(3):
                    up = values[1 + 5 * j + 2 * kind, b]
                    if kind < 2:
                        down = values[2 + 5 * j + 2 * kind, b]
                        sens[kind, k0 + b, j] = (up - down) / (2.0 * steps[kind])
                    else:
                        sens[kind, k0 + b, j] = up - values[0, b]


#: RNEA for any chain
rnea_rows = _rnea_kernel(False)
#: RNEA for a chain whose joints turn first (``z_first``)
rnea_rows_dh = _rnea_kernel(True)
#: the regressor for any chain
regressor_rows = _regressor_kernel(False)
#: the regressor for a chain whose joints turn first (``z_first``)
regressor_rows_dh = _regressor_kernel(True)
