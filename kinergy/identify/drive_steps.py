"""The drive steps of the sequential identification (UR5e doc sections 3-4), one joint at a time.

- :func:`rotor_inertias`: ``J_m + J_r`` per motor from the controller's reference torque
  (UR5e eqs 7-9), by least squares through the transmission matrix;
- :func:`current_step`: torque constant and friction of every motor together from the measured
  current (UR5e eqs 17-18): the current is linear in ``1/k_t`` (times the load torque) and in the
  friction parameters over ``k_t``; with ``hold="auto"`` the standstill hold that fits best, with
  ``friction="auto"`` the registry model that predicts held-out blocks best (:func:`candidates`).

:mod:`kinergy.identify.sequential` runs them in order and assembles the typed result.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.drives.transmission import transmission_matrix
from kinergy.dynamics.rnea import rnea
from kinergy.errors import KinergyError
from kinergy.friction.registry import (
    friction_columns,
    get_model,
    start_parameters,
    with_linear_parameters,
)
from kinergy.identify.columns import rotor_columns
from kinergy.identify.friction_curve import search_shape
from kinergy.identify.result import (
    IDENTIFIED,
    KEPT,
)
from kinergy.jsonable import OPTIONAL
from kinergy.linalg import Reduced, scaled_lstsq, scaled_solution
from kinergy.logs.prepare import IdentData
from kinergy.messages import Messages
from kinergy.model.robot import Friction, Joint, Robot

__all__ = [
    "AUTO_CANDIDATES",
    "CurrentProblem",
    "CurrentStats",
    "FrictionChoice",
    "JointFitter",
    "best_hold",
    "candidates",
    "current_fitter",
    "current_problem",
    "current_step",
    "fit_joints",
    "holdings_of",
    "motor_signals",
    "rotor_inertias",
    "rotor_problem",
    "rotor_solution",
    "rotor_step",
    "solve_current",
    "stack",
    "start_params",
    "with_rotor_inertias",
]


#: joint speed below which a joint counts as still, rad/s
STILL_SPEED = 0.005
#: a regression whose column-scaled condition number exceeds this cannot be trusted
MAX_CONDITION = 1e8
#: fractions of the friction a stopped joint is tried with (0: none, the seed's model)
HOLDINGS = (0.0, 0.25, 0.5, 0.75, 1.0)
#: a holding fraction is kept only if it cuts the squared current error by this share
MIN_GAIN = 0.005
#: relative standard deviation of 1/k_t above which the torque constant counts as unidentified
MAX_KT_SPREAD = 0.1
#: the models ``friction="auto"`` tries (those the logs support, :func:`candidates`)
AUTO_CANDIDATES = (
    "viscous_coulomb",
    "power_flow",
    "power_law",
    "directional_power_law",
    "stribeck",
    "load_coulomb",
    "thermal_viscous",
    "load_thermal_power_law",
)
#: temperature-dependent models are tried on a joint whose temperature spans this much, K
MIN_TEMPERATURE_SPAN = 3.0
#: contiguous blocks of the cross-validation that chooses a friction model
FOLDS = 5


def stack(datas: Sequence[IdentData], name: str) -> Array:
    """Field ``name`` of every log, stacked: ``(sum N_k, n)``."""
    return np.vstack([getattr(d, name) for d in datas])


def rotor_problem(robot: Robot, datas: Sequence[IdentData], into: Reduced | None = None) -> Reduced:
    """Step 2's least squares (UR5e eqs 7-9) folded into a triangle (:class:`Reduced`), every
    motor's column: ``tau_ref - f_link = N^T diag(J) N qdd`` with ``N`` the transmission matrix,
    linear in J; rows (sample, joint) of ``datas`` stacked onto ``into`` (default none yet)."""
    n_mat = transmission_matrix(robot)
    problem = Reduced.empty(robot.n) if into is None else into
    for data in datas:
        assert data.tau_ref is not None
        f_link = rnea(robot, data.q_cmd, data.qd_cmd, data.qdd_cmd)
        # rows (sample, joint), column m: contribution of J_m, n_mat[m, j] * (N qdd)_m
        a = rotor_columns(n_mat, data.qdd_cmd @ n_mat.T).reshape(-1, robot.n)
        problem = problem.stack(a, (data.tau_ref - f_link).reshape(-1))
    return problem


def rotor_solution(
    robot: Robot, problem: Reduced, active: Sequence[int] | None = None
) -> tuple[Array, Array, float]:
    """Step 2 from its triangle (:func:`rotor_problem`): ``J_m + J_r`` per motor.

    Returns
    -------
    inertia, std : ndarray, shape (n,)
        kg m^2 (motor side) and its standard deviation; motors not in ``active`` (default all)
        keep the model's value (moved into the target) and a NaN deviation.
    condition : float
    """
    active = list(range(robot.n)) if active is None else list(active)
    known = np.array([j.drive.rotor_inertia for j in robot.joints])
    pick = np.zeros((robot.n + 1, len(active) + 1))
    pick[active, np.arange(len(active))] = 1.0
    pick[:, -1] = np.append([0.0 if m in active else -known[m] for m in range(robot.n)], 1.0)
    sol, sol_std, cond = scaled_solution(problem.combine(pick))
    inertia, std = known.copy(), np.full(robot.n, np.nan)
    inertia[active], std[active] = sol, sol_std
    return inertia, std, cond


def rotor_inertias(
    robot: Robot, datas: Sequence[IdentData], active: Sequence[int] | None = None
) -> tuple[Array, Array, float]:
    """Step 2: ``J_m + J_r`` per motor from ``target_moment`` (UR5e eqs 7-9): :func:`rotor_solution`
    of :func:`rotor_problem` (kg m^2 motor side, standard deviations, condition number)."""
    return rotor_solution(robot, rotor_problem(robot, datas), active)


@dataclass(frozen=True, eq=False)
class _Signals:
    """One motor's signals for eq 18, motor side, each (N,): load torque ``tau_load`` (N m),
    speed ``wm`` (rad/s), acceleration ``dwm`` (rad/s^2), measured ``current`` (A), the joint
    ``temperature`` (deg C, None when not logged) and the stretch of time each row belongs to
    (``piece``, int: one per log; a friction held through standstill never crosses into the
    next piece)."""

    tau_load: Array
    wm: Array
    dwm: Array
    current: Array
    temperature: Array | None = None
    piece: NDArray[np.int64] | None = None

    def rows(self, keep: NDArray[np.bool_]) -> _Signals:
        """The rows ``keep``; where rows are left out between two kept ones, a new piece."""
        t = None if self.temperature is None else self.temperature[keep]
        piece = None
        if self.piece is not None:
            index = np.flatnonzero(keep)
            cut = (np.diff(index) > 1) | (np.diff(self.piece[keep]) != 0)
            piece = np.concatenate([[0], np.cumsum(cut)])
        return _Signals(
            self.tau_load[keep], self.wm[keep], self.dwm[keep], self.current[keep], t, piece
        )


@dataclass(frozen=True, eq=False)
class _CurrentFit:
    """Eq 18 for one motor: ``x = [1/k_t, values/k_t]`` with standard errors, the condition
    number, the squared current error, and whether ``k_t`` was held at the model's."""

    model: str
    params: dict[str, float]
    x: Array
    std: Array
    cond: float
    sse: float
    fixed: bool


