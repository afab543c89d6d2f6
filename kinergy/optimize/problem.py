"""The timing problem of a robot program: arrays and callables the solver works on.

The path of a program is fixed by its targets; what its moves are free to choose is how fast each
runs: URScript's ``v`` and ``a`` (movej: of the leading joint, rad/s and rad/s^2; movel/movep:
along the tool's path, m/s and m/s^2), the events' times fixed. :func:`path_problem` states it
as a :class:`TimingProblem` over the samples of :mod:`kinergy.optimize.samples`:

- caps per move (:func:`path_caps`): every joint's speed and acceleration limit and the
  optimiser's caps (:class:`Caps`: by default the program's own peak joint speed and
  acceleration), turned into the move's own unit by the most any joint moves per unit of its path
  (a movej's leading joint; along a tool line, ``max_s |dq_j/ds|``); the torque-limited
  acceleration at full speed by a scan (:func:`fastest_acceleration`);
- the objective (:mod:`kinergy.optimize.objectives`) with each move's part, and each move's torque
  ratio (:func:`kinergy.optimize.constraints.torque_ratio`), of batches of programs given by their
  move durations and ramp fractions; the cycle time: the moves' durations (less the blends'
  overlaps) plus the events' fixed times.

The solver (:mod:`kinergy.optimize.solve`) sees only these. :class:`PathChecks` re-simulates
programs on the path at 500 Hz (:func:`kinergy.optimize.verify.simulate_path`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.optimize.constraints import torque_ratio
from kinergy.optimize.objectives import Objective
from kinergy.optimize.samples import durations, path_schedule, sample_path_programs
from kinergy.optimize.verify import PathRun, ProgramResult, simulate_path
from kinergy.trajectory.program_motion import LineTables, line_tables
from kinergy.trajectory.program_path import ProgramPath, line_joints

__all__ = [
    "SLACK",
    "Caps",
    "CycleTime",
    "Evaluator",
    "PathChecks",
    "TimingProblem",
    "fastest_acceleration",
    "path_caps",
    "path_checks",
    "uniform_scaling",
]


@dataclass(frozen=True)
class Caps:
    """The joint speed (rad/s) and acceleration (rad/s^2) caps every program is held to, besides
    the robot's own limits: by default the program's own peaks (the speeds its programmer
    chose)."""

    speed: float
    acceleration: float


#: ``(t, f) -> (objective, torque_ratio)`` of B programs, see :class:`TimingProblem`
Evaluator = Callable[[Array, Array], tuple[Array, Array]]
#: ``(t, f) -> cycle time`` of B programs, s
CycleTime = Callable[[Array, Array], Array]
#: ``(t, f) -> (objective (B,), its per-move parts (B, K), torque_ratio (B, K))`` of B programs
Parts = Callable[[Array, Array], tuple[Array, Array, Array]]


@dataclass(frozen=True, eq=False)
class TimingProblem:
    """A program's timing problem as arrays and callables (built by :func:`path_checks`).

    Attributes
    ----------
    travel : ndarray, shape (K,)
        What each move's profile runs over (a movej's leading-joint travel, rad; a tool move's
        path length, m or rad).
    blends : ndarray, shape (K,)
        Each move's blend radius in the same unit (0 where it does not blend).
    v_cap, a_cap : ndarray, shape (K,)
        Largest leading-joint speed (rad/s) and acceleration (rad/s^2) of each move that keeps
        every joint within its speed and acceleration limits and the caps (``inf``: none).
    a_fast : ndarray, shape (K,)
        The largest acceleration at ``v_cap`` that keeps the torques within limits (and at most
        ``a_cap``): each move's fastest feasible setting.
    evaluate : callable
        ``evaluate(t, f) -> (objective, torque_ratio)``: for B programs given by the durations
        and ramp fractions of their moves, ``t, f`` of shape (B, K), the objective (B,) (the
        electrical energy, J, by default) and each move's largest joint torque over its limit
        (B, K).
    cycle : callable
        ``cycle(t, f) -> total time`` (B,), s.
    objective : Objective
        What ``evaluate`` returns (:mod:`kinergy.optimize.objectives`), to score re-simulations.
    v_limit, a_limit : tuple of str, shape (K,)
        What sets each move's ``v_cap`` and ``a_cap`` (for the report).
    parts : callable
        ``parts(t, f) -> (objective, parts, torque_ratio)``: ``evaluate`` with the objective's
        part of each move (B, K), which depends on the timing of that move and of the moves
        blended into it (``linked``) only: the solver's differences perturb many moves in one
        program.
    linked : ndarray of bool, shape (K,)
        Whether move k blends into move k + 1.
    """

    travel: Array
    blends: Array
    v_cap: Array
    a_cap: Array
    a_fast: Array
    evaluate: Evaluator = field(repr=False)
    cycle: CycleTime = field(repr=False)
    objective: Objective = field(repr=False)
    parts: Parts = field(repr=False)
    linked: NDArray[np.bool_]
    v_limit: tuple[str, ...] = ()
    a_limit: tuple[str, ...] = ()

    @property
    def moves(self) -> int:
        return int(self.travel.size)

    @property
    def fastest(self) -> tuple[Array, Array]:
        """Durations and ramp fractions of every move at its fastest feasible setting."""
        v = np.where(self.travel > 0.0, self.v_cap, 1.0)
        a = np.where(self.travel > 0.0, self.a_fast, 1.0)
        return durations(self.travel, v, a)

    @property
    def fastest_cycle_time(self) -> float:
        """The shortest cycle time within every limit, s."""
        t, f = self.fastest
        return float(self.cycle(t[None, :], f[None, :])[0])

    def cycle_time(self, v: Array, a: Array) -> float:
        """Total time of the program at per-move settings ``v`` and ``a`` (K,), s."""
        t, f = durations(self.travel, v, a)
        return float(self.cycle(t[None, :], f[None, :])[0])


def fastest_acceleration(
    evaluate: Evaluator,
    travel: Array,
    v_cap: Array,
    a_cap: Array,
    where: Callable[[int], str] | None = None,
) -> Array:
    """Per move the largest acceleration (at most ``a_cap``) at ``v_cap`` whose torques stay
    within the limits (0.1 % margin): a geometric scan of every move at once, then a finer linear
    scan inside the bracket each move found. ``where(k)`` names move k in a message (default
    ``move k + 1``)."""
    moving = travel > 0.0
    safe = 1.0 - 1e-3
    v = np.where(moving, v_cap, 1.0)

    def feasible(a: Array) -> NDArray[np.bool_]:
        """(G, K) accelerations -> whether each move's torques stay within the limits."""
        a = np.where(moving, np.minimum(a, a_cap), 1.0)
        _, ratio = evaluate(*durations(travel, np.broadcast_to(v, a.shape), a))
        return np.asarray(ratio <= safe)

    def last_good(grid: Array, ok: NDArray[np.bool_]) -> Array:
        """Index per move of the last feasible value before the first infeasible (-1: none)."""
        first_bad = np.where(ok.all(axis=0), grid.shape[0], np.argmin(ok, axis=0))
        return np.asarray(first_bad - 1)

    coarse = np.geomspace(0.02, 5000.0, 48)[:, None] * np.ones(travel.size)
    idx = last_good(coarse, feasible(coarse))
    for k in np.flatnonzero(moving & (idx < 0)):
        raise KinergyError(
            f"{f'move {k + 1}' if where is None else where(int(k))}: the joint torques exceed "
            f"their limits even at "
            f"{coarse[0, k]:g} rad/s² (a static overload: the payload or the pose)"
        )
    cols = np.arange(travel.size)
    best = coarse[np.maximum(idx, 0), cols]
    above = coarse[np.minimum(idx + 1, coarse.shape[0] - 1), cols]
    fine = best + np.linspace(0.0, 1.0, 33)[1:, None] * (above - best)
    idx = last_good(fine, feasible(fine))
    best = np.where(idx >= 0, fine[np.maximum(idx, 0), cols], best)
    return np.where(moving, np.minimum(best, a_cap), 0.0)


