"""The full method's physically consistent fit: least squares constrained to real bodies and drives.

When the unconstrained least squares of :mod:`kinergy.identify.regression` has no physical
realisation (a link whose standard parameters closest to the model's are not a real body, a
negative rotor inertia, friction outside its model's bounds), the
robot is written from the least-squares fit constrained to physical values instead: a convex
problem (a semidefinite program) solved by cvxpy with Clarabel (SCS as the fallback):

    minimise    |R z - r|^2 / sse_0  +  eps |S^-1 (pi - pi_0)|^2  +  eps_d |dropped - prior|^2
    subject to  T_l P_l(pi - payload) T_l  >=  margin 1     (each link, Wensing et al. 2018)
                rotor inertias >= 0,  friction within FrictionModel.bounds

``R z - r`` is the regression's own reduced triangle (:func:`kinergy.linalg.reduce`, column-scaled
unknowns ``z``, so the data enter as a (p + 1) x p matrix whatever the number of samples), ``pi``
the links' standard parameters (10 per link) whose base projection gives the link columns,
``P_l`` link ``l``'s 4x4 pseudo-inertia (positive definite exactly for a physically consistent
link), ``T_l`` a scaling that makes it dimensionless (kg and 0.1 m). The small ``eps`` terms
only settle what the data cannot see: the standard parameters outside the base projection stay
nearest the model's, and columns the data cannot tell apart stay at the model's unless a
constraint moves them. With ``sse_0`` the unconstrained fit's squared residual, the objective's
rise times ``rows - parameters`` is the chi^2 the constraints cost.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cvxpy as cp
import numpy as np
from numpy.typing import NDArray

from kinergy.dynamics.regressor import BaseParameters
from kinergy.friction.registry import get_model
from kinergy.identify.columns import Columns
from kinergy.identify.physical import (
    LENGTH_SCALE,
    PSEUDO_BASIS,
    base_projection,
    link_consistency,
    pseudo_inertia,
)
from kinergy.identify.regression import Solved

__all__ = ["MARGIN", "ConstrainedFit", "bounds", "physical_fit"]

Array = NDArray[np.float64]

#: smallest eigenvalue of each link's scaled pseudo-inertia (kg and LENGTH_SCALE as units)
MARGIN = 1e-5
#: weights of the terms that settle the directions the data cannot see
_EPS_LINKS = 1e-9
_EPS_DROPPED = 1e-3


def bounds(cols: Columns, models: Sequence[str]) -> tuple[Array, Array]:
    """Lower and upper bounds of every non-link column (p - b,), in the unknowns' own units:
    rotor inertias >= 0, each friction level within its model's ``bounds``
    (:class:`kinergy.friction.model.FrictionModel`)."""
    n_extra = len(cols.group) - cols.n_link
    lo, hi = np.full(n_extra, -np.inf), np.full(n_extra, np.inf)
    n = len(models)
    lo[:n] = 0.0
    for m, model in enumerate(models):
        spec = get_model(model)
        for k, name in enumerate(spec.linear):
            low, high = spec.bounds.get(name, (-np.inf, np.inf))
            at = int(cols.fric_at[m]) + k - cols.n_link
            lo[at], hi[at] = low, high
    return lo, hi


@dataclass(frozen=True, eq=False)
class ConstrainedFit:
    """The constrained fit.

    Attributes
    ----------
    pi : ndarray, shape (10 n,)
        Standard parameters of the links (payload included), kg, kg m, kg m^2.
    x : ndarray, shape (p,)
        The regression unknowns they go with (link columns the base projection of ``pi``).
    chi2 : float
        The chi^2 the constraints cost: the rise of the squared residual over the residual
        variance.
    active : tuple of str
        The constraints the solution sits on, one phrase each.
    at_bound : tuple of int
        Columns (indices into ``x``) held at a bound.
    solver : str
    """

    pi: Array
    x: Array
    chi2: float
    active: tuple[str, ...]
    at_bound: tuple[int, ...]
    solver: str


def _link_scaling(pi0: Array) -> Array:
    """``T_l`` (n, 4, 4): diag(1 / (L sqrt(m)), ..., 1 / sqrt(m)) with the model's link masses."""
    mass = np.maximum(pi0.reshape(-1, 10)[:, 0], 1e-3)
    t = np.zeros((mass.size, 4, 4))
    for k in range(3):
        t[:, k, k] = 1.0 / (LENGTH_SCALE * np.sqrt(mass))
    t[:, 3, 3] = 1.0 / np.sqrt(mass)
    return t


def _lmi(pi: cp.Expression, payload: Array, t: Array) -> tuple[list[cp.Constraint], list[Array]]:
    """Each link's scaled pseudo-inertia above :data:`MARGIN`; the constraint and the constant
    matrices ``T E_k T`` it is made of (n, 10, 4, 4 as a list per link)."""
    constraints, pieces = [], []
    for link in range(t.shape[0]):
        basis = np.einsum("ab,kbc,cd->kad", t[link], PSEUDO_BASIS, t[link])
        shift = np.einsum("k,kab->ab", payload[10 * link : 10 * link + 10], basis)
        mat = sum(pi[10 * link + k] * basis[k] for k in range(10)) - shift
        constraints.append(0.5 * (mat + mat.T) >> MARGIN * np.eye(4))
        pieces.append(basis)
    return constraints, pieces


