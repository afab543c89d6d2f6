"""``kinergy monitor``: energy per program cycle from a live controller, measured and predicted."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from kinergy.errors import KinergyError
from kinergy.live.monitor import MONITOR_FIELDS, CycleEnergy, CycleTracker
from kinergy.live.rtde import parse_address
from kinergy.live.stream import Gap, Stream, stop_on_signals
from kinergy.model.robot import Robot

__all__ = ["monitor_cycles"]


def monitor_cycles(
    address: str,
    robot: Robot,
    *,
    frequency: float = 500.0,
    duration: float | None = None,
    on_cycle: Callable[[CycleEnergy], None] | None = None,
    status: Callable[[str], None] | None = None,
) -> CycleTracker:
    """Follow the controller at ``address`` (``HOST[:PORT]``) until ``duration`` s of
    controller time, SIGINT or SIGTERM; ``on_cycle`` receives each cycle as it ends.

    Returns the tracker (its ``period`` and ``cycles``).
    """
    host, port = parse_address(address)
    if duration is not None and not duration > 0:
        raise KinergyError(f"--duration must be > 0, got {duration:g}")
    stop = threading.Event()
    with stop_on_signals(stop):
        stream = Stream(
            host, port, MONITOR_FIELDS, frequency, optional=MONITOR_FIELDS[2:], status=status
        )
        tracker = CycleTracker(robot, stream.recipe.names)
        if status is not None and not tracker.supply:
            status("the controller does not log its supply: predicted energy only")
        first: float | None = None
        updated = time.monotonic()
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
                if time.monotonic() - updated >= 0.25 or item is None:
                    for cycle in tracker.update():
                        if on_cycle is not None:
                            on_cycle(cycle)
                    updated = time.monotonic()
        finally:
            stream.close()
    for cycle in tracker.update():
        if on_cycle is not None:
            on_cycle(cycle)
    return tracker
