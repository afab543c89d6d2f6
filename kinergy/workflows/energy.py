"""``kinergy energy``: the energy of a logged or planned motion, beside what the log measured."""

from __future__ import annotations

import dataclasses
import os

import numpy as np

from kinergy.accounting.energy import EnergyReport, energy
from kinergy.accounting.energy_stream import EnergyAccumulator
from kinergy.accounting.figures import EnergyFigures
from kinergy.accounting.supply import measured_supply
from kinergy.arrays import Array
from kinergy.io.formats import iter_log
from kinergy.io.log import Log
from kinergy.io.motion import motion_from_log
from kinergy.io.motion_stream import iter_motion
from kinergy.io.rosbag import BagOptions
from kinergy.io.rtde import read_log
from kinergy.model.robot import Robot
from kinergy.predict import drive_state
from kinergy.trajectory.motion import Motion
from kinergy.workflows.logs import read_motion

__all__ = ["ENERGY_ROWS", "energy_figures_of_log", "energy_of_log"]

#: samples per chunk of the one-pass energy: 40 s at 500 Hz; the drive state of a chunk holds
#: about 40 arrays of (rows, n) (60-minute log: peak 400 MB against 530 MB at 50,000 rows)
ENERGY_ROWS = 20_000


def _temperature(log: Log, motion: Motion) -> Array | None:
    """The log's ``joint_temperatures`` where it has one per joint, else None."""
    if "joint_temperatures" in log and log["joint_temperatures"].shape == motion.q.shape:
        return log["joint_temperatures"]
    return None


def _measured_power(log: Log) -> Array | None:
    """``actual_robot_voltage x actual_robot_current`` where the log has both, W, else None."""
    if "actual_robot_voltage" in log and "actual_robot_current" in log:
        return np.asarray(log["actual_robot_voltage"] * log["actual_robot_current"])
    return None


#: the signals besides the motion that the energy of a log uses
_EXTRAS = ("joint_temperatures", "actual_robot_voltage", "actual_robot_current", "segment")


def _signals_used(
    path: str | os.PathLike[str],
    columns: str | None,
    source: str,
    joints: list[str],
    bag: BagOptions | None,
) -> list[str] | None:
    """The signals of the log at ``path`` its energy uses (the others are never converted):
    the motion of ``source`` (``auto`` as :func:`kinergy.io.motion.motion_from_log`) and
    :data:`_EXTRAS`, those the log has; None (all) when it has no joint positions, so the
    error lists what it has."""
    first = next(iter_log(path, columns=columns, rows=2, joints=joints, bag=bag), None)
    if first is None:
        return None
    names = first.signals
    if source == "auto":
        source = "target" if "target_q" in names else "actual"
    if f"{source}_q" not in names:
        return None
    wanted = [f"{source}_{x}" for x in ("q", "qd", "qdd")] + list(_EXTRAS)
    return [name for name in wanted if name in names]


def energy_of_log(
    robot: Robot,
    path: str | os.PathLike[str],
    *,
    columns: str | None = None,
    source: str = "auto",
    recovery: bool = True,
    bag: BagOptions | None = None,
) -> EnergyReport:
    """The energy of the motion in a log or motion file (:func:`kinergy.accounting.energy.energy`),
    with friction at the log's ``joint_temperatures`` where it has them, and the supply energy
    the log measured (``actual_robot_voltage`` x ``actual_robot_current``) beside the predicted
    one where it has both. A URScript program (``*.script``) is run as the controller would
    (:func:`kinergy.workflows.logs.read_motion`); a ROS 2 bag is read with the robot's joint
    names and ``bag``'s options (:mod:`kinergy.io.rosbag`)."""
    if os.fspath(path).endswith(".script"):
        return energy(robot, read_motion(path, n_joints=robot.n, robot=robot), recovery=recovery)
    log = read_log(path, columns=columns, joints=robot.joint_names, bag=bag)
    motion = motion_from_log(log, n_joints=robot.n, source=source)
    report = energy(robot, motion, recovery=recovery, temperature=_temperature(log, motion))
    if "actual_robot_voltage" in log and "actual_robot_current" in log:
        measured = measured_supply(log.t, log["actual_robot_voltage"], log["actual_robot_current"])
        report = dataclasses.replace(report, measured=measured)
    return report


def energy_figures_of_log(
    robot: Robot,
    path: str | os.PathLike[str],
    *,
    columns: str | None = None,
    source: str = "auto",
    recovery: bool = True,
    rows: int = ENERGY_ROWS,
    bag: BagOptions | None = None,
) -> EnergyFigures:
    """The figures of :func:`energy_of_log` (what ``kinergy energy`` prints), a log read in one
    pass: chunks of ``rows`` samples (:func:`kinergy.io.formats.iter_log`), their motion as the
    whole log's (:func:`kinergy.io.motion_stream.iter_motion`), predicted and accumulated
    (:class:`kinergy.accounting.energy_stream.EnergyAccumulator`); memory bounded by the chunk.
    Segments (a time gap or a ``segment`` change) are never integrated across. A URScript
    program takes the in-memory path; ``bag`` as :func:`energy_of_log` takes it."""
    if os.fspath(path).endswith(".script"):
        return energy_of_log(robot, path, recovery=recovery).figures()
    acc = EnergyAccumulator(robot, recovery=recovery)
    measured = False
    joints = robot.joint_names
    select = _signals_used(path, columns, source, joints, bag)
    chunks = iter_log(path, columns=columns, rows=rows, select=select, joints=joints, bag=bag)
    for part in iter_motion(chunks, n_joints=robot.n, source=source):
        m = part.motion
        state = drive_state(robot, m.q, m.qd, m.qdd, temperature=_temperature(part.log, m))
        power = _measured_power(part.log)
        measured = power is not None
        acc.add(m.t, state, starts=part.starts, measured_power=power)
    return acc.figures(measured=measured)
