"""Energy-optimal timing of a robot program: per-move speeds and accelerations for a cycle time.

The timing lever of a program: each move's ``v`` and ``a``, its path and its events' times fixed.
For a cycle-time budget ``T`` :func:`retime` finds the per-move ``v_k, a_k`` (and, optionally,
how ``T`` is shared among the moves) that minimise the objective (the supply energy the model
predicts, :mod:`kinergy.optimize.objectives`) within the joints' speed, acceleration, torque and
position limits and the caps, and verifies every result by re-simulating the program at the
controller's 500 Hz (:func:`kinergy.optimize.verify.simulate_path`).

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

How it is solved
----------------
:func:`kinergy.optimize.problem.path_checks` builds the problem (arrays and callables),
:func:`allocated` shares the budget among the moves as if each ran alone (a grid per move and
dynamic programming over the time used), :func:`kinergy.optimize.solve.solve_timing` polishes the
better of that start and uniform time scaling with SLSQP on the quadrature of
:mod:`kinergy.optimize.samples`, and every result is re-simulated at 500 Hz: the energy reported
is that re-simulation's, and the limits are checked at every one of its samples. Should a sample
exceed a limit the quadrature nodes missed, the caps are tightened by the excess and the problem
solved again. Every step stops on iterations and tolerances, never on a clock: the same answer on
every host. :func:`check_cycle_time` is the one refusal of a budget below the fastest possible.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.optimize.constraints import LIMIT_TOL
from kinergy.optimize.problem import SLACK, PathChecks, TimingProblem, uniform_scaling
from kinergy.optimize.samples import durations, settings
from kinergy.optimize.solve import Outcome, Solution, solve_timing
from kinergy.optimize.verify import ProgramResult
from kinergy.trajectory.program_path import ProgramPath

__all__ = [
    "NO_ROOM",
    "Verified",
    "allocated",
    "check_cycle_time",
    "retime",
    "scaled_to",
]


#: why the timing solver may find no timing for a program that runs within its caps as written
NO_ROOM = f"{100 * SLACK:g} % below the speed caps (its iterations end a few ms off the cycle time)"
#: SLSQP iterations per attempt of the timing solver
_MAXITER = 50
#: the allocation's grid: durations per move, ramp fractions, programs evaluated at once, and
#: the steps of the budget its dynamic programme counts in
_DURATIONS = 24
_RAMPS = 8
_CHUNK = 24
_UNITS = 2000


def check_cycle_time(problem: TimingProblem, path: ProgramPath, budget: float) -> None:
    """Refuse a cycle time below the program's fastest within the caps, naming the longest move's
    line: every move at its speed, acceleration and torque limits.

    Raises
    ------
    KinergyError
        One line.
    """
    fastest = problem.fastest_cycle_time
    if budget < fastest * (1.0 - 1e-9):
        t_fast, _ = problem.fastest
        k = int(np.argmax(t_fast))
        raise KinergyError(
            f"cycle time {budget:.4g} s is shorter than the fastest possible {fastest:.4g} s "
            "(every move at its speed, acceleration and torque limits; the longest move: "
            f"{path.program.where(path.program.moves[k].line)})"
        )


def _uniform_wins(uniform: ProgramResult, optimized: ProgramResult) -> bool:
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
    checks: PathChecks,
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
    named one) was kept because the solver ended above it, the solver's iterations (all
    attempts) and the limits the result runs into (one line each)."""

    outcome: Outcome | None
    start_kept: bool
    iterations: int
    start: str = "uniform scaling"
    active: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, object]:
        return {
            "outcome": None if self.outcome is None else self.outcome.value,
            "message": self.words,
            "iterations": self.iterations,
            "active_limits": list(self.active),
        }

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


