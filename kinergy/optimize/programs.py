"""Energy-optimal robot programs: the path levers and the timing of a URScript program.

:func:`optimize_program` takes a :class:`~kinergy.trajectory.robot_program.RobotProgram` and
returns the same program (same moves, events and line order) with changed targets, blend radii,
speeds and accelerations that does the same job with less supply energy
(:data:`kinergy.optimize.objectives.PROGRAM_OBJECTIVE`) at the same cycle time. The levers, in
order, each one kept only if its re-simulation scores better than the program before it:

1. ``2 pi``: every joint target takes the ``2 pi`` turn nearest the joints it comes from, within
   the joint limits (it changes no pose: always on);
2. ``configurations`` (``free``): a movej's pose target may take any inverse-kinematics branch
   (``keep``, the default, keeps the program's: a new branch can collide with the cell);
3. ``tool symmetry`` (``z``, ``z2``, ``z4``): a target may turn about the tool's z axis;
4. ``blends``: via points (a move followed by a move, no event between) get a blend radius of
   40 % of the shorter tool distance of the two moves, at most 10 cm;
5. ``timing``: every move's ``v`` and ``a`` (:func:`kinergy.optimize.program_timing.retime`).

Levers 1-3 are one search (:mod:`kinergy.optimize.program_search`: dynamic programming over the
targets' states with a cheap energy estimate of every move, :mod:`kinergy.optimize.path_costs`),
restricted per lever. Every figure is a 500 Hz re-simulation
(:func:`kinergy.optimize.program_verify.simulate_path`) at the program's cycle time (levers 1-4
uniformly slowed to it), with every joint limit checked at every sample and, by default, no joint
faster or harder than the program itself moves. :func:`target_errors` checks the optimised program
against every target of the original.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from kinergy.dynamics.poses import tcp_pose
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.optimize.objectives import PROGRAM_OBJECTIVE, Objective
from kinergy.optimize.path_costs import (
    TargetStates,
    move_costs,
    refined_turns,
    symmetry_angles,
    target_states,
)
from kinergy.optimize.problem import uniform_scaling
from kinergy.optimize.program import serial
from kinergy.optimize.program_search import (
    cheapest_cycle,
    chosen_moves,
    lever_mask,
    masked,
    wrapped_moves,
)
from kinergy.optimize.program_timing import PathChecks, path_problem, retime
from kinergy.optimize.program_verify import PathRun, TargetCheck, simulate_path, target_errors
from kinergy.optimize.verify import ProgramResult
from kinergy.trajectory.program_motion import schedule
from kinergy.trajectory.program_path import ProgramPath, program_path
from kinergy.trajectory.robot_program import Move, RobotProgram

__all__ = ["Lever", "ProgramOptimization", "optimize_program", "supply", "via_blends"]


#: a via point's blend radius: this share of the shorter tool distance of its two moves, ...
_BLEND_SHARE = 0.4
#: ... at most this, m
_BLEND_MAX = 0.10
#: a fully symmetric tool's turns are searched every 45 degrees, then around the best every
#: 15 and every 5 degrees (rad)
_FINER = (np.deg2rad(15.0), np.deg2rad(5.0))
#: processor seconds the whole optimisation aims at: the timing solver stops at what is left
_SECONDS = 40.0
#: the timing solver's caps are this share below the program's: its iterations end a few ms off
#: the cycle time, and the uniform rescaling to it (:func:`_at_cycle`) must stay within the caps
_SLACK = 0.005
#: targets are met within these (m, rad) and the arm is at rest below this joint speed (rad/s)
TARGET_TOL = (1e-3, np.deg2rad(0.5), 1e-3)


def supply(result: ProgramResult) -> float:
    """The supply energy of a scored program (:attr:`ProgramResult.score`), J."""
    if result.score is None:
        raise KinergyError(f"{result.label}: the program was not scored")
    return result.score


@dataclass(frozen=True, eq=False)
class Lever:
    """One lever's program, re-simulated at the cycle time.

    Attributes
    ----------
    name : str
        ``program``, ``2pi``, ``configurations``, ``tool symmetry``, ``blends``, ``timing`` (or
        ``timing only``: the program as written, only re-timed).
    result : ProgramResult
    kept : bool
        Whether the optimised program uses it (it scored better than the program before it).
    note : str
        Why not, or what it changed.
    """

    name: str
    result: ProgramResult
    kept: bool
    note: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "kept": self.kept,
            "note": self.note,
            "cycle_time": self.result.cycle_time,
            "e_supply": self.result.score,
            "e_elec": self.result.e_elec,
            "within_limits": self.result.ok,
        }


@dataclass(frozen=True, eq=False)
class ProgramOptimization:
    """What :func:`optimize_program` found.

    Attributes
    ----------
    program, optimized : PathRun
        The program as written and the optimised one, each re-simulated at 500 Hz.
    levers : tuple of Lever
        Each lever's figure in order, then ``timing only`` (the comparison: re-timing alone).
    targets : list of TargetCheck
        The optimised program at every target of the original.
    settings : dict
        The options used (configurations, tool symmetry, standby, caps, cycle time).
    """

    program: PathRun
    optimized: PathRun
    levers: tuple[Lever, ...]
    targets: list[TargetCheck]
    settings: dict[str, Any] = field(default_factory=dict)

    @property
    def written(self) -> RobotProgram:
        """The optimised program with its moves' ``v`` and ``a`` as it runs (what to write)."""
        return _with_timing(self.optimized.path, self.optimized.result)

    @property
    def saving(self) -> float:
        """Share of the supply energy saved, 0-1."""
        return 1.0 - supply(self.optimized.result) / supply(self.program.result)

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
        out["levers"] = [lever.to_dict() for lever in self.levers]
        out["targets"] = [c.to_dict() for c in self.targets]
        out["targets_met"] = self.targets_met
        out["settings"] = dict(self.settings)
        return out


