"""The commands that cut a program's energy, as functions: ``optimize_program``, ``place``."""

from __future__ import annotations

import os

from kinergy.api.common import PathLike, Progress, RobotLike, robot_of
from kinergy.checks import integer
from kinergy.errors import KinergyError
from kinergy.files import check_replaceable
from kinergy.messages import as_say
from kinergy.optimize.options import ProgramOptions
from kinergy.optimize.placement import PlacementGrid
from kinergy.workflows.optimize import OptimizeRun, run_optimize
from kinergy.workflows.optimize_program import ProgramRun, run_program_optimize
from kinergy.workflows.place import PlaceRun, run_place

__all__ = ["MAX_POINTS", "TASK_POINTS", "optimize_program", "place"]

#: a task's Pareto front: the cycle times it has unless told, and the most it may have
TASK_POINTS = 8
MAX_POINTS = 50


def _for_a_task(program: PathLike, options: ProgramOptions, motions: PathLike | None) -> None:
    """Refuse a lever only a URScript program takes, asked of a task (it would go unused)."""
    given = options.levers() + (["--motions"] if motions is not None else [])
    if given:
        raise KinergyError(
            f"{given[0]}: only for a URScript program (*.script); {os.fspath(program)} is a task, "
            "whose timing alone is optimised"
        )


def _for_a_program(
    program: PathLike, points: int | None, share_budget: bool, plot: PathLike | None
) -> None:
    """Refuse what only a task takes (its Pareto front), asked of a URScript program."""
    for flag, given in (
        ("--pareto-points", bool(points)),
        ("--fixed-shares", not share_budget),
        ("--plot", plot is not None),
    ):
        if given:
            raise KinergyError(
                f"{flag}: only for a task (the Pareto front of its timing); "
                f"{os.fspath(program)} is a URScript program"
            )


def optimize_program(
    model: RobotLike,
    program: PathLike,
    options: ProgramOptions | None = None,
    *,
    points: int | None = None,
    share_budget: bool = True,
    urscript: PathLike | None = None,
    motions: PathLike | None = None,
    plot: PathLike | None = None,
    progress: Progress | None = None,
) -> ProgramRun | OptimizeRun:
    """``kinergy optimize``: the same job with less energy, at the cycle time
    ``options.cycle_time`` (None: the program's own) within the caps ``options.v_max``,
    ``options.a_max``.

    ``program``: a URScript program (``*.script``: the levers of ``options`` and the timing,
    judged by the supply energy with standby; a :class:`ProgramRun`; ``motions``: a folder for
    its 500 Hz motions as written and optimised), or a task file or built-in task
    (``"test-a"``, ``"test-b"``: the timing only, by the motors' electrical energy; an
    :class:`OptimizeRun` with a Pareto front of ``points`` cycle times, 0 to
    :data:`MAX_POINTS`, default :data:`TASK_POINTS`, drawn to ``plot``; ``share_budget``
    False keeps each move's share of the cycle time). ``urscript``: write the optimised
    program there.

    Raises
    ------
    KinergyError
        An option the kind of ``program`` does not take, one line naming the option or the
        program's line at fault.
    """
    options = options or ProgramOptions()
    for path in (urscript, plot):
        if path is not None:
            check_replaceable(path)
    r = robot_of(model)
    if os.fspath(program).endswith(".script"):
        _for_a_program(program, points, share_budget, plot)
        return run_program_optimize(
            r, program, urscript=urscript, motions=motions, options=options, progress=progress
        )
    _for_a_task(program, options, motions)
    count = (
        TASK_POINTS if points is None else integer(points, "--pareto-points", ge=0, le=MAX_POINTS)
    )
    if plot is not None and count < 2:
        raise KinergyError("--plot: needs a Pareto front (--pareto-points of at least 2)")
    if progress is not None:
        progress(
            f"optimising the timing of {os.fspath(program)}"
            + (f" and {count} Pareto points" if count else "")
        )
    return run_optimize(
        r,
        program,
        cycle_time=options.cycle_time,
        v_max=options.v_max,
        a_max=options.a_max,
        points=count,
        share_budget=share_budget,
        urscript=urscript,
        plot=plot,
    )


def place(
    robot: RobotLike,
    program: PathLike,
    grid: PlacementGrid,
    options: ProgramOptions | None = None,
    *,
    urscript: PathLike | None = None,
    plot: PathLike | None = None,
    progress: Progress | None = None,
) -> PlaceRun:
    """``kinergy place``: the URScript ``program``'s supply energy over the base placements of
    ``grid`` around today's (each candidate checked for reach and optimised with the levers of
    ``options`` at today's cycle time within today's caps); the best's optimised program
    written to ``urscript``, the energy map to ``plot``.

    Raises
    ------
    KinergyError
        A program line that cannot be handled, no candidate reaching every pose within every
        limit.
    """
    for path in (urscript, plot):
        if path is not None:
            check_replaceable(path)
    return run_place(
        robot_of(robot), program, grid, options=options, urscript=urscript, plot=plot,
        progress=as_say(progress),
    )  # fmt: skip
