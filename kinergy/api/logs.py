"""The commands that read logs, as functions: ``read_log``, ``identify``, ``identify_payload``,
``validate``, ``energy``, ``report``."""

from __future__ import annotations

from collections.abc import Sequence

from kinergy.accounting.energy import EnergyReport
from kinergy.accounting.energy import energy as _energy_of_motion
from kinergy.api.common import PathLike, Progress, RobotLike, robot_of
from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.files import check_parent, check_replaceable
from kinergy.identification.options import IdentifyOptions
from kinergy.identification.result import IdentificationResult
from kinergy.identification.validation import ValidationReport
from kinergy.io.formats import read_log as _read_file
from kinergy.io.log import Log
from kinergy.logs.reading import CheckedLog, LogReading
from kinergy.messages import as_say
from kinergy.trajectory.motion import Motion
from kinergy.workflows.convert import Converted, LogKind, convert_log
from kinergy.workflows.energy import EnergyOptions, LogEnergy, energy_with_outputs
from kinergy.workflows.identify import PayloadRun, identify_logs, identify_payload_model
from kinergy.workflows.study import StudyReport, study_report
from kinergy.workflows.validate import validate_logs

__all__ = ["energy", "identify", "identify_payload", "read_log", "report", "validate"]


def read_log(
    path: PathLike, reading: LogReading | None = None, robot: RobotLike | None = None
) -> Log:
    """A log read whole: UR's record.py layout, a headerless file (``reading.columns``), a
    ROS 2 bag, the panda-gaz layout.

    With ``robot`` (a :class:`Robot`, a built-in name or a model file) the log is read through
    the plausibility checks (:mod:`kinergy.logs.checks`; ``reading.accept`` names checks to let
    through), its columns are checked against the robot's joint count, and a ROS 2 bag's joints
    are matched to the robot's by name (``reading.bag``).

    Raises
    ------
    KinergyError
        An unreadable or malformed log, a failed check.
    """
    reading = reading or LogReading()
    if robot is None:
        return _read_file(path, columns=reading.columns, repair=reading.repair)
    return CheckedLog(path, robot_of(robot), reading).read()


def convert(
    log: PathLike,
    out: PathLike,
    to: LogKind,
    robot: RobotLike = "ur5e",
    *,
    reading: LogReading | None = None,
) -> Converted:
    """``kinergy convert``: the log at ``log`` (any log kinergy reads) written to ``out`` as a
    ROS 2 bag (:attr:`LogKind.BAG`: a rosbag2 folder, MCAP; the motion and one effort) or a CSV
    log in UR's record.py layout (:attr:`LogKind.CSV`, every signal, each value read back as the
    same number). ``robot`` gives the joints' names and count; of ``reading``, the columns of a
    headerless text log, ``repair`` and a bag's topic and effort (read or written) apply.

    Raises
    ------
    KinergyError
        ``out`` exists or its folder does not; a bad log; an effort the log lacks.
    """
    r = robot_of(robot)
    check_parent(out)
    reading = reading or LogReading()
    return convert_log(
        log,
        out,
        to,
        tuple(r.joint_names),
        columns=reading.columns,
        repair=reading.repair,
        bag=reading.bag,
    )


def identify(
    logs: Sequence[PathLike | Log],
    robot: RobotLike,
    options: IdentifyOptions | None = None,
    *,
    reading: LogReading | None = None,
    out: PathLike | None = None,
    progress: Progress | None = None,
) -> IdentificationResult:
    """``kinergy identify``: a model identified from ``logs`` (files or logs in memory) starting
    from ``robot``, as ``options`` say (default: the sequential method); written to ``out`` when
    given (with where it came from). ``progress`` is told each log read, of all, and when the
    identification starts.

    Raises
    ------
    KinergyError
        A log that fails its checks, logs that cannot identify the model, a model its logs do not
        support (unless ``reading.accept`` holds ``fit``).
    """
    r = robot_of(robot)
    if out is not None:
        check_replaceable(out)
    return identify_logs(
        r, list(logs), out, reading=reading, options=options, progress=as_say(progress)
    )