def _columns(model: str, params: dict[str, float], signals: _Signals) -> Array:
    """Eq 18's regressor ``[tau_load, friction columns]`` (N, 1 + k)."""
    s = signals
    bounds = [0, s.wm.size]
    if s.piece is not None:
        bounds[1:1] = list(np.flatnonzero(np.diff(s.piece)) + 1)
    parts = []
    for lo, hi in itertools.pairwise(bounds):
        t = None if s.temperature is None else s.temperature[lo:hi]
        w, load, dw = s.wm[lo:hi], s.tau_load[lo:hi], s.dwm[lo:hi]
        parts.append(friction_columns(model, params, w, load, dw, temperature=t))
    return np.column_stack([s.tau_load, np.vstack(parts)])


def current_problem(model: str, params: dict[str, float], signals: _Signals) -> Reduced:
    """Eq 18's least squares for one motor, ``[tau_load, friction columns | current]``, folded
    into its triangle (:class:`Reduced`; stack more chunks onto it in time order)."""
    a = _columns(model, params, signals)
    return Reduced.empty(a.shape[1]).stack(a, signals.current)


#: eq 18's least squares: the regressor ``[tau_load, friction columns]`` (N, 1 + k) and the
#: current (N,), or both folded into a triangle (:func:`current_problem`, chunk by chunk)
CurrentProblem = Reduced | tuple[Array, Array]


