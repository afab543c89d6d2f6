"""The optimiser: a robot program doing the same job with less energy, at a cycle time.

:func:`optimize_program` takes a :class:`~kinergy.trajectory.robot_program.RobotProgram` (read
from a URScript file, or a task file's movej program, :mod:`kinergy.io.task`) and returns the
same program (same moves, events and line order) with changed targets, blend radii, speeds and
accelerations that does the same job with less supply energy
(:class:`kinergy.optimize.objectives.SupplyEnergy`: the motors on the DC bus, braking surplus
lost, plus the arm's standing draw over the cycle) at the same cycle time. The levers, in order
(:mod:`kinergy.optimize.levers`), each judged at the cycle time, repaired first should it break a
limit there (:mod:`kinergy.optimize.repair`), and kept only if its re-simulation scores better
than the program before it:

1. ``2 pi``: every joint target takes the ``2 pi`` turn nearest the joints it comes from, within
   the joint limits (it changes no pose: always on);
2. ``configurations`` (``free``): a movej's pose target may take any inverse-kinematics branch
   (``keep``, the default, keeps the program's: a new branch can collide with the cell);
3. ``tool symmetry`` (``z``, ``z2``, ``z4``): a target may turn about the tool's z axis;
4. ``via points`` (``free``): a joint-space via point (such as a home pose passed every cycle)
   may be left out of the route (``keep``, the default: the route may avoid something);
5. ``blends``: via points (a move followed by a move, no event between) get a blend radius of
   40 % of the shorter tool distance of the two moves, at most 10 cm;
6. ``timing``: every move's ``v`` and ``a`` (:func:`kinergy.optimize.timing.retime`).

Levers 1-4 are one search (:mod:`kinergy.optimize.search`: dynamic programming over the targets'
states with a cheap energy estimate of every move, :mod:`kinergy.optimize.path_costs`), restricted
per lever. Every figure is a 500 Hz re-simulation (:func:`kinergy.optimize.verify.simulate_path`)
at the cycle time, with every joint limit checked at every sample and, by default, no joint
faster or harder than the program itself moves (:class:`kinergy.optimize.problem.Caps`). Every
step stops on iteration limits and tolerances, never on a clock: the same program on every host.
:func:`pareto_front` re-times the optimised path at other cycle times.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from kinergy.accounting.uncertainty import NO_UNCERTAINTY
from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.messages import Say, as_say
from kinergy.model.robot import Robot
from kinergy.model.uncertainty import Interval, interval
from kinergy.optimize.levers import (
    Lever,
    LeverSearch,
    LeverStatus,
    PathLevers,
    path_levers,
    timed,
    via_blends,
    with_timing,
)
from kinergy.optimize.objectives import Objective, SupplyEnergy
from kinergy.optimize.options import ProgramOptions, ToolSymmetry, ViaPoints
from kinergy.optimize.problem import Caps
from kinergy.optimize.repair import Context, at_cycle
from kinergy.optimize.samples import serial
from kinergy.optimize.timing import NO_ROOM, Verified, check_cycle_time, retime
from kinergy.optimize.verify import PathRun, TargetCheck, target_errors
from kinergy.trajectory.program_path import ProgramPath, program_path
from kinergy.trajectory.robot_program import RobotProgram

__all__ = [
    "MAX_MOVES",
    "TARGET_TOL",
    "ParetoPoint",
    "ProgramOptimization",
    "ProgramSettings",
    "optimize_program",
    "pareto_front",
    "program_settings",
]


#: targets are met within these (m, rad) and the arm is at rest below this joint speed (rad/s)
TARGET_TOL = (1e-3, np.deg2rad(0.5), 1e-3)
#: the most moves a program may have (a 30-move program takes under a minute on two cores)
MAX_MOVES = 100


@dataclass(frozen=True)
class ProgramSettings:
    """The options an optimisation ran with, resolved: the robot file's standing draw where none
    was given, the program's own peaks as caps, its own cycle time.

    Attributes
    ----------
    options : ProgramOptions
        As given.
    standby : float
        W.
    caps : Caps
        Joint speed (rad/s) and acceleration (rad/s^2) caps.
    cycle_time : float
        s.
    """

    options: ProgramOptions
    standby: float
    caps: Caps
    cycle_time: float

    def to_dict(self) -> dict[str, Any]:
        return {
            "configurations": self.options.configurations.value,
            "tool_symmetry": self.options.tool_symmetry.value,
            "via_points": self.options.via.value,
            "blends": self.options.blends,
            "fixed_shares": self.options.fixed_shares,
            "standby": self.standby,
            "v_max": self.caps.speed,
            "a_max": self.caps.acceleration,
            "cycle_time": self.cycle_time,
        }


@dataclass(frozen=True)
class ParetoPoint:
    """The supply energy at one cycle time: the optimised path re-timed and the program as
    written uniformly scaled, re-simulated at 500 Hz (J), and whether each keeps every limit at
    every sample (None: the program cannot run at that cycle time)."""

    cycle_time: float
    optimized: float | None
    uniform: float
    optimized_ok: bool
    uniform_ok: bool

    def to_dict(self) -> dict[str, Any]:
        return {
            "cycle_time": self.cycle_time,
            "optimized": self.optimized,
            "uniform": self.uniform,
            "optimized_within_limits": self.optimized_ok,
            "uniform_within_limits": self.uniform_ok,
        }


@dataclass(frozen=True, eq=False)
class ProgramOptimization:
    """What :func:`optimize_program` found.

    Attributes
    ----------
    program, optimized : PathRun
        The program as written and the optimised one, each re-simulated at 500 Hz.
    levers : tuple of Lever
        Each lever's figure in order, the last ``timing only``: the program as written, only
        re-timed (kept when it beats the levers before it).
    targets : list of TargetCheck
        The optimised program at every target of the original.
    settings : ProgramSettings
        The options used.
    timing : Verified or None
        How the timing lever's solution came about (None when it could not run).
    pareto : tuple of ParetoPoint
        Energy against cycle time (:func:`pareto_front`), empty unless asked for.
    """

    program: PathRun
    optimized: PathRun
    levers: tuple[Lever, ...]
    targets: list[TargetCheck]
    settings: ProgramSettings
    timing: Verified | None = None
    pareto: tuple[ParetoPoint, ...] = ()

    @property
    def written(self) -> RobotProgram:
        """The optimised program with its moves' ``v`` and ``a`` as it runs (what to write)."""
        return with_timing(self.optimized.path, self.optimized.result)

    @property
    def saving(self) -> float:
        """Share of the supply energy saved (the objective), 0-1."""
        return self.saving_supply

    @property
    def saving_supply(self) -> float:
        """Share of what the arm draws from its supply per cycle saved, 0-1: the motors and the
        standing draw over the cycle."""
        return 1.0 - self.optimized.result.e_supply / self.program.result.e_supply

    @property
    def saving_motors(self) -> float:
        """Share of the motors' energy saved (on the DC bus, braking surplus lost), 0-1."""
        return 1.0 - self.optimized.result.e_elec / self.program.result.e_elec

    @property
    def saving_gradient(self) -> Array | None:
        """The saving's gradient over the model's parameter errors: of ``1 - S_o / S_p``,
        ``(S_o g_p / S_p - g_o) / S_p`` with the program's and the optimised one's supply
        energies ``S`` and their gradients ``g`` on the same parameters, so that errors both
        share cancel; None when the model carries none (:mod:`kinergy.model.uncertainty`)."""
        p, o = self.program, self.optimized
        if p.errors is None or p.gradient is None or o.gradient is None:
            return None
        g_p, g_o = p.gradient.copy(), o.gradient.copy()
        if "standby_power" in p.errors.parameters and self.settings.options.standby is None:
            k = p.errors.parameters.index("standby_power")
            g_p[k] += p.result.cycle_time
            g_o[k] += o.result.cycle_time
        s_p, s_o = p.result.e_supply, o.result.e_supply
        return (s_o * g_p / s_p - g_o) / s_p

    @property
    def saving_interval(self) -> Interval | None:
        """The saving's 95 % interval (0-1) from :attr:`saving_gradient` (None without errors)."""
        g = self.saving_gradient
        return None if g is None else interval(self.program.errors, self.saving, g)

    def _interval_dict(self) -> dict[str, Any]:
        iv = self.saving_interval
        if iv is None:
            return {"note": NO_UNCERTAINTY}
        return {
            "low": iv.low,
            "high": iv.high,
            "std": iv.std,
            "level": iv.level,
            "method": iv.method,
        }

    @property
    def targets_met(self) -> bool:
        """Every stop within 1 mm and 0.5 deg of its target and at rest."""
        dist, angle, speed = TARGET_TOL
        return all(
            c.distance <= dist and c.angle <= angle and c.speed <= speed
            for c in self.targets
            if c.stop
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "program": self.program.result.to_dict(),
            "optimized": self.optimized.result.to_dict(),
            "saving": self.saving,
            "saving_supply": self.saving_supply,
            "saving_motors": self.saving_motors,
            "levers": [lever.to_dict() for lever in self.levers],
            "timing": None if self.timing is None else self.timing.to_dict(),
            "targets": [c.to_dict() for c in self.targets],
            "targets_met": self.targets_met,
            "settings": self.settings.to_dict(),
            "pareto": [p.to_dict() for p in self.pareto],
            "saving_interval": self._interval_dict(),
        }


