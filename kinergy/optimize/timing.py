"""Energy-optimal timing of a movej program: per-move speeds and accelerations for a cycle time.

A task is fixed by its waypoints (the path in joint space); what a UR program is free to choose is
how fast each move runs: URScript's ``movej(q, a=..., v=...)`` per move. For a cycle-time budget
``T`` this module finds the per-move ``v_k, a_k`` (and, optionally, how ``T`` is shared among the
moves) that minimise the electrical energy the model predicts (UR5e eq 26, summed over the
motors), within the joints' speed, acceleration, torque and position limits, and verifies every
result by re-simulating the movej at the controller's 500 Hz with
:func:`kinergy.accounting.energy.energy` and :func:`limit_violations`.

Physics: what the timing can and cannot change
----------------------------------------------
Per motor the electrical power is ``tau_m^2 / k_m^2 + (k_b/k_t) wm tau_m`` (UR5e eq 23) with
``tau_m = tau_inertial + tau_gravity + tau_friction`` (motor side). Over one cycle of a movej
program (every move starts and ends at rest):

- *inertial* and *gravity* work is returned to the bus when braking and lowering (signed integrals,
  as the seed; a closed cycle gives back what it stored): close to zero whatever the timing.
- *Coulomb friction* costs ``Tc |wm|``: its energy is ``Tc`` times the motor-side distance, fixed by
  the path, not by the timing (only the direct/reverse power-flow coefficient, UR5e eqs 11-16,
  depends on the sign of the load torque). This is the floor the timing cannot touch.
- *viscous friction* costs ``b wm^2``: for a move of leading-joint travel ``D`` in time ``t`` its
  energy is ``b D^2 / t`` times a shape factor that is 1 for a constant speed and grows with the
  share of the move spent accelerating (``v^2 (t - 4 tau/3)`` for a trapezoid with ramp ``tau``).
  So at a fixed cycle time it pays to accelerate *harder* (a flatter speed profile, a lower peak
  speed) and to give more of the budget to the moves whose joints travel far on high-viscosity
  drives (equal marginal energy per second of every move: the Lagrange condition of
  ``sum_k E_k(t_k)`` subject to ``sum_k t_k = T``).
- *copper losses* ``tau_m^2 / k_m^2``: the acceleration torque costs about ``J^2 a^2`` over the
  ramps ``2 v / a``, i.e. ``~ 2 J^2 a v`` per move, growing with the acceleration; the gravity
  holding torque costs ``~ tau_g^2 / k_m^2`` per second, growing with the cycle time.

So the optimum is not "as slow as possible" nor "as hard as possible": at a fixed cycle time the
accelerations settle where the viscous saving of a flatter profile meets the extra copper loss of
the ramps (unless a cap or a torque limit binds first), and along the Pareto front (energy against
cycle time) the viscous energy falls like ``1 / T`` while gravity copper grows like ``T``: on the
UR5e the viscous term dominates for cycle times around the programs' own, so the front falls
over the range kinergy scans (fastest feasible to twice the program's time).

What this gives on the seed UR5e model, test A at its own 13.1 s (3 rad/s, 6 rad/s^2): of
1015 J, friction is 959 J (Coulomb 407 J, viscous 552 J) and copper 56 J; the optimum (about
8 %) comes from the viscous part, which even a rectangular speed profile with the best budget
shares could only bring to about 454 J: the Coulomb floor and the budget bound the saving.

How it is solved
----------------
:func:`kinergy.optimize.timing_problem` builds the problem (arrays and callables),
:func:`kinergy.optimize.solve.solve_timing` solves it with SLSQP on the quadrature of
:mod:`kinergy.optimize.program`, and :func:`kinergy.optimize.verify.simulate_program` re-simulates
every result at 500 Hz (``dt = 0.002``): the energy reported is that re-simulation's (the
quadrature agrees within about 0.1 %), and the limits are checked at every one of its samples.
Should a sample exceed a limit the quadrature nodes missed, the caps are tightened by the excess
and the problem solved again. The objective is pluggable (:mod:`kinergy.optimize.objectives`);
the default is the electrical energy.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.optimize.constraints import LIMIT_TOL
from kinergy.optimize.objectives import Objective
from kinergy.optimize.problem import (
    TimingProblem,
    program_settings,
    timing_problem,
    uniform_scaling,
)
from kinergy.optimize.program import durations, serial
from kinergy.optimize.solve import Outcome, Solution, solve_timing
from kinergy.optimize.verify import ProgramResult, simulate_program

__all__ = [
    "Checks",
    "ParetoPoint",
    "TimingResult",
    "Verified",
    "best_verified",
    "optimize_timing",
    "pareto_front",
    "uniform_wins",
]


@dataclass(frozen=True, eq=False)
class TimingResult:
    """The program as written, uniform time scaling and the energy-optimal timing at one cycle
    time, each re-simulated at 500 Hz.

    Attributes
    ----------
    cycle_time : float
        The budget, s.
    program, uniform, optimized : ProgramResult
    fastest_cycle_time : float
        Shortest cycle time within the limits (every move at its fastest feasible setting), s.
    v_cap, a_cap : ndarray, shape (K,)
        The optimiser's bounds on each move's ``v`` and ``a`` (``inf``: none but torque).
    active : list of str
        The limits the optimum runs into (one line each).
    iterations : int
        SLSQP iterations (all attempts).
    seconds : float
        Wall time of the optimisation and its verification, s (measured, never a budget).
    solver : Verified
        Why the solver stopped and whether uniform scaling was kept instead.
    """

    cycle_time: float
    program: ProgramResult
    uniform: ProgramResult
    optimized: ProgramResult
    fastest_cycle_time: float
    v_cap: Array
    a_cap: Array
    active: list[str]
    iterations: int
    seconds: float
    solver: Verified

    @property
    def message(self) -> str:
        """What the solver did, in words (:attr:`Verified.words`)."""
        return self.solver.words

    @property
    def saving(self) -> float:
        """``1 - E_optimized / E_program`` (fraction)."""
        return 1.0 - self.optimized.e_elec / self.program.e_elec

    @property
    def saving_vs_uniform(self) -> float:
        """``1 - E_optimized / E_uniform`` (fraction)."""
        return 1.0 - self.optimized.e_elec / self.uniform.e_elec

    def to_dict(self) -> dict[str, Any]:
        return {
            "cycle_time": self.cycle_time,
            "fastest_cycle_time": self.fastest_cycle_time,
            "program": self.program.to_dict(),
            "uniform": self.uniform.to_dict(),
            "optimized": self.optimized.to_dict(),
            "saving": self.saving,
            "saving_vs_uniform": self.saving_vs_uniform,
            "saving_percent": 100.0 * self.saving,
            "caps": {
                "v": [float(x) if np.isfinite(x) else None for x in self.v_cap],
                "a": [float(x) if np.isfinite(x) else None for x in self.a_cap],
            },
            "active_limits": list(self.active),
            "solver": {
                "iterations": self.iterations,
                "seconds": self.seconds,
                "outcome": None if self.solver.outcome is None else self.solver.outcome.value,
                "message": self.message,
            },
        }


class Checks(Protocol):
    """How every program of one comparison is re-simulated, checked and scored: the problem,
    and ``run(v, a, label, predicted)`` -> the re-simulated :class:`ProgramResult` (with its
    ``score``)."""

    @property
    def problem(self) -> TimingProblem: ...

    def run(
        self, v: Array, a: Array, label: str, predicted: float | None = None
    ) -> ProgramResult: ...


@dataclass(frozen=True)
class _Checks:
    """How every program of one comparison is re-simulated, checked and scored (movej)."""

    robot: Robot
    problem: TimingProblem
    v_max: float | None
    a_max: float | None
    recovery: bool

    def run(self, v: Array, a: Array, label: str, predicted: float | None = None) -> ProgramResult:
        return simulate_program(
            self.robot,
            self.problem.waypoints,
            v,
            a,
            self.problem.blends,
            recovery=self.recovery,
            speed_cap=self.v_max,
            acceleration_cap=self.a_max,
            label=label,
            predicted=predicted,
            objective=self.problem.objective,
        )


@dataclass(frozen=True)
class Caps:
    """The caps of one comparison besides the robot's limits: every joint's speed (rad/s) and
    acceleration (rad/s^2), None for none; and whether braking energy returns to the bus."""

    v_max: float | None = None
    a_max: float | None = None
    recovery: bool = True


def _comparison(
    robot: Robot,
    waypoints: ArrayLike,
    problem: TimingProblem | None,
    written: tuple[ArrayLike | None, ArrayLike | None],
    blends: ArrayLike | None,
    caps: Caps,
    objective: Objective | None,
) -> tuple[_Checks, Array, Array]:
    """The checks of one comparison and the program as written (per-move ``v``, ``a`` from the
    ``written`` speeds and accelerations), building the problem from the blends, the caps and
    ``objective`` unless given."""
    if problem is None:
        problem = timing_problem(
            robot,
            waypoints,
            blends=blends,
            v_max=caps.v_max,
            a_max=caps.a_max,
            recovery=caps.recovery,
            objective=objective,
        )
    checks = _Checks(robot, problem, caps.v_max, caps.a_max, caps.recovery)
    v_prog, a_prog = program_settings(problem, *written)
    return checks, v_prog, a_prog


def _scaled_to(
    problem: TimingProblem, v: Array, a: Array, cycle_time: float
) -> tuple[Array, Array]:
    """Settings ``(v, a)`` uniformly scaled so that the program takes ``cycle_time``."""
    return uniform_scaling(v, a, problem.cycle_time(v, a) / cycle_time)


def uniform_wins(uniform: ProgramResult, optimized: ProgramResult) -> bool:
    """Whether uniform scaling keeps the limits and the optimum does not, or scores better."""
    assert uniform.score is not None and optimized.score is not None
    return uniform.ok and (not optimized.ok or uniform.score < optimized.score)


def _tightened(problem: TimingProblem, over: dict[str, float]) -> TimingProblem:
    """The problem with its speed and acceleration caps shrunk by the excess ``over`` found at
    500 Hz (``{kind: worst ratio}``)."""
    shrink = {kind: (1.0 - 1e-6) / over.get(kind, 1.0 - 1e-6) for kind in ("speed", "acceleration")}
    a_cap = problem.a_cap * shrink["acceleration"]
    return dataclasses.replace(
        problem,
        v_cap=problem.v_cap * shrink["speed"],
        a_cap=a_cap,
        a_fast=np.minimum(problem.a_fast * shrink["acceleration"], a_cap),
    )


def _optimum(
    checks: Checks,
    cycle_time: float,
    v0: Array,
    a0: Array,
    *,
    share_budget: bool,
    maxiter: int = 150,
) -> tuple[ProgramResult, Solution | None, int]:
    """Solve, re-simulate at 500 Hz, and tighten the bounds by any excess found there (up to
    four attempts). Returns the verified program, the last solution (None at the fastest cycle
    time, which leaves nothing to choose) and the total iterations."""
    problem = checks.problem
    moving = problem.travel > 0.0
    if cycle_time <= problem.fastest_cycle_time * (1.0 + 1e-9):
        v = np.where(moving, problem.v_cap, v0)
        a = np.where(moving, problem.a_fast, a0)
        return checks.run(v, a, "optimized"), None, 0
    current = problem
    margin = 0.0
    iterations = 0
    for _ in range(4):
        sol = solve_timing(
            current,
            cycle_time,
            v0=v0,
            a0=a0,
            share_budget=share_budget,
            torque_margin=margin,
            maxiter=maxiter,
        )
        iterations += sol.iterations
        result = checks.run(sol.v, sol.a, "optimized", sol.value)
        over = {
            kind: ratio
            for kind, (ratio, _, _) in result.check.worst().items()
            if ratio > 1.0 + LIMIT_TOL
        }
        if not over or "position" in over:
            break  # (a movej cannot leave the box its waypoints span: nothing to tighten)
        current = _tightened(current, over)
        if "torque" in over:
            margin += over["torque"] - 1.0 + 2e-3
        v0, a0 = sol.v, sol.a
    return result, sol, iterations


def _active(problem: TimingProblem, result: ProgramResult) -> list[str]:
    """The limits the optimum runs into: the caps it sits on (per move), torques near theirs."""
    out = ["cycle time (the budget is used in full)"]
    moving = problem.travel > 0.0
    _, f = durations(problem.travel, result.speeds, result.accels)
    # a triangle never reaches its v: only a move that cruises is on its speed cap
    v_on = moving & (result.speeds >= problem.v_cap * (1.0 - 1e-3)) & (f < 1.0 - 1e-6)
    a_on = moving & (result.accels >= problem.a_fast * (1.0 - 1e-3))
    why_a = [
        problem.a_limit[k]
        if problem.a_fast[k] >= problem.a_cap[k]
        else "torque limits at full speed"
        for k in range(problem.moves)
    ]
    for kind, on, why in (("speed", v_on, problem.v_limit), ("acceleration", a_on, why_a)):
        for reason in sorted({why[k] for k in np.flatnonzero(on)}):
            moves = [str(k + 1) for k in np.flatnonzero(on) if why[k] == reason]
            out.append(f"{kind}: {reason} (move{'s' if len(moves) > 1 else ''} {', '.join(moves)})")
    ratio, joint, when = result.check.worst().get("torque", (0.0, "", 0.0))
    if ratio >= 0.98:
        out.append(f"torque: {joint} at {100 * ratio:.1f} % of its limit (t = {when:.2f} s)")
    return out


@dataclass(frozen=True)
class Verified:
    """How a verified timing came about: why the solver stopped (None at the fastest cycle
    time, where nothing is left to choose), whether its start (uniform scaling, or another
    named one) was kept because the solver ended above it, and the solver's iterations (all
    attempts)."""

    outcome: Outcome | None
    start_kept: bool
    iterations: int
    start: str = "uniform scaling"

    @property
    def words(self) -> str:
        """``optimal``, ``improved, iteration limit``, ... (:attr:`Outcome.words`), and what
        was kept instead when the solver ended above its start."""
        text = (
            "fastest cycle time: every move at its limits"
            if self.outcome is None
            else self.outcome.words
        )
        if self.start_kept:
            text += f"; the solver ended above {self.start}, which is kept"
        elif self.start != "uniform scaling":
            text += f" (from {self.start})"
        return text


def best_verified(
    checks: Checks,
    cycle_time: float,
    v0: Array,
    a0: Array,
    start: ProgramResult,
    share_budget: bool,
    maxiter: int = 150,
    label: str = "uniform scaling",
) -> tuple[ProgramResult, Verified]:
    """The verified optimum at ``cycle_time`` from ``(v0, a0)``: solved, re-simulated at 500 Hz
    and re-solved with the caps tightened by any excess found there (up to four attempts of at
    most ``maxiter`` SLSQP iterations each), or ``start`` (``label``: uniform scaling, by
    default) should the solver end above it; and how it came about. The solver stops on
    iterations and tolerances only: the same answer on every host."""
    optimized, sol, iterations = _optimum(
        checks, cycle_time, v0, a0, share_budget=share_budget, maxiter=maxiter
    )
    # uniform scaling to the budget is the program itself at the program's own cycle time
    kept = uniform_wins(start, optimized)
    if kept:
        optimized = checks.run(start.speeds, start.accels, "optimized")
    return optimized, Verified(None if sol is None else sol.outcome, kept, iterations, label)


def _budget(cycle_time: float | None, program: ProgramResult, fastest: float) -> float:
    """The cycle-time budget, s: the program's own unless given; at least the fastest."""
    budget = program.cycle_time if cycle_time is None else float(cycle_time)
    if not (np.isfinite(budget) and budget > 0.0):
        raise KinergyError(f"cycle time: must be > 0 s, got {cycle_time}")
    if budget < fastest * (1.0 - 1e-9):
        raise KinergyError(
            f"cycle time {budget:.4g} s is shorter than the fastest feasible {fastest:.4g} s "
            "(every move at its speed, acceleration and torque limits)"
        )
    return budget