def identify_payload(
    logs: Sequence[PathLike | Log],
    robot: RobotLike,
    *,
    out: PathLike,
    reading: LogReading | None = None,
) -> PayloadRun:
    """``kinergy identify --payload-only``: the payload ``robot`` (the model without it)
    carried in ``logs``, with standard errors, written to ``out`` as the robot carrying it.

    Raises
    ------
    KinergyError
        A log that fails its checks, logs that do not show a payload.
    """
    r = robot_of(robot)
    check_replaceable(out)
    return identify_payload_model(r, list(logs), out, reading)


def validate(
    model: RobotLike,
    logs: Sequence[PathLike | Log],
    *,
    reading: LogReading | None = None,
    plots: PathLike | None = None,
) -> ValidationReport:
    """``kinergy validate``: how well ``model`` predicts ``logs`` (UR5e Tables V and VII,
    pooled, per log, moving and holding apart); a log the model was identified from is named in
    a warning. ``logs`` may name the built-in motions ``"test-a"``, ``"test-b"`` (the realistic
    twin of the model running them). ``plots``: a folder to write the figures to (replaced
    whole)."""
    return validate_logs(robot_of(model), list(logs), reading, plots=plots)


def energy(
    model: RobotLike,
    log_or_motion: PathLike | Motion,
    options: EnergyOptions | None = None,
    *,
    reading: LogReading | None = None,
    temperature: Array | None = None,
    trace: PathLike | None = None,
    plot: PathLike | None = None,
) -> EnergyReport | LogEnergy:
    """``kinergy energy``: per-joint and total mechanical and electrical energy, what the arm
    draws from its supply, and where the energy goes.

    ``log_or_motion``: a :class:`Motion` (the energy of it held in memory, with its time series:
    :class:`EnergyReport`; ``temperature`` (N, n) deg C for temperature-dependent friction;
    ``reading.payload`` the payload it carries), or a log or motion file, a URScript program
    (``.script``), or a built-in motion (``"test-a"``, ``"test-b"``): :class:`LogEnergy`, read
    in one pass through the checks, with the power sample by sample written to ``trace`` (CSV
    or Parquet) and its plot to ``plot`` (PNG) when given.
    """
    r = robot_of(model)
    options = options or EnergyOptions()
    if isinstance(log_or_motion, Motion):
        loaded = r if reading is None else reading.loaded(r)
        return _energy_of_motion(
            loaded, log_or_motion, recovery=options.recovery, temperature=temperature
        )
    return energy_with_outputs(r, log_or_motion, reading, options, trace=trace, plot=plot)


def report(
    model: RobotLike,
    *,
    identify: Sequence[str] = (),
    validate: Sequence[str] = (),
    energy: Sequence[str] = (),
    reading: LogReading | None = None,
    out: PathLike | None = None,
    model_name: str = "",
    progress: Progress | None = None,
) -> StudyReport:
    """``kinergy report``: identify ``model`` (sequential method) on the ``identify`` logs if
    any, validate it on the ``validate`` logs, account the energy of the ``energy`` logs or
    motion files, and write the tables, figures and ``report.html`` into the folder ``out``
    (replaced whole; None: a new folder in the system's temporary folder). ``model_name``: what
    the report calls the model (default its name); ``progress`` is called with each step.

    Raises
    ------
    KinergyError
        No logs at all; a log that fails its checks.
    """
    if not (identify or validate or energy):
        raise KinergyError("report: give logs with --identify, --validate or --energy")
    return study_report(
        robot_of(model),
        out,
        identify_logs=identify,
        validate_logs=validate,
        energy_logs=energy,
        reading=reading,
        model_name=model_name,
        progress=progress,
    )
