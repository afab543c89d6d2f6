"""A robot program in time: when each move and event runs, and the joint motion at any time.

Given a resolved :class:`~kinergy.trajectory.program_path.ProgramPath` and each move's ``v`` and
``a``, :func:`schedule` plans every move's trapezoid (:func:`kinergy.trajectory.movej.
trapezoid_timing`: the leading joint's for a movej, the path length's for a tool move), their
start times (:func:`kinergy.trajectory.movej.blend_starts`: blends, and the events' fixed times
between moves) and when each event runs. :func:`sample_path` gives the joints of B such programs
at any times, batched for the optimiser: joint-space moves add their displacements along the
leading joint's profile (:func:`kinergy.trajectory.movej.trapezoid`), each run of blended tool
moves puts the tool on its lines (:mod:`kinergy.trajectory.movel`). :func:`program_motion`
samples one program at the controller's 500 Hz.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy.arrays import Array
from kinergy.model.robot import Robot
from kinergy.trajectory.motion import CONTROLLER_DT, Motion
from kinergy.trajectory.movej import blend_starts, trapezoid, trapezoid_timing
from kinergy.trajectory.movel import ToolSegment, joints_on_path, tool_motion
from kinergy.trajectory.program_path import ProgramPath

__all__ = [
    "Schedule",
    "payload_index",
    "program_motion",
    "sample_path",
    "schedule",
    "schedule_profiles",
    "tool_runs",
]


@dataclass(frozen=True, eq=False)
class Schedule:
    """When B programs' moves and events run (all arrays have B rows).

    Attributes
    ----------
    start, duration, ramp, peak, accel : ndarray, shape (B, K)
        Each move's start (s), duration (s), ramp time (s), peak speed and acceleration (in the
        move's own unit per s and s^2).
    event_start : ndarray, shape (B, E)
        s.
    total : ndarray, shape (B,)
        The program's time from its start to the end of its last move or event, s.
    """

    start: Array
    duration: Array
    ramp: Array
    peak: Array
    accel: Array
    event_start: Array
    total: Array


def schedule_profiles(
    path: ProgramPath, duration: Array, ramp: Array, peak: Array, accel: Array
) -> Schedule:
    """Plan B programs on ``path`` from their moves' profiles, each of shape (B, K): duration
    (s), ramp time (s), peak speed and acceleration (the move's unit per s and s^2)."""
    start = blend_starts(
        path.travel, path.blend, duration, accel, ramp, linked=path.linked, gaps=path.gaps
    )
    end = start + duration
    rows = duration.shape[0]
    event_start = np.zeros((rows, path.event_time.size))
    clock: dict[int, Array] = {}
    for e, (after, time) in enumerate(zip(path.event_after, path.event_time, strict=True)):
        begin = clock.get(int(after), np.zeros(rows) if after < 0 else end[:, after])
        event_start[:, e] = begin
        clock[int(after)] = begin + time
    total = end[:, -1] + path.tail
    return Schedule(start, duration, ramp, peak, accel, event_start, total)


def schedule(path: ProgramPath, speed: ArrayLike, accel: ArrayLike) -> Schedule:
    """Plan B programs on ``path`` at per-move ``v`` and ``a``, shape (B, K) or (K,)
    (:func:`kinergy.trajectory.movej.trapezoid_timing`; a move that does not move lasts 0 s)."""
    v = np.atleast_2d(np.asarray(speed, dtype=float))
    a = np.atleast_2d(np.asarray(accel, dtype=float))
    v, a = np.broadcast_arrays(v, a)
    duration, ramp, peak = trapezoid_timing(path.travel, v, a)
    still = path.travel <= 0.0
    return schedule_profiles(
        path,
        duration,
        np.where(still, 0.0, ramp),
        np.where(still, 0.0, peak),
        np.where(still, 0.0, np.asarray(a, dtype=float)),
    )


def tool_runs(path: ProgramPath) -> list[list[int]]:
    """The runs of consecutive tool moves joined by blends (each a list of move indices)."""
    runs: list[list[int]] = []
    for k, seg in enumerate(path.tool):
        if seg is None:
            continue
        if runs and runs[-1][-1] == k - 1 and path.linked[k - 1]:
            runs[-1].append(k)
        else:
            runs.append([k])
    return runs


def _profiles(sched: Schedule, t: Array, k: int) -> tuple[Array, Array, Array]:
    """Move k's distance, speed and acceleration at times ``t`` (B, M)."""
    return trapezoid(
        t - sched.start[:, k : k + 1],
        sched.duration[:, k : k + 1],
        sched.ramp[:, k : k + 1],
        sched.peak[:, k : k + 1],
        sched.accel[:, k : k + 1],
    )


def _tool_run(
    robot: Robot, path: ProgramPath, sched: Schedule, t: Array, run: list[int]
) -> tuple[Array, Array, Array]:
    """The joint displacement, speed and acceleration a run of tool moves adds, (B, M, n)."""
    first, last = run[0], run[-1]
    q_a = path.q_start[first]
    shape = (*t.shape, q_a.size)
    dq, dqd, dqdd = np.zeros(shape), np.zeros(shape), np.zeros(shape)
    dq[:] = np.where(
        (t >= sched.start[:, last : last + 1] + sched.duration[:, last : last + 1])[..., None],
        path.q_end[last] - q_a,
        0.0,
    )
    active = (t > sched.start[:, first : first + 1]) & (
        t < sched.start[:, last : last + 1] + sched.duration[:, last : last + 1]
    )
    if not np.any(active):
        return dq, dqd, dqdd
    profiles = [_profiles(sched, t, k) for k in run]
    s, sd, sdd = (np.stack([p[i][active] for p in profiles], axis=1) for i in range(3))
    segments: list[ToolSegment] = [seg for k in run if (seg := path.tool[k]) is not None]
    pose, twist, acc = tool_motion(
        segments[0].start,
        np.array([seg.shift for seg in segments]),
        np.array([seg.turn for seg in segments]),
        np.array([seg.length for seg in segments]),
        s,
        sd,
        sdd,
    )
    ref = q_a + sum(
        (path.q_end[k] - path.q_start[k]) * (s[:, i] / max(path.travel[k], 1e-300))[:, None]
        for i, k in enumerate(run)
    )
    assert path.geometry is not None
    q, qd, qdd = joints_on_path(
        robot, path.geometry, path.tcp[first], int(path.branch[first]), pose, twist, acc, ref
    )
    dq[active] = q - q_a
    dqd[active] = qd
    dqdd[active] = qdd
    return dq, dqd, dqdd


def sample_path(
    robot: Robot, path: ProgramPath, sched: Schedule, t: ArrayLike
) -> tuple[Array, Array, Array]:
    """Joint angles, speeds and accelerations of B scheduled programs at times ``t``.

    Parameters
    ----------
    robot : Robot
    path : ProgramPath
    sched : Schedule
        B programs on ``path`` (:func:`schedule`).
    t : array_like, shape (B, M)
        Times from each program's start, s.

    Returns
    -------
    q, qd, qdd : ndarray, shape (B, M, n)
        rad, rad/s, rad/s^2.
    """
    times = np.asarray(t, dtype=float)
    n = path.q0.size
    q = np.broadcast_to(path.q0, (*times.shape, n)).copy()
    qd = np.zeros_like(q)
    qdd = np.zeros_like(q)
    for k in range(path.moves):
        if path.tool[k] is not None or path.travel[k] <= 0.0:
            continue
        s, sd, sdd = _profiles(sched, times, k)
        unit = (path.q_end[k] - path.q_start[k]) / path.travel[k]
        q += s[..., None] * unit
        qd += sd[..., None] * unit
        qdd += sdd[..., None] * unit
    for run in tool_runs(path):
        dq, dqd, dqdd = _tool_run(robot, path, sched, times, run)
        q += dq
        qd += dqd
        qdd += dqdd
    return q, qd, qdd


def payload_index(path: ProgramPath, sched: Schedule, t: ArrayLike) -> NDArray[np.intp]:
    """Index into ``path.payloads`` of the load at each time, shape (B, M): that of the last
    move or event started at or before it (in program order)."""
    times = np.atleast_2d(np.asarray(t, dtype=float))
    order: list[tuple[str, int]] = []
    for k in range(-1, path.moves):
        if k >= 0:
            order.append(("move", k))
        order.extend(("event", int(e)) for e in np.flatnonzero(path.event_after == k))
    starts = np.stack(
        [sched.start[:, i] if kind == "move" else sched.event_start[:, i] for kind, i in order],
        axis=1,
    )  # (B, S), non-decreasing along S
    loads = np.array(
        [path.move_payload[i] if kind == "move" else path.event_payload[i] for kind, i in order]
    )
    started = np.sum(times[:, :, None] >= starts[:, None, :], axis=2) - 1
    return np.asarray(loads[np.maximum(started, 0)], dtype=np.intp)


def program_motion(
    robot: Robot, path: ProgramPath, *, dt: float = CONTROLLER_DT
) -> tuple[Motion, Schedule]:
    """One program at ``path.speed`` and ``path.accel`` sampled every ``dt`` s (the controller's
    500 Hz), from its start to the first sample at or after its end."""
    sched = schedule(path, path.speed, path.accel)
    steps = int(np.ceil(float(sched.total[0]) / dt - 1e-9))
    t = np.arange(steps + 1, dtype=float) * dt
    q, qd, qdd = sample_path(robot, path, sched, t[None, :])
    return Motion(t, q[0], qd[0], qdd[0]), sched
