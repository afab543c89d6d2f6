"""The coupled-drive nursing arm's identification from logs (nursing doc sections 4.1-4.2).

:func:`identify_nursing` runs the doc's two experiments, each with its own processing, in four
steps:

1. **Friction from runs** (section 4.1, eqs 17-21). Logs in which one joint moves back and forth
   at constant speed (:mod:`kinergy.experiments.friction_runs` designs them) give, per run, the
   joint torques from the currents (eq 21 and the coupling,
   :func:`kinergy.drives.coupled.joint_torques_from_current`) and their odd part over the two
   directions, the friction (eqs 19-20, :mod:`kinergy.identification.friction_points`); per joint a
   Makkar curve (eq 13, joint side) is fitted by particle swarm optimisation or least squares
   (:mod:`kinergy.identification.makkar_fit`).
2. **Per-motor pooling.** Per group of coupled motors one curve, fitted to all its joints'
   points, split onto the motors (:func:`kinergy.drives.coupled.makkar_motor_side`).
3. **Excitation regression** (section 4.2, eqs 22-26). A periodic Fourier excitation (eq 22; the
   doc's Table 6) runs for several periods; the currents are low-pass filtered (Butterworth,
   15 Hz; the doc's "4 dB ripple" cannot apply to a Butterworth filter, which has none) and every
   signal is averaged over the periods (eq 24, :mod:`kinergy.identification.cycles`); the joint torques
   from the currents, less friction and the coupled joints' internal inertia (eq 25), are
   regressed on the minimal (base) parameter set (eq 16) by ridge regression
   (:mod:`kinergy.identification.ridge`), trained on the first 70 % and tested on the last 30 %
   (per-joint RMSE, eq 26, Table 8).
4. **Write-back.** The links with the identified base parameters
   (:func:`kinergy.identification.physical.standard_from_base`); a link that is not physical keeps the
   model's data.

Passes over the logs' chunks (:class:`~kinergy.identification.chunks.LogChunks`): the first finds each
log's moving joints; the filtered, cycle-averaged signals of the excitation logs are folded
chunk by chunk (the zero-phase filter on windows reaching :data:`~kinergy.logs.filtering.FILTER_REACH`
periods of its cutoff into the neighbouring chunks, :func:`~kinergy.identification.chunks.windowed`;
eq 24 as sums per sample of the period, :class:`~kinergy.identification.cycles.CycleAverage`: the same
bits as whole). Three things take a log's samples of a few signals instead, because their maths
needs them all at once: a friction run's odd part pairs each forward sample with the backward
run's torque at the same position (the moving joint's position, torque, commanded speed and
acceleration: 4 numbers a sample); the period of an excitation is the first dip of the
autocorrelation over every shift (its time stamps and commanded positions, 1 + n a sample; none
when ``period`` is given); and an excitation that does not repeat is regressed on its own
samples (its filtered signals, 1 + 4 n a sample: there is nothing to average).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.drives.coupled import (
    joint_friction,
    joint_kind,
    joint_torques_from_current,
    makkar_motor_side,
    motor_share,
)
from kinergy.drives.transmission import reflected_inertia, transmission_matrix
from kinergy.dynamics.regressor import inertial_parameters
from kinergy.errors import KinergyError
from kinergy.friction.makkar import MODEL as MAKKAR
from kinergy.friction.makkar import PARAMETERS as MAKKAR_PARAMETERS
from kinergy.identification.chunks import LogChunks, one_blas_thread, windowed
from kinergy.identification.cycles import CycleAverage, find_period
from kinergy.identification.friction_points import (
    FrictionPoints,
    constant_speed_runs,
    friction_points,
)
from kinergy.identification.makkar_fit import MakkarFit, fit_makkar_lsq, fit_makkar_pso
from kinergy.identification.options import FILTER_CUTOFF, MakkarMethod, NursingOptions
from kinergy.identification.physical import (
    link_consistency,
    link_from_standard,
    parameter_scale,
    standard_from_base,
)
from kinergy.identification.result import (
    DriveEstimate,
    Fit,
    IdentificationResult,
    drive_fields,
    fit_fields,
)
from kinergy.identification.ridge import RidgeFit, ridge_minimal
from kinergy.jsonable import OPTIONAL
from kinergy.logs.filtering import FILTER_REACH, lowpass
from kinergy.logs.prepare import IdentData
from kinergy.messages import Messages
from kinergy.model.robot import Friction, Joint, Link, Robot, Source

__all__ = [
    "FILTER_CUTOFF",
    "BaseParameterValue",
    "ExcitationLog",
    "JointFrictionFit",
    "MotorFrictionFit",
    "NursingFit",
    "NursingJoint",
    "RidgeSummary",
    "identify_nursing",
    "nursing",
]

#: a Makkar fit of joint-side friction points: ``(speeds, friction) -> MakkarFit``
Fitter = Callable[[Array, Array], MakkarFit]


# ---------------------------------------------------------------------------------------------
# Results


@dataclass(frozen=True)
class JointFrictionFit:
    """One joint's Makkar curve (eq 13, joint side) from its runs: ``kind`` pitch, rotation or
    single; ``levels`` speed levels; ``gamma`` (6,); R^2 against the level means (``r2``) and
    every sample's odd part (``r2_samples``); ``error_mean`` the mean even part (N m)."""

    joint: int
    name: str
    kind: str
    levels: int
    gamma: tuple[float, ...]
    r2: float
    r2_samples: float
    error_mean: float


