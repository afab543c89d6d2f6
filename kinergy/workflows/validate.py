"""``kinergy validate``: how well a model predicts logs, and the plots that show it."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from kinergy.identify.preprocess import IdentData
from kinergy.identify.result import predict
from kinergy.identify.sanity import check_signals
from kinergy.identify.validation import ValidationReport, validation_report
from kinergy.model.robot import Robot
from kinergy.report.plots import error_boxplot, save, time_series

__all__ = ["validate_logs", "write_validation_plots"]


def validate_logs(
    robot: Robot, datas: Sequence[IdentData], *, plots: str | os.PathLike[str] | None = None
) -> ValidationReport:
    """UR5e Tables V and VII for ``datas``, pooled and per log, moving and holding apart
    (:func:`~kinergy.identify.validation.validation_report`); with ``plots``, also write the
    measured-against-predicted figures to that folder."""
    check_signals(datas)
    report = validation_report(robot, list(datas))
    if plots is not None:
        write_validation_plots(robot, datas, plots)
    return report


def write_validation_plots(
    robot: Robot, datas: Sequence[IdentData], folder: str | os.PathLike[str]
) -> None:
    """Per log, measured against predicted torque and current (``STEM_torque.png``,
    ``STEM_current.png``); over all logs, the error box plots (``torque_errors.png``, ...)."""
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    errors: dict[str, dict[str, Any]] = {"torque": {}, "current": {}}
    for k, data in enumerate(datas):
        pred = predict(robot, data)
        stem = Path(data.path).stem or f"log{k}"
        for key, measured, predicted, unit, label in (
            ("torque", data.tau_ref, pred.torque, "N m", "target_moment"),
            ("current", data.current, pred.current, "A", "actual_current"),
        ):
            if measured is None or predicted is None:
                continue
            fig = time_series(
                data.t - data.t[0],
                measured,
                predicted,
                joint_names=robot.joint_names,
                quantity=key,
                unit=unit,
                measured_label=label,
                predicted_label="model",
            )
            save(fig, out / f"{stem}_{key}.png")
            errors[key][stem] = measured - predicted
    for key, unit in (("torque", "N m"), ("current", "A")):
        if errors[key]:
            fig = error_boxplot(errors[key], joint_names=robot.joint_names, quantity=key, unit=unit)
            save(fig, out / f"{key}_errors.png")
