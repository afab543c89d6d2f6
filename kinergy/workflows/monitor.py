"""``kinergy monitor``: energy per program cycle from a live controller, measured and predicted."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from kinergy.live.monitor import MONITOR_FIELDS, CycleEnergy, CycleTracker, rows_log
from kinergy.live.rtde import parse_address
from kinergy.live.stream import Gap, Stream, StreamOptions, stop_on_signals
from kinergy.logs.checks import LogCheck
from kinergy.logs.reading import LogReading
from kinergy.model.robot import Robot

__all__ = ["MonitorRun", "monitor_cycles"]


@dataclass(frozen=True, eq=False)
class MonitorRun:
    """What ``kinergy monitor`` followed: the program's period and every cycle, measured (where
    the controller logs its supply) and predicted. :meth:`to_dict` is the command's ``--json``
    (without where the command came from)."""

    robot: Robot
    period: float | None
    supply_logged: bool
    cycles: tuple[CycleEnergy, ...]

    def to_dict(self) -> dict[str, Any]:
        return {
            "robot": self.robot.name,
            "period": self.period,
            "supply_logged": self.supply_logged,
            "cycles": [{**vars(c), "error": c.error} for c in self.cycles],
        }


def monitor_cycles(
    address: str,
    robot: Robot,
    options: StreamOptions | None = None,
    *,
    reading: LogReading | None = None,
    on_cycle: Callable[[CycleEnergy], None] | None = None,
    status: Callable[[str], None] | None = None,
    waiting: Callable[[float, int, float | None], None] | None = None,
) -> MonitorRun:
    """Follow the controller at ``address`` (``HOST[:PORT]``) until ``duration`` s of
    controller time, SIGINT or SIGTERM; ``on_cycle`` receives each cycle as it ends.

    The stream is folded into the plausibility checks (:mod:`kinergy.logs.checks`) as it comes;
    before the first cycle is reported their verdict is taken on what has been seen (a check
    that fails, unless in ``reading.accept``, stops the monitor with its line), and again at the
    end.

    Until the first cycle ends, ``waiting(seconds, samples, period)`` is told once a second
    (wall clock) how much of the stream has come (controller time, s; samples) and the period
    found so far (s; None before it is).

    Returns the period and the cycles.
    """
    options = options or StreamOptions()
    frequency, duration = options.frequency, options.duration
    accept = (reading or LogReading()).accept
    host, port = parse_address(address)
    stop = threading.Event()
    with stop_on_signals(stop):
        stream = Stream(
            host, port, MONITOR_FIELDS, frequency, optional=MONITOR_FIELDS[2:], status=status
        )
        names = stream.recipe.names
        tracker = CycleTracker(robot, names)
        if status is not None and not tracker.supply:
            status("the controller does not log its supply: predicted energy only")
        check = LogCheck(robot, address, accept)
        pending: list[Sequence[float]] = []
        judged = False
        first: float | None = None
        last, samples = 0.0, 0
        updated = told = time.monotonic()

        def report(cycles: list[CycleEnergy]) -> None:
            nonlocal judged, pending
            if pending:
                check.add(rows_log(address, names, pending, robot.n))
                pending = []
            if cycles and not judged:
                check.finish()  # raises when the stream is not this robot's, in these units
                judged = True
            for cycle in cycles:
                if on_cycle is not None:
                    on_cycle(cycle)

        try:
            while not stop.is_set():
                item = stream.get(timeout=0.1)
                if isinstance(item, Gap):
                    tracker.gap()
                elif item is not None:
                    first = float(item[0]) if first is None else first
                    if duration is not None and item[0] - first > duration:
                        break
                    tracker.add(item)
                    pending.append(item)
                    last, samples = float(item[0]) - first, samples + 1
                if time.monotonic() - updated >= 0.25 or item is None:
                    report(tracker.update())
                    updated = time.monotonic()
                if waiting is not None and not judged and updated - told >= 1.0:
                    waiting(last, samples, tracker.period)
                    told = updated
        finally:
            stream.close()
    report(tracker.update())
    return MonitorRun(robot, tracker.period, tracker.supply, tuple(tracker.cycles))
