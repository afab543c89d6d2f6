"""``kinergy demo``: the UR5e study on the built-in twin, from logs to report."""

from __future__ import annotations

from pathlib import Path

import click

from kinergy.cli.common import print_tables, progress, report_folder_option, writes
from kinergy.twin import MISMATCHES
from kinergy.workflows.demo import run_demo

__all__ = ["TABLES", "demo"]

#: the demo's tables, in the order it prints them
TABLES = ("IV", "V", "VI", "VII", "VIII", "breakdown", "timing", "truth")


@click.command()
@report_folder_option("the logs, figures")
@click.option(
    "--mismatch",
    type=click.Choice(MISMATCHES),
    default="realistic",
    show_default=True,
    help="realistic: the twin's true robot differs from the model identified; none: the twin is "
    "the UR5e doc's model itself.",
)
@writes(folders=("out",))
def demo(out: str | None, mismatch: str) -> None:
    """The UR5e study on the built-in twin: simulate tests A and B, identify on A, validate on A
    and B, compute the energy, print UR5e Tables IV-VIII (and the twin's truth against the
    identified values) and write an HTML report."""
    with progress() as say:
        tables, report, seconds = run_demo(
            None if out is None else Path(out), say, mismatch=mismatch
        )
    print_tables(tables, TABLES)
    click.echo(f"\nreport: {report} ({seconds:.1f} s)")
