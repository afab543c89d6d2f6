"""The commands that cut a program's energy, as functions: ``optimize_program``, ``place``."""

from __future__ import annotations

from kinergy.api.common import PathLike, Progress, RobotLike, robot_of
from kinergy.checks import integer
from kinergy.files import check_replaceable
from kinergy.messages import as_say
from kinergy.optimize.options import ProgramOptions
from kinergy.optimize.placement import PlacementGrid
from kinergy.workflows.optimize import OptimizeRun, run_optimize
from kinergy.workflows.place import PlaceRun, run_place

__all__ = ["MAX_POINTS", "PLOT_POINTS", "optimize_program", "place"]

#: the Pareto front's cycle times with a plot unless told, and the most it may have
PLOT_POINTS = 8
MAX_POINTS = 50


def optimize_program(
    model: RobotLike,
    program: PathLike,
    options: ProgramOptions | None = None,
    *,
    points: int | None = None,
    urscript: PathLike | None = None,
    motions: PathLike | None = None,
    plot: PathLike | None = None,
    progress: Progress | None = None,
) -> OptimizeRun:
    """``kinergy optimize``: the same job with less energy, at the cycle time
    ``options.cycle_time`` (None: the program's own) within the caps ``options.v_max``,
    ``options.a_max`` (None: the program's own peaks).

    ``program``: a URScript program (``*.script``), a task file or a built-in task
    (``"test-a"``, ``"test-b"``), all read into the one program type and optimised the same
    way (:func:`kinergy.workflows.optimize.run_optimize`: the levers of ``options`` and the
    timing, judged by the supply energy with the standing draw). ``points``: cycle times on the
    Pareto front, 0 to :data:`MAX_POINTS` (default :data:`PLOT_POINTS` with ``plot``, else 0),
    drawn to ``plot``; ``urscript``: write the optimised program there; ``motions``: a folder
    for its 500 Hz motions as written and optimised.

    Raises
    ------
    KinergyError
        A bad option, one line naming it; the program's line at fault.
    """
    for path in (urscript, plot):
        if path is not None:
            check_replaceable(path)
    default = PLOT_POINTS if plot is not None else 0
    count = default if points is None else integer(points, "--pareto-points", ge=0, le=MAX_POINTS)
    return run_optimize(
        robot_of(model), program, options=options, points=count, urscript=urscript,
        motions=motions, plot=plot, progress=progress,
    )  # fmt: skip


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