def uniform_scaling(speeds: Array, accels: Array, factor: float) -> tuple[Array, Array]:
    """Speeds times ``factor`` and accelerations times ``factor^2``: the same movej program run
    ``factor`` times faster (every duration, ramp and blend overlap divided by ``factor``)."""
    return np.asarray(speeds, dtype=float) * factor, np.asarray(accels, dtype=float) * factor**2


def joint_caps(robot: Robot, caps: Caps) -> tuple[Array, Array]:
    """Every joint's speed (rad/s) and acceleration (rad/s^2) bound: its limit or the cap,
    the lower, shape (n,) each (``inf``: none)."""
    speed = np.array([j.limits.speed for j in robot.joints])
    acc = np.array(
        [np.inf if j.limits.acceleration is None else j.limits.acceleration for j in robot.joints]
    )
    return np.minimum(speed, caps.speed), np.minimum(acc, caps.acceleration)


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
    tables: LineTables
    caps: Caps

    def parts(self, t: Array, f: Array) -> tuple[Array, Array, Array]:
        """Objective (B,), its per-move parts (B, K) and limit ratios (B, K) of B timings
        ``t, f`` (B, K): per move the largest joint torque over its limit at the samples and,
        for a tool move, the largest joint speed or acceleration over its cap (a line's joints
        move faster and harder where it curves in joint space than its ``v`` and ``a`` tell; a
        movej's joints follow its leading joint, bounded by ``v_cap`` and ``a_cap``)."""
        samples = sample_path_programs(
            self.robot, self.path, np.atleast_2d(t), np.atleast_2d(f), tables=self.tables
        )
        value, parts = self.objective(samples)
        ratio = torque_ratio(self.robot, samples)
        tool = np.array([segment is not None for segment in self.path.tool])
        if np.any(tool) and samples.qd is not None and samples.qdd is not None:
            speed, acc = joint_caps(self.robot, self.caps)
            room = 1.0 + _RATE_ROOM  # a move at its speed cap stays within the torque's margin
            rates = np.maximum(np.abs(samples.qd) / speed, np.abs(samples.qdd) / acc) / room
            ratio = np.maximum(ratio, np.where(tool, samples.move_max(rates.max(axis=1)), 0.0))
        return value, parts, ratio

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
        parts=model.parts,
        linked=path.linked,
    )


