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

The UR5e doc's test programs A and B that the twin usually runs are in
:mod:`kinergy.trajectory.programs`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from kinergy.errors import KinergyError
from kinergy.io.log import Log
from kinergy.model.robot import Robot
from kinergy.predict import drive_state
from kinergy.trajectory.motion import Motion

__all__ = ["TwinSettings", "simulate"]

Array = NDArray[np.float64]


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
    robot: Robot, target: Motion, settings: TwinSettings | None = None, *, name: str = "twin"
) -> Log:
    """Controller-like signals for ``target`` run on ``robot``.

    Parameters
    ----------
    robot : Robot
        The twin's "true" model.
    target : Motion
        The commanded motion (sampled at the rate the log should have, normally 500 Hz).
    settings : TwinSettings, optional
        Lag and noise; default :class:`TwinSettings` (realistic), :meth:`TwinSettings.exact` for none.

    name : str
        What the log is called in messages (its ``path``).

    Returns
    -------
    Log
        The signals of the module docstring, (N, n) or (N,), at ``target.t``.
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
    signals = {
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
    return Log(name, np.asarray(target.t, dtype=float), signals)