@dataclass(frozen=True)
class MotorFrictionFit:
    """One curve for a group of coupled motors (1-based ``motors``), fitted to the points of all
    its ``joints``: joint-side ``gamma`` (6,) and its R^2."""

    motors: tuple[int, ...]
    joints: tuple[int, ...]
    gamma_joint_side: tuple[float, ...]
    r2: float


@dataclass(frozen=True)
class ExcitationLog:
    """How an excitation log was used: its ``samples``, the current filter's ``cutoff`` (Hz;
    None: not filtered), the ``period`` it was averaged over (s; None: not repeated) and the
    number of ``cycles``."""

    path: str
    samples: int
    cutoff: float | None = field(default=None, metadata=OPTIONAL)
    period: float | None = None
    cycles: int | None = field(default=None, metadata=OPTIONAL)


@dataclass(frozen=True)
class RidgeSummary:
    """The ridge regression of the links (:class:`kinergy.identification.ridge.RidgeFit`) as reported:
    ``alpha``, ``intercept`` (N m), ``condition``, the training share ``split`` and its rows;
    per joint ``rmse_test``, ``rmse_train`` (N m, eq 26), ``r2_test`` and ``torque_std_test``
    (the spread of the regressed torques on the test part, N m, to read the RMSE against); the
    excitation ``logs``."""

    alpha: float
    intercept: float
    condition: float
    split: float
    rows_train: int
    rmse_test: tuple[float, ...]
    rmse_train: tuple[float, ...]
    r2_test: tuple[float, ...]
    torque_std_test: tuple[float, ...]
    logs: tuple[ExcitationLog, ...]


@dataclass(frozen=True)
class BaseParameterValue:
    """One identified base parameter: its expression in standard parameters and its value."""

    name: str
    value: float


@dataclass(frozen=True)
class NursingJoint(DriveEstimate):
    """A joint's drive from the nursing method; ``identified``: its friction came from runs."""

    identified: bool = False


@dataclass(frozen=True)
class NursingFit(Fit):
    """The nursing method's fit: friction per joint run and per motor group, the ridge
    regression of the links and its base parameters, and the links kept from the model
    (1-based)."""

    friction_runs: tuple[JointFrictionFit, ...] = ()
    friction_motors: tuple[MotorFrictionFit, ...] = ()
    ridge: RidgeSummary | None = field(default=None, metadata=OPTIONAL)
    base_parameters: tuple[BaseParameterValue, ...] | None = field(default=None, metadata=OPTIONAL)
    links_kept: tuple[int, ...] | None = field(default=None, metadata=OPTIONAL)


# ---------------------------------------------------------------------------------------------
# 1. Friction from runs


def _moving_joint(peak: Array, still: float = 1e-3, share: float = 0.1) -> int | None:
    """The one joint that moves in a log, else None: its largest |qd_cmd| (``peak``, (n,))
    above ``still`` rad/s and above ``share`` of the fastest joint's (a measured, filtered
    speed is never exactly still)."""
    moving = np.flatnonzero(peak > max(still, share * float(peak.max())))
    return int(moving[0]) if moving.size == 1 else None


