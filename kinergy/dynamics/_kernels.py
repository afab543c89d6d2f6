"""Compiled inner loops of the recursive Newton-Euler algorithm and of the regressor.

The public functions (:func:`kinergy.dynamics.rnea.rnea`,
:func:`kinergy.dynamics.regressor.regressor`) validate their inputs and call these kernels,
which loop over samples and joints with scalar arithmetic (numba). The benchmark in
``benchmarks/bench_dynamics.py`` shows why: a numpy version vectorised over samples ran at about
3.6 us per sample (RNEA) and 35 us (regressor) for the UR5e, slower than Pinocchio called from
Python; these loops run at a fraction of a microsecond.

Geometry (see :mod:`kinergy.dynamics.chain`): the pose of link frame F_i in F_{i-1} is
``R_i = c A_i + s B_i + C_i`` and ``p_i = c pa_i + s pb_i + pc_i`` with ``c, s = cos q_i, sin q_i``.
Joint i's motion subspace in F_i is ``S_i = (axis_i, axis_v_i)`` (angular, linear parts).
Spatial quantities are (angular, linear) pairs expressed at the origin of F_i; gravity enters as a
fictitious upward acceleration of the base (UR5e section 3.1).

Argument groups (tuples, so each kernel's signature stays short):

- ``geo = (A, B, C, pa, pb, pc, axis, axis_v)``: :func:`kinergy.dynamics.chain.kernel_geometry`;
- ``body = (mass, first, inertia)``: (n,), (n, 3) ``m c``, (n, 3, 3) about the link origins;
- ``ends = (base_rot, flange_pos, g0)``: (3, 3), (3,), (3,) gravity in frame 0;
- ``state = (q, qd, qdd)``: (N, n) each;
- ``z_first``: :func:`kinergy.dynamics.chain.z_first`, a constant of each compiled entry point:
  the ``*_dh`` functions are the same code for chains whose joints turn first (standard DH),
  about 5 % faster (a run-time flag in the loop made it twice as slow).

The ``*_rows`` functions fill rows ``lo:hi`` serially (called directly for small N); the
``*_kernel`` functions split the samples over numba's threads. All stay ``fastmath=False``: a
fresh compile and the on-disk cache must give the same bits.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from kinergy.arrays import Array

__all__ = [
    "GRADIENT_CHUNK",
    "regressor_gradient_kernel",
    "regressor_gradient_rows",
    "regressor_kernel",
    "regressor_kernel_dh",
    "regressor_rows",
    "regressor_rows_dh",
    "rnea_kernel",
    "rnea_kernel_dh",
    "rnea_rows",
    "rnea_rows_dh",
]


@njit(cache=True, fastmath=False, inline="always")
def _cross(a: Array, b: Array, out: Array) -> None:
    x = a[1] * b[2] - a[2] * b[1]
    y = a[2] * b[0] - a[0] * b[2]
    z = a[0] * b[1] - a[1] * b[0]
    out[0], out[1], out[2] = x, y, z


@njit(cache=True, fastmath=False, inline="always")
def _rot_t(rot: Array, x: Array, r: int) -> float:
    """Component r of ``R^T x``."""
    return rot[0, r] * x[0] + rot[1, r] * x[1] + rot[2, r] * x[2]


@njit(cache=True, fastmath=False, inline="always")
def _rot(rot: Array, x: Array, r: int) -> float:
    """Component r of ``R x``."""
    return rot[r, 0] * x[0] + rot[r, 1] * x[1] + rot[r, 2] * x[2]


@njit(cache=True, fastmath=False, inline="always")
def _link_pose(geo, i: int, q: float, rot: Array, pos: Array, z_first: bool) -> None:
    """Pose of F_i in F_{i-1} at joint angle ``q``: fills rot[i] (3, 3) and pos[i] (3,).

    ``z_first`` (a compile-time constant): every joint turns first, ``R_i = Rz(q) M_i`` (standard
    DH; :func:`kinergy.dynamics.chain.z_first`), so ``M_i``'s rows 0-1 are ``A_i``'s and row 2 is
    ``C_i``'s and the rotation takes 12 products instead of 27, with the same bits (the general
    form adds exact zeros)."""
    a_mat, b_mat, c_mat, pa, pb, pc = geo[0], geo[1], geo[2], geo[3], geo[4], geo[5]
    c = np.cos(q)
    s = np.sin(q)
    if z_first:
        for k in range(3):
            m0, m1 = a_mat[i, 0, k], a_mat[i, 1, k]
            rot[i, 0, k] = c * m0 - s * m1
            rot[i, 1, k] = s * m0 + c * m1
            rot[i, 2, k] = c_mat[i, 2, k]
        p0, p1 = pa[i, 0], pa[i, 1]
        pos[i, 0] = c * p0 - s * p1
        pos[i, 1] = s * p0 + c * p1
        pos[i, 2] = pc[i, 2]
    else:
        for r in range(3):
            pos[i, r] = c * pa[i, r] + s * pb[i, r] + pc[i, r]
            for k in range(3):
                rot[i, r, k] = c * a_mat[i, r, k] + s * b_mat[i, r, k] + c_mat[i, r, k]


@njit(cache=True, fastmath=False, inline="always")
def _motion_pass(geo, g0, q, qd, qdd, rot, pos, omega, vel, alpha, acl, work, z_first) -> None:
    """Forward recursion for one sample: fills rot, pos (n,3,3), (n,3) and the link velocities
    omega, vel, accelerations alpha and classical linear acceleration acl (n, 3) in F_i.
    ``work`` is scratch space of shape (9, 3)."""
    axis, axis_v = geo[6], geo[7]
    w_p, v_p, al_p, ac_p, t1 = work[0], work[1], work[2], work[3], work[4]
    t2, sw, sv, ac = work[5], work[6], work[7], work[8]
    for r in range(3):
        w_p[r] = 0.0
        v_p[r] = 0.0
        al_p[r] = 0.0
        ac_p[r] = -g0[r]
    for i in range(q.shape[0]):
        _link_pose(geo, i, q[i], rot, pos, z_first)
        # t1 = v_p + w_p x p ; t2 = ac_p + al_p x p   (spatial transform, parent coordinates)
        _cross(w_p, pos[i], t1)
        _cross(al_p, pos[i], t2)
        for r in range(3):
            t1[r] += v_p[r]
            t2[r] += ac_p[r]
            sw[r] = axis[i, r] * qd[i]
            sv[r] = axis_v[i, r] * qd[i]
        for r in range(3):  # rotate into F_i with R^T
            omega[i, r] = _rot_t(rot[i], w_p, r) + sw[r]
            vel[i, r] = _rot_t(rot[i], t1, r) + sv[r]
            alpha[i, r] = _rot_t(rot[i], al_p, r) + axis[i, r] * qdd[i]
            ac[r] = _rot_t(rot[i], t2, r) + axis_v[i, r] * qdd[i]
        # velocity-product terms: v_i x_m (S_i qd_i)
        _cross(omega[i], sw, t1)
        for r in range(3):
            alpha[i, r] += t1[r]
        _cross(omega[i], sv, t1)
        _cross(vel[i], sw, t2)
        for r in range(3):
            ac[r] += t1[r] + t2[r]
            w_p[r] = omega[i, r]
            v_p[r] = vel[i, r]
            al_p[r] = alpha[i, r]
            ac_p[r] = ac[r]
        _cross(omega[i], vel[i], t1)
        for r in range(3):
            acl[i, r] = ac[r] + t1[r]


@njit(cache=True, fastmath=False, inline="always")
def _link_wrench(body, i, omega, alpha, acl, force, moment, work) -> None:
    """Link i's wrench at its origin (UR5e eqs 5-6): force = m acl + alpha x h + w x (w x h),
    moment = I alpha + w x (I w) + h x acl, into force[i], moment[i]."""
    mass, first, inertia = body
    t1, t2, iw = work[0], work[1], work[2]
    h = first[i]
    _cross(alpha[i], h, t1)
    _cross(omega[i], h, t2)
    _cross(omega[i], t2, iw)
    for r in range(3):
        force[i, r] = mass[i] * acl[i, r] + t1[r] + iw[r]
    for r in range(3):
        t1[r] = _rot(inertia[i], omega[i], r)
    _cross(omega[i], t1, t2)
    _cross(h, acl[i], iw)
    for r in range(3):
        moment[i, r] = _rot(inertia[i], alpha[i], r) + t2[r] + iw[r]


@njit(cache=True, fastmath=False, inline="always")
def _flange_wrench(ends, rot, h, force, moment, work) -> None:
    """Add the wrench ``h`` (6,) the flange exerts (base-frame coordinates) to the last link's
    force and moment: rotated into F_n, its moment carried to F_n's origin."""
    base_rot, flange_pos = ends[0], ends[1]
    n = rot.shape[0]
    world, tmp = work[3:6], work[6:9]
    t1, t2, iw = work[0], work[1], work[2]
    world[:, :] = base_rot
    for i in range(n):
        for r in range(3):
            for c in range(3):
                tmp[r, c] = _rot(world, rot[i, :, c], r)
        world[:, :] = tmp
    for r in range(3):
        t1[r] = _rot_t(world, h[0:3], r)
        t2[r] = _rot_t(world, h[3:6], r)
    _cross(flange_pos, t1, iw)
    for r in range(3):
        force[n - 1, r] += t1[r]
        moment[n - 1, r] += t2[r] + iw[r]


