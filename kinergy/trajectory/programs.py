"""Built-in joint-space programs: the UR home pose and the UR5e doc's test programs A and B.

``test-a`` and ``test-b`` are the UR5e doc's experiments (section 2.2): a movej program from the
home pose through six random points and back, joint speed 3 rad/s, acceleration 6 rad/s^2 (capped
by the robot's joint limits), seeded (seeds 1 and 2) so they are reproducible, with points drawn
until the flange and the elbow stay above the table plane over the whole motion.
"""

from __future__ import annotations

import numpy as np

from kinergy.arrays import Array
from kinergy.dynamics.kinematics import link_poses
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.trajectory.motion import CONTROLLER_DT, Motion
from kinergy.trajectory.movej import movej

__all__ = [
    "TEST_TRAJECTORIES",
    "UR_HOME",
    "pad_rest",
    "paper_speed",
    "paper_trajectory",
    "paper_waypoints",
]


#: name -> seed of the UR5e doc's test programs
TEST_TRAJECTORIES = {"test-a": 1, "test-b": 2}

#: The UR arms' home pose (upright, wrist pointing forward), rad.
UR_HOME = np.array([0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0])
UR_HOME.setflags(write=False)


def _above_table(robot: Robot, q: Array, floor: float) -> bool:
    frames = link_poses(robot, q)  # (N, n, 4, 4)
    heights = frames[:, 2:, 2, 3]  # elbow onwards
    return bool(np.all(heights > floor))


def paper_speed(robot: Robot) -> tuple[float, float]:
    """The test programs' movej speed and acceleration: the UR5e doc's 3 rad/s and 6 rad/s^2,
    capped by the robot's slowest joint limits (so other arms run them within their limits)."""
    speed = min([3.0] + [j.limits.speed for j in robot.joints])
    acc = min(
        [6.0] + [j.limits.acceleration for j in robot.joints if j.limits.acceleration is not None]
    )
    return speed, acc


def paper_waypoints(robot: Robot, seed: int, *, points: int = 6, floor: float = 0.05) -> Array:
    """Home, ``points`` random joint targets, home: the UR5e doc's test programs (section 2.2).

    Targets are drawn (seeded) with the base and wrists anywhere in +-pi, the shoulder in
    [-pi, 0] and the elbow in +-2.5 rad (within the robot's joint limits), and redrawn until every link frame from the elbow on stays
    above ``floor`` (m) over the whole movej at 3 rad/s and 6 rad/s^2.

    Returns
    -------
    ndarray, shape (points + 2, n)
    """
    if robot.n != 6:
        raise KinergyError(
            f"the test programs are for 6-joint arms; {robot.name} has {robot.n} joints"
        )
    rng = np.random.default_rng(seed)
    limits = np.array([j.limits.position for j in robot.joints])
    lo = np.maximum([-np.pi, -np.pi, -2.5, -np.pi, -np.pi, -np.pi], limits[:, 0])
    hi = np.minimum([np.pi, 0.0, 2.5, np.pi, np.pi, np.pi], limits[:, 1])
    if np.any(lo >= hi):
        raise KinergyError(f"the test programs' joint ranges do not fit {robot.name}'s limits")
    speed, acc = paper_speed(robot)
    home = np.clip(UR_HOME, lo, hi)
    if not _above_table(robot, home[None, :], floor):
        floor = -np.inf  # an arm whose home pose is not above a table (a mobile or hanging arm)
    way = [home]
    for _ in range(2000):
        if len(way) == points + 1:
            break
        candidate = rng.uniform(lo, hi)
        leg = movej(np.vstack([way[-1], candidate]), speed=speed, acceleration=acc, dt=0.02)
        if _above_table(robot, leg.q, floor):
            way.append(candidate)
    else:
        raise KinergyError(
            f"could not draw {points} test points that keep {robot.name} above the table"
        )
    home_leg = movej(np.vstack([way[-1], home]), speed=speed, acceleration=acc, dt=0.02)
    if not _above_table(robot, home_leg.q, floor):  # pragma: no cover - depends on the draw
        return paper_waypoints(robot, seed + 1000, points=points, floor=floor)
    way.append(home)
    return np.vstack(way)


def paper_trajectory(
    robot: Robot, name: str, *, dt: float = CONTROLLER_DT, rest: float = 0.2
) -> Motion:
    """``test-a`` or ``test-b`` as a target motion at ``dt`` (with ``rest`` s still at each end)."""
    if name not in TEST_TRAJECTORIES:
        raise KinergyError(
            f"unknown test trajectory {name!r} (known: {', '.join(TEST_TRAJECTORIES)})"
        )
    waypoints = paper_waypoints(robot, TEST_TRAJECTORIES[name])
    speed, acc = paper_speed(robot)
    motion = movej(waypoints, speed=speed, acceleration=acc, dt=dt)
    return pad_rest(motion, rest, dt)


def pad_rest(motion: Motion, rest: float, dt: float) -> Motion:
    """Hold the first and last pose still for ``rest`` seconds."""
    k = round(rest / dt)
    if k == 0:
        return motion
    n = motion.n
    head_t = motion.t[0] - dt * np.arange(k, 0, -1)
    tail_t = motion.t[-1] + dt * np.arange(1, k + 1)
    zeros = np.zeros((k, n))
    t = np.concatenate([head_t, motion.t, tail_t]) - (motion.t[0] - k * dt)
    q = np.vstack([np.tile(motion.q[0], (k, 1)), motion.q, np.tile(motion.q[-1], (k, 1))])
    qd = np.vstack([zeros, motion.qd, zeros])
    qdd = np.vstack([zeros, motion.qdd, zeros])
    return Motion(t, q, qd, qdd)
