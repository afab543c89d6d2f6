"""The commands that design motions and run the digital twin, as functions: ``simulate``,
``excite``, ``nursing_study``, ``demo``."""

from __future__ import annotations

from pathlib import Path

from kinergy.api.common import PathLike, Progress, RobotLike, robot_of
from kinergy.files import atomic_write, check_replaceable
from kinergy.jsonable import dumps
from kinergy.logs.reading import LogReading
from kinergy.trajectory.motion import Motion
from kinergy.twin import Mismatch
from kinergy.workflows.demo import DemoRun, run_demo
from kinergy.workflows.excite import ExciteOptions, ExciteRun, run_excite
from kinergy.workflows.nursing import NursingStudy, NursingStudyOptions
from kinergy.workflows.nursing import nursing_study as run_nursing_study
from kinergy.workflows.twin import SimulateOptions, Simulation, run_twin

__all__ = ["demo", "excite", "nursing_study", "simulate"]


def simulate(
    robot: RobotLike,
    trajectory: PathLike | Motion = "test-a",
    options: SimulateOptions | None = None,
    *,
    reading: LogReading | None = None,
    out: PathLike | None = None,
    truth_out: PathLike | None = None,
) -> Simulation:
    """``kinergy simulate``: the log the digital twin of ``robot`` writes running ``trajectory``
    (``"test-a"``, ``"test-b"`` planned on ``robot``, a :class:`Motion`, a motion file or a
    URScript program read as ``reading`` says), with the truth, lag and noise of ``options``;
    written to ``out`` (record.py layout) when given, the twin's true robot to ``truth_out``.

    Raises
    ------
    KinergyError
        An unknown trajectory, a motion file that fails its checks, ``truth_out`` without the
        realistic mismatch.
    """
    r = robot_of(robot)
    for path in (out, truth_out):
        if path is not None:
            check_replaceable(path)
    return run_twin(
        r, trajectory, options or SimulateOptions(), reading=reading, out=out, truth_out=truth_out
    )


def excite(
    robot: RobotLike, options: ExciteOptions, *, progress: Progress | None = None
) -> ExciteRun:
    """``kinergy excite``: an excitation for identification designed for ``robot`` (nursing eqs
    22-23: a Fourier series at rest at both ends, within the joint, speed, acceleration and
    floor limits, minimising the condition number of the stacked base regressor), written to
    ``options.out`` (and ``options.urscript``); ``progress`` is told every few iterations.

    Raises
    ------
    KinergyError
        Options ``robot`` cannot take (a start pose of another joint count, URScript for an arm
        that is not a 6-joint UR), a start pose outside the limits.
    """
    for path in (options.out, options.urscript):
        if path is not None:
            check_replaceable(path)
    return run_excite(robot_of(robot), options, progress=progress)


def nursing_study(
    robot: RobotLike = "nursing-arm",
    options: NursingStudyOptions | None = None,
    *,
    out: PathLike | None = None,
    progress: Progress | None = None,
) -> NursingStudy:
    """``kinergy nursing``: the nursing doc's identification (friction runs, Makkar fits by
    particle swarm and least squares, ridge regression of the minimal set) run on ``robot``'s
    twin; written to ``out`` as JSON (:meth:`NursingStudy.to_dict`) when given."""
    if out is not None:
        check_replaceable(out)
    study = run_nursing_study(robot_of(robot), options, progress=progress)
    if out is not None:
        atomic_write(out, lambda fh: fh.write(dumps(study.to_dict()) + "\n"))
    return study


def demo(
    out: PathLike | None = None,
    *,
    mismatch: Mismatch | str = Mismatch.REALISTIC,
    progress: Progress | None = None,
) -> DemoRun:
    """``kinergy demo``: the UR5e study on the built-in twin (simulate tests A and B, identify
    on A, validate on A and B, the energy, UR5e Tables IV-VIII and the twin's truth against the
    identified values), written with its report into the folder ``out`` (replaced whole; None:
    a new folder in the system's temporary folder). ``mismatch``: ``realistic`` (the twin's
    truth differs from the model identified) or ``none``."""
    return run_demo(None if out is None else Path(out), progress, mismatch=mismatch)
