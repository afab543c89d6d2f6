"""The full method's least squares (:mod:`kinergy.identification.full`, its eq (1)), from its triangles.

Eq (1)'s rows are folded chunk by chunk into one QR triangle per joint
(:meth:`kinergy.identification.columns.Regression.rows`, :meth:`kinergy.linalg.Reduced.stack`);
everything here works on those small triangles, whatever the number of samples:

- column dependence (Gautier's numerical rank by pivoted QR, :func:`kinergy.linalg.pivoted_rank`):
  link base columns that the logs do not excite are an error; rotor and friction columns that
  depend on the link columns or on each other are dropped, keep the model's values, and are
  described as combinations of the kept columns (:class:`MergedColumn`);
- the friction's load torques (``power_flow``'s directions, load-proportional friction): the fit
  is repeated, one pass over the chunks each, with the load torques of the fitted friction until
  they settle (:func:`fit_power_flow`);
- solvers: ordinary least squares on the joints' triangles together, Gautier's weighted least
  squares (joint ``j``'s triangle weighted by ``1 / sigma_j``, ``sigma_j`` from the OLS fit's
  residual on it) and ridge regression toward the model's values (:func:`solve`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.identification.chunks import LogChunks, Store
from kinergy.identification.columns import Columns, Regression
from kinergy.identification.drive_steps import joined
from kinergy.identification.options import Solver
from kinergy.linalg import Reduced, ReducedSolution, pivoted_rank, solve_reduced
from kinergy.messages import Messages

__all__ = [
    "DEPENDENT_TOL",
    "LOAD_RTOL",
    "MAX_CONDITION",
    "MAX_FLOW_ITERATIONS",
    "FlowFit",
    "MergedColumn",
    "MergedInto",
    "Merging",
    "OlsFit",
    "Solved",
    "check_link_rank",
    "dependent_extras",
    "fit_ols",
    "fit_power_flow",
    "merged_columns",
    "solve",
]

Index = NDArray[np.intp]

#: the column-scaled regressor, after merged columns are dropped, is singular beyond this
MAX_CONDITION = 1e10
#: a column whose part independent of the kept ones is below this fraction of its norm is dependent
DEPENDENT_TOL = 1e-8
#: passes of the power-flow fixed point
MAX_FLOW_ITERATIONS = 10
#: relative change of a load-proportional friction's load torque between passes that counts as
#: settled
LOAD_RTOL = 1e-10


# ---------------------------------------------------------------------------------------------
# Column dependence


def check_link_rank(r_link: Array, expressions: list[str]) -> None:
    """Raise when the link base columns (their triangle ``r_link``, (b, b)) are rank deficient."""
    rank = pivoted_rank(r_link, rtol=1e-10)
    if rank.dependent.size:
        deficient = rank.dependent
        listed = "; ".join(expressions[k] for k in deficient[:4])
        more = f" and {deficient.size - 4} more" if deficient.size > 4 else ""
        raise KinergyError(
            f"the logs do not excite {deficient.size} link base parameter(s) ({listed}{more}): "
            "use a richer excitation (more joints moving together, more harmonics)"
        )


def dependent_extras(r_extra: Array) -> Index:
    """Rotor and friction columns that depend on the link columns or on earlier extras.

    ``r_extra`` is the extras' block of the triangle below the link rows, i.e. the R factor of
    their unit-norm parts orthogonal to the link columns; pivoted QR of it finds the columns whose
    remaining part is below :data:`DEPENDENT_TOL` (Gautier's numerical rank, link columns kept
    first). Returns sorted indices into the extras.
    """
    if r_extra.shape[1] == 0:
        return np.zeros(0, dtype=np.intp)
    return pivoted_rank(r_extra, atol=DEPENDENT_TOL).dependent


def _singular(r_a: Array, cond: float, names: list[str]) -> KinergyError:
    """The error for an ill-conditioned regression, naming the parameters of its weakest
    direction (largest entries of the last right singular vector of the scaled columns)."""
    _, _, vt = np.linalg.svd(r_a)
    weak = np.argsort(-np.abs(vt[-1]))[:4]
    return KinergyError(
        f"the stacked regressor is singular (condition {cond:.3g} > {MAX_CONDITION:g}): the logs "
        "barely excite " + ", ".join(names[i] for i in weak)
    )


def _fixed_target(red: Reduced, dropped: Index, prior: Array) -> Array:
    """``r_y`` less the dropped columns at the model's values (scaled coordinates)."""
    return red.r_y - red.r_a[:, dropped] @ (prior * red.scale)[dropped]


