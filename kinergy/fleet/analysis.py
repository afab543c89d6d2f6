"""One log of a fleet: its energy per program cycle, measured and predicted, and where it goes.

:func:`analyse_log` runs on a Dask worker and holds one log at a time; it returns small typed
figures, never the log's arrays. For each segment of the log (:mod:`kinergy.io.segments`):

1. the program's period from the commanded joint angles (:func:`kinergy.identification.cycles.find_period`);
   a segment with no repeat is one row covering it;
2. the model over the logged motion (:func:`kinergy.accounting.energy.energy`): the joints'
   electrical power (UR5e eq 23) split into inertial, gravity, friction and copper parts
   (framework Fig. 4), plus standby; on the DC bus the joints share power and a braking surplus
   is burnt in the shunt (:func:`kinergy.drives.bus.supply_power`): the predicted supply power
   is the parts plus that shunt power;
3. the measured supply power ``actual_robot_voltage * actual_robot_current``, when logged;
4. the measured motor work ``sum_j k_t,j I_j wm_j`` from ``actual_current`` and ``actual_qd``
   (UR5e eqs 17, 25): over a whole cycle the load's work nets to zero (the arm ends where it
   started, gravity is conservative), so this is what friction took -- the drift metric that a
   new payload leaves almost unchanged;
5. each quantity integrated over every whole cycle (cumulative trapezoid, read at the cycle
   boundaries).
"""

from __future__ import annotations

import datetime as dt
import functools
import os
import resource
import sys
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import cumulative_trapezoid

from kinergy.accounting.energy import energy
from kinergy.arrays import Array
from kinergy.drives.bus import supply_power
from kinergy.drives.electrics import torque_constants
from kinergy.drives.transmission import transmission_matrix
from kinergy.dynamics.threads import kernel_threads
from kinergy.errors import KinergyError
from kinergy.fleet.manifest import FleetLog
from kinergy.identification.cycles import find_period
from kinergy.io.log import Log
from kinergy.io.motion import motion_from_log
from kinergy.io.segments import split_segments
from kinergy.logs.payload import logged_loads
from kinergy.logs.reading import CheckedLog, LogReading
from kinergy.model.library import load_robot
from kinergy.model.robot import Robot
from kinergy.predict import drive_by_payload

__all__ = ["CycleRecord", "LogResult", "analyse_log"]


PARTS = ("inertial", "gravity", "friction", "copper")


@dataclass(frozen=True)
class CycleRecord:
    """One program cycle of a log (or a whole segment when no cycle was found).

    Energies in J, over the cycle. ``measured`` and ``motor_work`` are None when the log lacks
    the signals. ``cycle`` is -1 for a segment without a repeating program.
    """

    segment: int
    cycle: int
    start: float
    duration: float
    measured: float | None
    predicted: float
    inertial: float
    gravity: float
    friction: float
    copper: float
    standby: float
    shunt: float
    motor_work: float | None


@dataclass(frozen=True)
class LogResult:
    """What a worker found in one log.

    Attributes
    ----------
    robot, path : str
    date : datetime.date
    period : float or None
        The repeating program's period, s (None: no repeat found).
    ranges : list of float
        Each joint's lowest then highest commanded angle, rad (2n values): with the period,
        what tells programs apart.
    samples : int
    cycles : list of CycleRecord
    error : str or None
        Why the log could not be analysed (then there are no cycles).
    seconds : float
        Wall time the worker took.
    worker : int
        The worker's process id.
    peak_rss : float
        The worker process's peak resident memory so far, MB.
    """

    robot: str
    path: str
    date: dt.date
    period: float | None = None
    ranges: list[float] = field(default_factory=list)
    samples: int = 0
    cycles: list[CycleRecord] = field(default_factory=list)
    error: str | None = None
    seconds: float = 0.0
    worker: int = 0
    peak_rss: float = 0.0


@functools.lru_cache(maxsize=16)
def _robot(model: str) -> Robot:
    return load_robot(model)


