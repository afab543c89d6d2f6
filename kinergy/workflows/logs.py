"""Reading the user's logs for a command: each file read, its notes passed on, then prepared.

A motion can also be a URScript program (``*.script``): :func:`read_motion` then simulates it as
the UR controller runs it (:mod:`kinergy.trajectory.program_motion`, 500 Hz), which needs the
robot it runs on.
"""

from __future__ import annotations

import contextlib
import itertools
import os
from collections.abc import Iterator, Sequence

from kinergy.errors import KinergyError
from kinergy.io.formats import CHUNK_ROWS
from kinergy.io.log import Log
from kinergy.io.motion import motion_from_log
from kinergy.io.urscript_reader import read_program
from kinergy.logs.payload import PAYLOAD_SIGNALS, describe
from kinergy.logs.prepare import (
    SIGNALS,
    STATE,
    IdentData,
    PreparedSegment,
    prepare_segment,
    spill_log,
)
from kinergy.logs.reading import CheckedLog, InputLogs, LogReading
from kinergy.logs.samples import used_bounds
from kinergy.messages import Say, silent
from kinergy.model.robot import Robot
from kinergy.trajectory.motion import Motion, MotionSource
from kinergy.trajectory.program_motion import program_motion
from kinergy.trajectory.program_path import program_path

__all__ = [
    "MIN_SEGMENT",
    "InputLogs",
    "LogReading",
    "chunked_logs",
    "one_payload",
    "prepared_logs",
    "read_motion",
]


MIN_SEGMENT = 1.0
"""Shortest segment of a log (s) :func:`prepared_logs` identifies from."""


def _segments(
    path: str | os.PathLike[str], state: Log, notes: list[str], cuts: Sequence[int] = ()
) -> list[tuple[str, tuple[int, int]]]:
    """The segments of the log at ``path`` identified from (:func:`kinergy.logs.samples.used_bounds`
    of its time stamps and state columns ``state``: its segments, cut where the robot does not
    run and at ``cuts``, where the logged payload changes), each with the name :func:`~kinergy.io.segments.split_segments` gives it: those shorter
    than :data:`MIN_SEGMENT` are left out. Where there are several segments, ``notes`` receives
    what was done with them."""
    name, t, bounds = os.fspath(path), state.t, used_bounds(state, cuts)
    used = sum(b - a for a, b in bounds)
    if used < len(t):
        notes.append(
            f"{path}: {len(t) - used} of {len(t)} samples left out where the robot does not run "
            "(robot_mode not 7, or safety_mode not 1 or 2)"
        )
    if len(bounds) == 1:
        return [(name, bounds[0])]
    parts = [(f"{name}#{k}", ab) for k, ab in enumerate(bounds)]
    kept = [p for p in parts if t[p[1][1] - 1] - t[p[1][0]] >= MIN_SEGMENT] or [
        max(parts, key=lambda p: p[1][1] - p[1][0])
    ]
    gaps = [t[b[0]] - t[a[1] - 1] for a, b in itertools.pairwise(bounds)]
    notes.append(
        f"{path}: {len(parts)} segments (gaps up to {max(gaps):.3f} s), each prepared on "
        f"its own; {len(parts) - len(kept)} shorter than {MIN_SEGMENT:g} s left out"
    )
    return kept


#: the signals a spill keeps: what identification uses, the state that decides segments and the
#: logged payload
SPILLED = (*SIGNALS, *STATE, *PAYLOAD_SIGNALS)


def prepared_logs(
    paths: Sequence[str | os.PathLike[str] | Log], robot: Robot, reading: LogReading
) -> tuple[list[IdentData], InputLogs]:
    """:func:`chunked_logs` with each segment prepared whole (one chunk): the logs read through
    the checks, each segment of a log on its own (nothing is filtered or differentiated across a
    gap or a reconnection), as ``reading`` says.

    Segments shorter than :data:`MIN_SEGMENT` seconds are left out and counted in a note.
    """
    with chunked_logs(paths, robot, reading) as (segments, inputs):
        return [s.whole() for s in segments], inputs


