"""The full method: one base-parameter regression of the links, the rotor inertias and friction.

Where the sequential method (:mod:`kinergy.identification.sequential`) keeps the model's link data and
identifies the drives step by step, the full method identifies everything the joint torques are
linear in at once (Gautier's base-parameter identification; nursing eqs 15-16 and the nursing
paper's ridge regression)::

    tau = Y_b(q, qd, qdd) pi_b + N^T diag(J) N qdd + N^T F(wm) phi                  (1)

- ``Y_b pi_b``: rigid-body torques in the base (minimal) inertial parameters of the links (nursing
  eqs 15-16; :func:`kinergy.dynamics.regressor.base_parameters` gives the structural set);
- ``N^T diag(J) N qdd``: motor plus reducer inertias ``J = J_m + J_r`` (motor side, kg m^2)
  reflected through the transmission ``N`` (UR5e eq 2, ``i^2 (J_m + J_r) qdd`` for a UR joint);
- ``N^T F(wm) phi``: motor-side friction, ``F`` the columns of each joint's friction model
  (:meth:`kinergy.friction.model.FrictionModel.friction_columns`) at the motor speeds ``wm = N qd`` and ``phi``
  its linear parameters; shape parameters (smoothing, Stribeck speed, ...) stay the model's.

``tau`` is the signal chosen by ``target``:

``"moment"``
    ``target_moment`` on the commanded motion: the controller's feed-forward (UR5e eq 7), which has
    no friction, so (1) without its last term.
``"torque"``
    Measured joint torques (arms with joint torque sensors) on the real motion, with friction.
``"current"``
    ``actual_current`` on the real motion as joint torques through the model's torque constants,
    ``tau = N^T (k_t * I)`` (UR5e eq 17), with friction. A common scale of every parameter and of
    ``1/k_t`` cannot be told apart, so the torque constants stay the model's.

The pipeline: the stacked columns of (1) (:mod:`kinergy.identification.columns`); their linear
dependence by column-scaled QR with column pivoting (Gautier's numerical rank), the link base
columns first, and the solver (:mod:`kinergy.identification.regression`); the robot written back
(:mod:`kinergy.identification.writeback`, with the physically consistent refit of
:mod:`kinergy.identification.constrained`).

A rotor inertia can multiply the very signal a link base parameter does (on a UR arm ``J_1`` and
the ``Iyy1`` group both multiply only ``qdd1`` on joint 1), and a friction term can go unexcited.
Such columns are dropped: their parameters keep the model's values and the parameters they merge
into absorb the difference (``fit.merged`` gives the combination, ``fit.warnings`` says so; the
``Iyy1`` group carries ``i_1^2 (J_1 - J_1,model)``).

Solvers: ordinary least squares; Gautier's weighted least squares (the rows of joint ``j``
weighted by ``1 / sigma_j``, ``sigma_j`` its residual standard deviation after an OLS pass); ridge
regression on unit-norm columns shrinking toward the model's values (a weakly excited parameter
stays near its prior instead of collapsing to zero): with the columns scaled, ``z_k = |A_k| x_k``,
``|y - A_s z|^2 + lambda |z - z_model|^2`` is minimised, so ``lambda`` compares with the unit
diagonal of the scaled normal matrix and a direction whose scaled singular value is below
``sqrt(lambda)`` stays near the model. Each regression is solved from one QR factorisation of the
column-scaled ``[A | y]``; everything after it works on the small triangle.

A robot file stores masses, centres of mass and inertias, not base parameters. The standard
parameters closest to the model's that reproduce the identified base parameters exactly are
written back; when one of those links is not physical or a rotor inertia comes out negative, the
robot is written from the least-squares fit constrained to physically consistent links and
non-negative rotor inertias instead (``fit.write_back``, ``fit.physical_fit`` with its chi^2
increase; merged rotor inertias may then move, the merged combinations keep their fit). Every
non-physical link is named in ``fit.warnings``; a link that still cannot be made physical keeps
the model's data, and the returned robot then differs from the identified base parameters.
``fit.regression`` is always the unconstrained fit, ``fit.torque`` etc. the returned robot's.

Limitations: only the friction models' linear parameters are fitted, and the torque constants
never. With ``power_flow`` friction the direction of power flow is decided from the measurement
where the load is within its noise of zero: a small bias
(:func:`kinergy.identification.columns.power_flow_load`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from kinergy import checks
from kinergy.dynamics.regressor import BaseParameters, base_parameters, inertial_parameters
from kinergy.errors import Code, KinergyError
from kinergy.friction.model import FrictionModel
from kinergy.friction.none import MODEL as NO_FRICTION
from kinergy.identification.chunks import LogChunks, Summary, one_blas_thread
from kinergy.identification.columns import (
    LOAD_DEPENDENT,
    Regression,
    columns,
    joint_frictions,
    scale_row,
)
from kinergy.identification.drive_steps import FrictionChoice
from kinergy.identification.metrics import JointMetrics, MetricSums
from kinergy.identification.offsets import fixed_notes, weak_offsets, with_fixed
from kinergy.identification.options import (
    CurrentOptions,
    FrictionOption,
    IdentifyOptions,
    Method,
    Solver,
    Target,
    friction_option,
)
from kinergy.identification.regression import (
    MAX_CONDITION,
    FlowFit,
    MergedColumn,
    Merging,
    Solved,
    fit_power_flow,
    merged_columns,
    solve,
)
from kinergy.identification.result import (
    AT_BOUND,
    KEPT,
    DriveEstimate,
    Fit,
    Flag,
    IdentificationResult,
    drive_fields,
    fit_fields,
)
from kinergy.identification.sequential import DrivesFromCurrents, drives_from_currents
from kinergy.identification.smoothing import Smoothing, search_smoothing
from kinergy.identification.writeback import WriteBack, write_back
from kinergy.jsonable import OPTIONAL
from kinergy.logs.prepare import IdentData
from kinergy.messages import Messages
from kinergy.model.robot import Friction, Robot

__all__ = [
    "MAX_CONDITION",
    "FullFit",
    "FullJoint",
    "Parameter",
    "PhysicalFit",
    "full",
    "identify_full",
    "rescaled",
]


#: a joint whose speed never exceeds this (rad/s) counts as not moving
MOVING_SPEED = 0.05
#: samples needed per unknown parameter
SAMPLES_PER_PARAMETER = 2
#: against currents alone, where the common scale of every unknown comes from
SCALE_NOTE = (
    "currents alone cannot fix a common scale of the links, rotor inertias, friction and torque "
    "constants: taken from the model's published masses (the identified gravity torques, "
    "projected on the model's, equal the model's)"
)
#: the IdentData field and the log signal of each target
_FIELD = {Target.MOMENT: "tau_ref", Target.TORQUE: "torque", Target.CURRENT: "current"}
_SIGNAL = {
    Target.MOMENT: "target_moment",
    Target.TORQUE: "measured joint torques",
    Target.CURRENT: "actual_current",
}


# ---------------------------------------------------------------------------------------------
# Results


@dataclass(frozen=True)
class Parameter:
    """One unknown of the regression: its value, standard error and relative standard error
    (None where not estimable) and, for the stacked unknowns, its group (``link``, ``rotor``,
    ``friction``, ``torque_constant``) and flag (:data:`~kinergy.identification.result.FLAGS`, as
    written to the returned robot)."""

    name: str
    value: float
    std: float | None
    rel_std: float | None
    group: str | None = field(default=None, metadata=OPTIONAL)
    flag: Flag | None = field(default=None, metadata=OPTIONAL)


@dataclass(frozen=True)
class FullJoint(DriveEstimate):
    """A joint's drive from the full method. ``rotor_inertia`` is as written to the returned
    robot; ``motor_inertia`` = ``rotor_inertia - reducer_inertia`` (below the model's reducer
    inertia, 0 and the reducer inertia lowered to ``rotor_inertia``, with a warning);
    ``torque_constant`` is the model's. Adds the rotor inertia's standard error (None when
    merged), whether its column was merged into the link parameters, and the friction
    parameters' standard errors."""

    rotor_inertia_std: float | None = None
    rotor_inertia_merged: bool = False
    friction_std: dict[str, float | None] = field(default_factory=dict)
    torque_sensor_offset: float | None = field(default=None, metadata=OPTIONAL)
    torque_sensor_offset_std: float | None = field(default=None, metadata=OPTIONAL)


