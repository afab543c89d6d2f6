"""Cycle averaging of a repeated excitation (nursing section 4.2, eq 24).

A periodic excitation (eq 22) run for several periods is averaged sample by sample over the
periods, ``x_bar(k) = 1/N_j sum_i x_i(k)`` (eq 24), which cuts the noise by the root of the number
of periods without the phase lag of a filter:

- :func:`find_period`: the period of a repeated motion, from the log alone;
- :class:`CycleAverage`: eq 24, folded chunk by chunk (:func:`cycle_average` of signals held
  whole).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError

__all__ = ["CycleAverage", "cycle_average", "find_period"]


class CycleAverage:
    """Eq 24 folded chunk by chunk: the mean over whole periods, sample by sample within the
    period, ``x_bar(k) = 1/N_j sum_i x_i(k)`` (``k`` the sample within a period, ``i`` the
    period). The whole periods from ``t[0]`` are used (a trailing part is dropped); when
    ``period`` is not a whole number of samples, or the samples are not uniform, the signals are
    first interpolated (linearly) onto a grid that is. :meth:`add` takes the signals' samples in
    time order, in chunks of any size; the sums over the periods run in the order of the periods,
    so the result does not depend on the chunks.

    Parameters
    ----------
    t : array_like, shape (N,)
        Uniform time stamps of all the samples, s.
    period : float
        s.
    """

    def __init__(self, t: ArrayLike, period: float):
        tt = np.asarray(t, dtype=float)
        if tt.ndim != 1 or tt.size < 2:
            raise KinergyError("cycle averaging needs at least 2 time stamps")
        dt = float(np.median(np.diff(tt)))
        if not (np.isfinite(period) and period > 2 * dt):
            raise KinergyError(f"period must be longer than two samples, got {period}")
        k = round(period / dt)
        cycles = int(np.floor((tt[-1] - tt[0] + dt) / period + 1e-9))  # whole periods of samples
        if cycles < 1:
            raise KinergyError(
                f"the signals last {tt[-1] - tt[0]:.4g} s: not one whole period of {period:g} s"
            )
        self.t, self.k, self.cycles = tt, k, cycles
        self.exact = abs(k * dt - period) <= 1e-9 * period and np.allclose(
            np.diff(tt), dt, rtol=1e-6
        )
        self.grid = tt[0] + np.arange(cycles * k) * (period / k)
        # each grid point's sample on its left (-1: before the first)
        self.left = np.searchsorted(tt, self.grid, side="right") - 1
        self.sums: dict[str, Array] = {}
        self.rows = 0
        self.last: dict[str, Array] = {}

    def add(self, signals: Mapping[str, ArrayLike]) -> None:
        """Fold in the next samples of each signal, ``(m, ...)`` each."""
        arrays = {name: np.asarray(x, dtype=float) for name, x in signals.items()}
        size = len(next(iter(arrays.values())))
        a, b = self.rows, self.rows + size
        if self.exact:
            rows = np.arange(a, min(b, self.cycles * self.k))
            for name, x in arrays.items():
                self._sum(name, rows % self.k, x[: rows.size], x.shape[1:])
        else:
            lo = a - 1 if self.last else a
            tt = self.t[lo:b]
            upper = self.left < b - 1 if b < self.t.size else np.ones(self.left.size, bool)
            points = np.flatnonzero((self.left >= a - 1) & upper)
            for name, x in arrays.items():
                ext = np.concatenate([self.last[name], x]) if self.last else x
                flat = ext.reshape(ext.shape[0], -1)
                on_grid = np.column_stack(
                    [np.interp(self.grid[points], tt, flat[:, c]) for c in range(flat.shape[1])]
                ).reshape((points.size, *x.shape[1:]))
                self._sum(name, points % self.k, on_grid, x.shape[1:])
        self.last = {name: x[-1:].copy() for name, x in arrays.items()}
        self.rows = b

    def _sum(
        self, name: str, phase: NDArray[np.intp], values: Array, shape: tuple[int, ...]
    ) -> None:
        total = self.sums.setdefault(name, np.zeros((self.k, *shape)))
        np.add.at(total, phase, values)

    def result(self) -> tuple[Array, dict[str, Array]]:
        """Time within one period (from ``t[0]``, s, shape (K,)) and each signal's mean over the
        periods, ``(K, ...)``."""
        return self.grid[: self.k] - self.t[0], {
            name: total / self.cycles for name, total in self.sums.items()
        }


def cycle_average(
    t: ArrayLike, signals: ArrayLike | Mapping[str, ArrayLike], period: float
) -> tuple[Array, Array | dict[str, Array]]:
    """Eq 24 (:class:`CycleAverage`) of signals held whole.

    Parameters
    ----------
    t : array_like, shape (N,)
        Uniform time stamps, s.
    signals : array_like, shape (N, ...), or a mapping of names to such arrays
    period : float
        s.

    Returns
    -------
    t_one : ndarray, shape (K,)
        Time within one period (from ``t[0]``), s.
    averaged : ndarray, shape (K, ...), or a dict of them
    """
    average = CycleAverage(t, period)
    named = dict(signals) if isinstance(signals, Mapping) else {"x": signals}
    for x in named.values():
        if np.shape(x)[0] != average.t.size:
            raise KinergyError(f"a signal has {np.shape(x)[0]} samples, the time {average.t.size}")
    average.add(named)
    t_one, out = average.result()
    return t_one, out if isinstance(signals, Mapping) else out["x"]


def find_period(
    t: ArrayLike, x: ArrayLike, *, min_period: float = 1.0, tol: float = 1e-3
) -> float | None:
    """The period of a repeated motion, or None when it does not repeat at least twice.

    The smallest shift ``T >= min_period`` with ``mean |x(t + T) - x(t)|^2 <= tol * var(x)``
    (summed over columns), refined to the best shift within the first dip; computed for every
    shift at once with FFTs.

    Parameters
    ----------
    t : array_like, shape (N,)
        Uniform time stamps, s.
    x : array_like, shape (N, n)
        E.g. joint angles.
    """
    tt = np.asarray(t, dtype=float)
    arr = np.asarray(x, dtype=float).reshape(tt.size, -1)
    arr = arr - arr.mean(axis=0)
    big_n = tt.size
    var = float(np.sum(arr.var(axis=0)))
    if big_n < 8 or var == 0.0:
        return None
    dt = float(np.median(np.diff(tt)))
    size = 1 << int(np.ceil(np.log2(2 * big_n)))
    spec = np.fft.rfft(arr, size, axis=0)
    corr = np.fft.irfft(np.abs(spec) ** 2, size, axis=0)[:big_n].sum(axis=1)  # sum_i x_i x_{i+k}
    sq = np.sum(arr**2, axis=1)
    head = np.concatenate([[0.0], np.cumsum(sq)])  # head[m] = sum_{i<m} x_i^2
    lags = np.arange(big_n)
    count = big_n - lags
    tail = head[-1] - head[lags]  # sum_{i>=k} x_i^2
    mismatch = (tail + head[count] - 2.0 * corr) / np.maximum(count, 1)
    first = max(1, int(np.ceil(min_period / dt)))
    last = big_n // 2  # at least two periods
    if first >= last:
        return None
    good = np.flatnonzero(mismatch[first:last] <= tol * var)
    if good.size == 0:
        return None
    k0 = first + int(good[0])
    k1 = k0
    while k1 + 1 < last and mismatch[k1 + 1] <= tol * var:
        k1 += 1
    k = k0 + int(np.argmin(mismatch[k0 : k1 + 1]))
    return float(k * dt)