def _eq18(problem: CurrentProblem, kt_prior: float | None = None) -> tuple[Array, Array, float]:
    """:func:`~kinergy.linalg.scaled_lstsq` of eq 18 (x, standard errors, condition); with
    ``kt_prior``, of the friction columns alone against ``current - tau_load / kt_prior``."""
    if isinstance(problem, Reduced):
        if kt_prior is None:
            return scaled_solution(problem)
        p = problem.r.shape[1] - 1
        rest_of = np.zeros((p + 1, p))
        rest_of[1:p, : p - 1] = np.eye(p - 1)
        rest_of[0, -1], rest_of[p, -1] = -1.0 / kt_prior, 1.0
        return scaled_solution(problem.combine(rest_of))
    a, current = problem
    if kt_prior is None:
        return scaled_lstsq(a, current)
    return scaled_lstsq(a[:, 1:], current - a[:, 0] / kt_prior)


def solve_current(
    model: str, params: dict[str, float], problem: CurrentProblem, kt_prior: float
) -> _CurrentFit:
    """Eq 18 for one motor (:func:`_current_fit`), the model's shape parameters held, from its
    rows or its triangle (:data:`CurrentProblem`: the same fit to round-off)."""
    x, std, cond = _eq18(problem)
    fixed = not (x[0] > 0 and std[0] < MAX_KT_SPREAD * x[0])
    if fixed:
        rest, rest_std, cond = _eq18(problem, kt_prior)
        x = np.concatenate([[1.0 / kt_prior], rest])
        std = np.concatenate([[0.0], rest_std])
    if isinstance(problem, Reduced):
        sse = problem.norm2(np.append(-x, 1.0))
    else:
        sse = float(np.sum((problem[1] - problem[0] @ x) ** 2))
    return _CurrentFit(model, params, x, std, cond, sse, fixed)


def _solve_current(
    model: str, params: dict[str, float], signals: _Signals, kt_prior: float
) -> _CurrentFit:
    """Eq 18 for one motor with the model's shape parameters held (:func:`_current_fit`)."""
    problem = (_columns(model, params, signals), signals.current)
    return solve_current(model, params, problem, kt_prior)


def _current_fit(
    model: str, params: dict[str, float], signals: _Signals, kt_prior: float
) -> _CurrentFit:
    """Eq 18 for one motor: ``I = [tau_load, friction columns] @ [1/k_t, values/k_t]``.

    When the load torque is too small against the friction and noise to pin ``1/k_t`` down
    (relative standard deviation above :data:`MAX_KT_SPREAD`, or a non-positive estimate),
    ``k_t`` is fixed at ``kt_prior`` and only the friction is fitted. Shape parameters the model
    searches (``power_law``'s exponent) are found by a 1-D search on the squared current error
    (:func:`kinergy.identify.friction_curve.search_shape`).
    """
    if not get_model(model).search:
        return _solve_current(model, params, signals, kt_prior)
    shaped = search_shape(model, params, lambda p: _solve_current(model, p, signals, kt_prior).sse)
    return _solve_current(model, shaped, signals, kt_prior)


