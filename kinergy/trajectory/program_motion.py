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
    "LineTables",
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


def _profiles(
    sched: Schedule, rows: NDArray[np.intp], t: Array, k: int
) -> tuple[Array, Array, Array]:
    """Move k's distance, speed and acceleration at times ``t`` (S,) of programs ``rows`` (S,)."""
    return trapezoid(
        t - sched.start[rows, k],
        sched.duration[rows, k],
        sched.ramp[rows, k],
        sched.peak[rows, k],
        sched.accel[rows, k],
    )


def _tool_run(
    robot: Robot,
    path: ProgramPath,
    sched: Schedule,
    rows: NDArray[np.intp],
    t: Array,
    run: list[int],
) -> tuple[Array, Array, Array]:
    """The joint displacement, speed and acceleration a run of tool moves adds at times ``t``
    (S,) of programs ``rows`` (S,) inside the run, (S, n): the tool on its lines, the joints by
    inverse kinematics at every sample."""
    first = run[0]
    q_a = path.q_start[first]
    profiles = [_profiles(sched, rows, t, k) for k in run]
    s, sd, sdd = (np.stack([p[i] for p in profiles], axis=1) for i in range(3))
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
    return q - q_a, qd, qdd


#: the quintic Hermite basis (rows: q0, h q0', h^2 q0'', q1, h q1', h^2 q1'') in powers of the
#: local coordinate t in [0, 1] (columns: t^0 .. t^5)
_HERMITE = np.array(
    [
        [1.0, 0.0, 0.0, -10.0, 15.0, -6.0],
        [0.0, 1.0, 0.0, -6.0, 8.0, -3.0],
        [0.0, 0.0, 0.5, -1.5, 1.5, -0.5],
        [0.0, 0.0, 0.0, 10.0, -15.0, 6.0],
        [0.0, 0.0, 0.0, -4.0, 7.0, -3.0],
        [0.0, 0.0, 0.0, 0.5, -1.0, 0.5],
    ]
)


@dataclass(frozen=True, eq=False)
class LineTables:
    """The joints along straight tool lines as functions of the distance along each, for
    sampling the lines at many timings (the optimiser's quadrature): at ``_TABLE_POINTS`` points
    from 0 to each line's length (m or rad) the joints ``q(s)``, ``q'(s) = dq/ds`` and ``q''(s)``
    from the inverse kinematics and the TCP Jacobian (:func:`kinergy.trajectory.movel.
    joints_on_path` at unit path speed), interpolated between the points by quintic Hermite
    polynomials (error of order ``h^6``), kept as each interval's polynomial coefficients. Then
    ``qd = q' sd`` and ``qdd = q' sdd + q'' sd^2`` for any profile ``s(t)``.

    Attributes
    ----------
    index : dict of int to int
        The table of each tabled move.
    step : ndarray, shape (T,)
        Each table's point spacing.
    coefficients : ndarray, shape (T, P - 1, 6, n)
        Per table and interval, ``q`` as a polynomial of the interval's local coordinate.
    """

    index: dict[int, int]
    step: Array
    coefficients: Array

    def __len__(self) -> int:
        return len(self.index)

    def __contains__(self, move: object) -> bool:
        return move in self.index

    def at(self, table: NDArray[np.intp], s: Array) -> tuple[Array, Array, Array]:
        """``q``, ``q'`` and ``q''`` of tables ``table`` (S,) at distances ``s`` (S,): (S, n)."""
        h = self.step[table]
        pieces = self.coefficients.shape[1]
        x = np.clip(s / h, 0.0, float(pieces))
        i = np.minimum(x.astype(np.intp), pieces - 1)
        t = (x - i)[:, None]
        c = self.coefficients[table, i]  # (S, 6, n)
        q = c[:, 5]
        d1 = 5.0 * c[:, 5]
        d2 = 20.0 * c[:, 5]
        for j in (4, 3, 2, 1, 0):
            q = q * t + c[:, j]
            if j >= 1:
                d1 = d1 * t + j * c[:, j]
            if j >= 2:
                d2 = d2 * t + j * (j - 1) * c[:, j]
        return q, d1 / h[:, None], d2 / (h * h)[:, None]


def line_tables(robot: Robot, path: ProgramPath) -> LineTables:
    """A table (:class:`LineTables`) of every tool move that runs alone (not blended into
    another tool move)."""
    index: dict[int, int] = {}
    steps: list[float] = []
    coefficients: list[Array] = []
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
        h = float(s[1] - s[0])
        values = np.stack(
            [q[:-1], h * d1[:-1], h * h * d2[:-1], q[1:], h * d1[1:], h * h * d2[1:]], axis=1
        )  # (P - 1, 6, n)
        index[k] = len(steps)
        steps.append(h)
        coefficients.append(np.einsum("vp,ivn->ipn", _HERMITE, values))
    n = path.q0.size
    return LineTables(
        index,
        np.array(steps, dtype=float),
        np.array(coefficients) if coefficients else np.zeros((0, _TABLE_POINTS - 1, 6, n)),
    )


