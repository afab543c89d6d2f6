"""The study pipeline: predictions on logs, energy of motions and an optimal timing, then the
report (tables, figures, ``report.html``). ``kinergy report`` and ``kinergy demo`` run it."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from kinergy._version import __version__
from kinergy.accounting.energy import EnergyReport, energy
from kinergy.accounting.trace import PowerSeries, SupplyTrace
from kinergy.files import output_folder
from kinergy.identification.chunks import Segment
from kinergy.identification.result import IdentificationResult
from kinergy.identification.validation import PLOT_SAMPLES, validation_report
from kinergy.io.task import Task
from kinergy.logs.prepare import IdentData, PreparedSegment
from kinergy.logs.reading import LogReading
from kinergy.messages import Messages
from kinergy.model.robot import Robot
from kinergy.report.html import Section, Table, write_report
from kinergy.report.study import Comparison, Study, Timing, study_sections
from kinergy.trajectory.motion import Motion
from kinergy.workflows.energy import energy_of_log, log_energy_report, program_energy
from kinergy.workflows.identify import identify_logs as identified
from kinergy.workflows.logs import chunked_logs
from kinergy.workflows.optimize import optimize_task
from kinergy.workflows.twin import is_builtin

__all__ = ["StudyReport", "optimal_timing", "run_study", "study_report", "write_study"]

Progress = Callable[[str], None]


@dataclass(frozen=True, eq=False)
class StudyReport:
    """What ``kinergy report`` wrote: the path of ``report.html``, its tables by UR5e table
    (``"IV"`` ... ``"VIII"``, ``"breakdown"``), and what reading the logs and identifying said."""

    path: Path
    tables: dict[str, list[Table]]
    notes: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()


def _comparisons(
    model: Robot, validation: Mapping[str, Segment | IdentData], say: Progress
) -> tuple[dict[str, Comparison], dict[str, Comparison]]:
    """Per log: the model's reference torque and current against the logged ones (a log's
    figures over every sample, its plots over at most
    :data:`~kinergy.identification.validation.PLOT_SAMPLES`)."""
    torque: dict[str, Comparison] = {}
    current: dict[str, Comparison] = {}
    for name, log in validation.items():
        say(f"validating on {name}")
        loaded = log.robot(model) if isinstance(log, PreparedSegment) else model
        found = validation_report(loaded, [log], plot_samples=PLOT_SAMPLES).logs[0]
        for key, out in (("torque", torque), ("current", current)):
            series, metrics = found.series.get(key), getattr(found, key)
            if series is not None and metrics is not None:
                out[name] = Comparison(series.t, series.measured, series.predicted, metrics)
    return torque, current


def optimal_timing(model: Robot, task: Task, *, points: int = 6) -> Timing:
    """The energy-optimal timing of ``task`` at its own cycle time and the Pareto front."""
    result, front = optimize_task(model, task, points=points)
    return Timing(task.name, result, front)


def run_study(
    model: Robot,
    *,
    validation: Mapping[str, Segment | IdentData] | None = None,
    motions: Mapping[str, Motion | EnergyReport] | None = None,
    result: IdentificationResult | None = None,
    truth: Robot | None = None,
    paper: bool = False,
    task: Task | None = None,
    progress: Progress | None = None,
    supply: Mapping[str, SupplyTrace] | None = None,
) -> Study:
    """Compute everything a study report shows (:class:`kinergy.report.study.Study`).

    Parameters
    ----------
    model : Robot
    validation : mapping of str to Segment or IdentData
        Logs to compare the model with, by name (``"test A"``): prepared segments
        (:func:`~kinergy.workflows.logs.chunked_logs`, folded in chunks) or logs in memory.
    motions : mapping of str to Motion or EnergyReport
        Motions to account the energy of, by name (or their energy, accounted otherwise: a
        program run with the loads it sets, :func:`~kinergy.workflows.energy.program_energy`).
    result, truth, paper
        See :class:`~kinergy.report.study.Study`.
    task : Task, optional
        A movej program whose energy-optimal timing and Pareto front the report shows.
    supply : mapping of str to SupplyTrace, optional
        Per log name, the supply's power to plot (:func:`supply_trace`).
    """
    say = progress or (lambda _msg: None)
    torque, current = _comparisons(model, validation or {}, say)
    reports = {}
    for name, motion in (motions or {}).items():
        say(f"energy of {name}")
        reports[name] = motion if isinstance(motion, EnergyReport) else energy(model, motion)
    timing = None
    if task is not None:
        say(f"optimising the timing of {task.name}")
        timing = optimal_timing(model, task)
    return Study(model, result, truth, paper, torque, current, reports, timing, supply or {})


def write_study(
    study: Study,
    folder: str | os.PathLike[str],
    *,
    title: str,
    subtitle: str,
    meta: Mapping[str, str],
    extra: Sequence[Section] = (),
) -> tuple[Path, dict[str, list[Table]]]:
    """Write the study's figures and ``folder/report.html`` (with the ``extra`` sections after the
    study's first); return its path and the tables."""
    sections, tables = study_sections(study, Path(folder))
    path = write_report(
        Path(folder) / "report.html",
        title=title,
        subtitle=subtitle,
        sections=[*sections[:1], *extra, *sections[1:]],
        meta={**meta, "kinergy": __version__, "date": time.strftime("%Y-%m-%d %H:%M")},
    )
    return Path(path), tables


