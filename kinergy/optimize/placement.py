"""The cell's placement as a lever: where the robot's base should stand for its program.

Much of a pick-and-place program's energy is the base joint's Coulomb friction over the angle
between the pick and place points, which no lever of the program changes: it is set by where the
robot stands. :func:`place_program` tries every base placement of a :class:`PlacementGrid`
around today's (shifts in x, y, z and turns about the vertical, in today's base frame), the
program's poses re-expressed in each moved base frame
(:func:`kinergy.trajectory.program_placement.moved_program`), and at each:

1. checks reach: every target reachable in its configuration, every straight line inside the
   workspace and clear of singularities, every joint within its limits
   (:func:`kinergy.trajectory.program_path.program_path`);
2. optimises the program with every lever (:func:`kinergy.optimize.programs.optimize_program`)
   at today's cycle time and within today's caps (the program's own peak joint speed and
   acceleration unless given), and keeps it only if the optimum holds every limit at every
   500 Hz sample and meets every target.

A candidate that fails either is kept in the result with the reason, never dropped. The best
placement is the reachable candidate of least supply energy per cycle; today's placement is
always evaluated (the grid need not contain it). Every figure is a 500 Hz re-simulation.
"""

from __future__ import annotations

import enum
import math
import multiprocessing
import os
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from kinergy.errors import KinergyError
from kinergy.messages import Say, silent
from kinergy.model.robot import Robot
from kinergy.optimize.levers import CYCLE_TOLERANCE
from kinergy.optimize.options import ProgramOptions
from kinergy.optimize.programs import ProgramOptimization, optimize_program, program_settings
from kinergy.optimize.samples import serial
from kinergy.trajectory.program_path import ProgramPath, program_path
from kinergy.trajectory.program_placement import BasePlacement, moved_program
from kinergy.trajectory.robot_program import RobotProgram

__all__ = [
    "MAX_CANDIDATES",
    "Candidate",
    "PlacementGrid",
    "PlacementSearch",
    "Range",
    "Reason",
    "place_program",
]


#: the most candidate placements one search takes (each is a full optimisation)
MAX_CANDIDATES = 400
#: the largest shift of the base taken, m (beyond it no arm reaches today's cell)
MAX_SHIFT = 5.0
#: decimals a placement's coordinates are rounded to (m and rad: a nanometre, a nanoradian)
RESOLUTION = 9


@dataclass(frozen=True)
class Range:
    """A closed interval ``[low, high]`` of one coordinate of the base, its unit the
    coordinate's (m, or rad for the yaw)."""

    low: float
    high: float

    def values(self, step: float) -> np.ndarray:
        """``low, low + step, ...`` up to ``high`` (within a millionth of a step), shape (N,),
        each rounded to :data:`RESOLUTION`: a placement is the same number whatever grid it
        is part of (``-0.4 + 3 * 0.2`` is 0.2 as ``0 + 0.2`` is)."""
        return np.round(self.low + step * np.arange(self.count(step)), RESOLUTION)

    def count(self, step: float) -> int:
        """How many values :meth:`values` gives (capped at 10^9 for absurd steps)."""
        steps = (self.high - self.low) / step
        return 10**9 if not steps < 1e9 else math.floor(steps + 1e-6) + 1