def _together(joints: Sequence[Reduced], weights: Array | None = None) -> Reduced:
    """The joints' triangles (unit column scale) as one problem, each times its weight
    (default 1), with the columns scaled to unit norm (:meth:`Reduced.unit_columns`)."""
    w = np.ones(len(joints)) if weights is None else weights
    scaled = [Reduced(wj * t.r, t.scale, t.rows) for wj, t in zip(w, joints, strict=True)]
    return joined(scaled).unit_columns()


# ---------------------------------------------------------------------------------------------
# Ordinary least squares and the power-flow fixed point


@dataclass(frozen=True, eq=False)
class OlsFit:
    """Ordinary least squares on eq (1): the reduced problem, the joints' triangles it is made of
    (unit column scale), the dropped and kept columns (indices into all ``p``), the solution
    (scaled) and all unknowns ``x`` (p,), dropped ones at the model's values."""

    reduced: Reduced
    joints: list[Reduced]
    dropped: Index
    kept: Index
    solution: ReducedSolution
    x: Array


def fit_ols(
    joints: list[Reduced], cols: Columns, expressions: list[str], check_links: bool
) -> OlsFit:
    """OLS from the joints' triangles; ``check_links`` raises for unexcited link base
    parameters (:func:`check_link_rank`, their ``expressions`` name them)."""
    n_link, n_cols = cols.n_link, cols.prior.size
    red = _together(joints)
    if check_links:
        check_link_rank(red.r[:n_link, :n_link], expressions)
    dropped = np.union1d(n_link + dependent_extras(red.r[n_link:n_cols, n_link:n_cols]), cols.fixed)
    kept = np.setdiff1d(np.arange(n_cols), dropped)
    ols = solve_reduced(red.r_a[:, kept], _fixed_target(red, dropped, cols.prior), red.rows)
    if ols.cond > MAX_CONDITION:
        raise _singular(red.r_a[:, kept], ols.cond, [cols.names[k] for k in kept])
    x = cols.prior.copy()
    x[kept] = ols.x / red.scale[kept]
    return OlsFit(red, joints, dropped, kept, ols, x)


@dataclass(frozen=True, eq=False)
class FlowFit:
    """The OLS fit with settled load torques: the fit, the load torques it used (a record per
    piece of rows, :meth:`Regression.rows`; None without load-dependent friction), the passes
    made and whether the loads settled."""

    ols: OlsFit
    loads: Store | None
    iterations: int
    settled: bool


def _pass(
    reg: Regression, logs: LogChunks, previous: tuple[Store, Array] | None
) -> tuple[list[Reduced], Store | None, bool]:
    """One pass over the chunks: the joints' triangles of eq (1) with the loads of the model
    (``previous`` None) or those after a fit (``previous`` = (the loads it used, its unknowns
    ``x``), :meth:`Regression.rows`); the loads used, kept; and whether they settled against
    ``previous``'s: no power-flow direction changed and the other load-dependent models' loads
    moved by at most :data:`LOAD_RTOL` of their largest value."""
    n, p = reg.robot.n, reg.cols.prior.size
    joints = [Reduced.empty(p) for _ in range(n)]
    store = logs.derived() if reg.needs_load else None
    loads, x = (iter(previous[0]), previous[1]) if previous is not None else (None, None)
    same_signs, moved, largest = True, 0.0, 0.0
    own = reg.own_load
    for _, rows in reg.rows(logs, loads, x):
        for j in range(n):
            joints[j] = joints[j].stack(rows.a[:, j, :], rows.y3[:, j])
        if store is not None:
            store.put([rows.load])
        if previous is not None:
            same_signs &= bool(
                np.array_equal(np.sign(rows.wm * rows.load), np.sign(rows.wm * rows.previous))
            )
            if own and len(rows.load):
                moved = max(moved, float(np.max(np.abs(rows.load - rows.previous)[:, own])))
                largest = max(largest, float(np.max(np.abs(rows.load[:, own]))))
    settled = same_signs and moved <= LOAD_RTOL * max(largest, 1e-300)
    return joints, store, settled


