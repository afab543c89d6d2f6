"""The ``kinergy place ROBOT PROGRAM.script`` pipeline: where the robot should stand.

:func:`run_place` reads a URScript program (:mod:`kinergy.io.urscript_reader`), searches the base
placements of a grid around today's (:func:`kinergy.optimize.placement.place_program`: each
checked for reach and optimised with every lever at today's cycle time), writes the best
placement's optimised program as URScript (its poses in the moved base frame, the user's names
and comments kept: :func:`kinergy.workflows.optimize.optimized_script`) and the energy
map (PNG, :func:`kinergy.report.placement.placement_map`) where asked, all or none and never over
the program. The written program is read back with kinergy's own reader and simulated again:
:attr:`PlaceRun.readback` is that energy, beside today's optimised program read back the same
way.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from kinergy.files import all_or_none, check_outputs
from kinergy.io.urscript import write_script
from kinergy.io.urscript_reader import parse_program, read_program
from kinergy.messages import Say
from kinergy.model.robot import Robot
from kinergy.optimize.options import ProgramOptions
from kinergy.optimize.placement import Candidate, PlacementGrid, PlacementSearch, place_program
from kinergy.optimize.programs import ProgramOptimization
from kinergy.optimize.verify import simulate_path
from kinergy.report.placement import placement_map
from kinergy.report.plots import save
from kinergy.trajectory.program_path import program_path
from kinergy.trajectory.robot_program import RobotProgram
from kinergy.workflows.optimize import optimized_script

__all__ = ["PlaceRun", "placed_script", "run_place"]


@dataclass(frozen=True, eq=False)
class PlaceRun:
    """What ``kinergy place`` found and wrote.

    Attributes
    ----------
    robot : Robot
    program : RobotProgram
        The program as read.
    search : PlacementSearch
    script : str
        The best placement's optimised program as URScript.
    readback : float
        Its supply energy, read back and simulated again, J.
    today_readback : float
        Today's optimised program written, read back and simulated again, J.
    written : list of Path
    """

    robot: Robot
    program: RobotProgram
    search: PlacementSearch
    script: str
    readback: float
    today_readback: float
    written: list[Path]

    @property
    def saving(self) -> float:
        """The best placement's written program against today's optimised one, both read back,
        0-1: what the placement saves beyond the program's levers, of what the arm draws from
        its supply (the motors and its standing draw over the cycle)."""
        return 1.0 - self.readback / self.today_readback

    def to_dict(self) -> dict[str, Any]:
        search = self.search
        today, best = search.today, search.best
        assert today.result is not None and best.result is not None
        return {
            "robot": self.robot.name,
            "task": self.program.name,
            "cycle_time": best.result.settings.cycle_time,
            "settings": best.result.settings.to_dict(),
            "today": _summary(today),
            "best": _summary(best),
            "today_readback_e_supply": self.today_readback,
            "best_readback_e_supply": self.readback,
            "saving_beyond_levers": self.saving,
            "saving_beyond_levers_motors": search.saving_motors,
            "candidates": [c.to_dict() for c in search.candidates],
            "written": [str(p) for p in self.written],
        }


def _summary(candidate: Candidate) -> dict[str, Any]:
    """A candidate with its program as written there and its optimum (levers and saving)."""
    out = candidate.to_dict()
    result = candidate.result
    if result is not None:
        out["e_program"] = result.program.result.e_supply
        out["e_program_motors"] = result.program.result.e_elec
        out["saving_by_levers"] = result.saving_supply
        out["saving_by_levers_motors"] = result.saving_motors
        out["levers"] = [lv.to_dict() for lv in result.levers]
        out["within_limits"] = result.optimized.result.ok
        out["targets_met"] = result.targets_met
    return out


def placed_script(search: PlacementSearch) -> str:
    """The best placement's optimised program as URScript, its header saying where the base
    stands and what the placement saves on today's optimum."""
    best = search.best
    assert best.result is not None
    text = optimized_script(best.result)
    lines = text.splitlines()
    at = next((i + 1 for i, line in enumerate(lines) if line.lstrip().startswith("def ")), 0)
    p = best.placement
    note = [
        f"  # kinergy place: the robot's base moved by x {p.x:+.3f} m, y {p.y:+.3f} m, "
        f"z {p.z:+.3f} m and turned {math.degrees(p.yaw):+.1f} deg about the vertical, in "
        "today's base frame; every pose below is in the moved base frame",
    ]
    saving = search.saving
    if saving is not None:
        note.append(
            f"  # {100 * saving:.1f} % less supply energy than today's placement with the same "
            "levers (model-predicted)"
        )
    lines[at:at] = note
    return "\n".join(lines) + "\n"


def _read_back(robot: Robot, script: str, name: str, result: ProgramOptimization) -> float:
    """Supply energy of a written program read back by kinergy's reader and simulated again."""
    back = parse_program(script, path=f"{name}.script", name=name)
    again = simulate_path(robot, program_path(robot, back), standby=result.settings.standby)
    return again.result.e_supply


def run_place(
    robot: Robot,
    program_file: str | os.PathLike[str],
    grid: PlacementGrid,
    *,
    options: ProgramOptions | None = None,
    urscript: str | os.PathLike[str] | None = None,
    plot: str | os.PathLike[str] | None = None,
    progress: Say | None = None,
) -> PlaceRun:
    """``kinergy place``: read, search the placements, read the best back, write.

    Raises
    ------
    KinergyError
        ``FILE:LINE: ...`` for a line that cannot be handled or a target today's base cannot
        reach; no candidate reaching every pose within every limit; an unwritable file.
    """
    source = Path(program_file)
    check_outputs([("--urscript", urscript), ("--plot", plot)], [source])
    program = read_program(source)
    search = place_program(robot, program, grid, options, progress=progress)
    assert search.best.result is not None and search.today.result is not None
    script = placed_script(search)
    readback = _read_back(robot, script, f"{source.stem}_placed", search.best.result)
    today_script = optimized_script(search.today.result)
    today_readback = _read_back(robot, today_script, f"{source.stem}_today", search.today.result)
    figure = None if plot is None else placement_map(search, title=f"{robot.name}, {program.name}")
    with all_or_none() as written:
        if figure is not None and plot is not None:
            written.append(save(figure, plot))
        if urscript is not None:
            written.append(write_script(urscript, script))
    return PlaceRun(robot, program, search, script, readback, today_readback, list(written))
