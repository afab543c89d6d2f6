"""Transmissions: joint side <-> motor side, for plain and coupled (differential) joints.

Each motor turns ``gear_ratio`` times faster than its transmission input, and the inputs are the
coupling of the joint angles (``robot.coupling``; identity for independent joints, nursing eq 3
for a differential joint: ``phi1 = q1 + q2``, ``phi2 = -q1 + q2``)::

    wm = N qd,   with   N = diag(gear_ratio) @ coupling          (motor speeds, rad/s)

Power balance gives the torques: ``tau^T qd = tau_m^T wm`` for every ``qd``, so ::

    tau = N^T tau_m,    tau_m = N^-T tau

For a UR arm (``coupling = I``) this is UR5e eq 2's ``wm = i qd``, ``tau = i tau_m``. The motor
and reducer inertias (motor side) reflect to the joint side as ``N^T diag(J_m + J_r) N``: UR5e
eq 2's ``i^2 (J_m + J_r)`` on the diagonal, and nursing eq 4's ``J11 = J1 + J2, J12 = J1 - J2,
J22 = J1 + J2`` (motor-to-bevel-gear parts) for a differential joint. What is particular to
differential joints (their internal dynamics, currents to torques, Makkar's friction on either
side) is in :mod:`kinergy.drives.coupled`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.model.robot import Robot, transmission_matrix

__all__ = [
    "joint_torque",
    "motor_speed",
    "motor_torque",
    "reflected_inertia",
    "rotor_inertia",
    "transmission_matrix",
]


def rotor_inertia(robot: Robot) -> Array:
    """``J_m + J_r`` per motor, shape (n,), kg m^2, motor side (UR5e eq 9)."""
    return np.array([j.drive.rotor_inertia for j in robot.joints])


def motor_speed(robot: Robot, qd: ArrayLike) -> Array:
    """Motor speeds ``wm = N qd`` (rad/s), shape like ``qd`` ((n,) or (N, n))."""
    return np.asarray(qd, dtype=float) @ transmission_matrix(robot).T


def motor_torque(robot: Robot, tau: ArrayLike) -> Array:
    """Motor torques that produce joint torques ``tau``: ``tau_m = N^-T tau`` (N m), like ``tau``."""
    n_mat = transmission_matrix(robot)
    return np.linalg.solve(n_mat.T, np.asarray(tau, dtype=float).T).T


def joint_torque(robot: Robot, tau_m: ArrayLike) -> Array:
    """Joint torques from motor torques: ``tau = N^T tau_m`` (N m), shape like ``tau_m``."""
    return np.asarray(tau_m, dtype=float) @ transmission_matrix(robot)


def reflected_inertia(robot: Robot) -> Array:
    """Motor and reducer inertia seen at the joints, ``N^T diag(J_m + J_r) N``, (n, n), kg m^2.

    The joint-side torque it needs is ``reflected_inertia(robot) @ qdd`` (UR5e eq 2, second term).
    """
    n_mat = transmission_matrix(robot)
    return n_mat.T @ (rotor_inertia(robot)[:, None] * n_mat)