def via_blends(robot: Robot, path: ProgramPath) -> list[Move]:
    """The program's moves with a blend radius at every via point that has none (module
    docstring, lever 4)."""
    program = path.program
    steps, index = program.steps, program.move_index
    tips = np.array([tcp_pose(robot, path.q_end[k], path.tcp[k])[:3, 3] for k in range(path.moves)])
    start = tcp_pose(robot, path.q0, path.tcp[0])[:3, 3]
    reach = np.linalg.norm(np.diff(np.vstack([start, tips]), axis=0), axis=1)  # (K,)
    out = []
    for k, move in enumerate(program.moves):
        i = index[k]
        via = k + 1 < path.moves and isinstance(steps[i + 1], Move) and move.r == 0.0
        if via:
            r = min(_BLEND_MAX, _BLEND_SHARE * min(reach[k], reach[k + 1]))
            move = move.replaced(r=round(float(r), 4))
        out.append(move)
    return out


def _at_cycle(
    robot: Robot,
    path: ProgramPath,
    budget: float,
    objective: Objective,
    caps: tuple[float, float],
    label: str,
) -> PathRun:
    """``path`` uniformly slowed (or sped up) to last ``budget`` s, re-simulated."""
    fixed = float(path.event_time.sum())
    own = float(schedule(path, path.speed, path.accel).total[0])
    v, a = uniform_scaling(path.speed, path.accel, (own - fixed) / max(budget - fixed, 1e-9))
    return simulate_path(
        robot,
        path.with_timing(v, a),
        objective=objective,
        speed_cap=caps[0],
        acceleration_cap=caps[1],
        label=label,
    )


def _better(new: PathRun, old: PathRun) -> bool:
    assert new.result.score is not None and old.result.score is not None
    return new.result.ok and new.result.score < old.result.score


def _with_timing(path: ProgramPath, result: ProgramResult) -> RobotProgram:
    """The program of ``path`` with the result's ``v`` and ``a`` on every move (``t`` dropped)."""
    moves = [
        m.replaced(v=round(float(v), 6), a=round(float(a), 6), t=0.0)
        for m, v, a in zip(path.program.moves, result.speeds, result.accels, strict=True)
    ]
    return path.program.with_moves(moves)


class _Search:
    """The levers' runs, in order, the best so far carried on."""

    def __init__(
        self,
        robot: Robot,
        budget: float,
        objective: Objective,
        caps: tuple[float, float],
        best: PathRun,
    ) -> None:
        self.robot, self.budget, self.objective, self.caps = robot, budget, objective, caps
        self.best = best
        self.started = time.process_time()
        self.levers: list[Lever] = []

    def try_program(
        self,
        name: str,
        program: RobotProgram,
        note: str,
        fallback: tuple[RobotProgram, str] | None = None,
    ) -> None:
        """Re-simulate ``program`` at the cycle time and keep it if better; if not, the
        ``fallback`` program (with its note), if any. One lever is recorded: the kept run, or
        the last one tried."""
        lever = Lever(name, self.best.result, False, "")
        for candidate, text in [(program, note)] + ([fallback] if fallback is not None else []):
            try:
                path = program_path(self.robot, candidate)
            except KinergyError as exc:
                lever = Lever(name, self.best.result, False, f"not used: {exc}")
                continue
            run = _at_cycle(self.robot, path, self.budget, self.objective, self.caps, name)
            kept = _better(run, self.best)
            lever = Lever(name, run.result, kept, text if kept else f"not better: {text}")
            if kept:
                self.best = run
                break
        self.levers.append(lever)


