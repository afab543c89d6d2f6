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
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy.friction.registry import friction_torque
from kinergy.model.robot import Robot

__all__ = [
    "back_emf_constants",
    "electrical_power",
    "friction_torques",
    "motor_constants",
    "torque_constants",
    "winding_resistances",
]

Array = NDArray[np.float64]


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


def friction_torques(robot: Robot, wm: Array, tau_load: Array, dwm: Array | None = None) -> Array:
    """Motor-side friction of every joint, (N, n), N m (``dwm``: motor accelerations, for
    friction held through standstill)."""
    out = np.empty_like(wm)
    for i, joint in enumerate(robot.joints):
        fr = joint.drive.friction
        acc = None if dwm is None else dwm[:, i]
        out[:, i] = friction_torque(fr.model, fr.params, wm[:, i], tau_load[:, i], acc)
    return out
