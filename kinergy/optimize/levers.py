"""The levers of a robot program, each judged at the cycle time after any repair it needs.

:class:`LeverSearch` carries the best program so far. :meth:`LeverSearch.judge` resolves a
lever's program, runs it at the cycle time (uniformly slowed or sped up), repairs it if it breaks
a limit (:func:`kinergy.optimize.repair.repair`: re-timed per move, then by the timing
solver) and keeps it if its 500 Hz re-simulation beats the best so far; every lever is recorded
as a :class:`Lever` with what it saved or why it was dropped. :func:`path_levers` runs the ``2 pi``
wraps and the search over configurations, tool turns and via points (one cost table, a cheapest
cycle per set of levers, :mod:`kinergy.optimize.search`), :func:`via_blends` the blend
radii and :func:`timed` the timing solver.
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from kinergy.dynamics.poses import tcp_pose
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.optimize.options import ToolSymmetry
from kinergy.optimize.path_costs import TargetStates, move_costs, refined_turns, target_states
from kinergy.optimize.repair import Context, at_cycle, repair
from kinergy.optimize.search import (
    cheapest_cycle,
    chosen_moves,
    lever_mask,
    masked,
    wrapped_moves,
)
from kinergy.optimize.timing import NO_ROOM, Verified, retime
from kinergy.optimize.verify import PathRun, ProgramResult
from kinergy.trajectory.program_path import ProgramPath, program_path
from kinergy.trajectory.robot_program import Move, RobotProgram

__all__ = [
    "Lever",
    "LeverSearch",
    "LeverStatus",
    "PathLevers",
    "path_levers",
    "timed",
    "via_blends",
    "with_timing",
]


#: a via point's blend radius: this share of the shorter tool distance of its two moves, ...
_BLEND_SHARE = 0.4
#: ... at most this, m
_BLEND_MAX = 0.10
#: a fully symmetric tool's turns are searched every 45 degrees, then around the best every
#: 15 and every 5 degrees (rad)
_FINER = (np.deg2rad(15.0), np.deg2rad(5.0))


def _score(result: ProgramResult) -> float:
    """The objective of a scored program (:attr:`ProgramResult.score`: the supply energy, J)."""
    if result.score is None:
        raise KinergyError(f"{result.label}: the program was not scored")
    return result.score


#: s: how much longer than the cycle time a lever's program may take (a 500 Hz sample)
CYCLE_TOLERANCE = 0.002


class LeverStatus(enum.Enum):
    """What became of a lever: ``KEPT`` (it beat the program before it), ``NOT_BETTER``,
    ``OVER_LIMITS`` (it breaks a limit even after its repair), ``NOT_POSSIBLE`` (its program
    cannot run: a target out of reach, a line through a singularity, ...), ``NO_CHANGE`` (it
    changes nothing on this program), ``AS_WRITTEN`` (the program itself, the reference)."""

    KEPT = "kept"
    NOT_BETTER = "not better"
    OVER_LIMITS = "over the limits"
    NOT_POSSIBLE = "not possible"
    NO_CHANGE = "no change"
    AS_WRITTEN = "as written"


@dataclass(frozen=True, eq=False)
class Lever:
    """One lever's program, re-simulated at the cycle time.

    Attributes
    ----------
    name : str
        ``program``, ``2pi``, ``configurations``, ``tool symmetry``, ``via points``, ``blends``,
        ``timing`` (or ``timing only``: the program as written, only re-timed).
    result : ProgramResult
        Its 500 Hz run at the cycle time (after its repair, if it needed one); the program
        before it when it could not run.
    status : LeverStatus
    saved : float
        Supply energy it saved on the program before it, J (negative: it cost more).
    note : str
        What it changed, or why it was dropped.
    repaired : str
        How its first result was brought within the limits (``per move``, ``re-timed``), or ``''``.
    """

    name: str
    result: ProgramResult
    status: LeverStatus
    saved: float = 0.0
    note: str = ""
    repaired: str = ""

    @property
    def kept(self) -> bool:
        """Whether the optimised program uses it (the program as written counts as kept)."""
        return self.status in (LeverStatus.KEPT, LeverStatus.AS_WRITTEN)

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "kept": self.kept,
            "status": self.status.value,
            "saved": self.saved,
            "repaired": self.repaired or None,
            "note": self.note,
            "cycle_time": self.result.cycle_time,
            "e_supply": self.result.e_supply,
            "e_elec": self.result.e_elec,
            "within_limits": self.result.ok,
        }


def _rounded(x: float) -> float:
    """A setting as the program will state it: 6 decimals (9 significant digits below 1e-3)."""
    return round(float(x), 6) if abs(x) >= 1e-3 else float(f"{float(x):.9g}")


def with_timing(path: ProgramPath, result: ProgramResult) -> RobotProgram:
    """The program of ``path`` with the result's ``v`` and ``a`` on every move that moves (``t``
    dropped; a move that goes nowhere, less than 1 nrad, keeps its settings)."""
    moves = [
        m.replaced(v=_rounded(v), a=_rounded(a), t=0.0)
        if travel > 1e-9 and v > 0.0 and a > 0.0
        else m
        for m, v, a, travel in zip(
            path.program.moves, result.speeds, result.accels, path.travel, strict=True
        )
    ]
    return path.program.with_moves(moves)


def _same_moves(a: RobotProgram, b: RobotProgram) -> bool:
    """Whether two programs' moves have the same targets and settings."""

    def key(m: Move) -> tuple[object, ...]:
        qnear = None if m.qnear is None else m.qnear.tobytes()
        return (m.kind, m.target.tobytes(), m.pose, m.a, m.v, m.t, m.r, m.joint_blend, qnear)

    return [key(m) for m in a.moves] == [key(m) for m in b.moves]