def _search_levers(
    search: _Search,
    path: ProgramPath,
    free: bool,
    symmetry: str,
    standby: float,
    say: Callable[[str], None],
) -> None:
    """Levers 1-3: one cost table, a cheapest cycle per set of levers."""
    states = target_states(search.robot, path, free=free, symmetry=symmetry)
    say(f"estimating {sum(s.q.shape[0] for s in states)} target states' moves")
    costs = move_costs(search.robot, path, states, standby=standby)
    say("2pi: re-simulating")
    search.try_program(
        "2pi", path.program.with_moves(wrapped_moves(search.robot, path, states)), "smaller turns"
    )
    levels = []
    if free:
        levels.append(("configurations", True, False))
    if symmetry != "none":
        levels.append(("tool symmetry", free, True))
    for name, branch, turn in levels:
        choice, estimate = cheapest_cycle(
            masked(costs, lever_mask(path, states, branch=branch, turn=turn))
        )
        if not np.isfinite(estimate):
            continue
        if turn and symmetry == "z":
            finer, pick, value = _finer(search, path, states, choice, estimate, free, standby)
        else:
            finer, pick, value = states, choice, estimate
        program, note = _chosen_program(path, finer, pick)
        fallback = None
        if finer is not states:  # the finer turns, then the 45 degree ones
            note += " (turns to 5 degrees)"
            coarse, text = _chosen_program(path, states, choice)
            fallback = (coarse, f"{text} (45 degree turns: the finer ones were not better)")
        say(f"{name}: estimated {value:.1f} J, re-simulating")
        search.try_program(name, program, note, fallback)


def _chosen_program(
    path: ProgramPath, states: list[TargetStates], choice: NDArray[np.intp]
) -> tuple[RobotProgram, str]:
    """The program with the chosen states as its targets, and how many changed."""
    changed = sum(int(c != s.own) for c, s in zip(choice, states, strict=True))
    moves = chosen_moves(path, states, choice)
    return path.program.with_moves(moves), f"{changed} target states changed"


def _finer(
    search: _Search,
    path: ProgramPath,
    states: list[TargetStates],
    choice: NDArray[np.intp],
    estimate: float,
    free: bool,
    standby: float,
) -> tuple[list[TargetStates], NDArray[np.intp], float]:
    """A fully symmetric tool's turns searched again around the best, every ``_FINER`` step
    (:func:`kinergy.optimize.path_costs.refined_turns`); the best states, choice and estimate."""
    for step in _FINER:
        turns = refined_turns(
            np.array([s.turn[c] for s, c in zip(states, choice, strict=True)]), step
        )
        finer = target_states(search.robot, path, free=free, symmetry="z", turns=turns)
        costs = move_costs(search.robot, path, finer, standby=standby)
        pick, value = cheapest_cycle(masked(costs, lever_mask(path, finer, branch=free, turn=True)))
        if value < estimate:
            states, choice, estimate = finer, pick, value
    return states, choice, estimate


