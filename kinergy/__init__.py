"""kinergy: electro-mechanical models of robot arms from the logs their controllers write.

The public API at the top level mirrors the commands (:mod:`kinergy.api`, the one front door:
every command parses its flags into the typed options these functions take and calls them)::

    robot = kinergy.load_robot("ur10e")             # a built-in model, or a path to a file
    reading = kinergy.LogReading.parse(columns="timestamp,actual_q:6,...")  # how logs are read
    log = kinergy.read_log("run.csv", reading, robot=robot)
    result = kinergy.identify(["run.csv"], robot, reading=reading, out="my-ur10e.toml")
    report = kinergy.validate(result.robot, ["held-out.csv"], reading=reading)
    kinergy.energy(result.robot, "held-out.csv", reading=reading).supply.drawn   # J

and the dynamics underneath::

    tau = kinergy.rnea(robot, q, qd, qdd)           # (N, n) joint torques, batched
    Y = kinergy.regressor(robot, q, qd, qdd)        # (N, n, 10 n)
    Y @ kinergy.inertial_parameters(robot)          # == tau
    motion = kinergy.movej(waypoints, speed=3.0, acceleration=6.0, dt=0.002)
    kinergy.energy(robot, motion).total_e_elec      # J

Names are imported on first use, so ``import kinergy`` stays quick and a command loads only what
it needs.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from kinergy._version import __version__

#: public name -> module that defines it
_API = {
    "BaseParameters": "kinergy.dynamics.regressor",
    "base_parameters": "kinergy.dynamics.regressor",
    "inertial_parameters": "kinergy.dynamics.regressor",
    "parameter_names": "kinergy.dynamics.regressor",
    "regressor": "kinergy.dynamics.regressor",
    "flange_pose": "kinergy.dynamics.kinematics",
    "jacobian": "kinergy.dynamics.kinematics",
    "link_poses": "kinergy.dynamics.kinematics",
    "forward_dynamics": "kinergy.dynamics.rnea",
    "gravity_torque": "kinergy.dynamics.rnea",
    "mass_matrix": "kinergy.dynamics.rnea",
    "rnea": "kinergy.dynamics.rnea",
    "EnergyReport": "kinergy.accounting.energy",
    "energy": "kinergy.api",
    "identify": "kinergy.api",
    "identify_payload": "kinergy.api",
    "optimize_program": "kinergy.api",
    "read_log": "kinergy.api",
    "simulate": "kinergy.api",
    "validate": "kinergy.api",
    "LogReading": "kinergy.api",
    "IdentifyOptions": "kinergy.api",
    "EnergyOptions": "kinergy.api",
    "SimulateOptions": "kinergy.api",
    "ProgramOptions": "kinergy.api",
    "IdentificationResult": "kinergy.identification.result",
    "ValidationReport": "kinergy.identification.validation",
    "LogEnergy": "kinergy.workflows.energy",
    "Log": "kinergy.io.log",
    "KinergyError": "kinergy.errors",
    "Payload": "kinergy.model.robot",
    "Robot": "kinergy.model.robot",
    "library_names": "kinergy.model.library",
    "load_robot": "kinergy.model.library",
    "save_robot": "kinergy.model.toml",
    "Motion": "kinergy.trajectory.motion",
    "movej": "kinergy.trajectory.movej",
}

__all__ = [
    "BaseParameters",
    "EnergyOptions",
    "EnergyReport",
    "IdentificationResult",
    "IdentifyOptions",
    "KinergyError",
    "Log",
    "LogEnergy",
    "LogReading",
    "Motion",
    "Payload",
    "ProgramOptions",
    "Robot",
    "SimulateOptions",
    "ValidationReport",
    "__version__",
    "base_parameters",
    "energy",
    "flange_pose",
    "forward_dynamics",
    "gravity_torque",
    "identify",
    "identify_payload",
    "inertial_parameters",
    "jacobian",
    "library_names",
    "link_poses",
    "load_robot",
    "mass_matrix",
    "movej",
    "optimize_program",
    "parameter_names",
    "read_log",
    "regressor",
    "rnea",
    "save_robot",
    "simulate",
    "validate",
]

if TYPE_CHECKING:  # pragma: no cover - for type checkers and IDEs only
    from kinergy.accounting.energy import EnergyReport
    from kinergy.api import (
        EnergyOptions,
        IdentifyOptions,
        LogReading,
        ProgramOptions,
        SimulateOptions,
        energy,
        identify,
        identify_payload,
        optimize_program,
        read_log,
        simulate,
        validate,
    )
    from kinergy.dynamics.kinematics import flange_pose, jacobian, link_poses
    from kinergy.dynamics.regressor import (
        BaseParameters,
        base_parameters,
        inertial_parameters,
        parameter_names,
        regressor,
    )
    from kinergy.dynamics.rnea import forward_dynamics, gravity_torque, mass_matrix, rnea
    from kinergy.errors import KinergyError
    from kinergy.identification.result import IdentificationResult
    from kinergy.identification.validation import ValidationReport
    from kinergy.io.log import Log
    from kinergy.model.library import library_names, load_robot
    from kinergy.model.robot import Payload, Robot
    from kinergy.model.toml import save_robot
    from kinergy.trajectory.motion import Motion
    from kinergy.trajectory.movej import movej
    from kinergy.workflows.energy import LogEnergy


def __getattr__(name: str) -> Any:
    """Import a public name's module on first use (PEP 562)."""
    module = _API.get(name)
    if module is None:
        raise AttributeError(f"module 'kinergy' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
