"""``kinergy optimize``: energy-optimal speeds and accelerations of a movej program.

Parses the flags into :class:`~kinergy.optimize.options.ProgramOptions` (which checks them),
runs :func:`kinergy.api.optimize_program` (the optimum at a cycle time against the program as
written and uniform time scaling, all re-simulated at 500 Hz, the Pareto front, the URScript and
plot files) and prints its result as text or JSON.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

import click

from kinergy import api
from kinergy.cli.common import (
    as_usage,
    choice_of,
    json_result,
    load,
    output_file_option,
    payload_option,
    progress,
    prose,
    table,
    writes,
)
from kinergy.optimize import ParetoPoint, ProgramResult, TimingResult
from kinergy.optimize.options import MAX_CYCLE_TIME
from kinergy.optimize.programs import Lever, supply

__all__ = ["CycleTime", "lever_options", "optimize", "optimize_text", "program_text"]

F = TypeVar("F", bound=Callable[..., Any])

_PARTS = ("friction", "copper", "inertial", "gravity")


class CycleTime(click.ParamType):
    """``--cycle-time SECONDS|same``: a number of seconds, or ``same`` (None: the program's
    own); the bounds are :class:`~kinergy.optimize.options.ProgramOptions`'."""

    name = "seconds|same"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        if value is None or isinstance(value, float):
            return value
        if str(value).strip().lower() == "same":
            return None
        try:
            return float(value)
        except ValueError:
            self.fail(f"expected seconds or 'same', got {value!r}", param, ctx)

    def shown(self, value: float | None) -> float | str:
        """The value as ``--json`` records the options given: ``same`` for None."""
        return "same" if value is None else value


def _moves_table(prog: ProgramResult, opt: ProgramResult) -> str:
    """Per move: ``v``, ``a``, duration and energy of the program as written and the optimum."""
    rows = [
        [
            str(k + 1),
            *(
                f"{x:.{d}f}"
                for p in (prog, opt)
                for x, d in (
                    (p.speeds[k], 3),
                    (p.accels[k], 2),
                    (p.durations[k], 3),
                    (p.e_moves[k], 1),
                )
            ),
        ]
        for k in range(prog.speeds.size)
    ]
    headers = ["move", "v [rad/s]", "a [rad/s²]", "t [s]", "E [J]", "v opt", "a opt", "t opt"]
    return table([*headers, "E opt"], rows)


def _totals_table(result: TimingResult) -> str:
    """Per program (as written, uniform scaling, optimum): cycle time, energy and its parts,
    and whether it keeps the limits."""
    rows = [
        [
            label,
            f"{p.cycle_time:.3f}",
            f"{p.e_elec:.1f}",
            *(f"{p.breakdown[k]:.1f}" for k in _PARTS),
            "yes" if p.ok else "NO: " + "; ".join(p.check.violations()),
        ]
        for label, p in (
            ("program as written", result.program),
            ("uniform scaling", result.uniform),
            ("optimised", result.optimized),
        )
    ]
    headers = ["", "cycle [s]", "E_elec [J]", *(f"{k} [J]" for k in _PARTS), "within limits"]
    return table(headers, rows)


def _summary(result: TimingResult) -> list[str]:
    """The saving, the active limits, how close the optimum comes to each, the solver."""
    opt = result.optimized
    saving = (
        f"saving: {100 * result.saving:.1f} % of E_elec against the program as written, "
        f"{100 * result.saving_vs_uniform:.1f} % against uniform scaling (E_elec: the motors' "
        "electrical energy with braking returned to the bus, UR5e eq 25; what the arm draws from "
        "its supply, braking burnt in the shunt: kinergy energy of the written program)"
    )
    if opt.predicted is not None:
        saving += f" (predicted by the optimiser {opt.predicted:.1f} J)"
    closest = ", ".join(
        f"{kind} {100 * ratio:.1f} % ({joint})"
        for kind, (ratio, joint, _) in opt.check.worst().items()
    )
    return [
        saving,
        "active limits: " + "; ".join(result.active),
        "closest to a limit: " + closest,
        f"solver: {result.message} ({result.iterations} iterations, {result.seconds:.2f} s)",
    ]


def _pareto_table(front: Sequence[ParetoPoint]) -> str:
    def energy(value: float, ok: bool) -> str:
        return f"{value:.1f}" + ("" if ok else " (over a limit)")

    rows = [
        [
            f"{p.cycle_time:.3f}",
            energy(p.optimized, p.optimized_ok),
            energy(p.uniform, p.uniform_ok),
        ]
        for p in front
    ]
    return table(["cycle [s]", "optimised [J]", "uniform [J]"], rows)