@njit(cache=True, fastmath=False, inline="always")
def _backward_pass(geo, rot, pos, force, moment, tau, work) -> None:
    """Joint torques ``tau`` (n,) from the link wrenches, each carried into its parent."""
    axis, axis_v = geo[6], geo[7]
    t1, t2, iw = work[0], work[1], work[2]
    for i in range(rot.shape[0] - 1, -1, -1):
        acc = 0.0
        for r in range(3):
            acc += moment[i, r] * axis[i, r]
        for r in range(3):
            acc += force[i, r] * axis_v[i, r]
        tau[i] = acc
        if i > 0:
            for r in range(3):
                t1[r] = _rot(rot[i], force[i], r)
                t2[r] = _rot(rot[i], moment[i], r)
            _cross(pos[i], t1, iw)
            for r in range(3):
                force[i - 1, r] += t1[r]
                moment[i - 1, r] += t2[r] + iw[r]


@njit(cache=True, fastmath=False, inline="always")
def _rnea_rows(lo, hi, geo, ends, body, state, wrench, tau, z_first) -> None:
    """Fill rows lo:hi of ``tau`` (N, n) with the joint torques of ``state``; ``wrench`` is
    (N, 6), or (0, 6) for none; ``z_first`` as :func:`_link_pose`."""
    q, qd, qdd = state
    n = q.shape[1]
    frames = np.empty((6, n, 3))  # pos, omega, vel, alpha, acl, force
    rot = np.empty((n, 3, 3))
    moment = np.empty((n, 3))
    work = np.zeros((9, 3))
    pos, omega, vel, alpha, acl = frames[0], frames[1], frames[2], frames[3], frames[4]
    force = frames[5]
    for k in range(lo, hi):
        _motion_pass(
            geo, ends[2], q[k], qd[k], qdd[k], rot, pos, omega, vel, alpha, acl, work, z_first
        )
        for i in range(n):
            _link_wrench(body, i, omega, alpha, acl, force, moment, work)
        if wrench.shape[0] > 0:
            _flange_wrench(ends, rot, wrench[k], force, moment, work)
        _backward_pass(geo, rot, pos, force, moment, tau[k], work)


