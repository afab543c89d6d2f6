"""A lever's program brought back within the limits at the cycle time, before it is judged.

A lever (a turn about the tool axis, another configuration, a via point left out, a blend)
changes how far and how fast the joints move. Uniformly slowed or sped up to the cycle time
(:func:`at_cycle`), its first result can break a joint's speed or acceleration cap or a torque
limit in a few moves while the others have room to spare. :func:`repair` fixes the timing, never
the path, before the lever is judged:

1. **per move**: each move over a limit at 500 Hz is slowed by its excess (``v`` by the speed
   excess, ``a`` by the acceleration or torque excess, 0.5 % more), and the moves within their
   limits are sped up uniformly (``v c``, ``a c^2``, each at most to its own headroom) to keep the
   cycle time: up to three rounds, each re-simulated at 500 Hz;
2. **re-timed**: should that not do, the timing solver at the cycle time within the caps
   (:func:`kinergy.optimize.program_timing.retime`).

Either way the result is a 500 Hz re-simulation; when neither brings it within the limits the
caller drops the lever and says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.optimize.constraints import LIMIT_TOL
from kinergy.optimize.objectives import Objective
from kinergy.optimize.problem import uniform_scaling
from kinergy.optimize.program_timing import PathChecks, path_checks, retime
from kinergy.optimize.program_verify import PathRun, simulate_path
from kinergy.trajectory.program_motion import schedule
from kinergy.trajectory.program_path import ProgramPath

__all__ = ["Caps", "Repair", "at_cycle", "repair", "timing_checks"]


#: rounds of the per-move repair
_ROUNDS = 3
#: a move over a limit is slowed this much beyond its excess
_MARGIN = 1.005
#: the timing solver's caps are this share below the program's: its iterations end a few ms off
#: the cycle time, and the uniform rescaling to it must stay within the caps
_SLACK = 0.005
#: why the timing solver may find no timing for a program that runs within its caps as written
NO_ROOM = (
    f"{100 * _SLACK:g} % below the speed caps (its iterations end a few ms off the cycle time)"
)


@dataclass(frozen=True)
class Caps:
    """The joint speed (rad/s) and acceleration (rad/s^2) caps every program is held to, besides
    the robot's own limits."""

    speed: float
    acceleration: float


@dataclass(frozen=True, eq=False)
class Repair:
    """A repaired program: its 500 Hz run and how it was repaired (``per move`` or
    ``re-timed``)."""

    run: PathRun
    how: str


def at_cycle(
    robot: Robot, path: ProgramPath, budget: float, objective: Objective, caps: Caps, label: str
) -> PathRun:
    """``path`` uniformly slowed (or sped up) to last ``budget`` s, its events keeping their
    time, re-simulated at 500 Hz against the caps."""
    fixed = float(path.event_time.sum())
    own = float(schedule(path, path.speed, path.accel).total[0])
    v, a = uniform_scaling(path.speed, path.accel, (own - fixed) / max(budget - fixed, 1e-9))
    return _run(robot, path.with_timing(v, a), objective, caps, label)


def _run(robot: Robot, path: ProgramPath, objective: Objective, caps: Caps, label: str) -> PathRun:
    return simulate_path(
        robot,
        path,
        objective=objective,
        speed_cap=caps.speed,
        acceleration_cap=caps.acceleration,
        label=label,
    )


def timing_checks(robot: Robot, path: ProgramPath, objective: Objective, caps: Caps) -> PathChecks:
    """The timing problem of ``path`` with the caps ``_SLACK`` below ``caps`` (speed, and its
    square for acceleration: what a uniform rescaling by ``1 + _SLACK`` needs)."""
    v_max, a_max = caps.speed * (1.0 - _SLACK), caps.acceleration * (1.0 - _SLACK) ** 2
    return path_checks(robot, path, objective, v_max, a_max)


