"""``kinergy simulate``: run the digital twin on a built-in program or a motion file, write its log."""

from __future__ import annotations

import os

from kinergy.io.log import Log
from kinergy.io.rtde import write_log
from kinergy.model.robot import Robot
from kinergy.simulate import TwinSettings, simulate
from kinergy.trajectory.programs import TEST_TRAJECTORIES, paper_trajectory
from kinergy.workflows.logs import read_motion

__all__ = ["simulate_to_file"]


def simulate_to_file(
    robot: Robot,
    trajectory: str,
    out: str | os.PathLike[str],
    settings: TwinSettings,
    *,
    columns: str | None = None,
) -> Log:
    """Simulate ``trajectory`` (``test-a``, ``test-b`` or a motion file's target motion) on the
    twin ``robot`` and write the log to ``out`` (record.py layout, atomically)."""
    if trajectory in TEST_TRAJECTORIES:
        motion = paper_trajectory(robot, trajectory)
    else:
        motion = read_motion(
            trajectory, n_joints=robot.n, columns=columns, source="target", robot=robot
        )
    twin = simulate(robot, motion, settings, name=os.fspath(out))
    write_log(out, twin.t, twin.signals)
    return twin
