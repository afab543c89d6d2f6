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
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import NDArray

Array = NDArray[np.float64]

__all__ = ["regressor_kernel", "rnea_kernel"]


@njit(cache=True, fastmath=False, inline="always")
def _cross(a: Array, b: Array, out: Array) -> None:
    x = a[1] * b[2] - a[2] * b[1]
    y = a[2] * b[0] - a[0] * b[2]
    z = a[0] * b[1] - a[1] * b[0]
    out[0], out[1], out[2] = x, y, z


@njit(cache=True, fastmath=False, inline="always")
def _motion_pass(
    geo: tuple[Array, Array, Array, Array, Array, Array, Array, Array],
    g0: Array,
    q: Array,
    qd: Array,
    qdd: Array,
    rot: Array,
    pos: Array,
    omega: Array,
    vel: Array,
    alpha: Array,
    acl: Array,
    work: Array,
) -> None:
    """Forward recursion for one sample: fills rot, pos (n,3,3), (n,3) and the link velocities
    omega, vel, accelerations alpha and classical linear acceleration acl (n, 3) in F_i.
    ``work`` is scratch space of shape (9, 3)."""
    a_mat, b_mat, c_mat, pa, pb, pc, axis, axis_v = geo
    n = q.shape[0]
    w_p, v_p, al_p, ac_p, t1, t2, sw, sv, ac = (
        work[0],
        work[1],
        work[2],
        work[3],
        work[4],
        work[5],
        work[6],
        work[7],
        work[8],
    )
    for r in range(3):
        w_p[r] = 0.0
        v_p[r] = 0.0
        al_p[r] = 0.0
        ac_p[r] = -g0[r]
    for i in range(n):
        c = np.cos(q[i])
        s = np.sin(q[i])
        for r in range(3):
            pos[i, r] = c * pa[i, r] + s * pb[i, r] + pc[i, r]
            for k in range(3):
                rot[i, r, k] = c * a_mat[i, r, k] + s * b_mat[i, r, k] + c_mat[i, r, k]
        # t1 = v_p + w_p x p ; t2 = ac_p + al_p x p   (spatial transform, parent coordinates)
        _cross(w_p, pos[i], t1)
        _cross(al_p, pos[i], t2)
        for r in range(3):
            t1[r] += v_p[r]
            t2[r] += ac_p[r]
            sw[r] = axis[i, r] * qd[i]
            sv[r] = axis_v[i, r] * qd[i]
        for r in range(3):  # rotate into F_i with R^T
            omega[i, r] = (
                rot[i, 0, r] * w_p[0] + rot[i, 1, r] * w_p[1] + rot[i, 2, r] * w_p[2] + sw[r]
            )
            vel[i, r] = rot[i, 0, r] * t1[0] + rot[i, 1, r] * t1[1] + rot[i, 2, r] * t1[2] + sv[r]
            alpha[i, r] = (
                rot[i, 0, r] * al_p[0]
                + rot[i, 1, r] * al_p[1]
                + rot[i, 2, r] * al_p[2]
                + axis[i, r] * qdd[i]
            )
            ac[r] = (
                rot[i, 0, r] * t2[0]
                + rot[i, 1, r] * t2[1]
                + rot[i, 2, r] * t2[2]
                + axis_v[i, r] * qdd[i]
            )
        # velocity-product terms: v_i x_m (S_i qd_i)
        _cross(omega[i], sw, t1)
        for r in range(3):
            alpha[i, r] += t1[r]
        _cross(omega[i], sv, t1)
        _cross(vel[i], sw, t2)
        for r in range(3):
            ac[r] += t1[r] + t2[r]
        for r in range(3):
            w_p[r] = omega[i, r]
            v_p[r] = vel[i, r]
            al_p[r] = alpha[i, r]
            ac_p[r] = ac[r]
        _cross(omega[i], vel[i], t1)
        for r in range(3):
            acl[i, r] = ac[r] + t1[r]


