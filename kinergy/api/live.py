"""The commands that follow controllers and fleets, as functions: ``record``, ``monitor``,
``fleet_energy``."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from kinergy.api.common import PathLike, Progress, RobotLike, robot_of
from kinergy.fleet.analysis import LogResult
from kinergy.fleet.summary import FleetResult
from kinergy.live.monitor import CycleEnergy
from kinergy.live.recorder import Recording
from kinergy.live.stream import RecordOptions, StreamOptions
from kinergy.logs.reading import LogReading
from kinergy.workflows.fleet import FleetOptions
from kinergy.workflows.fleet import fleet_energy as run_fleet
from kinergy.workflows.monitor import MonitorRun, monitor_cycles
from kinergy.workflows.record import record_to_file

__all__ = ["fleet_energy", "monitor", "record"]


def record(
    address: str,
    out: PathLike,
    options: RecordOptions | None = None,
    *,
    status: Progress | None = None,
) -> Recording:
    """``kinergy record``: every field kinergy uses from the UR controller at ``address``
    (``HOST[:PORT]``, RTDE) into ``out`` (record.py layout, with a ``segment`` column counting
    reconnections) until ``options.duration``, Ctrl-C or SIGTERM; ``status`` is told of
    connections and gaps."""
    return record_to_file(address, out, options, status=status)


def monitor(
    address: str,
    robot: RobotLike,
    options: StreamOptions | None = None,
    *,
    reading: LogReading | None = None,
    on_cycle: Callable[[CycleEnergy], None] | None = None,
    status: Progress | None = None,
    waiting: Callable[[float, int, float | None], None] | None = None,
) -> MonitorRun:
    """``kinergy monitor``: the energy of every program cycle of the controller at ``address``,
    its supply's (where logged) beside ``robot``'s prediction, until ``options.duration``,
    Ctrl-C or SIGTERM; ``on_cycle`` receives each cycle as it ends. The stream passes the
    plausibility checks but those ``reading.accept`` names. Until the first cycle ends,
    ``waiting(seconds, samples, period)`` is told once a second how much has come (controller
    time, s; samples; the period found so far, s, or None)."""
    return monitor_cycles(
        address,
        robot_of(robot),
        options,
        reading=reading,
        on_cycle=on_cycle,
        status=status,
        waiting=waiting,
    )


def fleet_energy(
    logs: Sequence[PathLike],
    manifest: PathLike,
    out: PathLike,
    options: FleetOptions | None = None,
    *,
    reading: LogReading | None = None,
    report: PathLike | None = None,
    progress: Callable[[int, int, LogResult], None] | None = None,
) -> FleetResult:
    """``kinergy fleet energy``: every log's energy per cycle (``logs`` and the manifest's
    globs) on Dask, by robot and by day, with each robot's drift; the cycles written to ``out``
    (Parquet) and, with ``report``, the HTML report into that folder. ``reading``: the ROS 2 bag
    options (a robot entry's own win) and the checks accepted. ``progress(done, total, log)``
    is called as each log is analysed. Needs the fleet extra."""
    return run_fleet(
        logs, manifest, out, options, reading=reading, report=report, progress=progress
    )