def _as_written(
    robot: Robot, path: ProgramPath, objective: Objective, options: ProgramOptions, standby: float
) -> tuple[PathRun, Caps]:
    """The program re-simulated against the caps, and the caps: ``v_max`` and ``a_max``, or the
    program's own peak joint speed and acceleration."""
    own = Context(robot, 1.0, objective, Caps(np.inf, np.inf), standby).run(path, "program")
    caps = Caps(
        float(np.max(np.abs(own.motion.qd))) if options.v_max is None else options.v_max,
        float(np.max(np.abs(own.motion.qdd))) if options.a_max is None else options.a_max,
    )
    checked = Context(robot, 1.0, objective, caps, standby).run(path, "program")
    return checked, caps


def _timing_only(search: LeverSearch, path: ProgramPath, say: Callable[[str], None]) -> None:
    """The program as written, only re-timed, judged against the levers' best: kept when it
    beats them (a lever chain whose own re-timing stopped short of it), recorded either way
    (what re-timing alone saves). When no path lever was kept the timing lever re-timed this
    very path: its figure is recorded again."""
    timing = next((lv for lv in search.levers if lv.name == "timing"), None)
    if timing is not None and search.best.path.program.moves == path.program.moves:
        note = "the program as written, re-timed: as the timing lever (no path lever was kept)"
        status = LeverStatus.NOT_BETTER if timing.kept else timing.status
        search.record(Lever("timing only", timing.result, status, 0.0, note, timing.repaired))
        return
    say("timing only: re-timing the program as written")
    try:
        result, verified = retime(
            search.ctx.checks(path), search.budget, share_budget=search.ctx.share_budget, starts=1
        )
    except KinergyError as exc:  # the timing model's fastest is above the budget
        note = f"the program as written, re-timed: no room: the solver keeps {NO_ROOM}; {exc}"
        search.record(Lever("timing only", search.best.result, LeverStatus.NOT_POSSIBLE, note=note))
        return
    none = np.zeros(path.moves, dtype=bool)
    search.judge(
        "timing only",
        with_timing(path, result),
        f"the program as written, re-timed: {verified.words}",
        left_out=(none, none),
    )