def _resampled_notes(resampled: Sequence[tuple[str, int, int, float]]) -> list[str]:
    """The note on a log's segments resampled onto a regular grid (name, rows, samples, step
    in s each): one note for all of a log's segments."""
    if len(resampled) == 1:
        name, rows, samples, step = resampled[0]
        return [
            f"{name}: irregular time stamps: its {rows} rows resampled to {samples} samples "
            f"{step * 1e3:.4g} ms apart (the counts identify and validate give)"
        ]
    if not resampled:
        return []
    each = ", ".join(
        f"{name} {rows} to {samples} ({step * 1e3:.4g} ms)"
        for name, rows, samples, step in resampled
    )
    return [
        f"irregular time stamps: segments resampled onto a regular grid, rows to samples (the "
        f"counts identify and validate give): {each}"
    ]


@contextlib.contextmanager
def chunked_logs(
    paths: Sequence[str | os.PathLike[str] | Log],
    robot: Robot,
    reading: LogReading,
    *,
    rows: int = CHUNK_ROWS,
    progress: Say = silent,
) -> Iterator[tuple[list[PreparedSegment], InputLogs]]:
    """Every log read once, through the checks (:class:`~kinergy.logs.reading.CheckedLog`, in
    chunks of ``rows``), into a temporary spill removed on leaving the context, and its segments
    prepared (:func:`kinergy.logs.prepare.prepare_segment`): each yields its samples in chunks of
    any size, equal to the whole segment's preparation. ``progress`` is told each log read, of
    all."""
    inputs = InputLogs()
    with contextlib.ExitStack() as stack:
        segments: list[PreparedSegment] = []
        for k, path in enumerate(paths):
            name = path.path if isinstance(path, Log) else os.fspath(path)
            progress(f"reading and preparing {os.path.basename(name)}", done=k, total=len(paths))
            checked = CheckedLog(path, robot, reading, select=SPILLED, rows=rows)
            spill = spill_log(checked)
            stack.callback(spill.close)
            inputs.add(checked)
            cuts = [start for start, _ in spill.loads[1:]]
            resampled: list[tuple[str, int, int, float]] = []
            for name, ab in _segments(checked.path, spill.state, inputs.notes, cuts):
                prepared = prepare_segment(spill, ab, name, robot.n, reading.cutoff)
                if prepared.grid is not None:
                    rows = prepared.rows.stop - prepared.rows.start
                    resampled.append((name, rows, prepared.grid[1], prepared.grid[0]))
                segments.append(prepared)
            inputs.notes += _resampled_notes(resampled)
        yield segments, inputs


def one_payload(robot: Robot, segments: Sequence[PreparedSegment], notes: list[str]) -> Robot:
    """``robot`` carrying the payload its logs' controller logged (:attr:`PreparedSegment.load`;
    ``robot`` as it is where none is logged), for a method that fits one model to all of them;
    ``notes`` says which payload was used.

    Raises
    ------
    KinergyError
        Segments that logged different payloads (name two), with what to do.
    """
    logged = {s.load.tobytes(): s for s in segments if s.load is not None}
    if not logged:
        return robot
    if len(logged) > 1:
        a, b = list(logged.values())[:2]
        raise KinergyError(
            f"the logs carry different payloads ({describe(a.robot(robot).payload)} in {a.path}, "
            f"{describe(b.robot(robot).payload)} in {b.path}): identify from the samples of one "
            "payload (--from/--to), or give the payload with --payload"
        )
    segment = next(iter(logged.values()))
    loaded = segment.robot(robot)
    where = ", ".join(sorted({s.path.split("#")[0] for s in segments if s.load is not None}))
    notes.append(
        f"{where}: the controller's logged payload, {describe(loaded.payload)}, is the "
        "payload of the dynamics (--payload replaces it)"
    )
    return loaded


def read_motion(
    path: str | os.PathLike[str],
    robot: Robot,
    reading: LogReading | None = None,
    *,
    source: MotionSource | str = MotionSource.AUTO,
) -> tuple[Motion, InputLogs]:
    """The joint motion of a log or motion file (:func:`kinergy.io.motion.motion_from_log`,
    read through the checks), or of a URScript program (``*.script``) on ``robot`` as the
    controller runs it (one cycle, starting where it ends, at 500 Hz)."""
    inputs = InputLogs()
    if os.fspath(path).endswith(".script"):
        motion, _ = program_motion(robot, program_path(robot, read_program(path)))
        return motion, inputs
    checked = CheckedLog(path, robot, reading or LogReading())
    log = checked.read()
    inputs.add(checked)
    return motion_from_log(log, n_joints=robot.n, source=source), inputs
