"""Verification of a robot program: re-simulated at the controller's 500 Hz, and its targets.

:func:`simulate_path` re-simulates a resolved program (:mod:`kinergy.trajectory.program_motion`)
every 2 ms and reports it as a :class:`~kinergy.optimize.verify.ProgramResult`: the objective
(the supply energy by default, :mod:`kinergy.optimize.objectives`) at the 500 Hz samples and per
move, the motors' electrical energy on the bus (clipped at 0: what the supply delivers, without
standby) with its breakdown (:func:`kinergy.accounting.energy.energy`, each stretch with the load
the program sets there), and every joint limit at every sample
(:func:`kinergy.optimize.constraints.limit_violations`).

:func:`target_errors` checks a changed program against the one it came from: the tool at every
stop (a move that ends at rest: before an event, at the end, or without a blend) within a
distance and an angle of the original target, up to a declared tool symmetry about the tool's z
axis; the arm at rest at those stops and during every event; how far blended via points are
passed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from kinergy.accounting.energy import energy
from kinergy.arrays import Array
from kinergy.dynamics.poses import tcp_pose
from kinergy.model.robot import Robot
from kinergy.model.uncertainty import Uncertainty
from kinergy.optimize.constraints import limit_violations
from kinergy.optimize.objectives import Objective, SupplyEnergy
from kinergy.optimize.options import ToolSymmetry
from kinergy.optimize.program_samples import grid_path_samples
from kinergy.optimize.verify import ProgramResult
from kinergy.predict import DriveState
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.program_motion import Schedule, payload_index, program_motion, sample_path
from kinergy.trajectory.program_path import ProgramPath

__all__ = ["PathRun", "TargetCheck", "simulate_path", "target_errors"]


@dataclass(frozen=True, eq=False)
class PathRun:
    """A program re-simulated at 500 Hz: the result, the motion and its schedule; where the
    model carries parameter errors (``errors``), the gradient of the motors' supply energy
    ``result.e_elec`` over them (J per parameter unit, :mod:`kinergy.accounting.uncertainty`)."""

    result: ProgramResult
    motion: Motion
    schedule: Schedule
    path: ProgramPath
    gradient: Array | None = None
    errors: Uncertainty | None = None


def _energy(
    robot: Robot, path: ProgramPath, motion: Motion, sched: Schedule
) -> tuple[float, dict[str, float], DriveState, Array | None]:
    """Clipped bus energy (J), its breakdown, the drive state over the motion, each stretch
    of samples with its own load, and the energy's gradient over the model's parameter errors
    (None without them)."""
    load = payload_index(path, sched, motion.t)[0]
    cuts = np.flatnonzero(np.diff(load)) + 1
    bounds = np.concatenate([[0], cuts, [motion.t.size]])
    total = 0.0
    parts: dict[str, float] = {}
    states = []
    gradient: Array | None = None
    for i in range(bounds.size - 1):
        lo, hi = int(bounds[i]), int(bounds[i + 1])
        stretch = motion.sliced(max(lo - 1, 0), hi)  # one shared sample: the integrals add up
        report = energy(robot.with_payload(path.payloads[int(load[lo])]), stretch, recovery=False)
        total += report.total_e_elec
        if report.intervals is not None:
            g = report.intervals.gradients["motors"]
            gradient = g if gradient is None else gradient + g
        for key, value in report.breakdown.items():
            parts[key] = parts.get(key, 0.0) + float(value.sum())
        skip = 1 if lo > 0 else 0
        states.append({f: getattr(report.drive, f)[skip:] for f in DriveState.__dataclass_fields__})
    drive = DriveState(**{f: np.vstack([s[f] for s in states]) for f in states[0]})
    return total, parts, drive, gradient


def simulate_path(
    robot: Robot,
    path: ProgramPath,
    *,
    objective: Objective | None = None,
    speed_cap: float | None = None,
    acceleration_cap: float | None = None,
    label: str = "program",
    predicted: float | None = None,
) -> PathRun:
    """Re-simulate a program at 500 Hz at its moves' ``path.speed`` and ``path.accel``.

    Parameters
    ----------
    robot : Robot
    path : ProgramPath
    objective : Objective, optional
        Scores the run (``score``, ``e_moves``); default :class:`SupplyEnergy` without standby.
    speed_cap, acceleration_cap : float, optional
        Caps on every joint's speed (rad/s) and acceleration (rad/s^2) besides the robot's limits.
    label : str
    predicted : float, optional
        The optimiser's estimate of the objective.

    Returns
    -------
    PathRun
        ``result.e_elec``: the motors' electrical energy on the bus, clipped at 0, J;
        ``result.score``: the objective; ``result.e_moves``: its share per move (a move's events
        count to it); ``result.blends``: each move's blend radius in its own unit.
    """
    objective = SupplyEnergy() if objective is None else objective
    motion, sched = program_motion(robot, path)
    e_bus, breakdown, drive, gradient = _energy(robot, path, motion, sched)
    samples = grid_path_samples(robot, path, sched, motion)
    score, parts = objective(samples)
    check = limit_violations(
        robot, motion, drive, speed_cap=speed_cap, acceleration_cap=acceleration_cap
    )
    result = ProgramResult(
        label=label,
        speeds=path.speed.copy(),
        accels=path.accel.copy(),
        blends=np.where(path.linked, path.blend, 0.0),
        starts=sched.start[0],
        durations=sched.duration[0],
        cycle_time=float(sched.total[0]),
        e_elec=e_bus,
        e_moves=parts[0],
        breakdown=breakdown,
        check=check,
        predicted=predicted,
        score=float(score[0]),
    )
    return PathRun(result, motion, sched, path, gradient, robot.uncertainty)


@dataclass(frozen=True)
class TargetCheck:
    """How a changed program meets one of the original program's targets.

    Attributes
    ----------
    line : int
        The move's line in the program.
    stop : bool
        Whether the move ends at rest (else it is a via point the program blends through).
    left_out : bool
        A joint-space via point the route leaves out (free via points): not a target of the
        job, its figures are those of the move's new end.
    distance : float
        Stops: the tool's distance from the target at the stop, m. Via points: the closest the
        tool passes, m.
    angle : float
        Stops: the tool's rotation from the target's (up to the tool symmetry), rad; NaN at via
        points.
    speed : float
        Stops: the largest joint speed at the stop, rad/s; NaN at via points.

    A stop is checked at the instant its move ends (the planned motion there, not the next
    500 Hz sample, which may already lie in the following move).
    """

    line: int
    stop: bool
    distance: float
    angle: float
    speed: float
    left_out: bool = False

    def to_dict(self) -> dict[str, Any]:
        return {
            "line": self.line,
            "stop": self.stop,
            "left_out": self.left_out,
            "distance": self.distance,
            "angle": None if np.isnan(self.angle) else self.angle,
            "speed": None if np.isnan(self.speed) else self.speed,
        }


def _angle(want: Array, got: Array, symmetry: ToolSymmetry) -> float:
    """Rotation angle between two orientations (3, 3), rad, up to turns about the tool z axis."""
    if symmetry.any_angle:
        return float(np.arccos(np.clip(want[:, 2] @ got[:, 2], -1.0, 1.0)))
    best = np.inf
    for a in symmetry.equivalent():
        rz = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
        rel = (want @ rz).T @ got
        best = min(best, float(np.arccos(np.clip(0.5 * (np.trace(rel) - 1.0), -1.0, 1.0))))
    return best


def target_errors(
    robot: Robot,
    original: ProgramPath,
    run: PathRun,
    *,
    symmetry: ToolSymmetry = ToolSymmetry.NONE,
    left_out: NDArray[np.bool_] | None = None,
) -> list[TargetCheck]:
    """Check every target of ``original`` in a re-simulated changed program (same moves).

    Parameters
    ----------
    robot : Robot
    original : ProgramPath
        The program as written.
    run : PathRun
        The changed program at 500 Hz.
    symmetry : ToolSymmetry
        Turns about the tool axis that meet a target.
    left_out : ndarray of bool, shape (K,), optional
        Via points the changed route leaves out (checked where the move now ends instead).

    Returns
    -------
    list of TargetCheck
        One per move, in order.
    """
    path, motion, sched = run.path, run.motion, run.schedule
    skipped = np.zeros(path.moves, dtype=bool) if left_out is None else left_out
    want = np.array(
        [
            tcp_pose(robot, (path if skipped[k] else original).q_end[k], original.tcp[k])
            for k in range(original.moves)
        ]
    )
    out = []
    for k in range(path.moves):
        end = sched.start[0, k] + sched.duration[0, k]
        line = original.program.moves[k].line
        if path.linked[k]:
            tips = tcp_pose(robot, motion.q, path.tcp[k])[:, :3, 3]
            gap = float(np.min(np.linalg.norm(tips - want[k, :3, 3], axis=1)))
            out.append(TargetCheck(line, False, gap, np.nan, np.nan, bool(skipped[k])))
            continue
        q, qd, _ = sample_path(robot, path, sched, np.array([[end]]))
        got = tcp_pose(robot, q[0, 0], path.tcp[k])
        out.append(
            TargetCheck(
                line=line,
                stop=True,
                distance=float(np.linalg.norm(got[:3, 3] - want[k, :3, 3])),
                angle=_angle(want[k, :3, :3], got[:3, :3], symmetry),
                speed=float(np.max(np.abs(qd[0, 0]))),
                left_out=bool(skipped[k]),
            )
        )
    return out
