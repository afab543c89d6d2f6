"""The ``kinergy excite`` pipeline: design an excitation, compare it with random ones, write it.

:func:`run_excite` builds the design problem (:func:`kinergy.experiments.excitation_problem.
excitation_problem`: nursing eqs 22-23), optimises it (:func:`kinergy.experiments.
excitation_design.design_excitation`), draws ``compare`` random feasible excitations of the same
size for comparison, and writes ``periods`` repeats of the design at ``dt`` in UR's record.py
layout (``timestamp target_q_* target_qd_* target_qdd_*``, the motion file ``kinergy simulate
ROBOT --trajectory FILE`` runs on the twin) and, where asked, a URScript ``servoj`` program that
runs it: all files or none.
"""

from __future__ import annotations

import contextlib
import enum
import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from kinergy.checks import choice, flag, integer, number
from kinergy.errors import KinergyError
from kinergy.experiments.excitation_design import (
    Excitation,
    Progress,
    design_excitation,
    random_feasible,
)
from kinergy.experiments.excitation_limits import DEFAULT_RANGE, excitation_limits
from kinergy.experiments.excitation_problem import ExcitationProblem, excitation_problem
from kinergy.experiments.excitation_regression import CRITERIA
from kinergy.io.rtde import write_log
from kinergy.io.urscript import servoj_program, write_script
from kinergy.model.robot import Robot
from kinergy.trajectory.motion import Motion
from kinergy.workflows.twin import MAX_SEED

__all__ = ["COUNTS", "LIMITS", "ExciteOptions", "ExciteRun", "FloorFrames", "run_excite"]

#: report progress every this many SLSQP iterations
_PROGRESS_EVERY = 10


#: flags that count something: the least and most each may be (the most: sizes that fit in
#: memory and finish in minutes)
COUNTS = {
    "harmonics": (2, 50),
    "periods": (1, 100),
    "starts": (1, 1000),
    "maxiter": (1, 100_000),
    "samples": (1, 20_000),
    "compare": (0, 10_000),
}
#: flags that must be > 0 when given, with their least and most values (s, deg, rad/s, rad/s^2)
LIMITS = {
    "period": (1e-2, 600.0),
    "range_deg": (1e-3, 360.0),
    "speed": (1e-3, 100.0),
    "acceleration": (1e-3, 1e4),
}
#: m: the highest (and lowest) floor taken
MAX_FLOOR = 100.0


class FloorFrames(enum.Enum):
    """What keeps above the floor: the flange and the link frames from the elbow on
    (``LINKS``), or the flange only."""

    LINKS = "links"
    FLANGE = "flange"


def _angles(value: str | Sequence[float], what: str) -> tuple[float, ...]:
    """``"0,-90,0"`` (or a sequence of numbers) as a tuple of finite numbers."""
    parts = value.split(",") if isinstance(value, str) else list(value)
    try:
        out = tuple(float(x) for x in parts)
    except ValueError:
        out = ()
    if not out or not all(math.isfinite(x) for x in out):
        raise KinergyError(
            f"{what}: must be comma-separated finite angles in deg, got {str(value)!r}"
        )
    return out