# ---------------------------------------------------------------------------------------------
# Step 2: rotor inertias (UR5e eqs 7-9, Table IV)


def rotor_step(
    robot: Robot, problem: Reduced | None, active: list[int], said: Messages
) -> tuple[Array, Array, float | None]:
    """Rotor inertias (kg m^2, motor side) from step 2's triangle (:func:`rotor_problem`; None
    when no log has ``target_moment``), their standard errors (NaN where not identified) and
    the regression's condition number (None without ``target_moment``). A rotor inertia that
    comes out negative is not written: the model's is kept (NaN standard error) with a warning."""
    rotor = np.array([j.drive.rotor_inertia for j in robot.joints])
    rotor_std = np.full(robot.n, np.nan)
    cond = None
    if problem is not None:
        rotor, rotor_std, cond = rotor_solution(robot, problem, active)
        if cond > MAX_CONDITION:
            raise KinergyError(
                f"rotor inertia regression is singular (condition {cond:.3g}): too little acceleration"
            )
    else:
        said.note("the logs have no target_moment: rotor inertias kept from the model")
    for j, joint in enumerate(robot.joints):
        if rotor[j] < 0:
            said.warn(
                f"joint {j + 1} ({joint.name}): identified rotor inertia {rotor[j]:.3g} kg m^2 "
                "is negative, not a physical value (target_moment does not fit this model): "
                f"kept the model's {joint.drive.rotor_inertia:.4g} kg m^2"
            )
            rotor[j], rotor_std[j] = joint.drive.rotor_inertia, np.nan
    return rotor, rotor_std, cond


def with_rotor_inertias(robot: Robot, rotor: Array, said: Messages) -> Robot:
    """Motor inertia = rotor inertia - the model's reducer inertia (Table IV), at least 0."""
    joints = []
    for j, joint in enumerate(robot.joints):
        drive = joint.drive
        motor = max(float(rotor[j]) - drive.reducer_inertia, 0.0)
        joints.append(
            dataclasses.replace(joint, drive=dataclasses.replace(drive, motor_inertia=motor))
        )
    for j, joint in enumerate(robot.joints):
        if rotor[j] < joint.drive.reducer_inertia:
            said.note(
                f"joint {j + 1} ({joint.name}): rotor inertia {rotor[j]:.3g} is below the model's "
                f"reducer inertia {joint.drive.reducer_inertia:.3g}; motor inertia set to 0"
            )
    return robot.with_joints(joints)


# ---------------------------------------------------------------------------------------------
# Step 3: torque constants and friction (UR5e eqs 17-18)


def motor_signals(robot: Robot, rotor: Array, logs: Sequence[IdentData]) -> list[_Signals]:
    """Per motor: the load torque of ``robot`` with rotor inertias ``rotor``, the motor speed and
    acceleration, the measured current and the joint temperature (when every log has it), on
    the real motion of ``logs`` (:class:`_Signals`)."""
    q, qd, qdd = stack(logs, "q"), stack(logs, "qd"), stack(logs, "qdd")
    n_mat = transmission_matrix(robot)
    tau_sim = rnea(robot, q, qd, qdd) + qdd @ (n_mat.T @ (rotor[:, None] * n_mat)).T
    tau_load = np.asarray(np.linalg.solve(n_mat.T, tau_sim.T).T, dtype=float)
    wm, dwm, current = qd @ n_mat.T, qdd @ n_mat.T, stack(logs, "current")
    temps = None
    if all(d.temperature is not None for d in logs):
        temps = stack(logs, "temperature")
    piece = np.repeat(np.arange(len(logs)), [d.qd.shape[0] for d in logs])
    return [
        _Signals(
            tau_load[:, m],
            wm[:, m],
            dwm[:, m],
            current[:, m],
            None if temps is None else temps[:, m],
            piece,
        )
        for m in range(robot.n)
    ]