@dataclass(frozen=True)
class PhysicalFit:
    """The fit constrained to physical values (:mod:`kinergy.identification.constrained`): its chi^2
    increase over the unconstrained fit, the constraints it sits on, the solver, its base
    parameters (b,), rotor inertias (n, kg m^2, motor side) and per-joint metrics of its
    prediction of the target (N m, joint side; ``FullFit.regression`` is the unconstrained
    fit's, so their RMS are the fit before and after the constraints)."""

    chi2_increase: float
    active: tuple[str, ...]
    solver: str
    base_parameters: tuple[float, ...]
    rotor_inertia: tuple[float, ...]
    regression: tuple[JointMetrics, ...]


@dataclass(frozen=True)
class FullFit(Fit):
    """The full method's fit (module docstring).

    Attributes
    ----------
    target, solver, ridge :
        The regression's settings.
    condition : float
        Condition number of the column-scaled stacked regressor (kept columns).
    power_flow_iterations, power_flow_mismatch : int
        Passes of the power-flow fixed point, and samples where the fitted model's own load
        torque disagrees with the direction used (0 without ``power_flow`` friction).
    weights, condition_weighted :
        WLS only: per-joint weights ``1 / sigma_j^2`` and the weighted problem's condition.
    residual_std : tuple of float
        N m per joint, joint side.
    regression : tuple of JointMetrics
        The base-parameter model's prediction of the target (N m, joint side).
    merged : tuple of MergedColumn
        Dropped columns: the model's value kept and what they merge into.
    parameters, base_parameters : tuple of Parameter
        Every column of the regression with its group; the base parameters, named by
        :meth:`BaseParameters.expressions`.
    physical_fit : PhysicalFit or None
        When the robot was written from the constrained fit.
    write_back : str
        ``"closest"`` (the unconstrained fit is physical: it is the constrained problem's
        solution) or ``"physically consistent least squares"``.
    drives : str
        Where the torque constants and friction come from: ``"currents"`` (UR5e eqs 17-18 on the
        identified links, :func:`~kinergy.identification.sequential.drives_from_currents`),
        ``"regression"`` (unknowns of the regression) or ``"model"``.
    scale : str or None
        Against currents alone: where the common scale comes from.
    friction_holding : tuple of float or None
        With drives from the currents: the friction fraction held through standstill per joint.
    friction_choice : tuple of FrictionChoice or None
        With ``friction="auto"``: how each joint's family was chosen on the currents.
    links_not_physical_closest, links_physical, standard_parameters :
        Links (1-based) whose closest standard parameters are not physical; per link whether
        the returned robot's is the identified one; the written standard parameters by name.
    """

    target: str = ""
    solver: str = "ols"
    ridge: float = 0.0
    condition: float = float("nan")
    power_flow_iterations: int = 0
    power_flow_mismatch: int = 0
    weights: tuple[float, ...] | None = field(default=None, metadata=OPTIONAL)
    condition_weighted: float | None = field(default=None, metadata=OPTIONAL)
    residual_std: tuple[float, ...] = ()
    regression: tuple[JointMetrics, ...] = ()
    merged: tuple[MergedColumn, ...] = ()
    parameters: tuple[Parameter, ...] = ()
    base_parameters: tuple[Parameter, ...] = ()
    physical_fit: PhysicalFit | None = field(default=None, metadata=OPTIONAL)
    write_back: str = "closest"
    drives: str = "model"
    scale: str | None = field(default=None, metadata=OPTIONAL)
    friction_holding: tuple[float | None, ...] | None = field(default=None, metadata=OPTIONAL)
    friction_choice: tuple[FrictionChoice | None, ...] | None = field(
        default=None, metadata=OPTIONAL
    )
    links_not_physical_closest: tuple[int, ...] = ()
    links_physical: tuple[bool, ...] = ()
    standard_parameters: dict[str, float] = field(default_factory=dict)


