"""``kinergy place``: where the robot's base should stand for a URScript program.

Parses the search area into a typed grid (:class:`kinergy.optimize.placement.PlacementGrid`) and
the levers into :class:`kinergy.optimize.options.ProgramOptions`, runs :func:`kinergy.api.place`
(every candidate checked for reach and optimised at today's cycle time; the best's program and the
energy map written where asked) and prints the result as text or JSON.
"""

from __future__ import annotations

import math

import click

from kinergy import api
from kinergy.cli.common import (
    as_usage,
    json_result,
    load,
    output_file_option,
    payload_option,
    progress,
    prose,
    table,
    writes,
)
from kinergy.cli.optimize import CycleTime, lever_options, program_options
from kinergy.errors import KinergyError
from kinergy.optimize.placement import Candidate

__all__ = ["parse_range", "place", "place_text"]


def parse_range(text: str | None, flag: str, unit: str, scale: float = 1.0) -> api.Range:
    """``MIN:MAX`` (in ``unit``, times ``scale`` into SI) as a :class:`Range`; None: ``0:0``.

    Raises
    ------
    KinergyError
        Not two numbers separated by a colon, or not finite: one line naming the flag. (A range
        backwards is refused by :class:`PlacementGrid`.)
    """
    if text is None:
        return api.Range(0.0, 0.0)
    parts = text.split(":")
    try:
        low, high = (float(p) for p in parts) if len(parts) == 2 else (math.nan, math.nan)
    except ValueError:
        low = high = math.nan
    if len(parts) != 2 or not (math.isfinite(low) and math.isfinite(high)):
        raise KinergyError(f"{flag}: expected MIN:MAX in {unit} (two finite numbers), got {text!r}")
    return api.Range(low * scale, high * scale)


def _percent(x: float | None) -> str:
    return "-" if x is None else f"{100 * x:.1f} %"


def _energy(c: Candidate) -> str:
    return f"{c.e_supply:.1f}" if c.e_supply is not None else "-"


def place_text(run: api.PlaceRun) -> str:
    """The ``place`` report: the candidates, today's and the best placement, what it saves."""
    search = run.search
    today, best = search.today, search.best
    rows = [
        [
            f"{c.placement.x:+.3f}",
            f"{c.placement.y:+.3f}",
            f"{c.placement.z:+.3f}",
            f"{math.degrees(c.placement.yaw):+.1f}",
            "yes" if c.reachable else "no",
            _energy(c),
        ]
        for c in search.candidates
    ]
    headers = ["x [m]", "y [m]", "z [m]", "yaw [deg]", "reachable", "E supply [J]"]
    why = [
        prose(f"{c.placement.label()}: {c.reason.value}: {c.why}")
        for c in search.candidates
        if not c.reachable
    ]
    assert today.result is not None and best.result is not None
    cycle = best.result.settings.cycle_time
    reachable = sum(c.reachable for c in search.candidates)
    lines = [
        prose(
            f"{run.robot.name}, program {run.program.name}: {len(search.candidates)} candidate "
            f"placements, {reachable} reachable; each optimised at today's cycle time of "
            f"{cycle:.3f} s within today's caps (supply energy per cycle, model-predicted)",
        ),
        table(headers, rows),
        *(["", "not reachable:", *why] if why else []),
        "",
        prose(
            f"today's placement: {today.result.program.result.e_supply:.1f} J as written, "
            f"{_energy(today)} J optimised ({100 * today.result.saving_supply:.1f} % of the supply "
            f"energy by the levers, {100 * today.result.saving_motors:.1f} % of the motors'); its "
            f"optimised program read back: {run.today_readback:.1f} J",
        ),
        prose(
            f"best placement: {best.placement.label()}: {_energy(best)} J optimised; its "
            f"written program read back and simulated again: {run.readback:.1f} J, "
            f"{100 * run.saving:.1f} % less than today's placement beyond the program levers "
            f"(supply energy: the motors and the standing draw of {best.result.settings.standby:.1f}"
            f" W over the cycle; the motors' alone {_percent(search.saving_motors)} less)",
        ),
    ]
    return "\n".join(lines)


