"""Energy-optimal robot programs: the path levers and the timing of a URScript program.

:func:`optimize_program` takes a :class:`~kinergy.trajectory.robot_program.RobotProgram` and
returns the same program (same moves, events and line order) with changed targets, blend radii,
speeds and accelerations that does the same job with less supply energy
(:data:`kinergy.optimize.objectives.PROGRAM_OBJECTIVE`) at the same cycle time. The levers, in
order (:mod:`kinergy.optimize.program_levers`), each judged at the cycle time, repaired first
should it break a limit there (:mod:`kinergy.optimize.program_repair`), and kept only if its
re-simulation scores better than the program before it:

1. ``2 pi``: every joint target takes the ``2 pi`` turn nearest the joints it comes from, within
   the joint limits (it changes no pose: always on);
2. ``configurations`` (``free``): a movej's pose target may take any inverse-kinematics branch
   (``keep``, the default, keeps the program's: a new branch can collide with the cell);
3. ``tool symmetry`` (``z``, ``z2``, ``z4``): a target may turn about the tool's z axis;
4. ``via points`` (``free``): a joint-space via point (such as a home pose passed every cycle)
   may be left out of the route (``keep``, the default: the route may avoid something);
5. ``blends``: via points (a move followed by a move, no event between) get a blend radius of
   40 % of the shorter tool distance of the two moves, at most 10 cm;
6. ``timing``: every move's ``v`` and ``a`` (:func:`kinergy.optimize.program_timing.retime`).

Levers 1-4 are one search (:mod:`kinergy.optimize.program_search`: dynamic programming over the
targets' states with a cheap energy estimate of every move, :mod:`kinergy.optimize.path_costs`),
restricted per lever. Every figure is a 500 Hz re-simulation
(:func:`kinergy.optimize.program_verify.simulate_path`) at the program's cycle time, with every
joint limit checked at every sample and, by default, no joint faster or harder than the program
itself moves. Every step stops on iteration limits and tolerances, never on a clock: the same
program on every host. :func:`target_errors` checks the optimised program against every target
of the original.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinergy.accounting.uncertainty import NO_UNCERTAINTY
from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.model.uncertainty import Interval, interval
from kinergy.optimize.objectives import PROGRAM_OBJECTIVE, Objective
from kinergy.optimize.options import ProgramOptions, ViaPoints
from kinergy.optimize.program import serial
from kinergy.optimize.program_levers import (
    Lever,
    LeverSearch,
    LeverStatus,
    PathLevers,
    path_levers,
    supply,
    timed,
    via_blends,
    with_timing,
)
from kinergy.optimize.program_repair import NO_ROOM, Caps, timing_checks
from kinergy.optimize.program_timing import retime
from kinergy.optimize.program_verify import PathRun, TargetCheck, simulate_path, target_errors
from kinergy.trajectory.program_path import ProgramPath, program_path
from kinergy.trajectory.robot_program import RobotProgram

__all__ = [
    "TARGET_TOL",
    "Lever",
    "LeverStatus",
    "ProgramOptimization",
    "ProgramSettings",
    "optimize_program",
    "supply",
    "via_blends",
]


#: targets are met within these (m, rad) and the arm is at rest below this joint speed (rad/s)
TARGET_TOL = (1e-3, np.deg2rad(0.5), 1e-3)


@dataclass(frozen=True)
class ProgramSettings:
    """The options an optimisation ran with, resolved: the robot file's standby where none was
    given, the program's own peaks as caps, its own cycle time.

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
            "standby": self.standby,
            "v_max": self.caps.speed,
            "a_max": self.caps.acceleration,
            "cycle_time": self.cycle_time,
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
    """

    program: PathRun
    optimized: PathRun
    levers: tuple[Lever, ...]
    targets: list[TargetCheck]
    settings: ProgramSettings

    @property
    def written(self) -> RobotProgram:
        """The optimised program with its moves' ``v`` and ``a`` as it runs (what to write)."""
        return with_timing(self.optimized.path, self.optimized.result)

    @property
    def saving(self) -> float:
        """Share of the supply energy saved, 0-1."""
        return 1.0 - supply(self.optimized.result) / supply(self.program.result)

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
        s_p, s_o = supply(p.result), supply(o.result)
        return (s_o * g_p / s_p - g_o) / s_p

    @property
    def saving_interval(self) -> Interval | None:
        """The saving's 95 % interval (0-1) from :attr:`saving_gradient` (None without errors)."""
        g = self.saving_gradient
        return None if g is None else interval(self.program.errors, self.saving, g)

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
        out: dict[str, Any] = {}
        for key, run in (("program", self.program), ("optimized", self.optimized)):
            d = run.result.to_dict()
            d["e_supply"] = run.result.score
            out[key] = d
        out["saving"] = self.saving
        iv = self.saving_interval
        out["saving_interval"] = (
            {"low": iv.low, "high": iv.high, "std": iv.std, "level": iv.level, "method": iv.method}
            if iv is not None
            else {"note": NO_UNCERTAINTY}
        )
        out["levers"] = [lever.to_dict() for lever in self.levers]
        out["targets"] = [c.to_dict() for c in self.targets]
        out["targets_met"] = self.targets_met
        out["settings"] = self.settings.to_dict()
        return out


