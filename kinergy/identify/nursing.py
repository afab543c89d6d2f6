"""The coupled-drive nursing arm's identification from logs (nursing doc sections 4.1-4.2).

:func:`identify_nursing` runs the doc's two experiments, each with its own processing, in four
steps:

1. **Friction from runs** (section 4.1, eqs 17-21). Logs in which one joint moves back and forth
   at constant speed (:mod:`kinergy.experiments.friction_runs` designs them) give, per run, the
   joint torques from the currents (eq 21 and the coupling,
   :func:`kinergy.drives.coupled.joint_torques_from_current`) and their odd part over the two
   directions, the friction (eqs 19-20, :mod:`kinergy.identify.friction_points`); per joint a
   Makkar curve (eq 13, joint side) is fitted by particle swarm optimisation or least squares
   (:mod:`kinergy.identify.makkar_fit`).
2. **Per-motor pooling.** Per group of coupled motors one curve, fitted to all its joints'
   points, split onto the motors (:func:`kinergy.drives.coupled.makkar_motor_side`).
3. **Excitation regression** (section 4.2, eqs 22-26). A periodic Fourier excitation (eq 22; the
   doc's Table 6) runs for several periods; the currents are low-pass filtered (Butterworth,
   15 Hz; the doc's "4 dB ripple" cannot apply to a Butterworth filter, which has none) and every
   signal is averaged over the periods (eq 24, :mod:`kinergy.identify.cycles`); the joint torques
   from the currents, less friction and the coupled joints' internal inertia (eq 25), are
   regressed on the minimal (base) parameter set (eq 16) by ridge regression
   (:mod:`kinergy.identify.ridge`), trained on the first 70 % and tested on the last 30 %
   (per-joint RMSE, eq 26, Table 8).
4. **Write-back.** The links with the identified base parameters
   (:func:`kinergy.identify.physical.standard_from_base`); a link that is not physical keeps the
   model's data.
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
from kinergy.friction.makkar import PARAMETERS as MAKKAR_PARAMETERS
from kinergy.identify.chunks import LogChunks
from kinergy.identify.cycles import cycle_average, find_period
from kinergy.identify.friction_points import FrictionPoints, constant_speed_runs, friction_points
from kinergy.identify.makkar_fit import MakkarFit, fit_makkar_lsq, fit_makkar_pso
from kinergy.identify.physical import (
    link_consistency,
    link_from_standard,
    parameter_scale,
    standard_from_base,
)
from kinergy.identify.result import (
    DriveEstimate,
    Fit,
    IdentificationResult,
    drive_fields,
    fit_fields,
)
from kinergy.identify.ridge import RidgeFit, ridge_minimal
from kinergy.jsonable import OPTIONAL
from kinergy.logs.prepare import IdentData, lowpass
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
]

#: a Makkar fit of joint-side friction points: ``(speeds, friction) -> MakkarFit``
Fitter = Callable[[Array, Array], MakkarFit]

#: the doc's low-pass cutoff for the motor currents, Hz
FILTER_CUTOFF = 15.0


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
    """The ridge regression of the links (:class:`kinergy.identify.ridge.RidgeFit`) as reported:
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


def _moving_joint(data: IdentData, still: float = 1e-3, share: float = 0.1) -> int | None:
    """The one joint that moves in a log, else None: max |qd_cmd| above ``still`` rad/s and above
    ``share`` of the fastest joint's (a measured, filtered speed is never exactly still)."""
    peak = np.max(np.abs(data.qd_cmd), axis=0)
    moving = np.flatnonzero(peak > max(still, share * float(peak.max())))
    return int(moving[0]) if moving.size == 1 else None


def _sort_logs(
    robot: Robot, datas: Sequence[IdentData], eta: float, trim: int
) -> tuple[dict[int, list[FrictionPoints]], list[IdentData]]:
    """The friction points of every friction run, by joint, and the other (excitation) logs."""
    runs: dict[int, list[FrictionPoints]] = {}
    excitation: list[IdentData] = []
    for d in datas:
        j = _moving_joint(d)
        if j is None:
            excitation.append(d)
            continue
        speeds, fwd, bwd = constant_speed_runs(d.qd_cmd[:, j], d.qdd_cmd[:, j])
        if speeds.size == 0:
            excitation.append(d)
            continue
        assert d.current is not None
        tau = joint_torques_from_current(robot, d.current, eta=eta)
        runs.setdefault(j, []).append(
            friction_points(d.q[:, j], tau[:, j], speeds, fwd, bwd, joint=j, trim=trim)
        )
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
    return Friction("makkar", params)


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
    robot: Robot, data: IdentData, *, eta: float, period: float | None, cutoff: float | None
) -> tuple[dict[str, Array], ExcitationLog]:
    """Filtered (Butterworth), cycle-averaged (eq 24) motion and joint torques from currents."""
    assert data.current is not None
    current = data.current
    fs = 1.0 / data.dt
    used_cutoff = None
    if cutoff is not None and cutoff < fs / 2.0:
        current = lowpass(current, fs, cutoff)
        used_cutoff = cutoff
    found = period if period is not None else find_period(data.t, data.q_cmd)
    signals = {"q": data.q, "qd": data.qd, "qdd": data.qdd, "current": current}
    averaged, cycles = None, None
    if found is not None and (data.t[-1] - data.t[0]) >= 2 * found - 1.5 * data.dt:
        _, signals = cycle_average(data.t, signals, found)
        averaged = found
        cycles = int(np.floor((data.t[-1] - data.t[0] + data.dt) / found + 1e-9))
    signals["tau"] = joint_torques_from_current(robot, signals["current"], eta=eta)
    return signals, ExcitationLog(data.path, len(data), used_cutoff, averaged, cycles)


