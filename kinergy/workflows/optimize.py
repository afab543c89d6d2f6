"""The ``kinergy optimize`` pipeline: a task's energy-optimal timing, its Pareto front, files.

Given a model and a task (the waypoints of a movej program, :mod:`kinergy.io.task`),
:func:`optimize_task` finds the per-move ``v`` and ``a`` that minimise the model's electrical
energy at a cycle time (:func:`kinergy.optimize.optimize_timing`), compared with the program as
written and with uniform time scaling, all re-simulated at 500 Hz, and the Pareto front of energy
against cycle time (:func:`kinergy.optimize.pareto_front`). :func:`run_optimize` also loads the
task and writes the optimum as URScript (:func:`timing_script`) and the Pareto plot, all or none.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from kinergy.errors import KinergyError
from kinergy.files import all_or_none
from kinergy.io.task import Task, load_task
from kinergy.io.urscript import movej_program, write_script
from kinergy.model.robot import Robot
from kinergy.optimize import (
    ParetoPoint,
    TimingResult,
    optimize_timing,
    pareto_front,
    timing_problem,
)
from kinergy.report.plots import save, timing_pareto

__all__ = ["MAX_MOVES", "OptimizeRun", "optimize_task", "run_optimize", "timing_script"]


@dataclass(frozen=True, eq=False)
class OptimizeRun:
    """What ``kinergy optimize`` computed and wrote.

    Attributes
    ----------
    robot : Robot
    task : Task
    result : TimingResult
        The program, uniform scaling and the optimum at the cycle time.
    front : list of ParetoPoint
        Energy against cycle time (empty when not asked for).
    written : list of Path
        The files written (Pareto plot, URScript).
    """

    robot: Robot
    task: Task
    result: TimingResult
    front: list[ParetoPoint]
    written: list[Path]

    def to_dict(self) -> dict[str, Any]:
        """The ``optimize --json`` shape: the result, the robot's and task's names, the front."""
        out = self.result.to_dict()
        out["robot"] = self.robot.name
        out["task"] = self.task.name
        out["pareto"] = [p.to_dict() for p in self.front]
        return out


MAX_MOVES = 100
"""Most moves :func:`optimize_task` takes: a 30-move task costs about 40 s per timing on two
cores, so a 100-move task with the default Pareto front already runs for tens of minutes."""


def optimize_task(
    robot: Robot,
    task: Task,
    *,
    cycle_time: float | None = None,
    v_max: float | None = None,
    a_max: float | None = None,
    points: int = 8,
    share_budget: bool = True,
) -> tuple[TimingResult, list[ParetoPoint]]:
    """The energy-optimal timing of ``task`` at ``cycle_time`` (s; None: the program's own) and,
    with ``points`` >= 2, the Pareto front; one timing problem serves both.

    Raises
    ------
    KinergyError
        Prefixed with the task's name; a task of more than :data:`MAX_MOVES` moves.
    """
    if task.moves > MAX_MOVES:
        raise KinergyError(
            f"{task.name}: {task.moves} moves; the timing optimiser takes at most {MAX_MOVES} "
            "(each timing costs about 1.4 s per move on two cores; split the program)"
        )
    try:
        problem = timing_problem(
            robot, task.waypoints, blends=task.blends, v_max=v_max, a_max=a_max
        )
        result = optimize_timing(
            robot,
            task.waypoints,
            cycle_time=cycle_time,
            speeds=task.speeds,
            accels=task.accels,
            blends=task.blends,
            v_max=v_max,
            a_max=a_max,
            share_budget=share_budget,
            problem=problem,
        )
        front = []
        if points:
            front = pareto_front(
                robot,
                task.waypoints,
                points=points,
                speeds=task.speeds,
                accels=task.accels,
                blends=task.blends,
                v_max=v_max,
                a_max=a_max,
                share_budget=share_budget,
                problem=problem,
            )
    except KinergyError as exc:
        raise exc.prefixed(f"{task.name}") from None
    return result, front


def timing_script(robot: Robot, task: Task, result: TimingResult) -> str:
    """The optimum as a URScript movej program (the task's UR blend radii, if any)."""
    opt = result.optimized
    return movej_program(
        task.waypoints,
        opt.speeds,
        opt.accels,
        task.ur_blends if np.any(task.ur_blends > 0.0) else None,
        name="kinergy_" + "".join(c if c.isalnum() else "_" for c in task.name),
        cycle_time=opt.cycle_time,
        energy=opt.e_elec,
        comments=[
            f"{robot.name}, task {task.name}: {100 * result.saving:.1f} % less energy than "
            f"the program as written ({result.program.e_elec:.1f} J) at the same cycle time"
        ],
    )


def _write(
    robot: Robot,
    task: Task,
    timing: tuple[TimingResult, list[ParetoPoint]],
    urscript: str | os.PathLike[str] | None,
    plot: str | os.PathLike[str] | None,
) -> list[Path]:
    """Write the Pareto plot and the URScript where asked: all or none (no file is left behind
    when one fails). Returns the paths written."""
    result, front = timing
    script = None if urscript is None else timing_script(robot, task, result)
    figure = None if plot is None else timing_pareto(result, front)
    with all_or_none() as written:
        if figure is not None and plot is not None:
            written.append(save(figure, plot))
        if script is not None and urscript is not None:
            written.append(write_script(urscript, script))
    return written


def run_optimize(
    robot: Robot,
    task_name: str | os.PathLike[str],
    *,
    cycle_time: float | None = None,
    v_max: float | None = None,
    a_max: float | None = None,
    points: int = 8,
    share_budget: bool = True,
    urscript: str | os.PathLike[str] | None = None,
    plot: str | os.PathLike[str] | None = None,
) -> OptimizeRun:
    """``kinergy optimize``: load the task, optimise it (:func:`optimize_task`), write the
    URScript and the Pareto plot (PNG) where asked.

    Raises
    ------
    KinergyError
        A bad task, a cycle time below the fastest feasible, an unwritable file.
    """
    task = load_task(task_name, robot=robot)
    result, front = optimize_task(
        robot,
        task,
        cycle_time=cycle_time,
        v_max=v_max,
        a_max=a_max,
        points=points,
        share_budget=share_budget,
    )
    written = _write(robot, task, (result, front), urscript, plot)
    return OptimizeRun(robot, task, result, front, written)