def start_params(joint: Joint, model: str, standstill: float, holding: float) -> dict[str, float]:
    """Parameters to fit ``model`` from, holding ``holding`` of the friction through standstill."""
    params = start_parameters(model, joint.drive.friction.model, joint.drive.friction.params)
    params.pop("standstill", None)
    params.pop("holding", None)
    if holding > 0.0:
        params["standstill"] = standstill
        params["holding"] = holding
    return params


def _best_hold(
    joint: Joint,
    model: str,
    standstill: float,
    signals: _Signals,
    holdings: Sequence[float],
) -> _CurrentFit:
    """Eq 18 with each fraction of ``holdings`` of the friction held through standstill (below
    ``standstill`` rad/s, motor side): :func:`best_hold`."""

    def fit(holding: float) -> _CurrentFit:
        params = start_params(joint, model, standstill, holding)
        return _current_fit(model, params, signals, joint.drive.torque_constant)

    return best_hold(holdings, fit)


def best_hold(holdings: Sequence[float], fit: Callable[[float], _CurrentFit]) -> _CurrentFit:
    """Of the fits of eq 18 holding each fraction of ``holdings`` of the friction through
    standstill (``fit(holding)``), the first whose squared current error no later one cuts by
    :data:`MIN_GAIN`."""
    best: _CurrentFit | None = None
    for holding in holdings:
        this = fit(holding)
        if best is None or this.sse < best.sse * (1.0 - MIN_GAIN):
            best = this
    assert best is not None
    return best


@dataclass(frozen=True)
class FrictionChoice:
    """How ``friction="auto"`` chose a joint's model: each candidate's cross-validated current
    RMS (A, :data:`FOLDS` contiguous blocks), the winner, how much lower its RMS is than
    Coulomb + viscous's and than the runner-up's (%), and the standard error of the first (%,
    from the spread of the per-block differences). A model other than Coulomb + viscous wins
    only if it beats it by more than that standard error (the one-standard-error rule)."""

    model: str
    cv_rms: dict[str, float]
    gain_over_viscous_coulomb: float | None
    margin: float | None
    gain_std: float | None = field(default=None, metadata=OPTIONAL)


def candidates(signals: _Signals) -> list[str]:
    """The models of :data:`AUTO_CANDIDATES` this joint's logs can support: temperature-dependent
    ones only where its temperature spans :data:`MIN_TEMPERATURE_SPAN`."""
    t = signals.temperature
    warm = t is not None and float(np.ptp(t)) >= MIN_TEMPERATURE_SPAN
    return [m for m in AUTO_CANDIDATES if warm or not get_model(m).needs_temperature]


def _cv_errors(fit: _CurrentFit, signals: _Signals, kt_prior: float) -> Array:
    """Squared current error (A^2) summed over each of :data:`FOLDS` contiguous blocks of the
    samples, ``fit``'s model (its shape and hold held) fitted on the others, shape (FOLDS,)."""
    index = np.arange(signals.current.size)
    edges = np.linspace(0, index.size, FOLDS + 1).astype(int)
    fold = np.searchsorted(edges, index, side="right") - 1
    if signals.piece is not None and np.unique(signals.piece).size >= 3:
        fold = signals.piece
    a = _columns(fit.model, fit.params, signals)
    squared = []
    for k in np.unique(fold):
        held = fold == k
        train = _solve_current(fit.model, fit.params, signals.rows(~held), kt_prior)
        squared.append(float(np.sum((signals.current[held] - a[held] @ train.x) ** 2)))
    return np.array(squared)


def _gain(errors: dict[str, Array], model: str, other: str) -> tuple[float, float]:
    """How much lower ``model``'s cross-validated RMS is than ``other``'s (%), and the standard
    error of that gain from the per-block differences of the squared error (%)."""
    a, b = errors[model], errors[other]
    gain = 100.0 * (1.0 - np.sqrt(a.sum() / b.sum()))
    # gain ~ -(sum a - sum b) / (2 sum b); the blocks' differences give that sum's spread
    std = 50.0 * np.sqrt(a.size) * float(np.std(a - b, ddof=1)) / float(b.sum())
    return float(gain), std


