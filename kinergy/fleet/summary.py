"""A fleet's figures by robot and by day, with each robot's drift flag, from the per-log results.

Energies are supply side, J: measured (``actual_robot_voltage * actual_robot_current``) where
every cycle of the robot has it, else the model's prediction (joints' electrical power on the
bus plus standby); both are given where both exist. Drift (:mod:`kinergy.fleet.drift`) is judged
per robot and program (same fingerprint) on two figures per whole cycle: the energy (measured,
else predicted) and the motor work that friction takes (from the currents).
"""

from __future__ import annotations

import datetime as dt
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from kinergy.fleet.analysis import PARTS, CycleRecord, LogResult
from kinergy.fleet.drift import Trend, trend
from kinergy.fleet.manifest import FleetLog
from kinergy.jsonable import to_jsonable

__all__ = [
    "ChangeNote",
    "DaySummary",
    "FleetResult",
    "ProgramTrend",
    "RobotSummary",
    "programs_of",
    "summarise",
]

_DATE = {"json": str}
_DATES = {"json": lambda days: [str(d) for d in days]}


@dataclass(frozen=True)
class DaySummary:
    """One robot's day: logs, cycles and energy (J); per-cycle means over whole cycles."""

    date: dt.date = field(metadata=_DATE)
    logs: int = 0
    cycles: int = 0
    energy_J: float = 0.0
    measured_J: float | None = None
    predicted_J: float = 0.0
    energy_per_cycle_J: float | None = None
    predicted_per_cycle_J: float | None = None
    motor_work_per_cycle_J: float | None = None


@dataclass(frozen=True)
class ChangeNote:
    """A step change of a figure (not drift): a new payload, tool or program speed."""

    metric: str
    program: str
    date: dt.date = field(metadata=_DATE)
    before: float = 0.0
    after: float = 0.0
    relative: float = 0.0


@dataclass(frozen=True)
class ProgramTrend:
    """One program of a robot: its period and the trends of its two figures."""

    program: str
    period: float | None
    cycles: int
    days: list[dt.date] = field(metadata=_DATES)
    energy: list[float] = field(default_factory=list)
    motor_work: list[float] | None = None
    energy_drift: bool = False
    friction_drift: bool = False
    energy_rise: float = 0.0
    friction_rise: float = 0.0


@dataclass(frozen=True)
class RobotSummary:
    """One robot over all its logs."""

    name: str
    model: str
    logs: int
    cycles: int
    energy_J: float
    measured_J: float | None
    predicted_J: float
    breakdown_J: dict[str, float]
    drift: bool
    changes: list[ChangeNote]
    programs: list[ProgramTrend]
    days: list[DaySummary]


@dataclass(frozen=True)
class FleetResult:
    """The fleet: robots, logs analysed and skipped, workers, wall time."""

    robots: list[RobotSummary]
    logs: int
    skipped: list[dict[str, str]]
    workers: int
    seconds: float
    peak_rss_MB: float
    cycles_table: list[dict[str, object]] = field(default_factory=list, metadata={"json": False})

    def to_dict(self) -> dict[str, Any]:
        """``kinergy fleet energy --json`` (without where the command came from)."""
        out: dict[str, Any] = to_jsonable(self)
        return out


def _sum(values: Sequence[float | None]) -> float | None:
    return (
        None if any(v is None for v in values) else float(sum(v for v in values if v is not None))
    )


def _day(date: dt.date, logs: list[LogResult]) -> DaySummary:
    cycles = [c for r in logs for c in r.cycles]
    whole = [c for c in cycles if c.cycle >= 0]
    measured = _sum([c.measured for c in cycles])
    predicted = float(sum(c.predicted for c in cycles))
    work = [c.motor_work for c in whole]
    per = [c.measured if c.measured is not None else c.predicted for c in whole]
    return DaySummary(
        date=date,
        logs=len(logs),
        cycles=len(whole),
        energy_J=predicted if measured is None else measured,
        measured_J=measured,
        predicted_J=predicted,
        energy_per_cycle_J=float(np.mean(per)) if per else None,
        predicted_per_cycle_J=_mean([c.predicted for c in whole]),
        motor_work_per_cycle_J=_mean(work),
    )


def _mean(values: Sequence[float | None]) -> float | None:
    if not values or any(v is None for v in values):
        return None
    return float(np.mean([v for v in values if v is not None]))


