"""Energy accounting of a motion: where each joule drawn by the motors goes.

Per joint j (UR5e section 5):

- mechanical power ``P_mech = tau_m wm`` and energy ``E_mech = int P_mech dt`` (eq 25),
- electrical power ``W_elec = tau_m^2 / k_m^2 + (k_b / k_t) wm tau_m`` and ``E_elec = int W_elec dt``
  (eqs 23, 26),
- efficiency ``eta = E_mech / E_elec`` (eq 24), mean and peak electrical power.

The electrical energy splits exactly into four parts (framework Fig. 4): the motor torque is
``tau_m = tau_inertial + tau_gravity + tau_friction`` (motor side; inertial includes the
Coriolis/centrifugal terms and the rotor inertia), and ``W_elec`` is the copper loss
``tau_m^2 / k_m^2`` plus ``(k_b / k_t) wm tau_m``, linear in the torque, so::

    E_elec = E_inertial + E_gravity + E_friction + E_copper

where each motion part includes its share of the non-copper motor losses (the ``k_b / k_t`` factor).
Integrals run over each stretch of unbroken sampling (:mod:`kinergy.io.segments`), never
across a gap in the time stamps. They are signed by default, as in the seed: braking energy
returns to the DC bus and is counted negative. ``recovery=False`` clips negative power: per
joint for the joint figures, and on the summed bus power for the total (joints braking can still
feed joints driving; the supply takes nothing back).

What the arm draws from its supply -- the answer to "how much did it cost" -- is the report's
``supply`` (:mod:`kinergy.accounting.supply`): the joints' powers shared on the DC bus, the
surplus burnt in the shunt, plus standby. Where a log measured its supply, ``measured`` holds that
figure beside it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.integrate import trapezoid

from kinergy.accounting.figures import EnergyFigures
from kinergy.accounting.supply import MeasuredSupply, SupplyEnergy, supply_energy
from kinergy.arrays import Array
from kinergy.drives.transmission import transmission_matrix
from kinergy.io.segments import segment_bounds
from kinergy.model.robot import Robot
from kinergy.predict import DriveState, drive_state
from kinergy.trajectory.motion import Motion

__all__ = ["EnergyReport", "energy", "part_powers"]


BREAKDOWN = ("inertial", "gravity", "friction", "copper")


@dataclass(frozen=True, eq=False)
class EnergyReport:
    """Energy figures of one motion on one robot.

    Attributes
    ----------
    robot : str
    joints : list of str
    t : ndarray, shape (N,)
        s.
    p_mech, p_elec : ndarray, shape (N, n)
        Mechanical and electrical power per motor, W (clipped at 0 when ``recovery`` is False).
    e_mech, e_elec : ndarray, shape (n,)
        J, per joint.
    breakdown : dict of str to ndarray, shape (n,)
        ``inertial``, ``gravity``, ``friction``, ``copper`` parts of ``e_elec`` (signed integrals;
        with ``recovery`` False they no longer add up to the clipped ``e_elec``).
    part_power : dict of str to ndarray, shape (N, n)
        The electrical power of each part over time, W (framework Fig. 4).
    standby : float
        Energy of the robot's constant standby power over the motion, J.
    recovery : bool
        Whether braking energy was counted as returned to the bus.
    drive : DriveState
        The drive model's torques, currents, voltages over the motion.
    supply : SupplyEnergy
        What the arm draws from its supply (bus model; module docstring).
    measured : MeasuredSupply or None
        The supply energy the log measured, where it did.
    """

    robot: str
    joints: list[str]
    t: Array
    p_mech: Array
    p_elec: Array
    e_mech: Array
    e_elec: Array
    breakdown: dict[str, Array]
    part_power: dict[str, Array]
    standby: float
    total_e_mech: float
    total_e_elec: float
    recovery: bool
    drive: DriveState = field(repr=False)
    supply: SupplyEnergy
    measured: MeasuredSupply | None = None

    @property
    def duration(self) -> float:
        """Seconds sampled: the sum of the segments' durations (gaps left out)."""
        return float(sum(self.t[b - 1] - self.t[a] for a, b in segment_bounds(self.t)))

    @property
    def efficiency(self) -> Array:
        """Per joint ``E_mech / E_elec`` (UR5e eq 24); NaN where ``E_elec`` is 0."""
        return self.figures().efficiency

    @property
    def total_efficiency(self) -> float:
        """``sum E_mech / sum E_elec`` over the joints (standby excluded), the seed's eta."""
        return self.figures().total_efficiency

    def figures(self) -> EnergyFigures:
        """The report's figures without its time series (what ``energy`` prints)."""
        return EnergyFigures(
            robot=self.robot,
            joints=self.joints,
            duration=self.duration,
            span=float(self.t[-1] - self.t[0]),
            samples=int(self.t.size),
            segments=len(segment_bounds(self.t)),
            recovery=self.recovery,
            e_mech=self.e_mech,
            e_elec=self.e_elec,
            breakdown=self.breakdown,
            peak_power=np.max(self.p_elec, axis=0),
            bus_peak=float(np.max(self.p_elec.sum(axis=1))),
            rms_current=np.sqrt(np.mean(self.drive.current**2, axis=0)),
            peak_current=np.max(np.abs(self.drive.current), axis=0),
            standby=self.standby,
            total_e_mech=self.total_e_mech,
            total_e_elec=self.total_e_elec,
            supply=self.supply,
            measured=self.measured,
        )

    def to_dict(self) -> dict[str, Any]:
        """The ``energy --json`` shape of DESIGN.md (:meth:`EnergyFigures.to_dict`)."""
        return self.figures().to_dict()

    def measured_dict(self) -> dict[str, Any]:
        """The ``measured`` object of the JSON (:meth:`EnergyFigures.measured_dict`)."""
        return self.figures().measured_dict()