def _context(
    robot: Robot,
    program: RobotProgram,
    options: ProgramOptions,
    objective: Objective | None,
    path: ProgramPath | None = None,
) -> tuple[ProgramPath, PathRun, Context]:
    """The program resolved (``path``, when the caller has it) and run as written, and the
    context every lever is judged in (the cycle time checked against the fastest possible once,
    here)."""
    if len(program.moves) > MAX_MOVES:
        raise KinergyError(
            f"{program.path or program.name}: {len(program.moves)} moves; the optimiser takes "
            f"at most {MAX_MOVES} (split the program)"
        )
    standby = robot.standby_power if options.standby is None else options.standby
    objective = SupplyEnergy(standby) if objective is None else objective
    path = program_path(robot, program) if path is None else path
    if not np.any(path.travel > 0.0):
        raise KinergyError(
            f"{program.path or program.name}: no move changes the arm's position; nothing to "
            "optimise"
        )
    own, caps = _as_written(robot, path, objective, options, standby)
    budget = own.result.cycle_time if options.cycle_time is None else options.cycle_time
    ctx = Context(robot, budget, objective, caps, standby, share_budget=not options.fixed_shares)
    if options.cycle_time is not None:
        check_cycle_time(ctx.checks(path).problem, path, budget)
    return path, own, ctx


class _Steps:
    """:func:`optimize_program`'s progress: each step it starts, with the steps done of those
    planned (simulating the program, uniform scaling to a cycle time given, the ``2 pi`` wraps and their estimate, each path lever
    asked for, blends, timing, timing only, the targets' check: an upper bound, as a lever
    with no cycle of states or a timing only that repeats the timing says nothing), so that a
    terminal shows a fraction and the time left (:class:`kinergy.messages.Say`)."""

    def __init__(self, say: Say, options: ProgramOptions) -> None:
        self.say = say
        path_levers = sum(
            (
                options.configurations.value == "free",
                options.tool_symmetry is not ToolSymmetry.NONE,
                options.via is ViaPoints.FREE,
            )
        )
        rescale = int(options.cycle_time is not None)  # uniform scaling to another cycle time
        self.total = 1 + rescale + 2 + path_levers + int(options.blends) + 3
        self.done = 0

    def __call__(self, message: str, *, last: bool = False) -> None:
        """Start a step (``last``: the last one, whatever was skipped before it)."""
        self.done = self.total - 1 if last else min(self.done, self.total - 1)
        self.say(message, done=self.done, total=self.total)
        self.done += 1