def _gathered(logs: LogChunks, take: dict[int, Callable[[IdentData], Array]]) -> dict[int, Array]:
    """One pass: for each segment ``k`` of ``take``, ``take[k]`` of its chunks, joined."""
    parts: dict[int, list[Array]] = {k: [] for k in take}
    for k, chunk in logs.chunks():
        if k in take:  # a copy: a view would keep the whole chunk
            parts[k].append(np.array(take[k](chunk)))
    return {k: np.concatenate(p) for k, p in parts.items()}


def _sort_logs(
    robot: Robot, logs: LogChunks, eta: float, trim: int
) -> tuple[dict[int, list[FrictionPoints]], list[int]]:
    """The friction points of every friction run, by joint, and the other (excitation) logs."""
    moving = {k: _moving_joint(s.peak_cmd) for k, s in enumerate(logs.summaries)}

    def run(j: int) -> Callable[[IdentData], Array]:
        def columns(d: IdentData) -> Array:
            assert d.current is not None
            tau = joint_torques_from_current(robot, d.current, eta=eta)[:, j]
            return np.column_stack([d.qd_cmd[:, j], d.qdd_cmd[:, j], d.q[:, j], tau])

        return columns

    signals = _gathered(logs, {k: run(j) for k, j in moving.items() if j is not None})
    runs: dict[int, list[FrictionPoints]] = {}
    excitation: list[int] = []
    for k, j in moving.items():
        if j is None:
            excitation.append(k)
            continue
        qd_cmd, qdd_cmd, q, tau = signals.pop(k).T
        speeds, fwd, bwd = constant_speed_runs(qd_cmd, qdd_cmd)
        if speeds.size == 0:
            excitation.append(k)
            continue
        runs.setdefault(j, []).append(friction_points(q, tau, speeds, fwd, bwd, joint=j, trim=trim))
    return runs, excitation


def _joint_fits(
    robot: Robot, runs: dict[int, list[FrictionPoints]], fitter: Fitter, said: Messages
) -> tuple[list[JointFrictionFit], dict[int, tuple[Array, Array, MakkarFit]]]:
    """Per joint with runs, its Makkar curve (eq 13, joint side) from the level means; and the
    points and fit of each, for pooling per motor group."""
    fits: list[JointFrictionFit] = []
    pooled: dict[int, tuple[Array, Array, MakkarFit]] = {}
    for j in sorted(runs):
        pts = runs[j]
        v = np.concatenate([p.speeds for p in pts])
        f = np.concatenate([p.friction for p in pts])
        if v.size < 6:
            said.note(
                f"joint {j + 1} ({robot.joints[j].name}): {v.size} speed levels, Makkar's model "
                "needs at least 6; its motors keep the model's friction"
            )
            continue
        mf = fitter(v, f)
        r2_samples = mf.r2_against(
            np.concatenate([p.sample_speeds for p in pts]),
            np.concatenate([p.sample_friction for p in pts]),
        )
        fits.append(
            JointFrictionFit(
                joint=j + 1,
                name=robot.joints[j].name,
                kind=joint_kind(robot, j),
                levels=int(v.size),
                gamma=tuple(mf.gamma.tolist()),
                r2=mf.r2,
                r2_samples=r2_samples,
                error_mean=float(np.mean(np.concatenate([p.error for p in pts]))),
            )
        )
        pooled[j] = (v, f, mf)
    return fits, pooled


# ---------------------------------------------------------------------------------------------
# 2. Per-motor pooling


def _motor_group(robot: Robot, j: int, fitted: Sequence[int]) -> list[int]:
    """The fitted joints that move exactly joint ``j``'s motors at its ratio (``[j]`` when one
    of them turns them at another ratio)."""
    n_mat = transmission_matrix(robot)
    ratio, k, motors = motor_share(robot, j)
    group = [jj for jj in fitted if set(np.flatnonzero(np.abs(n_mat[:, jj]) > 0)) == set(motors)]
    shares = [motor_share(robot, jj)[:2] for jj in group]
    if any(not np.isclose(r, ratio) or kk != k for r, kk in shares):
        return [j]
    return group


def _motor_friction(motor: Joint, gamma_motor: Array) -> Friction:
    """Makkar's friction with ``gamma_motor`` (motor side), keeping the motor's standstill
    options."""
    old = motor.drive.friction.params
    params = {name: float(x) for name, x in zip(MAKKAR_PARAMETERS, gamma_motor, strict=True)}
    params.update({key: old[key] for key in ("standstill", "holding") if key in old})
    return Friction(MAKKAR, params)