@serial
def optimize_program(
    robot: Robot,
    program: RobotProgram,
    *,
    configurations: str = "keep",
    tool_symmetry: str = "none",
    blends: bool = True,
    standby: float | None = None,
    cycle_time: float | None = None,
    v_max: float | None = None,
    a_max: float | None = None,
    compare_timing: bool = False,
    progress: Callable[[str], None] | None = None,
) -> ProgramOptimization:
    """The energy-optimal program doing the same job at a cycle time (module docstring).

    Parameters
    ----------
    robot : Robot
    program : RobotProgram
    configurations : {'keep', 'free'}
    tool_symmetry : {'none', 'z', 'z2', 'z4'}
    blends : bool
        Whether via points may get blend radii.
    standby : float, optional
        Standby power, W (adds ``standby * cycle time`` to every figure); default the robot
        file's ``standby_power``.
    cycle_time : float, optional
        s (default the program's own).
    v_max, a_max : float, optional
        Caps on every joint's speed (rad/s) and acceleration (rad/s^2); default the program's
        own peaks.
    compare_timing : bool
        Also re-time the program as written alone (the last lever, ``timing only``: what
        re-timing alone saves).
    progress : callable, optional
        Called with a line before each long step.

    Raises
    ------
    KinergyError
        A target out of reach or outside the joint limits, a cycle time shorter than the fastest
        possible (naming the program line).
    """
    if configurations not in ("keep", "free"):
        raise KinergyError(f"configurations: expected keep or free, got {configurations!r}")
    symmetry_angles(tool_symmetry)  # validates
    say = progress if progress is not None else (lambda _: None)
    standby = robot.standby_power if standby is None else standby
    objective = PROGRAM_OBJECTIVE(standby)
    path = program_path(robot, program)
    if not np.any(path.travel > 0.0):
        raise KinergyError(
            f"{program.path or program.name}: no move changes the arm's position; nothing to "
            "optimise"
        )
    say(f"{program.name}: simulating the program at 500 Hz")
    own, caps = _as_written(robot, path, objective, v_max, a_max)
    budget = own.result.cycle_time if cycle_time is None else cycle_time
    search = _Search(robot, budget, objective, caps, own)
    search.levers.append(Lever("program", own.result, True, "as written"))
    _search_levers(search, path, configurations == "free", tool_symmetry, standby, say)
    if blends:
        say("blends: re-simulating")
        best = search.best.path
        search.try_program("blends", best.program.with_moves(via_blends(robot, best)), "blended")
    optimized = _timed(search, say)
    levers = tuple(search.levers)
    if compare_timing:
        only = _timing_only(robot, path, objective, caps, budget, say)
        levers += (Lever("timing only", only, False, "the program as written, re-timed"),)
    say("checking the targets")
    targets = target_errors(robot, path, optimized, symmetry=tool_symmetry)
    settings = {
        "configurations": configurations,
        "tool_symmetry": tool_symmetry,
        "blends": blends,
        "standby": standby,
        "v_max": caps[0],
        "a_max": caps[1],
        "cycle_time": budget,
    }
    return ProgramOptimization(own, optimized, levers, targets, settings)


def _as_written(
    robot: Robot, path: ProgramPath, objective: Objective, v_max: float | None, a_max: float | None
) -> tuple[PathRun, tuple[float, float]]:
    """The program re-simulated, and the joint speed and acceleration caps: ``v_max`` and
    ``a_max``, or the program's own peaks."""
    own = simulate_path(robot, path, objective=objective)
    caps = (
        float(np.max(np.abs(own.motion.qd))) if v_max is None else v_max,
        float(np.max(np.abs(own.motion.qdd))) if a_max is None else a_max,
    )
    checked = simulate_path(
        robot, path, objective=objective, speed_cap=caps[0], acceleration_cap=caps[1]
    )
    return checked, caps


def _timed(search: _Search, say: Callable[[str], None]) -> PathRun:
    """Lever 5 on the best program: re-timed, written back as a program and re-simulated."""
    path = search.best.path
    say("timing: solving every move's v and a")
    checks = _timing_checks(search.robot, path, search.objective, search.caps)
    left = max(5.0, _SECONDS - (time.process_time() - search.started))
    result, message, _ = retime(checks, search.budget, seconds=left)
    if "StopIteration" in message:
        message = f"the solver stopped after {left:.0f} s of processor time (the budget): improved, not optimal"
    search.try_program("timing", _with_timing(path, result), message)
    return search.best


def _timing_only(
    robot: Robot,
    path: ProgramPath,
    objective: Objective,
    caps: tuple[float, float],
    budget: float,
    say: Callable[[str], None],
) -> ProgramResult:
    """The program as written, only re-timed (the comparison)."""
    say("timing only: re-timing the program as written")
    result, _, _ = retime(_timing_checks(robot, path, objective, caps), budget)
    written = program_path(robot, _with_timing(path, result))
    return _at_cycle(robot, written, budget, objective, caps, "timing only").result


def _timing_checks(
    robot: Robot, path: ProgramPath, objective: Objective, caps: tuple[float, float]
) -> PathChecks:
    """The timing problem of ``path`` with the caps ``_SLACK`` below ``caps`` (speed, and its
    square for acceleration: what a uniform rescaling by ``1 + _SLACK`` needs)."""
    v_max, a_max = caps[0] * (1.0 - _SLACK), caps[1] * (1.0 - _SLACK) ** 2
    problem = path_problem(robot, path, objective=objective, v_max=v_max, a_max=a_max)
    return PathChecks(robot, path, problem, v_max, a_max)
