"""A robot program (URScript's moves and events) as a batched function of its moves' timing.

The timing solver (:mod:`kinergy.optimize.solve`) sees a program through the durations ``t_k``
and ramp fractions ``f_k`` of its moves (:func:`kinergy.optimize.program.settings`). For a
resolved :class:`~kinergy.trajectory.program_path.ProgramPath` (movej, movel, movep, blends,
events of fixed time), :func:`sample_path_programs` plans B such programs
(:func:`kinergy.trajectory.program_motion.schedule_profiles`), samples them at Gauss-Legendre
nodes between all their switching times (each move's start, end of ramp, start of braking, end;
each event's start and end: :func:`kinergy.optimize.program.quadrature_nodes`) and runs the
drive model over every sample with the load the program has set there
(:func:`drive_by_payload`). :func:`grid_path_samples` gives a 500 Hz re-simulation the same
form, so one objective (:mod:`kinergy.optimize.objectives`) scores both.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.model.robot import Robot
from kinergy.optimize.program import (
    ProgramSamples,
    grid_weights,
    quadrature_nodes,
    samples_at,
    settings,
)
from kinergy.predict import drive_by_payload  # its home is the one forward path
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.program_motion import (
    LineTable,
    Schedule,
    payload_index,
    sample_path,
    schedule_profiles,
)
from kinergy.trajectory.program_path import ProgramPath

__all__ = ["drive_by_payload", "grid_path_samples", "path_schedule", "sample_path_programs"]


#: Gauss-Legendre sub-intervals per piece (the 500 Hz re-simulation makes the final figures)
_SUB = 2


def path_schedule(path: ProgramPath, t: Array, f: Array) -> Schedule:
    """B programs on ``path`` given their moves' durations ``t`` (s) and ramp fractions ``f``,
    shape (B, K) (:func:`kinergy.optimize.program.settings`)."""
    v, a, ramp = settings(path.travel, t, f)
    return schedule_profiles(path, t, ramp, v, a)


def _breaks(path: ProgramPath, sched: Schedule) -> Array:
    """Every switching time of B programs, sorted, shape (B, P)."""
    end = sched.start + sched.duration
    event_end = sched.event_start + path.event_time
    parts = [
        np.zeros((sched.start.shape[0], 1)),
        sched.start,
        sched.start + sched.ramp,
        end - sched.ramp,
        end,
        sched.event_start,
        event_end,
        sched.total[:, None],
    ]
    return np.sort(np.concatenate(parts, axis=1), axis=1)


def _samples(
    robot: Robot,
    path: ProgramPath,
    sched: Schedule,
    times: Array,
    weights: Array,
    valid: NDArray[np.bool_] | None,
    tables: dict[int, LineTable] | None = None,
) -> ProgramSamples:
    q, qd, qdd = sample_path(robot, path, sched, times, tables=tables)
    n = path.q0.size
    load = payload_index(path, sched, times).reshape(-1)
    drive = drive_by_payload(
        robot, path.payloads, load, q.reshape(-1, n), qd.reshape(-1, n), qdd.reshape(-1, n)
    )
    end = sched.start + sched.duration
    return samples_at(times, weights, sched.start, end, drive, valid)


def sample_path_programs(
    robot: Robot,
    path: ProgramPath,
    t: Array,
    f: Array,
    *,
    tables: dict[int, LineTable] | None = None,
) -> ProgramSamples:
    """B programs on ``path`` at the quadrature nodes, with the drive model.

    Parameters
    ----------
    robot : Robot
    path : ProgramPath
    t, f : ndarray, shape (B, K)
        Each program's move durations (s) and ramp fractions.
    tables : dict of int to LineTable, optional
        Lone tool moves sampled from their tables
        (:func:`kinergy.trajectory.program_motion.line_tables`).

    Returns
    -------
    ProgramSamples
        Gauss-Legendre nodes between every program's switching times; events count to the move
        before them.
    """
    sched = path_schedule(path, t, f)
    times, weights, valid = quadrature_nodes(_breaks(path, sched), sub=_SUB)
    return _samples(robot, path, sched, times, weights, valid, tables)


def grid_path_samples(
    robot: Robot, path: ProgramPath, sched: Schedule, motion: Motion
) -> ProgramSamples:
    """One program's samples on its time grid (a 500 Hz re-simulation, trapezoid weights)."""
    times = motion.t[None, :]
    return _samples(robot, path, sched, times, grid_weights(motion.t)[None, :], None)
