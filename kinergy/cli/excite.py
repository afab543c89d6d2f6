"""``kinergy excite``: an optimised Fourier excitation for identification, written as a motion file
and optionally as a URScript servoj program.

Parses the flags into :class:`~kinergy.workflows.excite.ExciteOptions` (each checked here: one
line per bad flag), runs :func:`kinergy.workflows.excite.run_excite` (nursing eqs 22-23: Fourier
series, zero speed and acceleration at both ends, joint, speed, acceleration and floor limits,
minimum condition number or D-optimality of the stacked regressor; ``--compare N`` also draws N
random feasible Fourier trajectories of the same size) and prints its condition number and
constraint margins, as text or JSON.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import click
import numpy as np

from kinergy.cli.common import (
    Finite,
    json_result,
    output_file_option,
    progress,
    refuse_together,
    seed_option,
    writes,
)
from kinergy.errors import KinergyError
from kinergy.experiments.excitation_regression import CRITERIA
from kinergy.model import Robot, load_robot
from kinergy.workflows.excite import ExciteOptions, ExciteRun, run_excite

__all__ = ["excite", "excite_options", "excite_text"]

#: flags that count something, and the least and most each may be (the most: sizes that fit in
#: memory and finish in minutes)
_COUNTS = {
    "harmonics": (2, 50),
    "periods": (1, 100),
    "starts": (1, 1000),
    "maxiter": (1, 100_000),
    "samples": (1, 20_000),
    "compare": (0, 10_000),
}
#: flags that must be > 0 when given, with their least and most values (s, deg, rad/s, rad/s^2)
_POSITIVE = {
    "period": (1e-2, 600.0),
    "range_deg": (1e-3, 360.0),
    "speed": (1e-3, 100.0),
    "acceleration": (1e-3, 1e4),
}


def _flag(name: str) -> str:
    """``range_deg`` -> ``--range-deg``."""
    return "--" + name.replace("_", "-")


def _degrees(option: str, text: str | None, n: int) -> tuple[float, ...] | None:
    """``"0,-90,0,-90,0,0"`` (deg) -> rad, n entries."""
    if text is None:
        return None
    message = f"{option}: expected {n} comma-separated angles in deg, got {text!r}"
    try:
        values = np.radians([float(x) for x in text.split(",")])
    except ValueError:
        raise KinergyError(message) from None
    if values.shape != (n,) or not np.all(np.isfinite(values)):
        raise KinergyError(message)
    return tuple(float(v) for v in values)


def _check_flags(robot: Robot, flags: Mapping[str, Any]) -> None:
    """Counts, positive numbers, a finite floor, URScript only for a 6-joint arm."""
    for name, (least, most) in _COUNTS.items():
        if flags[name] < least:
            raise KinergyError(f"{_flag(name)}: must be >= {least}, got {flags[name]}")
        if flags[name] > most:
            raise KinergyError(f"{_flag(name)}: must be at most {most}, got {flags[name]}")
    for name, (low, high) in _POSITIVE.items():
        value = flags[name]
        if value is not None and not (math.isfinite(value) and value > 0.0):
            raise KinergyError(f"{_flag(name)}: must be > 0, got {value:g}")
        if value is not None and not low <= value <= high:
            raise KinergyError(f"{_flag(name)}: must be from {low:g} to {high:g}, got {value:g}")
    if not math.isfinite(flags["floor"]) or abs(flags["floor"]) > 100.0:
        raise KinergyError(f"--floor: must be a height in m, got {flags['floor']}")
    if flags["urscript"] is not None and robot.n != 6:
        raise KinergyError(f"--urscript: URScript runs 6-joint UR arms; {robot.name} has {robot.n}")


def excite_options(robot: Robot, flags: Mapping[str, Any]) -> ExciteOptions:
    """The command line's flags (by parameter name) as the workflow's options, SI units.

    Raises
    ------
    KinergyError
        One line naming the first bad flag.
    """
    _check_flags(robot, flags)
    return ExciteOptions(
        out=flags["out"],
        urscript=flags["urscript"],
        harmonics=flags["harmonics"],
        period=flags["period"],
        periods=flags["periods"],
        criterion=flags["criterion"],
        seed=flags["seed"],
        starts=flags["starts"],
        maxiter=flags["maxiter"],
        samples=flags["samples"],
        floor=None if flags["no_floor"] else flags["floor"],
        floor_frames="flange" if flags["flange_only"] else "links",
        start=_degrees("--start-deg", flags["start_deg"], robot.n),
        position_range=math.radians(flags["range_deg"]),
        speed=flags["speed"],
        acceleration=flags["acceleration"],
        include_drives=not flags["no_drives"],
        compare=flags["compare"],
    )


def _fmt_margins(margins: Mapping[str, float]) -> str:
    units = {"position": "rad", "speed": "rad/s", "acceleration": "rad/s²", "floor": "m"}
    return ", ".join(f"{k} {margins[k]:.4g} {u}" for k, u in units.items() if k in margins)


def excite_text(run: ExciteRun) -> str:
    """The ``excite`` report: size, condition number (against the random median), margins,
    optimiser effort, the files written."""
    best, motion, options = run.best, run.motion, run.options
    condition = (
        f"condition number {best.condition:.4g} ({run.problem.columns} columns, "
        f"criterion {options.criterion}"
    )
    if run.median is not None:
        condition += (
            f"; median of {len(run.randoms)} random feasible trajectories {run.median:.4g}, "
            f"{run.median / best.condition:.1f}x higher"
        )
    return "\n".join(
        [
            f"{run.robot.name}: {best.harmonics} harmonics, period {best.period:g} s, "
            f"{options.periods} period(s) ({motion.duration:.3f} s, {len(motion)} samples at "
            f"{1.0 / run.problem.dt:g} Hz)",
            condition + ")",
            f"margins to the limits: {_fmt_margins(best.margins)}",
            f"optimised in {best.seconds:.1f} s ({options.starts} start(s), best after "
            f"{best.iterations} iterations)",
            "wrote " + " and ".join(str(p) for p in (options.out, options.urscript) if p),
        ]
    )


@click.command()
@click.argument("robot_name", metavar="ROBOT")
@click.option("--harmonics", type=int, default=5, show_default=True, help="Harmonics N (>= 2).")
@click.option("--period", type=Finite(), default=10.0, show_default=True, help="Period T, s.")
@click.option(
    "--periods",
    type=int,
    default=2,
    show_default=True,
    help="Periods written to the motion file (repeats help identification: cycle averaging).",
)
@output_file_option(
    "--out", "Motion file to write (record.py layout, 500 Hz).", metavar="MOTION.csv", required=True
)
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
@output_file_option(
    "--urscript",
    "Also write a URScript program that runs the motion (movej to the start, servoj at 500 Hz).",
)
@click.option(
    "--criterion",
    type=click.Choice(CRITERIA),
    default="cond",
    show_default=True,
    help="Minimise the condition number or -log det (D-optimality) of the scaled regressor.",
)
@seed_option
@click.option(
    "--starts", type=int, default=4, show_default=True, help="Random feasible starting points."
)
@click.option(
    "--maxiter", type=int, default=100, show_default=True, help="SLSQP iterations per start."
)
@click.option(
    "--samples",
    type=int,
    default=200,
    show_default=True,
    help="Grid points per period for the criterion (the constraints use twice as many).",
)
@click.option(
    "--floor",
    type=Finite(),
    default=0.05,
    show_default=True,
    help="Height above the base plane the flange and link frames from the elbow on must keep, m.",
)
@click.option("--no-floor", is_flag=True, help="No floor constraint.")
@click.option(
    "--flange-only",
    is_flag=True,
    help="Keep only the flange (not the link frames) above the floor.",
)
@click.option(
    "--start-deg",
    "start_deg",
    default=None,
    metavar="Q1,...,Qn",
    help="Start and end pose, deg [6-joint arms: 0,-90,0,-90,0,0; else mid-range].",
)
@click.option(
    "--range-deg",
    "range_deg",
    type=Finite(),
    default=90.0,
    show_default=True,
    help="Half-width of each joint's range about the start pose, deg (within the robot's limits).",
)
@click.option("--speed", type=Finite(), default=None, help="Speed limit, rad/s [the robot's].")
@click.option(
    "--acceleration",
    type=Finite(),
    default=None,
    help="Acceleration limit, rad/s² [the robot's; 2/s times the speed limit where it has none].",
)
@click.option(
    "--no-drives",
    is_flag=True,
    help="Condition only the link base parameters (leave out rotor-inertia and friction columns).",
)
@click.option(
    "--compare",
    type=int,
    default=0,
    show_default=True,
    metavar="N",
    help="Also draw N random feasible trajectories of the same size and report their median.",
)
@click.option("--quiet", is_flag=True, help="No progress on stderr.")
@writes(files=("out", "urscript"), inputs=("robot_name",))
def excite(robot_name: str, as_json: bool, quiet: bool, **flags: Any) -> None:
    """Design an excitation trajectory for identification (nursing eqs 22-23) and write it.

    ROBOT is a built-in name or a model file. The trajectory is a Fourier series of N harmonics
    and period T starting and ending at rest in the start pose; its coefficients minimise the
    condition number of the stacked base regressor within the joint, speed, acceleration and
    floor limits. Progress goes to stderr.
    """
    refuse_together(
        ("no_floor", "floor", "no floor constraint, or one at that height?"),
        ("no_floor", "flange_only", "the flange above which floor?"),
    )
    robot = load_robot(robot_name)
    options = excite_options(robot, flags)
    with progress(quiet=quiet) as say:
        run = run_excite(robot, options, progress=say)
    click.echo(json_result(run.to_dict()) if as_json else excite_text(run))
