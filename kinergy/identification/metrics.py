"""Accuracy of a model's predictions: the statistics of the UR5e doc's Tables V and VII."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array

__all__ = [
    "EXCITED_RANGE",
    "ExcitedSums",
    "JointMetrics",
    "MetricSums",
    "SignalMetrics",
    "fit_metrics",
    "r_squared",
    "rmse",
]

#: rad: a joint whose position spans less than this over the samples is not excited
EXCITED_RANGE = 0.02


def r_squared(measured: ArrayLike, predicted: ArrayLike) -> Array:
    """Coefficient of determination per column, ``1 - SS_res / SS_tot``; (N, n) -> (n,). NaN
    where the measured signal does not vary (``SS_tot`` at round-off of its level): the ``r2``
    of :func:`fit_metrics`."""
    return np.array([m.r2 for m in fit_metrics(measured, predicted)])


def rmse(measured: ArrayLike, predicted: ArrayLike) -> Array:
    """Root-mean-square error per column (nursing eq 26); (N, n) -> (n,)."""
    e = np.asarray(predicted, dtype=float) - np.asarray(measured, dtype=float)
    return np.sqrt(np.mean(e**2, axis=0))


@dataclass(frozen=True)
class JointMetrics:
    """How well one joint's signal is predicted (UR5e Tables V, VII): mean, max |.| and RMS of
    the error (measured - predicted), in the signal's unit, and R^2 (NaN when the signal does not
    vary)."""

    mean: float
    max: float
    rms: float
    r2: float


def fit_metrics(measured: ArrayLike, predicted: ArrayLike) -> tuple[JointMetrics, ...]:
    """Per joint (column of ``measured`` and ``predicted``, both (N, n)): :class:`JointMetrics`
    (:class:`MetricSums` of one block)."""
    sums = MetricSums(np.shape(measured)[1])
    sums.add(measured, predicted)
    return sums.metrics()


class MetricSums:
    """UR5e Tables V and VII's statistics accumulated block by block (the same figures to
    round-off, whatever the blocks): per joint the count, sum, largest ``|.|`` and sum of
    squares of the error, and the measured signal's mean and sum of squared deviations (merged
    by Chan's formula, no cancellation); R^2 is NaN where the measured signal does not vary
    (as :func:`r_squared`)."""

    def __init__(self, n: int):
        self.count = 0
        self.err_sum = np.zeros(n)
        self.err_max = np.zeros(n)
        self.err_sq = np.zeros(n)
        self.mean = np.zeros(n)
        self.dev_sq = np.zeros(n)
        self.sq = np.zeros(n)

    def add(self, measured: ArrayLike, predicted: ArrayLike) -> None:
        """Fold in a block of ``measured`` and ``predicted`` (N, n)."""
        y = np.asarray(measured, dtype=float)
        err = y - np.asarray(predicted, dtype=float)
        k = y.shape[0]
        if k == 0:
            return
        self.err_sum += err.sum(axis=0)
        self.err_max = np.maximum(self.err_max, np.abs(err).max(axis=0))
        self.err_sq += np.sum(err**2, axis=0)
        mean = y.mean(axis=0)
        dev = np.sum((y - mean) ** 2, axis=0)
        total = self.count + k
        delta = mean - self.mean
        self.dev_sq += dev + delta**2 * self.count * k / total
        self.mean += delta * k / total
        self.sq += np.sum(y**2, axis=0)
        self.count = total

    def merge(self, other: MetricSums) -> None:
        """Fold in ``other``'s blocks (Chan's formula for the measured signal's moments)."""
        if other.count == 0:
            return
        total = self.count + other.count
        delta = other.mean - self.mean
        self.dev_sq += other.dev_sq + delta**2 * self.count * other.count / total
        self.mean += delta * other.count / total
        self.err_sum += other.err_sum
        self.err_max = np.maximum(self.err_max, other.err_max)
        self.err_sq += other.err_sq
        self.sq += other.sq
        self.count = total

    def metrics(self) -> tuple[JointMetrics, ...]:
        """Per joint :class:`JointMetrics` of all the blocks."""
        with np.errstate(divide="ignore", invalid="ignore"):
            varies = self.dev_sq > 1e-20 * np.maximum(self.sq, 1e-300)
            r2 = np.where(varies, 1.0 - self.err_sq / self.dev_sq, np.nan)
        return tuple(
            JointMetrics(
                mean=float(self.err_sum[j] / self.count),
                max=float(self.err_max[j]),
                rms=float(np.sqrt(self.err_sq[j] / self.count)),
                r2=float(r2[j]),
            )
            for j in range(self.mean.size)
        )


@dataclass(frozen=True)
class SignalMetrics(JointMetrics):
    """:class:`JointMetrics` with the RMS error over the RMS of the measured signal (``nrms``)
    and a ``note`` where R² means nothing (``not excited``, ``signal constant``; None
    otherwise, R² then NaN, JSON null)."""

    nrms: float = float("nan")
    note: str | None = None


class ExcitedSums:
    """One signal's figures over some samples, accumulated block by block: the error
    statistics (:class:`MetricSums`) and each joint's position
    range (which joints were excited)."""

    def __init__(self, n: int):
        self.sums = MetricSums(n)
        self.low = np.full(n, np.inf)
        self.high = np.full(n, -np.inf)

    def add(self, measured: Array, predicted: Array, q: Array) -> None:
        """Fold in a block of (N, n) signals and joint positions."""
        if len(q):
            self.sums.add(measured, predicted)
            self.low = np.minimum(self.low, q.min(axis=0))
            self.high = np.maximum(self.high, q.max(axis=0))

    def metrics(self) -> tuple[SignalMetrics, ...] | None:
        """Per joint :class:`SignalMetrics`; None without samples."""
        if self.sums.count == 0:
            return None
        level = np.sqrt(self.sums.sq / self.sums.count)
        out = []
        for j, m in enumerate(self.sums.metrics()):
            note = None
            if self.high[j] - self.low[j] < EXCITED_RANGE:
                note = "not excited"
            elif not np.isfinite(m.r2):
                note = "signal constant"
            r2 = m.r2 if note is None else float("nan")
            nrms = m.rms / level[j] if level[j] > 0 else float("nan")
            out.append(SignalMetrics(m.mean, m.max, m.rms, r2, nrms, note))
        return tuple(out)