def fit_power_flow(reg: Regression, logs: LogChunks, expressions: list[str]) -> FlowFit:
    """OLS with the friction's load torques settled (at most :data:`MAX_FLOW_ITERATIONS`
    passes): ``power_flow`` directions from the measurement less the fitted friction,
    load-proportional friction (``load_coulomb``, ``load_thermal_power_law``) from the fitted
    model's own load torque, a fixed point that converges because friction is a few per cent
    of the load. Each pass makes the next loads from the last fit and folds the rows with them;
    a pass whose loads settled is not solved (the fit before it stands)."""
    joints, loads, _ = _pass(reg, logs, None)
    fit = fit_ols(joints, reg.cols, expressions, True)
    iterations, settled = 1, not reg.needs_load
    while not settled and iterations < MAX_FLOW_ITERATIONS:
        assert loads is not None
        joints, new, settled = _pass(reg, logs, (loads, fit.x))
        assert new is not None
        if settled:
            new.close()
            break
        loads.close()
        loads = new
        fit = fit_ols(joints, reg.cols, expressions, False)
        iterations += 1
    return FlowFit(fit, loads, iterations if reg.needs_load else 0, settled)


# ---------------------------------------------------------------------------------------------
# The chosen solver


@dataclass(frozen=True, eq=False)
class Solved:
    """The solved regression.

    Attributes
    ----------
    reduced : Reduced
        Its reduced triangle (of the weighted problem for WLS).
    kept, dropped : ndarray of int
        Columns solved for, and dropped (kept at the model's values).
    lam : float
        Ridge weight (0 for OLS and WLS).
    solution : ReducedSolution
        In scaled coordinates.
    x, std : ndarray, shape (p,)
        All unknowns and their standard errors (NaN for dropped columns).
    weights : ndarray, shape (n,), optional
        WLS per-joint weights ``1 / sigma_j^2``.
    """

    reduced: Reduced
    kept: Index
    dropped: Index
    lam: float
    solution: ReducedSolution
    x: Array
    std: Array
    weights: Array | None = None

    @property
    def sigma2(self) -> float:
        """Residual variance, ``sse / (rows - kept)``."""
        return self.solution.sse / max(self.reduced.rows - self.kept.size, 1)


def _wls(ols: OlsFit, prior: Array) -> tuple[Reduced, ReducedSolution, Array]:
    """Gautier's weighted least squares: the rows of joint ``j`` weighted by ``1 / sigma_j``,
    ``sigma_j`` its residual standard deviation after the OLS pass (from its triangle). Returns
    the weighted reduced problem, its solution and the weights ``1 / sigma_j^2``."""
    n = len(ols.joints)
    samples = ols.reduced.rows // n
    resid2 = np.array([t.norm2(np.append(-ols.x, 1.0)) for t in ols.joints])
    dof_share = max(1.0 - ols.kept.size / ols.reduced.rows, 1e-9)
    sigma = np.sqrt(resid2 / (samples * dof_share))
    if np.any(sigma > 0.0):
        w_j = 1.0 / np.maximum(sigma, 1e-9 * float(sigma.max()))
    else:  # noise-free data: nothing to weigh
        w_j = np.ones(n)
    used = _together(ols.joints, w_j)
    r_y = _fixed_target(used, ols.dropped, prior)
    return used, solve_reduced(used.r_a[:, ols.kept], r_y, used.rows), w_j**2


