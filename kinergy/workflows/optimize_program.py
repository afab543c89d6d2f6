"""The ``kinergy optimize ROBOT PROGRAM.script`` pipeline: an energy-optimal URScript program.

:func:`run_program_optimize` reads a URScript program (:mod:`kinergy.io.urscript_reader`),
optimises its path and timing (:func:`kinergy.optimize.programs.optimize_program`), and writes
where asked, all or none and never over the program itself: the optimised program as URScript
(:func:`kinergy.io.urscript.program_script`: every line but the moves kept) and the two motions
``program.csv`` and ``optimized.csv`` (record.py layout, 500 Hz, ``timestamp``, ``target_q_*``,
``target_qd_*``, ``target_qdd_*``). The URScript written is read back with kinergy's own reader
and simulated again: :attr:`ProgramRun.readback` is that energy.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from kinergy.arrays import Array
from kinergy.files import all_or_none, atomic_folder, check_outputs
from kinergy.io.rtde import write_log
from kinergy.io.urscript import program_script, write_script
from kinergy.io.urscript_reader import parse_program, read_program
from kinergy.model.robot import Robot
from kinergy.optimize.objectives import PROGRAM_OBJECTIVE
from kinergy.optimize.options import ProgramOptions
from kinergy.optimize.program_verify import simulate_path
from kinergy.optimize.programs import ProgramOptimization, optimize_program, supply
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.program_path import program_path

__all__ = ["ProgramRun", "optimized_script", "run_program_optimize"]


@dataclass(frozen=True, eq=False)
class ProgramRun:
    """What ``kinergy optimize`` did with a URScript program.

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


def optimized_script(result: ProgramOptimization) -> str:
    """The optimised program as URScript, with a header saying what changed and its figures."""
    own, opt = result.program.result, result.optimized.result
    kept = [lv.name for lv in result.levers if lv.kept and lv.name not in ("program",)]
    options = result.settings.options
    header = [
        f"kinergy optimize: {100 * result.saving:.1f} % less supply energy (model-predicted) "
        f"than the program as written: {own.score:.1f} J -> {opt.score:.1f} J per cycle of "
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
    return program_script(result.written, header)


def _motion_signals(motion: Motion) -> dict[str, Array]:
    return {"target_q": motion.q, "target_qd": motion.qd, "target_qdd": motion.qdd}


def _write(
    run: tuple[ProgramOptimization, str],
    urscript: str | os.PathLike[str] | None,
    motions: str | os.PathLike[str] | None,
) -> list[Path]:
    """Write the URScript and the motions folder where asked: all or none."""
    result, script = run
    with all_or_none() as written:
        if urscript is not None:
            written.append(write_script(urscript, script))
        if motions is not None:
            with atomic_folder(motions) as folder:
                for name, run_ in (("program", result.program), ("optimized", result.optimized)):
                    write_log(folder / f"{name}.csv", run_.motion.t, _motion_signals(run_.motion))
            written += [Path(motions) / "program.csv", Path(motions) / "optimized.csv"]
    return written


def run_program_optimize(
    robot: Robot,
    program_file: str | os.PathLike[str],
    *,
    urscript: str | os.PathLike[str] | None = None,
    motions: str | os.PathLike[str] | None = None,
    options: ProgramOptions | None = None,
    progress: Callable[[str], None] | None = None,
) -> ProgramRun:
    """``kinergy optimize ROBOT PROGRAM.script``: read, optimise with ``options``
    (:func:`kinergy.optimize.programs.optimize_program`), read the result back, write.

    Raises
    ------
    KinergyError
        ``FILE:LINE: ...`` for a line that cannot be handled, a target out of reach or outside
        the joint limits, a cycle time shorter than the fastest possible; an unwritable file.
    """
    source = Path(program_file)
    check_outputs([("--urscript", urscript), ("--motions", motions)], [source])
    program = read_program(source)
    result = optimize_program(robot, program, options, progress=progress)
    script = optimized_script(result)
    back = parse_program(script, path=f"{source.stem}_optimized.script", name=program.name)
    again = simulate_path(
        robot,
        program_path(robot, back),
        objective=PROGRAM_OBJECTIVE(result.settings.standby),
    )
    readback = supply(again.result)
    written = _write((result, script), urscript, motions)
    return ProgramRun(robot, result, script, readback, written, program.notes)
