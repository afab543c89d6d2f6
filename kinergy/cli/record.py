"""``kinergy record``: record a UR controller's RTDE stream to record.py-layout log files."""

from __future__ import annotations

import click

from kinergy import api
from kinergy.cli.common import as_usage, log_output, output_file_option, progress, writes

__all__ = ["record"]


@click.command()
@click.argument("address", metavar="HOST[:PORT]")
@output_file_option("--out", "Log file to write.", required=True)
@click.option(
    "--frequency",
    type=float,
    default=500.0,
    show_default=True,
    help="Packages per second, Hz (> 0, <= 500).",
)
@click.option("--duration", type=float, help="Stop after this many seconds of controller time.")
@click.option(
    "--rotate", "rotate_minutes", type=float, metavar="MINUTES", help="New file every MINUTES."
)
@click.option(
    "--rotate-size", "rotate_megabytes", type=float, metavar="MB", help="New file every MB."
)
@writes(files=("out",))
def record(
    address: str,
    out: str,
    frequency: float,
    duration: float | None,
    rotate_minutes: float | None,
    rotate_megabytes: float | None,
) -> None:
    """Record every field kinergy uses from a UR controller over RTDE (port 30004 by default).

    Every package is kept, with the controller's own time stamps, in UR's record.py layout plus a
    `segment` column that counts reconnections. Ctrl-C or SIGTERM stops with complete files.
    """
    with as_usage():
        options = api.RecordOptions(
            frequency=frequency,
            duration=duration,
            rotate_minutes=rotate_minutes,
            rotate_megabytes=rotate_megabytes,
        )
    log_output("--out", out)
    with progress() as say:
        result = api.record(address, out, options, status=say)
    span = 0.0 if result.first is None else (result.last or 0.0) - result.first
    files = ", ".join(result.files)
    click.echo(
        f"stopped ({result.stopped}): {result.rows} rows, {span:.3f} s of controller time, "
        f"{result.segments} segment(s) in {files}",
        err=True,
    )