def _best_verified(
    checks: PathChecks,
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
    kept = _uniform_wins(start, optimized)
    if kept:
        optimized = checks.run(start.speeds, start.accels, "optimized")
    outcome = None if sol is None else sol.outcome
    active = tuple(_active(checks.problem, optimized))
    return optimized, Verified(outcome, kept, iterations, label, active)


def _ramps(dist: Array, grid_t: Array, v_cap: Array, a_cap: Array) -> Array:
    """``_RAMPS`` ramp fractions per grid duration and move, (D, R, m), spanning those within
    the move's speed and acceleration caps: ``f (1 - f/2) >= 2 D / (a t^2)`` (the acceleration)
    and ``f <= 2 (1 - D / (v t))`` (the speed), where the two meet near the fastest duration."""
    c = 2.0 * dist / (a_cap * grid_t**2)
    low = np.where(c <= 0.5, 1.0 - np.sqrt(np.maximum(1.0 - 2.0 * c, 0.0)), 1.0)
    high = np.clip(2.0 * (1.0 - dist / (grid_t * v_cap)), 0.0, 1.0)
    high = np.maximum(high, low)
    u = np.linspace(0.0, 1.0, _RAMPS)[None, :, None]
    return np.clip(low[:, None, :] + u * (high - low)[:, None, :], 1e-3, 1.0)


def _grid_energy(
    checks: PathChecks, moving: NDArray[np.intp], grid_t: Array, grid_f: Array
) -> tuple[Array, Array]:
    """Each moving move's part of the objective at every grid duration (D, m), with its cheapest
    ramp fraction of ``grid_f`` (D, R, m) within its speed and acceleration caps and its limits:
    the least part (D, m, inf where none fits) and that ramp fraction (D, m). Program ``(d, r)``
    of the grid runs every move at its own ``(grid_t[d], grid_f[d, r])``."""
    model, problem, path = checks.model, checks.problem, checks.path
    d_count, r_count = grid_f.shape[0], grid_f.shape[1]
    dist = path.travel[moving]
    t_all = np.repeat(grid_t, r_count, axis=0)  # (D R, m)
    f_all = grid_f.reshape(d_count * r_count, moving.size)
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
    ramp = np.take_along_axis(grid_f, pick[:, None, :], axis=1)[:, 0, :]  # (D, m)
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
    longest the budget leaves it) and ramp fraction (``_RAMPS`` across those within its caps,
    :func:`_ramps`), all moves at once in each of the grid's programs; per duration the cheapest
    ramp within the move's caps and limits; then the durations whose sum fits the budget at the
    least total, exactly on the grid, by dynamic programming over the time used
    (:func:`_share`). A second pass does the same on a finer grid around each move's choice
    (between its neighbouring grid durations). The moves interact only through blends, which this ignores: the solver
    starts from it, uniformly scaled to the budget. None where no grid point fits.
    """
    problem, path = checks.problem, checks.path
    moving = np.flatnonzero(path.travel > 0.0)
    if checks.model is None or moving.size == 0:
        return None
    dist = path.travel[moving]
    # the moves' durations add up to the budget less the events' time, plus what blends overlap
    # (as in the program uniformly scaled to the budget)
    t0, _ = durations(path.travel, *scaled_to(problem, path, path.speed, path.accel, budget))
    total = max(float(t0.sum()), budget - float(path.event_time.sum()))
    fast_t, _ = durations(dist, problem.v_cap[moving], problem.a_fast[moving])
    spare = total - float(fast_t.sum())
    if spare <= 0.0:
        return None
    v_cap, a_fast = problem.v_cap[moving], problem.a_fast[moving]
    grid_t = fast_t * np.geomspace(1.0, (fast_t + spare) / fast_t, _DURATIONS)  # (D, m)
    best, ramp = _grid_energy(checks, moving, grid_t, _ramps(dist, grid_t, v_cap, a_fast))
    chosen = _share(best, grid_t, total)
    if chosen is None:
        return None
    cols = np.arange(moving.size)
    low = grid_t[np.maximum(chosen - 1, 0), cols]
    high = grid_t[np.minimum(chosen + 1, _DURATIONS - 1), cols]
    fine_t = low + np.linspace(0.0, 1.0, _DURATIONS)[:, None] * (high - low)
    fine, fine_ramp = _grid_energy(checks, moving, fine_t, _ramps(dist, fine_t, v_cap, a_fast))
    again = _share(fine, fine_t, total)
    t, f = grid_t[chosen, cols], ramp[chosen, cols]
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


def _starts(checks: PathChecks, budget: float) -> list[tuple[Array, Array, str]]:
    """The solver's starts at ``budget``, the more promising first: the program uniformly scaled
    to it and the budget shared per move (:func:`allocated`), ordered by their quadrature
    objective (a start over a torque limit last)."""
    problem, path = checks.problem, checks.path
    starts = [(*scaled_to(problem, path, path.speed, path.accel, budget), "uniform scaling")]
    shared = allocated(checks, budget)
    if shared is None:
        return starts
    starts.append((*shared, "the budget shared per move"))
    timings = [durations(path.travel, v, a) for v, a, _ in starts]
    t = np.array([x[0] for x in timings])
    f = np.array([x[1] for x in timings])
    value, ratio = problem.evaluate(t, f)
    over = np.max(ratio, axis=1) > 1.0
    order = np.lexsort((value, over))
    return [starts[int(i)] for i in order]


def retime(
    checks: PathChecks,
    budget: float,
    *,
    share_budget: bool = True,
    maxiter: int = _MAXITER,
    starts: int = 2,
) -> tuple[ProgramResult, Verified]:
    """The verified energy-optimal timing at ``budget`` s, and how it came about: the solver runs
    from the program uniformly scaled to the budget and from the budget shared among the moves
    (:func:`_starts`, the more promising first; ``starts=1``: that one only, or the other should
    it not hold the limits), at most ``maxiter`` SLSQP iterations per attempt (it stops on
    iterations and tolerances, never on a clock: the same answer on every host), each keeping
    its start should it end above it; the best within the limits. (The energy is not convex in
    the timing: the two starts can end in different optima.)

    Raises
    ------
    KinergyError
        A budget below the fastest feasible cycle time (naming the slowest move's line).
    """
    check_cycle_time(checks.problem, checks.path, budget)
    best: tuple[ProgramResult, Verified] | None = None
    for i, (v0, a0, label) in enumerate(_starts(checks, budget)):
        if i >= starts and best is not None and best[0].ok:
            break
        start = checks.run(v0, a0, "uniform" if label == "uniform scaling" else "allocated")
        found = _best_verified(checks, budget, v0, a0, start, share_budget, maxiter, label)
        if best is None or _better(found[0], best[0]):
            best = found
    assert best is not None
    return best


def _better(a: ProgramResult, b: ProgramResult) -> bool:
    """Within the limits where the other is not, or as much so and a lower objective."""
    assert a.score is not None and b.score is not None
    return (not a.ok, a.score) < (not b.ok, b.score)
