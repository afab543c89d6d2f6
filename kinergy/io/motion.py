"""Motions from logs and motion files, whole or chunk by chunk.

A motion file is a log in record.py layout holding at least ``timestamp`` and ``target_q`` (the
twin and ``kinergy excite`` write ``target_qd`` and ``target_qdd`` too). Missing derivatives are
computed from a cubic spline through the samples of each segment (:mod:`kinergy.io.segments`):
:func:`motion_from_log` of a log held whole, :func:`iter_motion` of a log read in chunks.

A spline's value at one knot depends on the others with a weight that falls by ``2 - sqrt(3)``
(about 0.27) per knot, so :func:`iter_motion` differentiates each chunk inside a window reaching
:data:`HALO` samples into its neighbours (clipped at segment boundaries, where the whole-log spline
ends too): at 48 samples the far end weighs below 1e-27, and the result equals the whole-log
spline's to round-off. Each chunk is held until the next one arrives (its look-ahead), so at most
two chunks are in memory.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from kinergy import checks
from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.io.log import Log
from kinergy.io.segments import segment_bounds
from kinergy.trajectory.motion import Motion, MotionSource

__all__ = ["HALO", "MotionChunk", "iter_motion", "motion_from_log"]


def _derivatives(t: Array, x: Array, order: int, bounds: list[tuple[int, int]]) -> Array:
    """The ``order``-th derivative of a spline through each segment of samples (never across
    a gap); a segment of one sample has none (0)."""
    out = np.zeros_like(x, dtype=float)
    for a, b in bounds:
        if b - a > 1:
            out[a:b] = CubicSpline(t[a:b], x[a:b], axis=0)(t[a:b], order)
    return out


def motion_from_log(
    log: Log, *, n_joints: int | None = None, source: MotionSource | str = MotionSource.AUTO
) -> Motion:
    """The joint motion recorded in a log.

    Parameters
    ----------
    log : Log
    n_joints : int, optional
        The robot's joint count, checked against the log's vectors.
    source : MotionSource
        ``target`` uses the commanded ``target_q/qd/qdd`` (noise-free, what the program asked
        for); ``actual`` the measured ``actual_q/qd`` with accelerations from a spline of the speed;
        ``auto`` takes target signals when the log has them, else actual ones.

    Raises
    ------
    KinergyError
        No joint positions, a joint count that does not match the robot.
    """
    source = checks.choice(source, MotionSource, "source")
    if source == MotionSource.AUTO:
        source = MotionSource.TARGET if "target_q" in log else MotionSource.ACTUAL
    q_name, qd_name, qdd_name = (f"{source}_q", f"{source}_qd", f"{source}_qdd")
    if q_name not in log:
        log.require(q_name, purpose="a motion")
    q = log[q_name]
    if q.ndim != 2:
        raise KinergyError(f"{log.path}: {q_name} must be a vector ({q_name}_0, {q_name}_1, ...)")
    if n_joints is not None and q.shape[1] != n_joints:
        raise KinergyError(
            f"{log.path}: the log has {q.shape[1]} joints ({q_name}_0..{q.shape[1] - 1}) "
            f"but the robot has {n_joints}"
        )
    t = log.t
    bounds = segment_bounds(t, log.signals.get("segment"))
    qd = log[qd_name] if qd_name in log else _derivatives(t, q, 1, bounds)
    if qdd_name in log:
        qdd = log[qdd_name]
    elif qd_name in log:
        qdd = _derivatives(t, qd, 1, bounds)
    else:
        qdd = _derivatives(t, q, 2, bounds)
    for name, arr in ((qd_name, qd), (qdd_name, qdd)):
        if arr.shape != q.shape:
            raise KinergyError(
                f"{log.path}: {name} has {arr.shape[1]} joints, {q_name} has {q.shape[1]}"
            )
    return Motion(t, q, qd, qdd)


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
    tail: Log | None,
    log: Log,
    head: Log | None,
    n_joints: int | None,
    source: MotionSource | str,
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
    source: MotionSource | str = MotionSource.AUTO,
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
