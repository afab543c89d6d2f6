"""Solving an excitation design problem: SLSQP from random feasible starts, and random feasible
excitations to compare with.

``scipy.optimize.minimize(method="SLSQP")`` runs from several seeded random feasible starts
(:meth:`ExcitationProblem.random_start`) with the problem's exact gradients and constraint
Jacobians (:mod:`kinergy.experiments.excitation_problem`); the best result is checked at every
``dt`` sample and, should a sample still overshoot between grid points, scaled toward the start
pose until none does. The result is an :class:`Excitation`: nursing eq 22's coefficients, its
motion, condition number and the room left to every limit.

Examples
--------
>>> import kinergy
>>> from kinergy.experiments.excitation_problem import excitation_problem
>>> problem = excitation_problem(kinergy.load_robot("ur5e"), harmonics=2, samples=40)
>>> [round(e.margins["boundary"], 9) for e in random_feasible(problem, np.random.default_rng(0))]
[0.0]
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.optimize

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.experiments.excitation_problem import ExcitationProblem
from kinergy.experiments.excitation_regression import scaled_condition
from kinergy.jsonable import to_jsonable
from kinergy.trajectory.fourier import fourier_motion
from kinergy.trajectory.motion import Motion

__all__ = ["Excitation", "Progress", "design_excitation", "random_feasible"]


#: progress callback: (start number from 1, SLSQP iteration (0 = the start point), condition number)
Progress = Callable[[int, int, float], None]


@dataclass(frozen=True, eq=False)
class Excitation:
    """An excitation trajectory (nursing eq 22) and how good it is.

    Attributes
    ----------
    q0 : ndarray, shape (n,)
        Offsets, rad.
    a, b : ndarray, shape (n, L)
        Coefficients, rad/s.
    period : float
        s.
    start : ndarray, shape (n,)
        Start and end pose, rad.
    criterion : str
        What was optimised (``"cond"`` or ``"dopt"``; ``"random"`` for a random draw).
    condition : float
        Condition number of the column-scaled regression matrix on the problem's grid.
    d_criterion : float
        ``-log det(W_s^T W_s)`` on the same grid.
    margins : dict of str to float
        :meth:`ExcitationLimits.check`: smallest room to each limit at every ``dt`` sample.
    motion : Motion
        One period sampled every ``dt`` (:func:`fourier_motion`).
    iterations : int
        SLSQP iterations of the best start (0 for a random draw).
    seconds : float
        Wall time of the design, s.
    history : list of float
        Condition number after each iteration of the best start.
    """

    q0: Array
    a: Array
    b: Array
    period: float
    start: Array
    criterion: str
    condition: float
    d_criterion: float
    margins: dict[str, float]
    motion: Motion = field(metadata={"json": False})
    iterations: int = 0
    seconds: float = 0.0
    history: list[float] = field(default_factory=list, metadata={"json": False})

    @property
    def harmonics(self) -> int:
        return int(self.a.shape[1])

    @property
    def base_frequency(self) -> float:
        """``w_f``, rad/s."""
        return 2.0 * np.pi / self.period

    def repeated(self, periods: int = 1, *, dt: float | None = None) -> Motion:
        """``periods`` whole periods back to back, sampled every ``dt`` s (default the motion's)."""
        step = float(self.motion.t[1] - self.motion.t[0]) if dt is None else dt
        return fourier_motion(
            self.q0, self.a, self.b, base_frequency=self.base_frequency, periods=periods, dt=step
        )

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON data: the fields but the motion and the history, plus ``harmonics`` and
        ``base_frequency``."""
        derived = {"harmonics": self.harmonics, "base_frequency": self.base_frequency}
        return derived | to_jsonable(self)


@dataclass(frozen=True)
class _Run:
    """What the optimiser did: the unknowns (size,), its iterations and the condition number
    after each (none for a random draw)."""

    z: Array
    iterations: int = 0
    history: list[float] = field(default_factory=list)


def _excitation(
    problem: ExcitationProblem, run: _Run, criterion: str, seconds: float = 0.0
) -> Excitation:
    """The excitation of the unknowns ``run.z``, evaluated on the problem's grids."""
    q0, a, b = problem.coefficients(run.z)
    motion = problem.motion(run.z)
    condition, d_criterion = scaled_condition(problem.regression.flat(*problem.states(run.z)))
    return Excitation(
        q0=q0,
        a=a,
        b=b,
        period=problem.period,
        start=problem.limits.start.copy(),
        criterion=criterion,
        condition=condition,
        d_criterion=d_criterion,
        margins=problem.limits.check(problem.robot, motion),
        motion=motion,
        iterations=run.iterations,
        seconds=seconds,
        history=list(run.history),
    )


def random_feasible(
    problem: ExcitationProblem, rng: np.random.Generator, count: int = 1
) -> list[Excitation]:
    """``count`` random feasible excitations of the problem's size
    (:meth:`ExcitationProblem.random_start`).

    Each meets every limit at every ``dt`` sample and uses the whole room they give (scaled to
    99.9 % of the largest feasible size): the baseline an optimised design is compared with.
    """
    if count < 1:
        raise KinergyError(f"count must be >= 1, got {count}")
    return [_excitation(problem, _Run(problem.random_start(rng)), "random") for _ in range(count)]


def _run_from(
    problem: ExcitationProblem, z0: Array, k: int, maxiter: int, progress: Progress | None
) -> tuple[float, _Run]:
    """SLSQP from ``z0`` (start number ``k``): its criterion and its result fitted into the
    limits."""
    history = [problem.condition(z0, exact=False)]
    if progress is not None:
        progress(k, 0, history[0])

    def step(xk: Array) -> None:
        history.append(problem.condition(xk, exact=False))
        if progress is not None:
            progress(k, len(history) - 1, history[-1])

    res = scipy.optimize.minimize(
        problem.objective,
        z0,
        jac=True,
        method="SLSQP",
        constraints=[
            {"type": "ineq", "fun": problem.constraints, "jac": problem.constraints_jacobian}
        ],
        callback=step,
        options={"maxiter": int(maxiter), "ftol": 1e-7},
    )
    z = problem.fit_into_limits(res.x if np.all(np.isfinite(res.x)) else z0)
    return problem.objective(z)[0], _Run(z, int(res.nit), history)


def design_excitation(
    problem: ExcitationProblem,
    *,
    starts: int = 4,
    seed: int = 0,
    maxiter: int = 100,
    progress: Progress | None = None,
) -> Excitation:
    """Optimise the problem's criterion with SLSQP from ``starts`` random feasible starts.

    Parameters
    ----------
    problem : ExcitationProblem
    starts : int
        Random feasible starting points (:meth:`ExcitationProblem.random_start`), seeded.
    seed : int
    maxiter : int
        SLSQP iterations per start.
    progress : callable, optional
        ``progress(start, iteration, condition)`` after every iteration (``iteration`` 0 is the
        starting point; start counts from 1).

    Returns
    -------
    Excitation
        The start whose result has the best criterion, checked and if need be scaled so every
        ``dt`` sample meets every limit.
    """
    if isinstance(starts, bool) or not isinstance(starts, int | np.integer) or starts < 1:
        raise KinergyError(f"starts must be an integer >= 1, got {starts!r}")
    if maxiter < 1:
        raise KinergyError(f"maxiter must be >= 1, got {maxiter}")
    clock = time.perf_counter()
    rng = np.random.default_rng(seed)
    runs = [
        _run_from(problem, problem.random_start(rng), k, maxiter, progress)
        for k in range(1, starts + 1)
    ]
    best = min(runs, key=lambda run: run[0])[1]  # the first of equals, as the starts came
    return _excitation(problem, best, problem.criterion, time.perf_counter() - clock)