@njit(cache=True, fastmath=False, inline="always")
def _carry_axes(j, rot, pos, sax, work) -> None:
    """Carry the axes ``sax`` (n, 6) of joints 0..j-1 from F_{j-1} into F_j:
    ``w' = R^T w``, ``v' = R^T (v + w x p)``."""
    t1, t2 = work[0], work[1]
    for i in range(j):
        for r in range(3):
            t1[r] = sax[i, r]
        _cross(t1, pos[j], t2)
        for r in range(3):
            t2[r] += sax[i, 3 + r]
        for r in range(3):
            sax[i, r] = _rot_t(rot[j], t1, r)
            sax[i, 3 + r] = _rot_t(rot[j], t2, r)


@njit(cache=True, fastmath=False, inline="always")
def _wrench_matrix(w: Array, al: Array, ac: Array, kmat: Array) -> None:
    """``K`` (6, 10) with link wrench (moment; force) ``= K pi`` (module docstring of
    :func:`regressor_rows`); only the non-zero entries are written."""
    wx, wy, wz = w[0], w[1], w[2]
    ax, ay, az = al[0], al[1], al[2]
    # mass: force = acl
    kmat[3, 0], kmat[4, 0], kmat[5, 0] = ac[0], ac[1], ac[2]
    # first moment h: moment = h x acl = -[acl]x h; force = ([alpha]x + [w]x[w]x) h
    kmat[0, 2], kmat[0, 3] = ac[2], -ac[1]
    kmat[1, 1], kmat[1, 3] = -ac[2], ac[0]
    kmat[2, 1], kmat[2, 2] = ac[1], -ac[0]
    kmat[3, 1], kmat[3, 2], kmat[3, 3] = -(wy * wy + wz * wz), wx * wy - az, wx * wz + ay
    kmat[4, 1], kmat[4, 2], kmat[4, 3] = wx * wy + az, -(wx * wx + wz * wz), wy * wz - ax
    kmat[5, 1], kmat[5, 2], kmat[5, 3] = wx * wz - ay, wy * wz + ax, -(wx * wx + wy * wy)
    # inertia about the origin: moment = L(alpha) + [w]x L(w), I w = L(w) [Ixx Ixy Iyy Ixz Iyz Izz]
    kmat[0, 4], kmat[1, 4], kmat[2, 4] = ax, wx * wz, -wx * wy
    kmat[0, 5], kmat[1, 5], kmat[2, 5] = ay - wx * wz, ax + wy * wz, wx * wx - wy * wy
    kmat[0, 6], kmat[1, 6], kmat[2, 6] = -wy * wz, ay, wx * wy
    kmat[0, 7], kmat[1, 7], kmat[2, 7] = az + wx * wy, wz * wz - wx * wx, ax - wy * wz
    kmat[0, 8], kmat[1, 8], kmat[2, 8] = wy * wy - wz * wz, az - wx * wy, ay + wx * wz
    kmat[0, 9], kmat[1, 9], kmat[2, 9] = wy * wz, -wx * wz, az


