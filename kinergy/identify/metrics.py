"""Accuracy of a model's predictions: the statistics of the UR5e doc's Tables V and VII."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["JointMetrics", "fit_metrics", "r_squared", "rmse"]

Array = NDArray[np.float64]


def r_squared(measured: ArrayLike, predicted: ArrayLike) -> Array:
    """Coefficient of determination per column, ``1 - SS_res / SS_tot``; (N, n) -> (n,). NaN
    where the measured signal does not vary (``SS_tot`` at round-off of its level)."""
    y = np.asarray(measured, dtype=float)
    p = np.asarray(predicted, dtype=float)
    ss_res = np.sum((y - p) ** 2, axis=0)
    ss_tot = np.sum((y - y.mean(axis=0)) ** 2, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        varies = ss_tot > 1e-20 * np.maximum(np.sum(y**2, axis=0), 1e-300)
        return np.where(varies, 1.0 - ss_res / ss_tot, np.nan)


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
    """Per joint (column of ``measured`` and ``predicted``, both (N, n)): :class:`JointMetrics`."""
    y = np.asarray(measured, dtype=float)
    p = np.asarray(predicted, dtype=float)
    err = y - p
    r2 = r_squared(y, p)
    return tuple(
        JointMetrics(
            mean=float(np.mean(err[:, j])),
            max=float(np.max(np.abs(err[:, j]))),
            rms=float(np.sqrt(np.mean(err[:, j] ** 2))),
            r2=float(r2[j]),
        )
        for j in range(y.shape[1])
    )