class LeverSearch:
    """The levers' runs, in order, the best so far carried on (module docstring)."""

    def __init__(self, ctx: Context, best: PathRun) -> None:
        self.ctx = ctx
        self.robot, self.budget = ctx.robot, ctx.budget
        self.best = best
        #: how the timing lever's solution came about (None until it ran)
        self.timing: Verified | None = None
        self.levers: list[Lever] = [Lever("program", best.result, LeverStatus.AS_WRITTEN)]
        #: which moves' targets the best program leaves out (via points), shape (K,)
        self.left_out = np.zeros(best.path.moves, dtype=bool)

    def run(self, program: RobotProgram, label: str) -> tuple[PathRun, str]:
        """``program`` at the cycle time, repaired if it breaks a limit, and how it was
        repaired ('' if it needed no repair; its first run if no repair worked).

        Raises
        ------
        KinergyError
            The program cannot run (a target out of reach, ...).
        """
        path = program_path(self.robot, program)
        first = at_cycle(self.ctx, path, label)
        if first.result.ok:
            return first, ""
        fixed = repair(self.ctx, first)
        return (first, "") if fixed is None else (fixed.run, fixed.how)

    def judge(
        self,
        name: str,
        program: RobotProgram,
        note: str,
        fallback: tuple[RobotProgram, str] | None = None,
        left_out: tuple[NDArray[np.bool_], NDArray[np.bool_]] | None = None,
    ) -> bool:
        """Run ``program`` (then, if it is not kept, ``fallback`` with its note) at the cycle
        time, repaired as needed, and keep it if it beats the best so far; record one lever (the
        kept run, or the last one tried). ``left_out``: the via points each of the two leaves
        out. Returns whether it was kept."""
        before = self.best.result
        lever = Lever(name, before, LeverStatus.NO_CHANGE, note="no target changes")
        tries = [(program, note), *([fallback] if fallback is not None else [])]
        for i, (candidate, text) in enumerate(tries):
            if _same_moves(candidate, self.best.path.program):
                continue
            try:
                run, how = self.run(candidate, name)
            except KinergyError as exc:
                lever = Lever(name, before, LeverStatus.NOT_POSSIBLE, note=f"{text}: {exc}")
                continue
            saved = _score(before) - _score(run.result)
            late = run.result.cycle_time - self.budget
            if not run.result.ok:
                why = "; ".join(run.result.check.violations())
                status, text = LeverStatus.OVER_LIMITS, f"{text}; even re-timed: {why}"
            elif late > CYCLE_TOLERANCE:  # the job must take no longer than the cycle time
                status = LeverStatus.OVER_LIMITS
                text = (
                    f"{text}; within the limits only at {run.result.cycle_time:.3f} s, over the "
                    f"cycle time of {self.budget:.3f} s"
                )
            elif saved > 0.0 or not before.ok:  # any run within the limits beats one over them
                status = LeverStatus.KEPT
            else:
                status = LeverStatus.NOT_BETTER
            lever = Lever(name, run.result, status, saved, text, how)
            if status is LeverStatus.KEPT:
                self.best = run
                if left_out is not None:
                    self.left_out = left_out[i].copy()
                break
        self.levers.append(lever)
        return lever.kept

    def record(self, lever: Lever) -> None:
        self.levers.append(lever)

    def rescale(self) -> None:
        """Start from the program as written uniformly slowed or sped up to the cycle time
        (repaired if it breaks a limit there), recorded as the lever ``uniform scaling``, when
        the cycle time is not the program's own."""
        before = self.best
        run, how = self.run(before.path.program, "uniform scaling")
        late = run.result.cycle_time - self.budget > CYCLE_TOLERANCE
        status = LeverStatus.KEPT if run.result.ok and not late else LeverStatus.OVER_LIMITS
        note = "the program as written at the cycle time"
        if not run.result.ok:
            note += "; even re-timed: " + "; ".join(run.result.check.violations())
        elif late:
            note += f"; within the limits only at {run.result.cycle_time:.3f} s"
        saved = _score(before.result) - _score(run.result)
        self.levers.append(Lever("uniform scaling", run.result, status, saved, note, how))
        self.best = run


