"""Motions from a log read in chunks, equal to :func:`kinergy.io.motion.motion_from_log` of the
whole log.

Where a chunk lacks the speeds or accelerations, :func:`~kinergy.io.motion.motion_from_log`
differentiates a cubic spline through each segment. A spline's value at one knot depends on the
others with a weight that falls by ``2 - sqrt(3)`` (about 0.27) per knot, so each chunk is
differentiated inside a window reaching ``HALO`` samples into its neighbours (clipped at segment
boundaries, where the whole-log spline ends too): at 48 samples the far end weighs below 1e-27,
and the result equals the whole-log spline's to round-off. Each chunk is held until the next one
arrives (its look-ahead), so at most two chunks are in memory.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass

from kinergy.io.log import Log
from kinergy.io.motion import motion_from_log
from kinergy.io.segments import segment_bounds
from kinergy.trajectory.motion import Motion

__all__ = ["HALO", "MotionChunk", "iter_motion"]

#: samples of a neighbouring chunk each chunk's spline reaches into
HALO = 48


@dataclass(frozen=True, eq=False)
class MotionChunk:
    """One chunk of a log and its motion.

    Attributes
    ----------
    log : Log
        The chunk's samples.
    motion : Motion
        Its joint motion (derivatives as the whole log's).
    starts : list of int
        Indices into the chunk where a segment begins (a time gap or a ``segment`` change);
        ``0`` when the chunk does not continue the previous one's segment.
    """

    log: Log
    motion: Motion
    starts: list[int]


def _rows(log: Log, a: int, b: int) -> Log:
    return Log(log.path, log.t[a:b], {k: v[a:b] for k, v in log.signals.items()}, log.notes)


def _chunk(
    tail: Log | None, log: Log, head: Log | None, n_joints: int | None, source: str
) -> MotionChunk:
    """``log`` with ``tail`` (the samples before it) and ``head`` (after it) as context."""
    parts = [p for p in (tail, log, head) if p is not None and len(p)]
    window = Log.concatenate(parts)
    before = len(tail) if tail is not None else 0
    motion = motion_from_log(window, n_joints=n_joints, source=source)
    bounds = segment_bounds(window.t, window.signals.get("segment"))
    end = before + len(log)
    starts = [a - before for a, _ in bounds if before <= a < end and (a > 0 or before == 0)]
    if before == 0:
        starts = sorted({0, *starts})
    sl = slice(before, end)
    return MotionChunk(
        log, Motion(motion.t[sl], motion.q[sl], motion.qd[sl], motion.qdd[sl]), starts
    )


def iter_motion(
    chunks: Iterable[Log],
    *,
    n_joints: int | None = None,
    source: str = "auto",
    halo: int = HALO,
) -> Iterator[MotionChunk]:
    """The motion of a log read in ``chunks`` (consecutive, as :func:`kinergy.io.formats.iter_log`
    yields them), chunk by chunk (:class:`MotionChunk`); ``n_joints`` and ``source`` as
    :func:`kinergy.io.motion.motion_from_log`."""
    pending: Log | None = None
    tail: Log | None = None
    for log in chunks:
        if pending is not None:
            yield _chunk(tail, pending, _rows(log, 0, halo), n_joints, source)
            joined = pending if tail is None else Log.concatenate([tail, pending])
            tail = _rows(joined, max(len(joined) - halo, 0), len(joined))
        pending = log
    if pending is not None:
        yield _chunk(tail, pending, None, n_joints, source)
