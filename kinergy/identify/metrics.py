"""Accuracy of a model's predictions: the statistics of the UR5e doc's Tables V and VII."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["fit_metrics", "r_squared", "rmse"]

Array = NDArray[np.float64]


def r_squared(measured: ArrayLike, predicted: ArrayLike) -> Array:
    """Coefficient of determination per column, ``1 - SS_res / SS_tot``; (N, n) -> (n,)."""
    y = np.asarray(measured, dtype=float)
    p = np.asarray(predicted, dtype=float)
    ss_res = np.sum((y - p) ** 2, axis=0)
    ss_tot = np.sum((y - y.mean(axis=0)) ** 2, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(ss_tot > 0, 1.0 - ss_res / ss_tot, np.nan)


def rmse(measured: ArrayLike, predicted: ArrayLike) -> Array:
    """Root-mean-square error per column (nursing eq 26); (N, n) -> (n,)."""
    e = np.asarray(predicted, dtype=float) - np.asarray(measured, dtype=float)
    return np.sqrt(np.mean(e**2, axis=0))


def fit_metrics(measured: ArrayLike, predicted: ArrayLike) -> list[dict[str, float]]:
    """Per joint: mean, max |.| and RMS of the error (measured - predicted) and R^2 (UR5e Tables V, VII).

    Returns
    -------
    list of dict
        ``{"mean", "max", "rms", "r2"}`` per column.
    """
    y = np.asarray(measured, dtype=float)
    p = np.asarray(predicted, dtype=float)
    err = y - p
    r2 = r_squared(y, p)
    return [
        {
            "mean": float(np.mean(err[:, j])),
            "max": float(np.max(np.abs(err[:, j]))),
            "rms": float(np.sqrt(np.mean(err[:, j] ** 2))),
            "r2": float(r2[j]),
        }
        for j in range(y.shape[1])
    ]
