"""Model + motion -> torques, currents, voltages and powers: the one forward path.

Energy accounting, validation, the twin and the optimiser all predict through
:func:`drive_state`. For a motion ``q, qd, qdd`` (joint side), UR5e sections 3-5:

1. link torques ``f_link`` by RNEA (eq 1), plus the motor and reducer inertia (eq 2):
   ``tau_sim = f_link + N^T diag(J_m + J_r) N qdd`` -- the controller's ``target_moment`` (eq 7);
2. motor side: ``wm = N qd`` and the torque the motor delivers to the load ``tau_load = N^-T tau_sim``
   (``tau_sim / i`` for a UR joint);
3. friction on the motor side (eqs 11-16, or the joint's model), whose power-flow direction is the
   sign of ``wm * tau_load``, at the joint temperatures when given (temperature-dependent models);
4. motor torque ``tau_m = tau_load + tau_f`` and current ``I = tau_m / k_t`` (eqs 10, 17, 20);
5. voltage ``V = R I + k_b wm`` (eq 19) and electrical power
   ``W = tau_m^2 / k_m^2 + (k_b / k_t) wm tau_m`` (eqs 21-23), with ``R = (k_t / k_m)^2`` and
   ``k_b = k_t / (k_t/k_b)``; a drive's ``winding_resistance``, when given, replaces ``R``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy.arrays import Array
from kinergy.drives.electrics import (
    back_emf_constants,
    electrical_power,
    friction_torques,
    torque_constants,
    winding_resistances,
)
from kinergy.drives.transmission import reflected_inertia, rotor_inertia, transmission_matrix
from kinergy.dynamics.chain import check_state
from kinergy.dynamics.rnea import gravity_torque, rnea
from kinergy.model.robot import Payload, Robot

__all__ = ["DriveState", "drive_by_payload", "drive_state", "payload_robots", "sensor_torque"]


@dataclass(frozen=True)
class DriveState:
    """Everything the drive model says about a motion; arrays of shape (N, n) unless noted.

    Attributes
    ----------
    tau_link : joint side, N m
        Rigid-body torques f_link (UR5e eq 1).
    tau_sim : joint side, N m
        ``f_link`` plus reflected motor and reducer inertia (UR5e eq 2; ``target_moment``, eq 7).
    tau_gravity : joint side, N m
        The gravity part of ``tau_link``.
    wm, dwm : motor side, rad/s and rad/s^2
        Motor speeds and accelerations.
    tau_load : motor side, N m
        Torque the motor delivers to the load: ``N^-T tau_sim``.
    tau_friction : motor side, N m
        Friction torque.
    tau_m : motor side, N m
        Motor torque ``tau_load + tau_friction`` (UR5e eq 17 times k_t).
    current, voltage : A, V
        UR5e eqs 17/20 and 19.
    power : W
        Electrical power per motor, eq 23; positive when drawn from the bus.
    """

    tau_link: Array
    tau_sim: Array
    tau_gravity: Array
    wm: Array
    dwm: Array
    tau_load: Array
    tau_friction: Array
    tau_m: Array
    current: Array
    voltage: Array
    power: Array

    @property
    def p_mech(self) -> Array:
        """Mechanical power of each motor ``tau_m * wm`` (UR5e eq 25 integrand), W."""
        return self.tau_m * self.wm


def drive_state(
    robot: Robot,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    *,
    wrench: ArrayLike | None = None,
    temperature: ArrayLike | None = None,
) -> DriveState:
    """Run the drive model over a motion (UR5e eqs 1-2, 10-23).

    Parameters
    ----------
    robot : Robot
    q, qd, qdd : array_like, shape (N, n) or (n,)
        Joint angles (rad), speeds (rad/s), accelerations (rad/s^2).
    wrench : array_like, shape (6,) or (N, 6), optional
        Wrench the flange exerts on its environment (see :func:`kinergy.rnea`).
    temperature : array_like, shape like ``q``, optional
        Joint temperatures, deg C (a log's ``joint_temperatures``), for temperature-dependent
        friction; without them such models take their reference temperature.

    Returns
    -------
    DriveState
        Arrays of shape (N, n) (a single sample gives N = 1).
    """
    _, s = check_state(robot, q=q, qd=qd, qdd=qdd)
    q_, qd_, qdd_ = s["q"], s["qd"], s["qdd"]
    tau_link = rnea(robot, q_, qd_, qdd_, wrench=wrench)
    tau_gravity = gravity_torque(robot, q_)
    tau_sim = tau_link + qdd_ @ reflected_inertia(robot).T
    n_mat = transmission_matrix(robot)
    wm = qd_ @ n_mat.T
    dwm = qdd_ @ n_mat.T
    tau_load = np.asarray(np.linalg.solve(n_mat.T, tau_sim.T).T, dtype=float)
    temp = None if temperature is None else np.broadcast_to(temperature, wm.shape).astype(float)
    tau_friction = friction_torques(robot, wm, tau_load, dwm, temp)
    tau_m = tau_load + tau_friction
    current = tau_m / torque_constants(robot)
    voltage = winding_resistances(robot) * current + back_emf_constants(robot) * wm
    power = electrical_power(robot, tau_m, wm)
    return DriveState(
        tau_link=tau_link,
        tau_sim=tau_sim,
        tau_gravity=tau_gravity,
        wm=wm,
        dwm=dwm,
        tau_load=tau_load,
        tau_friction=tau_friction,
        tau_m=tau_m,
        current=current,
        voltage=voltage,
        power=power,
    )


def sensor_torque(robot: Robot, state: DriveState) -> Array:
    """What each joint's torque sensor reads (``actual_joint_torque``), N m, shape like
    ``state.tau_m``.

    With ``N`` the transmission, ``J = J_m + J_r`` the rotor inertias (motor side), ``F`` the
    drives' friction (motor side, ``state.tau_friction``) and ``tau_link`` the links' rigid-body
    torques (RNEA)::

        motor side:  tau_s = N^T tau_m + offset
                           = tau_link + N^T diag(J) N qdd + N^T F + offset
        link side:   tau_s = tau_link + N^T F + offset

    A link-side sensor sits between the gear's output and the link: the rotor's inertia torque
    (UR5e eq 2's second term) is spent before the gear and never reaches it. The friction it
    sees is the joint's model, which a model identified from link-side torques holds as the
    friction between the sensor and the link (:class:`kinergy.model.robot.TorqueSensor`). The
    offset is the sensor's (no energy includes it).
    """
    n_mat = transmission_matrix(robot)
    rotor = (rotor_inertia(robot) * state.dwm) @ n_mat
    link = np.array([not j.torque_sensor.sees_rotor for j in robot.joints])
    offset = np.array([j.torque_sensor.offset for j in robot.joints])
    return np.asarray(state.tau_m @ n_mat - link * rotor + offset, dtype=float)


def drive_by_payload(
    robots: Sequence[Robot],
    load: NDArray[np.intp],
    q: Array,
    qd: Array,
    qdd: Array,
    *,
    temperature: Array | None = None,
) -> DriveState:
    """:func:`drive_state` at samples that carry different loads (a program's ``set_payload``, a
    log's ``payload`` column).

    Parameters
    ----------
    robots : sequence of Robot
        The robot carrying each load (:func:`payload_robots`; built once by whoever evaluates
        many motions with the same loads, as the optimiser does).
    load : ndarray of int, shape (N,)
        Index into ``robots`` of each sample's load.
    q, qd, qdd : ndarray, shape (N, n)
    temperature : ndarray, shape (N, n), optional
        As :func:`drive_state`'s.

    Returns
    -------
    DriveState
        Arrays of shape (N, n), each sample computed with its load.
    """
    used = np.unique(load)
    if used.size == 1:
        return drive_state(robots[int(used[0])], q, qd, qdd, temperature=temperature)
    parts = {}
    for i in used:
        m = load == i
        temp = None if temperature is None else temperature[m]
        parts[int(i)] = drive_state(robots[int(i)], q[m], qd[m], qdd[m], temperature=temp)
    out = {}
    for f in fields(DriveState):
        arr = np.zeros(np.shape(q))
        for i, state in parts.items():
            arr[load == i] = getattr(state, f.name)
        out[f.name] = arr
    return DriveState(**out)


def payload_robots(robot: Robot, payloads: Sequence[Payload | None]) -> tuple[Robot, ...]:
    """``robot`` carrying each of ``payloads`` (``None``: nothing at the flange), in order."""
    return tuple(robot if p is robot.payload else robot.with_payload(p) for p in payloads)