def part_powers(robot: Robot, state: DriveState) -> dict[str, Array]:
    """The electrical power of each part of the motor torque (framework Fig. 4), W, each
    (N, n): ``inertial``, ``gravity``, ``friction`` (motor side, each with its ``k_b / k_t``
    share) and ``copper`` (``W_elec`` minus those three); they add up to ``state.power``."""
    n_mat = transmission_matrix(robot)
    tau_gravity_m = np.linalg.solve(n_mat.T, state.tau_gravity.T).T
    tau_inertial_m = state.tau_load - tau_gravity_m
    kt_over_kb = np.array([j.drive.kt_over_kb for j in robot.joints])
    return {
        "inertial": state.wm * tau_inertial_m / kt_over_kb,
        "gravity": state.wm * tau_gravity_m / kt_over_kb,
        "friction": state.wm * state.tau_friction / kt_over_kb,
        "copper": state.power - state.wm * state.tau_m / kt_over_kb,
    }


def energy(
    robot: Robot,
    motion: Motion,
    *,
    recovery: bool = True,
    temperature: Array | None = None,
) -> EnergyReport:
    """Per-joint and total mechanical and electrical energy of ``motion`` (UR5e eqs 23-26).

    Parameters
    ----------
    robot : Robot
        The model (link data, payload, drives, friction, motor constants, standby power).
    motion : Motion
        Joint angles, speeds and accelerations over time.
    recovery : bool
        True (default, as the seed): signed integrals, braking energy returns to the bus.
        False: negative power is clipped (see the module docstring).
    temperature : ndarray, shape (N, n), optional
        Joint temperatures over the motion, deg C (a log's ``joint_temperatures``), for
        temperature-dependent friction.

    Returns
    -------
    EnergyReport
    """
    state = drive_state(robot, motion.q, motion.qd, motion.qdd, temperature=temperature)
    t = motion.t
    p_mech = state.p_mech
    p_elec = state.power
    pieces = segment_bounds(t)  # never integrate across a gap in the time stamps

    def integral(power: Array) -> Array:
        return np.asarray(
            sum(trapezoid(power[a:b], t[a:b], axis=0) for a, b in pieces), dtype=float
        )

    part_power = part_powers(robot, state)
    breakdown = {name: integral(power) for name, power in part_power.items()}
    if recovery:
        total_mech = float(integral(p_mech.sum(axis=1)[:, None])[0])
        total_elec = float(integral(p_elec.sum(axis=1)[:, None])[0])
    else:
        total_mech = float(integral(np.maximum(p_mech.sum(axis=1), 0.0)[:, None])[0])
        total_elec = float(integral(np.maximum(p_elec.sum(axis=1), 0.0)[:, None])[0])
        p_mech = np.maximum(p_mech, 0.0)
        p_elec = np.maximum(p_elec, 0.0)
    recorded = float(sum(t[b - 1] - t[a] for a, b in pieces))  # gaps excluded
    return EnergyReport(
        robot=robot.name,
        joints=robot.joint_names,
        t=t,
        p_mech=p_mech,
        p_elec=p_elec,
        e_mech=integral(p_mech),
        e_elec=integral(p_elec),
        breakdown=breakdown,
        part_power=part_power,
        standby=robot.standby_power * recorded,
        total_e_mech=total_mech,
        total_e_elec=total_elec,
        recovery=recovery,
        drive=state,
        supply=supply_energy(t, state.power, robot.standby_power),
    )