@dataclass(frozen=True)
class PlacementGrid:
    """The candidate placements: every combination of the ranges' values.

    Attributes
    ----------
    x, y, z : Range
        m, relative to today's base.
    yaw : Range
        rad.
    step : float
        Grid step of x, y and z, m (> 0).
    yaw_step : float
        Grid step of the yaw, rad (> 0).

    Raises
    ------
    KinergyError
        A range backwards or not finite, a shift beyond :data:`MAX_SHIFT`, a step that is not
        a finite number > 0, more than :data:`MAX_CANDIDATES` candidates: one line naming the
        flag (``--x``, ``--step``, ...).
    """

    x: Range
    y: Range
    z: Range = Range(0.0, 0.0)
    yaw: Range = Range(0.0, 0.0)
    step: float = 0.1
    yaw_step: float = math.radians(15.0)

    def __post_init__(self) -> None:
        for name, value in (("--step", self.step), ("--yaw-step", self.yaw_step)):
            if not (math.isfinite(value) and value > 0.0):
                raise KinergyError(f"{name}: must be a finite number > 0, got {value:g}")
        for name, r, limit, unit in (
            ("--x", self.x, MAX_SHIFT, "m"),
            ("--y", self.y, MAX_SHIFT, "m"),
            ("--z", self.z, MAX_SHIFT, "m"),
            ("--yaw", self.yaw, 2.0 * math.pi, "rad"),
        ):
            if not (math.isfinite(r.low) and math.isfinite(r.high)):
                raise KinergyError(f"{name}: the range must be finite, got {r.low:g}:{r.high:g}")
            if r.low > r.high:
                raise KinergyError(
                    f"{name}: the range {r.low:g}:{r.high:g} runs backwards (MIN:MAX with MIN <= MAX)"
                )
            if max(abs(r.low), abs(r.high)) > limit:
                if unit == "m":
                    given, shown = f"{r.low:g}:{r.high:g}", f"{limit:g} m"
                else:  # the flag is in degrees
                    given = f"{math.degrees(r.low):g}:{math.degrees(r.high):g}"
                    shown = "360 deg"
                raise KinergyError(f"{name}: {given} reaches beyond {shown} from today's base")
        count = self.count
        if count > MAX_CANDIDATES:
            raise KinergyError(
                f"--step: the ranges give {count} candidate placements, at most "
                f"{MAX_CANDIDATES} are searched (each is a full optimisation): a larger --step "
                "or --yaw-step, or smaller ranges"
            )

    @property
    def count(self) -> int:
        """How many candidates the grid holds (a Python int: no overflow)."""
        n = 1
        for r, step in ((self.x, self.step), (self.y, self.step), (self.z, self.step)):
            n *= r.count(step)
        return n * self.yaw.count(self.yaw_step)

    def placements(self) -> list[BasePlacement]:
        """Every candidate, x fastest, then y, z, yaw."""
        return [
            BasePlacement(float(x), float(y), float(z), float(yaw))
            for yaw in self.yaw.values(self.yaw_step)
            for z in self.z.values(self.step)
            for y in self.y.values(self.step)
            for x in self.x.values(self.step)
        ]


class Reason(enum.Enum):
    """Why a candidate placement is not reachable (``NONE``: it is)."""

    NONE = "reachable"
    OUT_OF_REACH = "out of reach"
    CANNOT_RUN = "cannot run at the cycle time"
    OVER_LIMIT = "over a limit"
    TARGET_MISSED = "a target missed"

    @property
    def code(self) -> str:
        """One letter for a map: ``R`` reach, ``C`` cycle time, ``L`` limit, ``T`` target."""
        return {"reachable": "", "out of reach": "R", "cannot run at the cycle time": "C",
                "over a limit": "L", "a target missed": "T"}[self.value]  # fmt: skip


@dataclass(frozen=True, eq=False)
class Candidate:
    """One placement and what the program does there.

    Attributes
    ----------
    placement : BasePlacement
    reason : Reason
        ``NONE`` when every target is reached, every limit held at the cycle time and every
        target met.
    why : str
        The details ('' when reachable): the line out of reach, the limit broken, ...
    e_supply : float or None
        The optimised program's supply energy per cycle (the motors and the arm's standing draw
        over the cycle), J (None when not reachable).
    e_motors : float or None
        Its motors' part (on the DC bus, braking lost in the shunt), J.
    cycle_time : float or None
        Its cycle time, s (None when the program cannot run there).
    result : ProgramOptimization or None
        The whole optimisation, kept for today's placement and the best only (each holds its
        500 Hz motions: a few MB).
    """

    placement: BasePlacement
    reason: Reason
    why: str = ""
    e_supply: float | None = None
    cycle_time: float | None = None
    result: ProgramOptimization | None = None
    e_motors: float | None = None

    @property
    def reachable(self) -> bool:
        return self.reason is Reason.NONE

    def summary(self) -> Candidate:
        """The candidate without its optimisation (its figures kept)."""
        return replace(self, result=None)

    def to_dict(self) -> dict[str, Any]:
        p = self.placement
        return {
            "x": p.x,
            "y": p.y,
            "z": p.z,
            "yaw": p.yaw,
            "reachable": self.reachable,
            "e_supply": self.e_supply,
            "e_motors": self.e_motors,
            "cycle_time": self.cycle_time,
            "reason": None if self.reachable else self.reason.value,
            "why": self.why or None,
        }