def _as_written(
    robot: Robot, path: ProgramPath, objective: Objective, options: ProgramOptions
) -> tuple[PathRun, Caps]:
    """The program re-simulated, and the joint speed and acceleration caps: ``v_max`` and
    ``a_max``, or the program's own peaks."""
    own = simulate_path(robot, path, objective=objective)
    caps = Caps(
        float(np.max(np.abs(own.motion.qd))) if options.v_max is None else options.v_max,
        float(np.max(np.abs(own.motion.qdd))) if options.a_max is None else options.a_max,
    )
    checked = simulate_path(
        robot, path, objective=objective, speed_cap=caps.speed, acceleration_cap=caps.acceleration
    )
    return checked, caps


def _timing_only(search: LeverSearch, path: ProgramPath, say: Callable[[str], None]) -> None:
    """The program as written, only re-timed, judged against the levers' best: kept when it
    beats them (a lever chain whose own re-timing stopped short of it), recorded either way
    (what re-timing alone saves)."""
    say("timing only: re-timing the program as written")
    checks = timing_checks(search.robot, path, search.objective, search.caps)
    try:
        result, verified = retime(checks, search.budget)
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


@serial
def optimize_program(
    robot: Robot,
    program: RobotProgram,
    options: ProgramOptions | None = None,
    *,
    progress: Callable[[str], None] | None = None,
) -> ProgramOptimization:
    """The energy-optimal program doing the same job at a cycle time (module docstring).

    Parameters
    ----------
    robot : Robot
    program : RobotProgram
    options : ProgramOptions, optional
        The levers and limits (default :class:`ProgramOptions`: configurations and via points
        kept, no tool symmetry, blends, the program's own cycle time and peaks).
    progress : callable, optional
        Called with a line before each long step.

    Raises
    ------
    KinergyError
        A target out of reach or outside the joint limits, a cycle time shorter than the fastest
        possible (naming the program line).
    """
    options = ProgramOptions() if options is None else options
    say = progress if progress is not None else (lambda _: None)
    standby = robot.standby_power if options.standby is None else options.standby
    objective = PROGRAM_OBJECTIVE(standby)
    path = program_path(robot, program)
    if not np.any(path.travel > 0.0):
        raise KinergyError(
            f"{program.path or program.name}: no move changes the arm's position; nothing to "
            "optimise"
        )
    say(f"{program.name}: simulating the program at 500 Hz")
    own, caps = _as_written(robot, path, objective, options)
    budget = own.result.cycle_time if options.cycle_time is None else options.cycle_time
    search = LeverSearch(robot, budget, objective, caps, own)
    if options.cycle_time is not None:
        _check_cycle_time(robot, path, objective, caps, budget)
        if abs(budget - own.result.cycle_time) > 1e-9:
            say("uniform scaling to the cycle time")
            search.rescale()
    levers = PathLevers(
        free=options.configurations.value == "free",
        symmetry=options.tool_symmetry,
        via=options.via is ViaPoints.FREE,
        standby=standby,
    )
    path_levers(search, path, levers, say)
    if options.blends:
        say("blends: re-simulating")
        best = search.best.path
        search.judge("blends", best.program.with_moves(via_blends(robot, best)), "blended")
    timed(search, say)
    _timing_only(search, path, say)
    optimized = search.best
    found = tuple(search.levers)
    say("checking the targets")
    targets = target_errors(
        robot,
        path,
        optimized,
        symmetry=options.tool_symmetry,
        left_out=search.left_out,
    )
    settings = ProgramSettings(options, standby, caps, budget)
    return ProgramOptimization(own, optimized, found, targets, settings)


def _check_cycle_time(
    robot: Robot, path: ProgramPath, objective: Objective, caps: Caps, budget: float
) -> None:
    """Refuse a cycle time below the program's fastest within the caps (naming the longest
    move's line), before any lever is tried."""
    checks = timing_checks(robot, path, objective, caps)
    fastest = checks.problem.fastest_cycle_time
    if budget < fastest * (1.0 - 1e-9):
        t_fast, _ = checks.problem.fastest
        k = int(np.argmax(t_fast))
        line = path.program.where(path.program.moves[k].line)
        raise KinergyError(
            f"cycle time {budget:.4g} s is shorter than the fastest possible {fastest:.4g} s "
            f"(every move at its speed, acceleration and torque limits; the longest move: {line})"
        )