def optimize_text(run: api.OptimizeRun) -> str:
    """The ``optimize`` report: per move, the totals, the saving and limits, the Pareto front."""
    result, task = run.result, run.task
    lines = [
        f"{run.robot.name}, task {task.name}: {task.moves} moves, cycle time "
        f"{result.cycle_time:.3f} s (program as written {result.program.cycle_time:.3f} s, "
        f"fastest feasible {result.fastest_cycle_time:.3f} s)",
        "",
        "Per move: the program as written and the optimum (energies re-simulated at 500 Hz)",
        _moves_table(result.program, result.optimized),
        "",
        f"Totals at a cycle time of {result.cycle_time:.3f} s",
        _totals_table(result),
        "",
        *_summary(result),
    ]
    if run.front:
        lines += ["", "Pareto front: energy against cycle time (re-simulated at 500 Hz)"]
        lines.append(_pareto_table(run.front))
    return "\n".join(lines)


def _levers_table(levers: Sequence[Lever]) -> str:
    rows = [
        [
            lv.name,
            f"{lv.result.cycle_time:.3f}",
            f"{supply(lv.result):.1f}",
            f"{lv.result.e_elec:.1f}",
            "yes" if lv.result.ok else "NO",
            "" if lv.name == "program" else f"{lv.saved:+.1f}",
            lv.status.value + (f" ({lv.repaired})" if lv.repaired else ""),
            lv.note,
        ]
        for lv in levers
    ]
    headers = ["lever", "cycle [s]", "supply [J]", "motors [J]", "limits ok", "saved [J]"]
    return table([*headers, "used", "note"], rows)


def program_text(run: api.ProgramRun) -> str:
    """The ``optimize`` report of a URScript program: per move, per lever, the targets."""
    result = run.result
    own, opt = result.program.result, result.optimized.result
    name = result.program.path.program.name
    stops = [c for c in result.targets if c.stop]
    lines = [
        f"{run.robot.name}, program {name}: {own.speeds.size} moves, cycle time "
        f"{opt.cycle_time:.3f} s (program as written {own.cycle_time:.3f} s)",
        "",
        "Per move: the program as written and the optimum (energies re-simulated at 500 Hz)",
        _moves_table(own, opt),
        "",
        "Levers, each on the program before it, at the cycle time (supply energy: motors on the "
        "DC bus, braking surplus lost, plus standby; model-predicted)",
        _levers_table(result.levers),
        "",
        f"Saving: {100 * result.saving:.1f} % of the supply energy ({supply(own):.1f} J -> "
        f"{supply(opt):.1f} J); the written program read back and simulated again: "
        f"{run.readback:.1f} J ({100 * (run.readback / supply(opt) - 1.0):+.2f} %)",
        f"Targets: {len(stops)} stops, worst {1e3 * max(c.distance for c in stops):.3f} mm, "
        f"{math.degrees(max(c.angle for c in stops)):.3f} deg, joint speed "
        f"{max(c.speed for c in stops):.2g} rad/s; "
        + ("all met" if result.targets_met else "NOT all met (1 mm, 0.5 deg, at rest)"),
        f"Within limits: {'yes' if opt.ok else 'NO: ' + '; '.join(opt.check.violations())}",
    ]
    left = [str(c.line) for c in result.targets if c.left_out]
    if left:
        lines.append(
            f"Via points left out of the route (free via points): line{'s' if len(left) > 1 else ''} "
            f"{', '.join(left)} now take the joints of the target before them"
        )
    lines += [f"note: {n}" for n in run.notes]
    return "\n".join(line if "\n" in line else prose(line) for line in lines)


def lever_options(prefix: str = "") -> Callable[[F], F]:
    """The levers of a URScript program's optimisation as options (``prefix`` starts each help
    text): --configurations, --tool-symmetry, --via, --no-blends, --standby."""

    def said(text: str) -> str:
        return prefix + text if prefix else text[0].upper() + text[1:]

    options = [
        click.option(
            "--configurations",
            type=choice_of(api.Configurations),
            default=api.Configurations.KEEP.value,
            show_default=True,
            help=said("the IK branch of a movej's pose target (free: any of the eight)."),
        ),
        click.option(
            "--tool-symmetry",
            "tool_symmetry",
            type=choice_of(api.ToolSymmetry),
            default=api.ToolSymmetry.NONE.value,
            show_default=True,
            help=said("the tool may turn about its z axis (any angle, 180 or 90 deg)."),
        ),
        click.option(
            "--via",
            type=choice_of(api.ViaPoints),
            default=api.ViaPoints.KEEP.value,
            show_default=True,
            help=said(
                "joint-space via points (a movej's target followed by a movej, nothing "
                "at rest between; e.g. a home pose passed every cycle) stay on the route, or free: "
                "the route may leave them out."
            ),
        ),
        click.option("--no-blends", is_flag=True, help=said("no blend radii on via points.")),
        click.option(
            "--standby",
            type=float,
            default=None,
            help=said("standby power (W) counted over the cycle time [default: the robot file's]."),
        ),
    ]

    def decorate(func: F) -> F:
        for option in reversed(options):
            func = option(func)
        return func

    return decorate