@njit(cache=True, fastmath=False)
def _rnea_chunk(
    lo: int,
    hi: int,
    geo: tuple[Array, Array, Array, Array, Array, Array, Array, Array],
    base_rot: Array,
    flange_pos: Array,
    g0: Array,
    mass: Array,
    first: Array,
    inertia: Array,
    q: Array,
    qd: Array,
    qdd: Array,
    wrench: Array,
    use_wrench: bool,
    tau: Array,
) -> None:
    """Fill rows lo:hi of ``tau`` (N, n) with the joint torques for states (N, n); ``inertia``
    about the link origins (n, 3, 3)."""
    axis, axis_v = geo[6], geo[7]
    n = q.shape[1]
    rot = np.empty((n, 3, 3))
    pos = np.empty((n, 3))
    omega = np.empty((n, 3))
    vel = np.empty((n, 3))
    alpha = np.empty((n, 3))
    acl = np.empty((n, 3))
    force = np.empty((n, 3))
    moment = np.empty((n, 3))
    t1 = np.zeros(3)
    t2 = np.zeros(3)
    iw = np.zeros(3)
    world = np.zeros((3, 3))
    tmp = np.zeros((3, 3))
    work = np.zeros((9, 3))
    for k in range(lo, hi):
        _motion_pass(geo, g0, q[k], qd[k], qdd[k], rot, pos, omega, vel, alpha, acl, work)
        for i in range(n):
            h = first[i]
            # force = m acl + alpha x h + w x (w x h)
            _cross(alpha[i], h, t1)
            _cross(omega[i], h, t2)
            _cross(omega[i], t2, iw)
            for r in range(3):
                force[i, r] = mass[i] * acl[i, r] + t1[r] + iw[r]
            # moment = I alpha + w x (I w) + h x acl
            for r in range(3):
                t1[r] = (
                    inertia[i, r, 0] * omega[i, 0]
                    + inertia[i, r, 1] * omega[i, 1]
                    + inertia[i, r, 2] * omega[i, 2]
                )
            _cross(omega[i], t1, t2)
            _cross(h, acl[i], iw)
            for r in range(3):
                moment[i, r] = (
                    inertia[i, r, 0] * alpha[i, 0]
                    + inertia[i, r, 1] * alpha[i, 1]
                    + inertia[i, r, 2] * alpha[i, 2]
                    + t2[r]
                    + iw[r]
                )
        if use_wrench:
            world[:, :] = base_rot
            for i in range(n):
                for r in range(3):
                    for c in range(3):
                        tmp[r, c] = (
                            world[r, 0] * rot[i, 0, c]
                            + world[r, 1] * rot[i, 1, c]
                            + world[r, 2] * rot[i, 2, c]
                        )
                world[:, :] = tmp
            for r in range(3):
                t1[r] = (
                    world[0, r] * wrench[k, 0]
                    + world[1, r] * wrench[k, 1]
                    + world[2, r] * wrench[k, 2]
                )
                t2[r] = (
                    world[0, r] * wrench[k, 3]
                    + world[1, r] * wrench[k, 4]
                    + world[2, r] * wrench[k, 5]
                )
            _cross(flange_pos, t1, iw)
            for r in range(3):
                force[n - 1, r] += t1[r]
                moment[n - 1, r] += t2[r] + iw[r]
        for i in range(n - 1, -1, -1):
            tau[k, i] = (
                moment[i, 0] * axis[i, 0]
                + moment[i, 1] * axis[i, 1]
                + moment[i, 2] * axis[i, 2]
                + force[i, 0] * axis_v[i, 0]
                + force[i, 1] * axis_v[i, 1]
                + force[i, 2] * axis_v[i, 2]
            )
            if i > 0:
                for r in range(3):
                    t1[r] = (
                        rot[i, r, 0] * force[i, 0]
                        + rot[i, r, 1] * force[i, 1]
                        + rot[i, r, 2] * force[i, 2]
                    )
                    t2[r] = (
                        rot[i, r, 0] * moment[i, 0]
                        + rot[i, r, 1] * moment[i, 1]
                        + rot[i, r, 2] * moment[i, 2]
                    )
                _cross(pos[i], t1, iw)
                for r in range(3):
                    force[i - 1, r] += t1[r]
                    moment[i - 1, r] += t2[r] + iw[r]


