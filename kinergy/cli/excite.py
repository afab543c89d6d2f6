"""``kinergy excite``: an optimised Fourier excitation for identification, written as a motion file
and optionally as a URScript servoj program.

Parses the flags into :class:`~kinergy.workflows.excite.ExciteOptions` (which checks them: one
line per bad flag), runs :func:`kinergy.api.excite` (nursing eqs 22-23: Fourier series, zero
speed and acceleration at both ends, joint, speed, acceleration and floor limits, minimum
condition number or D-optimality of the stacked regressor; ``--compare N`` also draws N random
feasible Fourier trajectories of the same size) and prints its condition number and constraint
margins, as text or JSON.
"""

from __future__ import annotations

from collections.abc import Mapping

import click

from kinergy import api
from kinergy.cli.common import (
    as_usage,
    choice_of,
    json_result,
    output_file_option,
    progress,
    refuse_together,
    seed_option,
    writes,
)
from kinergy.experiments.excitation_regression import Criterion

__all__ = ["excite", "excite_text"]


def _fmt_margins(margins: Mapping[str, float]) -> str:
    units = {"position": "rad", "speed": "rad/s", "acceleration": "rad/s²", "floor": "m"}
    return ", ".join(f"{k} {margins[k]:.4g} {u}" for k, u in units.items() if k in margins)


def excite_text(run: api.ExciteRun) -> str:
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
@click.option("--harmonics", type=int, default=5, show_default=True, help="Harmonics N (2 to 50).")
@click.option("--period", type=float, default=10.0, show_default=True, help="Period T, s.")
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
    type=choice_of(Criterion),
    default=Criterion.COND.value,
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
    type=float,
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
    type=float,
    default=90.0,
    show_default=True,
    help="Half-width of each joint's range about the start pose, deg (within the robot's limits).",
)
@click.option("--speed", type=float, default=None, help="Speed limit, rad/s [the robot's].")
@click.option(
    "--acceleration",
    type=float,
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
def excite(
    robot_name: str,
    as_json: bool,
    quiet: bool,
    no_floor: bool,
    flange_only: bool,
    floor: float,
    no_drives: bool,
    out: str,
    urscript: str | None,
    harmonics: int,
    period: float,
    periods: int,
    criterion: Criterion,
    seed: int,
    starts: int,
    maxiter: int,
    samples: int,
    start_deg: str | None,
    range_deg: float,
    speed: float | None,
    acceleration: float | None,
    compare: int,
) -> None:
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
    with as_usage():
        options = api.ExciteOptions(
            out=out, urscript=urscript, harmonics=harmonics, period=period, periods=periods,
            criterion=criterion, seed=seed, starts=starts, maxiter=maxiter, samples=samples,
            floor=None if no_floor else floor,
            floor_frames=api.FloorFrames.FLANGE if flange_only else api.FloorFrames.LINKS,
            start_deg=start_deg,  # type: ignore[arg-type]  # parsed on construction
            range_deg=range_deg, speed=speed, acceleration=acceleration,
            include_drives=not no_drives, compare=compare,
        )  # fmt: skip
    with progress(quiet=quiet) as say:
        run = api.excite(robot_name, options, progress=say)
    click.echo(json_result(run) if as_json else excite_text(run))
