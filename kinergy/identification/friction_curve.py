"""A friction model fitted to friction points, and the model chosen by cross-validation.

Friction points are what a friction run or a joint calibration measures: at motor speeds ``wm``
(rad/s) the friction torque ``tau`` (N m, motor side), and where known the load torque the
joint carried and its temperature. Any friction model (:mod:`kinergy.friction`) that is
linear in some parameters fits them by weighted least squares; shape parameters the model names
in its ``search`` bounds (``power_law``'s exponent) are found by a 1-D search around that least
squares (:func:`search_shape`, shared with the sequential method's current fit).

:func:`choose_model` fits each candidate model on all points but one block and scores it on the
block left out (cross-validation); the model with the lowest held-out RMS wins.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.friction.model import FrictionModel
from kinergy.identification.chunks import Asks, answer, translated
from kinergy.linalg import scaled_lstsq

__all__ = [
    "CurveFit",
    "FrictionPoints",
    "Search",
    "bounded_minimum",
    "choose_model",
    "fit_curve",
    "points_from",
    "search_shape",
    "shape_search",
]


#: trial values of a searched shape parameter before the bounded refinement
SEARCH_GRID = 15


@dataclass(frozen=True, eq=False)
class FrictionPoints:
    """Friction measured at a set of speeds, motor side; arrays of shape (k,).

    Attributes
    ----------
    wm : ndarray
        Motor speed, rad/s.
    tau : ndarray
        Friction torque, N m.
    load, temperature : ndarray or None
        Load torque (N m, motor side) and joint temperature (deg C), where measured.
    weights : ndarray or None
        Least-squares weights (default 1): ``1 / tolerance`` fits every point to the same
        relative accuracy.
    """

    wm: Array
    tau: Array
    load: Array | None = None
    temperature: Array | None = None
    weights: Array | None = None

    def __len__(self) -> int:
        return int(self.wm.size)

    def subset(self, keep: NDArray[np.bool_]) -> FrictionPoints:
        """The points where ``keep`` is True."""

        def cut(x: Array | None) -> Array | None:
            return None if x is None else x[keep]

        return FrictionPoints(
            self.wm[keep], self.tau[keep], cut(self.load), cut(self.temperature), cut(self.weights)
        )


@dataclass(frozen=True)
class CurveFit:
    """A friction model fitted to points.

    Attributes
    ----------
    model : FrictionModel
    params : dict of str to float
        All its parameters (the robot-file form), motor side.
    rms : float
        Weighted RMS of the fit's error on the points it was fitted to (N m with unit weights).
    cv_rms : float or None
        The same on held-out blocks (:func:`choose_model`); None when not cross-validated.
    """

    model: FrictionModel = field(metadata={"json": lambda m: m.name})
    params: dict[str, float]
    rms: float
    cv_rms: float | None = None

    def torque(self, points: FrictionPoints) -> Array:
        """The fitted friction at ``points``' speeds (and loads, temperatures), N m."""
        return self.model.friction_torque(
            self.params, points.wm, points.load, temperature=points.temperature
        )


#: a search of shape parameters (:func:`shape_search`): asks for the cost of batches of
#: parameter sets and returns the parameters found
Search = Asks[dict[str, float], float, dict[str, float]]


def shape_search(model: FrictionModel, params: Mapping[str, float]) -> Search:
    """``params`` with each shape parameter the model searches (``FrictionModel.search``) set to
    the value in its bounds that minimises a cost it asks for (:data:`Search`): a grid of
    :data:`SEARCH_GRID` values in one batch, then a bounded 1-D refinement around the best
    (:func:`bounded_minimum`); ``params`` unchanged for models without one."""
    best = dict(params)
    for name, (low, high) in model.search.items():
        grid = np.linspace(low, high, SEARCH_GRID)
        costs = yield [{**best, name: float(v)} for v in grid]
        k = int(np.argmin(costs))
        lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]

        def at(value: float, name: str = name) -> dict[str, float]:
            return {**best, name: float(value)}

        x, fx = yield from translated(bounded_minimum(lo, hi, xatol=1e-4), at, _same)
        best[name] = float(x) if fx <= costs[k] else float(grid[k])
    return best


def _same(_: float, cost: float) -> float:
    return cost


def search_shape(
    model: FrictionModel, params: Mapping[str, float], cost: Callable[[dict[str, float]], float]
) -> dict[str, float]:
    """:func:`shape_search` with each parameter set's cost from ``cost``."""
    return answer(shape_search(model, params), lambda batch: [cost(p) for p in batch])


class _Unknown(Exception):
    """The cost at ``value`` is not known yet."""

    def __init__(self, value: float):
        self.value = value


def bounded_minimum(
    low: float, high: float, *, xatol: float = 1e-5
) -> Asks[float, float, tuple[float, float]]:
    """SciPy's bounded minimisation (Brent's ``fminbound``) of a function of one value on
    ``[low, high]``, asking for its value one point at a time; returns the minimum found and
    its value. Each time it needs a value it does not know yet, the search is run again from
    the start with the values known so far (it is deterministic, so it retraces its steps to
    the new point): the same result whether the costs come from memory or from passes over
    chunks, for a few dozen cheap reruns."""
    from scipy.optimize import minimize_scalar  # slow to import; only shape searches need it

    known: dict[float, float] = {}

    def cost(value: float) -> float:
        if float(value) not in known:
            raise _Unknown(float(value))
        return known[float(value)]

    while True:
        try:
            found = minimize_scalar(
                cost, bounds=(low, high), method="bounded", options={"xatol": xatol}
            )
        except _Unknown as unknown:
            (known[unknown.value],) = yield [unknown.value]
        else:
            return float(found.x), float(found.fun)


