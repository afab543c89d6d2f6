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
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.optimize.constraints import torque_ratio
from kinergy.optimize.objectives import Objective
from kinergy.optimize.problem import TimingProblem, fastest_acceleration, uniform_scaling
from kinergy.optimize.program import durations, settings
from kinergy.optimize.program_samples import path_schedule, sample_path_programs
from kinergy.optimize.program_verify import PathRun, simulate_path
from kinergy.optimize.timing import Verified, best_verified
from kinergy.optimize.verify import ProgramResult
from kinergy.trajectory.program_motion import LineTable, line_tables
from kinergy.trajectory.program_path import ProgramPath, line_joints

__all__ = [
    "PathChecks",
    "allocated",
    "path_caps",
    "path_checks",
    "path_problem",
    "retime",
    "scaled_to",
]


#: SLSQP iterations per attempt of the program's timing solver
_MAXITER = 15
#: the allocation's grid: durations per move, ramp fractions, programs evaluated at once, and
#: the steps of the budget its dynamic programme counts in
_DURATIONS = 24
_RAMPS = 8
_CHUNK = 24
_UNITS = 2000


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


@dataclass(frozen=True, eq=False)
class _PathModel:
    """A resolved program's objective at the quadrature nodes of B timings: the total and each
    move's part (the move and the events after it), and each move's torque ratio."""

    robot: Robot
    path: ProgramPath
    objective: Objective
    tables: dict[int, LineTable]

    def parts(self, t: Array, f: Array) -> tuple[Array, Array, Array]:
        """Objective (B,), its per-move parts (B, K) and torque ratios (B, K) of B timings
        ``t, f`` (B, K)."""
        samples = sample_path_programs(
            self.robot, self.path, np.atleast_2d(t), np.atleast_2d(f), tables=self.tables
        )
        value, parts = self.objective(samples)
        return value, parts, torque_ratio(self.robot, samples)

    def evaluate(self, t: Array, f: Array) -> tuple[Array, Array]:
        value, _, ratio = self.parts(t, f)
        return value, ratio

    def cycle(self, t: Array, f: Array) -> Array:
        return path_schedule(self.path, np.atleast_2d(t), np.atleast_2d(f)).total


def _problem(model: _PathModel, v_max: float | None, a_max: float | None) -> TimingProblem:
    robot, path = model.robot, model.path
    v_cap, a_cap, v_why, a_why = path_caps(robot, path, v_max, a_max)
    program = path.program
    a_fast = fastest_acceleration(
        model.evaluate,
        path.travel,
        v_cap,
        a_cap,
        where=lambda k: program.where(program.moves[k].line),
    )
    return TimingProblem(
        waypoints=np.vstack([path.q0, path.q_end]),
        travel=path.travel,
        blends=np.where(path.linked, path.blend, 0.0),
        v_cap=v_cap,
        a_cap=a_cap,
        a_fast=a_fast,
        evaluate=model.evaluate,
        cycle=model.cycle,
        objective=model.objective,
        v_limit=tuple(v_why),
        a_limit=tuple(a_why),
    )


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
    return _problem(_PathModel(robot, path, objective, line_tables(robot, path)), v_max, a_max)


@dataclass(frozen=True, eq=False)
class PathChecks:
    """Re-simulates programs on one path at 500 Hz (:class:`kinergy.optimize.timing.Checks`),
    with the path's timing problem and its per-move objective (for :func:`allocated`)."""

    robot: Robot
    path: ProgramPath
    problem: TimingProblem
    v_max: float | None
    a_max: float | None
    model: _PathModel | None = None

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


def path_checks(
    robot: Robot,
    path: ProgramPath,
    objective: Objective,
    v_max: float | None,
    a_max: float | None,
) -> PathChecks:
    """The timing problem of ``path`` within the caps and its checks at 500 Hz."""
    model = _PathModel(robot, path, objective, line_tables(robot, path))
    return PathChecks(robot, path, _problem(model, v_max, a_max), v_max, a_max, model)


def _grid_energy(
    checks: PathChecks, moving: NDArray[np.intp], grid_t: Array, grid_f: Array
) -> tuple[Array, Array]:
    """Each moving move's part of the objective at every grid duration (D, m), with its cheapest
    ramp fraction of ``grid_f`` (R, m) within its speed and acceleration caps and torque limits:
    the least part (D, m, inf where none fits) and that ramp fraction (D, m). Program ``(d, r)``
    of the grid runs every move at its own ``(grid_t[d], grid_f[r])``."""
    model, problem, path = checks.model, checks.problem, checks.path
    assert model is not None
    d_count, r_count = grid_t.shape[0], grid_f.shape[0]
    dist = path.travel[moving]
    t_all = np.repeat(grid_t, r_count, axis=0)  # (D R, m)
    f_all = np.tile(grid_f, (d_count, 1))
    v_all, a_all, _ = settings(dist, t_all, f_all)
    t_full = np.zeros((t_all.shape[0], path.moves))
    f_full = np.ones((t_all.shape[0], path.moves))
    t_full[:, moving], f_full[:, moving] = t_all, f_all
    parts, ratio = [], []
    for lo in range(0, t_full.shape[0], _CHUNK):
        _, p, r = model.parts(t_full[lo : lo + _CHUNK], f_full[lo : lo + _CHUNK])
        parts.append(p[:, moving])
        ratio.append(r[:, moving])
    ok = (
        (np.vstack(ratio) <= 1.0 - 1e-3)
        & (v_all <= problem.v_cap[moving] * (1.0 + 1e-9))
        & (a_all <= problem.a_fast[moving] * (1.0 + 1e-9))
    )
    energy = np.where(ok, np.vstack(parts), np.inf).reshape(d_count, r_count, moving.size)
    pick = np.argmin(energy, axis=1)  # (D, m)
    best = np.take_along_axis(energy, pick[:, None, :], axis=1)[:, 0, :]
    ramp = np.take_along_axis(grid_f, pick, axis=0)  # (D, m)
    return best, ramp


