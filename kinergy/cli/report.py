"""``kinergy report``: the study report from your own model and logs."""

from __future__ import annotations

import click

from kinergy.cli.common import (
    accept_option,
    columns_option,
    effort_option,
    load,
    log_reading,
    payload_option,
    print_tables,
    progress,
    repair_option,
    report_folder_option,
    tell,
    topic_option,
    window_options,
    writes,
)
from kinergy.errors import KinergyError
from kinergy.workflows.study import study_report

__all__ = ["report"]


@click.command()
@click.argument("model", metavar="MODEL")
@click.option(
    "--identify",
    "identify_logs",
    multiple=True,
    metavar="LOG",
    help="Identify the model from this log first (sequential method; repeatable).",
)
@click.option(
    "--validate",
    "validate_logs",
    multiple=True,
    metavar="LOG",
    help="Compare the model with this log (repeatable).",
)
@click.option(
    "--energy",
    "energy_logs",
    multiple=True,
    metavar="LOG_OR_MOTION",
    help="Account the energy of this log's or motion file's motion (repeatable).",
)
@report_folder_option()
@columns_option
@accept_option
@topic_option
@effort_option
@payload_option
@repair_option
@window_options
@writes(folders=("out",), inputs=("model", "identify_logs", "validate_logs", "energy_logs"))
def report(
    model: str,
    identify_logs: tuple[str, ...],
    validate_logs: tuple[str, ...],
    energy_logs: tuple[str, ...],
    out: str | None,
    columns: str | None,
    payload: str | None,
    repair: bool,
    accept: tuple[str, ...],
    topic: str | None,
    effort: str | None,
    start: float | None,
    stop: float | None,
) -> None:
    """Build the study report (tables, figures, report.html) from your own model and logs."""
    if not (identify_logs or validate_logs or energy_logs):
        raise KinergyError("report: give logs with --identify, --validate or --energy")
    robot = load(model, None)
    reading = log_reading(
        robot,
        columns=columns,
        repair=repair,
        accept=accept,
        topic=topic,
        effort=effort,
        payload=payload,
        start=start,
        stop=stop,
    )
    with progress() as say:
        path, tables, said = study_report(
            robot,
            out,
            identify_logs=identify_logs,
            validate_logs=validate_logs,
            energy_logs=energy_logs,
            reading=reading,
            model_name=model,
            progress=say,
        )
    tell(said.notes, said.warnings)
    print_tables(tables, ["IV", "V", "VI", "VII", "VIII", "breakdown"])
    click.echo(f"\nreport: {path}")
