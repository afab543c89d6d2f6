"""The full method's least squares (:mod:`kinergy.identify.full`, its eq (1)) on the stacked columns.

- Column dependence (Gautier's numerical rank by pivoted QR, :func:`kinergy.linalg.pivoted_rank`):
  link base columns that the logs do not excite are an error; rotor and friction columns that
  depend on the link columns or on each other are dropped, keep the model's values, and are
  described as combinations of the kept columns (:class:`MergedColumn`).
- The ``power_flow`` friction's directions: the fit is repeated with the load torques of the
  fitted friction until the directions settle (:func:`fit_power_flow`).
- Solvers, each from one QR factorisation of the column-scaled ``[A | y]``
  (:func:`kinergy.linalg.reduce`): ordinary least squares, Gautier's weighted least squares
  (rows of joint ``j`` weighted by ``1 / sigma_j`` from an OLS pass's residuals) and ridge
  regression toward the model's values (:func:`solve`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.friction import get_model
from kinergy.identify.columns import (
    LOAD_DEPENDENT,
    Columns,
    Stacked,
    power_flow_load,
    set_friction,
)
from kinergy.linalg import Reduced, ReducedSolution, pivoted_rank, reduce, solve_reduced
from kinergy.messages import Messages
from kinergy.model.robot import Robot
from kinergy.predict import drive_state

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

#: the column-scaled stacked regressor, after merged columns are dropped, is singular beyond this
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


# ---------------------------------------------------------------------------------------------
# Ordinary least squares and the power-flow fixed point


@dataclass(frozen=True, eq=False)
class OlsFit:
    """Ordinary least squares on the stacked columns: the reduced problem, the dropped and kept
    columns (indices into all ``p``), the solution (scaled) and all unknowns ``x`` (p,), dropped
    ones at the model's values."""

    reduced: Reduced
    dropped: Index
    kept: Index
    solution: ReducedSolution
    x: Array


def fit_ols(stacked: Stacked, expressions: list[str], check_links: bool) -> OlsFit:
    """OLS with the friction block as it stands; ``check_links`` raises for unexcited link
    base parameters (:func:`check_link_rank`, their ``expressions`` name them)."""
    cols = stacked.cols
    n_link, n_cols = cols.n_link, cols.prior.size
    red = reduce(stacked.a_flat, stacked.y)
    if check_links:
        check_link_rank(red.r[:n_link, :n_link], expressions)
    dropped = n_link + dependent_extras(red.r[n_link:n_cols, n_link:n_cols])
    kept = np.setdiff1d(np.arange(n_cols), dropped)
    ols = solve_reduced(red.r_a[:, kept], _fixed_target(red, dropped, cols.prior), red.rows)
    if ols.cond > MAX_CONDITION:
        raise _singular(red.r_a[:, kept], ols.cond, [cols.names[k] for k in kept])
    x = cols.prior.copy()
    x[kept] = ols.x / red.scale[kept]
    return OlsFit(red, dropped, kept, ols, x)


@dataclass(frozen=True, eq=False)
class FlowFit:
    """The OLS fit with settled power-flow directions: the fit, the load torques used (N, n,
    motor side), passes made, whether the directions settled, and on how many samples the fitted
    model's own load torque disagrees with the direction used (0 without power-flow friction)."""

    ols: OlsFit
    load: Array
    iterations: int
    settled: bool
    mismatch: int


def _own_load(stacked: Stacked, x: Array) -> Array:
    """The load torques a model with unknowns ``x`` predicts itself (motor side, (N, n))."""
    n_fixed = stacked.n_fixed
    tau_sim = (stacked.a_flat[:, :n_fixed] @ x[:n_fixed]).reshape(stacked.y3.shape)
    return np.asarray(np.linalg.solve(stacked.n_mat.T, tau_sim.T).T)


def _initial_load(robot: Robot, stacked: Stacked) -> Array:
    """The load torques the friction columns start from (motor side, (N, n)): the model's own
    for load-dependent friction (``load_coulomb``, ``load_thermal_power_law``: the load is the
    link side's, which friction does not change), and for ``power_flow`` the measurement less the
    model's friction (directions from the model's own load where the measurement is ambiguous);
    zeros where no model takes a load."""
    if not stacked.needs_load:
        return np.zeros_like(stacked.q)
    predicted = np.asarray(drive_state(robot, stacked.q, stacked.qd, stacked.qdd).tau_load)
    if not stacked.needs_flow:
        return predicted
    cols = stacked.cols
    values = [cols.friction(cols.prior, m) for m in range(robot.n)]
    return power_flow_load(stacked, values, predicted)


