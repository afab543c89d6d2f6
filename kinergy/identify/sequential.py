"""The UR5e doc's sequential identification (sections 3-4).

1. Link data are taken from the robot model (UR's published masses and centres of mass; the
   inertia tensors barely matter behind a 100:1 gear, UR5e section 3.1).
2. Rotor inertia ``J_m + J_r`` of every drive from the controller's reference torque: the part of
   ``target_moment`` the links do not explain is the reflected rotor inertia times the
   acceleration (eqs 7-9), solved by least squares. (For coupled joints the reflection goes
   through the coupling matrix; the same least squares holds.)
3. Torque constant and friction of every motor together from the measured current (eqs 17-18):
   the current is linear in ``1/k_t`` (times the load torque from step 2's model) and in the
   friction parameters over ``k_t``. Any friction model linear in its parameters can be used
   (the model's ``linear`` parameters, :mod:`kinergy.friction`); the UR5e doc's is ``power_flow``.
4. Motor inertia = rotor inertia - the model's reducer inertia (Table IV).

Real controllers add one thing the seed does not model: a joint that stops stays in stiction,
and its current keeps part of the friction of the direction it stopped in. With ``hold="auto"``
each joint's fit is made holding 0, 25, 50, 75 and 100 % of its friction through standstill (the
``standstill`` and ``holding`` friction parameters) and keeps the best.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

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
from kinergy.identify.preprocess import IdentData
from kinergy.identify.result import (
    DriveEstimate,
    Fit,
    IdentificationResult,
    friction_entry,
    validation_metrics,
)
from kinergy.jsonable import OPTIONAL
from kinergy.linalg import scaled_lstsq
from kinergy.model.robot import Friction, Joint, Robot, Source

__all__ = [
    "AUTO_CANDIDATES",
    "FrictionChoice",
    "SequentialFit",
    "SequentialJoint",
    "identify_sequential",
    "rotor_inertias",
]

Array = NDArray[np.float64]

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
#: the models ``friction="auto"`` tries (those the logs support, :func:`_candidates`)
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


def _stack(datas: Sequence[IdentData], name: str) -> Array:
    return np.vstack([getattr(d, name) for d in datas])


@dataclass(frozen=True)
class SequentialJoint(DriveEstimate):
    """A joint's drive from the sequential method, with standard errors (motor side) and
    whether the logs identified it (``problem`` says why not)."""

    rotor_inertia_std: float | None = None
    torque_constant_std: float | None = field(default=None, metadata=OPTIONAL)
    friction_std: dict[str, float] | None = field(default=None, metadata=OPTIONAL)
    condition_current: float | None = field(default=None, metadata=OPTIONAL)
    identified: bool = True
    problem: str | None = field(default=None, metadata=OPTIONAL)


@dataclass(frozen=True)
class SequentialFit(Fit):
    """The sequential method's fit: the condition numbers of its regressions and the friction
    hold chosen per joint (None where not fitted)."""

    condition_rotor_inertia: float | None = field(default=None, metadata=OPTIONAL)
    friction_holding: tuple[float | None, ...] | None = field(default=None, metadata=OPTIONAL)
    friction_choice: tuple[FrictionChoice | None, ...] | None = field(
        default=None, metadata=OPTIONAL
    )


def rotor_inertias(
    robot: Robot, datas: Sequence[IdentData], active: Sequence[int] | None = None
) -> tuple[Array, Array, float]:
    """Step 2: ``J_m + J_r`` per motor from ``target_moment`` (UR5e eqs 7-9).

    ``tau_ref - f_link = N^T diag(J) N qdd`` with ``N`` the transmission matrix, linear in J.

    Returns
    -------
    inertia, std : ndarray, shape (n,)
        kg m^2 (motor side) and its standard deviation; motors not in ``active`` (default all)
        keep the model's value and a NaN deviation.
    condition : float
    """
    active = list(range(robot.n)) if active is None else list(active)
    q, qd, qdd = _stack(datas, "q_cmd"), _stack(datas, "qd_cmd"), _stack(datas, "qdd_cmd")
    tau_ref = _stack(datas, "tau_ref")
    f_link = rnea(robot, q, qd, qdd)
    n_mat = transmission_matrix(robot)
    # rows (sample, joint), column m: contribution of J_m, n_mat[m, j] * (N qdd)_m
    a = rotor_columns(n_mat, qdd @ n_mat.T).reshape(-1, robot.n)
    fixed = [m for m in range(robot.n) if m not in active]
    known = np.array([j.drive.rotor_inertia for j in robot.joints])
    y = (tau_ref - f_link).reshape(-1) - a[:, fixed] @ known[fixed]
    sol, sol_std, cond = scaled_lstsq(a[:, active], y)
    inertia, std = known.copy(), np.full(robot.n, np.nan)
    inertia[active], std[active] = sol, sol_std
    return inertia, std, cond


def _diagnose_motion(robot: Robot, datas: Sequence[IdentData]) -> dict[int, str]:
    """What the logs cannot identify, per joint (index -> reason).

    Raises
    ------
    KinergyError
        Too few samples, or no joint identifiable: one line naming every joint and why.
    """
    qd = _stack(datas, "qd")
    samples = qd.shape[0]
    if samples < 50:
        raise KinergyError(
            f"cannot identify from these logs: only {samples} samples (need at least 50)"
        )
    problems: dict[int, str] = {}
    for j, joint in enumerate(robot.joints):
        speed = np.abs(qd[:, j])
        if speed.max() < 10 * STILL_SPEED:
            problems[j] = (
                f"joint {j + 1} ({joint.name}) never moves (max |qd| {speed.max():.3g} rad/s): "
                "its rotor inertia, torque constant and friction cannot be identified"
            )
        elif (qd[:, j] > STILL_SPEED).sum() < 10 or (qd[:, j] < -STILL_SPEED).sum() < 10:
            problems[j] = (
                f"joint {j + 1} ({joint.name}) never reverses: Coulomb friction in one direction "
                "and the torque constant cannot be separated"
            )
    if len(problems) == robot.n:
        raise KinergyError("cannot identify from these logs: " + "; ".join(problems.values()))
    return problems


@dataclass(frozen=True, eq=False)
class _Signals:
    """One motor's signals for eq 18, motor side, each (N,): load torque ``tau_load`` (N m),
    speed ``wm`` (rad/s), acceleration ``dwm`` (rad/s^2), measured ``current`` (A) and the
    joint ``temperature`` (deg C, None when not logged)."""

    tau_load: Array
    wm: Array
    dwm: Array
    current: Array
    temperature: Array | None = None

    def rows(self, keep: NDArray[np.bool_]) -> _Signals:
        t = None if self.temperature is None else self.temperature[keep]
        return _Signals(self.tau_load[keep], self.wm[keep], self.dwm[keep], self.current[keep], t)


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
    cols = friction_columns(model, params, s.wm, s.tau_load, s.dwm, temperature=s.temperature)
    return np.column_stack([s.tau_load, cols])


def _solve_current(
    model: str, params: dict[str, float], signals: _Signals, kt_prior: float
) -> _CurrentFit:
    """Eq 18 for one motor with the model's shape parameters held (:func:`_current_fit`)."""
    a = _columns(model, params, signals)
    current = signals.current
    x, std, cond = scaled_lstsq(a, current)
    fixed = not (x[0] > 0 and std[0] < MAX_KT_SPREAD * x[0])
    if fixed:
        rest, rest_std, cond = scaled_lstsq(a[:, 1:], current - signals.tau_load / kt_prior)
        x = np.concatenate([[1.0 / kt_prior], rest])
        std = np.concatenate([[0.0], rest_std])
    sse = float(np.sum((current - a @ x) ** 2))
    return _CurrentFit(model, params, x, std, cond, sse, fixed)


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