def _solve(problem: cp.Problem) -> str | None:
    """Solve with Clarabel, else SCS; the solver's name, or None when neither finds the optimum."""
    for solver in ("CLARABEL", "SCS"):
        try:
            problem.solve(solver=solver)
        except (cp.error.SolverError, ValueError):  # pragma: no cover - solver failure
            continue
        if problem.status in ("optimal", "optimal_inaccurate"):
            return solver
    return None


def _active(
    x: Array, cols: Columns, lo: Array, hi: Array, pi: Array, payload: Array, names: Sequence[str]
) -> tuple[list[str], list[int]]:
    """The constraints ``x`` and ``pi`` sit on (within 1e-6 of the bound's scale)."""
    phrases, at_bound = [], []
    t = _link_scaling(pi)
    eig = np.linalg.eigvalsh(np.einsum("lab,lbc,lcd->lad", t, pseudo_inertia(pi - payload), t))
    for link, low in enumerate(eig[:, 0]):
        if low < 1.01 * MARGIN:
            phrases.append(
                f"link {link + 1} ({names[link]}): physical consistency (pseudo-inertia at its margin)"
            )
    extra = x[cols.n_link :]
    for k, (value, low, high) in enumerate(zip(extra, lo, hi, strict=True)):
        size = max(abs(float(cols.prior[cols.n_link + k])), 1e-9)
        if np.isfinite(low) and value <= low + 1e-6 * size:
            phrases.append(f"{cols.names[cols.n_link + k]} at its lower bound {low:.4g}")
            at_bound.append(cols.n_link + k)
        elif np.isfinite(high) and value >= high - 1e-6 * size:
            phrases.append(f"{cols.names[cols.n_link + k]} at its upper bound {high:.4g}")
            at_bound.append(cols.n_link + k)
    return phrases, at_bound


def physical_fit(
    problem: Solved,
    base: BaseParameters,
    cols: Columns,
    models: Sequence[str],
    pi0: Array,
    scale: Array,
    payload: Array,
    names: Sequence[str],
) -> ConstrainedFit | None:
    """Least squares on the regression's reduced triangle constrained to physical values (module
    docstring).

    Parameters
    ----------
    problem : Solved
        The unconstrained regression (its triangle, ridge weight, kept and dropped columns).
    base : BaseParameters
    cols : Columns
    models : sequence of str
        Each motor's friction model (its ``bounds`` bound the friction columns).
    pi0 : ndarray, shape (10 n,)
        The model's standard parameters (payload included).
    scale : ndarray, shape (10 n,)
        Typical size of each standard parameter (:func:`~kinergy.identify.physical.parameter_scale`).
    payload : ndarray, shape (10 n,)
        The payload's share of ``pi0`` (the last link's), which the links' consistency excludes.
    names : sequence of str
        Joint names, for the active-constraint phrases.

    Returns
    -------
    ConstrainedFit or None
        ``None`` when neither solver finds the optimum or a link is still not physical.
    """
    red = problem.reduced
    n_link, p = cols.n_link, cols.prior.size
    p_mat = base_projection(base, pi0.size)
    lo, hi = bounds(cols, models)
    sse0 = max(problem.solution.sse, 1e-300)
    v = cp.Variable(pi0.size)
    z_extra = cp.Variable(p - n_link)
    pi = pi0 + cp.multiply(scale, v)
    z = cp.hstack([cp.multiply(red.scale[:n_link], p_mat @ pi), z_extra])
    z_prior = cols.prior * red.scale
    fit = cp.sum_squares(red.r_a @ z - red.r_y)
    if problem.lam > 0.0:
        kept = problem.kept
        fit = fit + problem.lam * cp.sum_squares(z[kept] - z_prior[kept])
    dropped = problem.dropped[problem.dropped >= n_link] - n_link
    size = np.maximum(np.abs(z_prior[n_link:][dropped]), 1e-6 * float(np.linalg.norm(red.r_y)))
    objective = fit / sse0 + _EPS_LINKS * cp.sum_squares(v)
    if dropped.size:
        gap = (z_extra[dropped] - z_prior[n_link:][dropped]) / size
        objective = objective + _EPS_DROPPED * cp.sum_squares(gap)
    t = _link_scaling(pi0)
    constraints, _ = _lmi(pi, payload, t)
    s_extra = red.scale[n_link:]
    finite_lo, finite_hi = np.isfinite(lo), np.isfinite(hi)
    if finite_lo.any():
        constraints.append(z_extra[finite_lo] >= (lo * s_extra)[finite_lo])
    if finite_hi.any():
        constraints.append(z_extra[finite_hi] <= (hi * s_extra)[finite_hi])
    solver = _solve(cp.Problem(cp.Minimize(objective), constraints))
    if solver is None or v.value is None or z_extra.value is None:
        return None
    pi_hat = pi0 + scale * np.asarray(v.value)
    if any(e is not None for e in link_consistency(pi_hat - payload)):
        return None
    x = np.empty(p)
    x[:n_link] = p_mat @ pi_hat
    x[n_link:] = np.clip(np.asarray(z_extra.value) / s_extra, lo, hi)
    z_hat = x * red.scale
    sse = float(np.sum((red.r_a @ z_hat - red.r_y) ** 2))
    chi2 = max(sse - problem.solution.sse, 0.0) / max(problem.sigma2, 1e-300)
    phrases, at_bound = _active(x, cols, lo, hi, pi_hat, payload, names)
    return ConstrainedFit(pi_hat, x, chi2, tuple(phrases), tuple(at_bound), solver)