def supply_trace(robot: Robot, path: str, reading: LogReading) -> SupplyTrace:
    """The supply's power over the log at ``path`` for a plot, predicted and (where the log has
    ``actual_robot_voltage`` and ``actual_robot_current``) measured, with their energies: one
    more pass over the log (:func:`~kinergy.workflows.energy.energy_of_log`), memory bounded."""
    series = PowerSeries()
    figures = energy_of_log(robot, path, reading, sinks=[series])
    return SupplyTrace(
        series.t,
        series.predicted,
        series.measured,
        figures.supply.drawn,
        None if figures.measured is None else figures.measured.drawn,
        robot.standby_power,
    )


def study_report(
    robot: Robot,
    out: str | os.PathLike[str] | None,
    *,
    identify_logs: Sequence[str] = (),
    validate_logs: Sequence[str] = (),
    energy_logs: Sequence[str] = (),
    reading: LogReading | None = None,
    model_name: str = "",
    progress: Progress | None = None,
) -> StudyReport:
    """``kinergy report``: identify (sequential method) on ``identify_logs`` if any, validate on
    ``validate_logs``, account the energy of ``energy_logs``, and write ``out/report.html``.

    The folder is built beside ``out`` and renamed into place at the end
    (:func:`kinergy.files.atomic_folder`); ``out`` None: a new folder ``kinergy-report-*`` in the
    system's temporary folder.
    """
    say = progress or (lambda _msg: None)
    reading = reading or LogReading()
    said = Messages()
    result = None
    if identify_logs:
        say("identifying")
        result = identified(robot, identify_logs, None, reading=reading)
        said.notes += result.notes
        said.warnings += result.warnings
        robot = result.robot
    robot = reading.loaded(robot)  # --payload: of every log and motion
    motions: dict[str, Motion | EnergyReport] = {}
    supply: dict[str, SupplyTrace] = {}
    for p in energy_logs:
        if p.endswith(".script"):  # run with the loads it sets
            motions[Path(p).name] = program_energy(robot, p)
            continue
        report, inputs = log_energy_report(robot, p, reading)
        said.notes += inputs.notes
        said.warnings += inputs.warnings
        motions[Path(p).name] = report
        if not is_builtin(p):
            supply[Path(p).name] = supply_trace(robot, p, reading)
    with chunked_logs(validate_logs, robot, reading) as (segments, inputs):
        said.notes += inputs.notes
        said.warnings += inputs.warnings
        validation = {Path(s.path).name: s for s in segments}
        study = run_study(
            robot,
            validation=validation,
            motions=motions,
            result=result,
            progress=progress,
            supply=supply,
        )
    with output_folder(out, prefix="kinergy-report") as (folder, target):
        _, tables = write_study(
            study,
            folder,
            title=f"kinergy report: {robot.name}",
            subtitle="Model parameters, accuracy on logs and energy of motions",
            meta={
                "model": model_name or robot.name,
                "logs": ", ".join([*identify_logs, *validate_logs, *energy_logs]),
            },
        )
    return StudyReport(target / "report.html", tables, tuple(said.notes), tuple(said.warnings))