def _rotor_step(
    robot: Robot, ref_logs: Sequence[IdentData], active: list[int], warnings: list[str]
) -> tuple[Array, Array, float | None]:
    """Rotor inertias (kg m^2, motor side), their standard errors (NaN where not identified) and
    the regression's condition number (None without ``target_moment``)."""
    rotor = np.array([j.drive.rotor_inertia for j in robot.joints])
    rotor_std = np.full(robot.n, np.nan)
    cond = None
    if ref_logs:
        rotor, rotor_std, cond = rotor_inertias(robot, ref_logs, active)
        if cond > MAX_CONDITION:
            raise KinergyError(
                f"rotor inertia regression is singular (condition {cond:.3g}): too little acceleration"
            )
    else:
        warnings.append("the logs have no target_moment: rotor inertias kept from the model")
    for j, joint in enumerate(robot.joints):
        if rotor[j] <= 0:
            warnings.append(
                f"joint {j + 1} ({joint.name}): identified rotor inertia {rotor[j]:.3g} kg m^2 is not positive"
            )
    return rotor, rotor_std, cond


def _with_rotor_inertias(robot: Robot, rotor: Array, warnings: list[str]) -> Robot:
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
            warnings.append(
                f"joint {j + 1} ({joint.name}): rotor inertia {rotor[j]:.3g} is below the model's "
                f"reducer inertia {joint.drive.reducer_inertia:.3g}; motor inertia set to 0"
            )
    return robot.with_joints(joints)