def program_options(
    *,
    configurations: api.Configurations,
    tool_symmetry: api.ToolSymmetry,
    via: api.ViaPoints,
    no_blends: bool,
    standby: float | None,
    cycle_time: float | None,
    v_max: float | None,
    a_max: float | None,
) -> api.ProgramOptions:
    """The flags of the levers, the cycle time and the caps as the API's
    :class:`~kinergy.optimize.options.ProgramOptions` (a value it refuses: a usage error)."""
    with as_usage():
        return api.ProgramOptions(
            configurations=configurations, tool_symmetry=tool_symmetry, via=via,
            blends=not no_blends, standby=standby, cycle_time=cycle_time, v_max=v_max, a_max=a_max,
        )  # fmt: skip


@click.command()
@click.argument("model", metavar="MODEL")
@click.argument("task_name", metavar="TASK")
@click.option(
    "--cycle-time",
    "cycle_time",
    type=CycleTime(),
    default="same",
    show_default=True,
    metavar="SECONDS|same",
    help=f"Cycle-time budget (at most {MAX_CYCLE_TIME:g} s); 'same': the program's own.",
)
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
@output_file_option(
    "--urscript",
    "Write the optimised program as URScript to this file (a URScript program: as written, "
    "your names and comments kept; a task: movej per move).",
)
@output_file_option(
    "--plot", "Write the Pareto plot (energy against cycle time) to this PNG.", metavar="FILE.png"
)
@payload_option
@click.option(
    "--v-max", "v_max", type=float, default=None, help="Cap on every joint's speed, rad/s."
)
@click.option(
    "--a-max",
    "a_max",
    type=float,
    default=None,
    help="Cap on every joint's acceleration, rad/s² [default: the model's limits; a UR model "
    "has none, so the torque limits bound it].",
)
@click.option(
    "--pareto-points",
    "points",
    type=int,
    default=None,
    help=f"Tasks: cycle times on the Pareto front, 0 (none) to {api.MAX_POINTS} "
    f"[{api.TASK_POINTS}].",
)
@click.option(
    "--fixed-shares",
    is_flag=True,
    help="Tasks: keep each move's share of the cycle time; choose only speeds and accelerations.",
)
@lever_options("URScript programs: ")
@click.option(
    "--motions",
    type=click.Path(file_okay=False),
    default=None,
    metavar="DIR",
    help="URScript programs: write program.csv and optimized.csv (500 Hz) to this folder.",
)
@writes(files=("urscript", "plot"), into=("motions",), inputs=("model", "task_name"))
def optimize(
    model: str,
    task_name: str,
    cycle_time: float | None,
    as_json: bool,
    urscript: str | None,
    plot: str | None,
    payload: str | None,
    v_max: float | None,
    a_max: float | None,
    points: int | None,
    fixed_shares: bool,
    configurations: api.Configurations,
    tool_symmetry: api.ToolSymmetry,
    via: api.ViaPoints,
    no_blends: bool,
    standby: float | None,
    motions: str | None,
) -> None:
    """Energy-optimal speeds and accelerations of a movej program at a cycle time.

    MODEL is a built-in robot or a model file; TASK a task file (TOML: the movej's waypoints),
    test-a / test-b (the UR5e doc's test programs), or a URScript program (*.script: its path
    as well, with the levers --configurations, --tool-symmetry, --via and blends). Compares the
    optimum with the program as written and with uniform time scaling to the same cycle time,
    all re-simulated at 500 Hz with every speed, acceleration, torque and position limit
    checked at every sample.
    """
    options = program_options(
        configurations=configurations, tool_symmetry=tool_symmetry, via=via, no_blends=no_blends,
        standby=standby, cycle_time=cycle_time, v_max=v_max, a_max=a_max,
    )  # fmt: skip
    with progress() as say:
        run = api.optimize_program(
            load(model, payload), task_name, options, points=points,
            share_budget=not fixed_shares, urscript=urscript, motions=motions, plot=plot,
            progress=say,
        )  # fmt: skip
    if as_json:
        click.echo(json_result(run))
        return
    click.echo(program_text(run) if isinstance(run, api.ProgramRun) else optimize_text(run))
    for path in run.written:
        click.echo(f"wrote {path}")
