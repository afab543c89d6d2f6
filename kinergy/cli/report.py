"""``kinergy report``: the study report from your own model and logs."""

from __future__ import annotations

import click

from kinergy.cli.common import (
    bag_options,
    columns_option,
    effort_option,
    load,
    note,
    payload_option,
    print_tables,
    progress,
    repair_option,
    report_folder_option,
    topic_option,
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
@payload_option
@repair_option
@topic_option
@effort_option
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
    topic: str | None,
    effort: str | None,
) -> None:
    """Build the study report (tables, figures, report.html) from your own model and logs."""
    if not (identify_logs or validate_logs or energy_logs):
        raise KinergyError("report: give logs with --identify, --validate or --energy")
    with progress() as say:
        path, tables = study_report(
            load(model, payload),
            out,
            identify_logs=identify_logs,
            validate_logs=validate_logs,
            energy_logs=energy_logs,
            columns=columns,
            repair=repair,
            model_name=model,
            progress=say,
            note=note,
            bag=bag_options(topic, effort),
        )
    print_tables(tables, ["IV", "V", "VI", "VII", "VIII", "breakdown"])
    click.echo(f"\nreport: {path}")