@njit(cache=True, fastmath=False)
def _regressor_chunk(
    lo: int,
    hi: int,
    geo: tuple[Array, Array, Array, Array, Array, Array, Array, Array],
    g0: Array,
    q: Array,
    qd: Array,
    qdd: Array,
    y: Array,
) -> None:
    """Fill ``y`` (N, n, 10 n), zeros on entry, with the regressor in the parameter order ``[m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``.

    Link j's wrench (moment; force) at the origin of F_j is linear in its parameters,
    ``wrench_j = K_j pi_j`` with::

        moment = h x acl + I alpha + w x (I w),   force = m acl + alpha x h + w x (w x h)

    and joint i's torque is ``S_i . X_{i<-j}^T wrench_j = (X_{j<-i} S_i) . K_j pi_j`` summed over
    j >= i: each joint axis is carried out to the links it moves instead of carrying every link's
    ten wrench columns back to each joint.
    """
    axis, axis_v = geo[6], geo[7]
    n = q.shape[1]
    rot = np.empty((n, 3, 3))
    pos = np.empty((n, 3))
    omega = np.empty((n, 3))
    vel = np.empty((n, 3))
    alpha = np.empty((n, 3))
    acl = np.empty((n, 3))
    work = np.zeros((9, 3))
    sax = np.empty((n, 6))  # joint axes (angular; linear) in the current link frame
    kmat = np.empty((6, 10))
    t1 = np.zeros(3)
    t2 = np.zeros(3)
    for k in range(lo, hi):
        _motion_pass(geo, g0, q[k], qd[k], qdd[k], rot, pos, omega, vel, alpha, acl, work)
        for j in range(n):
            # carry the axes of joints 0..j-1 from F_{j-1} into F_j: w' = R^T w, v' = R^T (v + w x p)
            for i in range(j):
                t1[0] = sax[i, 0]
                t1[1] = sax[i, 1]
                t1[2] = sax[i, 2]
                _cross(t1, pos[j], t2)
                for r in range(3):
                    t2[r] += sax[i, 3 + r]
                for r in range(3):
                    sax[i, r] = rot[j, 0, r] * t1[0] + rot[j, 1, r] * t1[1] + rot[j, 2, r] * t1[2]
                    sax[i, 3 + r] = (
                        rot[j, 0, r] * t2[0] + rot[j, 1, r] * t2[1] + rot[j, 2, r] * t2[2]
                    )
            for r in range(3):
                sax[j, r] = axis[j, r]
                sax[j, 3 + r] = axis_v[j, r]
            w = omega[j]
            al = alpha[j]
            ac = acl[j]
            wx, wy, wz = w[0], w[1], w[2]
            ax, ay, az = al[0], al[1], al[2]
            # K_j, rows 0-2 moment, 3-5 force; columns m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz
            for r in range(6):
                for c in range(10):
                    kmat[r, c] = 0.0
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
            c0 = 10 * j
            for i in range(j + 1):  # skip K_j's structural zeros
                y[k, i, c0] = (
                    sax[i, 3] * kmat[3, 0] + sax[i, 4] * kmat[4, 0] + sax[i, 5] * kmat[5, 0]
                )
                for c in range(1, 4):
                    acc = 0.0
                    for r in range(6):
                        acc += sax[i, r] * kmat[r, c]
                    y[k, i, c0 + c] = acc
                for c in range(4, 10):
                    y[k, i, c0 + c] = (
                        sax[i, 0] * kmat[0, c] + sax[i, 1] * kmat[1, c] + sax[i, 2] * kmat[2, c]
                    )


_CHUNK = 256  # samples per parallel work item


@njit(cache=True, parallel=True)
def rnea_kernel(
    geo: tuple[Array, Array, Array, Array, Array, Array, Array, Array],
    base_rot: Array,
    flange_pos: Array,
    g0: Array,
    mass: Array,
    first: Array,
    inertia: Array,
    q: Array,
    qd: Array,
    qdd: Array,
    wrench: Array,
    use_wrench: bool,
    tau: Array,
) -> None:
    """Fill ``tau`` (N, n) with rigid-body joint torques; samples split over threads."""
    big_n = q.shape[0]
    chunks = (big_n + _CHUNK - 1) // _CHUNK
    for c in prange(chunks):
        _rnea_chunk(
            c * _CHUNK,
            min(big_n, (c + 1) * _CHUNK),
            geo,
            base_rot,
            flange_pos,
            g0,
            mass,
            first,
            inertia,
            q,
            qd,
            qdd,
            wrench,
            use_wrench,
            tau,
        )


@njit(cache=True, parallel=True)
def regressor_kernel(
    geo: tuple[Array, Array, Array, Array, Array, Array, Array, Array],
    g0: Array,
    q: Array,
    qd: Array,
    qdd: Array,
    y: Array,
) -> None:
    """Fill ``y`` (N, n, 10 n), zeros on entry, with the regressor; samples split over threads."""
    big_n = q.shape[0]
    chunks = (big_n + _CHUNK - 1) // _CHUNK
    for c in prange(chunks):
        _regressor_chunk(c * _CHUNK, min(big_n, (c + 1) * _CHUNK), geo, g0, q, qd, qdd, y)