def _motor_fits(
    robot: Robot, pooled: dict[int, tuple[Array, Array, MakkarFit]], fitter: Fitter
) -> tuple[dict[int, Friction], list[MotorFrictionFit]]:
    """Per group of coupled motors one curve from all its joints' points, on the motor side."""
    new_friction: dict[int, Friction] = {}
    motor_fits: list[MotorFrictionFit] = []
    done: set[int] = set()
    for j in sorted(pooled):
        if j in done:
            continue
        group = _motor_group(robot, j, sorted(pooled))
        done.update(group)
        if len(group) == 1:
            mf = pooled[j][2]
        else:
            mf = fitter(
                np.concatenate([pooled[jj][0] for jj in group]),
                np.concatenate([pooled[jj][1] for jj in group]),
            )
        ratio, k, motors = motor_share(robot, j)
        g_motor = makkar_motor_side(mf.gamma, ratio, k)
        for m in motors:
            new_friction[int(m)] = _motor_friction(robot.joints[m], g_motor)
        motor_fits.append(
            MotorFrictionFit(
                motors=tuple(int(m) + 1 for m in motors),
                joints=tuple(jj + 1 for jj in group),
                gamma_joint_side=tuple(mf.gamma.tolist()),
                r2=mf.r2,
            )
        )
    return new_friction, motor_fits


def _with_friction(robot: Robot, new_friction: dict[int, Friction], said: Messages) -> Robot:
    """``robot`` with the identified motors' friction; a note for every other motor."""
    joints = []
    for m, jt in enumerate(robot.joints):
        if m in new_friction:
            drive = dataclasses.replace(jt.drive, friction=new_friction[m])
            joints.append(dataclasses.replace(jt, drive=drive))
        else:
            said.note(f"motor {m + 1} ({jt.name}): no friction run; kept the model's friction")
            joints.append(jt)
    return robot.with_joints(joints)


# ---------------------------------------------------------------------------------------------
# 3. Excitation regression


def _excitation_arrays(
    robot: Robot, logs: LogChunks, excitation: list[int], options: NursingOptions
) -> tuple[list[dict[str, Array]], list[ExcitationLog]]:
    """Each excitation log's motion and currents, filtered (Butterworth) and cycle-averaged
    (eq 24), and the joint torques from the currents; folded in one pass (module docstring)."""
    n = robot.n
    need_q = options.period is None
    stamps = _gathered(
        logs,
        {
            k: (lambda d: np.column_stack([d.t, d.q_cmd])) if need_q else (lambda d: d.t[:, None])
            for k in excitation
        },
    )
    averages: dict[int, CycleAverage] = {}
    whole: dict[int, list[dict[str, Array]]] = {}
    notes: dict[int, ExcitationLog] = {}
    rate: dict[int, float] = {}
    reach = 2
    for k in excitation:
        t = stamps[k][:, 0]
        dt = float(t[1] - t[0])
        rate[k] = 1.0 / dt
        cutoff = options.cutoff
        used = cutoff if cutoff is not None and cutoff < 0.5 / dt else None
        if used is not None:
            reach = max(reach, int(np.ceil(FILTER_REACH / (used * dt))) + 2)
        found = options.period if not need_q else find_period(t, stamps[k][:, 1 : 1 + n])
        cycles = None
        if found is not None and (t[-1] - t[0]) >= 2 * found - 1.5 * dt:
            averages[k] = CycleAverage(t, found)
            cycles = int(np.floor((t[-1] - t[0] + dt) / found + 1e-9))
        else:
            whole[k], found = [], None
        notes[k] = ExcitationLog(logs.segments[k].path, t.size, used, found, cycles)
    chunks = ((k, c) for k, c in logs.chunks() if k in notes)
    for k, chunk, window, at in windowed(chunks, reach):
        assert window.current is not None
        current = window.current[at : at + len(chunk)]
        used = notes[k].cutoff
        if used is not None:
            filtered = lowpass(window.current, rate[k], used)
            current = filtered[at : at + len(chunk)]
        signals = {"q": chunk.q, "qd": chunk.qd, "qdd": chunk.qdd, "current": current}
        if k in averages:
            averages[k].add(signals)
        else:  # copies: views would keep the whole chunks
            whole[k].append({name: np.array(x) for name, x in signals.items()})
    parts = []
    for k in excitation:
        if k in averages:
            _, signals = averages[k].result()
        else:
            signals = {name: np.concatenate([p[name] for p in whole[k]]) for name in whole[k][0]}
        signals["tau"] = joint_torques_from_current(robot, signals["current"], eta=options.eta)
        parts.append(signals)
    return parts, [notes[k] for k in excitation]


