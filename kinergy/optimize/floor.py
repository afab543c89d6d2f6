"""Where a robot program's energy goes, per joint, and the share of it no lever can touch.

:func:`energy_floor` splits a re-simulated program (:class:`~kinergy.optimize.verify.
PathRun`) into the parts of :func:`kinergy.accounting.energy.part_powers` per joint (friction,
copper, gravity, inertial; framework Fig. 4) and sets beside them two figures that no timing,
blend or speed lever changes once the joint path is chosen:

- the friction floor of each joint: its motor turning through the same angle ``Theta_j`` (the
  joint's path length times its gear ratio) at one constant speed over all the program's moving
  time ``T_m`` (the cycle less its events), in the power-flow direction of the lower friction:
  ``Theta_j * tau_f,j(Theta_j / T_m) / (k_t/k_b)_j``. When the friction power ``wm tau_f(wm)`` is
  convex in the speed (Coulomb, viscous, power laws of exponent >= 0) and does not fall with the
  load, Jensen's inequality makes it a lower bound of the friction part over any timing of that
  path: a stop, a ramp or a faster move only adds to it;
- the copper loss of holding the arm against gravity along the same motion (UR5e eq 23 at zero
  speed and acceleration, each sample with the load the program sets there): an estimate, not a
  bound (friction and inertial torques can partly cancel gravity's).

Their sum over the program's own figure is how much of it the levers leave; one minus it bounds
(roughly) the saving any timing of the optimised path can reach.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from kinergy.accounting.energy import part_powers
from kinergy.arrays import Array
from kinergy.drives.electrics import friction_torques
from kinergy.drives.transmission import transmission_matrix
from kinergy.model.robot import Robot
from kinergy.optimize.verify import PathRun
from kinergy.predict import drive_by_payload
from kinergy.trajectory.program_motion import payload_index

__all__ = ["EnergyFloor", "energy_floor"]


#: load torque (motor side, N m) that sets the power-flow direction of the friction floor
_FLOW = 1e-9


@dataclass(frozen=True)
class EnergyFloor:
    """A program's energy per joint and part, and what no lever touches (module docstring).

    Attributes
    ----------
    path_length : ndarray, shape (n,)
        Each joint's path over the cycle, rad.
    parts : dict of str to ndarray, shape (n,)
        ``friction``, ``copper``, ``gravity``, ``inertial`` per joint, J.
    friction_floor : ndarray, shape (n,)
        The friction part at one constant speed over the moving time, J (a lower bound).
    holding_copper : float
        The copper loss of holding the arm against gravity along the motion, J (an estimate).
    moving_time : float
        The cycle less its events, s.
    """

    path_length: Array
    parts: dict[str, Array]
    friction_floor: Array
    holding_copper: float
    moving_time: float

    @property
    def untouched(self) -> float:
        """The friction floor plus the holding copper, J."""
        return float(self.friction_floor.sum()) + self.holding_copper

    def to_dict(self) -> dict[str, Any]:
        return {
            "path_length": self.path_length.tolist(),
            "parts": {k: v.tolist() for k, v in self.parts.items()},
            "friction_floor": self.friction_floor.tolist(),
            "holding_copper": self.holding_copper,
            "moving_time": self.moving_time,
            "untouched": self.untouched,
        }


def _friction_floor(robot: Robot, path_length: Array, moving_time: float) -> Array:
    """Each joint's friction part at one constant speed over ``moving_time``, J, shape (n,)."""
    ratio = np.abs(np.diag(transmission_matrix(robot)))
    theta = ratio * path_length  # motor turns, rad
    wm = (theta / max(moving_time, 1e-300))[None, :]
    zero = np.zeros_like(wm)
    tau = np.minimum(
        friction_torques(robot, wm, np.full_like(wm, _FLOW), zero),
        friction_torques(robot, wm, np.full_like(wm, -_FLOW), zero),
    )[0]
    kt_over_kb = np.array([j.drive.kt_over_kb for j in robot.joints])
    return np.asarray(theta * tau / kt_over_kb)


def energy_floor(robot: Robot, run: PathRun) -> EnergyFloor:
    """Per-joint parts, friction floor and holding copper of a re-simulated program.

    Parameters
    ----------
    robot : Robot
    run : PathRun
        The program at 500 Hz (:func:`kinergy.optimize.verify.simulate_path`).

    Returns
    -------
    EnergyFloor
    """
    motion, path = run.motion, run.path
    load = payload_index(path, run.schedule, motion.t)[0]  # (N,)
    state = drive_by_payload(path.robots, load, motion.q, motion.qd, motion.qdd)
    powers = part_powers(robot, state)
    parts = {k: np.asarray(np.trapezoid(p, motion.t, axis=0)) for k, p in powers.items()}
    still = np.zeros_like(motion.q)
    holding = drive_by_payload(path.robots, load, motion.q, still, still).power
    length = np.sum(np.abs(np.diff(motion.q, axis=0)), axis=0)
    moving = run.result.cycle_time - float(path.event_time.sum())
    return EnergyFloor(
        path_length=length,
        parts=parts,
        friction_floor=_friction_floor(robot, length, moving),
        holding_copper=float(np.trapezoid(holding.sum(axis=1), motion.t)),
        moving_time=moving,
    )
