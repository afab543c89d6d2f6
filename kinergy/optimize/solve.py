"""The solver: the best timing of a :class:`~kinergy.optimize.problem.TimingProblem` at one cycle
time, by SLSQP.

Decision variables are, per move, its duration ``t_k`` (its share of the budget) and ``ln a_k``;
the speed follows as the smaller root of ``t = D / v + v / a``. The acceleration cap is then a
bound (the cap, or where the model has none, the torque-limited acceleration at full speed,
:attr:`TimingProblem.a_fast`), the cycle time is linear (``sum t_k``; blends: kinergy's overlap
rule), and the speed cap and "reaches a speed at all" (``a t^2 >= 4 D``, a triangle at equality)
are smooth inequalities. Unlike ``(v, a)`` this has no kink at the trapezoid/triangle switch and
no curved equality to crawl along. (Parametrising the ramp between the two caps instead makes both
caps bounds, but degenerates where they meet: a move at its fastest then cannot leave it.) The
torque limits are constraints on the simulated motion (each move's largest ``|tau_joint| /
limit``). :func:`scipy.optimize.minimize` (SLSQP) solves it with forward-difference gradients,
all perturbed programs evaluated in one batched call of ``problem.evaluate``: the solver sees the
problem's callables only, whatever its objective.
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import minimize

from kinergy.arrays import Array
from kinergy.optimize.problem import TimingProblem
from kinergy.optimize.samples import durations, settings

__all__ = ["Outcome", "Solution", "solve_timing"]


#: relative forward-difference step in the decision variables
_FD_STEP = 1e-6


class Outcome(enum.Enum):
    """Why the solver stopped: a typed value, never read from the solver's message.

    ``CONVERGED``: the optimality conditions hold to the tolerance; ``ITERATION_LIMIT``: it used
    its iterations (the result improves on the start but is not proven optimal); ``STALLED``: its
    line search made no further progress (the result improves on the start); ``INFEASIBLE``: the
    constraints could not all be met from the start point.
    """

    CONVERGED = "converged"
    ITERATION_LIMIT = "iteration limit"
    STALLED = "stalled"
    INFEASIBLE = "infeasible"

    @classmethod
    def of_slsqp(cls, status: int) -> Outcome:
        """The outcome of SciPy's SLSQP exit ``status`` (0 success, 9 iteration limit, 2 and 4
        incompatible constraints, others a failed line search or a singular subproblem)."""
        if status == 0:
            return cls.CONVERGED
        if status == 9:
            return cls.ITERATION_LIMIT
        if status in (2, 4):
            return cls.INFEASIBLE
        return cls.STALLED

    @property
    def words(self) -> str:
        """What happened, for a user: ``optimal``, ``improved, iteration limit``, ..."""
        return {
            "converged": "optimal",
            "iteration limit": "improved, iteration limit",
            "stalled": "improved, no further progress",
            "infeasible": "infeasible: the limits and the cycle time cannot all be met",
        }[self.value]


@dataclass(frozen=True)
class Solution:
    """What :func:`solve_timing` found: ``v`` and ``a`` per move (K,), rad/s and rad/s^2, the
    predicted (quadrature) objective (the electrical energy, J, by default), the iterations and
    why the solver stopped."""

    v: Array
    a: Array
    value: float
    iterations: int
    outcome: Outcome


@dataclass(frozen=True, eq=False)
class _Variables:
    """The decision variables ``x = [z, ln a]`` and their map to the moves' timing.

    ``z`` (nz,) scales the start durations: one per moving move (``scale`` (K, nz) puts each on
    its move) or one for all (fixed shares); ``ln a`` (m,) per moving move. ``lower``, ``upper``
    bound x; ``steps`` are the forward-difference steps (relative to the start point).
    """

    travel: Array
    moving: NDArray[np.intp]
    scale: Array
    v_cap: Array
    lower: Array
    upper: Array
    steps: Array

    @property
    def nz(self) -> int:
        return int(self.scale.shape[1])

    def unpack(self, x: Array) -> tuple[Array, Array, Array]:
        """Rows of x (B, nz + m) -> durations (B, K), moving moves' accelerations and speeds
        (B, m): the smaller root of ``t = D / v + v / a`` (at the triangle limit, ``2 D / t``)."""
        x = np.atleast_2d(x)
        t = x[:, : self.nz] @ self.scale.T
        a = np.exp(x[:, self.nz :])
        tm = t[:, self.moving]
        dist = self.travel[self.moving]
        root = np.sqrt(np.maximum(a**2 * tm**2 - 4.0 * a * dist, 0.0))
        v = 0.5 * (a * tm - root)
        return t, a, v

    def timing(self, x: Array) -> tuple[Array, Array]:
        """Durations and ramp fractions (B, K)."""
        t, a, v = self.unpack(x)
        f = np.ones_like(t)
        f[:, self.moving] = np.clip(2.0 * v / (a * t[:, self.moving]), 0.0, 1.0)
        return t, f

    def shape(self, x: Array) -> Array:
        """Smooth inequalities (>= 0) of one or more points: reach, speed cap; (B, 2m)."""
        t, a, v = self.unpack(x)
        dist = self.travel[self.moving]
        reach = np.log(a) + 2.0 * np.log(t[:, self.moving]) - np.log(4.0 * dist)
        return np.hstack([reach, 1.0 - v / self.v_cap])

    def step(self, x: Array) -> Array:
        """Forward-difference steps at x, backward at an upper bound."""
        return np.where(x + self.steps > self.upper, -self.steps, self.steps)

    def jacobian(self, fun: Callable[[Array], Array], x: Array, h: Array) -> Array:
        """Forward-difference Jacobian (outputs, nx) of a cheap function of rows of x."""
        rows = np.asarray(fun(np.vstack([x, x + np.diag(h)])))
        rows = rows[:, None] if rows.ndim == 1 else rows  # (1 + nx, outputs)
        return np.asarray(((rows[1:] - rows[0]) / h[:, None]).T)


def _variables(
    problem: TimingProblem, cycle_time: float, v0: Array, a0: Array, share_budget: bool
) -> tuple[_Variables, Array]:
    """The variables of ``problem`` at ``cycle_time`` and the start point from ``(v0, a0)``."""
    travel = problem.travel
    moving = np.flatnonzero(travel > 0.0)
    m = moving.size
    dist = travel[moving]
    a_cap = problem.a_fast[moving]  # at most the cap, and the torques allow it at full speed
    t_start, _ = durations(travel, np.minimum(v0, problem.v_cap), np.minimum(a0, problem.a_fast))
    t_low, _ = durations(dist, problem.v_cap[moving], a_cap)  # fastest under the caps
    t_start = t_start.copy()
    t_start[moving] = np.maximum(t_start[moving], t_low)
    if share_budget:
        scale = np.zeros((travel.size, m))
        scale[moving, np.arange(m)] = t_start[moving]
        z_lo = t_low / t_start[moving]
        z_hi = np.maximum(cycle_time / t_start[moving], z_lo)
    else:
        scale = t_start[:, None].copy()
        z_lo = np.array([np.max(t_low / t_start[moving])])
        z_hi = np.maximum(np.array([cycle_time / np.min(t_start[moving])]), z_lo)
    ln_a_lo = np.log(np.minimum(4.0 * dist / cycle_time**2, a_cap))
    lower = np.concatenate([z_lo, ln_a_lo])
    upper = np.concatenate([z_hi, np.log(a_cap)])
    x0 = np.concatenate([np.ones(scale.shape[1]), np.log(np.minimum(a0, problem.a_fast)[moving])])
    x0 = np.clip(x0, lower, upper)
    steps = _FD_STEP * np.maximum(1.0, np.abs(x0))
    return _Variables(travel, moving, scale, problem.v_cap[moving], lower, upper, steps), x0


class _Model:
    """The problem's objective (scaled by its value at the start) and the moving moves' torque
    ratios at x, and their forward differences: a few points cached.

    A move's part of the objective and its torque ratio depend on its own variables and those of
    the moves blended into it only, so one program perturbs many moves at once (those three or
    more moves apart, or all of them when nothing is blended): a gradient costs two to six
    programs, evaluated in one batch, not two per move (sparse differences: Curtis, Powell and
    Reid, J. Inst. Maths Applics 13, 1974)."""

    def __init__(self, problem: TimingProblem, variables: _Variables, x0: Array) -> None:
        self.problem = problem
        self.variables = variables
        self.values: dict[bytes, tuple[float, Array, Array]] = {}
        self.slopes: dict[bytes, tuple[Array, Array]] = {}
        self.ref = 1.0
        self.ref = abs(self.value(x0)[0]) or 1.0
        self.values.clear()
        self.groups = _groups(problem, variables)

    def _evaluate(self, x: Array) -> tuple[Array, Array, Array]:
        """Objective (B,), its per-move parts (B, K), torque ratios (B, K) of rows x."""
        return self.problem.parts(*self.variables.timing(x))

    def value(self, x: Array) -> tuple[float, Array, Array]:
        """Scaled objective, the moving moves' torque ratios and the per-move parts at x."""
        key = x.tobytes()
        if key not in self.values:
            e, parts, ratio = self._evaluate(x)
            if len(self.values) > 8:
                self.values.clear()
            self.values[key] = (float(e[0]) / self.ref, ratio[0, self.variables.moving], parts[0])
        return self.values[key]

    def slope(self, x: Array) -> tuple[Array, Array]:
        """Gradient of the scaled objective and Jacobian of the torque ratios at x."""
        key = x.tobytes()
        if key not in self.slopes:
            e0, r0, p0 = self.value(x)
            h = self.variables.step(x)
            self.slopes.clear()
            self.slopes[key] = self._sparse(x, h, e0, r0, p0)
        return self.slopes[key]

    def _sparse(self, x: Array, h: Array, e0: float, r0: Array, p0: Array) -> tuple[Array, Array]:
        """The gradient and Jacobian from one perturbed program per group of variables."""
        index = np.arange(x.size)
        rows = np.array([x + np.where(np.isin(index, g), h, 0.0) for g, _ in self.groups])
        e, parts, ratio = self._evaluate(rows)
        moving = self.variables.moving
        grad = np.zeros(x.size)
        jac = np.zeros((moving.size, x.size))
        for (members, reach), e_g, p_g, r_g in zip(
            self.groups, e, parts, ratio[:, moving], strict=True
        ):
            for i in members:
                near = reach[int(i)]  # the moves whose parts x_i changes; None: every move
                if near is None:
                    grad[i] = (e_g / self.ref - e0) / h[i]
                    jac[:, i] = (r_g - r0) / h[i]
                    continue
                grad[i] = np.sum(p_g[near] - p0[near]) / self.ref / h[i]
                rows_m = np.flatnonzero(np.isin(moving, near))
                jac[rows_m, i] = (r_g[rows_m] - r0[rows_m]) / h[i]
        return grad, jac