def _next_load(stacked: Stacked, x: Array, load: Array) -> tuple[Array, bool]:
    """The loads for the next pass after a fit with unknowns ``x``, and whether they settled:
    ``power_flow`` directions from the measurement less the fitted friction
    (:func:`kinergy.identify.columns.power_flow_load`; settled when no direction changes), the
    other load-dependent models the fitted model's own load torque (settled when it moves by less
    than :data:`LOAD_RTOL` of its largest value)."""
    values = [stacked.cols.friction(x, m) for m in range(len(stacked.models))]
    new = power_flow_load(stacked, values, load) if stacked.needs_flow else load.copy()
    wm = stacked.wm
    settled = bool(np.array_equal(np.sign(wm * new), np.sign(wm * load)))
    own_models = [m for m, name in enumerate(stacked.models) if name not in LOAD_DEPENDENT]
    own_models = [m for m in own_models if get_model(stacked.models[m]).needs_load]
    if own_models:
        own = _own_load(stacked, x)[:, own_models]
        moved = float(np.max(np.abs(own - load[:, own_models])))
        settled &= moved <= LOAD_RTOL * max(float(np.max(np.abs(own))), 1e-300)
        new[:, own_models] = own
    return new, settled


def fit_power_flow(robot: Robot, stacked: Stacked, expressions: list[str]) -> FlowFit:
    """OLS with the friction's load torques settled (at most :data:`MAX_FLOW_ITERATIONS`
    passes, :func:`_next_load`): ``power_flow`` directions from the measurement less the fitted
    friction, load-proportional friction (``load_coulomb``, ``load_thermal_power_law``) from the
    fitted model's own load torque, a fixed point that converges because friction is a few
    per cent of the load. ``stacked``'s friction block is left at the load used."""
    load = _initial_load(robot, stacked)
    iterations, settled = 0, not stacked.needs_load
    while True:
        iterations += 1
        set_friction(stacked, load)
        fit = fit_ols(stacked, expressions, iterations == 1)
        if settled or iterations >= MAX_FLOW_ITERATIONS:
            break
        new, settled = _next_load(stacked, fit.x, load)
        if settled:
            break
        load = new
    mismatch = 0
    if stacked.needs_flow:  # how often the fitted model's own load torque disagrees
        flow = [m in LOAD_DEPENDENT for m in stacked.models]
        own, wm = _own_load(stacked, fit.x)[:, flow], stacked.wm[:, flow]
        mismatch = int(np.sum(np.sign(wm * own) != np.sign(wm * load[:, flow])))
    return FlowFit(fit, load, iterations if stacked.needs_load else 0, settled, mismatch)


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


def _wls(stacked: Stacked, ols: OlsFit) -> tuple[Reduced, ReducedSolution, Array]:
    """Gautier's weighted least squares: the rows of joint ``j`` weighted by ``1 / sigma_j``,
    ``sigma_j`` its residual standard deviation after the OLS pass. Returns the weighted reduced
    problem, its solution and the weights ``1 / sigma_j^2``."""
    n, samples = stacked.y3.shape[1], stacked.y3.shape[0]
    rows_joint = np.tile(np.arange(n), samples)
    resid = stacked.y - stacked.a_flat @ ols.x
    dof_share = max(1.0 - ols.kept.size / ols.reduced.rows, 1e-9)
    sigma = np.sqrt(np.bincount(rows_joint, resid**2, minlength=n) / (samples * dof_share))
    if np.any(sigma > 0.0):
        w_j = 1.0 / np.maximum(sigma, 1e-9 * float(sigma.max()))
    else:  # noise-free data: nothing to weigh
        w_j = np.ones(n)
    w = w_j[rows_joint]
    used = reduce(stacked.a_flat * w[:, None], stacked.y * w)
    r_y = _fixed_target(used, ols.dropped, stacked.cols.prior)
    return used, solve_reduced(used.r_a[:, ols.kept], r_y, used.rows), w_j**2


def solve(stacked: Stacked, ols: OlsFit, solver: str, ridge: float) -> Solved:
    """The regression by ``solver`` (``"ols"``, ``"wls"`` or ``"ridge"`` with weight ``ridge``),
    with the OLS fit's dropped columns at the model's values."""
    red, kept, dropped, prior = ols.reduced, ols.kept, ols.dropped, stacked.cols.prior
    used, lam, sol, weights = red, 0.0, ols.solution, None
    if solver == "wls":
        used, sol, weights = _wls(stacked, ols)
    elif solver == "ridge":
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
    unit = " kg m^2" if cols.group[k] == "rotor" else " (motor side)"
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
    reduced triangle, in the unknowns' own units)."""
    red, kept, dropped, n_link = ols.reduced, ols.kept, ols.dropped, cols.n_link
    if not dropped.size:
        return Merging((), Messages(), {})
    coef_s = np.linalg.lstsq(red.r_a[:, kept], red.r_a[:, dropped], rcond=None)[0]
    coef = coef_s * red.scale[dropped][None, :] / red.scale[kept][:, None]
    excited = np.linalg.norm(red.r_a[:, dropped], axis=0) > 0
    entries, said, rotor = [], Messages(), {}
    for i, k in enumerate(dropped):
        text, entry = _merge_note(int(k), cols, kept, coef[:, i] if excited[i] else None)
        said.note(text)
        entries.append(entry)
        if cols.group[k] == "rotor" and entry.into and all(e.index < n_link for e in entry.into):
            c_vec = np.zeros(n_link)
            for e in entry.into:
                c_vec[e.index] = e.coefficient
            rotor[int(k - n_link)] = c_vec
    return Merging(tuple(entries), said, rotor)