@dataclass(frozen=True, eq=False)
class PlacementSearch:
    """What :func:`place_program` found.

    Attributes
    ----------
    today : Candidate
        Today's placement, optimised with the same levers.
    candidates : tuple of Candidate
        Every candidate of the grid, in its order.
    best : Candidate
        The reachable candidate (today's included) of least supply energy.
    options : ProgramOptions
        The levers and limits every candidate was optimised with (today's cycle time and caps).
    """

    today: Candidate
    candidates: tuple[Candidate, ...]
    best: Candidate
    options: ProgramOptions

    @property
    def saving(self) -> float | None:
        """The best placement's saving on today's optimised program, of what the arm draws from
        its supply, 0-1 (None when today's optimum does not hold every limit)."""
        if self.best.e_supply is None or self.today.e_supply is None:
            return None
        return 1.0 - self.best.e_supply / self.today.e_supply

    @property
    def saving_motors(self) -> float | None:
        """The same, of the motors' energy alone, 0-1."""
        if self.best.e_motors is None or self.today.e_motors is None:
            return None
        return 1.0 - self.best.e_motors / self.today.e_motors


def _judged(placement: BasePlacement, result: ProgramOptimization) -> Candidate:
    """A placement's optimisation: reachable if it holds every limit and meets every target."""
    opt = result.optimized.result
    cycle = opt.cycle_time
    if cycle > result.settings.cycle_time + CYCLE_TOLERANCE:
        why = f"within the limits only at {cycle:.3f} s"
        return Candidate(placement, Reason.CANNOT_RUN, why, None, cycle, result)
    if not opt.ok:
        why = "; ".join(opt.check.violations())
        return Candidate(placement, Reason.OVER_LIMIT, why, None, cycle, result)
    if not result.targets_met:
        why = "not within 1 mm and 0.5 deg, or not at rest"
        return Candidate(placement, Reason.TARGET_MISSED, why, None, cycle, result)
    return Candidate(placement, Reason.NONE, "", opt.e_supply, cycle, result, opt.e_elec)


def _reach(
    robot: Robot, program: RobotProgram, placement: BasePlacement
) -> tuple[RobotProgram, ProgramPath] | Candidate:
    """The program moved to ``placement`` and its path if every target, line and joint limit
    holds there; else the candidate marked out of reach with the line that fails."""
    try:
        moved = moved_program(robot, program, placement)
        path = program_path(robot, moved)
    except KinergyError as exc:
        return Candidate(placement, Reason.OUT_OF_REACH, str(exc))
    return moved, path


def _candidate(
    robot: Robot,
    moved: RobotProgram,
    path: ProgramPath,
    placement: BasePlacement,
    options: ProgramOptions,
) -> Candidate:
    """A reachable placement's program (``moved``, its ``path`` as :func:`_reach` found it)
    optimised at the cycle time and judged, from its arguments alone (a task of
    :func:`_optimise_all`)."""
    try:
        result = optimize_program(robot, moved, options, path=path)
    except KinergyError as exc:
        return Candidate(placement, Reason.CANNOT_RUN, str(exc))
    return _judged(placement, result)


def _today(robot: Robot, program: RobotProgram, options: ProgramOptions) -> Candidate:
    """Today's placement: the program as it stands optimised with ``options`` and judged (it
    raises, where a candidate is marked, when the program cannot run)."""
    return _judged(BasePlacement(), optimize_program(robot, program, options))


def _refusal(candidates: list[Candidate]) -> KinergyError:
    """No candidate reaches every pose within every limit: the commonest reason, an example."""
    counts: dict[Reason, int] = {}
    for c in candidates:
        counts[c.reason] = counts.get(c.reason, 0) + 1
    common = max(counts, key=lambda r: counts[r])
    example = next(c for c in candidates if c.reason is common)
    return KinergyError(
        f"no candidate placement reaches every pose within every limit: {len(candidates)} "
        f"candidates, {counts[common]} {common.value} (e.g. at {example.placement.label()}: "
        f"{example.why})"
    )


