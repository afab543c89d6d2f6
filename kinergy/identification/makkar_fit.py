"""Makkar's friction model (nursing eq 13) fitted to friction points (nursing section 4.1).

``f(v) = gamma1 (tanh(gamma2 v) - tanh(gamma3 v)) + gamma4 tanh(gamma5 v) + gamma6 v``
(:func:`kinergy.friction.makkar.makkar`) is fitted to the joint-side friction of constant-speed
runs (:mod:`kinergy.identification.friction_points`), with R^2 as the doc reports it (0.931 rotation,
0.927 pitch):

- :func:`fit_makkar_pso`: particle swarm optimisation with a constriction factor (the doc's
  method; :mod:`kinergy.identification.pso`), by default searching only the three rates and solving the
  three gains by linear least squares (variable projection);
- :func:`fit_makkar_lsq`: deterministic least squares from a grid of the rates.

Both can end with a local least-squares polish on all six parameters (:func:`_refine`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.optimize
from numpy.typing import ArrayLike
from scipy.ndimage import minimum_filter

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.friction.makkar import MODEL as MAKKAR
from kinergy.friction.makkar import PARAMETERS as _MAKKAR
from kinergy.friction.makkar import makkar, makkar_columns
from kinergy.identification.metrics import r_squared, rmse
from kinergy.identification.pso import SwarmResult, particle_swarm

__all__ = ["MakkarFit", "fit_makkar_lsq", "fit_makkar_pso"]

Seed = np.random.Generator | int | None

#: gamma1, gamma4, gamma6: the parameters the model is linear in
_GAINS = tuple(_MAKKAR.index(name) for name in MAKKAR.linear)
#: gamma2, gamma3, gamma5: the rates, which it is not linear in
_RATES = tuple(k for k in range(len(_MAKKAR)) if k not in _GAINS)


def _makkar_rows(gammas: Array, v: Array) -> Array:
    """Eq 13 for each row of ``gammas`` (P, 6) at the speeds ``v`` (M,): shape (P, M)."""
    return np.array([makkar(g, v) for g in gammas])


def _canonical(gamma: Array) -> Array:
    """Swap ``gamma2 <-> gamma3`` (negating ``gamma1``) so that ``gamma2 >= gamma3``: the two give
    the same curve; the canonical form has the Stribeck hump as a positive ``gamma1``."""
    g = np.asarray(gamma, dtype=float).copy()
    if g[1] < g[2]:
        g[1], g[2] = g[2], g[1]
        g[0] = -g[0]
    return g


@dataclass(frozen=True, eq=False)
class MakkarFit:
    """A fitted Makkar curve (eq 13) on the joint side.

    Attributes
    ----------
    gamma : ndarray, shape (6,)
        ``gamma1..gamma6`` (N m, s/rad, s/rad, N m, s/rad, N m s/rad), ``gamma2 >= gamma3``.
    r2, rmse : float
        Of the fitted curve against the points it was fitted to.
    method : str
        ``"pso"`` or ``"lsq"``.
    history : ndarray
        PSO: best mean squared error per iteration (the doc's Figure 7); LSQ: empty.
    """

    gamma: Array
    r2: float
    rmse: float
    method: str
    history: Array

    @property
    def params(self) -> dict[str, float]:
        """``{"gamma1": ..., "gamma6": ...}``."""
        return {name: float(x) for name, x in zip(_MAKKAR, self.gamma, strict=True)}

    def r2_against(self, speeds: ArrayLike, friction: ArrayLike) -> float:
        """R^2 of this curve against other points: ``speeds`` (rad/s) and ``friction`` (N m),
        both shape (M,) (say, every sample's odd part rather than the level means)."""
        pred = makkar(self.gamma, speeds)
        return float(r_squared(np.asarray(friction, dtype=float)[:, None], pred[:, None])[0])


def _check_points(speeds: ArrayLike, friction: ArrayLike) -> tuple[Array, Array]:
    """The points as flat arrays (M,): at least 6, of equal count, finite, speeds not all 0."""
    v = np.asarray(speeds, dtype=float).reshape(-1)
    f = np.asarray(friction, dtype=float).reshape(-1)
    if v.shape != f.shape or v.size < 6:
        raise KinergyError(
            f"Makkar fit: need at least 6 (speed, friction) points of equal count, got {v.size} and {f.size}"
        )
    if not (np.all(np.isfinite(v)) and np.all(np.isfinite(f))) or np.max(np.abs(v)) == 0:
        raise KinergyError("Makkar fit: speeds and friction must be finite, speeds not all zero")
    return v, f


def _rate_bounds(v: Array) -> tuple[float, float]:
    """Rates that bend the curve inside the data: ``tanh(gamma v)`` from 0.1 at the fastest point to
    10 at the slowest."""
    a = np.abs(v[v != 0])
    return 0.1 / float(a.max()), 10.0 / float(a.min())


def _gains(rates: Array, v: Array, f: Array, positive: bool = True) -> tuple[Array, Array]:
    """Variable projection: the best ``gamma1, gamma4, gamma6`` for each row of ``rates`` (P, 3) =
    ``(gamma2, gamma3, gamma5)`` by linear least squares (non-negative with ``positive``), and the
    mean squared error (P,)."""
    cols = makkar_columns(rates, v)  # (P, M, 3)
    scale = np.sqrt(np.einsum("pmk,pmk->pk", cols, cols)) + 1e-300
    cs = cols / scale[:, None, :]
    if positive:
        xs = np.array([scipy.optimize.nnls(c, f)[0] for c in cs])
    else:
        ata = np.einsum("pmk,pml->pkl", cs, cs) + 1e-12 * np.eye(3)
        xs = np.linalg.solve(ata, np.einsum("pmk,m->pk", cs, f)[..., None])[..., 0]
    x = xs / scale
    mse = np.mean((np.einsum("pmk,pk->pm", cols, x) - f) ** 2, axis=1)
    return x, mse


def _assemble(gains: Array, rates: Array) -> Array:
    """``gamma`` (P, 6) from the gains ``gamma1, gamma4, gamma6`` and rates (each (P, 3))."""
    g = np.empty((rates.shape[0], 6))
    g[:, list(_GAINS)] = gains
    g[:, list(_RATES)] = rates
    return g


def _fit_result(gamma: Array, v: Array, f: Array, method: str, history: Array) -> MakkarFit:
    """The canonical ``gamma`` with its R^2 and RMSE against the points ``v``, ``f``."""
    g = _canonical(gamma)
    pred = makkar(g, v)
    return MakkarFit(
        gamma=g,
        r2=float(r_squared(f[:, None], pred[:, None])[0]),
        rmse=float(rmse(f[:, None], pred[:, None])[0]),
        method=method,
        history=history,
    )


def _polish(gamma: Array, v: Array, f: Array, max_nfev: int = 2000, positive: bool = True) -> Array:
    """Local least squares on all six parameters from ``gamma``; the better of start and result.

    Unknowns ``[g1, log(g2/g3), log g3, g4, log g5, g6]`` with the exact Jacobian: Levenberg-
    Marquardt, or with ``positive`` a trust-region solve with ``g1, g4, g6 >= 0`` and
    ``g2 >= g3`` (Makkar's parameters are all positive; his model's hump then rises, not dips)
    and ``g1 <= 10 max|f|``: with ``g2 -> g3`` and ``g1 -> inf`` the hump tends to a finite shape
    (``g1 (g2 - g3) v / cosh^2(g3 v)``) that noisy data may prefer, and the bound keeps ``g1``
    from running off along it.
    """
    g0 = _canonical(gamma)
    g0[list(_RATES)] = np.maximum(np.abs(g0[list(_RATES)]), 1e-9)
    if positive:
        g0[list(_GAINS)] = np.maximum(g0[list(_GAINS)], 0.0)
    p0 = np.array(
        [g0[0], np.log(g0[1] / g0[2]), np.log(g0[2]), g0[3], np.log(g0[4]), g0[5]], dtype=float
    )

    def decode(p: Array) -> Array:
        l3 = np.clip(p[2], -50.0, 50.0)
        return np.array(
            [
                p[0],
                np.exp(np.clip(l3 + p[1], -50.0, 50.0)),
                np.exp(l3),
                p[3],
                np.exp(np.clip(p[4], -50.0, 50.0)),
                p[5],
            ]
        )

    def jac(p: Array) -> Array:
        g = decode(p)
        t2, t3, t5 = np.tanh(g[1] * v), np.tanh(g[2] * v), np.tanh(g[4] * v)
        d2 = g[0] * (1.0 - t2**2) * g[1] * v  # d f / d log g2
        d3 = -g[0] * (1.0 - t3**2) * g[2] * v  # d f / d log g3
        return np.column_stack([t2 - t3, d2, d2 + d3, t5, g[3] * (1.0 - t5**2) * g[4] * v, v])

    def resid(p: Array) -> Array:
        return np.asarray(makkar(decode(p), v) - f)

    tol = {"xtol": 1e-15, "ftol": 1e-15, "gtol": 1e-15, "max_nfev": max_nfev}
    if positive:
        lower = np.array([0.0, 0.0, -np.inf, 0.0, -np.inf, 0.0])
        upper = np.full(6, np.inf)
        upper[0] = 10.0 * max(float(np.max(np.abs(f))), 1e-300)
        g0[0] = min(g0[0], upper[0])
        p0[0] = g0[0]
        p0 = np.clip(p0, lower + 1e-12 * np.maximum(np.abs(p0), 1.0), upper * (1.0 - 1e-12))
        sol = scipy.optimize.least_squares(
            resid, p0, jac=jac, bounds=(lower, upper), method="trf", x_scale="jac", **tol
        )
    else:
        sol = scipy.optimize.least_squares(resid, p0, jac=jac, method="lm", x_scale="jac", **tol)
    g = decode(sol.x)
    better = np.sum((makkar(g, v) - f) ** 2) <= np.sum((makkar(g0, v) - f) ** 2)
    return g if better else g0


def _refine(starts: list[Array], v: Array, f: Array, positive: bool) -> Array:
    """Polish every start (:func:`_polish`); then, since two ``tanh`` steps of similar rate can
    trade places at a cost of ~1e-6 of the curve's variance (a near-symmetry of Makkar's model
    with its own local minima), polish the three best again from their rates permuted; return
    the best of all, polished to convergence."""

    def sse(g: Array) -> float:
        return float(np.sum((makkar(g, v) - f) ** 2))

    found = [_polish(g, v, f, 200, positive) for g in starts]
    found.sort(key=sse)
    for g in found[:3]:
        rates = np.abs(g[list(_RATES)])
        for perm in ((2, 1, 0), (0, 2, 1), (1, 2, 0)):
            r = rates[list(perm)][None, :]
            found.append(
                _polish(_assemble(_gains(r, v, f, positive)[0], r)[0], v, f, 200, positive)
            )
    return _polish(min(found, key=sse), v, f, 4000, positive)


def _swarm_rates(
    v: Array, f: Array, positive: bool, particles: int, iterations: int, rng: Seed
) -> tuple[Array, SwarmResult]:
    """Variable projection: the swarm searches the rates ``gamma2, gamma3, gamma5`` on a log scale
    (``gamma3`` as a fraction of ``gamma2`` with ``positive``); each particle's gains follow by
    linear least squares (:func:`_gains`). Returns ``gamma`` (6,) and the swarm's result."""
    r_lo, r_hi = np.log(_rate_bounds(v))
    big_f = float(np.max(np.abs(f))) or 1.0

    def rates_of(u: Array) -> Array:
        r = np.exp(r_lo + u * (r_hi - r_lo))
        if positive:  # the swarm searches gamma3 as a fraction of gamma2
            r[:, 1] = r[:, 0] * u[:, 1]
        return r

    def objective(u: Array) -> Array:
        gains, mse = _gains(rates_of(u), v, f, positive)
        if positive:  # gamma1 <= 10 max|f|, as in _polish
            return np.where(gains[:, 0] <= 10.0 * big_f, mse, np.inf)
        return mse

    res = particle_swarm(
        objective, np.zeros(3), np.ones(3), particles=particles, iterations=iterations, rng=rng
    )
    rates = rates_of(res.x[None, :])
    return _assemble(_gains(rates, v, f, positive)[0], rates)[0], res


def _swarm_all(
    v: Array, f: Array, positive: bool, particles: int, iterations: int, rng: Seed
) -> tuple[Array, SwarmResult]:
    """The doc's swarm: six-dimensional particles over all of ``gamma1..gamma6`` (rates on a log
    scale, ``gamma3`` as a fraction of ``gamma2``, ``gamma1 in [0, 5 F]``, ``gamma4 in [0, 2 F]``,
    ``gamma6 in [0, 2 F / V]``; the gains from ``-1`` times those without ``positive``).
    Returns ``gamma`` (6,) and the swarm's result."""
    r_lo, r_hi = np.log(_rate_bounds(v))
    big_f = float(np.max(np.abs(f))) or 1.0
    big_v = float(np.max(np.abs(v)))
    low = 0.0 if positive else -1.0

    def decode(u: Array) -> Array:
        g = np.empty_like(u)
        g[:, 0] = 5.0 * big_f * u[:, 0]
        g[:, 1] = np.exp(r_lo + u[:, 1] * (r_hi - r_lo))
        g[:, 2] = g[:, 1] * u[:, 2]
        g[:, 3] = 2.0 * big_f * u[:, 3]
        g[:, 4] = np.exp(r_lo + u[:, 4] * (r_hi - r_lo))
        g[:, 5] = 2.0 * big_f / big_v * u[:, 5]
        return g

    def objective(u: Array) -> Array:
        return np.asarray(np.mean((_makkar_rows(decode(u), v) - f) ** 2, axis=1))

    lower = np.array([low, 0.0, 0.0, low, 0.0, low])
    res = particle_swarm(
        objective, lower, np.ones(6), particles=particles, iterations=iterations, rng=rng
    )
    return decode(res.x[None, :])[0], res


def fit_makkar_pso(
    speeds: ArrayLike,
    friction: ArrayLike,
    *,
    particles: int = 30,
    iterations: int = 200,
    variable_projection: bool = True,
    positive: bool = True,
    polish: bool = False,
    rng: Seed = 0,
) -> MakkarFit:
    """Fit Makkar's model (eq 13) by particle swarm optimisation with a constriction factor.

    The objective is the mean squared difference between the measured and the modelled friction
    (section 4.1). The doc lets six-dimensional particles search all of ``gamma1..gamma6``
    (``variable_projection=False``, :func:`_swarm_all`). That swarm now and then settles where
    the Stribeck hump is switched off (R^2 0.978 on the twin's curve, for 1 seed in 20). By
    default the particles search only the three rates ``gamma2, gamma3, gamma5`` and each
    particle's ``gamma1, gamma4, gamma6`` follow by linear least squares, non-negative with
    ``positive`` (variable projection, G. Golub and V. Pereyra, SIAM J. Numer. Anal. 10(2),
    1973; particles whose ``gamma1`` exceeds ``10 F`` count as infeasible, see :func:`_polish`;
    :func:`_swarm_rates`), which finds the curve every time. ``polish=True`` ends with local
    least squares from the swarm's best (:func:`_refine`; as SciPy's ``differential_evolution``
    polishes): the swarm finds the curve, but Makkar's parameters lie along flat valleys, and
    only a polish pins them down.

    Parameters
    ----------
    speeds, friction : array_like, shape (M,)
        rad/s and N m (joint side), both signs allowed; at least 6 points.
    particles, iterations : int
        Swarm size and iterations (the doc: 200 iterations).
    positive : bool
        Keep every parameter >= 0 and ``gamma2 >= gamma3`` (Makkar's model as published; the
        doc's Table 4). The curve then extrapolates beyond the fastest point as
        ``gamma4 + gamma6 v``, never with a steep negative slope.
    rng : numpy.random.Generator or int, optional
        Seed of the swarm.

    Returns
    -------
    MakkarFit
        ``method = "pso"``; ``history`` is the swarm's best mean squared error per iteration.
    """
    v, f = _check_points(speeds, friction)
    swarm = _swarm_rates if variable_projection else _swarm_all
    gamma, res = swarm(v, f, positive, particles, iterations, rng)
    if polish:
        gamma = _refine([gamma], v, f, positive)
    return _fit_result(gamma, v, f, "pso", res.history)


def fit_makkar_lsq(
    speeds: ArrayLike,
    friction: ArrayLike,
    *,
    positive: bool = True,
    grid: int = 16,
    starts: int = 8,
) -> MakkarFit:
    """Fit Makkar's model (eq 13) by deterministic least squares.

    The model is linear in ``gamma1, gamma4, gamma6`` for fixed rates ``gamma2, gamma3, gamma5``:
    those are solved in closed form (non-negative with ``positive``) over a ``grid``-point
    logarithmic grid of each rate (in :func:`_rate_bounds`'s range, ``gamma2 > gamma3``). The
    grid's local minima, best first (up to ``starts``), are polished on all six parameters, and
    again from their rates permuted (:func:`_refine`); the best is kept. No randomness.

    Parameters
    ----------
    speeds, friction : array_like, shape (M,)
        rad/s and N m, both signs allowed; at least 6 points.
    positive : bool
        As :func:`fit_makkar_pso`'s.

    Returns
    -------
    MakkarFit
        ``method = "lsq"``.
    """
    v, f = _check_points(speeds, friction)
    lo, hi = _rate_bounds(v)
    axis = np.geomspace(lo, hi, grid)
    combos = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    valid = np.flatnonzero(combos[:, 0] > combos[:, 1])
    gains = np.zeros((combos.shape[0], 3))
    mse = np.full(combos.shape[0], np.inf)
    gains[valid], mse[valid] = _gains(combos[valid], v, f, positive)
    cube = mse.reshape(grid, grid, grid)
    local = np.flatnonzero((cube <= minimum_filter(cube, size=3, mode="nearest")).reshape(-1))
    local = local[np.isfinite(mse[local])]
    order = [int(k) for k in local[np.argsort(mse[local])][:starts]]
    order += [int(k) for k in np.argsort(mse)[: starts - len(order)] if k not in order]

    starts_ = [_assemble(gains[k : k + 1], combos[k : k + 1])[0] for k in order]
    return _fit_result(_refine(starts_, v, f, positive), v, f, "lsq", np.zeros(0))