@serial
def optimize_timing(
    robot: Robot,
    waypoints: ArrayLike,
    *,
    cycle_time: float | None = None,
    speeds: ArrayLike | None = None,
    accels: ArrayLike | None = None,
    blends: ArrayLike | None = None,
    v_max: float | None = None,
    a_max: float | None = None,
    share_budget: bool = True,
    recovery: bool = True,
    objective: Objective | None = None,
    problem: TimingProblem | None = None,
) -> TimingResult:
    """Energy-optimal per-move ``v`` and ``a`` of a movej program for a cycle time.

    Parameters
    ----------
    robot : Robot
    waypoints : array_like, shape (K + 1, n)
        Start pose and the K targets, rad.
    cycle_time : float, optional
        The budget, s; default the program's own cycle time (``--cycle-time same``).
    speeds, accels : float or array_like, shape (K,), optional
        The program as written (rad/s, rad/s^2); NaN or None: the fastest feasible.
    blends : float or array_like, shape (K,), optional
        Joint-space blend radii, rad (kept as given).
    v_max, a_max : float, optional
        Caps on every joint's speed and acceleration besides the robot's limits (the leading
        joint's ``v`` and ``a``). Without ``a_max`` a model without acceleration limits (UR arms)
        is bounded by its torque limits alone.
    share_budget : bool
        Let the optimiser share the budget among the moves (default); otherwise each move keeps
        its share of the program's time.
    recovery : bool
        Braking energy returns to the bus (default, as the seed).
    objective : Objective, optional
        What to minimise (:mod:`kinergy.optimize.objectives`); default the electrical energy.
    problem : TimingProblem, optional
        Built by :func:`timing_problem` with the same arguments and objective, to reuse it.

    Returns
    -------
    TimingResult
        The program, uniform scaling to ``cycle_time`` (speeds times ``k``, accelerations times
        ``k^2``) and the optimum, each re-simulated at 500 Hz (energy, and every limit at every
        sample). The optimum never scores worse than uniform scaling when that keeps the limits:
        should the solver end above it, uniform scaling is returned (and ``solver`` says so).

    Raises
    ------
    KinergyError
        Bad inputs, or a cycle time shorter than the fastest feasible.
    """
    started = time.perf_counter()
    checks, v_prog, a_prog = _comparison(
        robot, waypoints, problem, (speeds, accels), blends, Caps(v_max, a_max, recovery), objective
    )
    problem = checks.problem
    program = checks.run(v_prog, a_prog, "program")
    budget = _budget(cycle_time, program, problem.fastest_cycle_time)
    uniform = checks.run(*uniform_scaling(v_prog, a_prog, program.cycle_time / budget), "uniform")
    v0, a0 = _scaled_to(problem, v_prog, a_prog, budget)
    optimized, verified = best_verified(checks, budget, v0, a0, uniform, share_budget)
    return TimingResult(
        cycle_time=budget,
        program=program,
        uniform=uniform,
        optimized=optimized,
        fastest_cycle_time=problem.fastest_cycle_time,
        v_cap=problem.v_cap,
        a_cap=problem.a_cap,
        active=_active(problem, optimized),
        iterations=verified.iterations,
        seconds=time.perf_counter() - started,
        solver=verified,
    )