# ---------------------------------------------------------------------------------------------
# Checks of the options and the logs


def _parsed(target: Target | str, solver: Solver | str) -> tuple[Target, Solver]:
    """``target`` and ``solver`` as their types (the Python API's strings parsed)."""
    return checks.choice(target, Target, "target"), checks.choice(solver, Solver, "solver")


def _pick_target(logs: LogChunks, target: Target) -> Target:
    """``target``, checked against the logs; ``AUTO``: torque, else moment, else current."""
    if target == Target.AUTO:
        for name in (Target.TORQUE, Target.MOMENT, Target.CURRENT):
            if logs.every(_FIELD[name]):
                return name
        raise KinergyError(
            "the full method needs measured joint torques, target_moment or actual_current in "
            "every log; the logs have none of them in common"
        )
    missing = [s.path for s, summary in zip(logs.segments, logs.summaries, strict=True)
               if _FIELD[target] not in summary.has]  # fmt: skip
    if missing:
        raise KinergyError(
            f"target {target.value!r} needs {_SIGNAL[target]}, missing in {', '.join(missing)}"
        )
    return target


def _diagnose(robot: Robot, summary: Summary, commanded: bool, n_params: int) -> None:
    """One line naming what the logs cannot identify: too few samples, joints that never move
    (in the motion regressed on: commanded against ``target_moment``)."""
    problems = []
    samples = summary.samples
    need = SAMPLES_PER_PARAMETER * n_params
    if samples < need:
        problems.append(f"only {samples} samples for {n_params} parameters (need at least {need})")
    peak = summary.peak_cmd if commanded else summary.peak
    for j, joint in enumerate(robot.joints):
        top = float(peak[j]) if samples else 0.0
        if top < MOVING_SPEED:
            problems.append(
                f"joint {j + 1} ({joint.name}) never moves (max |qd| {top:.3g} rad/s): its link, "
                "rotor inertia and friction parameters cannot be identified"
            )
    if problems:
        raise KinergyError("cannot identify from these logs: " + "; ".join(problems))