@serial
def place_program(
    robot: Robot,
    program: RobotProgram,
    grid: PlacementGrid,
    options: ProgramOptions | None = None,
    *,
    progress: Say | None = None,
    workers: int | None = None,
) -> PlacementSearch:
    """Every placement of ``grid`` and today's, each checked and optimised (module docstring).

    Every placement's reach is checked first (a grid out of reach is refused at once), today's
    cycle time and caps resolved (:func:`kinergy.optimize.programs.program_settings`: the
    program simulated as written); then today's optimisation and every reachable candidate's
    are tasks on a pool of processes, today's first, each candidate's path sent with it.

    Parameters
    ----------
    robot : Robot
    program : RobotProgram
        The program as it runs today.
    grid : PlacementGrid
    options : ProgramOptions, optional
        The levers (as :func:`kinergy.optimize.programs.optimize_program`); the cycle time and
        caps default to today's program's own and hold for every candidate.
    progress : Say, optional
        Told each step, and as each placement is done how many of them are.
    workers : int, optional
        Processes the placements are optimised on (default: one per core). Each placement's
        optimisation is independent of the others, of the order they run in and of the process
        (its linear algebra on one thread: :func:`kinergy.optimize.samples.serial`): the same
        result whatever the host's core count and with any number of processes.

    Raises
    ------
    KinergyError
        Today's program cannot run; no candidate reaches every pose within every limit (one line
        with the commonest reason).
    """
    say = progress if progress is not None else silent
    options = ProgramOptions() if options is None else options
    placements = grid.placements()
    say(f"checking the reach of {len(placements)} placements")
    reached = [_reach(robot, program, p) for p in placements]
    if all(isinstance(r, Candidate) for r in reached):
        raise _refusal([r for r in reached if isinstance(r, Candidate)])
    say("today's placement: simulating the program as written")
    settings = program_settings(robot, program, options)
    fixed = replace(
        options,
        cycle_time=settings.cycle_time,
        v_max=settings.caps.speed,
        a_max=settings.caps.acceleration,
    )
    tasks: list[_Task] = [(_today, (robot, program, options))]
    index: dict[int, int] = {}  # placement -> its task
    for i, (placement, r) in enumerate(zip(placements, reached, strict=True)):
        if not isinstance(r, Candidate) and not placement.today:
            index[i] = len(tasks)
            tasks.append((_candidate, (robot, *r, placement, fixed)))
    found = _optimise_all(tasks, say, workers)
    today = found[0]
    candidates = [
        r if isinstance(r, Candidate) else today if p.today else found[index[i]]
        for i, (p, r) in enumerate(zip(placements, reached, strict=True))
    ]
    if not any(c.reachable for c in candidates):
        raise _refusal(candidates)
    best = today if today.reachable else None
    for c in candidates:
        if c.reachable and (best is None or _better(c, best)):
            best = c  # the only one whose optimisation is kept, besides today's
    assert best is not None
    kept = tuple(c if c is best or c is today else c.summary() for c in candidates)
    return PlacementSearch(today, kept, best, fixed)


#: one placement's work: a function of this module and its arguments (picklable: run on a pool)
_Task = tuple[Callable[..., Candidate], tuple[Any, ...]]


def _workers(count: int) -> int:
    """Processes for ``count`` tasks: one per core this process may use, at most one per
    task (each task's result does not depend on which process computes it)."""
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # (not on every platform)
        cores = os.cpu_count() or 1
    return max(1, min(cores, count))


def _optimise_all(tasks: list[_Task], say: Say, workers: int | None) -> list[Candidate]:
    """Every task's candidate, in the order of ``tasks``, computed on ``workers`` processes
    (None: one per core; one: in this process). A task that raises raises here."""
    count = len(tasks)
    n = _workers(count) if workers is None else max(1, min(workers, count))
    out: dict[int, Candidate] = {}
    if n <= 1:
        for i, (task, args) in enumerate(tasks):
            say(_label(i, args), done=i, total=count)
            out[i] = task(*args)
        say("placements optimised", done=count, total=count)
        return [out[i] for i in range(count)]
    say(f"optimising {count} placements on {n} processes", done=0, total=count)
    context = multiprocessing.get_context("spawn")  # no thread of this process is copied
    with ProcessPoolExecutor(max_workers=n, mp_context=context) as pool:
        futures = {pool.submit(task, *args): i for i, (task, args) in enumerate(tasks)}
        try:
            for done, future in enumerate(as_completed(futures)):
                i = futures[future]
                out[i] = future.result()
                say(f"placement {out[i].placement.label()}", done=done + 1, total=count)
        except BaseException:  # today's program cannot run, Ctrl-C: the rest is not started
            for future in futures:
                future.cancel()
            raise
    return [out[i] for i in range(count)]


def _label(i: int, args: tuple[Any, ...]) -> str:
    """What task ``i`` (of :func:`place_program`'s list) works on, for the progress line."""
    return "today's placement" if i == 0 else f"placement {args[3].label()}"


def _better(a: Candidate, b: Candidate) -> bool:
    """Less energy, or as much and nearer today's placement."""
    assert a.e_supply is not None and b.e_supply is not None
    return (a.e_supply, _distance(a.placement)) < (b.e_supply, _distance(b.placement))


def _distance(p: BasePlacement) -> float:
    """How far a placement is from today's (m, a radian of yaw counting as a metre): ties go
    to the nearer."""
    return math.hypot(p.x, p.y, p.z, p.yaw)
