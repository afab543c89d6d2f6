"""The digital twin: a robot that writes the logs a UR controller would, from a true model.

Given the twin's true robot and a commanded (target) motion, the twin produces, at the rate the
motion is sampled (the controller's 500 Hz), the RTDE signals the UR5e doc works from (section
2.2) and the drive-side ones a real controller also logs:

- ``target_q``, ``target_qd``, ``target_qdd``: the commanded motion;
- ``target_moment``: the controller's feed-forward torque, UR5e eq 7 on the *target* motion
  (rigid-body torques plus reflected motor and reducer inertia; no friction), computed with the
  true robot (the controller knows its arm);
- ``actual_q``, ``actual_qd``: the real motion, which trails the target by ``lag`` seconds; the
  measured angle and speed carry encoder noise;
- ``actual_current``: UR5e eq 17 on the *real* motion (friction included, at the joints'
  temperatures) plus current noise, quantised to the controller's current step;
- ``actual_robot_voltage`` and ``actual_robot_current``: the arm's supply, the DC bus voltage
  (with ripple) and the current it draws for the bus model's power (:mod:`kinergy.drives.bus`:
  motors summed on the bus, surplus braking power to the shunt, plus the standing draw);
- ``actual_joint_voltage``: each joint's supply as a UR controller logs it, the bus voltage at
  the joint (the supply's less the arm's cable drop,
  :func:`kinergy.drives.bus.joint_bus_voltage`), plus noise; not the motor's voltage;
- ``joint_temperatures``: each joint warmed by its losses and its share of the arm's standby
  power (:mod:`kinergy.drives.thermal`), when the true robot has thermal models;
  temperature-dependent friction follows them;
- ``robot_mode`` 7 (running) and ``runtime_state`` 2 (playing), as a program run logs them;
- ``actual_joint_torque`` (with :attr:`TwinSettings.torque_sensors`): what each joint's torque
  sensor reads on the real motion, :func:`kinergy.predict.sensor_torque` (link side: the links'
  torques and friction, no rotor inertia; the sensor's offset from the true robot's
  ``torque_sensor``), plus noise.

The twin is not the model: :func:`realistic_truth` makes a true robot that differs from a model
the way a real arm differs from its data sheet (``kinergy simulate --mismatch realistic``, the
default of ``kinergy demo``); with the model itself as the truth and
:meth:`TwinSettings.exact`, the signals are the model's equations exactly (for tests).

The UR5e doc's test programs A and B that the twin usually runs are in
:mod:`kinergy.trajectory.programs`.
"""

from __future__ import annotations

import dataclasses
import enum
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from kinergy import checks
from kinergy.arrays import Array
from kinergy.drives.bus import joint_bus_voltage, supply_power
from kinergy.drives.electrics import winding_resistances
from kinergy.drives.thermal import joint_losses, joint_temperatures
from kinergy.errors import KinergyError
from kinergy.friction.load_thermal_power_law import MODEL as LOAD_THERMAL_POWER_LAW
from kinergy.friction.model import SMOOTHING
from kinergy.friction.power_law import speed_power
from kinergy.io.log import Log
from kinergy.model.robot import Friction, Joint, Robot, Source, Thermal
from kinergy.predict import DriveState, drive_state, sensor_torque
from kinergy.trajectory.motion import Motion

__all__ = ["Mismatch", "TwinSettings", "realistic_truth", "simulate"]


class Mismatch(enum.StrEnum):
    """How the twin's true robot differs from the model it simulates (``--mismatch``): not at all
    (the model is the truth) or as a real arm does (:func:`realistic_truth`)."""

    NONE = "none"
    REALISTIC = "realistic"


@dataclass(frozen=True)
class TwinSettings:
    """Imperfections of the simulated controller and its measurements, and the thermal start.

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
    current_step : float
        Quantisation step of the logged currents (motor and supply), A; 0: none.
    voltage_noise : float
        Standard deviation of the logged joint voltages' noise, V.
    ripple : float
        Amplitude of the supply voltage's ripple, V (100 Hz, plus a fifth of it as noise).
    ambient : float
        Air temperature, deg C; the joints start at it unless ``initial_temperature`` is given.
    initial_temperature : float or None
        The joints' temperature at the start, deg C (a warm robot).
    torque_sensors : bool
        Log ``actual_joint_torque``, as an arm with joint torque sensors does.
    torque_noise : float
        Standard deviation of the measured joint torques' noise, N m.
    """

    lag: float = 0.004
    speed_noise: float = 0.01
    position_noise: float = 1e-5
    current_noise: float = 0.04
    seed: int = 0
    current_step: float = 0.0
    voltage_noise: float = 0.0
    ripple: float = 0.0
    ambient: float = 25.0
    initial_temperature: float | None = None
    torque_sensors: bool = False
    torque_noise: float = 0.0

    def __post_init__(self) -> None:
        for name in (
            "torque_noise",
            "lag",
            "speed_noise",
            "position_noise",
            "current_noise",
            "current_step",
            "voltage_noise",
            "ripple",
        ):
            object.__setattr__(self, name, checks.number(getattr(self, name), name, ge=0.0))

    @classmethod
    def exact(cls) -> TwinSettings:
        """No lag, no noise: the signals are the model's equations exactly."""
        return cls(lag=0.0, speed_noise=0.0, position_noise=0.0, current_noise=0.0)

    @classmethod
    def realistic(cls, seed: int = 0) -> TwinSettings:
        """A real controller's imperfections: 4 ms lag, encoder noise, 0.04 A current noise in
        5 mA steps, 0.05 V voltage noise and 0.25 V of supply ripple."""
        return cls(seed=seed, current_step=0.005, voltage_noise=0.05, ripple=0.25)


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