def _regress_links(
    robot: Robot,
    excitation: Sequence[IdentData],
    *,
    eta: float,
    period: float | None,
    cutoff: float | None,
    split: float,
    alphas: ArrayLike | None,
) -> tuple[RidgeFit, RidgeSummary]:
    """Joint torques less friction and drive inertia (eq 25) regressed on the minimal set."""
    parts, notes = [], []
    for d in excitation:
        sig, note = _excitation_arrays(robot, d, eta=eta, period=period, cutoff=cutoff)
        parts.append(sig)
        notes.append(note)
    q, qd, qdd, tau = (np.vstack([p[key] for p in parts]) for key in ("q", "qd", "qdd", "tau"))
    tau_links = tau - joint_friction(robot, qd) - qdd @ reflected_inertia(robot).T
    rf = ridge_minimal(robot, q, qd, qdd, tau_links, split=split, alphas=alphas)
    test = tau_links[rf.split :] if rf.split < len(tau_links) else tau_links
    summary = RidgeSummary(
        alpha=rf.alpha,
        intercept=rf.intercept,
        condition=rf.condition,
        split=split,
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
    (:func:`kinergy.identify.physical.standard_from_base`); a link that is not physical keeps the
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


def _check_inputs(logs: LogChunks, fit: str) -> None:
    if fit not in ("lsq", "pso"):
        raise KinergyError(f"unknown Makkar fit {fit!r} (known: lsq, pso)")
    for segment, summary in zip(logs.segments, logs.summaries, strict=True):
        if "current" not in summary.has:
            raise KinergyError(f"{segment.path}: the nursing method needs actual_current")


def _fitter(fit: str, seed: int) -> Fitter:
    """The Makkar fit ``fit`` names: :func:`fit_makkar_pso` (seeded) or :func:`fit_makkar_lsq`."""
    if fit == "pso":
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
    fit: str = "lsq",
    period: float | None = None,
    cutoff: float | None = FILTER_CUTOFF,
    split: float = 0.7,
    alphas: ArrayLike | None = None,
    trim: int = 10,
    seed: int = 0,
) -> IdentificationResult:
    """:func:`nursing` on prepared logs held in memory (each one chunk)."""
    options = dict(eta=eta, fit=fit, period=period, cutoff=cutoff, split=split)
    return nursing(robot, LogChunks.of(datas), alphas=alphas, trim=trim, seed=seed, **options)  # type: ignore[arg-type]


def nursing(
    robot: Robot,
    logs: LogChunks,
    *,
    eta: float = 1.0,
    fit: str = "lsq",
    period: float | None = None,
    cutoff: float | None = FILTER_CUTOFF,
    split: float = 0.7,
    alphas: ArrayLike | None = None,
    trim: int = 10,
    seed: int = 0,
) -> IdentificationResult:
    """The nursing doc's identification (sections 4.1-4.2) from prepared logs.

    The four steps of the module docstring. Logs in which one joint moves (the others below a
    tenth of its peak speed) at back-and-forth constant speeds are friction runs; motors without
    runs keep the model's friction. The other (excitation) logs are low-pass filtered (``cutoff``
    Hz; None: not filtered), each averaged over its periods (``period`` s, else
    :func:`find_period`) and joined in order; the first ``split`` in time trains the ridge
    regression on the weights ``alphas`` (:func:`~kinergy.identify.ridge.ridge_minimal`).

    Parameters
    ----------
    robot : Robot
        The starting model (kinematics, coupling, gear ratios, torque constants, rotor inertias).
    logs : LogChunks
        Prepared logs with ``actual_current``.
    eta : float
        Eq 21's efficiency (the twin: 1; the doc's robot: 0.82).
    fit : {"lsq", "pso"}
        Makkar fit: :func:`fit_makkar_lsq` or :func:`fit_makkar_pso` (seeded by ``seed``).
    trim : int
        Samples dropped at each end of a constant-speed run.

    Returns
    -------
    IdentificationResult
        ``method = "nursing"``, with a :class:`NursingFit`: ``torque`` and ``current`` are the
        returned robot's :func:`kinergy.identify.result.validation_metrics` on all logs.

    Raises
    ------
    KinergyError
        No logs, a log without ``actual_current``, an unknown ``fit``.
    """
    _check_inputs(logs, fit)
    datas = _whole(logs)
    said = Messages()
    fitter = _fitter(fit, seed)
    runs, excitation = _sort_logs(robot, datas, eta, trim)
    joint_fits, pooled = _joint_fits(robot, runs, fitter, said)
    new_friction, motor_fits = _motor_fits(robot, pooled, fitter)
    staged = _with_friction(robot, new_friction, said)
    identified, rf, summary, kept = staged, None, None, None
    if excitation:
        rf, summary = _regress_links(
            staged, excitation, eta=eta, period=period, cutoff=cutoff, split=split, alphas=alphas
        )
        identified, kept = _write_links(staged, rf, said)
    else:
        said.note("no excitation log (every log moves one joint): link data kept from the model")
    links = kept is not None and len(kept) < robot.n
    identified = _sources(identified, friction=bool(new_friction), links=links)
    fit_out = NursingFit(
        **fit_fields(identified, logs, said),
        friction_runs=tuple(joint_fits),
        friction_motors=tuple(motor_fits),
        ridge=summary,
        base_parameters=None if rf is None else _base_values(rf),
        links_kept=kept,
    )
    joints = _drive_estimates(identified, set(new_friction))
    return IdentificationResult(identified, "nursing", joints, fit_out)


def _whole(logs: LogChunks) -> list[IdentData]:
    """Each segment's chunks joined."""
    parts: list[list[IdentData]] = [[] for _ in logs.segments]
    for k, chunk in logs.chunks():
        parts[k].append(chunk)
    return [IdentData.joined(p) for p in parts]