def _linear_fit(
    model: FrictionModel, params: Mapping[str, float], points: FrictionPoints
) -> CurveFit:
    """The model's linear parameters by weighted least squares, its shape parameters held."""
    cols = model.friction_columns(params, points.wm, points.load, temperature=points.temperature)
    w = np.ones(len(points)) if points.weights is None else points.weights
    values, _, _ = scaled_lstsq(cols * w[:, None], points.tau * w)
    fitted = model.with_values(params, values)
    rms = float(np.sqrt(np.mean((w * (cols @ values - points.tau)) ** 2)))
    return CurveFit(model, fitted, rms)


def fit_curve(
    model: FrictionModel, points: FrictionPoints, params: Mapping[str, float] | None = None
) -> CurveFit:
    """Fit ``model`` to ``points`` (module docstring).

    Parameters
    ----------
    model : FrictionModel
        A model linear in some parameters.
    points : FrictionPoints
    params : mapping, optional
        Starting parameters (their shape parameters are kept unless searched); default the
        model's shape defaults.

    Raises
    ------
    KinergyError
        Fewer points than the model has linear parameters; a model the points cannot evaluate
        (one that needs the load torque, given none).
    """
    if len(points) < len(model.linear):
        raise KinergyError(
            f"friction model {model.name!r} has {len(model.linear)} linear parameters; "
            f"{len(points)} points cannot fit it"
        )
    start = dict(params) if params is not None else model.start()
    shaped = search_shape(model, start, lambda p: _linear_fit(model, p, points).rms)
    return _linear_fit(model, shaped, points)


def _blocks(count: int, folds: int) -> list[NDArray[np.bool_]]:
    """``folds`` contiguous blocks of ``count`` items (as masks; at least 2)."""
    edges = np.linspace(0, count, max(2, min(folds, count)) + 1).astype(int)
    index = np.arange(count)
    return [(index >= a) & (index < b) for a, b in itertools.pairwise(edges)]


def _cv_rms(model: FrictionModel, points: FrictionPoints, folds: int) -> float:
    """Weighted RMS of ``model`` on each block left out, fitted on the others."""
    errors = []
    for held in _blocks(len(points), folds):
        fit = fit_curve(model, points.subset(~held))
        test = points.subset(held)
        w = np.ones(len(test)) if test.weights is None else test.weights
        errors.append(w * (fit.torque(test) - test.tau))
    return float(np.sqrt(np.mean(np.concatenate(errors) ** 2)))


def choose_model(
    candidates: Sequence[FrictionModel], points: FrictionPoints, *, folds: int | None = None
) -> tuple[CurveFit, tuple[CurveFit, ...]]:
    """The candidate with the lowest cross-validated RMS, fitted on all points.

    Parameters
    ----------
    candidates : sequence of FrictionModel
        Registry models to try (those the points cannot fit are skipped).
    points : FrictionPoints
        In an order whose contiguous blocks make fair held-out sets (speed order for a
        calibration: each block is a stretch of the curve the others must predict).
    folds : int, optional
        Number of blocks; default one point per block (leave one out).

    Returns
    -------
    best : CurveFit
        With its ``cv_rms``.
    tried : tuple of CurveFit
        Every candidate that could be fitted, fitted on all points, with its ``cv_rms``.
    """
    folds = len(points) if folds is None else folds
    tried = []
    for model in candidates:
        if (model.needs_load and points.load is None) or len(points) - max(
            1, len(points) // folds
        ) < len(model.linear):
            continue
        fit = fit_curve(model, points)
        tried.append(CurveFit(fit.model, fit.params, fit.rms, _cv_rms(model, points, folds)))
    if not tried:
        names = ", ".join(c.name for c in candidates)
        raise KinergyError(f"no friction model of {names} fits these points")
    best = min(tried, key=lambda f: f.cv_rms if f.cv_rms is not None else np.inf)
    return best, tuple(tried)


def points_from(
    wm: ArrayLike,
    tau: ArrayLike,
    *,
    load: ArrayLike | None = None,
    temperature: ArrayLike | None = None,
    tolerance: tuple[float, float] | None = None,
) -> FrictionPoints:
    """:class:`FrictionPoints` from arrays; ``tolerance = (relative, absolute)`` weights each
    point by ``1 / max(relative |tau|, absolute)``."""

    def arr(x: ArrayLike | None) -> Array | None:
        return None if x is None else np.asarray(x, dtype=float)

    wm_, tau_ = np.asarray(wm, dtype=float), np.asarray(tau, dtype=float)
    weights = None
    if tolerance is not None:
        weights = 1.0 / np.maximum(tolerance[0] * np.abs(tau_), tolerance[1])
    return FrictionPoints(wm_, tau_, arr(load), arr(temperature), weights)
