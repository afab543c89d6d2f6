"""``kinergy fleet energy``: every log's energy per cycle on Dask, by robot and day, with drift."""

from __future__ import annotations

from pathlib import Path

import click

from kinergy import api
from kinergy.cli.common import (
    as_usage,
    json_result,
    output_file_option,
    progress,
    reading_options,
    table,
    warn,
)
from kinergy.fleet.analysis import LogResult
from kinergy.logs.reading import LogReading

__all__ = ["fleet"]


@click.group()
def fleet() -> None:
    """Many robots' logs at once (needs the fleet extra: pip install 'kinergy[fleet]')."""


@fleet.command("energy")
@click.argument("logs", nargs=-1, metavar="[LOGS]...", type=click.Path())
@click.option("--manifest", required=True, type=click.Path(dir_okay=False), help="FLEET.toml.")
@output_file_option("--out", "FLEET.parquet.", required=True)
@click.option("--report", type=click.Path(file_okay=False), help="Write the HTML report here.")
@click.option("--scheduler", metavar="ADDRESS", help="A Dask scheduler (default: a local cluster).")
@click.option("--workers", type=int, help="Local cluster worker processes, >= 1 [one per core].")
@click.option(
    "--min-rise",
    type=float,
    default=0.05,
    show_default=True,
    help="Smallest rise called drift (a fraction, >= 0).",
)
@click.option("--json", "as_json", is_flag=True, help="Print the robots as JSON.")
@reading_options("topic", "effort", "accept", "payload", "start", "stop")
def energy(
    logs: tuple[str, ...],
    manifest: str,
    out: str,
    report: str | None,
    scheduler: str | None,
    workers: int | None,
    min_rise: float,
    as_json: bool,
    reading: LogReading,
) -> None:
    """Energy per cycle of every log (LOGS and the manifest's globs), by robot and by day.

    Writes one row per cycle to --out (Parquet) and flags each robot whose energy or friction
    per cycle, for the same program, rises beyond its own spread; a step (a new payload) is
    reported as a change, not as drift. A log may be a ROS 2 bag (folder or .mcap/.db3 file); a
    robot entry's topic and effort win over --topic and --effort for its bags.
    """

    def tick(done: int, total: int, result: LogResult) -> None:
        if result.error is not None:  # a log left out: the robot's figures lack it
            warn(f"{result.error} (left out of {result.robot}'s figures)")
        say("energy of the fleet's logs", done=done, total=total)

    with as_usage():
        options = api.FleetOptions(scheduler=scheduler, workers=workers, min_rise=min_rise)
    with progress() as say:
        result = api.fleet_energy(
            logs, manifest, out, options, reading=reading, report=report, progress=tick
        )
    if as_json:
        click.echo(json_result(result))
        return
    rows = [
        [r.name, str(r.logs), str(r.cycles), f"{r.energy_J / 1e3:.2f}",
         "-" if not r.measured_J else f"{r.predicted_J / r.measured_J:.4f}",
         "DRIFT" if r.drift else "-", str(len(r.changes))]
        for r in result.robots
    ]  # fmt: skip
    click.echo(
        table(
            ["robot", "logs", "cycles", "energy [kJ]", "model/measured", "drift", "changes"], rows
        )
    )
    for r in result.robots:
        for c in r.changes:
            click.echo(
                f"{r.name}: {c.metric} per cycle of {c.program} changed on {c.date} "
                f"({100 * c.relative:+.1f} %): a change, not drift"
            )
    where = f"; report {Path(report) / 'report.html'}" if report else ""
    click.echo(
        f"{result.logs} logs"
        + (f" ({len(result.skipped)} more left out: refused)" if result.skipped else "")
        + f" on {result.workers} worker(s) in {result.seconds:.1f} s: {out}{where}",
        err=True,
    )