# ---------------------------------------------------------------------------------------------
# Step 3: torque constants and friction (UR5e eqs 17-18)


def _motor_signals(robot: Robot, rotor: Array, logs: Sequence[IdentData]) -> list[_Signals]:
    """Per motor: the load torque of ``robot`` with rotor inertias ``rotor``, the motor speed and
    acceleration, the measured current and the joint temperature (when every log has it), on
    the real motion of ``logs`` (:class:`_Signals`)."""
    q, qd, qdd = _stack(logs, "q"), _stack(logs, "qd"), _stack(logs, "qdd")
    n_mat = transmission_matrix(robot)
    tau_sim = rnea(robot, q, qd, qdd) + qdd @ (n_mat.T @ (rotor[:, None] * n_mat)).T
    tau_load = np.asarray(np.linalg.solve(n_mat.T, tau_sim.T).T, dtype=float)
    wm, dwm, current = qd @ n_mat.T, qdd @ n_mat.T, _stack(logs, "current")
    temps = None
    if all(d.temperature is not None for d in logs):
        temps = _stack(logs, "temperature")
    return [
        _Signals(
            tau_load[:, m],
            wm[:, m],
            dwm[:, m],
            current[:, m],
            None if temps is None else temps[:, m],
        )
        for m in range(robot.n)
    ]


def _start(joint: Joint, model: str, standstill: float, holding: float) -> dict[str, float]:
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
    ``standstill`` rad/s, motor side); the first whose squared current error no later one cuts by
    :data:`MIN_GAIN`."""
    best: _CurrentFit | None = None
    for holding in holdings:
        params = _start(joint, model, standstill, holding)
        fit = _current_fit(model, params, signals, joint.drive.torque_constant)
        if best is None or fit.sse < best.sse * (1.0 - MIN_GAIN):
            best = fit
    assert best is not None
    return best


@dataclass(frozen=True)
class FrictionChoice:
    """How ``friction="auto"`` chose a joint's model: each candidate's cross-validated current
    RMS (A, :data:`FOLDS` contiguous blocks), the winner, and how much lower its RMS is than
    Coulomb + viscous's and than the runner-up's (%)."""

    model: str
    cv_rms: dict[str, float]
    gain_over_viscous_coulomb: float | None
    margin: float | None


def _candidates(signals: _Signals) -> list[str]:
    """The models of :data:`AUTO_CANDIDATES` this joint's logs can support: temperature-dependent
    ones only where its temperature spans :data:`MIN_TEMPERATURE_SPAN`."""
    t = signals.temperature
    warm = t is not None and float(np.ptp(t)) >= MIN_TEMPERATURE_SPAN
    return [m for m in AUTO_CANDIDATES if warm or not get_model(m).needs_temperature]


def _cv_rms(fit: _CurrentFit, signals: _Signals, kt_prior: float) -> float:
    """Current RMS (A) of ``fit``'s model (its shape held) on each of :data:`FOLDS` contiguous
    blocks of the samples, fitted on the others."""
    index = np.arange(signals.current.size)
    edges = np.linspace(0, index.size, FOLDS + 1).astype(int)
    a = _columns(fit.model, fit.params, signals)
    squared = 0.0
    for lo, hi in itertools.pairwise(edges):
        held = (index >= lo) & (index < hi)
        train = _solve_current(fit.model, fit.params, signals.rows(~held), kt_prior)
        squared += float(np.sum((signals.current[held] - a[held] @ train.x) ** 2))
    return float(np.sqrt(squared / index.size))


def _auto_fit(
    joint: Joint, standstill: float, signals: _Signals, holdings: Sequence[float]
) -> tuple[_CurrentFit, FrictionChoice]:
    """``friction="auto"``: the standstill hold chosen with the joint's own model, then every
    candidate model fitted with it and scored by cross-validation; the lowest held-out RMS wins.
    Candidates whose regression is singular on these logs are left out."""
    own = _best_hold(joint, joint.drive.friction.model, standstill, signals, holdings)
    holding = float(own.params.get("holding", 0.0))
    kt = joint.drive.torque_constant
    fits, scores = {}, {}
    for model in _candidates(signals):
        fit = _current_fit(model, _start(joint, model, standstill, holding), signals, kt)
        if fit.cond <= MAX_CONDITION:
            fits[model], scores[model] = fit, _cv_rms(fit, signals, kt)
    ranked = sorted(scores, key=scores.__getitem__)
    best = ranked[0]

    def lower(other: str) -> float:
        return 100.0 * (1.0 - scores[best] / scores[other])

    vc = scores.get("viscous_coulomb")
    choice = FrictionChoice(
        model=best,
        cv_rms=scores,
        gain_over_viscous_coulomb=None if vc is None else lower("viscous_coulomb"),
        margin=lower(ranked[1]) if len(ranked) > 1 else None,
    )
    return fits[best], choice


@dataclass(frozen=True)
class _CurrentStats:
    """A joint's standard errors and condition number from eq 18 (:class:`SequentialJoint`)."""

    torque_constant_std: float | None = None
    friction_std: dict[str, float] | None = None
    condition_current: float | None = None


