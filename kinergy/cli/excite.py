"""``kinergy excite``: an optimised Fourier excitation for identification, written as a motion file
and optionally as a URScript servoj program.

Designs the trajectory with :func:`kinergy.experiments.excitation.design_excitation` (nursing eqs
22-23: Fourier series, zero speed and acceleration at both ends, joint, speed, acceleration and
floor limits, minimum condition number or D-optimality of the stacked regressor), reports its
condition number and constraint margins, and writes ``--periods`` repeats of it at 500 Hz in
UR's record.py layout (``timestamp target_q_* target_qd_* target_qdd_*``), the motion file
``kinergy simulate ROBOT --trajectory FILE`` runs on the twin. ``--compare N`` also draws N random
feasible Fourier trajectories of the same size and prints their median condition number.
"""

from __future__ import annotations

import functools
import json
import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click
import numpy as np

from kinergy.errors import KinergyError

__all__ = ["excite"]

#: report progress every this many SLSQP iterations
_PROGRESS_EVERY = 10


class _OneLineError(click.ClickException):
    """A user error shown as one ``kinergy: error: ...`` line (exit status 1), the same whether
    the command runs under ``kinergy.cli.main`` or on its own."""

    def show(self, file: Any = None) -> None:
        click.echo(f"kinergy: error: {self.format_message()}", err=True)


