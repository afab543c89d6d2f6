"""``kinergy energy``: the energy of a logged or planned motion, beside what the log measured."""

from __future__ import annotations

import dataclasses
import os

from kinergy.accounting.energy import EnergyReport, energy
from kinergy.accounting.supply import measured_supply
from kinergy.io.motion import motion_from_log
from kinergy.io.rtde import read_log
from kinergy.model.robot import Robot
from kinergy.workflows.logs import read_motion

__all__ = ["energy_of_log"]


def energy_of_log(
    robot: Robot,
    path: str | os.PathLike[str],
    *,
    columns: str | None = None,
    source: str = "auto",
    recovery: bool = True,
) -> EnergyReport:
    """The energy of the motion in a log or motion file (:func:`kinergy.accounting.energy.energy`),
    with friction at the log's ``joint_temperatures`` where it has them, and the supply energy
    the log measured (``actual_robot_voltage`` x ``actual_robot_current``) beside the predicted
    one where it has both. A URScript program (``*.script``) is run as the controller would
    (:func:`kinergy.workflows.logs.read_motion`)."""
    if os.fspath(path).endswith(".script"):
        return energy(robot, read_motion(path, n_joints=robot.n, robot=robot), recovery=recovery)
    log = read_log(path, columns=columns)
    motion = motion_from_log(log, n_joints=robot.n, source=source)
    temperature = None
    if "joint_temperatures" in log and log["joint_temperatures"].shape == motion.q.shape:
        temperature = log["joint_temperatures"]
    report = energy(robot, motion, recovery=recovery, temperature=temperature)
    if "actual_robot_voltage" in log and "actual_robot_current" in log:
        measured = measured_supply(log.t, log["actual_robot_voltage"], log["actual_robot_current"])
        report = dataclasses.replace(report, measured=measured)
    return report