#: the variables perturbed together, each with the moves whose parts it changes (None: all)
_Groups = list[tuple[NDArray[np.intp], dict[int, NDArray[np.intp] | None]]]


def _groups(problem: TimingProblem, var: _Variables) -> _Groups:
    """The variables perturbed together (:class:`_Model`): the durations and the accelerations
    of the moves ``k mod 3`` apart (every move at once when none is blended), or the one
    duration scale of fixed shares."""
    moves = problem.moves
    linked = np.asarray(problem.linked, dtype=bool)
    stride = 3 if np.any(linked) else 1
    m = var.moving.size
    z_move = var.moving if var.nz == m else None  # one z per moving move, or one for all
    groups: _Groups = []

    def reach(k: int) -> NDArray[np.intp]:
        lo = k - 1 if k > 0 and linked[k - 1] else k
        hi = k + 1 if k + 1 < moves and linked[k] else k
        return np.arange(lo, hi + 1)

    if z_move is None:
        every: dict[int, NDArray[np.intp] | None] = {i: None for i in range(var.nz)}
        groups.append((np.arange(var.nz), every))
    for offset, kind_moves in ((0, z_move), (var.nz, var.moving)):
        if kind_moves is None:
            continue
        for r in range(stride):
            members = np.flatnonzero(kind_moves % stride == r)
            if members.size:
                near: dict[int, NDArray[np.intp] | None] = {
                    int(i) + offset: reach(int(kind_moves[i])) for i in members
                }
                groups.append((members + offset, near))
    return groups