@dataclass(frozen=True)
class ParetoPoint:
    """Energy at one cycle time: the optimum and uniform scaling of the program, re-simulated at
    500 Hz (J), and whether each keeps every limit at every sample."""

    cycle_time: float
    optimized: float
    uniform: float
    optimized_ok: bool
    uniform_ok: bool

    def to_dict(self) -> dict[str, Any]:
        return {
            "cycle_time": self.cycle_time,
            "optimized": self.optimized,
            "uniform": self.uniform,
            "optimized_within_limits": self.optimized_ok,
            "uniform_within_limits": self.uniform_ok,
        }


def _cycle_times(
    cycle_times: Sequence[float] | None, points: int, fastest: float, own: float
) -> Array:
    """The front's cycle times, s, increasing: given, or ``points`` from the fastest feasible to
    twice the program's own, plus its own."""
    if cycle_times is None:
        if points < 2:
            raise KinergyError(f"points: need at least 2, got {points}")
        return np.unique(np.append(np.linspace(fastest, max(2.0 * own, fastest), points), own))
    times = np.sort(np.asarray(cycle_times, dtype=float))
    if times.size == 0 or not np.all(np.isfinite(times)) or times[0] < fastest * (1 - 1e-9):
        raise KinergyError(
            f"cycle_times: each must be at least the fastest feasible {fastest:.4g} s"
        )
    return times


