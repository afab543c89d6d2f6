"""kinergy: electro-mechanical models of robot arms from the logs their controllers write.

The public API at the top level::

    robot = kinergy.load_robot("ur5e")             # a built-in model, or a path to a file
    tau = kinergy.rnea(robot, q, qd, qdd)           # (N, n) joint torques, batched
    Y = kinergy.regressor(robot, q, qd, qdd)        # (N, n, 10 n)
    Y @ kinergy.inertial_parameters(robot)          # == tau
    motion = kinergy.movej(waypoints, speed=3.0, acceleration=6.0, dt=0.002)
    kinergy.energy(robot, motion).total_e_elec      # J
"""

from kinergy.dynamics import (
    BaseParameters,
    base_parameters,
    flange_pose,
    forward_dynamics,
    gravity_torque,
    inertial_parameters,
    jacobian,
    link_poses,
    mass_matrix,
    parameter_names,
    regressor,
    rnea,
)
from kinergy.energy.accounting import EnergyReport, energy
from kinergy.errors import KinergyError
from kinergy.model import Payload, Robot, library_names, load_robot, save_robot
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.movej import movej

__version__ = "0.1.0"

__all__ = [
    "BaseParameters",
    "EnergyReport",
    "KinergyError",
    "Motion",
    "Payload",
    "Robot",
    "__version__",
    "base_parameters",
    "energy",
    "flange_pose",
    "forward_dynamics",
    "gravity_torque",
    "inertial_parameters",
    "jacobian",
    "library_names",
    "link_poses",
    "load_robot",
    "mass_matrix",
    "movej",
    "parameter_names",
    "regressor",
    "rnea",
    "save_robot",
]