@dataclass(frozen=True)
class PathLevers:
    """The path levers a program optimisation may use."""

    free: bool
    symmetry: ToolSymmetry
    via: bool
    standby: float


def _chosen_program(
    path: ProgramPath, states: list[TargetStates], choice: NDArray[np.intp]
) -> tuple[RobotProgram, str, NDArray[np.bool_]]:
    """The program with the chosen states as their targets, how many changed, and which via
    points it leaves out."""
    changed = sum(int(c != s.own) for c, s in zip(choice, states, strict=True))
    left_out = np.array([bool(s.moved[c]) for c, s in zip(choice, states, strict=True)])
    note = f"{changed} target states changed"
    if np.any(left_out):
        count = int(left_out.sum())
        note += f", {count} via point{'s' if count > 1 else ''} left out"
    return path.program.with_moves(chosen_moves(path, states, choice)), note, left_out


def _finer(
    search: LeverSearch,
    path: ProgramPath,
    found: tuple[list[TargetStates], NDArray[np.intp], float],
    levers: PathLevers,
    via: bool,
) -> tuple[list[TargetStates], NDArray[np.intp], float]:
    """A fully symmetric tool's turns searched again around the best, every ``_FINER`` step
    (:func:`kinergy.optimize.path_costs.refined_turns`); the best states, choice and estimate."""
    states, choice, estimate = found
    for step in _FINER:
        chosen = np.array([s.turn[c] for s, c in zip(states, choice, strict=True)])
        turns = refined_turns(chosen, step)
        finer = target_states(
            search.robot, path, free=levers.free, symmetry=levers.symmetry, via=via, turns=turns
        )
        costs = move_costs(search.robot, path, finer, standby=levers.standby)
        mask = lever_mask(path, finer, branch=levers.free, turn=True, via=via)
        pick, value = cheapest_cycle(masked(costs, mask))
        if value < estimate:
            states, choice, estimate = finer, pick, value
    return states, choice, estimate