def _excess(run: PathRun) -> tuple[Array, Array]:
    """Each move's largest speed ratio and largest acceleration-or-torque ratio to its limit
    over the samples of its own span, shape (K,) each (NaN-free; 0 where nothing moves)."""
    check, sched = run.result.check, run.schedule
    t = check.t
    speed = np.nan_to_num(check.ratios["speed"]).max(axis=1)
    harder = np.maximum(
        np.nan_to_num(check.ratios["acceleration"]).max(axis=1),
        check.ratios["torque"].max(axis=1),
    )
    moves = sched.start.shape[1]
    v_ratio, a_ratio = np.zeros(moves), np.zeros(moves)
    for k in range(moves):
        begin = sched.start[0, k]
        inside = (t >= begin) & (t <= begin + sched.duration[0, k])
        if np.any(inside):
            v_ratio[k] = float(speed[inside].max())
            a_ratio[k] = float(harder[inside].max())
    return v_ratio, a_ratio


def _per_move(path: ProgramPath, run: PathRun, budget: float) -> tuple[Array, Array] | None:
    """New ``(v, a)``: the moves over a limit slowed by their excess, the others sped up to keep
    the cycle time (each at most to its own headroom); None when they cannot keep it."""
    v_ratio, a_ratio = _excess(run)
    over = (v_ratio > 1.0 + LIMIT_TOL) | (a_ratio > 1.0 + LIMIT_TOL)
    moving = path.travel > 0.0
    v, a = path.speed.copy(), path.accel.copy()
    slow_v = np.where(v_ratio > 1.0 + LIMIT_TOL, v_ratio * _MARGIN, 1.0)
    slow_a = np.where(a_ratio > 1.0 + LIMIT_TOL, a_ratio * _MARGIN, 1.0)
    v = np.where(over, v / slow_v, v)
    a = np.where(over, a / slow_a, a)
    free = moving & ~over
    with np.errstate(divide="ignore"):
        room = np.minimum(
            np.where(v_ratio > 0.0, 1.0 / v_ratio, np.inf),
            np.where(a_ratio > 0.0, 1.0 / np.sqrt(a_ratio), np.inf),
        )
    room = np.where(free, np.maximum(room / _MARGIN, 1.0), 1.0)

    def total(c: float) -> float:
        factor = np.minimum(c, room)
        return float(schedule(path, v * factor, a * factor**2).total[0]) - budget

    if total(1.0) <= 0.0:  # the slowed moves still fit: all slowed alike to the cycle time

        def slower(c: float) -> float:
            return float(schedule(path, v * c, a * c**2).total[0]) - budget

        c = brentq(slower, 1e-3, 1.0, xtol=1e-12, rtol=1e-12, maxiter=200)
        return v * c, a * c**2
    top = float(np.max(room[free])) if np.any(free) else 1.0
    if not np.isfinite(top):
        top = 1e3
    if total(top) > 0.0:
        return None
    c = brentq(total, 1.0, top, xtol=1e-12, rtol=1e-12, maxiter=200)
    factor = np.minimum(c, room)
    return v * factor, a * factor**2


def repair(
    robot: Robot,
    run: PathRun,
    budget: float,
    objective: Objective,
    caps: Caps,
) -> Repair | None:
    """The program of ``run`` (over a limit at ``budget`` s) within every limit and cap at the
    same cycle time, by its timing alone (module docstring); None when neither step does it.

    Raises
    ------
    KinergyError
        Not raised for a program the timing cannot repair; only for bad input (a move whose
        torques exceed the limits at any acceleration names its line).
    """
    path, current = run.path, run
    for _ in range(_ROUNDS):
        timing = _per_move(path, current, budget)
        if timing is None:
            break
        path = path.with_timing(*timing)
        current = _run(robot, path, objective, caps, run.result.label)
        if current.result.ok:
            return Repair(current, "per move")
    try:
        checks = timing_checks(robot, run.path, objective, caps)
        result, _ = retime(checks, budget)
    except KinergyError:
        return None  # (the cycle time is too short for this path within the caps)
    if not result.ok:
        return None
    timed = _run(
        robot, run.path.with_timing(result.speeds, result.accels), objective, caps, run.result.label
    )
    return Repair(timed, "re-timed") if timed.result.ok else None