@njit(cache=True, fastmath=False, inline="always")
def _regressor_block(j, sax, kmat, y, clear) -> None:
    """Columns ``10 j .. 10 j + 9`` of one sample's regressor ``y`` (n, 10 n): joint i's row is
    ``(X_{j<-i} S_i) . K_j`` for i <= j (K_j's structural zeros skipped), zero below (written
    only if ``clear``: 20 % of the time)."""
    c0 = 10 * j
    for i in range(j + 1):
        y[i, c0] = sax[i, 3] * kmat[3, 0] + sax[i, 4] * kmat[4, 0] + sax[i, 5] * kmat[5, 0]
        for c in range(1, 4):
            acc = 0.0
            for r in range(6):
                acc += sax[i, r] * kmat[r, c]
            y[i, c0 + c] = acc
        for c in range(4, 10):
            y[i, c0 + c] = sax[i, 0] * kmat[0, c] + sax[i, 1] * kmat[1, c] + sax[i, 2] * kmat[2, c]
    for i in range(j + 1, y.shape[0] if clear else 0):
        for c in range(10):
            y[i, c0 + c] = 0.0


@njit(cache=True, fastmath=False, inline="always")
def _regressor_scratch(n):
    """Scratch space of :func:`_regressor_sample` for n joints."""
    frames = np.empty((6, n, 3))  # pos, omega, vel, alpha, acl
    rot = np.empty((n, 3, 3))
    work = np.zeros((9, 3))
    sax = np.empty((n, 6))  # joint axes (angular; linear) in the current link frame
    kmat = np.zeros((6, 10))  # only its non-zero entries are ever written
    return frames, rot, work, sax, kmat


