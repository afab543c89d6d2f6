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
from kinergy.trajectory.motion import CONTROLLER_DT, Motion, sample_times
from kinergy.trajectory.movej import blend_starts, trapezoid, trapezoid_timing
from kinergy.trajectory.movel import ToolSegment, joints_on_path, tool_motion
from kinergy.trajectory.program_path import ProgramPath

__all__ = [
    "LineTable",
    "Schedule",
    "line_tables",
    "payload_index",
    "program_motion",
    "sample_path",
    "schedule",
    "schedule_profiles",
    "tool_runs",
]


#: points of a straight tool line's table (:class:`LineTable`)
_TABLE_POINTS = 129


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


@dataclass(frozen=True, eq=False)
class LineTable:
    """The joints along one straight tool line as a function of the distance along it, for
    sampling the line at many timings (the optimiser's quadrature): at ``s`` (0 to the line's
    length, m or rad) the joints ``q(s)``, ``q'(s) = dq/ds`` and ``q''(s)`` from the inverse
    kinematics and the TCP Jacobian (:func:`kinergy.trajectory.movel.joints_on_path` at unit
    path speed), interpolated between the points by quintic Hermite polynomials (error of order
    ``h^6``). Then ``qd = q' sd`` and ``qdd = q' sdd + q'' sd^2`` for any profile ``s(t)``.

    Attributes
    ----------
    s : ndarray, shape (P,)
    q, d1, d2 : ndarray, shape (P, n)
    """

    s: Array
    q: Array
    d1: Array
    d2: Array

    def at(self, s: Array) -> tuple[Array, Array, Array]:
        """``q``, ``q'`` and ``q''`` at distances ``s`` (S,): each (S, n)."""
        h = float(self.s[1] - self.s[0])
        x = np.clip(np.asarray(s, dtype=float), self.s[0], self.s[-1])
        i = np.minimum(((x - self.s[0]) / h).astype(np.intp), self.s.size - 2)
        t = ((x - self.s[i]) / h)[:, None]
        t2, t3, t4, t5 = t * t, t**3, t**4, t**5
        q0, q1 = self.q[i], self.q[i + 1]
        a0, a1 = self.d1[i] * h, self.d1[i + 1] * h
        b0, b1 = self.d2[i] * h * h, self.d2[i + 1] * h * h
        basis = (
            (1 - 10 * t3 + 15 * t4 - 6 * t5, -30 * t2 + 60 * t3 - 30 * t4, -60 * t + 180 * t2 - 120 * t3),
            (t - 6 * t3 + 8 * t4 - 3 * t5, 1 - 18 * t2 + 32 * t3 - 15 * t4, -36 * t + 96 * t2 - 60 * t3),
            (0.5 * t2 - 1.5 * t3 + 1.5 * t4 - 0.5 * t5, t - 4.5 * t2 + 6 * t3 - 2.5 * t4,
             1 - 9 * t + 18 * t2 - 10 * t3),
            (10 * t3 - 15 * t4 + 6 * t5, 30 * t2 - 60 * t3 + 30 * t4, 60 * t - 180 * t2 + 120 * t3),
            (-4 * t3 + 7 * t4 - 3 * t5, -12 * t2 + 28 * t3 - 15 * t4, -24 * t + 84 * t2 - 60 * t3),
            (0.5 * t3 - t4 + 0.5 * t5, 1.5 * t2 - 4 * t3 + 2.5 * t4, 3 * t - 12 * t2 + 10 * t3),
        )  # fmt: skip
        values = (q0, a0, b0, q1, a1, b1)
        q = sum(b[0] * v for b, v in zip(basis, values, strict=True))
        d1 = sum(b[1] * v for b, v in zip(basis, values, strict=True)) / h
        d2 = sum(b[2] * v for b, v in zip(basis, values, strict=True)) / (h * h)
        return np.asarray(q), np.asarray(d1), np.asarray(d2)


def line_tables(robot: Robot, path: ProgramPath) -> dict[int, LineTable]:
    """A :class:`LineTable` of every tool move that runs alone (not blended into another tool
    move), by move index."""
    out = {}
    for run in tool_runs(path):
        if len(run) != 1:
            continue
        k = run[0]
        segment = path.tool[k]
        assert segment is not None and path.geometry is not None
        length = max(segment.length, 1e-12)
        s = np.linspace(0.0, length, _TABLE_POINTS)
        one, zero = np.ones((s.size, 1)), np.zeros((s.size, 1))
        pose, twist, acc = tool_motion(
            segment.start, segment.shift[None], segment.turn[None], np.array([length]),
            s[:, None], one, zero,
        )  # fmt: skip
        ref = path.q_start[k] + (path.q_end[k] - path.q_start[k]) * (s / length)[:, None]
        q, d1, d2 = joints_on_path(
            robot, path.geometry, path.tcp[k], int(path.branch[k]), pose, twist, acc, ref
        )
        out[k] = LineTable(s, q, d1, d2)
    return out


def _tabled_run(
    table: LineTable, path: ProgramPath, sched: Schedule, t: Array, k: int
) -> tuple[Array, Array, Array]:
    """The joint displacement, speed and acceleration a lone tool move adds, (B, M, n), from
    its table."""
    q_a = path.q_start[k]
    shape = (*t.shape, q_a.size)
    dq, dqd, dqdd = np.zeros(shape), np.zeros(shape), np.zeros(shape)
    end = sched.start[:, k : k + 1] + sched.duration[:, k : k + 1]
    dq[:] = np.where((t >= end)[..., None], path.q_end[k] - q_a, 0.0)
    active = (t > sched.start[:, k : k + 1]) & (t < end)
    if not np.any(active):
        return dq, dqd, dqdd
    s, sd, sdd = (x[active] for x in _profiles(sched, t, k))
    q, d1, d2 = table.at(s)
    dq[active] = q - q_a
    dqd[active] = d1 * sd[:, None]
    dqdd[active] = d1 * sdd[:, None] + d2 * (sd * sd)[:, None]
    return dq, dqd, dqdd


def sample_path(
    robot: Robot,
    path: ProgramPath,
    sched: Schedule,
    t: ArrayLike,
    *,
    tables: dict[int, LineTable] | None = None,
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
    tables : dict of int to LineTable, optional
        Tool moves sampled from their tables (:func:`line_tables`) rather than by inverse
        kinematics at every sample: the optimiser's quadrature; the 500 Hz verification does
        without.

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
        if tables is not None and len(run) == 1 and run[0] in tables:
            dq, dqd, dqdd = _tabled_run(tables[run[0]], path, sched, times, run[0])
        else:
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
    k = int(np.argmax(sched.duration[0])) if sched.duration.shape[1] else 0
    longest = f"move {k + 1} alone {sched.duration[0, k]:.4g} s" if sched.duration.shape[1] else ""
    t = sample_times(float(sched.total[0]), dt, longest)
    q, qd, qdd = sample_path(robot, path, sched, t[None, :])
    return Motion(t, q[0], qd[0], qdd[0]), sched