def _auto_fit(
    joint: Joint, standstill: float, signals: _Signals, holdings: Sequence[float]
) -> tuple[_CurrentFit, FrictionChoice]:
    """``friction="auto"``: every candidate model fitted with its own standstill hold and scored
    by cross-validation; the lowest held-out RMS wins unless it beats Coulomb + viscous by no
    more than the standard error of that gain. Candidates whose regression is singular on these
    logs are left out."""
    kt = joint.drive.torque_constant
    fits, errors = {}, {}
    for model in candidates(signals):
        fit = _best_hold(joint, model, standstill, signals, holdings)
        if fit.cond <= MAX_CONDITION:
            fits[model], errors[model] = fit, _cv_errors(fit, signals, kt)
    scores = {m: float(np.sqrt(e.sum() / signals.current.size)) for m, e in errors.items()}
    ranked = sorted(scores, key=scores.__getitem__)
    best, gain, std = ranked[0], None, None
    if "viscous_coulomb" in scores:
        gain, std = _gain(errors, best, "viscous_coulomb")
        if gain <= std:
            best = "viscous_coulomb"
            gain, std = 0.0, None
    others = [m for m in ranked if m != best]
    choice = FrictionChoice(
        model=best,
        cv_rms=scores,
        gain_over_viscous_coulomb=gain,
        margin=100.0 * (1.0 - scores[best] / scores[others[0]]) if others else None,
        gain_std=std,
    )
    return fits[best], choice


@dataclass(frozen=True)
class CurrentStats:
    """A joint's standard errors and condition number from eq 18 (:class:`SequentialJoint`),
    and the flags of its torque constant and friction parameters (empty: not fitted)."""

    torque_constant_std: float | None = None
    friction_std: dict[str, float] | None = None
    condition_current: float | None = None
    flags: dict[str, str] = field(default_factory=dict)


def _unsupported(model: str, values: Array, kt: float) -> str | None:
    """Why a current fit's torque constant ``kt`` and friction levels ``values`` are not a
    physical drive (a friction level outside its model's bounds), or None."""
    if not kt > 0:
        return f"torque constant {kt:.3g} N m/A is not positive"
    spec = get_model(model)
    for name, value in zip(spec.linear, values, strict=True):
        low, high = spec.bounds.get(name, (-np.inf, np.inf))
        if not low <= value <= high:
            return f"friction {name} = {value:.3g} is outside [{low:.3g}, {high:.3g}]"
    return None


def _apply_current_fit(
    m: int, joint: Joint, fit: _CurrentFit, said: Messages
) -> tuple[Joint, CurrentStats]:
    """``joint`` with the torque constant and friction of ``fit``, and their standard errors;
    a fit that is not a physical drive is not written (the model's values, flagged)."""
    if fit.cond > MAX_CONDITION:
        raise KinergyError(
            f"joint {m + 1} ({joint.name}): the current regression is singular (condition "
            f"{fit.cond:.3g}): the log does not excite every friction term of model {fit.model!r}"
        )
    x, std, names = fit.x, fit.std, get_model(fit.model).linear
    kt = 1.0 / x[0]
    values = x[1:] * kt
    problem = _unsupported(fit.model, values, kt)
    if problem is not None:
        said.warn(
            f"joint {m + 1} ({joint.name}): {problem}, not a physical drive (the currents do "
            f"not support friction model {fit.model!r} here): kept the model's torque constant "
            "and friction"
        )
        kept = {name: KEPT for name in ("torque_constant", *names)}
        return joint, CurrentStats(condition_current=fit.cond, flags=kept)
    if fit.fixed:
        said.note(
            f"joint {m + 1} ({joint.name}): the logs do not pin the torque constant down "
            "(too little load torque against friction and noise); kept the model's "
            f"{joint.drive.torque_constant:.4g} N m/A"
        )
    kt_std = std[0] / x[0] ** 2
    value_std = np.sqrt((std[1:] * kt) ** 2 + (x[1:] * kt_std * kt) ** 2)
    friction = Friction(fit.model, with_linear_parameters(fit.model, fit.params, values))
    drive = dataclasses.replace(joint.drive, torque_constant=float(kt), friction=friction)
    flags = {"torque_constant": KEPT if fit.fixed else IDENTIFIED}
    flags.update({name: IDENTIFIED for name in names})
    stats = CurrentStats(
        torque_constant_std=float(kt_std),
        friction_std={name: float(s) for name, s in zip(names, value_std, strict=True)},
        condition_current=fit.cond,
        flags=flags,
    )
    return dataclasses.replace(joint, drive=drive), stats