@njit(cache=True, fastmath=False, inline="always")
def _regressor_sample(geo, g0, q, qd, qdd, y, clear, scratch, z_first) -> None:
    """One sample's regressor ``y`` (n, 10 n) (:func:`regressor_rows`)."""
    frames, rot, work, sax, kmat = scratch
    axis, axis_v = geo[6], geo[7]
    pos, omega, vel, alpha, acl = frames[0], frames[1], frames[2], frames[3], frames[4]
    _motion_pass(geo, g0, q, qd, qdd, rot, pos, omega, vel, alpha, acl, work, z_first)
    for j in range(q.shape[0]):
        _carry_axes(j, rot, pos, sax, work)
        for r in range(3):
            sax[j, r] = axis[j, r]
            sax[j, 3 + r] = axis_v[j, r]
        _wrench_matrix(omega[j], alpha[j], acl[j], kmat)
        _regressor_block(j, sax, kmat, y, clear)


@njit(cache=True, fastmath=False, inline="always")
def _regressor_rows(lo, hi, geo, g0, state, y, clear, z_first) -> None:
    """Fill rows lo:hi of ``y`` (N, n, 10 n) with the regressor in the parameter order
    ``[m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``; the structurally zero entries are written
    if ``clear`` (any contents on entry), else left as they are (zeros on entry).

    Link j's wrench (moment; force) at the origin of F_j is linear in its parameters,
    ``wrench_j = K_j pi_j`` with::

        moment = h x acl + I alpha + w x (I w),   force = m acl + alpha x h + w x (w x h)

    and joint i's torque is ``S_i . X_{i<-j}^T wrench_j = (X_{j<-i} S_i) . K_j pi_j`` summed over
    j >= i: each joint axis is carried out to the links it moves instead of carrying every link's
    ten wrench columns back to each joint.
    """
    q, qd, qdd = state
    scratch = _regressor_scratch(q.shape[1])
    for k in range(lo, hi):
        _regressor_sample(geo, g0, q[k], qd[k], qdd[k], y[k], clear, scratch, z_first)


@njit(cache=True, fastmath=False, inline="always")
def _weighted(geo, g0, x, weights, y, scratch, z_first) -> float:
    """``sum(weights * Y(x))`` for one sample, ``x = (q, qd, qdd)`` (n,) each."""
    _regressor_sample(geo, g0, x[0], x[1], x[2], y, True, scratch, z_first)
    acc = 0.0
    for i in range(y.shape[0]):
        for c in range(y.shape[1]):
            acc += weights[i, c] * y[i, c]
    return acc


@njit(cache=True, fastmath=False)
def regressor_gradient_rows(lo, hi, geo, g0, state, weights, step_q, sens) -> None:
    """Rows lo:hi of ``sens`` (3, N, n): the derivatives of ``f = sum(weights[k] * Y_k)`` in
    every sample's ``q``, ``qd`` and ``qdd``.

    ``Y`` is linear in ``qdd`` and a quadratic in ``qd``, so a unit forward step in ``qdd`` and
    a central unit step in ``qd`` give their derivatives up to rounding; ``q`` takes a central
    step of ``step_q`` rad (error ``O(step_q^2)``).
    """
    q, qd, qdd = state
    n = q.shape[1]
    scratch = _regressor_scratch(n)
    y = np.empty((n, 10 * n))
    x = np.empty((3, n))
    steps = (step_q, 1.0)
    for k in range(lo, hi):
        x[0, :] = q[k]
        x[1, :] = qd[k]
        x[2, :] = qdd[k]
        w = weights[k]
        f0 = _weighted(geo, g0, x, w, y, scratch, False)
        for j in range(n):
            for kind in range(2):  # central steps in q, qd
                h = steps[kind]
                x[kind, j] += h
                up = _weighted(geo, g0, x, w, y, scratch, False)
                x[kind, j] -= 2.0 * h
                down = _weighted(geo, g0, x, w, y, scratch, False)
                x[kind, j] = state[kind][k, j]
                sens[kind, k, j] = (up - down) / (2.0 * h)
            x[2, j] += 1.0
            sens[2, k, j] = _weighted(geo, g0, x, w, y, scratch, False) - f0
            x[2, j] = qdd[k, j]


