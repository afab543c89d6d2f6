"""The commands that cut a program's energy, as functions: ``optimize_program``."""

from __future__ import annotations

import os

from kinergy.api.common import PathLike, RobotLike, robot_of
from kinergy.errors import KinergyError
from kinergy.files import check_replaceable
from kinergy.optimize.options import Configurations, ProgramOptions, ToolSymmetry, ViaPoints
from kinergy.workflows.optimize import OptimizeRun, run_optimize
from kinergy.workflows.optimize_program import ProgramRun, run_program_optimize

__all__ = ["optimize_program"]


def optimize_program(
    model: RobotLike,
    program: PathLike,
    *,
    configurations: str = "keep",
    tool_symmetry: str = "none",
    via: str = "keep",
    blends: bool = True,
    standby: float | None = None,
    cycle_time: float | None = None,
    v_max: float | None = None,
    a_max: float | None = None,
    urscript: PathLike | None = None,
) -> ProgramRun | OptimizeRun:
    """``kinergy optimize``: the same job with less energy from the supply, at the same cycle
    time (``cycle_time``, s: another; None: the program's own).

    ``program``: a URScript program (``*.script``: the levers ``configurations`` (``keep`` or
    ``free``), ``tool_symmetry`` (``none``, ``z``, ``z2``, ``z4``), ``via`` (``keep`` or
    ``free``), ``blends`` and the timing, judged by the supply energy with ``standby`` W; a
    :class:`~kinergy.workflows.optimize_program.ProgramRun`), or a task file or built-in task
    (``"test-a"``, ``"test-b"``: the timing only; an
    :class:`~kinergy.workflows.optimize.OptimizeRun`). ``v_max`` (rad/s) and ``a_max``
    (rad/s²) cap every joint (None: a program's own peaks; a task: the robot's limits).
    ``urscript``: write the optimised program there.

    Raises
    ------
    KinergyError
        One line naming the option or the program's line at fault.
    """
    r = robot_of(model)
    if urscript is not None:
        check_replaceable(urscript)
    if os.fspath(program).endswith(".script"):
        options = ProgramOptions(
            configurations=Configurations.parse(configurations),
            tool_symmetry=ToolSymmetry.parse(tool_symmetry),
            via=ViaPoints.parse(via),
            blends=blends,
            standby=standby,
            cycle_time=cycle_time,
            v_max=v_max,
            a_max=a_max,
        )
        return run_program_optimize(r, program, urscript=urscript, options=options)
    levers = {
        "configurations": configurations != "keep",
        "tool_symmetry": tool_symmetry != "none",
        "via": via != "keep",
        "blends": not blends,
        "standby": standby is not None,
    }
    for name, given in levers.items():
        if given:
            raise KinergyError(
                f"{name}: only for a URScript program (*.script); {program} is a task, whose "
                "timing alone is optimised"
            )
    return run_optimize(
        r, program, cycle_time=cycle_time, v_max=v_max, a_max=a_max, points=0, urscript=urscript
    )
