"""``kinergy validate``: how well a model predicts logs, and the plots that show it."""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Sequence
from pathlib import Path

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.files import atomic_folder
from kinergy.identification.validation import (
    PLOT_SAMPLES,
    LogValidation,
    ValidationReport,
    validation_report,
)
from kinergy.io.log import Log
from kinergy.logs.reading import InputLogs, LogReading
from kinergy.model.robot import Robot
from kinergy.report.plots import error_boxplot, save, time_series
from kinergy.workflows.logs import MIN_SEGMENT, chunked_logs
from kinergy.workflows.twin import builtin_log, check_source, is_builtin

__all__ = ["identified_from", "validate_logs", "write_validation_plots"]


def identified_from(robot: Robot, inputs: InputLogs) -> list[str]:
    """Warnings for each log the model ``robot`` was identified from (same SHA-256): a
    validation on it is not on unseen motion."""
    if robot.identified is None:
        return []
    seen = {i.sha256: i.path for i in robot.identified.inputs}
    return [
        f"{p.path}: the model was identified from this log (as {seen[p.sha256]}, same SHA-256): "
        "this validation is not on unseen motion"
        for p in inputs.provenance
        if p.sha256 in seen
    ]


def validate_logs(
    robot: Robot,
    logs: Sequence[str | os.PathLike[str] | Log],
    reading: LogReading | None = None,
    *,
    plots: str | os.PathLike[str] | None = None,
) -> ValidationReport:
    """UR5e Tables V and VII for ``logs`` (read through the checks, in chunks), pooled and per
    log, moving and holding apart (:func:`~kinergy.identification.validation.validation_report`);
    with ``plots``, also write the measured-against-predicted figures to that folder. A log the
    model was identified from is named in a warning."""
    for log in logs:
        check_source(log)
    sources = [builtin_log(robot, str(log)) if is_builtin(log) else log for log in logs]
    reading = reading or LogReading()
    robot = reading.loaded(robot)
    with chunked_logs(sources, robot, reading) as (segments, inputs):
        report = validation_report(
            robot,
            segments,
            plot_samples=PLOT_SAMPLES if plots is not None else 0,
            robots=[s.robot(robot) for s in segments],
        )
        short = [
            f"{s.path}: {len(s)} samples over {(len(s) - 1) * s.dt:.3g} s: too short for these "
            f"figures to tell how the model predicts (identify asks for {MIN_SEGMENT:g} s)"
            for s in segments
            if (len(s) - 1) * s.dt < MIN_SEGMENT
        ]
    if report.torque is None and report.current is None and report.joint_torque is None:
        names = ", ".join(os.fspath(p) if not isinstance(p, Log) else p.path for p in logs)
        raise KinergyError(
            f"{names}: nothing to compare the model with: no target_moment, actual_current or "
            "measured joint torques (a ROS 2 bag without effort?)"
        )
    inputs.notes += [
        f"{log}: the realistic twin of {robot.name} (seed 0) running the built-in motion {log}: "
        "a simulated log, not a real robot's"
        for log in logs
        if is_builtin(log)
    ]
    if plots is not None:
        write_validation_plots(robot, report.logs, plots)
        inputs.notes += [
            f"{log.log}: its plots show one sample in {s.step} of {log.samples:,} "
            "(the figures use every sample)"
            for log in report.logs
            for s in list(log.series.values())[:1]
            if s.step > 1
        ]
    warnings = [*inputs.warnings, *short, *identified_from(robot, inputs)]
    return dataclasses.replace(
        report, inputs=inputs, notes=tuple(inputs.notes), warnings=tuple(warnings)
    )


def _stems(names: Sequence[str]) -> list[str]:
    """A distinct file stem for each log or segment (``run.csv#1`` -> ``run#1``; a stem seen
    before gets ``-2``, ``-3``, ...)."""
    out: list[str] = []
    for k, name in enumerate(names):
        path, _, segment = name.partition("#")
        stem = (Path(path).stem or f"log{k}") + (f"#{segment}" if segment else "")
        base, n = stem, 1
        while stem in out:
            n += 1
            stem = f"{base}-{n}"
        out.append(stem)
    return out


def write_validation_plots(
    robot: Robot, logs: Sequence[LogValidation], folder: str | os.PathLike[str]
) -> None:
    """Per log (or segment), measured against predicted reference torque, current and measured
    joint torque, each joint with its residual below (``STEM_torque.png``, ``STEM_current.png``,
    ``STEM_joint_torque.png``, :func:`_stems`) from its :attr:`~kinergy.identification.validation.LogValidation.series`;
    over all logs, the error box plots (``torque_errors.png``, ...). The folder is built
    beside ``folder`` and replaces it whole (:func:`kinergy.files.atomic_folder`: refused when
    it holds a file kinergy did not write)."""
    with atomic_folder(folder) as out:
        _plots(robot, logs, out)


#: the signals ``validate --plots`` draws: its key, unit and what the log calls the measurement
PLOTTED = (
    ("torque", "N m", "target_moment"),
    ("current", "A", "actual_current"),
    ("joint_torque", "N m", "actual_joint_torque"),
)


def _plots(robot: Robot, logs: Sequence[LogValidation], out: Path) -> None:
    errors: dict[str, dict[str, Array]] = {key: {} for key, _, _ in PLOTTED}
    for log, stem in zip(logs, _stems([log.log for log in logs]), strict=True):
        for key, unit, label in PLOTTED:
            series = log.series.get(key)
            if series is None:
                continue
            fig = time_series(
                series.t,
                series.measured,
                series.predicted,
                joint_names=robot.joint_names,
                quantity=key,
                unit=unit,
                measured_label=label,
                predicted_label="model",
                band=series.band,
            )
            save(fig, out / f"{stem}_{key}.png")
            errors[key][stem] = series.measured - series.predicted
    for key, unit, _ in PLOTTED:
        if errors[key]:
            fig = error_boxplot(errors[key], joint_names=robot.joint_names, quantity=key, unit=unit)
            save(fig, out / f"{key}_errors.png")
