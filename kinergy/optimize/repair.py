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
   (:func:`kinergy.optimize.timing.retime`).

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
from kinergy.optimize.problem import Caps, PathChecks, path_checks, uniform_scaling
from kinergy.optimize.timing import retime
from kinergy.optimize.verify import PathRun, simulate_path
from kinergy.trajectory.program_motion import schedule
from kinergy.trajectory.program_path import ProgramPath

__all__ = ["Context", "Repair", "at_cycle", "repair"]


#: rounds of the per-move repair
_ROUNDS = 3
#: a move over a limit is slowed this much beyond its excess
_MARGIN = 1.005


@dataclass(frozen=True, eq=False)
class Context:
    """What every program of one optimisation is run and judged with: the robot, the cycle time
    (s), the objective, the caps, the arm's standing draw (W) and whether the timing keeps each
    move's share of the cycle time."""

    robot: Robot
    budget: float
    objective: Objective
    caps: Caps
    standby: float
    share_budget: bool = True

    def run(self, path: ProgramPath, label: str) -> PathRun:
        """``path`` at its own timing, re-simulated at 500 Hz against the caps."""
        return simulate_path(
            self.robot,
            path,
            standby=self.standby,
            objective=self.objective,
            speed_cap=self.caps.speed,
            acceleration_cap=self.caps.acceleration,
            label=label,
        )

    def checks(self, path: ProgramPath) -> PathChecks:
        """The timing problem of ``path`` and its checks (:func:`kinergy.optimize.problem.
        path_checks`)."""
        return path_checks(self.robot, path, self.objective, self.caps, self.standby)


@dataclass(frozen=True, eq=False)
class Repair:
    """A repaired program: its 500 Hz run and how it was repaired (``per move`` or
    ``re-timed``)."""

    run: PathRun
    how: str


def at_cycle(ctx: Context, path: ProgramPath, label: str) -> PathRun:
    """``path`` uniformly slowed (or sped up) to last the cycle time, its events keeping their
    time, re-simulated at 500 Hz against the caps."""
    fixed = float(path.event_time.sum())
    own = float(schedule(path, path.speed, path.accel).total[0])
    factor = (own - fixed) / max(ctx.budget - fixed, 1e-9)
    v, a = uniform_scaling(path.speed, path.accel, factor)
    return ctx.run(path.with_timing(v, a), label)


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


def repair(ctx: Context, run: PathRun) -> Repair | None:
    """The program of ``run`` (over a limit at the cycle time) within every limit and cap at the
    same cycle time, by its timing alone (module docstring); None when neither step does it."""
    path, current, budget = run.path, run, ctx.budget
    for _ in range(_ROUNDS):
        timing = _per_move(path, current, budget)
        if timing is None:
            break
        path = path.with_timing(*timing)
        current = ctx.run(path, run.result.label)
        if current.result.ok:
            return Repair(current, "per move")
    try:
        result, _ = retime(ctx.checks(run.path), budget, share_budget=ctx.share_budget)
    except KinergyError:
        return None  # (the cycle time is too short for this path within the caps)
    if not result.ok:
        return None
    # the solver's iterations end a few ms off the cycle time: uniformly to it (the caps keep
    # room for that)
    timed = at_cycle(ctx, run.path.with_timing(result.speeds, result.accels), run.result.label)
    return Repair(timed, "re-timed") if timed.result.ok else None
