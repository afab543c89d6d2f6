"""``kinergy report``: the study report from your own model and logs."""

from __future__ import annotations

import click

from kinergy import api
from kinergy.cli.common import (
    print_tables,
    progress,
    reading_options,
    report_folder_option,
    tell,
    writes,
)
from kinergy.logs.reading import LogReading

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
@reading_options("columns", "repair", "accept", "topic", "effort", "payload", "start", "stop")
@writes(folders=("out",), inputs=("model", "identify_logs", "validate_logs", "energy_logs"))
def report(
    model: str,
    identify_logs: tuple[str, ...],
    validate_logs: tuple[str, ...],
    energy_logs: tuple[str, ...],
    out: str | None,
    reading: LogReading,
) -> None:
    """Build the study report (tables, figures, report.html) from your own model and logs."""
    with progress() as say:
        study = api.report(
            model,
            identify=identify_logs,
            validate=validate_logs,
            energy=energy_logs,
            reading=reading,
            out=out,
            model_name=model,
            progress=say,
        )
    tell(study.notes, study.warnings)
    print_tables(study.tables, ["IV", "V", "VI", "VII", "VIII", "breakdown"])
    click.echo(f"\nreport: {study.path}")
