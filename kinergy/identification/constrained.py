"""The full method's physically consistent fit: least squares constrained to real bodies and drives.

When the unconstrained least squares of :mod:`kinergy.identification.regression` has no physical
realisation (a link whose standard parameters closest to the model's are not a real body, a
negative rotor inertia, friction outside its model's bounds), the
robot is written from the least-squares fit constrained to physical values instead: a convex
problem (a semidefinite program) solved by cvxpy with Clarabel (SCS as the fallback):

    minimise    |R (z - z_hat)|^2 / (sigma^2 c)  +  eps |S^-1 (pi - pi_0)|^2  +  eps_d |dropped - prior|^2
    subject to  T_l P_l(pi - payload) T_l  >=  margin 1     (each link, Wensing et al. 2018)
                rotor inertias >= 0,  friction within FrictionModel.bounds

``R`` is the regression's own reduced triangle (:func:`kinergy.linalg.reduce`, column-scaled
unknowns ``z``, so the data enter as a (p + 1) x p matrix whatever the number of samples) and
``z_hat`` its least-squares optimum, so the first term is the chi^2 the constraints cost
(``|R z - r|^2 = |R (z - z_hat)|^2 + sse_0``, the residual being orthogonal to the columns),
in units ``c`` of the chi^2 the model itself would cost (feasible, so the optimum is below 1); ``pi``
the links' standard parameters (10 per link) whose base projection gives the link columns,
``P_l`` link ``l``'s 4x4 pseudo-inertia (positive definite exactly for a physically consistent
link), ``T_l`` a scaling that makes it dimensionless (kg and 0.1 m). The small ``eps`` terms
only settle what the data cannot see: the standard parameters outside the base projection stay
nearest the model's, and columns the data cannot tell apart stay at the model's unless a
constraint moves them.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import cvxpy as cp
import numpy as np

from kinergy.arrays import Array
from kinergy.dynamics.regressor import BaseParameters
from kinergy.friction.model import FrictionModel
from kinergy.identification.columns import Columns
from kinergy.identification.physical import (
    LENGTH_SCALE,
    PSEUDO_BASIS,
    base_projection,
    link_consistency,
    pseudo_inertia,
)
from kinergy.identification.regression import Solved

__all__ = ["MARGIN", "ConstrainedFit", "bounds", "physical_fit"]


#: smallest eigenvalue of each link's scaled pseudo-inertia (kg and LENGTH_SCALE as units)
MARGIN = 1e-5
#: weights (in units of the model's chi^2) of the terms that settle what the data cannot see
_EPS_LINKS = 1e-6
_EPS_DROPPED = 1e-4
#: singular values of the regression's triangle below this share of the largest are round-off
_ROUND_OFF = 1e-12


def bounds(cols: Columns, models: Sequence[FrictionModel]) -> tuple[Array, Array]:
    """Lower and upper bounds of every non-link column (p - b,), in the unknowns' own units:
    rotor inertias >= 0, each friction level within its model's ``bounds``
    (:class:`kinergy.friction.model.FrictionModel`)."""
    n_extra = len(cols.group) - cols.n_link
    lo, hi = np.full(n_extra, -np.inf), np.full(n_extra, np.inf)
    n = len(models)
    lo[:n] = 0.0
    for m, model in enumerate(models):
        for k, name in enumerate(model.linear):
            low, high = model.bounds.get(name, (-np.inf, np.inf))
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


def _metric(problem: Solved) -> Array:
    """``L`` with ``|L (z - z_hat)|^2`` the chi^2 increase of the unknowns ``z`` (scaled) over the
    regression's optimum ``z_hat``: the triangle (with the ridge term) over the residual's
    standard deviation (floored at 1e-6 of the signal for noise-free data), in the canonical
    form ``S V^T`` of its singular value decomposition, the directions whose singular value is
    round-off (below :data:`_ROUND_OFF` of the largest: columns the data cannot tell apart)
    left out.

    The triangle is the least-squares problem only up to rotations of its rows, and where
    columns are merged its last rows are round-off that depends on how the rows were folded;
    the solver equilibrates rows, so those would steer where it stops along the directions the
    data do not see. In canonical form the constrained fit depends on the problem alone, not on
    the chunks its rows came in."""
    red = problem.reduced
    sigma2 = max(problem.sigma2, 1e-12 * float(red.r_y @ red.r_y) / red.rows, 1e-300)
    rows = [red.r_a]
    if problem.lam > 0.0:
        ridge = np.zeros((problem.kept.size, red.r_a.shape[1]))
        ridge[np.arange(problem.kept.size), problem.kept] = np.sqrt(problem.lam)
        rows.append(ridge)
    _, s, vt = np.linalg.svd(np.vstack(rows), full_matrices=False)
    keep = s > _ROUND_OFF * s[0]
    sign = np.sign(vt[np.arange(vt.shape[0]), np.argmax(np.abs(vt), axis=1)])
    return np.asarray(((s * sign)[:, None] * vt)[keep] / np.sqrt(sigma2))


def _solve(problem: cp.Problem) -> str | None:
    """Solve with Clarabel, else SCS; the solver's name, or None when neither finds the optimum."""
    for solver in ("CLARABEL", "SCS"):
        try:
            with warnings.catch_warnings():  # "inaccurate" is judged below, by the links
                warnings.simplefilter("ignore", UserWarning)
                problem.solve(solver=solver)
        except (cp.error.SolverError, ValueError):  # pragma: no cover - solver failure
            continue
        if problem.status in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
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
        if cols.n_link + k in cols.fixed:  # not an unknown: the model's value, not a bound's
            continue
        size = max(abs(float(cols.prior[cols.n_link + k])), 1e-9)
        if np.isfinite(low) and value <= low + 1e-6 * size:
            phrases.append(f"{cols.names[cols.n_link + k]} at its lower bound {low:.4g}")
            at_bound.append(cols.n_link + k)
        elif np.isfinite(high) and value >= high - 1e-6 * size:
            phrases.append(f"{cols.names[cols.n_link + k]} at its upper bound {high:.4g}")
            at_bound.append(cols.n_link + k)
    return phrases, at_bound