_CHUNK = 256  # samples per parallel work item
#: samples per parallel work item of the gradient (a sample costs 5 n + 1 regressors)
GRADIENT_CHUNK = 16


@njit(cache=True, fastmath=False)
def rnea_rows(lo, hi, geo, ends, body, state, wrench, tau) -> None:
    """:func:`_rnea_rows` for any chain."""
    _rnea_rows(lo, hi, geo, ends, body, state, wrench, tau, False)


@njit(cache=True, fastmath=False)
def rnea_rows_dh(lo, hi, geo, ends, body, state, wrench, tau) -> None:
    """:func:`_rnea_rows` for a chain whose joints turn first (``z_first``)."""
    _rnea_rows(lo, hi, geo, ends, body, state, wrench, tau, True)


@njit(cache=True, fastmath=False)
def regressor_rows(lo, hi, geo, g0, state, y, clear) -> None:
    """:func:`_regressor_rows` for any chain."""
    _regressor_rows(lo, hi, geo, g0, state, y, clear, False)


@njit(cache=True, fastmath=False)
def regressor_rows_dh(lo, hi, geo, g0, state, y, clear) -> None:
    """:func:`_regressor_rows` for a chain whose joints turn first (``z_first``)."""
    _regressor_rows(lo, hi, geo, g0, state, y, clear, True)


@njit(cache=True, parallel=True)
def rnea_kernel(geo, ends, body, state, wrench, tau) -> None:
    """:func:`rnea_rows` over all samples, split over threads."""
    big_n = tau.shape[0]
    for c in prange((big_n + _CHUNK - 1) // _CHUNK):
        rnea_rows(c * _CHUNK, min(big_n, (c + 1) * _CHUNK), geo, ends, body, state, wrench, tau)


@njit(cache=True, parallel=True)
def rnea_kernel_dh(geo, ends, body, state, wrench, tau) -> None:
    """:func:`rnea_rows_dh` over all samples, split over threads."""
    big_n = tau.shape[0]
    for c in prange((big_n + _CHUNK - 1) // _CHUNK):
        lo, hi = c * _CHUNK, min(big_n, (c + 1) * _CHUNK)
        rnea_rows_dh(lo, hi, geo, ends, body, state, wrench, tau)


@njit(cache=True, parallel=True)
def regressor_kernel(geo, g0, state, y, clear) -> None:
    """:func:`regressor_rows` over all samples, split over threads."""
    big_n = y.shape[0]
    for c in prange((big_n + _CHUNK - 1) // _CHUNK):
        regressor_rows(c * _CHUNK, min(big_n, (c + 1) * _CHUNK), geo, g0, state, y, clear)


@njit(cache=True, parallel=True)
def regressor_kernel_dh(geo, g0, state, y, clear) -> None:
    """:func:`regressor_rows_dh` over all samples, split over threads."""
    big_n = y.shape[0]
    for c in prange((big_n + _CHUNK - 1) // _CHUNK):
        regressor_rows_dh(c * _CHUNK, min(big_n, (c + 1) * _CHUNK), geo, g0, state, y, clear)


@njit(cache=True, parallel=True)
def regressor_gradient_kernel(geo, g0, state, weights, step_q, sens) -> None:
    """:func:`regressor_gradient_rows` over all samples, split over threads."""
    big_n = weights.shape[0]
    for c in prange((big_n + GRADIENT_CHUNK - 1) // GRADIENT_CHUNK):
        lo, hi = c * GRADIENT_CHUNK, min(big_n, (c + 1) * GRADIENT_CHUNK)
        regressor_gradient_rows(lo, hi, geo, g0, state, weights, step_q, sens)
