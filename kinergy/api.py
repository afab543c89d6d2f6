"""The Python API that mirrors the commands: the same options, the same checks, the same results.

Each function takes what its command takes, as Python values (an option's name as a string is
parsed here, once, into the types the workflows take) and returns the typed result the command
prints; its ``to_dict()`` is the command's ``--json`` without the ``kinergy`` record of the
command line (version, command, options) and with the same ``inputs`` (each input log by content,
with its checks), ``notes`` and ``warnings``.

=================================  ==========================================================
``read_log(path, columns, robot)``  a log read whole (through the plausibility checks when a
                                    robot is given)
``identify(logs, robot, ...)``      ``kinergy identify``: :class:`IdentificationResult`
``identify_payload(logs, robot)``   ``kinergy identify --payload-only``: a :class:`PayloadRun`
``validate(model, logs, ...)``      ``kinergy validate``: :class:`ValidationReport`
``energy(model, log_or_motion)``    ``kinergy energy``: :class:`LogEnergy` of a log or motion
                                    file, :class:`EnergyReport` of a :class:`Motion`
``simulate(robot, trajectory)``     ``kinergy simulate``: the twin's :class:`Log`
``optimize_program(model, prog)``  ``kinergy optimize``: a URScript program's or a task's
                                    energy-optimal version at the same cycle time
=================================  ==========================================================

Every function that reads a log takes ``payload`` (a :class:`~kinergy.model.robot.Payload` or
``--payload``'s text: it replaces the payload the log's controller logged, which is used
otherwise, and the model's) and ``start``, ``stop`` (``--from``, ``--to``: seconds on the log's
own time axis).
"""

from __future__ import annotations

import enum
import os
from collections.abc import Sequence
from typing import Any, TypeVar

from kinergy.accounting.energy import EnergyReport
from kinergy.accounting.energy import energy as _energy_of_motion
from kinergy.errors import KinergyError
from kinergy.files import check_replaceable
from kinergy.identification.options import IdentifyOptions, Method, Solver, Target, friction_option
from kinergy.identification.result import IdentificationResult
from kinergy.identification.validation import ValidationReport
from kinergy.io.columns import ColumnMap, parse_column_spec
from kinergy.io.formats import read_log as _read_file
from kinergy.io.log import Log
from kinergy.io.rosbag import bag_options
from kinergy.logs.checks import parse_accept
from kinergy.logs.reading import CheckedLog, LogReading
from kinergy.logs.window import TimeWindow
from kinergy.model.library import load_robot
from kinergy.model.robot import Payload, Robot
from kinergy.model.toml import parse_payload
from kinergy.optimize.options import Configurations, ProgramOptions, ToolSymmetry, ViaPoints
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.programs import TEST_TRAJECTORIES, paper_trajectory
from kinergy.twin import TwinSettings
from kinergy.twin import simulate as _simulate
from kinergy.workflows.energy import LogEnergy, energy_of_log
from kinergy.workflows.identify import PayloadRun, identify_logs, identify_payload_model
from kinergy.workflows.optimize import OptimizeRun, run_optimize
from kinergy.workflows.twin import twin_truth
from kinergy.workflows.validate import validate_logs

__all__ = [
    "energy",
    "identify",
    "identify_payload",
    "optimize_program",
    "read_log",
    "simulate",
    "validate",
]

PathLike = str | os.PathLike[str]
RobotLike = Robot | PathLike


def _robot(robot: RobotLike) -> Robot:
    return robot if isinstance(robot, Robot) else load_robot(robot)


E = TypeVar("E", bound=enum.Enum)


def _choice(kind: type[E], value: str, name: str) -> E:
    """``value`` as the ``kind`` option ``name`` takes, or one line naming the values it takes."""
    try:
        return kind(value)
    except ValueError:
        known = ", ".join(str(k.value) for k in kind)
        raise KinergyError(f"{name}={value!r}: not one of {known}") from None


def _reading(
    robot: Robot,
    columns: str | ColumnMap | Sequence[str] | None,
    repair: bool,
    cutoff: float | None,
    accept: str | Sequence[str],
    topic: str | None,
    effort: str | None,
    payload: str | Payload | None = None,
    window: tuple[float | None, float | None] = (None, None),
) -> LogReading:
    """The reading options of the commands, parsed as the command line parses them
    (``payload`` as ``--payload``, ``window`` as ``--from``, ``--to``)."""
    if isinstance(columns, str):
        columns = parse_column_spec(columns, robot.n)
    return LogReading(
        columns=columns if columns is None or isinstance(columns, ColumnMap) else tuple(columns),
        repair=repair,
        cutoff=cutoff,
        accept=parse_accept([accept] if isinstance(accept, str) else accept),
        bag=bag_options(topic, effort),
        payload=None if payload is None else _payload(payload),
        window=None if window == (None, None) else TimeWindow(*window),
    )