def solve(ols: OlsFit, prior: Array, solver: Solver, ridge: float) -> Solved:
    """The regression by ``solver`` (ridge with weight ``ridge``), with the OLS fit's dropped
    columns at the model's values ``prior``."""
    red, kept, dropped = ols.reduced, ols.kept, ols.dropped
    used, lam, sol, weights = red, 0.0, ols.solution, None
    if solver == Solver.WLS:
        used, sol, weights = _wls(ols, prior)
    elif solver == Solver.RIDGE:
        lam = float(ridge)
        z_prior = prior * red.scale
        sol = solve_reduced(
            red.r_a[:, kept], _fixed_target(red, dropped, prior), red.rows, z_prior[kept], lam
        )
    x = prior.copy()
    x[kept] = sol.x / used.scale[kept]
    std = np.full(prior.size, np.nan)
    std[kept] = sol.std / used.scale[kept]
    return Solved(used, kept, dropped, lam, sol, x, std, weights)


# ---------------------------------------------------------------------------------------------
# Merged columns


@dataclass(frozen=True)
class MergedInto:
    """One kept column a dropped one merges into: ``coefficient`` times it (index into all)."""

    parameter: str
    index: int
    coefficient: float


@dataclass(frozen=True)
class MergedColumn:
    """A dropped column: its parameter, the model's value it keeps, and its column as a
    combination of the kept ones (empty when the column is zero)."""

    parameter: str
    value: float
    into: tuple[MergedInto, ...]


@dataclass(frozen=True, eq=False)
class Merging:
    """Every dropped column (:class:`MergedColumn`), a note for each, and for each merged rotor
    inertia whose column is a combination of link base columns only, that combination (motor ->
    coefficients, (b,))."""

    columns: tuple[MergedColumn, ...]
    said: Messages
    rotor: dict[int, Array]


def _merge_note(k: int, cols: Columns, kept: Index, coef: Array | None) -> tuple[str, MergedColumn]:
    """Warning text and entry for the dropped column ``k`` (``coef``: its column as a combination
    of the kept columns, ``None`` when it is zero)."""
    name, value = cols.names[k], float(cols.prior[k])
    unit = " kg m²" if cols.group[k] == "rotor" else " (motor side)"
    if coef is None:
        text = f"{name} is not excited by the logs (its column is zero): kept the model's {value:.4g}{unit}"
        return text, MergedColumn(name, value, ())
    order = np.argsort(-np.abs(coef))
    into = tuple(
        MergedInto(cols.names[kept[i]], int(kept[i]), float(coef[i]))
        for i in order
        if abs(coef[i]) > 1e-9 * np.abs(coef).max()
    )
    shown = " ".join(f"{e.coefficient:+.4g}*[{e.parameter}]" for e in into[:3])
    more = f" and {len(into) - 3} more" if len(into) > 3 else ""
    text = (
        f"{name} cannot be told apart from the other parameters (its column = {shown}{more}): "
        f"merged into them, kept the model's {value:.4g}{unit}"
    )
    return text, MergedColumn(name, value, into)


def merged_columns(ols: OlsFit, cols: Columns) -> Merging:
    """Each dropped column of the OLS fit as a combination of the kept ones (least squares on the
    reduced triangle, in the unknowns' own units); the columns the target does not see
    (:attr:`Columns.fixed`) are not merged, only kept."""
    red, kept, n_link = ols.reduced, ols.kept, cols.n_link
    dropped = np.setdiff1d(ols.dropped, cols.fixed)
    if not dropped.size:
        return Merging((), Messages(), {})
    coef_s = np.linalg.lstsq(red.r_a[:, kept], red.r_a[:, dropped], rcond=None)[0]
    coef = coef_s * red.scale[dropped][None, :] / red.scale[kept][:, None]
    excited = np.linalg.norm(red.r_a[:, dropped], axis=0) > 0
    entries, said, rotor = [], Messages(), {}
    for i, k in enumerate(dropped):
        text, entry = _merge_note(int(k), cols, kept, coef[:, i] if excited[i] else None)
        entries.append(entry)
        if cols.group[k] == "rotor" and entry.into and all(e.index < n_link for e in entry.into):
            c_vec = np.zeros(n_link)
            for e in entry.into:
                c_vec[e.index] = e.coefficient
            rotor[int(k - n_link)] = c_vec
            # the physically constrained fit may move it: "kept" would not be true then
            text = text.replace("kept the model's", "the regression keeps the model's") + (
                " (a physically constrained fit may move it: the model file holds what is written)"
            )
        said.note(text)
    return Merging(tuple(entries), said, rotor)
