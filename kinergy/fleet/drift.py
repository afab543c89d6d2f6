"""Drift and step changes in a robot's energy or friction per cycle, day after day.

For one robot running one program, a figure per cycle (energy, or the motor work that friction
takes) is summarised per day. Two things can move it:

- a **step change**: a new payload, a new gripper, a changed program speed -- the level jumps
  from one day to the next and stays. It is found by binary segmentation: for every split day
  ``k`` a line with a step is fitted (each side its own line when both have
  :data:`SLOPE_DAYS` days, else one shared slope), and its jump ``J`` is read half-way between
  the two days, so a steady trend gives ``J`` near 0; the split with the largest ``|J|`` over
  its standard error is a change when that ratio is more than :data:`STEP_SIGMAS` spreads; the
  parts are searched again (at most :data:`MAX_CHANGES` changes).
- **drift**: the level creeps up day after day inside one stretch between changes (a wearing
  gearbox). A line is fitted over at least :data:`MIN_DAYS` days; the stretch drifts when its
  rise from the first to the last day is more than :data:`DRIFT_SIGMAS` spreads *and* more than
  ``min_rise`` (5 %) of its first level -- unless two levels fit the stretch better than the
  line does: then it is a step too small for the test above, and reported as a change.

The spread is the figure's own: the larger of the scatter of the cycles within a day (pooled)
and of the days about the best line with a step (its residual standard deviation), with a floor
of 0.2 % of the level. On seven days with 0.4 % day-to-day scatter (tests/test_fleet.py) this
calls pure noise a change about once in 300 series and never drift, and finds every 5 % step.
"""

from __future__ import annotations

import datetime as dt
import itertools
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from kinergy.arrays import Array

__all__ = [
    "DRIFT_SIGMAS",
    "MAX_CHANGES",
    "MIN_DAYS",
    "SLOPE_DAYS",
    "STEP_SIGMAS",
    "Change",
    "Trend",
    "trend",
]


STEP_SIGMAS = 6.0
DRIFT_SIGMAS = 4.0
MIN_DAYS = 3
MAX_CHANGES = 3
#: days each side of a step needs for a slope of its own
SLOPE_DAYS = 4


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


def _step_fit(x: Array, y: Array, k: int) -> tuple[float, float, float]:
    """A step between days ``k - 1`` and ``k``: its jump, the jump's standard error per unit
    spread and the fit's own spread (residual standard deviation).

    Each side is its own line when both have :data:`SLOPE_DAYS` days, else one slope is shared
    (a level for :data:`MIN_DAYS` days or fewer in all); the jump is read half-way between the
    two days, so a steady trend gives a jump near 0 and a ramp is not mistaken for steps.
    """
    left = np.arange(x.size) < k
    centre = x - 0.5 * (x[k - 1] + x[k])
    columns = [np.ones_like(x), (~left).astype(float)]
    if min(k, x.size - k) >= SLOPE_DAYS:
        columns += [centre * left, centre * ~left]
    elif x.size > MIN_DAYS:
        columns.append(centre)
    design = np.column_stack(columns)
    coef = np.linalg.lstsq(design, y, rcond=None)[0]
    dof = x.size - design.shape[1]
    own = float(np.sqrt(np.sum((y - design @ coef) ** 2) / dof)) if dof > 0 else 0.0
    return float(coef[1]), float(np.sqrt(np.linalg.pinv(design.T @ design)[1, 1])), own


def _best_step(x: Array, y: Array) -> tuple[int, float, float, float] | None:
    """The most significant step (the day it starts and :func:`_step_fit`'s figures); None for
    fewer than two days."""
    fits = [(k, *_step_fit(x, y, k)) for k in range(1, y.size)]
    return max(fits, key=lambda fit: abs(fit[1]) / fit[2]) if fits else None


def _spread(groups: Sequence[Array], x: Array, means: Array) -> float:
    within = [g - g.mean() for g in groups if g.size > 1]
    dof = sum(g.size - 1 for g in groups)
    pooled = float(np.sqrt(sum(float(np.sum(w**2)) for w in within) / dof)) if dof else 0.0
    step = _best_step(x, means) if means.size > MIN_DAYS + 1 else None
    daily = 0.0 if step is None else step[3]  # the days about the best line with a step
    return max(pooled, daily, 0.002 * float(np.mean(np.abs(means))))


def _steps(x: Array, y: Array, spread: float, offset: int = 0) -> list[int]:
    """Indices where a new level starts (binary segmentation)."""
    step = _best_step(x, y)
    if step is None or abs(step[1]) <= STEP_SIGMAS * spread * step[2]:
        return []
    k = step[0]
    left = _steps(x[:k], y[:k], spread, offset)
    right = _steps(x[k:], y[k:], spread, offset + k)
    return sorted([*left, offset + k, *right])[:MAX_CHANGES]


def _rise(x: Array, y: Array) -> tuple[float, float]:
    """Rise of the line through ``y`` from its first to its last day: absolute, relative."""
    first, last = np.polyval(np.polyfit(x, y, 1), [x[0], x[-1]])
    return float(last - first), float((last - first) / first) if first else 0.0


def _drifts(x: Array, y: Array, spread: float, min_rise: float) -> bool:
    """Whether a stretch of days drifts (see the module docstring)."""
    if y.size < MIN_DAYS:
        return False
    rise, relative = _rise(x, y)
    return rise > DRIFT_SIGMAS * spread and relative > min_rise


def _two_levels(x: Array, y: Array) -> int | None:
    """Where two levels fit ``y`` better than a line does (a step a line would read as a rise)."""
    line = float(np.sum((y - np.polyval(np.polyfit(x, y, 1), x)) ** 2))
    sse = [float(np.sum((y[:k] - y[:k].mean()) ** 2) + np.sum((y[k:] - y[k:].mean()) ** 2))
           for k in range(1, y.size)]  # fmt: skip
    k = int(np.argmin(sse))
    return k + 1 if sse[k] < line else None


def _with_level_steps(
    x: Array, y: Array, spread: float, min_rise: float, starts: list[int]
) -> list[int]:
    """``starts`` and the day of every stretch that would drift but is two levels, not a line."""
    found = list(starts)
    for a, b in itertools.pairwise([0, *starts, y.size]):
        k = _two_levels(x[a:b], y[a:b]) if _drifts(x[a:b], y[a:b], spread, min_rise) else None
        found += [] if k is None else [a + k]
    return sorted(found)[:MAX_CHANGES]


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
    starts = _with_level_steps(x, means, spread, min_rise, _steps(x, means, spread))
    changes = [Change(days[k], float(means[k - 1]), float(means[k])) for k in starts]
    stretches = [(x[a:b], means[a:b]) for a, b in itertools.pairwise([0, *starts, len(days)])]
    long = [(sx, sy) for sx, sy in stretches if sy.size >= MIN_DAYS]
    drift = any(_drifts(sx, sy, spread, min_rise) for sx, sy in long)
    rise = max([0.0, *(_rise(sx, sy)[1] for sx, sy in long)])
    return Trend(list(days), means.tolist(), spread, changes, drift, rise)