def path_levers(
    search: LeverSearch, path: ProgramPath, levers: PathLevers, say: Callable[[str], None]
) -> None:
    """The ``2 pi`` wraps, then one cost table and a cheapest cycle per set of levers:
    configurations, tool symmetry, via points (each with the ones before it)."""
    robot = search.robot
    states = target_states(robot, path, free=levers.free, symmetry=levers.symmetry, via=levers.via)
    say(f"estimating {sum(s.q.shape[0] for s in states)} target states' moves")
    costs = move_costs(robot, path, states, standby=levers.standby)
    say("2pi: re-simulating")
    search.judge(
        "2pi", path.program.with_moves(wrapped_moves(robot, path, states)), "smaller turns"
    )
    turn = levers.symmetry is not ToolSymmetry.NONE
    steps = []
    if levers.free:
        steps.append(("configurations", True, False, False))
    if turn:
        steps.append(("tool symmetry", levers.free, True, False))
    if levers.via:
        steps.append(("via points", levers.free, turn, True))
    for name, branch, turning, via in steps:
        mask = lever_mask(path, states, branch=branch, turn=turning, via=via)
        choice, estimate = cheapest_cycle(masked(costs, mask))
        if not np.isfinite(estimate):
            search.record(
                Lever(name, search.best.result, LeverStatus.NOT_POSSIBLE, note="no cycle of states")
            )
            continue
        found = (states, choice, estimate)
        if turning and levers.symmetry.any_angle:
            found = _finer(search, path, found, levers, via)
        program, note, left = _chosen_program(path, found[0], found[1])
        fallback, left_coarse = None, left
        if found[0] is not states:  # the finer turns, then the 45 degree ones
            note += " (turns to 5 degrees)"
            coarse, text, left_coarse = _chosen_program(path, states, choice)
            fallback = (coarse, f"{text} (45 degree turns: the finer ones were not better)")
        say(f"{name}: estimated {found[2]:.1f} J, re-simulating")
        search.judge(name, program, note, fallback, (left, left_coarse))


def via_blends(robot: Robot, path: ProgramPath) -> list[Move]:
    """The program's moves with a blend radius at every joint-space via point that has none: a
    movej followed by a movej with no event between gets 40 % of the shorter tool distance of the
    two, at most 10 cm. A move into or out of a movel or movep is never blended: the straight
    line (an approach, a retreat) stays whole."""
    program = path.program
    steps, index = program.steps, program.move_index
    tips = np.array([tcp_pose(robot, path.q_end[k], path.tcp[k])[:3, 3] for k in range(path.moves)])
    start = tcp_pose(robot, path.q0, path.tcp[0])[:3, 3]
    reach = np.linalg.norm(np.diff(np.vstack([start, tips]), axis=0), axis=1)  # (K,)
    out = []
    for k, move in enumerate(program.moves):
        i = index[k]
        after = steps[i + 1] if k + 1 < path.moves else None
        via = isinstance(after, Move) and move.kind == after.kind == "movej" and not move.blends
        if via:
            r = min(_BLEND_MAX, _BLEND_SHARE * min(reach[k], reach[k + 1]))
            move = move.replaced(r=round(float(r), 4))
        out.append(move)
    return out


def timed(search: LeverSearch, say: Callable[[str], None]) -> None:
    """The timing lever on the best program: every move's ``v`` and ``a`` by the timing solver
    at the cycle time within the caps, written back as a program and judged."""
    path = search.best.path
    say("timing: solving every move's v and a")
    try:
        result, verified = retime(
            search.ctx.checks(path), search.budget, share_budget=search.ctx.share_budget
        )
    except KinergyError as exc:  # the timing model's fastest is above the cycle time
        note = f"no room to re-time: the solver keeps {NO_ROOM}; {exc}"
        search.record(Lever("timing", search.best.result, LeverStatus.NOT_POSSIBLE, note=note))
        return
    search.timing = verified
    search.judge("timing", with_timing(path, result), verified.words)
