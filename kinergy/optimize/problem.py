"""The timing problem of a movej program: arrays and callables the solver works on.

A task is fixed by its waypoints (the path in joint space); what a UR program is free to choose is
how fast each move runs: URScript's ``movej(q, a=..., v=...)`` per move. :func:`timing_problem`
turns a robot, the waypoints and the caps into a :class:`TimingProblem`: each move's leading-joint
travel, the largest speed and acceleration the joints' limits allow (:func:`joint_caps`), the
torque-limited acceleration at full speed (each move's fastest feasible setting), and two
callables over batches of programs given by their move durations and ramp fractions
(:mod:`kinergy.optimize.program`): ``evaluate`` (the objective, :mod:`kinergy.optimize.objectives`,
and each move's torque ratio, :func:`kinergy.optimize.constraints.torque_ratio`) and ``cycle``
(the program's total time). The solver (:mod:`kinergy.optimize.solve`) sees only these.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.optimize.constraints import torque_ratio
from kinergy.optimize.objectives import ElectricalEnergy, Objective
from kinergy.optimize.program import durations, sample_programs, serial, settings
from kinergy.trajectory.movej import blend_starts, check_waypoints, per_move

__all__ = [
    "CycleTime",
    "Evaluator",
    "TimingProblem",
    "fastest_acceleration",
    "joint_caps",
    "program_settings",
    "timing_problem",
    "uniform_scaling",
]


#: ``(t, f) -> (objective, torque_ratio)`` of B programs, see :class:`TimingProblem`
Evaluator = Callable[[Array, Array], tuple[Array, Array]]
#: ``(t, f) -> cycle time`` of B programs, s
CycleTime = Callable[[Array, Array], Array]


@dataclass(frozen=True, eq=False)
class TimingProblem:
    """A movej timing problem as arrays and callables (build it with :func:`timing_problem`).

    Attributes
    ----------
    waypoints : ndarray, shape (K + 1, n)
        rad.
    travel : ndarray, shape (K,)
        Leading-joint travel of each move, rad.
    blends : ndarray, shape (K,)
        Joint-space blend radii, rad.
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
    """

    waypoints: Array
    travel: Array
    blends: Array
    v_cap: Array
    a_cap: Array
    a_fast: Array
    evaluate: Evaluator = field(repr=False)
    cycle: CycleTime = field(repr=False)
    objective: Objective = field(default_factory=ElectricalEnergy, repr=False)
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


def _callables(
    robot: Robot, waypoints: Array, blends: Array, objective: Objective
) -> tuple[Evaluator, CycleTime]:
    """The batched objective/torque evaluator and the cycle-time function of a movej program."""
    travel = np.max(np.abs(np.diff(waypoints, axis=0)), axis=1)

    def cycle(t: Array, f: Array) -> Array:
        t = np.atleast_2d(t)
        _, a, ramp = settings(travel, t, np.atleast_2d(f))
        start = blend_starts(travel, blends, t, a, ramp)
        return np.asarray(np.max(start + t, axis=1))

    def evaluate(t: Array, f: Array) -> tuple[Array, Array]:
        t = np.atleast_2d(np.asarray(t, dtype=float))
        f = np.atleast_2d(np.asarray(f, dtype=float))
        samples = sample_programs(robot, waypoints, blends, t, f)
        value, _ = objective(samples)
        return value, torque_ratio(robot, samples)

    return evaluate, cycle


def joint_caps(
    robot: Robot, waypoints: Array, v_max: float | None, a_max: float | None
) -> tuple[Array, Array, list[str], list[str]]:
    """Per move the largest leading-joint speed (rad/s) and acceleration (rad/s^2) within every
    joint's limits and the caps, shape (K,) (``inf``: none), and what sets each (for the report).

    A joint that travels ``s_j`` times the leading joint's distance runs at ``s_j`` times its
    speed and acceleration, so its limit allows the leading joint ``limit_j / s_j``.
    """
    delta = np.abs(np.diff(waypoints, axis=0))
    travel = delta.max(axis=1)
    speed = np.array([j.limits.speed for j in robot.joints])
    acc = np.array(
        [np.inf if j.limits.acceleration is None else j.limits.acceleration for j in robot.joints]
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        share = np.where(travel[:, None] > 0.0, delta / travel[:, None], 0.0)  # (K, n)
        v_joint = np.where(share > 0.0, speed / share, np.inf)
        a_joint = np.where(share > 0.0, acc / share, np.inf)
    names = robot.joint_names
    v_cap, a_cap, v_why, a_why = [], [], [], []
    for k in range(travel.size):
        jv, ja = int(np.argmin(v_joint[k])), int(np.argmin(a_joint[k]))
        v, a = float(v_joint[k, jv]), float(a_joint[k, ja])
        vw, aw = f"{names[jv]} speed limit", f"{names[ja]} acceleration limit"
        if v_max is not None and v_max <= v:
            v, vw = float(v_max), "v_max"
        if a_max is not None and a_max <= a:
            a, aw = float(a_max), "a_max"
        v_cap.append(v)
        a_cap.append(a)
        v_why.append(vw)
        a_why.append(aw if np.isfinite(a) else "torque limits")
    return np.array(v_cap), np.array(a_cap), v_why, a_why


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


def _checked_inputs(
    robot: Robot,
    waypoints: ArrayLike,
    blends: ArrayLike | None,
    v_max: float | None,
    a_max: float | None,
) -> tuple[Array, Array]:
    """The waypoints (K + 1, n) within the joints' position limits and the blends (K,)."""
    w = check_waypoints(waypoints)
    if w.shape[1] != robot.n:
        raise KinergyError(f"waypoints have {w.shape[1]} joints but {robot.name} has {robot.n}")
    for name, cap in (("v_max", v_max), ("a_max", a_max)):
        if cap is not None and not (np.isfinite(cap) and cap > 0.0):
            raise KinergyError(f"{name}: must be > 0, got {cap}")
    for j, joint in enumerate(robot.joints):
        lo, hi = joint.limits.position
        bad = np.flatnonzero((w[:, j] < lo) | (w[:, j] > hi))
        if bad.size:
            i = int(bad[0])
            raise KinergyError(
                f"waypoint {i} ({'start' if i == 0 else f'move {i}'}): {joint.name} at "
                f"{w[i, j]:.4g} rad is outside its limits [{lo:.4g}, {hi:.4g}] rad"
            )
    moves = w.shape[0] - 1
    r = np.zeros(moves) if blends is None else np.asarray(blends, dtype=float)
    r = np.broadcast_to(r, (moves,)).copy() if r.ndim == 0 else r
    if r.shape != (moves,) or np.any(r < 0.0) or not np.all(np.isfinite(r)):
        raise KinergyError(f"blends: expected {moves} finite values >= 0, got {np.shape(r)}")
    if not np.any(np.abs(np.diff(w, axis=0)) > 0.0):
        raise KinergyError("the task does not move: every target equals the start pose")
    return w, r


