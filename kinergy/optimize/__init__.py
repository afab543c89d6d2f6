"""Energy-optimal programs: the timing of movej tasks, the levers of URScript programs, and
where the robot stands.

``problem`` builds a :class:`TimingProblem` (arrays and callables), ``solve`` minimises its
objective (``objectives``: the electrical energy by default, pluggable) under the limits
(``constraints``) on the batched program model (``program``), ``verify`` re-simulates every result
at 500 Hz, and ``timing`` compares the program as written, uniform time scaling and the optimum at
one cycle time (:func:`optimize_timing`) or many (:func:`pareto_front`). A URScript program's
levers are in ``programs`` (options typed in ``options``: :class:`ProgramOptions`), the cell's
placement in ``placement``. Every solver stops on iterations and tolerances, never on a clock
(:class:`Outcome` says why it stopped).
"""

from __future__ import annotations

from kinergy.optimize.constraints import LIMIT_TOL, LimitCheck, limit_violations, torque_ratio
from kinergy.optimize.objectives import ElectricalEnergy, Objective, bus_power
from kinergy.optimize.options import Configurations, ProgramOptions, ToolSymmetry, ViaPoints
from kinergy.optimize.problem import (
    TimingProblem,
    joint_caps,
    program_settings,
    timing_problem,
    uniform_scaling,
)
from kinergy.optimize.program import ProgramSamples
from kinergy.optimize.solve import Outcome, Solution, solve_timing
from kinergy.optimize.timing import ParetoPoint, TimingResult, optimize_timing, pareto_front
from kinergy.optimize.verify import VERIFY_DT, ProgramResult, program_energy, simulate_program

__all__ = [
    "LIMIT_TOL",
    "VERIFY_DT",
    "Configurations",
    "ElectricalEnergy",
    "LimitCheck",
    "Objective",
    "Outcome",
    "ParetoPoint",
    "ProgramOptions",
    "ProgramResult",
    "ProgramSamples",
    "Solution",
    "TimingProblem",
    "TimingResult",
    "ToolSymmetry",
    "ViaPoints",
    "bus_power",
    "joint_caps",
    "limit_violations",
    "optimize_timing",
    "pareto_front",
    "program_energy",
    "program_settings",
    "simulate_program",
    "solve_timing",
    "timing_problem",
    "torque_ratio",
    "uniform_scaling",
]