@click.command()
@click.argument("robot_name", metavar="ROBOT")
@click.argument("program_file", metavar="PROGRAM.script")
@click.option("--x", "x", required=True, metavar="MIN:MAX", help="Base shift along x, m.")
@click.option("--y", "y", required=True, metavar="MIN:MAX", help="Base shift along y, m.")
@click.option("--z", "z", default=None, metavar="MIN:MAX", help="Base shift along z, m [0:0].")
@click.option(
    "--yaw", "yaw", default=None, metavar="MIN:MAX", help="Base turn about the vertical, deg [0:0]."
)
@click.option(
    "--step", type=float, default=0.1, show_default=True, help="Grid step of x, y, z, m (> 0)."
)
@click.option(
    "--yaw-step",
    "yaw_step",
    type=float,
    default=15.0,
    show_default=True,
    help="Grid step, deg (> 0).",
)
@output_file_option("--urscript", "Write the best placement's optimised program to this file.")
@output_file_option("--plot", "Write the energy map to this PNG.", metavar="FILE.png")
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
@payload_option
@click.option(
    "--cycle-time",
    "cycle_time",
    type=CycleTime(),
    default="same",
    show_default=True,
    metavar="SECONDS|same",
    help="Cycle time of every candidate; 'same': today's program's own.",
)
@click.option(
    "--v-max", "v_max", type=float, default=None, help="Cap on every joint's speed, rad/s "
    "[default: today's program's peak]."
)  # fmt: skip
@click.option(
    "--a-max", "a_max", type=float, default=None, help="Cap on every joint's acceleration, "
    "rad/s² [default: today's program's peak]."
)  # fmt: skip
@lever_options()
@writes(files=("urscript", "plot"), inputs=("robot_name", "program_file"))
def place(
    robot_name: str,
    program_file: str,
    x: str,
    y: str,
    z: str | None,
    yaw: str | None,
    step: float,
    yaw_step: float,
    urscript: str | None,
    plot: str | None,
    as_json: bool,
    payload: str | None,
    cycle_time: float | None,
    v_max: float | None,
    a_max: float | None,
    configurations: api.Configurations,
    tool_symmetry: api.ToolSymmetry,
    via: api.ViaPoints,
    no_blends: bool,
    standby: float | None,
) -> None:
    """Where the robot should stand: the program's energy over base placements around today's.

    Every candidate (x, y, z shifts and yaw turns of the base in today's base frame, on a grid of
    --step) gets the program's poses re-expressed in its moved base frame, is checked for reach
    (every pose, every limit) and optimised with the levers at today's cycle time within today's
    caps. Unreachable candidates are listed with the reason. Prints the map, today's placement
    and the best, whose optimised program --urscript writes (read back and simulated again).
    At most 400 candidates.
    """
    with as_usage():
        grid = api.PlacementGrid(
            x=parse_range(x, "--x", "m"),
            y=parse_range(y, "--y", "m"),
            z=parse_range(z, "--z", "m"),
            yaw=parse_range(yaw, "--yaw", "deg", math.pi / 180.0),
            step=step,
            yaw_step=math.radians(yaw_step),
        )
    options = program_options(
        configurations=configurations, tool_symmetry=tool_symmetry, via=via, no_blends=no_blends,
        standby=standby, cycle_time=cycle_time, v_max=v_max, a_max=a_max,
    )  # fmt: skip
    robot = load(robot_name, payload)
    with progress() as say:
        run = api.place(
            robot, program_file, grid, options, urscript=urscript, plot=plot, progress=say
        )
    if as_json:
        click.echo(json_result(run.to_dict()))
        return
    click.echo(place_text(run))
    for path in run.written:
        click.echo(f"wrote {path}")
