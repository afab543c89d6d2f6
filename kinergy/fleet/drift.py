"""Drift and step changes in a robot's energy or friction per cycle, day after day.

For one robot running one program, a figure per cycle (energy, or the motor work that friction
takes) is summarised per day. Two things can move it:

- a **step change**: a new payload, a new gripper, a changed program speed -- the level jumps
  from one day to the next and stays. It is found by binary segmentation: the split of the days
  into two levels that explains the most, accepted when the jump is more than
  :data:`STEP_SIGMAS` spreads and two levels fit the days better than a straight line does;
  the parts are searched again (at most :data:`MAX_CHANGES` changes).
- **drift**: the level creeps up day after day inside one stretch between changes (a wearing
  gearbox). A line is fitted over at least :data:`MIN_DAYS` days; the stretch drifts when its
  rise from the first to the last day is more than :data:`DRIFT_SIGMAS` spreads *and* more than
  ``min_rise`` (5 %) of its first level.

The spread is the figure's own: the larger of the scatter of the cycles within a day (pooled)
and of the day-to-day scatter (the median absolute residual of the daily means about the better
of a line and two levels, so neither a steady trend nor a step inflates it, scaled to a standard
deviation), with a floor of 0.2 % of the level.
"""

from __future__ import annotations

import datetime as dt
import itertools
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

__all__ = ["DRIFT_SIGMAS", "MAX_CHANGES", "MIN_DAYS", "STEP_SIGMAS", "Change", "Trend", "trend"]

Array = NDArray[np.float64]

STEP_SIGMAS = 6.0
DRIFT_SIGMAS = 4.0
MIN_DAYS = 3
MAX_CHANGES = 3


@dataclass(frozen=True)
class Change:
    """A step between two days: ``before`` up to ``date`` (exclusive), ``after`` from it."""

    date: dt.date
    before: float
    after: float

    @property
    def relative(self) -> float:
        return (self.after - self.before) / self.before if self.before else float("nan")


@dataclass(frozen=True)
class Trend:
    """A figure's days, its step changes and whether it drifts.

    Attributes
    ----------
    days : list of datetime.date
    means : list of float
        The figure's mean per day.
    spread : float
        Its own scatter (see the module docstring), same unit.
    changes : list of Change
    drift : bool
    rise : float
        The largest relative rise of a stretch between changes (its line's last day over its
        first), 0 when no stretch is long enough or none rises.
    """

    days: list[dt.date]
    means: list[float]
    spread: float
    changes: list[Change] = field(default_factory=list)
    drift: bool = False
    rise: float = 0.0


def _line_sse(x: Array, y: Array) -> float:
    if y.size < 3:
        return 0.0
    coef = np.polyfit(x, y, 1)
    return float(np.sum((y - np.polyval(coef, x)) ** 2))


def _residuals(x: Array, y: Array) -> Array:
    """Residuals of the better of a line and two levels (the best split) through ``y``."""
    best = y - np.polyval(np.polyfit(x, y, 1), x)
    for k in range(2, y.size - 1):
        step = np.concatenate([y[:k] - y[:k].mean(), y[k:] - y[k:].mean()])
        if np.sum(step**2) < np.sum(best**2):
            best = step
    return best


def _spread(groups: Sequence[Array], x: Array, means: Array) -> float:
    within = [g - g.mean() for g in groups if g.size > 1]
    dof = sum(g.size - 1 for g in groups)
    pooled = float(np.sqrt(sum(float(np.sum(w**2)) for w in within) / dof)) if dof else 0.0
    daily = 0.0
    if means.size >= 4:  # robust scatter of the days about a line or two levels
        residuals = np.abs(_residuals(x, means))
        daily = float(1.4826 * np.median(residuals) * np.sqrt(means.size / (means.size - 2)))
    return max(pooled, daily, 0.002 * float(np.mean(np.abs(means))))


def _best_step(x: Array, y: Array, spread: float) -> int | None:
    """Where two levels fit ``y`` best, if that is a real step (see the module docstring)."""
    if y.size < 2:
        return None
    sse = [
        float(np.sum((y[:k] - y[:k].mean()) ** 2) + np.sum((y[k:] - y[k:].mean()) ** 2))
        for k in range(1, y.size)
    ]
    k = 1 + int(np.argmin(sse))
    jump = abs(y[k:].mean() - y[:k].mean())
    if jump <= STEP_SIGMAS * spread or sse[k - 1] >= _line_sse(x, y):
        return None
    return k


def _steps(x: Array, y: Array, spread: float, offset: int = 0) -> list[int]:
    """Indices where a new level starts (binary segmentation)."""
    k = _best_step(x, y, spread)
    if k is None:
        return []
    left = _steps(x[:k], y[:k], spread, offset)
    right = _steps(x[k:], y[k:], spread, offset + k)
    return sorted([*left, offset + k, *right])[:MAX_CHANGES]


def trend(
    days: Sequence[dt.date], values: Sequence[Sequence[float]], *, min_rise: float = 0.05
) -> Trend:
    """Step changes and drift of a figure over days.

    Parameters
    ----------
    days : sequence of datetime.date, length D
        Distinct days, increasing.
    values : sequence of sequences of float, length D
        The figure for each cycle of each day.
    min_rise : float
        Smallest relative rise called drift.

    Returns
    -------
    Trend
    """
    groups = [np.asarray(v, dtype=float) for v in values]
    means = np.array([g.mean() for g in groups])
    x = np.array([(d - days[0]).days for d in days], dtype=float)
    spread = _spread(groups, x, means)
    starts = _steps(x, means, spread)
    changes = [Change(days[k], float(means[k - 1]), float(means[k])) for k in starts]
    drift, rise = False, 0.0
    bounds = [0, *starts, len(days)]
    for a, b in itertools.pairwise(bounds):
        if b - a < MIN_DAYS:
            continue
        coef = np.polyfit(x[a:b], means[a:b], 1)
        first, last = np.polyval(coef, [x[a], x[b - 1]])
        stretch_rise = float((last - first) / first) if first else 0.0
        rise = max(rise, stretch_rise)
        if last - first > DRIFT_SIGMAS * spread and stretch_rise > min_rise:
            drift = True
    return Trend(list(days), means.tolist(), spread, changes, drift, rise)