def _one_line_errors(func: Callable[..., None]) -> Callable[..., None]:
    """Turn a :class:`KinergyError` into :class:`_OneLineError`."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> None:
        try:
            func(*args, **kwargs)
        except KinergyError as exc:
            raise _OneLineError(str(exc)) from None

    return wrapper


def _degrees(option: str, text: str | None, n: int) -> np.ndarray | None:
    """``"0,-90,0,-90,0,0"`` (deg) -> rad, shape (n,)."""
    if text is None:
        return None
    try:
        values = np.radians([float(x) for x in text.split(",")])
    except ValueError:
        raise KinergyError(
            f"{option}: expected {n} comma-separated angles in deg, got {text!r}"
        ) from None
    if values.shape != (n,) or not np.all(np.isfinite(values)):
        raise KinergyError(f"{option}: expected {n} comma-separated angles in deg, got {text!r}")
    return values


def _positive(option: str, value: float | None) -> None:
    if value is not None and not (math.isfinite(value) and value > 0.0):
        raise KinergyError(f"{option}: must be > 0, got {value:g}")


def _fmt_margins(margins: dict[str, float]) -> str:
    units = {"position": "rad", "speed": "rad/s", "acceleration": "rad/s^2", "floor": "m"}
    return ", ".join(f"{k} {margins[k]:.4g} {u}" for k, u in units.items() if k in margins)


@click.command()
@click.argument("robot_name", metavar="ROBOT")
@click.option("--harmonics", type=int, default=5, show_default=True, help="Harmonics N (>= 2).")
@click.option("--period", type=float, default=10.0, show_default=True, help="Period T, s.")
@click.option(
    "--periods",
    type=int,
    default=2,
    show_default=True,
    help="Periods written to the motion file (repeats help identification: cycle averaging).",
)
@click.option(
    "--out",
    "out",
    required=True,
    type=click.Path(dir_okay=False),
    metavar="MOTION.csv",
    help="Motion file to write (record.py layout, 500 Hz).",
)
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
@click.option(
    "--urscript",
    "urscript",
    type=click.Path(dir_okay=False),
    default=None,
    metavar="FILE",
    help="Also write a URScript program that runs the motion (movej to the start, servoj at 500 Hz).",
)
@click.option(
    "--criterion",
    type=click.Choice(["cond", "dopt"]),
    default="cond",
    show_default=True,
    help="Minimise the condition number or -log det (D-optimality) of the scaled regressor.",
)
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the random starts.")
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
    help="Acceleration limit, rad/s^2 [the robot's; 2/s times the speed limit where it has none].",
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
@_one_line_errors
def excite(
    robot_name: str,
    harmonics: int,
    period: float,
    periods: int,
    out: str,
    as_json: bool,
    urscript: str | None,
    criterion: str,
    seed: int,
    starts: int,
    maxiter: int,
    samples: int,
    floor: float,
    no_floor: bool,
    flange_only: bool,
    start_deg: str | None,
    range_deg: float,
    speed: float | None,
    acceleration: float | None,
    no_drives: bool,
    compare: int,
    quiet: bool,
) -> None:
    """Design an excitation trajectory for identification (nursing eqs 22-23) and write it.

    ROBOT is a built-in name or a model file. The trajectory is a Fourier series of N harmonics
    and period T starting and ending at rest in the start pose; its coefficients minimise the
    condition number of the stacked base regressor within the joint, speed, acceleration and
    floor limits. Progress goes to stderr.
    """
    from kinergy.experiments.excitation import (
        design_excitation,
        excitation_problem,
        random_feasible,
    )
    from kinergy.io.rtde import write_log
    from kinergy.io.urscript import servoj_program, write_script
    from kinergy.model import load_robot

    if periods < 1:
        raise KinergyError(f"--periods: must be >= 1, got {periods}")
    if starts < 1:
        raise KinergyError(f"--starts: must be >= 1, got {starts}")
    if maxiter < 1:
        raise KinergyError(f"--maxiter: must be >= 1, got {maxiter}")
    if compare < 0:
        raise KinergyError(f"--compare: must be >= 0, got {compare}")
    _positive("--period", period)
    _positive("--range-deg", range_deg)
    _positive("--speed", speed)
    _positive("--acceleration", acceleration)
    if not math.isfinite(floor):
        raise KinergyError(f"--floor: must be a height in m, got {floor}")
    robot = load_robot(robot_name)
    if urscript is not None and robot.n != 6:
        raise KinergyError(f"--urscript: URScript runs 6-joint UR arms; {robot.name} has {robot.n}")
    problem = excitation_problem(
        robot,
        harmonics=harmonics,
        period=period,
        start=_degrees("--start-deg", start_deg, robot.n),
        position_range=math.radians(range_deg),
        speed=speed,
        acceleration=acceleration,
        floor=None if no_floor else floor,
        floor_frames="flange" if flange_only else "links",
        criterion=criterion,
        include_drives=not no_drives,
        samples=samples,
    )
    clock = time.perf_counter()

    def progress(start: int, iteration: int, condition: float) -> None:
        if quiet or iteration % _PROGRESS_EVERY:
            return
        click.echo(
            f"[{time.perf_counter() - clock:6.1f} s] start {start}/{starts}, "
            f"iteration {iteration}: condition number {condition:.4g}",
            err=True,
        )

    best = design_excitation(problem, starts=starts, seed=seed, maxiter=maxiter, progress=progress)
    randoms = []
    if compare:
        if not quiet:
            click.echo(f"drawing {compare} random feasible trajectories", err=True)
        randoms = [
            e.condition for e in random_feasible(problem, np.random.default_rng(seed + 1), compare)
        ]
    median = float(np.median(randoms)) if randoms else None

    motion = best.repeated(periods)
    script = None
    if urscript is not None:
        script = servoj_program(
            motion.t,
            motion.q,
            name="kinergy_excitation",
            comments=[
                f"{robot.name}: excitation of {best.harmonics} harmonics, period "
                f"{best.period:g} s, {periods} period(s); condition number {best.condition:.4g}"
            ],
        )
    written: list[Path] = []
    try:
        write_log(
            out,
            motion.t,
            {"target_q": motion.q, "target_qd": motion.qd, "target_qdd": motion.qdd},
        )
        written.append(Path(out))
        if script is not None and urscript is not None:
            written.append(write_script(urscript, script))
    except BaseException:
        for path in written:
            path.unlink(missing_ok=True)
        raise

    if as_json:
        report: dict[str, Any] = {
            "robot": robot.name,
            **best.to_dict(),
            "periods": periods,
            "samples": len(motion),
            "duration": motion.duration,
            "columns": problem.columns,
            "limits": {
                "lower": problem.lower.tolist(),
                "upper": problem.upper.tolist(),
                "speed": problem.speed.tolist(),
                "acceleration": problem.acceleration.tolist(),
                "floor": problem.floor,
            },
            "random": None
            if median is None
            else {"count": len(randoms), "median": median, "conditions": randoms},
            "ratio": None if median is None else median / best.condition,
            "out": out,
            "urscript": urscript,
        }
        click.echo(json.dumps(report, indent=2))
        return
    click.echo(
        f"{robot.name}: {best.harmonics} harmonics, period {best.period:g} s, {periods} period(s) "
        f"({motion.duration:.3f} s, {len(motion)} samples at {1.0 / problem.dt:g} Hz)"
    )
    line = (
        f"condition number {best.condition:.4g} ({problem.columns} columns, criterion {criterion}"
    )
    if median is not None:
        line += (
            f"; median of {len(randoms)} random feasible trajectories {median:.4g}, "
            f"{median / best.condition:.1f}x higher"
        )
    click.echo(line + ")")
    click.echo(f"margins to the limits: {_fmt_margins(best.margins)}")
    click.echo(
        f"optimised in {best.seconds:.1f} s ({starts} start(s), best after {best.iterations} iterations)"
    )
    click.echo(f"wrote {out}" + (f" and {urscript}" if urscript else ""))