def _units(path: ProgramPath) -> list[list[int]]:
    """The program's moves as units whose displacements add up: each joint move that moves,
    each run of tool moves blended into one another (a lone tool move a run of one), in order."""
    units: list[list[int]] = []
    runs = {run[0]: run for run in tool_runs(path)}
    k = 0
    while k < path.moves:
        if k in runs:
            units.append(runs[k])
            k = runs[k][-1] + 1
            continue
        if path.travel[k] > 0.0:
            units.append([k])
        k += 1
    return units


def _profiled(
    path: ProgramPath,
    sched: Schedule,
    rows: NDArray[np.intp],
    t: Array,
    moves: NDArray[np.intp],
    tables: LineTables | None,
) -> tuple[Array, Array, Array]:
    """The displacement, speed and acceleration that joint moves and tabled tool moves
    ``moves`` (S,) add at times ``t`` (S,) of programs ``rows`` (S,), each inside its move."""
    s, sd, sdd = trapezoid(
        t - sched.start[rows, moves],
        sched.duration[rows, moves],
        sched.ramp[rows, moves],
        sched.peak[rows, moves],
        sched.accel[rows, moves],
    )
    tool = np.array([path.tool[k] is not None for k in range(path.moves)])[moves]
    travel = np.where(path.travel > 0.0, path.travel, 1.0)
    direction = (path.q_end - path.q_start) / travel[:, None]  # (K, n)
    dq = s[:, None] * direction[moves]
    dqd = sd[:, None] * direction[moves]
    dqdd = sdd[:, None] * direction[moves]
    if np.any(tool):
        assert tables is not None
        pick = np.flatnonzero(tool)
        which = np.array([tables.index.get(int(k), -1) for k in range(path.moves)])[moves[pick]]
        q, d1, d2 = tables.at(which, s[pick])
        dq[pick] = q - path.q_start[moves[pick]]
        dqd[pick] = d1 * sd[pick, None]
        dqdd[pick] = d1 * sdd[pick, None] + d2 * (sd[pick] * sd[pick])[:, None]
    return dq, dqd, dqdd


def sample_path(
    robot: Robot,
    path: ProgramPath,
    sched: Schedule,
    t: ArrayLike,
    *,
    tables: LineTables | None = None,
) -> tuple[Array, Array, Array]:
    """Joint angles, speeds and accelerations of B scheduled programs at times ``t``.

    Every move (a run of tool moves blended into one another counts as one) adds its
    displacement to the joints: all of it once it has ended, none before it starts, its profile
    in between. The moves that have ended and those that have started are prefixes (neither
    their starts nor their ends fall), so each sample takes the summed displacement of the
    first and the profiles of the (at most two, blended) moves between the two, each evaluated
    at its own samples only.

    Parameters
    ----------
    robot : Robot
    path : ProgramPath
    sched : Schedule
        B programs on ``path`` (:func:`schedule`), or one for every row of ``t``.
    t : array_like, shape (B, M)
        Times from each program's start, s.
    tables : LineTables, optional
        Lone tool moves sampled from their tables (:func:`line_tables`) rather than by inverse
        kinematics at every sample: the optimiser's quadrature; the 500 Hz verification does
        without.

    Returns
    -------
    q, qd, qdd : ndarray, shape (B, M, n)
        rad, rad/s, rad/s^2.
    """
    times = np.atleast_2d(np.asarray(t, dtype=float))
    if sched.start.shape[0] == 1 and times.shape[0] > 1:  # one program at several rows of times
        sched = Schedule(*(np.repeat(x, times.shape[0], axis=0) for x in vars(sched).values()))
    n = path.q0.size
    units = _units(path)
    first = np.array([u[0] for u in units], dtype=np.intp)
    last = np.array([u[-1] for u in units], dtype=np.intp)
    delta = (path.q_end[last] - path.q_start[first]).reshape(-1, n)
    cum = np.vstack([path.q0, path.q0 + np.cumsum(delta, axis=0)])  # (U + 1, n)
    u_start = sched.start[:, first]  # (B, U), neither falling
    u_end = (sched.start + sched.duration)[:, last]
    finished = np.sum(times[:, :, None] >= u_end[:, None, :], axis=2)
    started = np.sum(times[:, :, None] > u_start[:, None, :], axis=2)
    q = cum[finished]
    qd = np.zeros_like(q)
    qdd = np.zeros_like(q)
    simple = np.array(
        [path.tool[u[0]] is None or (tables is not None and len(u) == 1 and u[0] in tables)
         for u in units],
        dtype=bool,
    )  # fmt: skip
    for lag in (1, 2):
        unit = started - lag  # (B, M)
        rows, cols = np.nonzero((unit >= finished) & (unit >= 0))
        if rows.size == 0:
            continue
        which = unit[rows, cols]
        at = times[rows, cols]
        easy = simple[which]
        if np.any(easy):
            r, c = rows[easy], cols[easy]
            dq, dqd, dqdd = _profiled(path, sched, r, at[easy], first[which[easy]], tables)
            q[r, c] += dq
            qd[r, c] += dqd
            qdd[r, c] += dqdd
        for u in np.unique(which[~easy]):
            pick = np.flatnonzero(which == u)
            r, c = rows[pick], cols[pick]
            dq, dqd, dqdd = _tool_run(robot, path, sched, r, at[pick], units[int(u)])
            q[r, c] += dq
            qd[r, c] += dqd
            qdd[r, c] += dqdd
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