def _warm_state(
    robot: Robot, real: Motion, settings: TwinSettings
) -> tuple[DriveState, Array | None]:
    """The drive state on the real motion and the joint temperatures (None without thermal
    models): temperatures from the losses (the standby power included), friction at the temperatures, three times (the
    thermal time constant is minutes, the coupling weak: the third pass moves them by < 0.01 K)."""
    if any(j.drive.thermal is None for j in robot.joints):
        return drive_state(robot, real.q, real.qd, real.qdd), None
    start = (
        settings.ambient if settings.initial_temperature is None else settings.initial_temperature
    )
    temperature = np.full(real.q.shape, start)
    for _ in range(3):
        state = drive_state(robot, real.q, real.qd, real.qdd, temperature=temperature)
        losses = joint_losses(
            robot, state.current, state.tau_friction, state.wm, standby=robot.standby_power
        )
        temperature = joint_temperatures(
            robot, real.t, losses, ambient=settings.ambient, initial=start
        )
    return drive_state(robot, real.q, real.qd, real.qdd, temperature=temperature), temperature


def _quantised(x: Array, step: float) -> Array:
    return x if step <= 0.0 else np.round(x / step) * step


def _supply(
    robot: Robot, state: DriveState, t: Array, settings: TwinSettings, rng: np.random.Generator
) -> tuple[Array, Array]:
    """The supply voltage (V, with ripple) and the current the arm draws from it (A), (N,)."""
    ripple = settings.ripple * (
        np.sin(2.0 * np.pi * 100.0 * t + rng.uniform(0, 2 * np.pi))
        + 0.2 * rng.standard_normal(t.size)
    )
    voltage = robot.bus_voltage + ripple
    current = supply_power(state.power, robot.standby_power).supply / voltage
    return voltage, _quantised(current, settings.current_step)


