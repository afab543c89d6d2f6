"""Energy per program cycle, live: measured on the supply against the model's prediction.

A robot in production repeats one program. :class:`CycleTracker` takes the stream's samples
as they come and

1. finds the program's period from the commanded joint angles (``target_q``) by the
   autocorrelation search of :func:`kinergy.identification.cycles.find_period`, once two periods
   have been seen;
2. cuts the stream into cycles one period long, each boundary re-aligned to the pose at the
   first cycle's start (the best match of a short window of ``target_q`` within a tenth of a
   period of where it is expected), so cycles do not drift by a fraction of a sample each;
3. for each cycle, integrates the measured supply power ``actual_robot_voltage *
   actual_robot_current`` (when the controller logs them) and predicts the energy the model
   draws for the cycle's commanded motion: the joints' electrical power (UR5e eq 23) shared on
   the DC bus, braking surplus burnt in the shunt, plus standby (``supply.drawn`` of
   :func:`kinergy.accounting.energy.energy`).

A gap in the stream (a reconnection) drops the cycle in progress; the next cycle starts at the
first re-aligned boundary after it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import trapezoid

from kinergy.accounting.energy import energy
from kinergy.arrays import Array
from kinergy.identification.cycles import find_period
from kinergy.io.log import Log
from kinergy.model.robot import Robot
from kinergy.trajectory.motion import Motion

__all__ = ["MONITOR_FIELDS", "CycleEnergy", "CycleTracker", "rows_log"]


def rows_log(path: str, names: Sequence[str], rows: Sequence[Sequence[float]], n: int) -> Log:
    """Stream packages (flat values in the recipe's order of ``names``) as a :class:`Log`: the
    supply's two values scalars, every other field one value per joint (``n``)."""
    values = np.asarray(rows, dtype=float)
    signals: dict[str, Array] = {}
    k = 1
    for name in names[1:]:
        width = 1 if name in ("actual_robot_voltage", "actual_robot_current") else n
        block = values[:, k : k + width]
        signals[name] = block[:, 0] if width == 1 else block
        k += width
    return Log(path, values[:, 0], signals)


#: what the monitor subscribes to (from the third on, where the controller has them; the
#: measured motion and the reference torques and currents let the plausibility checks compare
#: the stream with the model, :mod:`kinergy.logs.checks`)
MONITOR_FIELDS = (
    "timestamp",
    "target_q",
    "target_qd",
    "target_qdd",
    "actual_robot_voltage",
    "actual_robot_current",
    "actual_q",
    "actual_qd",
    "target_moment",
    "actual_current",
)


@dataclass(frozen=True)
class CycleEnergy:
    """One program cycle.

    Attributes
    ----------
    index : int
        1, 2, ... in the order the cycles ended.
    start : float
        Controller time at the cycle's start, s.
    duration : float
        s.
    measured : float or None
        Supply energy ``int V I dt``, J; None when the supply is not logged.
    predicted : float
        The model's supply energy of the commanded motion (bus model plus standby), J.
    """

    index: int
    start: float
    duration: float
    measured: float | None
    predicted: float

    @property
    def error(self) -> float | None:
        """``(predicted - measured) / measured``; None without a measurement."""
        if self.measured is None or self.measured == 0.0:
            return None
        return (self.predicted - self.measured) / self.measured


@dataclass
class _Buffer:
    """Samples not yet assigned to a finished cycle."""

    t: list[float] = field(default_factory=list)
    rows: list[Sequence[float]] = field(default_factory=list)

    def arrays(self) -> tuple[Array, Array]:
        return np.asarray(self.t, dtype=float), np.asarray(self.rows, dtype=float)

    def drop_before(self, k: int) -> None:
        del self.t[:k]
        del self.rows[:k]


class CycleTracker:
    """Cycles and their energies from a stream of samples (see the module docstring).

    Parameters
    ----------
    robot : Robot
        The model predicting each cycle's energy.
    names : sequence of str
        The stream's variables, as in its recipe (:data:`MONITOR_FIELDS`, some perhaps left
        out); ``timestamp`` and ``target_q`` are needed.
    min_period, longest : float
        Shortest period looked for, and the longest stretch of samples kept while looking (the
        longest period found is half of it), s.
    """

    def __init__(
        self,
        robot: Robot,
        names: Sequence[str],
        *,
        min_period: float = 0.5,
        longest: float = 600.0,
    ) -> None:
        self.robot = robot
        self.min_period = min_period
        self.longest = longest
        widths = {"timestamp": 1, "actual_robot_voltage": 1, "actual_robot_current": 1}
        self._slices: dict[str, slice] = {}
        k = 0
        for name in names:
            w = widths.get(name, robot.n)
            self._slices[name] = slice(k, k + w)
            k += w
        self.supply = "actual_robot_voltage" in names and "actual_robot_current" in names
        self.period: float | None = None
        self.cycles: list[CycleEnergy] = []
        self._buffer = _Buffer()
        self._reference: Array | None = None  # target_q over a short window at a cycle start
        self._aligned = False
        self._next_search = 0.0

    def add(self, values: Sequence[float]) -> None:
        """One package's values (flat, in the recipe's order)."""
        self._buffer.t.append(float(values[0]))
        self._buffer.rows.append(values)

    def gap(self) -> None:
        """The stream broke: the cycle in progress is dropped, the next one re-aligned."""
        self._buffer = _Buffer()
        self._aligned = False

    def update(self) -> list[CycleEnergy]:
        """Find the period if not yet known and close every cycle the samples now cover;
        return the new cycles."""
        t, rows = self._buffer.arrays()
        if t.size < 4:
            return []
        if self.period is None and not self._find_period(t, rows):
            return []
        assert self.period is not None
        dt = float(np.median(np.diff(t)))
        k_period = round(self.period / dt)
        window = self._window(k_period)
        q = rows[:, self._slices["target_q"]]
        if not self._aligned:
            start = self._align(q, 0, k_period, window)
            if start is None:
                return []
            self._buffer.drop_before(start)
            self._aligned = True
            return self.update()
        new = []
        while True:
            end = self._align(q, k_period - k_period // 10, k_period + k_period // 10, window)
            if end is None:
                break
            cycle = self._cycle(t[: end + 1], rows[: end + 1])
            self.cycles.append(cycle)
            new.append(cycle)
            self._buffer.drop_before(end)
            t, rows = self._buffer.arrays()
            q = rows[:, self._slices["target_q"]]
        return new

    def _find_period(self, t: Array, rows: Array) -> bool:
        if t[-1] - t[0] < max(2.0 * self.min_period, self._next_search):
            return False
        if t[-1] - t[0] > self.longest:  # no repeat in this long: keep looking in the latest
            self._buffer.drop_before(int(np.searchsorted(t, t[-1] - self.longest / 2)))
            self._next_search = 0.0
            return False
        self._next_search = t[-1] - t[0] + 1.0  # search again after another second of data
        period = find_period(t, rows[:, self._slices["target_q"]], min_period=self.min_period)
        if period is None:
            return False
        self.period = period
        return True

    def _window(self, k_period: int) -> int:
        return max(2, min(k_period // 4, 125))

    def _align(self, q: Array, lo: int, hi: int, window: int) -> int | None:
        """The sample in ``lo..hi`` where the reference window matches best (None: not enough
        samples yet); the first call stores the reference."""
        if self._reference is None:
            if q.shape[0] < window:
                return None
            self._reference = q[:window].copy()
            return 0
        if q.shape[0] < hi + window:
            return None
        expected = (lo + hi) / 2
        candidates = np.arange(lo, hi + 1)
        mismatch = np.array(
            [np.sum((q[j : j + window] - self._reference) ** 2) for j in candidates]
        )
        scale = float(np.max(mismatch)) or 1.0
        penalty = 1e-6 * scale * ((candidates - expected) / max(hi - lo, 1)) ** 2
        return int(candidates[int(np.argmin(mismatch + penalty))])

    def _cycle(self, t: Array, rows: Array) -> CycleEnergy:
        """The energies of one cycle's samples (both ends included)."""
        s = self._slices
        q = rows[:, s["target_q"]]
        qd = rows[:, s["target_qd"]] if "target_qd" in s else np.gradient(q, t, axis=0)
        qdd = rows[:, s["target_qdd"]] if "target_qdd" in s else np.gradient(qd, t, axis=0)
        report = energy(self.robot, Motion(t - t[0], q, qd, qdd))
        measured = None
        if self.supply:
            volts = rows[:, s["actual_robot_voltage"]][:, 0]
            amps = rows[:, s["actual_robot_current"]][:, 0]
            measured = float(trapezoid(volts * amps, t))
        return CycleEnergy(
            index=len(self.cycles) + 1,
            start=float(t[0]),
            duration=float(t[-1] - t[0]),
            measured=measured,
            predicted=report.supply.drawn,
        )