def _constraints(model: _Model, cycle_time: float, torque_margin: float) -> list[dict[str, Any]]:
    """SLSQP's constraints: the cycle time (equality), reach and speed caps, torque limits."""
    problem, var = model.problem, model.variables

    def cycle(x: Array) -> Array:
        return problem.cycle(*var.timing(x)) / cycle_time - 1.0

    def cycle_jac(x: Array) -> Array:
        if np.any(problem.blends[:-1] > 0.0):
            return var.jacobian(cycle, x, var.step(x))[0]
        # without blends the cycle time is the sum of the durations: linear in z
        return np.concatenate([var.scale.sum(axis=0), np.zeros(var.moving.size)]) / cycle_time

    return [
        {"type": "eq", "fun": lambda x: float(cycle(x)[0]), "jac": cycle_jac},
        {
            "type": "ineq",
            "fun": lambda x: var.shape(x)[0],
            "jac": lambda x: var.jacobian(var.shape, x, var.step(x)),
        },
        {
            "type": "ineq",
            "fun": lambda x: 1.0 - torque_margin - model.value(x)[1],
            "jac": lambda x: -model.slope(x)[1],
        },
    ]


def solve_timing(
    problem: TimingProblem,
    cycle_time: float,
    *,
    v0: ArrayLike,
    a0: ArrayLike,
    share_budget: bool = True,
    torque_margin: float = 0.0,
    maxiter: int = 150,
) -> Solution:
    """Minimise the objective of ``problem`` at ``cycle_time`` with SLSQP, from ``(v0, a0)``.

    Parameters
    ----------
    problem : TimingProblem
    cycle_time : float
        s; the program's total time must equal it.
    v0, a0 : array_like, shape (K,)
        Start (rad/s, rad/s^2): e.g. the program uniformly scaled to the budget.
    share_budget : bool
        Choose each move's share of the budget (default); otherwise every move keeps its share of
        ``(v0, a0)``'s time (one common scale).
    torque_margin : float
        Keep each move's largest joint torque below ``1 - torque_margin`` times its limit.
    maxiter : int
        SLSQP iterations: the solver stops on them and on its tolerance, never on a clock, so
        every host gets the same answer.

    Returns
    -------
    Solution
        ``v`` and ``a`` within the caps; moves that do not move keep ``v0`` and ``a0``.
    """
    v0 = np.asarray(v0, dtype=float)
    a0 = np.asarray(a0, dtype=float)
    variables, x0 = _variables(problem, cycle_time, v0, a0, share_budget)
    model = _Model(problem, variables, x0)
    res = minimize(
        lambda x: model.value(x)[0],
        x0,
        jac=lambda x: model.slope(x)[0],
        method="SLSQP",
        bounds=list(zip(variables.lower, variables.upper, strict=True)),
        constraints=_constraints(model, cycle_time, torque_margin),
        options={"maxiter": maxiter, "ftol": 1e-8},
    )
    t, f = variables.timing(np.clip(res.x, variables.lower, variables.upper))
    e, _ = problem.evaluate(t, f)
    v, a, _ = settings(problem.travel, t[0], f[0])
    moving = problem.travel > 0.0
    return Solution(
        v=np.where(moving, np.minimum(v, problem.v_cap), v0),
        a=np.where(moving, np.minimum(a, problem.a_cap), a0),
        value=float(e[0]),
        iterations=int(res.nit),
        outcome=Outcome.of_slsqp(int(res.status)),
    )