def _apply_current_fit(
    m: int, joint: Joint, fit: _CurrentFit, warnings: list[str]
) -> tuple[Joint, _CurrentStats]:
    """``joint`` with the torque constant and friction of ``fit``, and their standard errors."""
    if fit.fixed:
        warnings.append(
            f"joint {m + 1} ({joint.name}): the logs do not pin the torque constant down "
            "(too little load torque against friction and noise); kept the model's "
            f"{joint.drive.torque_constant:.4g} N m/A"
        )
    if fit.cond > MAX_CONDITION:
        raise KinergyError(
            f"joint {m + 1} ({joint.name}): the current regression is singular (condition "
            f"{fit.cond:.3g}): the log does not excite every friction term of model {fit.model!r}"
        )
    x, std, names = fit.x, fit.std, get_model(fit.model).linear
    kt = 1.0 / x[0]
    values = x[1:] * kt
    kt_std = std[0] / x[0] ** 2
    value_std = np.sqrt((std[1:] * kt) ** 2 + (x[1:] * kt_std * kt) ** 2)
    for name, value in zip(names, values, strict=True):
        if value < 0 and name not in ("gamma1",):
            warnings.append(
                f"joint {m + 1} ({joint.name}): friction {name} = {value:.3g} is negative"
            )
    friction = Friction(fit.model, with_linear_parameters(fit.model, fit.params, values))
    drive = dataclasses.replace(joint.drive, torque_constant=float(kt), friction=friction)
    stats = _CurrentStats(
        torque_constant_std=float(kt_std),
        friction_std={name: float(s) for name, s in zip(names, value_std, strict=True)},
        condition_current=fit.cond,
    )
    return dataclasses.replace(joint, drive=drive), stats


def _current_step(
    staged: Robot,
    rotor: Array,
    logs: Sequence[IdentData],
    problems: dict[int, str],
    options: tuple[str | None, str | bool],
    warnings: list[str],
) -> tuple[Robot, list[_CurrentStats], tuple[float | None, ...], tuple[FrictionChoice | None, ...]]:
    """Torque constants and friction of every identifiable motor from the currents (eqs 17-18);
    ``options`` = (friction model, ``"auto"`` or None; hold). Returns the robot, each joint's
    statistics, the friction fraction held through standstill and, with ``"auto"``, how each
    joint's model was chosen (None where not fitted)."""
    friction, hold = options
    signals = _motor_signals(staged, rotor, logs)
    holdings = HOLDINGS if hold == "auto" else ((1.0,) if hold else (0.0,))
    joints: list[Joint] = []
    stats: list[_CurrentStats] = []
    held: list[float | None] = []
    chosen: list[FrictionChoice | None] = []
    for m, joint in enumerate(staged.joints):
        choice = None
        if m in problems:
            joints.append(joint)
            stats.append(_CurrentStats())
            held.append(None)
            chosen.append(None)
            continue
        standstill = STILL_SPEED * abs(joint.drive.gear_ratio)
        if friction == "auto":
            fit, choice = _auto_fit(joint, standstill, signals[m], holdings)
        else:
            model = friction or joint.drive.friction.model
            fit = _best_hold(joint, model, standstill, signals[m], holdings)
        held.append(float(fit.params.get("holding", 0.0)))
        chosen.append(choice)
        new, stat = _apply_current_fit(m, joint, fit, warnings)
        joints.append(new)
        stats.append(stat)
    return staged.with_joints(joints), stats, tuple(held), tuple(chosen)


# ---------------------------------------------------------------------------------------------
# The method