@serial
def pareto_front(
    robot: Robot,
    waypoints: ArrayLike,
    *,
    speeds: ArrayLike | None = None,
    accels: ArrayLike | None = None,
    blends: ArrayLike | None = None,
    v_max: float | None = None,
    a_max: float | None = None,
    cycle_times: Sequence[float] | None = None,
    points: int = 8,
    share_budget: bool = True,
    recovery: bool = True,
    objective: Objective | None = None,
    problem: TimingProblem | None = None,
) -> list[ParetoPoint]:
    """Energy against cycle time: the optimum and uniform scaling of the program at each.

    Parameters are those of :func:`optimize_timing`; ``cycle_times`` (s) default to ``points``
    evenly spaced from the fastest feasible to twice the program's, plus the program's own.
    Each optimum starts from the previous one stretched to the next budget.

    Returns
    -------
    list of ParetoPoint
        By increasing cycle time.
    """
    checks, v_prog, a_prog = _comparison(
        robot, waypoints, problem, (speeds, accels), blends, Caps(v_max, a_max, recovery), objective
    )
    problem = checks.problem
    own = problem.cycle_time(v_prog, a_prog)
    out = []
    v0, a0 = v_prog, a_prog
    for budget in _cycle_times(cycle_times, points, problem.fastest_cycle_time, own):
        uniform = checks.run(*uniform_scaling(v_prog, a_prog, own / budget), "uniform")
        v0, a0 = _scaled_to(problem, v0, a0, float(budget))
        best, _, _ = _optimum(checks, float(budget), v0, a0, share_budget=share_budget)
        if uniform_wins(uniform, best):
            best = uniform
        out.append(
            ParetoPoint(
                cycle_time=float(budget),
                optimized=best.e_elec,
                uniform=uniform.e_elec,
                optimized_ok=best.ok,
                uniform_ok=uniform.ok,
            )
        )
        v0, a0 = best.speeds, best.accels
    return out
