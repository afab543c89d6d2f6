"""The full method's physically consistent refit: least squares constrained to real bodies.

When the standard parameters closest to the model's (:func:`kinergy.identify.physical.
standard_from_base`) are not a physical link, or a rotor inertia comes out negative, the robot is
written from the least-squares fit constrained to physically consistent links (pseudo-inertia
positive definite, Wensing et al. 2018) and non-negative rotor inertias: a small convex problem on
the regression's own triangle (linear matrix inequalities), solved by a log-barrier method
(:func:`barrier_lsq`). It reproduces the identified base parameters exactly whenever they have a
physical realisation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from kinergy.dynamics.regressor import BaseParameters
from kinergy.identify.columns import Columns
from kinergy.identify.physical import (
    PSEUDO_BASIS,
    base_projection,
    link_consistency,
    pseudo_inertia,
)
from kinergy.identify.regression import Solved

__all__ = ["ConstrainedFit", "barrier_lsq", "physical_fit"]

Array = NDArray[np.float64]


# ---------------------------------------------------------------------------------------------
# The log-barrier solver


def _barrier(u: Array, c_blocks: Array, b_blocks: Array, a_vec: Array, r_mat: Array) -> float:
    """``-sum log det(C_l + sum_k u_k B_lk) - sum log(a + R u)``; inf outside the feasible set."""
    slack = a_vec + r_mat @ u
    if np.any(slack <= 0):
        return np.inf
    eig = np.linalg.eigvalsh(c_blocks + np.einsum("k,lkab->lab", u, b_blocks))
    if np.any(eig <= 0):
        return np.inf
    return float(-np.sum(np.log(eig)) - np.sum(np.log(slack)))


def _newton_step(
    u: Array, t: float, gtg: Array, gtr: Array, lmi: tuple[Array, Array], lin: tuple[Array, Array]
) -> tuple[Array, float] | None:
    """Newton step on ``t |r0 + jac u|^2 + barrier`` and its decrement; None when singular.
    ``lmi`` = (c_blocks, b_blocks), ``lin`` = (a_vec, r_mat)."""
    (c_blocks, b_blocks), (a_vec, r_mat) = lmi, lin
    inv = np.linalg.inv(c_blocks + np.einsum("k,lkab->lab", u, b_blocks))
    mk = np.einsum("lab,lkbc->lkac", inv, b_blocks)  # X^-1 B_k
    slack = a_vec + r_mat @ u
    grad = 2.0 * t * (gtg @ u + gtr) - np.einsum("lkaa->k", mk) - r_mat.T @ (1.0 / slack)
    hess = (
        2.0 * t * gtg + np.einsum("lkab,lmba->km", mk, mk) + (r_mat / slack[:, None] ** 2).T @ r_mat
    )
    try:
        step = -np.linalg.solve(hess, grad)
    except np.linalg.LinAlgError:
        return None
    return step, float(-grad @ step)


def barrier_lsq(
    r0: Array,
    jac: Array,
    lmi: tuple[Array, Array],
    lin: tuple[Array, Array],
    u0: Array,
    gap: float = 1e-3,
) -> Array | None:
    """``min |r0 + jac u|^2`` subject to ``C_l + sum_k u_k B_lk > 0`` (symmetric blocks) and
    ``a + R u > 0``, from a strictly feasible ``u0``: a log-barrier interior-point method with
    Newton steps (Boyd & Vandenberghe, Convex Optimization, section 11.3), stopped when the
    barrier's duality gap is below ``gap``.

    ``lmi`` = (``C`` (L, d, d), ``B`` (L, K, d, d)), ``lin`` = (``a`` (M,), ``R`` (M, K)).
    Returns ``None`` when ``u0`` is not strictly feasible or Newton fails.
    """
    gtg, gtr = jac.T @ jac, jac.T @ r0
    m = lmi[0].shape[0] * lmi[0].shape[1] + lin[0].size  # barrier weight count

    def merit(u: Array, t: float) -> float:
        r = r0 + jac @ u
        return t * float(r @ r) + _barrier(u, *lmi, *lin)

    u = u0.copy()
    if not np.isfinite(_barrier(u, *lmi, *lin)):
        return None
    t = m / max(float((r0 + jac @ u) @ (r0 + jac @ u)), 1e-6)
    for _ in range(60):  # outer: t grows tenfold each time
        for _ in range(100):  # Newton on t f + barrier
            newton = _newton_step(u, t, gtg, gtr, lmi, lin)
            if newton is None:
                return None
            step, decrement = newton
            if decrement / 2.0 < 1e-9:
                break
            value = merit(u, t)
            size = 1.0
            while size > 1e-12:
                trial = u + size * step
                if merit(trial, t) <= value - 0.25 * size * decrement:
                    break
                size *= 0.5
            else:
                break
            u = trial
        if m / t < gap:
            return u
        t *= 10.0
    return u


# ---------------------------------------------------------------------------------------------
# The constrained problem


@dataclass(frozen=True, eq=False)
class _Affine:
    """The unknowns of the constrained fit, ``u = [eta, t, delta]`` (``nk + nt + nd``).

    ``eta`` moves the kept unknowns along the regression's information (``x[kept] = x_hat +
    m_mat eta``, ``|eta|^2`` the chi^2 increase); ``t`` moves along the null space ``z_null`` of
    the base projection (standard parameters the data cannot see); ``delta`` moves the merged
    rotor inertias (``J = j0 + j_unit delta``). The standard parameters are ``pi = pi_a + b_mat u``.
    """

    m_mat: Array
    lam_h: Array
    vec_h: Array
    p_mat: Array
    k_mat: Array
    z_null: Array
    motors: list[int]
    j0: Array
    j_unit: Array
    c_dj: Array
    pi_a: Array
    b_mat: Array

    @property
    def sizes(self) -> tuple[int, int, int]:
        """``(nk, nt, nd)``."""
        return self.m_mat.shape[1], self.z_null.shape[1], len(self.motors)


def _information(problem: Solved) -> tuple[Array, Array, Array] | None:
    """Eigen-decomposition of the regression's information ``H`` in scaled unknowns, and
    ``m_mat`` with ``x[kept] - x_hat[kept] = m_mat @ eta`` (``|eta|^2`` the chi^2 increase)."""
    red, kept = problem.reduced, problem.kept
    s = red.scale[kept]
    # noise-free data: a floor at 1e-9 of the signal keeps H finite
    sigma2 = max(problem.sigma2, 1e-18 * float(red.r_y @ red.r_y) / red.rows, 1e-300)
    r_k = red.r_a[:, kept]
    # information in the scaled unknowns z = s x (unit-norm columns: well conditioned)
    hess = (r_k.T @ r_k + problem.lam * np.eye(kept.size)) / sigma2
    lam_h, vec_h = np.linalg.eigh(0.5 * (hess + hess.T))
    if lam_h[0] <= 0:
        return None
    return lam_h, vec_h, vec_h / np.sqrt(lam_h) / s[:, None]


def _affine(
    problem: Solved,
    base: BaseParameters,
    cols: Columns,
    x: Array,
    pi0: Array,
    scale: Array,
    merged_rotor: dict[int, Array],
) -> _Affine | None:
    """The standard parameters as an affine function of ``u`` (:class:`_Affine`):
    ``pi = pi_s(theta - C dJ) + S Z t`` with ``theta = theta_hat + m_mat[:b] eta``,
    ``pi_s`` = :func:`standard_from_base`'s map and ``C dJ`` the merged rotor inertias' share."""
    info = _information(problem)
    if info is None:
        return None
    lam_h, vec_h, m_mat = info
    n_link, p = cols.n_link, pi0.size
    p_mat = base_projection(base, p)
    k_mat = (scale**2)[:, None] * p_mat.T @ np.linalg.inv((p_mat * scale**2) @ p_mat.T)  # pi_s
    _, sv, vt = np.linalg.svd(p_mat * scale)
    z_null = vt[int(np.sum(sv > 1e-12 * sv[0])) :].T  # orthonormal, scaled coordinates
    motors = sorted(merged_rotor)
    j0 = np.array([cols.prior[n_link + m] for m in motors])
    j_unit = np.where(j0 > 0, j0, 1e-6)
    c_dj = (
        np.column_stack([merged_rotor[m] for m in motors]) * j_unit
        if motors
        else np.zeros((n_link, 0))
    )
    km = k_mat @ m_mat[:n_link]
    pi_a = pi0 + k_mat @ (x[:n_link] - p_mat @ pi0)
    b_mat = np.hstack([km, scale[:, None] * z_null, -k_mat @ c_dj])
    return _Affine(m_mat, lam_h, vec_h, p_mat, k_mat, z_null, motors, j0, j_unit, c_dj, pi_a, b_mat)


def _objective(aff: _Affine, pi0: Array, scale: Array, eps: float) -> tuple[Array, Array]:
    """``r0`` and ``jac`` of ``|eta|^2 + eps (|S^-1 (pi_s - pi0)|^2 + |t|^2 + |delta|^2)``."""
    nk, nt, nd = aff.sizes
    p = pi0.size
    root = np.sqrt(eps)
    r0 = np.concatenate([np.zeros(nk), root * (aff.pi_a - pi0) / scale, np.zeros(nt + nd)])
    jac = np.zeros((nk + p + nt + nd, nk + nt + nd))
    jac[:nk, :nk] = np.eye(nk)
    jac[nk : nk + p, :nk] = root * aff.b_mat[:, :nk] / scale[:, None]
    jac[nk : nk + p, nk + nt :] = -root * (aff.k_mat @ aff.c_dj) / scale[:, None]
    jac[nk + p :, nk:] = root * np.eye(nt + nd)
    return r0, jac


def _link_blocks(aff: _Affine, pi0: Array, payload: Array) -> tuple[Array, Array, Array] | None:
    """The links' constraints ``pseudo-inertia(pi - payload) > 1e-3`` times the start's smallest
    eigenvalue as blocks ``C + sum_k u_k B_k`` (each link normalised by that eigenvalue), and the
    start: the model, each link thickened by 1e-6 of its largest pseudo-inertia eigenvalue (a
    flat model link, e.g. a thin disc, sits on the boundary; the barrier needs the inside).
    None when the model itself is not physical."""
    n_links = pi0.size // 10
    eig0 = np.linalg.eigvalsh(pseudo_inertia(pi0 - payload))
    if np.any(eig0[:, 0] < -1e-9 * eig0[:, -1]):
        return None
    pi_start = pi0.copy()
    for link in range(n_links):  # Sigma + e 1  <=>  Ixx, Iyy, Izz + 2 e
        pi_start[10 * link + np.array([4, 6, 9])] += 2e-6 * eig0[link, -1]
    ref = np.linalg.eigvalsh(pseudo_inertia(pi_start - payload))[:, 0]
    c_blocks = pseudo_inertia(aff.pi_a - payload) / ref[:, None, None] - 1e-3 * np.eye(4)
    b_blocks = np.einsum("lpk,pab->lkab", aff.b_mat.reshape(n_links, 10, -1), PSEUDO_BASIS)
    b_blocks /= ref[:, None, None, None]
    return c_blocks, b_blocks, pi_start


def _rotor_bounds(
    aff: _Affine, cols: Columns, x: Array, kept: NDArray[np.intp]
) -> tuple[Array, Array]:
    """Rotor inertias, affine in ``u`` (kept ones through ``eta``, merged ones through
    ``delta``), ``>= -1e-3`` of their size (the barrier's strict start; clipped to 0 after), as
    ``a + R u > 0``."""
    nk, nt, nd = aff.sizes
    rotor_rows = np.flatnonzero([cols.group[k] == "rotor" for k in kept])
    rot_a = np.concatenate([x[kept[rotor_rows]], aff.j0])
    rot_b = np.zeros((rotor_rows.size + nd, nk + nt + nd))
    rot_b[: rotor_rows.size, :nk] = aff.m_mat[rotor_rows]
    rot_b[rotor_rows.size :, nk + nt :] = np.diag(aff.j_unit)
    rot_scale = np.maximum(np.abs(np.concatenate([cols.prior[kept[rotor_rows]], aff.j0])), 1e-9)
    return rot_a / rot_scale + 1e-3, rot_b / rot_scale[:, None]


def _start(
    aff: _Affine, problem: Solved, cols: Columns, x: Array, scale: Array, pi_start: Array
) -> Array:
    """``u`` of ``pi_start`` with the model's rotor inertias and friction (strictly feasible)."""
    nk, nt, nd = aff.sizes
    kept, n_link = problem.kept, cols.n_link
    s = problem.reduced.scale[kept]
    u0 = np.zeros(nk + nt + nd)
    x0 = cols.prior[kept].copy()
    x0[:n_link] = aff.p_mat @ pi_start
    u0[:nk] = np.sqrt(aff.lam_h) * (aff.vec_h.T @ (s * (x0 - x[kept])))
    pi_u0 = aff.pi_a + aff.b_mat[:, :nk] @ u0[:nk]  # = pi_s(P pi_start); the rest is null space
    u0[nk : nk + nt] = aff.z_null.T @ ((pi_start - pi_u0) / scale)
    return u0


@dataclass(frozen=True, eq=False)
class ConstrainedFit:
    """The constrained fit: standard parameters ``pi`` (p,), the regression unknowns they go with
    ``x`` (all columns; rotor inertias clipped at 0) and the chi^2 increase ``|eta|^2``."""

    pi: Array
    x: Array
    chi2: float


def _unknowns(aff: _Affine, problem: Solved, cols: Columns, x: Array, u: Array) -> Array:
    """The regression unknowns of the solution ``u``, rotor inertias clipped at 0."""
    nk, nt, _ = aff.sizes
    n_link, kept = cols.n_link, problem.kept
    out = x.copy()
    out[kept] = x[kept] + aff.m_mat @ u[:nk]
    out[:n_link] = aff.p_mat @ (aff.pi_a + aff.b_mat @ u)
    if aff.motors:
        out[n_link + np.array(aff.motors)] = aff.j0 + aff.j_unit * u[nk + nt :]
    n_rot = cols.group.count("rotor")
    out[n_link : n_link + n_rot] = np.maximum(out[n_link : n_link + n_rot], 0.0)
    return out


def physical_fit(
    problem: Solved,
    base: BaseParameters,
    cols: Columns,
    pi0: Array,
    scale: Array,
    payload: Array,
    merged_rotor: dict[int, Array],
    eps: float = 1e-3,
) -> ConstrainedFit | None:
    """Least squares constrained to physical links and non-negative rotor inertias.

    The regression's cost grows from its minimum ``x_hat = problem.x`` (kept unknowns) as
    ``(x - x_hat)^T H (x - x_hat)``, ``H`` from the reduced triangle (``(R^T R + lambda 1) /
    sigma^2`` in scaled unknowns); with ``x - x_hat = V Lambda^-1/2 eta`` (``H = V Lambda V^T``)
    that is ``|eta|^2``, a chi^2 increase. The link base parameters ``theta`` are ``x``'s first
    ``b``; the standard parameters are ``pi = pi_s(theta - C dJ) + S Z t``
    (:func:`~kinergy.identify.physical.standard_from_base` plus the null space ``Z`` of ``P S``;
    ``C dJ`` moves merged rotor inertias, ``dJ = J_model delta``), and ::

        |eta|^2 + eps (|S^-1 (pi_s - pi0)|^2 + |t|^2 + |delta|^2)

    is minimised subject to every link's pseudo-inertia (of ``pi - payload``, kg and m) staying
    above 1e-3 times the model's smallest eigenvalue and every rotor inertia being >= 0 (a convex
    problem: linear matrix inequalities, solved by :func:`barrier_lsq` from the model, which is
    feasible); ``eps`` only settles what the data cannot see. ``pi0`` (p,) are the model's
    standard parameters, ``scale`` (p,) their typical sizes, ``merged_rotor`` the merged rotor
    columns in link base columns (motor -> (b,)).

    Returns
    -------
    ConstrainedFit or None
        ``None`` when the solver fails or its links are still not physical.
    """
    aff = _affine(problem, base, cols, problem.x, pi0, scale, merged_rotor)
    if aff is None:
        return None
    blocks = _link_blocks(aff, pi0, payload)
    if blocks is None:
        return None
    c_blocks, b_blocks, pi_start = blocks
    r0, jac = _objective(aff, pi0, scale, eps)
    u0 = _start(aff, problem, cols, problem.x, scale, pi_start)
    lin = _rotor_bounds(aff, cols, problem.x, problem.kept)
    u = barrier_lsq(r0, jac, (c_blocks, b_blocks), lin, u0)
    if u is None:
        return None
    pi = aff.pi_a + aff.b_mat @ u
    if any(e is not None for e in link_consistency(pi - payload)):
        return None
    nk = aff.sizes[0]
    return ConstrainedFit(pi, _unknowns(aff, problem, cols, problem.x, u), float(u[:nk] @ u[:nk]))
