"""The optimiser: a robot program doing the same job with less energy, and where the robot
stands.

One program type (:class:`~kinergy.trajectory.robot_program.RobotProgram`: a URScript program,
or a task file's movej program), one set of levers (``levers``: ``2 pi`` wraps, configurations,
tool symmetry, via points, blends, timing), one timing solver (``timing`` on ``problem`` and
``solve``), one limit type (:class:`Caps` beside the robot's limits, ``constraints``), one 500 Hz
re-simulation (``verify``), one objective (``objectives``: the supply energy the model predicts)
and one result (:class:`ProgramOptimization`), entered by :func:`optimize_program`; the Pareto
front re-times its result at other cycle times (:func:`pareto_front`) and ``placement`` moves the
robot's base. Every solver stops on iterations and tolerances, never on a clock (:class:`Outcome`
says why it stopped).
"""

from __future__ import annotations

from kinergy.optimize.constraints import LIMIT_TOL, LimitCheck, limit_violations, torque_ratio
from kinergy.optimize.objectives import Objective, SupplyEnergy
from kinergy.optimize.options import Configurations, ProgramOptions, ToolSymmetry, ViaPoints
from kinergy.optimize.problem import Caps, TimingProblem
from kinergy.optimize.programs import (
    ParetoPoint,
    ProgramOptimization,
    optimize_program,
    pareto_front,
)
from kinergy.optimize.samples import ProgramSamples
from kinergy.optimize.solve import Outcome, Solution, solve_timing
from kinergy.optimize.verify import VERIFY_DT, ProgramResult, simulate_path

__all__ = [
    "LIMIT_TOL",
    "VERIFY_DT",
    "Caps",
    "Configurations",
    "LimitCheck",
    "Objective",
    "Outcome",
    "ParetoPoint",
    "ProgramOptimization",
    "ProgramOptions",
    "ProgramResult",
    "ProgramSamples",
    "Solution",
    "SupplyEnergy",
    "TimingProblem",
    "ToolSymmetry",
    "ViaPoints",
    "limit_violations",
    "optimize_program",
    "pareto_front",
    "simulate_path",
    "solve_timing",
    "torque_ratio",
]