def _payload(payload: str | Payload) -> Payload:
    """``payload`` as ``--payload`` takes it (text ``MASS[,CX,CY,CZ[,...]]``) or as it is."""
    return parse_payload(payload) if isinstance(payload, str) else payload


def read_log(
    path: PathLike,
    columns: str | Sequence[str] | None = None,
    robot: RobotLike | None = None,
    *,
    repair: bool = False,
    accept: str | Sequence[str] = (),
    topic: str | None = None,
    effort: str | None = None,
    payload: str | Payload | None = None,
    start: float | None = None,
    stop: float | None = None,
) -> Log:
    """A log read whole: UR's record.py layout, a headerless file with ``columns`` (a column
    spec ``"timestamp,actual_q:6,..."``), a ROS 2 bag, the panda-gaz layout.

    With ``robot`` (a :class:`Robot`, a built-in name or a model file) the log is read through
    the plausibility checks (:mod:`kinergy.logs.checks`; ``accept`` names checks to let through),
    its columns are checked against the robot's joint count, and a ROS 2 bag's joints are matched
    to the robot's by name (``topic``, ``effort`` as ``--topic``, ``--effort``).

    Raises
    ------
    KinergyError
        An unreadable or malformed log, a failed check.
    """
    if robot is None:
        return _read_file(path, columns=columns, repair=repair)
    r = _robot(robot)
    return CheckedLog(
        path, r, _reading(r, columns, repair, None, accept, topic, effort, payload, (start, stop))
    ).read()


def identify(
    logs: Sequence[PathLike | Log],
    robot: RobotLike,
    *,
    method: str = "sequential",
    friction: str | None = None,
    target: str = "auto",
    solver: str = "ols",
    ridge: float = 0.0,
    columns: str | Sequence[str] | None = None,
    repair: bool = False,
    cutoff: float | None = None,
    accept: str | Sequence[str] = (),
    topic: str | None = None,
    effort: str | None = None,
    payload: str | Payload | None = None,
    start: float | None = None,
    stop: float | None = None,
    out: PathLike | None = None,
) -> IdentificationResult:
    """``kinergy identify``: a model identified from ``logs`` (files or logs in memory) starting
    from ``robot``; written to ``out`` when given (with where it came from).

    Options as the command's (``method`` sequential, full or nursing; ``friction`` a friction
    model or ``"auto"``; ``target``, ``solver``, ``ridge`` for the full method).

    Raises
    ------
    KinergyError
        A log that fails its checks, logs that cannot identify the model, a model its logs do not
        support (unless ``accept`` names ``fit``).
    """
    r = _robot(robot)
    options = IdentifyOptions(
        method=_choice(Method, method, "method"),
        friction=friction_option(friction, "friction"),
        target=_choice(Target, target, "target"),
        solver=_choice(Solver, solver, "solver"),
        ridge=ridge,
    )
    reading = _reading(r, columns, repair, cutoff, accept, topic, effort, payload, (start, stop))
    if out is not None:
        check_replaceable(out)
    return identify_logs(r, list(logs), out, reading=reading, options=options)


def identify_payload(
    logs: Sequence[PathLike | Log],
    robot: RobotLike,
    *,
    out: PathLike,
    columns: str | Sequence[str] | None = None,
    repair: bool = False,
    cutoff: float | None = None,
    accept: str | Sequence[str] = (),
    topic: str | None = None,
    effort: str | None = None,
    payload: str | Payload | None = None,
    start: float | None = None,
    stop: float | None = None,
) -> PayloadRun:
    """``kinergy identify --payload-only``: the payload ``robot`` (the model without it)
    carried in ``logs``, with standard errors, written to ``out`` as the robot carrying it.

    Raises
    ------
    KinergyError
        A log that fails its checks, logs that do not show a payload.
    """
    r = _robot(robot)
    check_replaceable(out)
    reading = _reading(r, columns, repair, cutoff, accept, topic, effort, payload, (start, stop))
    return identify_payload_model(r, list(logs), out, reading)


def validate(
    model: RobotLike,
    logs: Sequence[PathLike | Log],
    *,
    columns: str | Sequence[str] | None = None,
    repair: bool = False,
    cutoff: float | None = None,
    accept: str | Sequence[str] = (),
    topic: str | None = None,
    effort: str | None = None,
    payload: str | Payload | None = None,
    start: float | None = None,
    stop: float | None = None,
    plots: PathLike | None = None,
) -> ValidationReport:
    """``kinergy validate``: how well ``model`` predicts ``logs`` (UR5e Tables V and VII,
    pooled, per log, moving and holding apart); a log the model was identified from is named in
    a warning. ``logs`` may name the built-in motions ``"test-a"``, ``"test-b"`` (the realistic
    twin of the model running them)."""
    r = _robot(model)
    reading = _reading(r, columns, repair, cutoff, accept, topic, effort, payload, (start, stop))
    return validate_logs(r, list(logs), reading, plots=plots)


