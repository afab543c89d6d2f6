"""The motors' electrical model: torque constants, winding resistance, back-EMF, power, friction.

The forward path that puts these together over a motion is :func:`kinergy.predict.drive_state`.

For a motion ``q, qd, qdd`` (joint side), UR5e section 3-5:

1. link torques ``f_link`` by RNEA (eq 1), plus the motor and reducer inertia (eq 2):
   ``tau_sim = f_link + N^T diag(J_m + J_r) N qdd`` -- the controller's ``target_moment`` (eq 7);
2. motor side: ``wm = N qd`` and the torque the motor delivers to the load ``tau_load = N^-T tau_sim``
   (``tau_sim / i`` for a UR joint);
3. friction on the motor side (eqs 11-16, or the joint's model), whose power-flow direction is the
   sign of ``wm * tau_load``;
4. motor torque ``tau_m = tau_load + tau_f`` and current ``I = tau_m / k_t`` (eqs 10, 17, 20);
5. voltage ``V = R I + k_b wm`` (eq 19) and electrical power
   ``W = tau_m^2 / k_m^2 + (k_b / k_t) wm tau_m`` (eqs 21-23), with ``R = (k_t / k_m)^2`` and
   ``k_b = k_t / (k_t/k_b)``; a drive's ``winding_resistance``, when given, replaces ``R``.

Voltage conventions
-------------------
UR5e eqs 19-23 describe each brushless motor as its equivalent DC motor (Park-Clarke), whose
power is ``V I`` and whose torque is ``k_t I``; kinergy's ``R``, ``k_b`` and voltages are that
motor's. A UR joint calibration (``robot import-calibration``) writes the motor's voltage ``U`` as
an amplitude-invariant dq quantity, with the same current ``I`` (``Tau = K_tau I``) but power
``3/2 U I``: ``V = 3/2 U`` (:data:`DQ_VOLTAGE_FACTOR`). The calibration file shows it: its
``K_tau / Km`` is 1.40 (joints 1-3) and 1.48 (joints 4-6), where a motor that does not create
energy needs ``k_t / k_b <= 1``; read with the 3/2, ``k_t / k_b`` = 0.92 and 0.97 (the UR5e doc's
catalogue conversion: 0.89). docs/FRICTION.md has the whole reconciliation.

A controller's logs carry no motor voltage: ``actual_joint_voltage`` is each joint's supply (the
DC bus at the joint, about 48 V, :func:`kinergy.drives.bus.joint_bus_voltage`), so ``R`` and
``k_b`` come from the robot file or a calibration's ``U`` and ``I``, never from a log.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.model.robot import Robot

__all__ = [
    "DQ_VOLTAGE_FACTOR",
    "back_emf_constants",
    "controller_voltage",
    "electrical_power",
    "equivalent_voltage",
    "friction_torques",
    "motor_constants",
    "torque_constants",
    "winding_resistances",
]


#: equivalent DC motor voltage per volt of the controller's dq voltage (module docstring)
DQ_VOLTAGE_FACTOR = 1.5


def torque_constants(robot: Robot) -> Array:
    """k_t per motor, N m/A, shape (n,)."""
    return np.array([j.drive.torque_constant for j in robot.joints])


def winding_resistances(robot: Robot) -> Array:
    """R per motor, ohm: the drive's ``winding_resistance`` or ``(k_t / k_m)^2``, shape (n,)."""
    return np.array(
        [
            j.drive.winding_resistance
            if j.drive.winding_resistance is not None
            else (j.drive.torque_constant / j.drive.motor_constant) ** 2
            for j in robot.joints
        ]
    )


def motor_constants(robot: Robot) -> Array:
    """k_m = k_t / sqrt(R) per motor, N m/sqrt(W), shape (n,) (consistent with the resistance)."""
    return torque_constants(robot) / np.sqrt(winding_resistances(robot))


def back_emf_constants(robot: Robot) -> Array:
    """k_b = k_t / (k_t/k_b) per motor, V s/rad, shape (n,)."""
    return torque_constants(robot) / np.array([j.drive.kt_over_kb for j in robot.joints])


def electrical_power(robot: Robot, tau_m: ArrayLike, wm: ArrayLike) -> Array:
    """Electrical power per motor, ``tau_m^2 / k_m^2 + (k_b / k_t) wm tau_m`` (UR5e eq 23), W."""
    tau_m = np.asarray(tau_m, dtype=float)
    kt_over_kb = np.array([j.drive.kt_over_kb for j in robot.joints])
    return tau_m**2 / motor_constants(robot) ** 2 + np.asarray(wm, dtype=float) * tau_m / kt_over_kb


def controller_voltage(voltage: ArrayLike) -> Array:
    """The dq voltage a UR joint calibration writes (``U``) for an equivalent DC motor voltage
    ``V`` (UR5e eq 19): ``V / 1.5``, V, shape like ``voltage``."""
    return np.asarray(voltage, dtype=float) / DQ_VOLTAGE_FACTOR


def equivalent_voltage(logged: ArrayLike) -> Array:
    """The equivalent DC motor voltage (UR5e eq 19) of a calibration's dq voltage ``U``:
    ``1.5 U``, V, shape like ``logged``."""
    return np.asarray(logged, dtype=float) * DQ_VOLTAGE_FACTOR


def friction_torques(
    robot: Robot,
    wm: Array,
    tau_load: Array,
    dwm: Array | None = None,
    temperature: Array | None = None,
) -> Array:
    """Motor-side friction of every joint, (N, n), N m.

    ``dwm``: motor accelerations (rad/s^2), for friction held through standstill;
    ``temperature``: joint temperatures (deg C, (N, n)), for temperature-dependent friction.
    """
    out = np.empty_like(wm)
    for i, joint in enumerate(robot.joints):
        acc = None if dwm is None else dwm[:, i]
        temp = None if temperature is None else temperature[:, i]
        out[:, i] = joint.drive.friction.torque(wm[:, i], tau_load[:, i], acc, temperature=temp)
    return out