def _realisation(
    problem: Solved,
    base: BaseParameters,
    cols: Columns,
    pis: tuple[Array, Array, Array],
    merged_rotor: dict[int, Array],
    t: Array,
) -> tuple[Array, Array, str] | None:
    """Physical links that reproduce the identified base parameters exactly, the constrained
    problem's solution at no cost, when they exist (None otherwise).

    Among them, the standard parameters closest to the model's (``|S^-1 (pi - pi0)|``, ``pis`` =
    (pi0, scale, payload)); a rotor inertia merged into link columns (``merged_rotor``, motor ->
    its column in link base columns, (b,)) may move by ``d >= -J_model`` with the links taking
    ``-C d`` so the torques stay the identified ones. Returns the standard parameters, all
    unknowns and the solver.
    """
    pi0, scale, payload = pis
    n_link = base.size
    motors = sorted(merged_rotor)
    v = cp.Variable(pi0.size)
    pi = pi0 + cp.multiply(scale, v)
    p_mat = base_projection(base, pi0.size)
    theta = problem.x[:n_link]
    size = np.maximum(np.abs(theta), 1e-12 * max(float(np.abs(theta).max()), 1e-300))
    constraints, _ = _lmi(pi, payload, t)
    j0 = np.array([cols.prior[n_link + m] for m in motors])
    d = cp.Variable(len(motors))
    shift = 0.0
    objective = cp.sum_squares(v)
    if motors:
        c_mat = np.column_stack([merged_rotor[m] for m in motors])
        unit = np.where(j0 > 0, j0, 1e-6)
        shift = c_mat @ cp.multiply(unit, d)
        constraints.append(j0 + cp.multiply(unit, d) >= 0)
        objective = objective + cp.sum_squares(d)
    constraints.append((p_mat @ pi + shift - theta) / size == 0)
    solver = _solve(cp.Problem(cp.Minimize(objective), constraints))
    if solver is None or v.value is None:
        return None
    x = problem.x.copy()
    if motors:
        moved = j0 + np.where(j0 > 0, j0, 1e-6) * np.asarray(d.value)
        x[n_link + np.array(motors)] = np.maximum(moved, 0.0)
    return pi0 + scale * np.asarray(v.value), x, solver