@serial
def program_settings(
    robot: Robot,
    program: RobotProgram,
    options: ProgramOptions | None = None,
    *,
    objective: Objective | None = None,
) -> ProgramSettings:
    """The settings :func:`optimize_program` resolves for ``program`` (its cycle time and caps:
    the program simulated as written once), without optimising.

    Raises
    ------
    KinergyError
        As :func:`optimize_program`.
    """
    options = ProgramOptions() if options is None else options
    _, _, ctx = _context(robot, program, options, objective)
    return ProgramSettings(options, ctx.standby, ctx.caps, ctx.budget)


@serial
def optimize_program(
    robot: Robot,
    program: RobotProgram,
    options: ProgramOptions | None = None,
    *,
    objective: Objective | None = None,
    progress: Say | Callable[[str], None] | None = None,
    path: ProgramPath | None = None,
) -> ProgramOptimization:
    """The energy-optimal program doing the same job at a cycle time (module docstring).

    Parameters
    ----------
    robot : Robot
    program : RobotProgram
    options : ProgramOptions, optional
        The levers and limits (default :class:`ProgramOptions`: configurations and via points
        kept, no tool symmetry, blends, the program's own cycle time and peaks).
    objective : Objective, optional
        What to minimise (default :class:`SupplyEnergy` with the standing draw).
    progress : Say or callable, optional
        Told each step as it starts, with the steps done of those planned (:class:`_Steps`).
    path : ProgramPath, optional
        ``program_path(robot, program)``, when the caller has it (not computed again).

    Raises
    ------
    KinergyError
        A target out of reach or outside the joint limits, a cycle time shorter than the fastest
        possible (naming the program line), more than :data:`MAX_MOVES` moves.
    """
    options = ProgramOptions() if options is None else options
    say = _Steps(as_say(progress), options)
    say(f"{program.name}: simulating the program at 500 Hz")
    path, own, ctx = _context(robot, program, options, objective, path)
    search = LeverSearch(ctx, own)
    if abs(ctx.budget - own.result.cycle_time) > 1e-9:
        say("uniform scaling to the cycle time")
        search.rescale()
    levers = PathLevers(
        free=options.configurations.value == "free",
        symmetry=options.tool_symmetry,
        via=options.via is ViaPoints.FREE,
        standby=ctx.standby,
    )
    path_levers(search, path, levers, say)
    if options.blends:
        say("blends: re-simulating")
        best = search.best.path
        search.judge("blends", best.program.with_moves(via_blends(robot, best)), "blended")
    timed(search, say)
    _timing_only(search, path, say)
    optimized = search.best
    say("checking the targets", last=True)
    targets = target_errors(
        robot, path, optimized, symmetry=options.tool_symmetry, left_out=search.left_out
    )
    settings = ProgramSettings(options, ctx.standby, ctx.caps, ctx.budget)
    return ProgramOptimization(
        own, optimized, tuple(search.levers), targets, settings, search.timing
    )


def _cycle_times(points: int, fastest: float, own: float) -> list[float]:
    """``points`` cycle times from the fastest possible to twice the program's own, and its own,
    s, increasing."""
    return [float(t) for t in np.unique(np.append(np.linspace(fastest, 2.0 * own, points), own))]


@serial
def pareto_front(
    robot: Robot,
    result: ProgramOptimization,
    *,
    points: int = 8,
    cycle_times: Sequence[float] | None = None,
    progress: Say | Callable[[str], None] | None = None,
) -> tuple[ParetoPoint, ...]:
    """Energy against cycle time: the optimised path re-timed (:func:`kinergy.optimize.timing.
    retime`, within the same caps) and the program as written uniformly scaled, at each cycle
    time: ``cycle_times`` (s), or ``points`` (>= 2) from the fastest possible on the optimised
    path to twice the program's own, plus its own.

    Returns
    -------
    tuple of ParetoPoint
        By increasing cycle time.
    """
    say = as_say(progress)
    settings = result.settings
    ctx = Context(
        robot,
        settings.cycle_time,
        SupplyEnergy(settings.standby),
        settings.caps,
        settings.standby,
        share_budget=not settings.options.fixed_shares,
    )
    best = result.optimized.path
    checks = ctx.checks(best)
    own = result.program.result.cycle_time
    if cycle_times is None:
        if points < 2:
            raise KinergyError(f"points: need at least 2 cycle times, got {points}")
        times = _cycle_times(points, checks.problem.fastest_cycle_time, own)
    else:
        times = sorted(float(t) for t in cycle_times)
    out = []
    written = result.program.path
    for i, budget in enumerate(times):
        say(f"Pareto front: cycle time {budget:.3f} s", done=i, total=len(times))
        uniform = at_cycle(replace(ctx, budget=budget), written, "uniform").result
        try:
            timed_run, _ = retime(checks, budget, share_budget=ctx.share_budget)
            optimized, ok = timed_run.e_supply, timed_run.ok
        except KinergyError:
            optimized, ok = None, False
        out.append(ParetoPoint(budget, optimized, uniform.e_supply, ok, uniform.ok))
    return tuple(out)
