"""The lag of the measured motion behind the commanded one: estimated by least squares over
sub-sample shifts (:func:`estimate_lag`, :func:`lag_search`) and applied by a cubic spline
(:func:`delay`)."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from kinergy.arrays import Array

__all__ = [
    "LAG_BATCH_ROWS",
    "MAX_LAG",
    "batches",
    "delay",
    "estimate_lag",
    "lag_samples",
    "lag_search",
]

#: s: the largest lag :func:`estimate_lag` looks for
MAX_LAG = 0.05

#: samples splined at once by the lag estimate (the windows around the compared samples, in
#: batches: the spline of a batch's windows needs a few times its samples while it is built)
LAG_BATCH_ROWS = 50_000


def lag_samples(t: Array, *, max_lag: float = MAX_LAG) -> NDArray[np.intp]:
    """The samples of uniform time stamps ``t`` (N,) :func:`estimate_lag` compares: those more
    than ``max_lag`` from either end, thinned to a few thousand (empty: too few to tell)."""
    inner = np.flatnonzero((t > t[0] + max_lag) & (t < t[-1] - max_lag))
    if inner.size < 10:
        return inner[:0]
    # a few thousand samples pin a lag of milliseconds down; evaluating every one is waste
    return inner[:: max(1, inner.size // 4000)]


def estimate_lag(t: Array, commanded: Array, measured: Array, *, max_lag: float = MAX_LAG) -> float:
    """Delay of ``measured`` behind ``commanded`` (both (N, n) speeds), s, by least squares over
    sub-sample shifts up to ``max_lag`` (a coarse grid then a golden-section refinement) at the
    samples :func:`lag_samples` picks."""
    inner = lag_samples(t, max_lag=max_lag)
    if inner.size == 0:
        return 0.0
    spline = CubicSpline(t, commanded, axis=0)
    return lag_search(spline, t[inner], measured[inner], float(t[1] - t[0]), max_lag=max_lag)


def lag_search(
    spline: Callable[[Array], Array],
    t: Array,
    measured: Array,
    dt: float,
    *,
    max_lag: float = MAX_LAG,
) -> float:
    """The shift (s) of the commanded speeds ``spline`` (times (k,) -> speeds (k, n)) that best
    matches ``measured`` (k, n) at the times ``t`` (k,): a grid of whole periods ``dt`` then a
    golden-section refinement."""

    def cost(lag: float) -> float:
        return float(np.sum((spline(t - lag) - measured) ** 2))

    grid = np.arange(-2, int(np.ceil(max_lag / dt)) + 1) * dt
    best = grid[int(np.argmin([cost(g) for g in grid]))]
    lo, hi = best - dt, best + dt
    ratio = (np.sqrt(5.0) - 1.0) / 2.0
    for _ in range(40):
        a, b = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
        if cost(a) < cost(b):
            hi = b
        else:
            lo = a
    return float(0.5 * (lo + hi))


def delay(t: Array, x: Array, lag: float, span: tuple[float, float] | None = None) -> Array:
    """``x(t - lag)`` by a cubic spline through ``t`` (N,), ``x`` (N, n), held at the value at
    the start of ``span`` (default ``t``'s ends: the whole log) before it."""
    lo, hi = (t[0], t[-1]) if span is None else span
    spline = CubicSpline(t, x, axis=0)
    return np.asarray(spline(np.clip(t - lag, lo, hi)), dtype=float)


def batches(windows: list[tuple[int, int]], rows: int) -> Iterator[list[tuple[int, int]]]:
    """Consecutive ``windows`` (start, stop) grouped into batches of about ``rows`` samples."""
    batch: list[tuple[int, int]] = []
    size = 0
    for a, b in windows:
        batch.append((a, b))
        size += b - a
        if size >= rows:
            yield batch
            batch, size = [], 0
    if batch:
        yield batch
