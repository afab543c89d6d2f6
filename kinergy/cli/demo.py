"""``kinergy demo``: the UR5e study on the built-in twin, from logs to report."""

from __future__ import annotations

import click

from kinergy import api
from kinergy.cli.common import choice_of, print_tables, progress, report_folder_option, writes

__all__ = ["TABLES", "demo"]

#: the demo's tables, in the order it prints them
TABLES = ("IV", "V", "VI", "VII", "VIII", "breakdown", "timing", "truth")


@click.command()
@report_folder_option("the logs, figures")
@click.option(
    "--mismatch",
    type=choice_of(api.Mismatch),
    default=api.Mismatch.REALISTIC.value,
    show_default=True,
    help="realistic: the twin's true robot differs from the model identified; none: the twin is "
    "the UR5e doc's model itself.",
)
@writes(folders=("out",))
def demo(out: str | None, mismatch: api.Mismatch) -> None:
    """The UR5e study on the built-in twin: simulate tests A and B, identify on A, validate on A
    and B, compute the energy, print UR5e Tables IV-VIII (and the twin's truth against the
    identified values) and write an HTML report."""
    with progress() as say:
        run = api.demo(out, mismatch=mismatch, progress=say)
    print_tables(run.tables, TABLES)
    click.echo(f"\nreport: {run.report} ({run.seconds:.1f} s)")