def _regress_links(
    robot: Robot, logs: LogChunks, excitation: list[int], options: NursingOptions
) -> tuple[RidgeFit, RidgeSummary]:
    """Joint torques less friction and drive inertia (eq 25) regressed on the minimal set."""
    parts, notes = _excitation_arrays(robot, logs, excitation, options)
    q, qd, qdd, tau = (np.vstack([p[key] for p in parts]) for key in ("q", "qd", "qdd", "tau"))
    tau_links = tau - joint_friction(robot, qd) - qdd @ reflected_inertia(robot).T
    rf = ridge_minimal(robot, q, qd, qdd, tau_links, split=options.split, alphas=options.alphas)
    test = tau_links[rf.split :] if rf.split < len(tau_links) else tau_links
    summary = RidgeSummary(
        alpha=rf.alpha,
        intercept=rf.intercept,
        condition=rf.condition,
        split=options.split,
        rows_train=rf.split,
        rmse_test=tuple(rf.rmse_test.tolist()),
        rmse_train=tuple(rf.rmse_train.tolist()),
        r2_test=tuple(rf.r2_test.tolist()),
        torque_std_test=tuple(np.std(test, axis=0).tolist()),
        logs=tuple(notes),
    )
    return rf, summary


# ---------------------------------------------------------------------------------------------
# 4. Write-back


def _identified_link(j: int, joint: Joint, standard: Array, said: Messages) -> Joint:
    """Joint ``j`` (0-based) with the link of the standard parameters (10,), or as it was when
    they do not make a valid link (with a warning)."""
    mass, com, i_c = link_from_standard(standard)
    inertia = np.array([i_c[0, 0], i_c[1, 1], i_c[2, 2], i_c[0, 1], i_c[1, 2], i_c[0, 2]])
    try:
        link = Link(mass=mass, com=com, inertia=inertia)
    except KinergyError as err:
        said.warn(f"link {j + 1} ({joint.name}): {err}; kept the model's link data")
        return joint
    return dataclasses.replace(joint, link=link)


def _write_links(robot: Robot, rf: RidgeFit, said: Messages) -> tuple[Robot, tuple[int, ...]]:
    """Links with the identified base parameters: the standard parameters closest to the model's
    (:func:`kinergy.identification.physical.standard_from_base`); a link that is not physical keeps the
    model's data, with a warning. Returns the robot and the kept links (1-based)."""
    pi0 = inertial_parameters(robot)
    payload = pi0 - inertial_parameters(robot, include_payload=False)
    pi = standard_from_base(rf.base, rf.coef, pi0, scale=parameter_scale(robot))
    links = (pi - payload).reshape(-1, 10)
    problems = link_consistency(pi - payload)
    joints = []
    for j, (jt, row, problem) in enumerate(zip(robot.joints, links, problems, strict=True)):
        if problem is not None:
            said.warn(f"link {j + 1} ({jt.name}): {problem}; kept the model's link data")
            joints.append(jt)
        else:
            joints.append(_identified_link(j, jt, row, said))
    kept = tuple(j + 1 for j, p in enumerate(problems) if p is not None)
    return robot.with_joints(joints), kept


# ---------------------------------------------------------------------------------------------
# The whole procedure


def _check_inputs(logs: LogChunks) -> None:
    for segment, summary in zip(logs.segments, logs.summaries, strict=True):
        if "current" not in summary.has:
            raise KinergyError(f"{segment.path}: the nursing method needs actual_current")


def _fitter(fit: MakkarMethod, seed: int) -> Fitter:
    """The Makkar fit ``fit`` names: :func:`fit_makkar_pso` (seeded) or :func:`fit_makkar_lsq`."""
    if fit == MakkarMethod.PSO:
        return lambda v, f: fit_makkar_pso(v, f, rng=seed)
    return fit_makkar_lsq