@dataclass(frozen=True, eq=False)
class PathChecks:
    """A program's path, its timing problem (and per-move objective, :func:`kinergy.optimize.
    timing.allocated`) and its re-simulation at 500 Hz against the caps."""

    robot: Robot
    path: ProgramPath
    problem: TimingProblem
    caps: Caps
    model: _PathModel
    standby: float = 0.0

    def simulate(self, v: Array, a: Array, label: str, predicted: float | None = None) -> PathRun:
        return simulate_path(
            self.robot,
            self.path.with_timing(v, a),
            standby=self.standby,
            objective=self.problem.objective,
            speed_cap=self.caps.speed,
            acceleration_cap=self.caps.acceleration,
            label=label,
            predicted=predicted,
        )

    def run(self, v: Array, a: Array, label: str, predicted: float | None = None) -> ProgramResult:
        return self.simulate(v, a, label, predicted).result


#: the timing solver's caps are this share below the program's: its iterations end a few ms off
#: the cycle time, and the uniform rescaling to it must stay within the caps
SLACK = 0.005
#: the joints' speeds and accelerations at the quadrature nodes may pass the solver's caps by
#: this share (they stay within the program's; the fastest setting of a move keeps the torques
#: 0.1 % below their limits, and its speed at its cap)
_RATE_ROOM = 0.002


def path_checks(
    robot: Robot, path: ProgramPath, objective: Objective, caps: Caps, standby: float = 0.0
) -> PathChecks:
    """The timing problem of ``path`` with the caps :data:`SLACK` below ``caps`` (speed, and its
    square for acceleration: what a uniform rescaling by ``1 + SLACK`` needs), and its checks
    (``standby``: the arm's standing draw, W, for the supply figures).

    Raises
    ------
    KinergyError
        A move whose torques exceed the limits at any acceleration (naming its line).
    """
    slack = Caps(caps.speed * (1.0 - SLACK), caps.acceleration * (1.0 - SLACK) ** 2)
    model = _PathModel(robot, path, objective, line_tables(robot, path), slack)
    problem = _problem(model, slack.speed, slack.acceleration)
    return PathChecks(robot, path, problem, slack, model, standby)
