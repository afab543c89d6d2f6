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
and its current keeps part of the friction of the direction it stopped in. With
``Hold.SEARCH`` each joint's fit is made holding 0, 25, 50, 75 and 100 % of its friction through
standstill (the ``standstill`` and ``holding`` friction parameters) and keeps the best.

Every step is a fold over the logs' prepared chunks (:mod:`kinergy.identification.chunks`): step 2's
triangle in one pass, step 3's trials in one pass per batch (:mod:`kinergy.identification.drive_steps`),
the fit statistics in one more; logs held in memory are one chunk each.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.identification.chunks import STILL_SPEED, LogChunks, Summary, one_blas_thread
from kinergy.identification.drive_steps import (
    AUTO_CANDIDATES,
    CurrentStats,
    FrictionChoice,
    current_step,
    joined,
    rotor_problem,
    rotor_step,
    with_rotor_inertias,
)
from kinergy.identification.options import CurrentOptions, FrictionOption, Hold, friction_option
from kinergy.identification.result import (
    AT_BOUND,
    IDENTIFIED,
    KEPT,
    DriveEstimate,
    Fit,
    Flag,
    IdentificationResult,
    drive_fields,
    fit_fields,
)
from kinergy.identification.uncertainty import jackknife_uncertainty
from kinergy.jsonable import OPTIONAL
from kinergy.logs.prepare import IdentData
from kinergy.messages import Messages
from kinergy.model.robot import Joint, Robot, Source

__all__ = [
    "AUTO_CANDIDATES",
    "DrivesFromCurrents",
    "FrictionChoice",
    "SequentialFit",
    "SequentialJoint",
    "drives_from_currents",
    "identify_sequential",
    "motion_problems",
    "sequential",
]


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


def motion_problems(robot: Robot, summary: Summary) -> dict[int, str]:
    """What the logs cannot identify, per joint (index -> reason), from the summary of their
    real joint speeds.

    Raises
    ------
    KinergyError
        Too few samples, or no joint identifiable: one line naming every joint and why.
    """
    if summary.samples < 50:
        raise KinergyError(
            f"cannot identify from these logs: only {summary.samples} samples (need at least 50)"
        )
    problems: dict[int, str] = {}
    for j, joint in enumerate(robot.joints):
        if summary.peak[j] < 10 * STILL_SPEED:
            problems[j] = (
                f"joint {j + 1} ({joint.name}) never moves (max |qd| {summary.peak[j]:.3g} rad/s): "
                "its rotor inertia, torque constant and friction cannot be identified"
            )
        elif summary.forward[j] < 10 or summary.backward[j] < 10:
            problems[j] = (
                f"joint {j + 1} ({joint.name}) never reverses: Coulomb friction in one direction "
                "and the torque constant cannot be separated"
            )
    if len(problems) == robot.n:
        raise KinergyError("cannot identify from these logs: " + "; ".join(problems.values()))
    return problems


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


def _drive_flags(
    joint: Joint, identified_rotor: float, rotor_std: float, stats: CurrentStats
) -> tuple[dict[str, Flag], dict[str, float | None]]:
    """Flags and standard errors of one joint's rotor inertia, torque constant and friction."""
    if np.isnan(rotor_std):
        rotor_flag = KEPT
    elif identified_rotor < joint.drive.reducer_inertia:
        rotor_flag = AT_BOUND  # motor inertia held at 0
    else:
        rotor_flag = IDENTIFIED
    names = joint.drive.friction.model.linear
    flags = {"rotor_inertia": rotor_flag, "torque_constant": KEPT, **dict.fromkeys(names, KEPT)}
    flags.update(stats.flags)
    fitted = stats.flags.get("torque_constant") == IDENTIFIED
    std: dict[str, float | None] = {
        "rotor_inertia": None if np.isnan(rotor_std) else float(rotor_std),
        "torque_constant": stats.torque_constant_std if fitted else None,
    }
    std.update({name: (stats.friction_std or {}).get(name) for name in names})
    return flags, std


def _joints(
    identified: Robot,
    rotor: tuple[Array, Array],
    problems: dict[int, str],
    stats: Sequence[CurrentStats],
) -> tuple[SequentialJoint, ...]:
    """Per joint: the identified drive with ``rotor`` = (inertias, standard errors)."""
    inertia, std = rotor
    out = []
    for j, joint in enumerate(identified.joints):
        flags, errors = _drive_flags(joint, float(inertia[j]), float(std[j]), stats[j])
        fields = {k: v for k, v in vars(stats[j]).items() if k not in ("flags", "replicates")}
        out.append(
            SequentialJoint(
                **drive_fields(joint),
                rotor_inertia_std=None if np.isnan(std[j]) else float(std[j]),
                flags=flags,
                std=errors,
                identified=j not in problems,
                problem=problems.get(j),
                **fields,
            )
        )
    return tuple(out)


