"""Energy-optimal speeds and accelerations of a robot program's moves at a cycle time.

The timing lever of a URScript program: each move's ``v`` and ``a`` (movej: of the leading joint,
rad/s and rad/s^2; movel/movep: along the tool's path, m/s and m/s^2), the path and the events'
times fixed. :func:`path_problem` states it as a
:class:`~kinergy.optimize.problem.TimingProblem` (the same solver as a movej task,
:mod:`kinergy.optimize.solve`), over the samples of :mod:`kinergy.optimize.program_samples`:

- caps per move: every joint's speed and acceleration limit and the optimiser's caps
  (``v_max``, ``a_max``: by default the program's own peak joint speed and acceleration), turned
  into the move's own unit by the most any joint moves per unit of its path (a movej's leading
  joint; along a tool line, ``max_s |dq_j/ds|``); the torque-limited acceleration at full speed
  by a scan (:func:`kinergy.optimize.problem.fastest_acceleration`);
- the cycle time: the moves' durations (less the blends' overlaps) plus the events' fixed times.

:func:`retime` solves it at a budget and verifies the optimum at 500 Hz
(:func:`kinergy.optimize.timing.best_verified`: caps tightened by any excess found there); it
stops on iterations and tolerances, never on a clock.
:func:`scaled_to` is uniform time scaling of the moves to a budget (the events keep their time).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.optimize.constraints import torque_ratio
from kinergy.optimize.objectives import Objective
from kinergy.optimize.problem import Evaluator, TimingProblem, fastest_acceleration, uniform_scaling
from kinergy.optimize.program_samples import path_schedule, sample_path_programs
from kinergy.optimize.program_verify import PathRun, simulate_path
from kinergy.optimize.timing import Verified, best_verified
from kinergy.optimize.verify import ProgramResult
from kinergy.trajectory.program_motion import line_tables
from kinergy.trajectory.program_path import ProgramPath, line_joints

__all__ = ["PathChecks", "path_caps", "path_problem", "retime", "scaled_to"]


#: SLSQP iterations per attempt of the program's timing solver
_MAXITER = 15


def path_caps(
    robot: Robot, path: ProgramPath, v_max: float | None, a_max: float | None
) -> tuple[Array, Array, list[str], list[str]]:
    """Per move the largest ``v`` and ``a`` (the move's own units) that keep every joint within
    its speed and acceleration limit and the caps (``inf``: none), and what sets each.

    A joint that moves ``g_j = max |dq_j / ds|`` per unit of the move's path runs at ``g_j``
    times its speed and acceleration (the path's curvature term ``q'' sd^2`` is left to the
    500 Hz verification)."""
    speed = np.array([j.limits.speed for j in robot.joints])
    acc = np.array(
        [np.inf if j.limits.acceleration is None else j.limits.acceleration for j in robot.joints]
    )
    if v_max is not None:
        speed = np.minimum(speed, v_max)
    if a_max is not None:
        acc = np.minimum(acc, a_max)
    names = robot.joint_names
    v_cap, a_cap, v_why, a_why = [], [], [], []
    for k in range(path.moves):
        if path.tool[k] is None:
            gain = np.abs(path.q_end[k] - path.q_start[k]) / max(path.travel[k], 1e-300)
        else:
            q = line_joints(robot, path, k)
            step = path.travel[k] / (q.shape[0] - 1)
            gain = np.max(np.abs(np.diff(q, axis=0)), axis=0) / max(step, 1e-300)
        with np.errstate(divide="ignore", invalid="ignore"):  # a joint that does not move
            v_joint = np.where(gain > 0.0, speed / gain, np.inf)
            a_joint = np.where(gain > 0.0, acc / gain, np.inf)
        jv, ja = int(np.argmin(v_joint)), int(np.argmin(a_joint))
        v_cap.append(float(v_joint[jv]))
        a_cap.append(float(a_joint[ja]))
        v_why.append(f"{names[jv]} speed" + (" (v_max)" if v_max is not None else " limit"))
        a_why.append(
            f"{names[ja]} acceleration" + (" (a_max)" if a_max is not None else " limit")
            if np.isfinite(a_joint[ja])
            else "torque limits"
        )
    return np.array(v_cap), np.array(a_cap), v_why, a_why


def path_problem(
    robot: Robot,
    path: ProgramPath,
    *,
    objective: Objective,
    v_max: float | None = None,
    a_max: float | None = None,
) -> TimingProblem:
    """The timing problem of a resolved program (see the module docstring).

    Raises
    ------
    KinergyError
        A move whose torques exceed the limits at any acceleration (naming its line).
    """
    v_cap, a_cap, v_why, a_why = path_caps(robot, path, v_max, a_max)
    tables = line_tables(robot, path)

    def evaluate(t: Array, f: Array) -> tuple[Array, Array]:
        samples = sample_path_programs(
            robot, path, np.atleast_2d(t), np.atleast_2d(f), tables=tables
        )
        value, _ = objective(samples)
        return value, torque_ratio(robot, samples)

    def cycle(t: Array, f: Array) -> Array:
        return path_schedule(path, np.atleast_2d(t), np.atleast_2d(f)).total

    evaluator: Evaluator = evaluate
    try:
        a_fast = fastest_acceleration(evaluator, path.travel, v_cap, a_cap)
    except KinergyError as exc:
        text = str(exc)
        k = int(text.split(":")[0].split()[-1]) - 1 if text.startswith("move ") else -1
        line = path.program.moves[k].line if k >= 0 else 0
        raise KinergyError(f"{path.program.where(line)}: {text}") from None
    return TimingProblem(
        waypoints=np.vstack([path.q0, path.q_end]),
        travel=path.travel,
        blends=np.where(path.linked, path.blend, 0.0),
        v_cap=v_cap,
        a_cap=a_cap,
        a_fast=a_fast,
        evaluate=evaluate,
        cycle=cycle,
        objective=objective,
        v_limit=tuple(v_why),
        a_limit=tuple(a_why),
    )


@dataclass(frozen=True)
class PathChecks:
    """Re-simulates programs on one path at 500 Hz (:class:`kinergy.optimize.timing.Checks`)."""

    robot: Robot
    path: ProgramPath
    problem: TimingProblem
    v_max: float | None
    a_max: float | None

    def simulate(self, v: Array, a: Array, label: str, predicted: float | None = None) -> PathRun:
        return simulate_path(
            self.robot,
            self.path.with_timing(v, a),
            objective=self.problem.objective,
            speed_cap=self.v_max,
            acceleration_cap=self.a_max,
            label=label,
            predicted=predicted,
        )

    def run(self, v: Array, a: Array, label: str, predicted: float | None = None) -> ProgramResult:
        return self.simulate(v, a, label, predicted).result


def scaled_to(
    problem: TimingProblem, path: ProgramPath, v: Array, a: Array, budget: float
) -> tuple[Array, Array]:
    """``(v, a)`` uniformly scaled (``v k``, ``a k^2``) so that the program lasts ``budget`` s,
    its events keeping their time: ``k = (T - T_events) / (budget - T_events)``."""
    fixed = float(path.event_time.sum())
    own = problem.cycle_time(v, a)
    if budget <= fixed:
        raise KinergyError(
            f"cycle time {budget:.4g} s: the program's events alone take {fixed:.4g} s"
        )
    return uniform_scaling(v, a, (own - fixed) / (budget - fixed))


def retime(
    checks: PathChecks,
    budget: float,
    *,
    share_budget: bool = True,
    maxiter: int = _MAXITER,
) -> tuple[ProgramResult, Verified]:
    """The verified energy-optimal timing at ``budget`` s, from the program uniformly scaled to
    it: at most ``maxiter`` SLSQP iterations per attempt (the solver stops on iterations and
    tolerances, never on a clock: the same answer on every host), and how it came about.

    Raises
    ------
    KinergyError
        A budget below the fastest feasible cycle time (naming the slowest move's line).
    """
    problem, path = checks.problem, checks.path
    fastest = problem.fastest_cycle_time
    if budget < fastest * (1.0 - 1e-9):
        t_fast, _ = problem.fastest
        k = int(np.argmax(t_fast))
        raise KinergyError(
            f"cycle time {budget:.4g} s is shorter than the fastest possible {fastest:.4g} s "
            "(every move at its speed, acceleration and torque limits; the longest move: "
            f"{path.program.where(path.program.moves[k].line)})"
        )
    v0, a0 = scaled_to(problem, path, path.speed, path.accel, budget)
    uniform = checks.run(v0, a0, "uniform")
    return best_verified(checks, budget, v0, a0, uniform, share_budget, maxiter)