@dataclass(frozen=True, kw_only=True)
class ExciteOptions:
    """What ``kinergy excite`` designs and writes (one field per command-line flag), checked on
    construction: one line naming the flag.

    Attributes
    ----------
    out : path
        Motion file to write (record.py layout, every ``dt``).
    urscript : path or None
        URScript program to write (movej to the start, then servoj every ``dt``; 6-joint arms).
    harmonics : int
        ``L`` of nursing eq 22 (2 to 50).
    period : float
        ``T``, s (0.01 to 600).
    periods : int
        Periods written to the motion file (1 to 100).
    criterion : {"cond", "dopt"}
    seed, starts, maxiter : int
        Seed of the random starts, their number, SLSQP iterations per start.
    samples : int
        Grid points per period for the criterion.
    floor : float or None
        Height above the base plane the checked frames keep, m (None: no floor).
    floor_frames : FloorFrames
    start_deg : tuple of float or None
        Start and end pose, deg, one per joint (text ``"0,-90,0,..."`` parsed on construction;
        None: the default of :func:`excitation_problem`).
    range_deg : float
        Half-width of each joint's range about the start pose, deg (0.001 to 360).
    speed, acceleration : float or None
        Limits, rad/s and rad/s^2 (None: the robot's).
    include_drives : bool
        Condition the rotor-inertia and friction columns too.
    compare : int
        Random feasible excitations to compare with (0: none).
    """

    out: str | os.PathLike[str]
    urscript: str | os.PathLike[str] | None = None
    harmonics: int = 5
    period: float = 10.0
    periods: int = 2
    criterion: str = "cond"
    seed: int = 0
    starts: int = 4
    maxiter: int = 100
    samples: int = 200
    floor: float | None = 0.05
    floor_frames: FloorFrames = FloorFrames.LINKS
    start_deg: tuple[float, ...] | None = None
    range_deg: float = math.degrees(DEFAULT_RANGE)
    speed: float | None = None
    acceleration: float | None = None
    include_drives: bool = True
    compare: int = 0

    def __post_init__(self) -> None:
        for name, (least, most) in COUNTS.items():
            object.__setattr__(
                self, name, integer(getattr(self, name), flag(name), ge=least, le=most)
            )
        object.__setattr__(self, "seed", integer(self.seed, "--seed", ge=0, le=MAX_SEED))
        for name, (low, high) in LIMITS.items():
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, number(value, flag(name), ge=low, le=high))
        if self.floor is not None:
            floor = number(self.floor, "--floor", ge=-MAX_FLOOR, le=MAX_FLOOR)
            object.__setattr__(self, "floor", floor)
        if self.criterion not in CRITERIA:
            known = ", ".join(CRITERIA)
            raise KinergyError(f"--criterion: must be one of {known}, got {self.criterion!r}")
        object.__setattr__(
            self, "floor_frames", choice(self.floor_frames, FloorFrames, "floor_frames")
        )
        if self.start_deg is not None:
            object.__setattr__(self, "start_deg", _angles(self.start_deg, "--start-deg"))
        object.__setattr__(self, "include_drives", bool(self.include_drives))

    def check(self, robot: Robot) -> None:
        """Refuse what ``robot`` cannot take: a start pose of another joint count, URScript for
        an arm that is not a 6-joint UR."""
        if self.start_deg is not None and len(self.start_deg) != robot.n:
            raise KinergyError(
                f"--start-deg: must be {robot.n} comma-separated angles in deg, got "
                f"{len(self.start_deg)}"
            )
        if self.urscript is not None and robot.n != 6:
            raise KinergyError(
                f"--urscript: URScript runs 6-joint UR arms; {robot.name} has {robot.n}"
            )


@dataclass(frozen=True, eq=False)
class ExciteRun:
    """What ``kinergy excite`` designed and wrote.

    Attributes
    ----------
    robot : Robot
    options : ExciteOptions
    problem : ExcitationProblem
    best : Excitation
        The optimised excitation.
    motion : Motion
        What the motion file holds: ``options.periods`` periods of ``best``.
    randoms : list of float
        Condition numbers of the random feasible excitations compared with.
    written : list of Path
        The files written.
    """

    robot: Robot
    options: ExciteOptions
    problem: ExcitationProblem
    best: Excitation
    motion: Motion
    randoms: list[float] = field(default_factory=list)
    written: list[Path] = field(default_factory=list)

    @property
    def median(self) -> float | None:
        """Median condition number of the random excitations (None without any)."""
        return float(np.median(self.randoms)) if self.randoms else None

    def to_dict(self) -> dict[str, Any]:
        """The ``excite --json`` shape: the design, the run's size, limits and comparison."""
        median = self.median
        return {
            "robot": self.robot.name,
            **self.best.to_dict(),
            "periods": self.options.periods,
            "samples": len(self.motion),
            "duration": self.motion.duration,
            "columns": self.problem.columns,
            "limits": self.problem.limits.to_dict(),
            "random": None
            if median is None
            else {"count": len(self.randoms), "median": median, "conditions": self.randoms},
            "ratio": None if median is None else median / self.best.condition,
            "out": str(self.options.out),
            "urscript": None if self.options.urscript is None else str(self.options.urscript),
        }