def _sources(robot: Robot, has_ref: bool, has_current: bool) -> dict[str, Source]:
    """The robot's sources with the identified groups marked."""
    sources = dict(robot.sources)
    if has_ref:
        sources["drive_inertia"] = Source(
            "identified", "kinergy identify (sequential, UR5e eqs 7-9)"
        )
    if has_current:
        ref = "kinergy identify (sequential, UR5e eqs 17-18)"
        sources["torque_constant"] = Source("identified", ref)
        sources["friction"] = Source("identified", ref)
    return sources


def _joints(
    identified: Robot,
    rotor: tuple[Array, Array],
    problems: dict[int, str],
    stats: Sequence[_CurrentStats],
) -> tuple[SequentialJoint, ...]:
    """Per joint: the identified drive with ``rotor`` = (inertias, standard errors)."""
    inertia, std = rotor
    return tuple(
        SequentialJoint(
            name=joint.name,
            rotor_inertia=float(joint.drive.motor_inertia + joint.drive.reducer_inertia)
            if inertia[j] >= joint.drive.reducer_inertia
            else float(inertia[j]),
            rotor_inertia_std=None if np.isnan(std[j]) else float(std[j]),
            motor_inertia=joint.drive.motor_inertia,
            torque_constant=joint.drive.torque_constant,
            friction=friction_entry(joint),
            identified=j not in problems,
            problem=problems.get(j),
            **vars(stats[j]),
        )
        for j, joint in enumerate(identified.joints)
    )


def identify_sequential(
    robot: Robot,
    datas: Sequence[IdentData],
    *,
    friction: str | None = None,
    hold: str | bool = "auto",
) -> IdentificationResult:
    """Identify rotor inertias, torque constants and friction with the UR5e doc's procedure.

    Parameters
    ----------
    robot : Robot
        The starting model: its link data are kept.
    datas : sequence of IdentData
        Prepared logs (:func:`kinergy.identify.preprocess.prepare`). Rotor inertias need
        ``target_moment``; torque constants and friction need ``actual_current``.
    friction : str, optional
        Friction model for every joint (default: each joint's model in ``robot``); it must be
        linear in its parameters (all of kinergy's are, given their shape parameters).
        ``"auto"``: per joint, the model of :data:`AUTO_CANDIDATES` the logs support with the
        lowest cross-validated current RMS (``fit.friction_choice`` says which won, by how much).
    hold : {"auto", True, False}
        Hold friction through standstill (see the module docstring); ``auto`` keeps whichever
        fits the currents better.

    Returns
    -------
    IdentificationResult
        ``method = "sequential"``, joints of :class:`SequentialJoint`, fit a
        :class:`SequentialFit`.

    Raises
    ------
    KinergyError
        Logs that cannot identify a parameter (a joint that never moves or never reverses, too few
        samples, a singular regression), naming the joints.
    """
    if not datas:
        raise KinergyError("no log to identify from")
    problems = _diagnose_motion(robot, datas)
    warnings: list[str] = [f"{text}; kept the model's values" for text in problems.values()]
    ref_logs = [d for d in datas if d.tau_ref is not None]
    current_logs = [d for d in datas if d.current is not None]
    if not (ref_logs or current_logs):
        raise KinergyError(
            "identification needs target_moment (rotor inertia) or actual_current (torque "
            "constant and friction); the logs have neither"
        )
    active = [j for j in range(robot.n) if j not in problems]
    rotor, rotor_std, cond = _rotor_step(robot, ref_logs, active, warnings)
    staged = _with_rotor_inertias(robot, rotor, warnings)
    stats: list[_CurrentStats] = [_CurrentStats() for _ in range(robot.n)]
    held = choices = None
    if current_logs:
        options = (friction, hold)
        staged, stats, held, choices = _current_step(
            staged, rotor, current_logs, problems, options, warnings
        )
    else:
        warnings.append(
            "the logs have no actual_current: torque constants and friction kept from the model"
        )
    sources = _sources(staged, bool(ref_logs), bool(current_logs))
    identified = dataclasses.replace(staged, sources=sources)
    fit = SequentialFit(
        **vars(validation_metrics(identified, datas)),
        samples=int(sum(len(d) for d in datas)),
        logs=tuple(d.path for d in datas),
        lag=tuple(d.lag for d in datas),
        warnings=tuple(warnings),
        condition_rotor_inertia=cond,
        friction_holding=held,
        friction_choice=choices if friction == "auto" else None,
    )
    joints = _joints(identified, (rotor, rotor_std), problems, stats)
    return IdentificationResult(identified, "sequential", joints, fit)
