"""``kinergy optimize``: energy-optimal speeds and accelerations of a movej program.

Given a model and a task (the waypoints of a movej program, :mod:`kinergy.io.task`), finds the
per-move ``v`` and ``a`` that minimise the model's electrical energy at a cycle time
(:func:`kinergy.optimize.timing.optimize_timing`), compares them with the program as written and
with uniform time scaling, verifies all three by re-simulating them at 500 Hz, and computes the
Pareto front of energy against cycle time. Optionally writes the optimum as a URScript program
and the Pareto plot.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import click
import numpy as np

from kinergy.cli.common import table
from kinergy.errors import KinergyError
from kinergy.report.plots import timing_pareto

__all__ = ["optimize"]


def _cycle_time(text: str) -> float | None:
    """``same`` -> None (the program's own); otherwise seconds > 0."""
    if text.strip().lower() == "same":
        return None
    try:
        value = float(text)
    except ValueError:
        raise KinergyError(f"--cycle-time: expected seconds or 'same', got {text!r}") from None
    if not (math.isfinite(value) and value > 0.0):
        raise KinergyError(f"--cycle-time: must be > 0 s, got {text!r}")
    return value


def _positive(name: str, value: float | None) -> None:
    if value is not None and not (math.isfinite(value) and value > 0.0):
        raise KinergyError(f"{name}: must be > 0, got {value}")


def _text_report(result: Any, task: Any, pareto: Sequence[Any], robot_name: str) -> str:
    prog, uni, opt = result.program, result.uniform, result.optimized
    lines = [
        f"{robot_name}, task {task.name}: {task.moves} moves, cycle time {result.cycle_time:.3f} s "
        f"(program as written {prog.cycle_time:.3f} s, fastest feasible "
        f"{result.fastest_cycle_time:.3f} s)",
        "",
        "Per move: the program as written and the optimum (energies re-simulated at 500 Hz)",
    ]
    rows = []
    for k in range(task.moves):
        rows.append(
            [
                str(k + 1),
                f"{prog.speeds[k]:.3f}",
                f"{prog.accels[k]:.2f}",
                f"{prog.durations[k]:.3f}",
                f"{prog.e_moves[k]:.1f}",
                f"{opt.speeds[k]:.3f}",
                f"{opt.accels[k]:.2f}",
                f"{opt.durations[k]:.3f}",
                f"{opt.e_moves[k]:.1f}",
            ]
        )
    lines.append(
        table(
            [
                "move",
                "v [rad/s]",
                "a [rad/s^2]",
                "t [s]",
                "E [J]",
                "v opt",
                "a opt",
                "t opt",
                "E opt",
            ],
            rows,
        )
    )
    lines += ["", f"Totals at a cycle time of {result.cycle_time:.3f} s"]
    parts = ("friction", "copper", "inertial", "gravity")
    totals = []
    for label, p in (("program as written", prog), ("uniform scaling", uni), ("optimized", opt)):
        totals.append(
            [
                label,
                f"{p.cycle_time:.3f}",
                f"{p.e_elec:.1f}",
                *(f"{p.breakdown[k]:.1f}" for k in parts),
                "yes" if p.ok else "NO: " + "; ".join(p.check.violations()),
            ]
        )
    lines.append(
        table(
            ["", "cycle [s]", "E_elec [J]", *(f"{k} [J]" for k in parts), "within limits"],
            totals,
        )
    )
    lines += [
        "",
        f"saving: {100 * result.saving:.1f} % against the program as written, "
        f"{100 * result.saving_vs_uniform:.1f} % against uniform scaling "
        f"(predicted by the optimiser {opt.predicted:.1f} J)"
        if opt.predicted is not None
        else f"saving: {100 * result.saving:.1f} % against the program as written, "
        f"{100 * result.saving_vs_uniform:.1f} % against uniform scaling",
        "active limits: " + "; ".join(result.active),
    ]
    worst = opt.check.worst()
    lines.append(
        "closest to a limit: "
        + ", ".join(
            f"{kind} {100 * ratio:.1f} % ({joint})" for kind, (ratio, joint, _) in worst.items()
        )
    )
    lines.append(
        f"solver: {result.message} ({result.iterations} iterations, {result.seconds:.2f} s)"
    )
    if pareto:
        lines += ["", "Pareto front: energy against cycle time (re-simulated at 500 Hz)"]
        lines.append(
            table(
                ["cycle [s]", "optimized [J]", "uniform [J]"],
                [
                    [
                        f"{p.cycle_time:.3f}",
                        f"{p.optimized:.1f}" + ("" if p.optimized_ok else " (over a limit)"),
                        f"{p.uniform:.1f}" + ("" if p.uniform_ok else " (over a limit)"),
                    ]
                    for p in pareto
                ],
            )
        )
    return "\n".join(lines)


@click.command()
@click.argument("model", metavar="MODEL")
@click.argument("task_name", metavar="TASK")
@click.option(
    "--cycle-time",
    "cycle_time",
    default="same",
    show_default=True,
    metavar="SECONDS|same",
    help="Cycle-time budget; 'same': the program's own.",
)
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
@click.option(
    "--urscript",
    "urscript",
    type=click.Path(dir_okay=False),
    default=None,
    help="Write the optimised program as URScript (movej per move) to this file.",
)
@click.option(
    "--plot",
    "plot",
    type=click.Path(dir_okay=False),
    default=None,
    metavar="FILE.png",
    help="Write the Pareto plot (energy against cycle time) to this PNG.",
)
@click.option(
    "--payload",
    metavar="MASS[,CX,CY,CZ[,IXX,IYY,IZZ,IXY,IYZ,IXZ]]",
    help="Payload at the flange (replaces the model's): kg, m (flange frame), kg m^2.",
)
@click.option(
    "--v-max", "v_max", type=float, default=None, help="Cap on every joint's speed, rad/s."
)
@click.option(
    "--a-max",
    "a_max",
    type=float,
    default=None,
    help="Cap on every joint's acceleration, rad/s^2 [default: the model's limits; a UR model "
    "has none, so the torque limits bound it].",
)
@click.option(
    "--pareto-points",
    "points",
    type=click.IntRange(min=0),
    default=8,
    show_default=True,
    help="Cycle times on the Pareto front (0: none).",
)
@click.option(
    "--fixed-shares",
    is_flag=True,
    help="Keep each move's share of the cycle time; choose only speeds and accelerations.",
)
def optimize(
    model: str,
    task_name: str,
    cycle_time: str,
    as_json: bool,
    urscript: str | None,
    plot: str | None,
    payload: str | None,
    v_max: float | None,
    a_max: float | None,
    points: int,
    fixed_shares: bool,
) -> None:
    """Energy-optimal speeds and accelerations of a movej program at a cycle time.

    MODEL is a built-in robot or a model file; TASK a task file (TOML: the movej's waypoints)
    or test-a / test-b (the UR5e doc's test programs). Compares the optimum with the program as
    written and with uniform time scaling to the same cycle time, all re-simulated at 500 Hz
    with every speed, acceleration, torque and position limit checked at every sample.
    """
    from kinergy.io.task import load_task
    from kinergy.io.urscript import movej_program, write_script
    from kinergy.model import load_robot, parse_payload
    from kinergy.optimize.timing import optimize_timing, pareto_front, timing_problem

    budget = _cycle_time(cycle_time)
    _positive("--v-max", v_max)
    _positive("--a-max", a_max)
    if plot is not None and points < 2:
        raise KinergyError("--plot: needs a Pareto front (--pareto-points of at least 2)")
    robot = load_robot(model, payload=None if payload is None else parse_payload(payload))
    task = load_task(task_name, robot=robot)
    if task.waypoints.shape[1] != robot.n:  # pragma: no cover - load_task checks files
        raise KinergyError(f"{task_name}: the task has {task.waypoints.shape[1]} joints")
    try:
        problem = timing_problem(
            robot, task.waypoints, blends=task.blends, v_max=v_max, a_max=a_max
        )
        common: dict[str, Any] = {
            "speeds": task.speeds,
            "accels": task.accels,
            "blends": task.blends,
            "v_max": v_max,
            "a_max": a_max,
            "share_budget": not fixed_shares,
            "problem": problem,
        }
        result = optimize_timing(robot, task.waypoints, cycle_time=budget, **common)
        front = pareto_front(robot, task.waypoints, points=points, **common) if points else []
    except KinergyError as exc:
        raise exc.prefixed(f"{task.name}") from None

    script = None
    if urscript is not None:
        opt = result.optimized
        script = movej_program(
            task.waypoints,
            opt.speeds,
            opt.accels,
            task.ur_blends if np.any(task.ur_blends > 0.0) else None,
            name="kinergy_" + "".join(c if c.isalnum() else "_" for c in task.name),
            cycle_time=opt.cycle_time,
            energy=opt.e_elec,
            comments=[
                f"{robot.name}, task {task.name}: {100 * result.saving:.1f} % less energy than "
                f"the program as written ({result.program.e_elec:.1f} J) at the same cycle time"
            ],
        )
    figure = timing_pareto(result, front) if plot is not None else None

    written: list[Path] = []
    try:
        if figure is not None and plot is not None:
            from kinergy.report.plots import save

            written.append(save(figure, plot))
        if script is not None and urscript is not None:
            written.append(write_script(urscript, script))
    except BaseException:
        for path in written:
            path.unlink(missing_ok=True)
        raise

    if as_json:
        out = result.to_dict()
        out["robot"] = robot.name
        out["task"] = task.name
        out["pareto"] = [p.to_dict() for p in front]
        click.echo(json.dumps(out, indent=2, allow_nan=False))
        return
    click.echo(_text_report(result, task, front, robot.name))
    for path in written:
        click.echo(f"wrote {path}")