def _problem(robot: Robot, options: ExciteOptions) -> ExcitationProblem:
    start = None if options.start_deg is None else np.radians(options.start_deg)
    limits = excitation_limits(
        robot,
        start=start,
        position_range=math.radians(options.range_deg),
        speed=options.speed,
        acceleration=options.acceleration,
        floor=options.floor,
        floor_frames=options.floor_frames.value,
    )
    return excitation_problem(
        robot,
        limits=limits,
        harmonics=options.harmonics,
        period=options.period,
        criterion=options.criterion,
        include_drives=options.include_drives,
        samples=options.samples,
    )


def _design_progress(say: Callable[[str], None] | None, starts: int) -> Progress | None:
    """The optimiser's progress as a message every :data:`_PROGRESS_EVERY` iterations."""
    if say is None:
        return None

    def report(start: int, iteration: int, condition: float) -> None:
        if iteration % _PROGRESS_EVERY == 0:
            say(f"start {start}/{starts}, iteration {iteration}: condition number {condition:.4g}")

    return report


def _script(robot: Robot, best: Excitation, motion: Motion, periods: int) -> str:
    """The URScript program that moves to the start and runs ``motion`` with servoj."""
    return servoj_program(
        motion.t,
        motion.q,
        name="kinergy_excitation",
        comments=[
            f"{robot.name}: excitation of {best.harmonics} harmonics, period "
            f"{best.period:g} s, {periods} period(s); condition number {best.condition:.4g}"
        ],
    )


def _write(robot: Robot, options: ExciteOptions, best: Excitation, motion: Motion) -> list[Path]:
    """Write the motion file and, where asked, the URScript: all or none (a failure removes
    what was written). Returns the paths written."""
    script = None if options.urscript is None else _script(robot, best, motion, options.periods)
    signals = {"target_q": motion.q, "target_qd": motion.qd, "target_qdd": motion.qdd}
    written: list[Path] = []
    with contextlib.ExitStack() as undo:
        write_log(options.out, motion.t, signals)
        written.append(Path(options.out))
        undo.callback(written[0].unlink, missing_ok=True)
        if script is not None and options.urscript is not None:
            written.append(write_script(options.urscript, script))
        undo.pop_all()  # everything is written: keep it
    return written


def run_excite(
    robot: Robot, options: ExciteOptions, *, progress: Callable[[str], None] | None = None
) -> ExciteRun:
    """``kinergy excite``: design the excitation, compare it with ``options.compare`` random
    feasible ones (seeded ``options.seed + 1``), write the motion file and the URScript.

    Parameters
    ----------
    robot : Robot
    options : ExciteOptions
    progress : callable, optional
        Called with a message every few optimiser iterations and before the random draws.

    Raises
    ------
    KinergyError
        Bad options (:func:`excitation_problem`), an unwritable file.
    """
    options.check(robot)
    problem = _problem(robot, options)
    best = design_excitation(
        problem,
        starts=options.starts,
        seed=options.seed,
        maxiter=options.maxiter,
        progress=_design_progress(progress, options.starts),
    )
    randoms: list[float] = []
    if options.compare:
        if progress is not None:
            progress(f"drawing {options.compare} random feasible trajectories")
        draws = random_feasible(problem, np.random.default_rng(options.seed + 1), options.compare)
        randoms = [e.condition for e in draws]
    motion = best.repeated(options.periods)
    written = _write(robot, options, best, motion)
    return ExciteRun(robot, options, problem, best, motion, randoms, written)