# ---------------------------------------------------------------------------------------------
# The steps


def _regression(
    robot: Robot,
    base: BaseParameters,
    logs: LogChunks,
    target: Target,
    friction: FrictionModel | None,
) -> Regression:
    """Eq (1) over ``logs`` (:class:`kinergy.identification.columns.Regression`), after checking the
    logs can identify its columns (:func:`_diagnose`)."""
    commanded = target == Target.MOMENT
    frictions = joint_frictions(robot, friction, commanded)
    cols = columns(robot, base, *frictions, target)
    _diagnose(robot, logs.summary(), commanded, cols.prior.size)
    return Regression(robot, base, cols, *frictions, target, logs.every("temperature"))


@dataclass(frozen=True, eq=False)
class _Evaluation:
    """What a last pass over the rows finds: the per-joint metrics (N m, joint side) of the
    regression's prediction of the target and of the constrained fit's (None when not used),
    the samples whose power-flow direction the fitted model's own load torque disagrees with,
    and a few thousand of the positions regressed on (for :func:`scale_row`)."""

    regression: tuple[JointMetrics, ...]
    physical: tuple[JointMetrics, ...] | None
    mismatch: int
    q: np.ndarray


def _evaluate(
    reg: Regression, logs: LogChunks, flow: FlowFit, solved: Solved, written: WriteBack
) -> _Evaluation:
    """:class:`_Evaluation` in one pass over the rows, with the load torques of the fit."""
    n, n_fixed, n_mat = reg.robot.n, reg.n_fixed, reg.n_mat
    regression = MetricSums(n)
    physical = MetricSums(n) if written.chi2 is not None else None
    flows = [m for m, model in enumerate(reg.models) if model in LOAD_DEPENDENT]
    step = max(1, logs.summary().samples // 2000)
    mismatch, at, poses = 0, 0, []
    loads = iter(flow.loads) if flow.loads is not None else None
    for _, rows in reg.rows(logs, loads):
        regression.add(rows.y3, rows.a @ solved.x)
        if physical is not None:
            physical.add(rows.y3, rows.a @ written.x)
        if flows:  # how often the fitted model's own load torque disagrees
            tau_sim = rows.a[:, :, :n_fixed] @ flow.ols.x[:n_fixed]
            own = np.linalg.solve(n_mat.T, tau_sim.T).T[:, flows]
            wm = rows.wm[:, flows]
            mismatch += int(np.sum(np.sign(wm * own) != np.sign(wm * rows.load[:, flows])))
        first = -at % step
        poses.append(rows.q[first::step].copy())  # no view: it would keep the chunk
        at += len(rows.q)
    return _Evaluation(
        regression.metrics(),
        None if physical is None else physical.metrics(),
        mismatch,
        np.vstack(poses),
    )


def _optional(value: float) -> float | None:
    return None if np.isnan(value) else float(value)


#: a base parameter whose standard error is below this share of the largest base parameter is
#: determined to round-off (a parameter that is zero, such as a product of inertia on an axis,
#: has a relative standard error of any size there)
ROUND_OFF = 1e-6


def _undetermined(base: Sequence[Parameter], parameters: Sequence[Parameter]) -> list[str]:
    """Warnings for what the logs do not determine: base parameters whose standard error exceeds
    their value (and :data:`ROUND_OFF`), and drive parameters held at a physical bound (the
    unconstrained fit put them outside it: what is written is the bound, not an estimate)."""
    out = []
    floor = ROUND_OFF * max((abs(p.value) for p in base), default=0.0)
    loose = [p for p in base if p.rel_std is not None and p.rel_std > 1.0 and (p.std or 0) > floor]
    if loose:
        worst = max(loose, key=lambda p: p.rel_std or 0.0)
        out.append(
            f"{len(loose)} of {len(base)} base parameters have a standard error larger than "
            f"their value (largest: {worst.name}, {worst.rel_std:.3g} times): the logs do not "
            "determine them; the model predicts motions like the logs', its link parameters "
            "are not measurements (fit.base_parameters[].rel_std)"
        )
    held: dict[str, list[str]] = {}
    for p in parameters[len(base) :]:
        if p.flag == AT_BOUND:
            what, _, joint = p.name.partition(" of joint ")
            held.setdefault(what, []).append(joint.split(" ")[0] if joint else p.name)
    if held:
        listed = "; ".join(f"{what} of joint(s) {', '.join(js)}" for what, js in held.items())
        out.append(
            f"held at a physical bound (the data put them outside it): {listed}; what is written "
            "for them is the bound, not an estimate"
        )
    return out


def _parameters(
    x: np.ndarray,
    std: np.ndarray,
    names: Sequence[str],
    groups: Sequence[str | None],
    flags: Sequence[Flag | None],
) -> tuple[Parameter, ...]:
    """The first ``len(names)`` unknowns ``x`` with their standard errors ``std``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.abs(std) / np.abs(x)
    return tuple(
        Parameter(name, float(x[k]), _optional(std[k]), _optional(rel[k]), group, flag)
        for k, (name, group, flag) in enumerate(zip(names, groups, flags, strict=True))
    )


def _regression_drive(
    m: int, written: WriteBack, solved: Solved, reg: Regression, commanded: bool
) -> tuple[dict[str, Flag], dict[str, float | None]]:
    """Flags and standard errors of motor ``m``'s rotor inertia, torque constant and friction as
    the regression gave them."""
    cols = reg.cols
    col = cols.n_link + m
    flags = {"rotor_inertia": written.flags[col], "torque_constant": KEPT}
    std: dict[str, float | None] = {"rotor_inertia": _optional(solved.std[col])}
    names = reg.models[m].linear
    for k, name in enumerate(names):
        at = int(cols.fric_at[m]) + k
        flags[name] = KEPT if commanded else written.flags[at]
        std[name] = None if commanded else _optional(solved.std[at])
    std["torque_constant"] = None
    return flags, std


def _joints(
    robot: Robot,
    written: WriteBack,
    solved: Solved,
    reg: Regression,
    drives: DrivesFromCurrents | None,
) -> tuple[FullJoint, ...]:
    """Per joint: the drive as written, with standard errors, flags and the merged flag."""
    cols, commanded = reg.cols, reg.target == Target.MOMENT
    out = []
    for m, joint in enumerate(robot.joints):
        col = cols.n_link + m
        flags, std = _regression_drive(m, written, solved, reg, commanded)
        if drives is not None:
            flags = {"rotor_inertia": flags["rotor_inertia"], **drives.flags[m]}
            std = {"rotor_inertia": std["rotor_inertia"], **drives.std[m]}
        fields = drive_fields(joint, rotor_inertia=float(written.x[col]))
        names = joint.drive.friction.model.linear
        offset = offset_std = None
        if cols.offset_at is not None:
            at = cols.offset_at + m
            offset, offset_std = float(written.x[at]), _optional(solved.std[at])
            flags = {**flags, "torque_sensor_offset": written.flags[at]}
            std = {**std, "torque_sensor_offset": offset_std}
        out.append(
            FullJoint(
                **fields,
                rotor_inertia_std=std["rotor_inertia"],
                rotor_inertia_merged=bool(col in solved.dropped and col not in cols.fixed),
                flags=flags,
                std=std,
                friction_std={name: std.get(name) for name in names},
                torque_sensor_offset=offset,
                torque_sensor_offset_std=offset_std,
            )
        )
    return tuple(out)


def _physical(reg: Regression, written: WriteBack, evaluation: _Evaluation) -> PhysicalFit | None:
    """The constrained fit's record, when the robot was written from it."""
    if written.chi2 is None or written.solver is None or evaluation.physical is None:
        return None
    n_link, n = reg.cols.n_link, reg.robot.n
    return PhysicalFit(
        chi2_increase=written.chi2,
        active=written.active,
        solver=written.solver,
        base_parameters=tuple(written.x[:n_link].tolist()),
        rotor_inertia=tuple(written.x[n_link : n_link + n].tolist()),
        regression=evaluation.physical,
    )


@dataclass(frozen=True, eq=False)
class _Steps:
    """What the steps of :func:`full` produced, for its fit record."""

    reg: Regression
    flow: FlowFit
    solved: Solved
    merging: Merging
    written: WriteBack
    evaluation: _Evaluation
    drives: DrivesFromCurrents | None
    robot: Robot
    choice: tuple[FrictionChoice | None, ...] | None
    smoothing: Smoothing


def _fit(logs: LogChunks, steps: _Steps, *, solver: Solver, ridge: float) -> FullFit:
    """The fit record of the steps of :func:`full`."""
    reg, flow, solved, written = steps.reg, steps.flow, steps.solved, steps.written
    cols, target = reg.cols, reg.target
    said = Messages()
    if not flow.settled:
        said.warn(
            f"the friction's power-flow directions did not settle in {flow.iterations} iterations"
        )
    if steps.drives is not None:
        said.extend(steps.drives.said)
    said.extend(steps.merging.said)
    bare = [
        str(m + 1)
        for m, (model, joint) in enumerate(zip(reg.models, reg.robot.joints, strict=True))
        if joint.drive.friction.model is NO_FRICTION and model is not NO_FRICTION
    ]
    if bare:
        said.note(
            f"joint(s) {', '.join(bare)} had no friction in the model: fitted with "
            f"{reg.models[int(bare[0]) - 1].name} friction"
        )
    said.notes += fixed_notes(cols)
    said.notes += [n for n in (steps.smoothing.note(),) if n]
    said.extend(written.said)
    weighted = solved.weights is not None
    b = cols.n_link
    regression = steps.evaluation.regression
    parameters = _parameters(solved.x, solved.std, cols.names, cols.group, written.flags)
    base = _parameters(solved.x, solved.std, reg.base.expressions(), [None] * b, written.flags[:b])
    said.warnings += _undetermined(base, parameters)
    return FullFit(
        **vars(fit_fields(steps.robot, logs, said)),
        target=target.value,
        solver=solver.value,
        ridge=float(ridge),
        condition=flow.ols.solution.cond,
        power_flow_iterations=flow.iterations,
        power_flow_mismatch=steps.evaluation.mismatch,
        weights=tuple(solved.weights.tolist()) if solved.weights is not None else None,
        condition_weighted=solved.solution.cond if weighted else None,
        residual_std=tuple(m.rms for m in regression),
        regression=regression,
        merged=steps.merging.columns,
        parameters=parameters,
        base_parameters=base,
        physical_fit=_physical(reg, written, steps.evaluation),
        write_back=written.method,
        drives="currents"
        if steps.drives
        else ("regression" if target != Target.MOMENT else "model"),
        scale=SCALE_NOTE if target == Target.CURRENT and steps.drives else None,
        friction_holding=steps.drives.holding if steps.drives else None,
        friction_choice=steps.choice,
        links_not_physical_closest=written.links_not_physical_closest,
        links_physical=written.links_physical,
        standard_parameters=written.standard_parameters,
    )


def rescaled(robot: Robot, s: float) -> Robot:
    """``robot`` with every torque scaled by ``s``: link masses and inertias, rotor inertias,
    friction levels, torque and motor constants (centres of mass, currents and copper losses
    unchanged). A fit against currents alone is only known up to this scale."""
    joints = []
    for j in robot.joints:
        link = dataclasses.replace(j.link, mass=j.link.mass * s, inertia=j.link.inertia * s)
        fr = j.drive.friction
        levels = fr.model.values_of(fr.params) * s
        drive = dataclasses.replace(
            j.drive,
            motor_inertia=j.drive.motor_inertia * s,
            reducer_inertia=j.drive.reducer_inertia * s,
            torque_constant=j.drive.torque_constant * s,
            motor_constant=j.drive.motor_constant * s,
            friction=Friction(fr.model, fr.model.with_values(fr.params, levels)),
        )
        joints.append(dataclasses.replace(j, link=link, drive=drive))
    return robot.with_joints(joints)


def identify_full(
    robot: Robot,
    datas: Sequence[IdentData],
    *,
    target: Target | str = Target.AUTO,
    solver: Solver | str = Solver.OLS,
    ridge: float = 0.0,
    friction: FrictionOption | str = None,
    currents: bool = True,
) -> IdentificationResult:
    """Identify link base parameters, rotor inertias and friction in one regression:
    :func:`full` on prepared logs held in memory (each one chunk).

    Solves, over every sample and joint of every log, the linear model (module docstring, eq
    (1)) ``tau = Y_b pi_b + N^T diag(J) N qdd + N^T F(wm) phi`` with ``pi_b`` the links' base
    parameters (nursing eqs 15-16), ``J = J_m + J_r`` the rotor inertias (motor side, kg m^2;
    UR5e eq 2) and ``phi`` the friction models' linear parameters (motor side), then writes
    physically consistent standard link parameters back into the model
    (:mod:`kinergy.identification.writeback`, :mod:`kinergy.identification.constrained`). Against
    ``target_moment`` or measured torques, logged currents then give the torque constants and
    friction (UR5e eqs 17-18); against currents alone they are unknowns of the regression.

    Parameters
    ----------
    robot : Robot
        The starting model: its kinematics, transmissions and friction shape parameters are used
        as they are; its link data, rotor inertias, torque constants and friction levels are the
        priors (kept where the logs cannot identify them, shrunk toward by ridge).
    datas : sequence of IdentData
        Prepared logs (:func:`kinergy.logs.prepare.prepare`), arrays (N, n).
    target : {"auto", "moment", "torque", "current"}
        The signal regressed against: ``target_moment`` (N m) on the commanded motion without
        friction, measured joint torques (N m) or ``actual_current`` (A) on the real motion with
        friction. ``"auto"``: torque if every log has it, else moment, else current.
    solver : {"ols", "wls", "ridge"}
        Ordinary least squares; weighted least squares, per-joint weights ``1 / sigma_j^2`` from an
        OLS pass's residuals (Gautier); ridge regression toward the model's values.
    ridge : float
        The ridge weight ``lambda`` on unit-norm columns (``solver="ridge"`` only, > 0; module
        docstring): 1e-6 to 1e-2 are typical.
    friction : FrictionModel or str, optional
        Friction model for every joint, or its name (default: each joint's own). Its shape
        parameters are the joint's when the model is the same, else defaults (smoothing 1e-3
        rad/s, ...). ``"auto"``: the regression takes each joint's own family and the currents
        then choose each joint's (as the sequential method does; the logs need
        ``actual_current``).
    currents : bool
        Fit the torque constants and friction on the currents (UR5e eqs 17-18) when every log
        has them (default), after the regression; False keeps the model's torque constants
        (and, against ``target_moment``, its friction). Against currents alone they are fitted
        first on the model's links, then again on the identified ones, and every parameter is
        then scaled so that the links' gravity torques match the model's published masses
        (a common scale that currents alone cannot fix, ``fit.scale``).

    Returns
    -------
    IdentificationResult
        ``method = "full"``, ``joints`` of :class:`FullJoint`, ``fit`` a :class:`FullFit`
        (``torque``/``current``/``joint_torque`` are the returned robot's
        :func:`~kinergy.identification.result.validation_metrics` on the same logs).

    Raises
    ------
    KinergyError
        Unknown options; a target signal the logs lack; too few samples for the number of
        parameters; a joint that never moves; link base parameters the logs do not excite; a
        stacked regressor whose condition number exceeds :data:`MAX_CONDITION` (naming the
        weakest parameters).
    """
    if not datas:
        raise KinergyError("no log to identify from")
    parsed_target, parsed_solver = _parsed(target, solver)
    family = friction_option(friction, "friction")
    options = IdentifyOptions(Method.FULL, family, parsed_target, parsed_solver, ridge)
    return full(robot, LogChunks.of(datas), options, currents=currents)


@one_blas_thread
def full(
    robot: Robot,
    logs: LogChunks,
    options: IdentifyOptions | None = None,
    *,
    currents: bool = True,
) -> IdentificationResult:
    """The full method (module docstring) by passes over ``logs``' chunks: the regression's
    rows folded into per-joint triangles, a pass per power-flow iteration, one to evaluate the
    fit, the drives from the currents as the sequential method fits them; as
    :func:`identify_full` with its ``target``, ``solver``, ``ridge`` and ``friction`` from
    ``options``."""
    options = options or IdentifyOptions(Method.FULL)
    target = _pick_target(logs, options.target)
    with_currents = currents and logs.every("current")
    current = CurrentOptions(options.friction)
    if current.auto and not with_currents:
        raise KinergyError(
            "--friction auto chooses each joint's family by its cross-validated current RMS: "
            f"these logs are regressed against {_SIGNAL[target]} with no actual_current in "
            "every log; name a family (--friction viscous_coulomb, ...)",
            Code.UNSUPPORTED,
        )
    start, choice = robot, None
    if with_currents and target == Target.CURRENT:  # drives from the model's links first
        first = drives_from_currents(robot, logs, current)
        start, choice, current = first.robot, first.choice, CurrentOptions()
    base = base_parameters(start)
    reg = _regression(start, base, logs, target, current.family)
    flow, smoothing = fit_power_flow(reg, logs, base.expressions()), Smoothing(None, ())
    if target == Target.TORQUE:  # the friction's smoothing too: its shape is rarely measured
        reg, flow, smoothing = search_smoothing(reg, logs, base.expressions())
    solved = solve(flow.ols, reg.cols.prior, options.solver, options.ridge)
    weak = weak_offsets(reg, logs, flow, solved)
    if weak.size:  # fitted again with the offsets the logs do not determine fixed
        reg = with_fixed(reg, weak)
        flow = fit_power_flow(reg, logs, base.expressions())
        solved = solve(flow.ols, reg.cols.prior, options.solver, options.ridge)
    merging = merged_columns(flow.ols, reg.cols)
    written = write_back(start, base, solved, reg, target == Target.MOMENT, merging.rotor)
    evaluation = _evaluate(reg, logs, flow, solved, written)
    drives = None
    if with_currents:
        drives = drives_from_currents(written.robot, logs, current)
        choice = drives.choice or choice
    out = drives.robot if drives is not None else written.robot
    if with_currents and target == Target.CURRENT:  # the common scale from the published masses
        gravity = scale_row(robot, base, evaluation.q) @ base.project(inertial_parameters(out))
        out = rescaled(out, 1.0 / float(gravity))
    steps = _Steps(reg, flow, solved, merging, written, evaluation, drives, out, choice, smoothing)
    fit = _fit(logs, steps, solver=options.solver, ridge=options.ridge)
    joints = _joints(out, written, solved, reg, drives)
    return IdentificationResult(out, "full", joints, fit)
