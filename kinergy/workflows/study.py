"""``kinergy report``: the study report (tables, figures, report.html) from a user's model and logs."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from kinergy.identify.sequential import identify_sequential
from kinergy.model.robot import Robot
from kinergy.report.build import StudyInputs, report_sections
from kinergy.report.html import write_report
from kinergy.workflows.logs import prepared_logs, read_motion

__all__ = ["study_report"]


def study_report(
    robot: Robot,
    out: str | os.PathLike[str],
    *,
    identify_logs: Sequence[str] = (),
    validate_logs: Sequence[str] = (),
    energy_logs: Sequence[str] = (),
    columns: str | None = None,
    repair: bool = False,
    model_name: str = "",
    progress: Callable[[str], None] | None = None,
    note: Callable[[str], None] | None = None,
) -> tuple[Path, dict[str, Any]]:
    """Identify (sequential method) on ``identify_logs`` if any, validate on ``validate_logs``,
    account the energy of ``energy_logs``, and write ``out/report.html`` with its figures.

    Returns the report's path and its tables (keyed as :func:`report_sections` keys them).
    """
    from kinergy import __version__

    say = progress or (lambda _msg: None)
    result = None
    if identify_logs:
        say("identifying")
        datas = prepared_logs(
            identify_logs, n_joints=robot.n, columns=columns, repair=repair, note=note
        )
        result = identify_sequential(robot, datas)
        robot = result.robot
    validation = dict(
        zip(
            (Path(p).name for p in validate_logs),
            prepared_logs(
                validate_logs, n_joints=robot.n, columns=columns, repair=repair, note=note
            ),
            strict=True,
        )
    )
    motions = {
        Path(p).name: read_motion(p, n_joints=robot.n, columns=columns, repair=repair)
        for p in energy_logs
    }
    folder = Path(out)
    inputs = StudyInputs(model=robot, validation=validation, motions=motions, result=result)
    sections, tables = report_sections(inputs, folder, say)
    path = write_report(
        folder / "report.html",
        title=f"kinergy report: {robot.name}",
        subtitle="Model parameters, accuracy on logs and energy of motions",
        sections=sections,
        meta={
            "model": model_name or robot.name,
            "kinergy": __version__,
            "date": time.strftime("%Y-%m-%d %H:%M"),
            "logs": ", ".join([*identify_logs, *validate_logs, *energy_logs]),
        },
    )
    return path, tables
