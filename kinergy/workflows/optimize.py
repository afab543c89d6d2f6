"""The ``kinergy optimize ROBOT PROGRAM`` pipeline: a program doing the same job with less energy.

:func:`read_any_program` reads a URScript program (``*.script``, :mod:`kinergy.io.urscript_reader`)
or a task (a task file or a built-in task, :mod:`kinergy.io.task`) into the one program type;
:func:`run_optimize` optimises it (:func:`kinergy.optimize.programs.optimize_program`), adds the
Pareto front where asked (:func:`kinergy.optimize.programs.pareto_front`), and writes where asked,
all or none and never over the program itself: the optimised program as URScript
(:func:`kinergy.io.urscript.program_script`: every line but the moves kept), the Pareto plot and
the two motions ``program.csv`` and ``optimized.csv`` (record.py layout, 500 Hz, ``timestamp``,
``target_q_*``, ``target_qd_*``, ``target_qdd_*``). The URScript written is read back with
kinergy's own reader and simulated again: :attr:`OptimizeRun.readback` is that energy.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from kinergy.errors import KinergyError
from kinergy.files import all_or_none, atomic_folder, check_outputs
from kinergy.io.rtde import write_log
from kinergy.io.task import load_task
from kinergy.io.urscript import move_statement, program_script, write_script
from kinergy.io.urscript_reader import parse_program, read_program
from kinergy.messages import Say
from kinergy.model.robot import Robot
from kinergy.optimize.options import ProgramOptions
from kinergy.optimize.programs import ProgramOptimization, optimize_program, pareto_front
from kinergy.optimize.verify import simulate_path
from kinergy.report.plots import save, timing_pareto
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.program_path import program_path
from kinergy.trajectory.robot_program import Move, RobotProgram

__all__ = ["OptimizeRun", "optimized_script", "read_any_program", "run_optimize"]


@dataclass(frozen=True, eq=False)
class OptimizeRun:
    """What ``kinergy optimize`` did with a program.

    Attributes
    ----------
    robot : Robot
    result : ProgramOptimization
    script : str
        The optimised program as URScript.
    readback : float
        The supply energy of ``script`` read back and simulated again, J.
    written : list of Path
    notes : tuple of str
        What reading the program assumed.
    """

    robot: Robot
    result: ProgramOptimization
    script: str
    readback: float
    written: list[Path]
    notes: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        out = self.result.to_dict()
        out["robot"] = self.robot.name
        out["task"] = self.result.program.path.program.name
        out["readback_e_supply"] = self.readback
        out["notes"] = list(self.notes)
        return out


def read_any_program(source: str | os.PathLike[str], robot: Robot) -> RobotProgram:
    """A URScript program (``*.script``) or a task (a task file or a built-in task) as the
    program the optimiser takes.

    Raises
    ------
    KinergyError
        ``FILE:LINE: ...`` or ``FILE: FIELD: ...``, one line.
    """
    if os.fspath(source).endswith(".script"):
        return read_program(source)
    return load_task(source, robot=robot)


def optimized_script(result: ProgramOptimization) -> str:
    """The optimised program as URScript, with a header saying what changed and its figures."""
    own, opt = result.program.result, result.optimized.result
    kept = [lv.name for lv in result.levers if lv.kept and lv.name not in ("program",)]
    options = result.settings.options
    header = [
        f"kinergy optimize: {100 * result.saving_supply:.1f} % less supply energy "
        f"(model-predicted; the motors' alone {100 * result.saving_motors:.1f} %) than the "
        f"program as written: {own.e_supply:.1f} J -> {opt.e_supply:.1f} J per cycle of "
        f"{opt.cycle_time:.3f} s",
        f"levers used: {', '.join(kept) or 'none'}; tool symmetry {options.tool_symmetry.value}, "
        f"configurations {options.configurations.value}, via points {options.via.value}",
    ]
    left = [c.line for c in result.targets if c.left_out]
    if left:
        header.append(
            "via points left out of the route (they take the joints of the target before "
            f"them): line{'s' if len(left) > 1 else ''} {', '.join(map(str, left))}"
        )
    written = result.written
    if written.lines or written.start is None:
        return program_script(written, header)
    # a task that starts elsewhere than it ends: to its start first, not part of the cycle
    first = Move("movej", written.start, pose=False, a=1.4, v=1.05)
    header.append(f"first to the task's start (not part of the cycle): {move_statement(first)}")
    return program_script(written, header)


def _motion_signals(motion: Motion) -> dict[str, Any]:
    return {"target_q": motion.q, "target_qd": motion.qd, "target_qdd": motion.qdd}


def _write(
    run: tuple[ProgramOptimization, str],
    urscript: str | os.PathLike[str] | None,
    motions: str | os.PathLike[str] | None,
    plot: str | os.PathLike[str] | None,
) -> list[Path]:
    """Write the URScript, the Pareto plot and the motions folder where asked: all or none."""
    result, script = run
    figure = None if plot is None else timing_pareto(result)
    with all_or_none() as written:
        if figure is not None and plot is not None:
            written.append(save(figure, plot))
        if urscript is not None:
            written.append(write_script(urscript, script))
        if motions is not None:
            with atomic_folder(motions) as folder:
                for name, run_ in (("program", result.program), ("optimized", result.optimized)):
                    write_log(folder / f"{name}.csv", run_.motion.t, _motion_signals(run_.motion))
            written += [Path(motions) / "program.csv", Path(motions) / "optimized.csv"]
    return written


def run_optimize(
    robot: Robot,
    source: str | os.PathLike[str],
    *,
    options: ProgramOptions | None = None,
    points: int = 0,
    urscript: str | os.PathLike[str] | None = None,
    motions: str | os.PathLike[str] | None = None,
    plot: str | os.PathLike[str] | None = None,
    progress: Say | Callable[[str], None] | None = None,
) -> OptimizeRun:
    """``kinergy optimize ROBOT PROGRAM``: read (:func:`read_any_program`), optimise with
    ``options`` (:func:`kinergy.optimize.programs.optimize_program`), the Pareto front at
    ``points`` cycle times (0: none), read the result back, write.

    Raises
    ------
    KinergyError
        ``FILE:LINE: ...`` for a line that cannot be handled, a target out of reach or outside
        the joint limits, a cycle time shorter than the fastest possible; a Pareto plot without
        a front; an unwritable file.
    """
    inputs = [Path(source)] if Path(source).exists() else []
    check_outputs([("--urscript", urscript), ("--motions", motions), ("--plot", plot)], inputs)
    if plot is not None and points < 2:
        raise KinergyError("--plot: needs a Pareto front (--pareto-points of at least 2)")
    program = read_any_program(source, robot)
    result = optimize_program(robot, program, options, progress=progress)
    if points:
        result = replace(
            result, pareto=pareto_front(robot, result, points=points, progress=progress)
        )
    script = optimized_script(result)
    stem = Path(program.path).stem if program.path else program.name
    back = parse_program(script, path=f"{stem}_optimized.script", name=program.name)
    again = simulate_path(robot, program_path(robot, back), standby=result.settings.standby)
    written = _write((result, script), urscript, motions, plot)
    return OptimizeRun(robot, result, script, again.result.e_supply, written, program.notes)