def identify_sequential(
    robot: Robot,
    datas: Sequence[IdentData],
    *,
    friction: FrictionOption | str = None,
    hold: Hold = Hold.SEARCH,
) -> IdentificationResult:
    """Identify rotor inertias, torque constants and friction with the UR5e doc's procedure:
    :func:`sequential` on prepared logs held in memory (each one chunk).

    Parameters
    ----------
    robot : Robot
        The starting model: its link data are kept.
    datas : sequence of IdentData
        Prepared logs (:func:`kinergy.logs.prepare.prepare`). Rotor inertias need
        ``target_moment``; torque constants and friction need ``actual_current``.
    friction : FrictionModel or str, optional
        Friction model for every joint, or its name (default: each joint's model in ``robot``);
        it must be linear in its parameters (all of kinergy's are, given their shape parameters).
        ``"auto"`` (:data:`~kinergy.identification.options.AUTO`): per joint, the model of :data:`AUTO_CANDIDATES` the logs support with the
        lowest cross-validated current RMS (``fit.friction_choice`` says which won, by how much).
    hold : Hold
        Hold friction through standstill (see the module docstring).

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
    options = CurrentOptions(friction_option(friction), hold)  # the family resolved, once
    return sequential(robot, LogChunks.of(datas), options)


@one_blas_thread
def sequential(
    robot: Robot, logs: LogChunks, options: CurrentOptions | None = None
) -> IdentificationResult:
    """The sequential identification (module docstring) by passes over ``logs``' chunks; as
    :func:`identify_sequential`, ``options`` saying how step 3 fits the currents."""
    options = options or CurrentOptions()
    rotor_pieces = rotor_problem(robot, logs)  # the first pass, when none was made yet
    rotor_triangle = None if rotor_pieces is None else joined(rotor_pieces)
    problems = motion_problems(robot, logs.summary())
    said = Messages([f"{text}; kept the model's values" for text in problems.values()])
    has_ref, has_current = logs.any("tau_ref"), logs.any("current")
    if not (has_ref or has_current):
        torques = logs.any("torque")
        raise KinergyError(
            "the sequential method needs target_moment (rotor inertia) or actual_current (torque "
            "constant and friction); the logs have neither"
            + (
                ", but they have measured joint torques: use --method full --target torque"
                if torques
                else ""
            )
        )
    active = [j for j in range(robot.n) if j not in problems]
    rotor, rotor_std, cond = rotor_step(robot, rotor_triangle, active, said)
    staged = with_rotor_inertias(robot, rotor, said)
    stats: list[CurrentStats] = [CurrentStats() for _ in range(robot.n)]
    held = choices = None
    if has_current:
        staged, stats, held, choices = current_step(staged, rotor, logs, problems, options, said)
    else:
        said.note(
            "the logs have no actual_current: torque constants and friction kept from the model"
        )
    sources = _sources(staged, has_ref, has_current)
    identified = dataclasses.replace(staged, sources=sources)
    fit = SequentialFit(
        **vars(fit_fields(identified, logs, said)),
        condition_rotor_inertia=cond,
        friction_holding=held,
        friction_choice=choices if options.auto else None,
    )
    joints = _joints(identified, (rotor, rotor_std), problems, stats)
    errors = None
    if options.errors:
        flags = [j.flags for j in joints]
        errors = jackknife_uncertainty(identified, rotor_pieces, flags, stats)
    identified = dataclasses.replace(identified, uncertainty=errors)
    return IdentificationResult(identified, "sequential", joints, fit)


@dataclass(frozen=True, eq=False)
class DrivesFromCurrents:
    """Step 3 on its own (:func:`drives_from_currents`): the robot with the torque constants and
    friction the currents give, per joint the flags and standard errors of those parameters
    (:class:`~kinergy.identification.result.DriveEstimate`), the friction fraction held through
    standstill (None where not fitted), what the fit said (:class:`~kinergy.messages.Messages`)
    and, with ``friction="auto"``, how each joint's family was chosen."""

    robot: Robot
    flags: tuple[dict[str, Flag], ...]
    std: tuple[dict[str, float | None], ...]
    holding: tuple[float | None, ...]
    said: Messages
    choice: tuple[FrictionChoice | None, ...] | None = None


@one_blas_thread
def drives_from_currents(
    robot: Robot, logs: LogChunks, options: CurrentOptions | None = None
) -> DrivesFromCurrents:
    """Torque constants and friction of every motor from ``actual_current`` (UR5e eqs 17-18),
    ``robot``'s links and rotor inertias taken as they are (the full method's drives).

    Raises
    ------
    KinergyError
        As :func:`identify_sequential`: too few samples, no joint that moves, a singular
        current regression.
    """
    problems = motion_problems(robot, logs.summary())
    said = Messages(
        [f"{text}; kept the model's torque constant and friction" for text in problems.values()]
    )
    rotor = np.array([j.drive.rotor_inertia for j in robot.joints])
    options = options or CurrentOptions()
    out, stats, held, chosen = current_step(robot, rotor, logs, problems, options, said)
    flags, std = [], []
    for joint, stat in zip(out.joints, stats, strict=True):
        f, s = _drive_flags(joint, float(joint.drive.rotor_inertia), np.nan, stat)
        flags.append({k: v for k, v in f.items() if k != "rotor_inertia"})
        std.append({k: v for k, v in s.items() if k != "rotor_inertia"})
    choice = chosen if options.auto else None
    return DrivesFromCurrents(out, tuple(flags), tuple(std), held, said, choice)