def current_step(
    staged: Robot,
    rotor: Array,
    logs: Sequence[IdentData],
    problems: dict[int, str],
    options: tuple[str | None, str | bool],
    said: Messages,
) -> tuple[Robot, list[CurrentStats], tuple[float | None, ...], tuple[FrictionChoice | None, ...]]:
    """Torque constants and friction of every identifiable motor from the currents (eqs 17-18);
    ``options`` = (friction model, ``"auto"`` or None; hold). Returns the robot, each joint's
    statistics, the friction fraction held through standstill and, with ``"auto"``, how each
    joint's model was chosen (None where not fitted)."""
    fitter = current_fitter(staged, rotor, logs, options)
    return fit_joints(staged, problems, fitter, said)


def current_fitter(
    staged: Robot,
    rotor: Array,
    logs: Sequence[IdentData],
    options: tuple[str | None, str | bool],
) -> JointFitter:
    """Step 3's fit of one joint on ``logs`` held whole (:data:`JointFitter`); ``options`` as
    :func:`current_step`."""
    friction, hold = options
    signals = motor_signals(staged, rotor, logs)
    holdings = holdings_of(hold)

    def fit_joint(
        m: int, joint: Joint, standstill: float
    ) -> tuple[_CurrentFit, FrictionChoice | None]:
        if friction == "auto":
            return _auto_fit(joint, standstill, signals[m], holdings)
        model = friction or joint.drive.friction.model
        return _best_hold(joint, model, standstill, signals[m], holdings), None

    return fit_joint


def holdings_of(hold: str | bool) -> tuple[float, ...]:
    """The friction fractions held through standstill that ``hold`` tries (:data:`HOLDINGS`)."""
    return HOLDINGS if hold == "auto" else ((1.0,) if hold else (0.0,))


#: one joint's eq 18 fit: (motor index, joint, standstill speed in rad/s motor side) -> the fit
#: and, with ``friction="auto"``, how its model was chosen
JointFitter = Callable[[int, Joint, float], tuple[_CurrentFit, "FrictionChoice | None"]]


def fit_joints(
    staged: Robot, problems: dict[int, str], fit_joint: JointFitter, said: Messages
) -> tuple[Robot, list[CurrentStats], tuple[float | None, ...], tuple[FrictionChoice | None, ...]]:
    """Step 3 over the joints: each identifiable joint fitted by ``fit_joint`` and written
    (:func:`_apply_current_fit`); returns as :func:`current_step`."""
    joints: list[Joint] = []
    stats: list[CurrentStats] = []
    held: list[float | None] = []
    chosen: list[FrictionChoice | None] = []
    for m, joint in enumerate(staged.joints):
        if m in problems:
            joints.append(joint)
            stats.append(CurrentStats())
            held.append(None)
            chosen.append(None)
            continue
        fit, choice = fit_joint(m, joint, STILL_SPEED * abs(joint.drive.gear_ratio))
        held.append(float(fit.params.get("holding", 0.0)))
        chosen.append(choice)
        new, stat = _apply_current_fit(m, joint, fit, said)
        joints.append(new)
        stats.append(stat)
    return staged.with_joints(joints), stats, tuple(held), tuple(chosen)


# ---------------------------------------------------------------------------------------------
# The method
