"""Batched rigid-body kinematics and dynamics: forward kinematics, Jacobian, RNEA, mass matrix,
forward dynamics, the inertial-parameter regressor and the base parameter set."""

from kinergy.dynamics.kinematics import flange_pose, jacobian, link_poses
from kinergy.dynamics.regressor import (
    PARAMETER_NAMES,
    BaseParameters,
    base_parameters,
    inertial_parameters,
    parameter_names,
    regressor,
)
from kinergy.dynamics.rnea import forward_dynamics, gravity_torque, mass_matrix, rnea

__all__ = [
    "PARAMETER_NAMES",
    "BaseParameters",
    "base_parameters",
    "flange_pose",
    "forward_dynamics",
    "gravity_torque",
    "inertial_parameters",
    "jacobian",
    "link_poses",
    "mass_matrix",
    "parameter_names",
    "regressor",
    "rnea",
]