def _share(best: Array, grid_t: Array, total: float) -> NDArray[np.intp] | None:
    """The grid duration of every move (index per move) whose sum uses ``total`` (to the step;
    else the most that fits) at the least summed part ``best`` (D, m): dynamic programming over
    the time used, in steps of ``total / _UNITS`` (each duration rounded up); None when nothing
    fits. (Using less time is cheaper on some programs, whose holding copper grows with the
    time, but the cycle time is fixed: the time has to go somewhere.)"""
    unit = total / _UNITS
    steps = np.ceil(grid_t / unit - 1e-9).astype(np.intp)  # (D, m)
    value = np.full(_UNITS + 1, np.inf)
    value[0] = 0.0
    back = []
    for j in range(best.shape[1]):
        new = np.full(_UNITS + 1, np.inf)
        arg = np.full(_UNITS + 1, -1, dtype=np.intp)
        for d in range(best.shape[0]):
            shift = int(steps[d, j])
            if not np.isfinite(best[d, j]) or shift > _UNITS:
                continue
            cand = np.full(_UNITS + 1, np.inf)
            cand[shift:] = value[: _UNITS + 1 - shift] + best[d, j]
            better = cand < new
            new[better], arg[better] = cand[better], d
        value = new
        back.append(arg)
    fits = np.flatnonzero(np.isfinite(value))
    if fits.size == 0:
        return None
    end = int(fits[-1])
    chosen = np.zeros(best.shape[1], dtype=np.intp)
    for j in range(best.shape[1] - 1, -1, -1):
        chosen[j] = int(back[j][end])
        end -= int(steps[chosen[j], j])
    return chosen


def allocated(checks: PathChecks, budget: float) -> tuple[Array, Array] | None:
    """A start for the timing solver: the budget shared among the moves as if each ran alone.

    Every move's part of the objective (the move and the events after it) is evaluated on a grid
    of its duration (``_DURATIONS`` geometric steps from its fastest within the caps to the
    longest the budget leaves it) and ramp fraction (``_RAMPS``), all moves at once in each of
    the grid's programs; per duration the cheapest ramp within the move's speed and acceleration
    caps and torque limits; then the durations whose sum fits the budget at the least total,
    exactly on the grid, by dynamic programming over the time used (:func:`_share`). A second
    pass does the same on a finer grid around each move's choice (between its neighbouring grid
    durations and ramps). The moves interact only through blends, which this ignores: the solver
    starts from it, uniformly scaled to the budget. None where no grid point fits.
    """
    problem, path = checks.problem, checks.path
    moving = np.flatnonzero(path.travel > 0.0)
    if checks.model is None or moving.size == 0:
        return None
    dist = path.travel[moving]
    total = budget - float(path.event_time.sum())
    fast_t, _ = durations(dist, problem.v_cap[moving], problem.a_fast[moving])
    spare = total - float(fast_t.sum())
    if spare <= 0.0:
        return None
    grid_t = fast_t * np.geomspace(1.0, (fast_t + spare) / fast_t, _DURATIONS)  # (D, m)
    grid_f = np.linspace(1.0 / _RAMPS, 1.0, _RAMPS)[:, None] * np.ones(moving.size)
    best, ramp = _grid_energy(checks, moving, grid_t, grid_f)
    chosen = _share(best, grid_t, total)
    if chosen is None:
        return None
    cols = np.arange(moving.size)
    low = grid_t[np.maximum(chosen - 1, 0), cols]
    high = grid_t[np.minimum(chosen + 1, _DURATIONS - 1), cols]
    f = ramp[chosen, cols]
    fine_t = low + np.linspace(0.0, 1.0, _DURATIONS)[:, None] * (high - low)
    step = 1.0 / _RAMPS
    fine_f = np.clip(f + np.linspace(-step, step, _RAMPS)[:, None], 0.25 * step, 1.0)
    fine, fine_ramp = _grid_energy(checks, moving, fine_t, fine_f)
    again = _share(fine, fine_t, total)
    t = grid_t[chosen, cols]
    if again is not None and fine[again, cols].sum() < best[chosen, cols].sum():
        t, f = fine_t[again, cols], fine_ramp[again, cols]
    v, a, _ = settings(dist, t, f)
    v_out, a_out = path.speed.copy(), path.accel.copy()
    v_out[moving], a_out[moving] = v, a
    return scaled_to(problem, path, v_out, a_out, budget)


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
    """The verified energy-optimal timing at ``budget`` s, and how it came about: the solver runs
    from the program uniformly scaled to the budget and from the budget shared among the moves
    (:func:`allocated`), at most ``maxiter`` SLSQP iterations per attempt each (it stops on
    iterations and tolerances, never on a clock: the same answer on every host), each keeping
    its start should it end above it; the better of the two.

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
    best = best_verified(checks, budget, v0, a0, uniform, share_budget, maxiter)
    shared = allocated(checks, budget)
    if shared is None:
        return best
    start = checks.run(*shared, "allocated")
    if not start.ok:
        return best
    other = best_verified(
        checks, budget, *shared, start, share_budget, maxiter, "the budget shared per move"
    )
    assert other[0].score is not None and best[0].score is not None
    return other if other[0].ok and other[0].score < best[0].score else best