@serial
def timing_problem(
    robot: Robot,
    waypoints: ArrayLike,
    *,
    blends: ArrayLike | None = None,
    v_max: float | None = None,
    a_max: float | None = None,
    recovery: bool = True,
    objective: Objective | None = None,
) -> TimingProblem:
    """Build the timing problem of a movej program through ``waypoints`` on ``robot``.

    Parameters
    ----------
    robot : Robot
    waypoints : array_like, shape (K + 1, n)
        Start pose and the K targets, rad; each within the joints' position limits.
    blends : float or array_like, shape (K,), optional
        Joint-space blend radii, rad (default 0: every move stops at its target).
    v_max, a_max : float, optional
        Caps on the leading joint's speed (rad/s) and acceleration (rad/s^2) besides the joint
        limits; without ``a_max`` a robot without acceleration limits (UR arms) is bounded by its
        torque limits alone.
    recovery : bool
        Braking energy returns to the bus (default, as the seed): for the default objective.
    objective : Objective, optional
        What to minimise (:mod:`kinergy.optimize.objectives`); default
        ``ElectricalEnergy(recovery)``.

    Returns
    -------
    TimingProblem
    """
    w, r = _checked_inputs(robot, waypoints, blends, v_max, a_max)
    travel = np.max(np.abs(np.diff(w, axis=0)), axis=1)
    objective = ElectricalEnergy(recovery) if objective is None else objective
    v_cap, a_cap, v_why, a_why = joint_caps(robot, w, v_max, a_max)
    evaluate, cycle = _callables(robot, w, r, objective)
    return TimingProblem(
        waypoints=w,
        travel=travel,
        blends=r,
        v_cap=v_cap,
        a_cap=a_cap,
        a_fast=fastest_acceleration(evaluate, travel, v_cap, a_cap),
        evaluate=evaluate,
        cycle=cycle,
        objective=objective,
        v_limit=tuple(v_why),
        a_limit=tuple(a_why),
    )


def _given(value: ArrayLike | None, moves: int, name: str) -> Array:
    """A per-move setting as written (NaN: not given), shape (K,)."""
    if value is None:
        return np.full(moves, np.nan)
    arr = per_move(value, moves, name)
    if np.any(arr[~np.isnan(arr)] <= 0.0) or np.any(np.isinf(arr)):
        raise KinergyError(f"{name}: must be finite and > 0, got {arr.tolist()}")
    return arr


def program_settings(
    problem: TimingProblem, speeds: ArrayLike | None, accels: ArrayLike | None
) -> tuple[Array, Array]:
    """The program as written: the given per-move ``v`` and ``a`` and, where not given (None or
    NaN), the fastest feasible (``v_cap`` and the torque-limited ``a_fast``)."""
    v = _given(speeds, problem.moves, "speeds")
    a = _given(accels, problem.moves, "accels")
    fast_v = np.where(np.isfinite(problem.v_cap), problem.v_cap, 1.0)
    fast_a = np.where(problem.a_fast > 0.0, problem.a_fast, 1.0)
    return np.where(np.isnan(v), fast_v, v), np.where(np.isnan(a), fast_a, a)


def uniform_scaling(speeds: ArrayLike, accels: ArrayLike, factor: float) -> tuple[Array, Array]:
    """Speeds times ``factor`` and accelerations times ``factor^2``: the same movej program run
    ``factor`` times faster (every duration, ramp and blend overlap divided by ``factor``)."""
    return np.asarray(speeds, dtype=float) * factor, np.asarray(accels, dtype=float) * factor**2