def _program_trend(
    name: str, logs: list[LogResult], min_rise: float
) -> tuple[ProgramTrend, list[ChangeNote]]:
    by_day: dict[dt.date, list[CycleRecord]] = defaultdict(list)
    for r in logs:
        by_day[r.date] += [c for c in r.cycles if c.cycle >= 0]
    days = sorted(d for d, cs in by_day.items() if cs)
    energy = [
        [c.measured if c.measured is not None else c.predicted for c in by_day[d]] for d in days
    ]
    work_known = all(c.motor_work is not None for d in days for c in by_day[d])
    work = [[float(c.motor_work or 0.0) for c in by_day[d]] for d in days]
    trends: dict[str, Trend | None] = {
        "energy": trend(days, energy, min_rise=min_rise) if days else None,
        "motor_work": trend(days, work, min_rise=min_rise) if days and work_known else None,
    }
    notes = [
        ChangeNote(metric, name, c.date, c.before, c.after, c.relative)
        for metric, tr in trends.items()
        if tr is not None
        for c in tr.changes
    ]
    e, w = trends["energy"], trends["motor_work"]
    return (
        ProgramTrend(
            program=name,
            period=logs[0].period,
            cycles=sum(len(cs) for cs in by_day.values()),
            days=days,
            energy=[] if e is None else e.means,
            motor_work=None if w is None else w.means,
            energy_drift=bool(e and e.drift),
            friction_drift=bool(w and w.drift),
            energy_rise=0.0 if e is None else e.rise,
            friction_rise=0.0 if w is None else w.rise,
        ),
        notes,
    )


def programs_of(logs: Sequence[LogResult]) -> dict[str, str]:
    """Log path -> program label (``P1``, ``P2``... in order of first appearance) for one robot's
    logs: the same program when the period agrees within 1 % and every joint's range within
    0.1 rad. Logs without a repeating program get none."""
    seen: list[tuple[str, float, np.ndarray]] = []
    labels = {}
    for r in logs:
        if r.period is None:
            continue
        ranges = np.asarray(r.ranges)
        label = next(
            (
                name
                for name, period, known in seen
                if abs(r.period - period) <= 0.01 * period and np.max(np.abs(ranges - known)) <= 0.1
            ),
            None,
        )
        if label is None:
            label = f"P{len(seen) + 1}"
            seen.append((label, r.period, ranges))
        labels[r.path] = label
    return labels


def _robot(name: str, model: str, logs: list[LogResult], min_rise: float) -> RobotSummary:
    cycles = [c for r in logs for c in r.cycles]
    programs, changes = [], []
    by_program: dict[str, list[LogResult]] = defaultdict(list)
    for path, label in programs_of(logs).items():
        by_program[label].append(next(r for r in logs if r.path == path))
    for key in sorted(by_program):
        program, notes = _program_trend(key, by_program[key], min_rise)
        programs.append(program)
        changes += notes
    by_day: dict[dt.date, list[LogResult]] = defaultdict(list)
    for r in logs:
        by_day[r.date].append(r)
    measured = _sum([c.measured for c in cycles])
    predicted = float(sum(c.predicted for c in cycles))
    return RobotSummary(
        name=name,
        model=model,
        logs=len(logs),
        cycles=sum(1 for c in cycles if c.cycle >= 0),
        energy_J=predicted if measured is None else measured,
        measured_J=measured,
        predicted_J=predicted,
        breakdown_J={
            k: float(sum(getattr(c, k) for c in cycles)) for k in (*PARTS, "standby", "shunt")
        },
        drift=any(p.energy_drift or p.friction_drift for p in programs),
        changes=sorted(changes, key=lambda c: (c.date, c.metric)),
        programs=programs,
        days=[_day(d, by_day[d]) for d in sorted(by_day)],
    )


def cycles_table(results: Sequence[LogResult]) -> list[dict[str, object]]:
    """One row per cycle (the Parquet table): robot, log, date, program and the cycle's figures."""
    labels: dict[str, str] = {}
    for name in {r.robot for r in results}:
        labels.update(programs_of([r for r in results if r.robot == name]))
    rows = []
    for r in results:
        for c in r.cycles:
            program = labels.get(r.path, "")
            rows.append(
                {"robot": r.robot, "log": r.path, "date": r.date, "program": program, **vars(c)}
            )
    return rows


def summarise(
    logs: Sequence[FleetLog],
    results: Sequence[LogResult],
    *,
    workers: int,
    seconds: float,
    min_rise: float = 0.05,
) -> FleetResult:
    """The fleet's figures from its logs' results (in any order)."""
    good = [r for r in results if r.error is None]
    models = {item.robot: item.model for item in logs}
    robots = []
    for name in sorted(models):
        mine = sorted((r for r in good if r.robot == name), key=lambda r: (r.date, r.path))
        robots.append(_robot(name, models[name], mine, min_rise))
    peaks: dict[int, float] = {}
    for r in results:
        peaks[r.worker] = max(peaks.get(r.worker, 0.0), r.peak_rss)
    return FleetResult(
        robots=robots,
        logs=len(good),
        skipped=[{"log": r.path, "error": r.error} for r in results if r.error is not None],
        workers=workers,
        seconds=seconds,
        peak_rss_MB=max(peaks.values(), default=0.0),
        cycles_table=cycles_table(good),
    )
