"""Verification: a robot program re-simulated at the controller's 500 Hz, and its targets.

:func:`simulate_path` re-simulates a resolved program (:mod:`kinergy.trajectory.program_motion`)
every :data:`VERIFY_DT` and reports it as a :class:`ProgramResult`: the objective (the supply
energy, :mod:`kinergy.optimize.objectives`) at the 500 Hz samples and per move, the motors'
electrical energy on the bus (clipped at 0: what the supply delivers to them, without the
standing draw) with its breakdown (:func:`kinergy.accounting.energy.energy`, each sample with the
load the program sets there, as ``kinergy energy`` accounts a program), and every joint limit at
every sample (:func:`kinergy.optimize.constraints.limit_violations`). Every figure the optimiser
reports is such a re-simulation, not its quadrature (which agrees within about 0.1 %).

:func:`target_errors` checks a changed program against the one it came from: the tool at every
stop (a move that ends at rest: before an event, at the end, or without a blend) within a
distance and an angle of the original target, up to a declared tool symmetry about the tool's z
axis; the arm at rest at those stops and during every event; how far blended via points are
passed.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from kinergy.accounting.energy import energy
from kinergy.arrays import Array
from kinergy.dynamics.poses import tcp_pose
from kinergy.model.robot import Robot
from kinergy.model.uncertainty import Uncertainty
from kinergy.optimize.constraints import LimitCheck, limit_violations
from kinergy.optimize.objectives import Objective, SupplyEnergy
from kinergy.optimize.options import ToolSymmetry
from kinergy.optimize.samples import grid_weights, samples_at
from kinergy.predict import drive_by_payload
from kinergy.trajectory.motion import CONTROLLER_DT, Motion
from kinergy.trajectory.program_motion import Schedule, payload_index, program_motion, sample_path
from kinergy.trajectory.program_path import ProgramPath

__all__ = [
    "VERIFY_DT",
    "PathRun",
    "ProgramResult",
    "TargetCheck",
    "simulate_path",
    "target_errors",
]


#: sample period of every verification: the UR controller's 500 Hz
VERIFY_DT = CONTROLLER_DT


@dataclass(frozen=True, eq=False)
class ProgramResult:
    """A program's timing and its re-simulated energy and limits.

    Attributes
    ----------
    label : str
        ``program``, ``optimized``, a lever's name, ...
    speeds, accels, blends : ndarray, shape (K,)
        Each move's ``v``, ``a`` and blend radius, in the move's own units.
    starts, durations : ndarray, shape (K,)
        When each move starts and how long it lasts on its own, s.
    cycle_time : float
        s.
    e_elec : float
        The motors' electrical energy on the DC bus, braking surplus lost in the shunt,
        re-simulated at 500 Hz, J: the motors' part of the supply energy.
    e_moves : ndarray, shape (K,)
        The objective's share per move (the move and the events after it), J.
    breakdown : dict of str to float
        ``inertial``, ``gravity``, ``friction``, ``copper`` parts of the motors' energy, J.
    check : LimitCheck
        The limits at every 500 Hz sample.
    predicted : float or None
        The optimiser's own (quadrature) estimate of its objective.
    score : float or None
        The objective (:mod:`kinergy.optimize.objectives`) at the 500 Hz samples: what the
        comparison of programs uses (the supply energy, J, by default).
    standby : float
        The arm's standing draw, W: the supply energy is ``e_elec + standby * cycle_time``.
    """

    label: str
    speeds: Array
    accels: Array
    blends: Array
    starts: Array
    durations: Array
    cycle_time: float
    e_elec: float
    e_moves: Array
    breakdown: dict[str, float]
    check: LimitCheck = field(repr=False)
    predicted: float | None = None
    score: float | None = None
    standby: float = 0.0

    @property
    def ok(self) -> bool:
        """Whether every 500 Hz sample is within every limit."""
        return self.check.ok

    @property
    def e_standby(self) -> float:
        """The standing draw over the cycle, J."""
        return self.standby * self.cycle_time

    @property
    def e_supply(self) -> float:
        """What the arm draws from its supply per cycle, J: the motors plus the standing draw."""
        return self.e_elec + self.e_standby

    def to_dict(self) -> dict[str, Any]:
        worst = self.check.worst()
        return {
            "label": self.label,
            "cycle_time": self.cycle_time,
            "e_elec": self.e_elec,
            "e_standby": self.e_standby,
            "e_supply": self.e_supply,
            "score": self.score,
            "predicted": self.predicted,
            "breakdown": dict(self.breakdown),
            "moves": [
                {
                    "v": float(self.speeds[k]),
                    "a": float(self.accels[k]),
                    "blend": float(self.blends[k]),
                    "start": float(self.starts[k]),
                    "duration": float(self.durations[k]),
                    "energy": float(self.e_moves[k]),
                }
                for k in range(self.speeds.size)
            ],
            "limits": {
                kind: {"ratio": ratio, "joint": joint, "t": t}
                for kind, (ratio, joint, t) in worst.items()
            },
            "within_limits": self.ok,
            "violations": self.check.violations(),
        }


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


def simulate_path(
    robot: Robot,
    path: ProgramPath,
    *,
    standby: float = 0.0,
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
    standby : float
        The arm's standing draw, W (>= 0).
    objective : Objective, optional
        Scores the run (``score``, ``e_moves``); default :class:`SupplyEnergy` with ``standby``.
    speed_cap, acceleration_cap : float, optional
        Caps on every joint's speed (rad/s) and acceleration (rad/s^2) besides the robot's limits.
    label : str
    predicted : float, optional
        The optimiser's estimate of the objective.

    Returns
    -------
    PathRun
        ``result.e_elec``: the motors' electrical energy on the bus, clipped at 0, J;
        ``result.e_supply``: plus the standing draw; ``result.score``: the objective;
        ``result.e_moves``: its share per move (a move's events count to it);
        ``result.blends``: each move's blend radius in its own unit.
    """
    objective = SupplyEnergy(standby) if objective is None else objective
    motion, sched = program_motion(robot, path)
    load = payload_index(path, sched, motion.t)[0]
    drive = drive_by_payload(path.robots, load, motion.q, motion.qd, motion.qdd)
    report = energy(robot, motion, recovery=False, state=drive)
    samples = samples_at(
        motion.t[None, :],
        grid_weights(motion.t)[None, :],
        sched.start,
        sched.start + sched.duration,
        drive,
    )
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
        e_elec=report.total_e_elec,
        e_moves=parts[0],
        breakdown={k: float(v.sum()) for k, v in report.breakdown.items()},
        check=check,
        predicted=predicted,
        score=float(score[0]),
        standby=standby,
    )
    gradient = None if report.intervals is None else report.intervals.gradients["motors"]
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
