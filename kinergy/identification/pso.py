"""Particle swarm optimisation with Clerc's constriction factor (the nursing doc's method, sec 4.1).

Each particle ``i`` has a position ``x_i`` and a velocity ``v_i`` in the box ``[lower, upper]``; it
remembers its own best position ``p_i`` and the swarm shares its best ``g`` (global-best
topology). One iteration is ::

    v_i <- chi (v_i + c1 r1 (p_i - x_i) + c2 r2 (g - x_i))
    x_i <- x_i + v_i

with ``r1, r2`` uniform on [0, 1) per particle and dimension, and the constriction factor ::

    chi = 2 / |2 - phi - sqrt(phi^2 - 4 phi)|,    phi = c1 + c2 > 4

(``c1 = c2 = 2.05``: ``chi = 0.7298``), which makes the swarm converge without a hand-tuned
inertia weight (M. Clerc and J. Kennedy, "The particle swarm - explosion, stability, and
convergence in a multidimensional complex space", IEEE Trans. Evol. Comput. 6(1):58-73, 2002).
Velocities are also clamped to the box's width per dimension, and a particle that would leave the
box stops at its wall with that velocity component set to zero (absorbing walls).

The objective takes every particle at once: ``f(X)`` with ``X`` of shape (P, d) returns (P,).
Optimisers take callables, not robots: the friction fit builds its objective and
calls :func:`particle_swarm`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.errors import KinergyError

__all__ = ["SwarmResult", "constriction", "particle_swarm"]


def constriction(c1: float = 2.05, c2: float = 2.05) -> float:
    """Clerc's constriction factor ``chi = 2 / |2 - phi - sqrt(phi^2 - 4 phi)|``, ``phi = c1 + c2``.

    Examples
    --------
    >>> round(constriction(2.05, 2.05), 4)
    0.7298
    """
    phi = c1 + c2
    if not phi > 4.0:
        raise KinergyError(f"the constriction factor needs c1 + c2 > 4, got {phi:g}")
    return float(2.0 / abs(2.0 - phi - np.sqrt(phi * phi - 4.0 * phi)))


@dataclass(frozen=True, eq=False)
class SwarmResult:
    """What :func:`particle_swarm` found.

    Attributes
    ----------
    x : ndarray, shape (d,)
        Best position.
    fun : float
        Objective at ``x``.
    history : ndarray, shape (iterations + 1,)
        Best objective after initialisation and after each iteration (non-increasing; the doc's
        Figure 7 "fitness curve").
    nfev : int
        Objective evaluations (particles times iterations + 1).
    """

    x: Array
    fun: float
    history: Array
    nfev: int


def _check_box(
    lower: ArrayLike, upper: ArrayLike, particles: int, iterations: int
) -> tuple[Array, Array]:
    """The search box as arrays (d,), checked, and the swarm's size."""
    lo = np.asarray(lower, dtype=float)
    hi = np.asarray(upper, dtype=float)
    if lo.ndim != 1 or lo.shape != hi.shape or not (np.all(np.isfinite(lo)) and np.all(hi > lo)):
        raise KinergyError("particle swarm bounds: need finite lower < upper of equal shape (d,)")
    if particles < 2 or iterations < 0:
        raise KinergyError(f"particle swarm: need >= 2 particles, got {particles}")
    return lo, hi


def _evaluate(fun: Callable[[Array], ArrayLike], x: Array) -> Array:
    """``fun(x)`` for the swarm ``x`` (P, d), shape (P,), non-finite values as +inf."""
    f = np.asarray(fun(x), dtype=float).reshape(-1)
    if f.shape != (x.shape[0],):
        raise KinergyError(
            f"particle swarm objective returned shape {f.shape}, expected ({x.shape[0]},)"
        )
    return np.where(np.isfinite(f), f, np.inf)


def _step(
    x: Array, v: Array, own: Array, social: Array, chi: float, lo: Array, hi: Array
) -> tuple[Array, Array]:
    """One move of the swarm (P, d): ``v <- chi (v + own + social)`` clamped to the box's width,
    ``x <- x + v``; a particle leaving the box stops at its wall with that velocity set to 0."""
    width = hi - lo
    v = chi * (v + own + social)
    v = np.clip(v, -width, width)
    x = x + v
    outside = (x < lo) | (x > hi)
    x = np.clip(x, lo, hi)
    v[outside] = 0.0
    return x, v


def particle_swarm(
    fun: Callable[[Array], ArrayLike],
    lower: ArrayLike,
    upper: ArrayLike,
    *,
    particles: int = 40,
    iterations: int = 200,
    c1: float = 2.05,
    c2: float = 2.05,
    rng: np.random.Generator | int | None = None,
    init: ArrayLike | None = None,
) -> SwarmResult:
    """Minimise ``fun`` over the box ``[lower, upper]`` with a constriction-factor swarm.

    Parameters
    ----------
    fun : callable
        ``fun(X) -> (P,)`` for ``X`` of shape (P, d); non-finite values count as +inf.
    lower, upper : array_like, shape (d,)
        Bounds of the search box (finite, ``lower < upper``).
    particles : int
        Swarm size P.
    iterations : int
        Number of velocity/position updates (the doc uses 200).
    c1, c2 : float
        Cognitive and social acceleration coefficients, ``c1 + c2 > 4``.
    rng : numpy.random.Generator or int, optional
        Random generator or seed (for reproducible runs).
    init : array_like, shape (k, d), optional
        Positions to put in the initial swarm (the rest are uniform in the box); clipped to it.

    Returns
    -------
    SwarmResult

    Examples
    --------
    >>> res = particle_swarm(lambda x: np.sum(x**2, axis=1), [-5, -5], [5, 5], rng=0)
    >>> bool(res.fun < 1e-12)
    True
    """
    lo, hi = _check_box(lower, upper, particles, iterations)
    chi = constriction(c1, c2)
    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    d = lo.size
    width = hi - lo

    x = lo + gen.random((particles, d)) * width
    if init is not None:
        seeds = np.clip(np.atleast_2d(np.asarray(init, dtype=float)), lo, hi)[:particles]
        x[: seeds.shape[0]] = seeds
    v = (gen.random((particles, d)) - 0.5) * width
    f = _evaluate(fun, x)
    best_x, best_f = x.copy(), f.copy()
    g = int(np.argmin(best_f))
    history = [float(best_f[g])]
    for _ in range(iterations):
        r1, r2 = gen.random((particles, d)), gen.random((particles, d))
        x, v = _step(x, v, c1 * r1 * (best_x - x), c2 * r2 * (best_x[g] - x), chi, lo, hi)
        f = _evaluate(fun, x)
        better = f < best_f
        best_x[better], best_f[better] = x[better], f[better]
        g = int(np.argmin(best_f))
        history.append(float(best_f[g]))
    return SwarmResult(
        x=best_x[g].copy(),
        fun=float(best_f[g]),
        history=np.array(history),
        nfev=particles * (iterations + 1),
    )