def energy(
    model: RobotLike,
    log_or_motion: PathLike | Motion,
    *,
    columns: str | Sequence[str] | None = None,
    repair: bool = False,
    accept: str | Sequence[str] = (),
    source: str = "auto",
    recovery: bool = True,
    temperature: Any = None,
    topic: str | None = None,
    effort: str | None = None,
    payload: str | Payload | None = None,
    start: float | None = None,
    stop: float | None = None,
) -> EnergyReport | LogEnergy:
    """``kinergy energy``: per-joint and total mechanical and electrical energy, what the arm
    draws from its supply, and where the energy goes.

    ``log_or_motion``: a :class:`Motion` (the energy of it held in memory, with its time series:
    :class:`EnergyReport`; ``temperature`` (N, n) deg C for temperature-dependent friction), or
    a log or motion file, a URScript program (``.script``), or a built-in motion (``"test-a"``,
    ``"test-b"``): :class:`LogEnergy`, read in one pass through the checks.
    """
    r = _robot(model)
    if isinstance(log_or_motion, Motion):
        loaded = r if payload is None else r.with_payload(_payload(payload))
        return _energy_of_motion(loaded, log_or_motion, recovery=recovery, temperature=temperature)
    reading = _reading(r, columns, repair, None, accept, topic, effort, payload, (start, stop))
    return energy_of_log(r, log_or_motion, reading, source=source, recovery=recovery)


def simulate(
    robot: RobotLike,
    trajectory: str | Motion = "test-a",
    *,
    mismatch: str = "none",
    seed: int = 0,
    settings: TwinSettings | None = None,
) -> Log:
    """``kinergy simulate``: the log the digital twin of ``robot`` writes running ``trajectory``
    (``"test-a"``, ``"test-b"`` planned on ``robot``, or a :class:`Motion`): the model itself
    (``mismatch="none"``) or a true robot that differs from it as a real arm does
    (``"realistic"``, seeded), with the lag and noise of ``settings`` (default: the command's)."""
    r = _robot(robot)
    if mismatch not in ("none", "realistic"):
        raise KinergyError(f"mismatch must be 'none' or 'realistic', got {mismatch!r}")
    if isinstance(trajectory, str):
        if trajectory not in TEST_TRAJECTORIES:
            known = ", ".join(TEST_TRAJECTORIES)
            raise KinergyError(f"trajectory must be a Motion or one of {known}, got {trajectory!r}")
        motion = paper_trajectory(r, trajectory)
    else:
        motion = trajectory
    if settings is None:
        settings = (
            TwinSettings.realistic(seed) if mismatch == "realistic" else TwinSettings(seed=seed)
        )
    name = trajectory if isinstance(trajectory, str) else "twin"
    return _simulate(twin_truth(r, mismatch, seed), motion, settings, name=name)


def optimize_program(
    model: RobotLike,
    program: PathLike,
    *,
    configurations: str = "keep",
    tool_symmetry: str = "none",
    via: str = "keep",
    blends: bool = True,
    fixed_shares: bool = False,
    standby: float | None = None,
    cycle_time: float | None = None,
    v_max: float | None = None,
    a_max: float | None = None,
    pareto_points: int = 0,
    urscript: PathLike | None = None,
) -> OptimizeRun:
    """``kinergy optimize``: the same job with less energy from the supply, at the same cycle
    time (``cycle_time``, s: another; None: the program's own).

    ``program``: a URScript program (``*.script``), a task file or a built-in task
    (``"test-a"``, ``"test-b"``), all one program type through the same levers:
    ``configurations`` (``keep`` or ``free``), ``tool_symmetry`` (``none``, ``z``, ``z2``,
    ``z4``), ``via`` (``keep`` or ``free``), ``blends`` and the timing (``fixed_shares``: each
    move keeps its share of the cycle time), judged by the supply energy with ``standby`` W (None:
    the robot file's standing draw). ``v_max`` (rad/s) and ``a_max`` (rad/s²) cap every joint
    (None: the program's own peaks). ``pareto_points``: the Pareto front at that many cycle
    times (0: none). ``urscript``: write the optimised program there. Returns an
    :class:`~kinergy.workflows.optimize.OptimizeRun`.

    Raises
    ------
    KinergyError
        One line naming the option or the program's line at fault.
    """
    r = _robot(model)
    if urscript is not None:
        check_replaceable(urscript)
    options = ProgramOptions(
        configurations=Configurations.parse(configurations),
        tool_symmetry=ToolSymmetry.parse(tool_symmetry),
        via=ViaPoints.parse(via),
        blends=blends,
        fixed_shares=fixed_shares,
        standby=standby,
        cycle_time=cycle_time,
        v_max=v_max,
        a_max=a_max,
    )
    return run_optimize(r, program, options=options, points=pareto_points, urscript=urscript)
