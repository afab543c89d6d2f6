"""``kinergy optimize``: a robot program (a URScript program or a task) doing the same job with
less energy at a cycle time.

Parses the flags into :class:`~kinergy.optimize.options.ProgramOptions` (which checks them),
runs :func:`kinergy.api.optimize_program` (the one optimiser: the levers and the timing, all
re-simulated at 500 Hz, the Pareto front where asked, the URScript, plot and motion files) and
prints its result as text or JSON.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

import click

from kinergy import api
from kinergy.accounting.uncertainty import NO_UNCERTAINTY
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
from kinergy.model.uncertainty import Interval
from kinergy.optimize import ParetoPoint, ProgramResult
from kinergy.optimize.levers import Lever
from kinergy.optimize.options import MAX_CYCLE_TIME

__all__ = ["CycleTime", "lever_options", "optimize", "optimize_text", "program_options"]

F = TypeVar("F", bound=Callable[..., Any])


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
    headers = ["move", "v", "a", "t [s]", "E [J]", "v opt", "a opt", "t opt"]
    return table([*headers, "E opt"], rows)


def _pareto_table(front: Sequence[ParetoPoint]) -> str:
    def energy(value: float | None, ok: bool) -> str:
        if value is None:
            return "cannot run"
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


def _saving_interval(iv: Interval | None) -> str:
    """The saving's 95 % interval, and how to read it (or why there is none)."""
    if iv is None:
        return f"Saving's 95 % interval: none: {NO_UNCERTAINTY}."
    verdict = (
        "not established: the interval includes 0"
        if iv.low <= 0.0 <= iv.high
        else "established: the interval excludes 0"
    )
    return (
        f"Saving's 95 % interval: {100 * iv.low:.1f} % .. {100 * iv.high:.1f} % ({verdict}; the "
        "program and the optimised one on the same parameter errors)"
    )