def simulate(
    robot: Robot, target: Motion, settings: TwinSettings | None = None, *, name: str = "twin"
) -> Log:
    """Controller-like signals for ``target`` run on ``robot``.

    Parameters
    ----------
    robot : Robot
        The twin's true robot (the model itself, or :func:`realistic_truth` of it).
    target : Motion
        The commanded motion (sampled at the rate the log should have, normally 500 Hz).
    settings : TwinSettings, optional
        Lag, noise and the thermal start; default :class:`TwinSettings` (lag and noise),
        :meth:`TwinSettings.realistic` for a real controller's, :meth:`TwinSettings.exact` for
        none.
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
    real = _delayed(target, settings.lag)
    actual, temperature = _warm_state(robot, real, settings)
    commanded = drive_state(robot, target.q, target.qd, target.qdd, temperature=temperature)
    big_n, n = target.q.shape
    # the noises are drawn in this order so that a seed gives the logs it always gave
    current = actual.current + settings.current_noise * rng.standard_normal((big_n, n))
    actual_q = real.q + settings.position_noise * rng.standard_normal((big_n, n))
    actual_qd = real.qd + settings.speed_noise * rng.standard_normal((big_n, n))
    voltage_noise = settings.voltage_noise * rng.standard_normal((big_n, n))
    bus_voltage, bus_current = _supply(robot, actual, target.t, settings, rng)
    joint_voltage = joint_bus_voltage(bus_voltage, bus_current, n) + voltage_noise
    signals = {
        "target_q": target.q,
        "actual_q": actual_q,
        "target_qd": target.qd,
        "actual_qd": actual_qd,
        "target_qdd": target.qdd,
        "target_moment": commanded.tau_sim,
        "target_current": commanded.current,
        "actual_current": _quantised(current, settings.current_step),
        "actual_joint_voltage": joint_voltage,
        "actual_robot_voltage": bus_voltage,
        "actual_robot_current": bus_current,
        "robot_mode": np.full(big_n, 7.0),
        "runtime_state": np.full(big_n, 2.0),
    }
    if temperature is not None:
        signals["joint_temperatures"] = temperature
    if settings.torque_sensors:  # drawn last: the other signals stay those the seed gave
        noise = settings.torque_noise * rng.standard_normal((big_n, n))
        signals["actual_joint_torque"] = sensor_torque(robot, actual) + noise
    return Log(name, np.asarray(target.t, dtype=float), signals)


# ---------------------------------------------------------------------------------------------
# The realistic true robot

#: joint speeds at which a model's friction is matched by the truth's power law, rad/s
_MATCH_SPEEDS = np.array([0.1, 0.5, 1.0, 2.0, 3.0])
#: share of the speed term the truth's friction loses per kelvin (18 % over 20 K: Raviola et al.)
_THERMAL_DROP = 0.009
#: the truth's standby power, W (the electronics of six joints and the brakes)
_STANDBY = 30.0


def _true_friction(joint: Joint, rng: np.random.Generator, scale: float) -> Friction:
    """A concave ``load_thermal_power_law`` near the joint's own friction curve: its Coulomb
    level, and a power-law speed term (exponent 0.5-0.65) matched to the rest of the curve
    between 0.1 and 3 rad/s; levels perturbed by ``scale``, a load term of 1-3 % and a speed
    term falling 18 % over 20 K."""
    drive = joint.drive
    wm = np.abs(drive.gear_ratio) * np.concatenate([[1e-3], _MATCH_SPEEDS])
    params = dict(drive.friction.params)
    params.pop("standstill", None)
    params.pop("holding", None)
    moving = Friction(drive.friction.model, params)  # without the standstill hold
    level = 0.5 * (moving.torque(wm, np.ones_like(wm)) + moving.torque(wm, -np.ones_like(wm)))
    exponent = float(rng.uniform(0.5, 0.65))
    coulomb = max(float(level[0]), 1e-4)
    speed = speed_power(wm[1:], exponent)
    viscous = max(float(speed @ (level[1:] - coulomb) / (speed @ speed)), 1e-6)
    viscous *= 1.0 + scale * rng.uniform(-1, 1)
    return Friction(
        LOAD_THERMAL_POWER_LAW,
        {
            "coulomb": coulomb * (1.0 + scale * rng.uniform(-1, 1)),
            "load": float(rng.uniform(0.01, 0.03)),
            "viscous": viscous,
            "viscous_temperature": float(-_THERMAL_DROP * viscous * rng.uniform(0.9, 1.1)),
            "exponent": exponent,
            "reference_temperature": 25.0,
            "smoothing": SMOOTHING,
        },
    )


def _true_joint(joint: Joint, resistance: float, rng: np.random.Generator) -> Joint:
    """One joint of :func:`realistic_truth`."""

    def vary(x: float, spread: float) -> float:
        return float(x * (1.0 + spread * rng.uniform(-1, 1)))

    link = dataclasses.replace(
        joint.link,
        mass=vary(joint.link.mass, 0.01),
        com=joint.link.com + rng.uniform(-0.002, 0.002, 3),
        inertia=joint.link.inertia * (1.0 + 0.10 * rng.uniform(-1, 1)),
    )
    drive = joint.drive
    thermal = drive.thermal
    if thermal is not None:
        thermal = Thermal(vary(thermal.capacity, 0.1), vary(thermal.resistance, 0.1))
    kt, ohm = vary(drive.torque_constant, 0.04), vary(resistance, 0.05)
    true_drive = dataclasses.replace(
        drive,
        motor_inertia=vary(drive.motor_inertia, 0.08),
        torque_constant=kt,
        motor_constant=kt / np.sqrt(ohm),
        winding_resistance=ohm,
        kt_over_kb=vary(drive.kt_over_kb, 0.03),
        friction=_true_friction(joint, rng, 0.10),
        thermal=thermal,
    )
    return dataclasses.replace(joint, link=link, drive=true_drive)


def realistic_truth(robot: Robot, seed: int = 0) -> Robot:
    """A true robot that differs from the model ``robot`` as a real arm does, seeded.

    Per joint: link mass 1 %, centre of mass 2 mm, inertia tensor 10 %; motor inertia 8 %; torque
    constant 4 %; winding resistance 5 % and ``k_t/k_b`` 3 %; thermal capacity and resistance
    10 %; friction a concave power law in speed with a Coulomb level that grows with the load
    (1-3 % of it) and a speed term that falls 18 % over 20 K as the joint warms
    (``load_thermal_power_law``, levels 10 % off the model's curve). The arm draws 30 W +- 20 %
    of standby power. (Each figure is the half-width of a uniform spread.)

    Returns
    -------
    Robot
        Named ``<model> (twin truth, seed N)``; its sources say ``user`` (a made-up arm).
    """
    rng = np.random.default_rng(seed)
    resistances = winding_resistances(robot)
    joints = [_true_joint(j, float(r), rng) for j, r in zip(robot.joints, resistances, strict=True)]
    truth = robot.with_joints(joints)
    ref = f"kinergy realistic twin truth of {robot.name}, seed {seed}"
    return dataclasses.replace(
        truth,
        description=ref,
        standby_power=_STANDBY * (1.0 + 0.2 * rng.uniform(-1, 1)),
        sources={cat: Source("user", ref) for cat in robot.sources},
    )
