"""``kinergy monitor``: live energy per program cycle, measured against the model."""

from __future__ import annotations

import click

from kinergy import api
from kinergy.cli.common import as_usage, fmt, json_result, load, progress, reading_options
from kinergy.live.monitor import CycleEnergy
from kinergy.logs.reading import LogReading

__all__ = ["monitor"]

_HEAD = f"{'cycle':>5}  {'start [s]':>11}  {'T [s]':>7}  {'measured [J]':>12}  {'model [J]':>10}  {'model err':>9}"


def _line(c: CycleEnergy) -> str:
    measured = "-" if c.measured is None else f"{c.measured:.1f}"
    error = "-" if c.error is None else f"{100 * c.error:+.2f} %"
    return (
        f"{c.index:>5}  {c.start:>11.3f}  {c.duration:>7.3f}  {measured:>12}  "
        f"{c.predicted:>10.1f}  {error:>9}"
    )


@click.command()
@click.argument("address", metavar="HOST[:PORT]")
@click.option(
    "--model", "model", required=True, metavar="ROBOT", help="Robot model (name or file)."
)
@click.option("--frequency", type=float, default=500.0, show_default=True, help="Hz (> 0, <= 500).")
@click.option("--duration", type=float, help="Stop after this many seconds of controller time.")
@click.option("--json", "as_json", is_flag=True, help="At the end, print the cycles as JSON.")
@reading_options("accept")
def monitor(
    address: str,
    model: str,
    frequency: float,
    duration: float | None,
    as_json: bool,
    reading: LogReading,
) -> None:
    """Energy of every program cycle, live: the supply's (voltage x current) against the model's.

    Cycles are found from the repeating commanded joint angles (a cycle is reported once the
    motion has repeated); until the first one, a line a second on stderr says how much has come.
    Ctrl-C stops.
    """
    with as_usage():
        options = api.StreamOptions(frequency=frequency, duration=duration)
    robot = load(model, None)
    shown: list[CycleEnergy] = []

    def show(cycle: CycleEnergy) -> None:
        if not shown and not as_json:
            click.echo(_HEAD)
        shown.append(cycle)
        if not as_json:
            click.echo(_line(cycle))

    def waiting(seconds: float, samples: int, period: float | None) -> None:
        found = "period not found yet" if period is None else f"period {fmt(period)} s"
        click.echo(
            f"waiting for the first cycle: {seconds:.1f} s of controller time, {samples} "
            f"samples, {found}",
            err=True,
        )

    with progress() as say:
        run = api.monitor(
            address, robot, options, reading=reading, on_cycle=show, status=say, waiting=waiting
        )
    period = "not found" if run.period is None else f"{fmt(run.period)} s"
    if as_json:
        click.echo(json_result(run))
    click.echo(f"{len(run.cycles)} cycle(s), period {period}", err=True)