def _sources(robot: Robot, friction: bool, links: bool) -> Robot:
    """``robot`` with the identified categories' sources."""
    sources = dict(robot.sources)
    if friction:
        sources["friction"] = Source("identified", "kinergy identify (nursing, eqs 13, 17-21)")
    if links:
        for cat in ("mass", "com", "inertia"):
            sources[cat] = Source("identified", "kinergy identify (nursing, eqs 16, 22-26, ridge)")
    return dataclasses.replace(robot, sources=sources)


def _drive_estimates(robot: Robot, identified: set[int]) -> tuple[NursingJoint, ...]:
    return tuple(
        NursingJoint(**drive_fields(jt), identified=m in identified)
        for m, jt in enumerate(robot.joints)
    )


def _base_values(rf: RidgeFit) -> tuple[BaseParameterValue, ...]:
    return tuple(
        BaseParameterValue(name, float(x))
        for name, x in zip(rf.base.expressions(), rf.coef, strict=True)
    )


def identify_nursing(
    robot: Robot,
    datas: Sequence[IdentData],
    *,
    eta: float = 1.0,
    fit: MakkarMethod | str = MakkarMethod.LSQ,
    period: float | None = None,
    cutoff: float | None = FILTER_CUTOFF,
    split: float = 0.7,
    alphas: ArrayLike | None = None,
    trim: int = 10,
    seed: int = 0,
) -> IdentificationResult:
    """:func:`nursing` on prepared logs held in memory (each one chunk), its options
    (:class:`~kinergy.identification.options.NursingOptions`) as keywords."""
    try:
        method = MakkarMethod(fit)
    except ValueError:
        raise KinergyError(f"unknown Makkar fit {fit!r} (known: lsq, pso)") from None
    candidates = None if alphas is None else tuple(np.asarray(alphas, dtype=float).ravel())
    options = NursingOptions(eta, method, period, cutoff, split, candidates, trim, seed)
    return nursing(robot, LogChunks.of(datas), options)


@one_blas_thread
def nursing(
    robot: Robot, logs: LogChunks, options: NursingOptions | None = None
) -> IdentificationResult:
    """The nursing doc's identification (sections 4.1-4.2) from prepared logs.

    The four steps of the module docstring. Logs in which one joint moves (the others below a
    tenth of its peak speed) at back-and-forth constant speeds are friction runs; motors without
    runs keep the model's friction. The other (excitation) logs are low-pass filtered
    (``options.cutoff`` Hz; None: not filtered), each averaged over its periods
    (``options.period`` s, else :func:`find_period`) and joined in order; the first
    ``options.split`` in time trains the ridge regression on the weights ``options.alphas``
    (:func:`~kinergy.identification.ridge.ridge_minimal`); Makkar's curves are fitted as
    ``options.fit`` says (:func:`fit_makkar_lsq`, or :func:`fit_makkar_pso` seeded by
    ``options.seed``) to runs trimmed by ``options.trim`` samples, the currents converted with
    eq 21's efficiency ``options.eta``.

    Returns
    -------
    IdentificationResult
        ``method = "nursing"``, with a :class:`NursingFit`: ``torque`` and ``current`` are the
        returned robot's :func:`kinergy.identification.result.validation_metrics` on all logs.

    Raises
    ------
    KinergyError
        A log without ``actual_current``.
    """
    options = options or NursingOptions()
    _check_inputs(logs)
    said = Messages()
    fitter = _fitter(options.fit, options.seed)
    runs, excitation = _sort_logs(robot, logs, options.eta, options.trim)
    joint_fits, pooled = _joint_fits(robot, runs, fitter, said)
    new_friction, motor_fits = _motor_fits(robot, pooled, fitter)
    staged = _with_friction(robot, new_friction, said)
    identified, rf, summary, kept = staged, None, None, None
    if excitation:
        rf, summary = _regress_links(staged, logs, excitation, options)
        identified, kept = _write_links(staged, rf, said)
    else:
        said.note("no excitation log (every log moves one joint): link data kept from the model")
    links = kept is not None and len(kept) < robot.n
    identified = _sources(identified, friction=bool(new_friction), links=links)
    fit_out = NursingFit(
        **vars(fit_fields(identified, logs, said)),
        friction_runs=tuple(joint_fits),
        friction_motors=tuple(motor_fits),
        ridge=summary,
        base_parameters=None if rf is None else _base_values(rf),
        links_kept=kept,
    )
    joints = _drive_estimates(identified, set(new_friction))
    return IdentificationResult(identified, "nursing", joints, fit_out)
