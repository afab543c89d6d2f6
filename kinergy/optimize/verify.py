"""Verification: a movej program re-simulated at the controller's 500 Hz.

Every program the optimiser compares (as written, uniformly scaled, optimised) is re-simulated
with :func:`kinergy.trajectory.movej.movej` every :data:`VERIFY_DT` and accounted with
:func:`kinergy.accounting.energy.energy` (the one forward path, UR5e eqs 23-26): the energy
reported is this re-simulation's, not the optimiser's quadrature (which agrees within about
0.1 %), and every limit is checked at every one of its samples
(:func:`kinergy.optimize.constraints.limit_violations`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import cumulative_trapezoid

from kinergy.accounting.energy import energy
from kinergy.arrays import Array
from kinergy.model.robot import Robot
from kinergy.optimize.constraints import LimitCheck, limit_violations
from kinergy.optimize.objectives import Objective
from kinergy.optimize.program import motion_samples, serial
from kinergy.trajectory.motion import CONTROLLER_DT
from kinergy.trajectory.movej import movej, plan_movej

__all__ = ["VERIFY_DT", "ProgramResult", "program_energy", "simulate_program"]


#: sample period of every verification: the UR controller's 500 Hz
VERIFY_DT = CONTROLLER_DT


@serial
def program_energy(
    robot: Robot,
    waypoints: ArrayLike,
    speeds: ArrayLike,
    accels: ArrayLike,
    blends: ArrayLike = 0.0,
    dt: float = VERIFY_DT,
    *,
    recovery: bool = True,
) -> float:
    """Total electrical energy of a movej program, re-simulated every ``dt`` s, J (UR5e eq 26).

    Parameters
    ----------
    robot : Robot
    waypoints : array_like, shape (K + 1, n)
        Start pose and targets, rad.
    speeds, accels : float or array_like, shape (K,)
        Leading-joint ``v`` (rad/s) and ``a`` (rad/s^2) per move.
    blends : float or array_like, shape (K,)
        Joint-space blend radii, rad (:func:`kinergy.trajectory.movej.plan_movej`).
    dt : float
        Sample period, s (0.002: the controller's 500 Hz).
    recovery : bool
        Braking energy returns to the bus (default, as the seed).
    """
    motion = movej(waypoints, speed=speeds, acceleration=accels, blend=blends, dt=dt)
    return energy(robot, motion, recovery=recovery).total_e_elec


@dataclass(frozen=True, eq=False)
class ProgramResult:
    """A movej program's settings and its re-simulated energy and limits.

    Attributes
    ----------
    label : str
        ``program``, ``uniform`` or ``optimized``.
    speeds, accels, blends : ndarray, shape (K,)
        rad/s, rad/s^2, rad (joint-space blend).
    starts, durations : ndarray, shape (K,)
        When each move starts and how long it lasts on its own, s.
    cycle_time : float
        s.
    e_elec : float
        Total electrical energy of the motors, re-simulated at 500 Hz, J.
    e_moves : ndarray, shape (K,)
        Its share per move (the bus energy between one move's start and the next's), J.
    breakdown : dict of str to float
        ``inertial``, ``gravity``, ``friction``, ``copper`` parts of ``e_elec``, J.
    check : LimitCheck
        The limits at every 500 Hz sample.
    predicted : float or None
        The optimiser's own (quadrature) estimate of its objective (``e_elec`` by default).
    score : float or None
        The objective (:mod:`kinergy.optimize.objectives`) at the 500 Hz samples, when scored;
        what the comparison of programs uses (``e_elec`` up to rounding, by default).
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

    @property
    def ok(self) -> bool:
        """Whether every 500 Hz sample is within every limit."""
        return self.check.ok

    def to_dict(self) -> dict[str, Any]:
        worst = self.check.worst()
        return {
            "label": self.label,
            "cycle_time": self.cycle_time,
            "e_elec": self.e_elec,
            "predicted_e_elec": self.predicted,
            "breakdown": dict(self.breakdown),
            "moves": [
                {
                    "v": float(self.speeds[k]),
                    "a": float(self.accels[k]),
                    "blend": float(self.blends[k]),
                    "start": float(self.starts[k]),
                    "duration": float(self.durations[k]),
                    "e_elec": float(self.e_moves[k]),
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


@serial
def simulate_program(
    robot: Robot,
    waypoints: ArrayLike,
    speeds: ArrayLike,
    accels: ArrayLike,
    blends: ArrayLike = 0.0,
    *,
    dt: float = VERIFY_DT,
    recovery: bool = True,
    speed_cap: float | None = None,
    acceleration_cap: float | None = None,
    label: str = "program",
    predicted: float | None = None,
    objective: Objective | None = None,
) -> ProgramResult:
    """Re-simulate a movej program at ``dt``: its energy (total, per move, breakdown) and limits.

    Parameters are those of :func:`program_energy` and
    :func:`kinergy.optimize.constraints.limit_violations`; ``label`` and ``predicted`` are
    passed on to the result, and ``objective`` (optional) scores the re-simulation
    (:attr:`ProgramResult.score`).
    """
    w = np.asarray(waypoints, dtype=float)
    plan = plan_movej(w, speed=speeds, acceleration=accels, blend=blends)
    motion = movej(w, speed=speeds, acceleration=accels, blend=blends, dt=dt)
    report = energy(robot, motion, recovery=recovery)
    bus = report.p_elec.sum(axis=1)
    if not recovery:
        bus = np.maximum(bus, 0.0)
    cumulative = cumulative_trapezoid(bus, motion.t, initial=0.0)
    bounds = np.concatenate([[motion.t[0]], plan.start[1:], [motion.t[-1]]])
    e_moves = np.diff(np.interp(bounds, motion.t, cumulative))
    check = limit_violations(
        robot, motion, report.drive, speed_cap=speed_cap, acceleration_cap=acceleration_cap
    )
    moves = plan.start.size
    score = None
    if objective is not None:
        score = float(objective(motion_samples(motion.t, plan, report.drive))[0][0])
    return ProgramResult(
        label=label,
        speeds=np.broadcast_to(np.asarray(speeds, dtype=float), (moves,)).copy(),
        accels=np.broadcast_to(np.asarray(accels, dtype=float), (moves,)).copy(),
        blends=np.broadcast_to(np.asarray(blends, dtype=float), (moves,)).copy(),
        starts=plan.start,
        durations=plan.duration,
        cycle_time=plan.total_time,
        e_elec=report.total_e_elec,
        e_moves=e_moves,
        breakdown={k: float(v.sum()) for k, v in report.breakdown.items()},
        check=check,
        predicted=predicted,
        score=score,
    )