def _within(z: cp.Variable, lo: Array, hi: Array) -> list[cp.Constraint]:
    """``lo <= z <= hi`` where the bounds are finite."""
    out = []
    for bound, sign in ((lo, 1.0), (hi, -1.0)):
        finite = np.isfinite(bound)
        if finite.any():
            out.append(sign * z[finite] >= sign * bound[finite])
    return out


def physical_fit(
    problem: Solved,
    base: BaseParameters,
    cols: Columns,
    models: Sequence[FrictionModel],
    pi0: Array,
    scale: Array,
    payload: Array,
    names: Sequence[str],
    merged_rotor: dict[int, Array],
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
        Typical size of each standard parameter (:func:`~kinergy.identification.physical.parameter_scale`).
    payload : ndarray, shape (10 n,)
        The payload's share of ``pi0`` (the last link's), which the links' consistency excludes.
    names : sequence of str
        Joint names, for the active-constraint phrases.
    merged_rotor : dict
        Rotor inertias merged into link columns: motor -> its column in link base columns (b,)
        (:class:`~kinergy.identification.regression.Merging`).

    Returns
    -------
    ConstrainedFit or None
        ``None`` when neither solver finds the optimum or a link is still not physical.
    """
    red = problem.reduced
    n_link, p = cols.n_link, cols.prior.size
    p_mat = base_projection(base, pi0.size)
    lo, hi = bounds(cols, models)
    t = _link_scaling(pi0)
    extra = problem.x[n_link:]
    if np.all((extra >= lo) & (extra <= hi)):
        found = _realisation(problem, base, cols, (pi0, scale, payload), merged_rotor, t)
        if found is not None and all(e is None for e in link_consistency(found[0] - payload)):
            phrases, _ = _active(found[1], cols, lo, hi, found[0], payload, names)
            return ConstrainedFit(found[0], found[1], 0.0, tuple(phrases), (), found[2])
    metric = _metric(problem)
    z_hat = problem.x * red.scale
    v = cp.Variable(pi0.size)
    z_extra = cp.Variable(p - n_link)
    pi = pi0 + cp.multiply(scale, v)
    z = cp.hstack([cp.multiply(red.scale[:n_link], p_mat @ pi), z_extra])
    z_prior = cols.prior * red.scale
    dropped = problem.dropped[problem.dropped >= n_link] - n_link
    size = np.maximum(np.abs(z_prior[n_link:][dropped]), 1e-6 * float(np.linalg.norm(red.r_y)))
    # in units of the chi^2 of the model itself (feasible): the optimum lies in [0, 1]
    unit = max(float(np.sum((metric @ (z_prior - z_hat)) ** 2)), 1e-12)
    objective = cp.sum_squares(metric @ (z - z_hat)) / unit + _EPS_LINKS * cp.sum_squares(v)
    if dropped.size:
        gap = (z_extra[dropped] - z_prior[n_link:][dropped]) / size
        objective = objective + _EPS_DROPPED * cp.sum_squares(gap)
    constraints, _ = _lmi(pi, payload, t)
    s_extra = red.scale[n_link:]
    constraints += _within(z_extra, lo * s_extra, hi * s_extra)
    fixed = cols.fixed - n_link  # not unknowns: kept at the model's values
    if fixed.size:
        constraints.append(z_extra[fixed] == z_prior[n_link:][fixed])
    solver = _solve(cp.Problem(cp.Minimize(objective), constraints))
    if solver is None or v.value is None or z_extra.value is None:
        return None
    pi_hat = pi0 + scale * np.asarray(v.value)
    if any(e is not None for e in link_consistency(pi_hat - payload)):
        return None
    x = np.empty(p)
    x[:n_link] = p_mat @ pi_hat
    x[n_link:] = np.clip(np.asarray(z_extra.value) / s_extra, lo, hi)
    x[cols.fixed] = cols.prior[cols.fixed]  # exactly, not to the solver's tolerance
    chi2 = float(np.sum((metric @ (x * red.scale - z_hat)) ** 2))
    phrases, at_bound = _active(x, cols, lo, hi, pi_hat, payload, names)
    return ConstrainedFit(pi_hat, x, chi2, tuple(phrases), tuple(at_bound), solver)