def _levers_table(levers: Sequence[Lever]) -> str:
    rows = [
        [
            lv.name,
            f"{lv.result.cycle_time:.3f}",
            f"{lv.result.e_supply:.1f}",
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


def _saving(run: api.OptimizeRun) -> list[str]:
    """The saving against the supply and against the motors, the read-back, the solver."""
    result = run.result
    own, opt = result.program.result, result.optimized.result
    lines = [
        f"Saving: {100 * result.saving_supply:.1f} % of what the arm draws from its supply per "
        f"cycle ({own.e_supply:.1f} J -> {opt.e_supply:.1f} J: the motors on the DC bus, braking "
        f"lost in the shunt, plus the standing draw of {result.settings.standby:.1f} W over the "
        f"cycle); {100 * result.saving_motors:.1f} % of the motors' energy alone "
        f"({own.e_elec:.1f} J -> {opt.e_elec:.1f} J); model-predicted",
        f"The written program read back and simulated again: {run.readback:.1f} J "
        f"({100 * (run.readback / opt.e_supply - 1.0):+.2f} %)",
    ]
    if result.timing is not None:
        lines.append(
            f"Timing solver: {result.timing.words} ({result.timing.iterations} iterations); "
            "active limits: " + "; ".join(result.timing.active)
        )
    closest = ", ".join(
        f"{kind} {100 * ratio:.1f} % ({joint})"
        for kind, (ratio, joint, _) in opt.check.worst().items()
    )
    lines.append("Closest to a limit: " + closest)
    return lines


def optimize_text(run: api.OptimizeRun) -> str:
    """The ``optimize`` report: per move, per lever, the saving, the targets, the Pareto front."""
    result = run.result
    own, opt = result.program.result, result.optimized.result
    name = result.program.path.program.name
    stops = [c for c in result.targets if c.stop]
    lines = [
        f"{run.robot.name}, program {name}: {own.speeds.size} moves, cycle time "
        f"{opt.cycle_time:.3f} s (program as written {own.cycle_time:.3f} s)",
        "",
        "Per move: the program as written and the optimum (v and a in the move's units: rad/s "
        "and rad/s^2 for a movej, m/s and m/s^2 along a line; energies re-simulated at 500 Hz)",
        _moves_table(own, opt),
        "",
        "Levers, each on the program before it, at the cycle time (supply energy: motors on the "
        "DC bus, braking surplus lost, plus the standing draw; model-predicted)",
        _levers_table(result.levers),
        "",
        *_saving(run),
        _saving_interval(result.saving_interval),
    ]
    if stops:
        lines.append(
            f"Targets: {len(stops)} stops, worst {1e3 * max(c.distance for c in stops):.3f} mm, "
            f"{math.degrees(max(c.angle for c in stops)):.3f} deg, joint speed "
            f"{max(c.speed for c in stops):.2g} rad/s; "
            + ("all met" if result.targets_met else "NOT all met (1 mm, 0.5 deg, at rest)")
        )
    lines.append(
        f"Within limits: {'yes' if opt.ok else 'NO: ' + '; '.join(opt.check.violations())}"
    )
    left = [str(c.line) for c in result.targets if c.left_out]
    if left:
        lines.append(
            f"Via points left out of the route (free via points): line{'s' if len(left) > 1 else ''} "
            f"{', '.join(left)} now take the joints of the target before them"
        )
    lines += [f"note: {n}" for n in run.notes]
    out = [line if "\n" in line else prose(line) for line in lines]
    if result.pareto:
        out += ["", "Pareto front: supply energy against cycle time (re-simulated at 500 Hz)"]
        out.append(_pareto_table(result.pareto))
    return "\n".join(out)


def lever_options(prefix: str = "") -> Callable[[F], F]:
    """The levers of a program's optimisation as options (``prefix`` starts each help
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
    fixed_shares: bool = False,
) -> api.ProgramOptions:
    """The flags of the levers, the cycle time and the caps as the API's
    :class:`~kinergy.optimize.options.ProgramOptions` (a value it refuses: a usage error)."""
    with as_usage():
        return api.ProgramOptions(
            configurations=configurations, tool_symmetry=tool_symmetry, via=via,
            blends=not no_blends, fixed_shares=fixed_shares, standby=standby,
            cycle_time=cycle_time, v_max=v_max, a_max=a_max,
        )  # fmt: skip


@click.command()
@click.argument("model", metavar="MODEL")
@click.argument("task_name", metavar="PROGRAM")
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
    "your names and comments kept; a task: one movej per move).",
)
@output_file_option(
    "--plot",
    "Write the Pareto plot (supply energy against cycle time) to this PNG.",
    metavar="FILE.png",
)
@payload_option
@click.option(
    "--v-max",
    "v_max",
    type=float,
    default=None,
    help="Cap on every joint's speed, rad/s [default: the program's own peak].",
)
@click.option(
    "--a-max",
    "a_max",
    type=float,
    default=None,
    help="Cap on every joint's acceleration, rad/s² [default: the program's own peak].",
)
@click.option(
    "--pareto-points",
    "points",
    type=int,
    default=None,
    help=f"Cycle times on the Pareto front, 0 (none) to {api.MAX_POINTS} [default: "
    f"{api.PLOT_POINTS} with --plot, else 0].",
)
@click.option(
    "--fixed-shares",
    is_flag=True,
    help="Keep each move's share of the cycle time; choose only speeds and accelerations.",
)
@lever_options()
@click.option(
    "--motions",
    type=click.Path(file_okay=False),
    default=None,
    metavar="DIR",
    help="Write program.csv and optimized.csv (500 Hz) to this folder.",
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
    """A program doing the same job with less energy at the same cycle time.

    MODEL is a built-in robot or a model file; PROGRAM a URScript program (*.script), a task
    file (TOML: a movej program's joint targets) or test-a / test-b (the UR5e doc's test
    programs). Every lever (2 pi wraps, --configurations, --tool-symmetry, --via, blends,
    timing) is judged by the supply energy the model predicts (the motors on the DC bus,
    braking lost in the shunt, plus the arm's standing draw), re-simulated at 500 Hz with every
    speed, acceleration, torque and position limit checked at every sample, and kept only when
    it saves energy.
    """
    options = program_options(
        configurations=configurations,
        tool_symmetry=tool_symmetry,
        via=via,
        no_blends=no_blends,
        standby=standby,
        cycle_time=cycle_time,
        v_max=v_max,
        a_max=a_max,
        fixed_shares=fixed_shares,
    )
    with progress() as say:
        run = api.optimize_program(
            load(model, payload), task_name, options, points=points, urscript=urscript,
            motions=motions, plot=plot, progress=say,
        )  # fmt: skip
    click.echo(json_result(run.to_dict()) if as_json else optimize_text(run))
    if not as_json:
        for path in run.written:
            click.echo(f"wrote {path}")
