"""The digital twin: a robot that writes the logs a UR controller would, from a model.

Given a robot model and a commanded (target) motion, the twin produces, at the controller's
500 Hz, the RTDE signals the UR5e doc works from (section 2.2):

- ``target_q``, ``target_qd``, ``target_qdd``: the commanded motion;
- ``target_moment``: the controller's feed-forward torque, UR5e eq 7 on the *target* motion
  (rigid-body torques plus reflected motor and reducer inertia; no friction);
- ``actual_q``, ``actual_qd``: the real motion, which trails the target by ``lag`` seconds; the
  measured speed carries encoder noise;
- ``actual_current``: UR5e eq 17 on the *real* motion (friction included) plus current noise;
- ``actual_joint_voltage`` (eq 19), ``actual_robot_voltage`` (the DC bus) and
  ``actual_robot_current`` (the bus current: motor powers, eq 23, plus standby, over the bus
  voltage);
- ``robot_mode`` 7 (running) and ``runtime_state`` 2 (playing), as a program run logs them.

``test-a`` and ``test-b`` are the UR5e doc's experiments (section 2.2): a movej program from the
home pose through six random points and back, joint speed 3 rad/s, acceleration 6 rad/s^2 (capped
by the robot's joint limits), seeded (seeds 1 and 2) so they are reproducible, with points drawn until the flange and the elbow stay
above the table plane over the whole motion.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from kinergy.drives.electrics import drive_state
from kinergy.dynamics.kinematics import link_poses
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.movej import movej

__all__ = [
    "TEST_TRAJECTORIES",
    "TwinSettings",
    "paper_trajectory",
    "paper_waypoints",
    "simulate",
]

Array = NDArray[np.float64]

#: name -> seed of the UR5e doc's test programs
TEST_TRAJECTORIES = {"test-a": 1, "test-b": 2}

_HOME = np.array([0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0])


@dataclass(frozen=True)
class TwinSettings:
    """Imperfections of the simulated controller's measurements.

    Attributes
    ----------
    lag : float
        How far the real motion trails the target, s (a few ms on a UR).
    speed_noise : float
        Standard deviation of the measured joint speed's noise, rad/s.
    position_noise : float
        Standard deviation of the measured joint angle's noise, rad (encoder resolution).
    current_noise : float
        Standard deviation of the measured motor current's noise, A.
    seed : int
        Seed of the noise generator.
    """

    lag: float = 0.004
    speed_noise: float = 0.01
    position_noise: float = 1e-5
    current_noise: float = 0.04
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("lag", "speed_noise", "position_noise", "current_noise"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0.0):
                raise KinergyError(f"{name} must be >= 0, got {value}")

    @classmethod
    def exact(cls) -> TwinSettings:
        """No lag, no noise: the signals are the model's equations exactly."""
        return cls(lag=0.0, speed_noise=0.0, position_noise=0.0, current_noise=0.0)


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
    home = np.clip(_HOME, lo, hi)
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


def paper_trajectory(robot: Robot, name: str, *, dt: float = 0.002, rest: float = 0.2) -> Motion:
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


def _delayed(motion: Motion, lag: float) -> Motion:
    """The motion ``lag`` s later: ``x(t - lag)``, held at its start value before it begins.

    Exact shifts on the sample grid; otherwise cubic-spline interpolation of each signal.
    """
    if lag == 0.0:
        return motion
    t = motion.t
    shifted = t - lag
    out = []
    for arr in (motion.q, motion.qd, motion.qdd):
        spline = CubicSpline(t, arr, axis=0)
        vals = spline(np.clip(shifted, t[0], t[-1]))
        vals[shifted < t[0]] = arr[0]
        out.append(vals)
    return Motion(t, out[0], out[1], out[2])


def simulate(
    robot: Robot, target: Motion, settings: TwinSettings | None = None
) -> dict[str, Array]:
    """Controller-like signals for ``target`` run on ``robot``.

    Parameters
    ----------
    robot : Robot
        The twin's "true" model.
    target : Motion
        The commanded motion (sampled at the rate the log should have, normally 500 Hz).
    settings : TwinSettings, optional
        Lag and noise; default :class:`TwinSettings` (realistic), :meth:`TwinSettings.exact` for none.

    Returns
    -------
    dict of str to ndarray
        ``timestamp`` (N,) and the signals of the module docstring, (N, n) or (N,).
    """
    settings = settings or TwinSettings()
    if target.n != robot.n:
        raise KinergyError(f"the motion has {target.n} joints but {robot.name} has {robot.n}")
    rng = np.random.default_rng(settings.seed)
    commanded = drive_state(robot, target.q, target.qd, target.qdd)
    real = _delayed(target, settings.lag)
    actual = drive_state(robot, real.q, real.qd, real.qdd)
    big_n, n = target.q.shape
    current = actual.current + settings.current_noise * rng.standard_normal((big_n, n))
    bus_power = actual.power.sum(axis=1) + robot.standby_power
    return {
        "timestamp": target.t,
        "target_q": target.q,
        "actual_q": real.q + settings.position_noise * rng.standard_normal((big_n, n)),
        "target_qd": target.qd,
        "actual_qd": real.qd + settings.speed_noise * rng.standard_normal((big_n, n)),
        "target_qdd": target.qdd,
        "target_moment": commanded.tau_sim,
        "target_current": commanded.current,
        "actual_current": current,
        "actual_joint_voltage": actual.voltage,
        "actual_robot_voltage": np.full(big_n, robot.bus_voltage),
        "actual_robot_current": bus_power / robot.bus_voltage,
        "robot_mode": np.full(big_n, 7.0),
        "runtime_state": np.full(big_n, 2.0),
    }