def _powers(robot: Robot, part: Log) -> dict[str, Array | None]:
    """Power over time of every figure a cycle row holds (W, shape (N,))."""
    motion = motion_from_log(part, n_joints=robot.n)
    loads = logged_loads(part)  # the payload the controller logged, sample by sample
    state = (
        None if loads is None else drive_by_payload(robot, *loads, motion.q, motion.qd, motion.qdd)
    )
    report = energy(robot, motion, state=state)
    bus = supply_power(report.p_elec, robot.standby_power)
    powers: dict[str, Array | None] = {
        "predicted": bus.supply,
        **{k: report.part_power[k].sum(axis=1) for k in PARTS},
        "standby": np.full(len(part), robot.standby_power),
        "shunt": bus.shunt,
        "measured": None,
        "motor_work": None,
    }
    if "actual_robot_voltage" in part and "actual_robot_current" in part:
        powers["measured"] = part["actual_robot_voltage"] * part["actual_robot_current"]
    if "actual_current" in part and "actual_qd" in part:
        wm = part["actual_qd"] @ transmission_matrix(robot).T
        powers["motor_work"] = np.sum(part["actual_current"] * torque_constants(robot) * wm, axis=1)
    return powers


def _segment_cycles(
    robot: Robot, part: Log, segment: int
) -> tuple[list[CycleRecord], float | None, list[float]]:
    """The cycle rows of one segment, its period and joint ranges."""
    t = part.t
    q = part["target_q"] if "target_q" in part else part["actual_q"]
    period = find_period(t, q, min_period=0.5) if len(part) >= 8 else None
    if period is None:
        bounds = np.array([t[0], t[-1]])
    else:
        bounds = t[0] + period * np.arange(int((t[-1] - t[0]) / period + 1e-9) + 1)
    integrals = {}
    for name, power in _powers(robot, part).items():
        if power is not None:
            integrals[name] = np.diff(
                np.interp(bounds, t, cumulative_trapezoid(power, t, initial=0.0))
            )
    rows = []
    for k in range(bounds.size - 1):
        value = {name: float(v[k]) for name, v in integrals.items()}
        rows.append(
            CycleRecord(
                segment=segment,
                cycle=k if period is not None else -1,
                start=float(bounds[k]),
                duration=float(bounds[k + 1] - bounds[k]),
                measured=value.get("measured"),
                predicted=value["predicted"],
                inertial=value["inertial"],
                gravity=value["gravity"],
                friction=value["friction"],
                copper=value["copper"],
                standby=value["standby"],
                shunt=value["shunt"],
                motor_work=value.get("motor_work"),
            )
        )
    return rows, period, [*q.min(axis=0).tolist(), *q.max(axis=0).tolist()]


def _peak_rss() -> float:
    """This process's peak resident memory, MB (Linux reports kB, macOS bytes)."""
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / (1024.0 * 1024.0 if sys.platform == "darwin" else 1024.0)


def analyse_log(item: FleetLog) -> LogResult:
    """Read one log and work out its cycles (see the module docstring); a log that cannot be
    read or analysed gives a result with ``error`` set, not an exception."""
    start = time.perf_counter()
    cycles: list[CycleRecord] = []
    period, samples, error = None, 0, None
    ranges: list[float] = []
    try:
        with kernel_threads(1):  # the workers are the parallelism
            reading = LogReading(
                bag=item.bag, accept=item.accept, payload=item.payload, window=item.window
            )
            robot = reading.loaded(_robot(item.model))
            log = CheckedLog(item.path, robot, reading).read()  # the checks decide first
            samples = len(log)
            for k, part in enumerate(split_segments(log)):
                rows, found, span = _segment_cycles(robot, part, k)
                cycles += rows
                period, ranges = (found, span) if period is None else (period, ranges)
    except KinergyError as exc:
        cycles, error = [], str(exc)
    return LogResult(
        robot=item.robot,
        path=item.path,
        date=item.date,
        period=period,
        ranges=ranges,
        samples=samples,
        cycles=cycles,
        error=error,
        seconds=time.perf_counter() - start,
        worker=os.getpid(),
        peak_rss=_peak_rss(),
    )
