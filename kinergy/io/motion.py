"""Motions from logs and motion files.

A motion file is a log in record.py layout holding at least ``timestamp`` and ``target_q`` (the
twin and ``kinergy excite`` write ``target_qd`` and ``target_qdd`` too). Missing derivatives are
computed from a cubic spline through the samples of each segment (:mod:`kinergy.io.segments`).
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.io.log import Log
from kinergy.io.segments import segment_bounds
from kinergy.trajectory.motion import Motion

__all__ = ["motion_from_log"]


def _derivatives(t: Array, x: Array, order: int, bounds: list[tuple[int, int]]) -> Array:
    """The ``order``-th derivative of a spline through each segment of samples (never across
    a gap); a segment of one sample has none (0)."""
    out = np.zeros_like(x, dtype=float)
    for a, b in bounds:
        if b - a > 1:
            out[a:b] = CubicSpline(t[a:b], x[a:b], axis=0)(t[a:b], order)
    return out


def motion_from_log(log: Log, *, n_joints: int | None = None, source: str = "auto") -> Motion:
    """The joint motion recorded in a log.

    Parameters
    ----------
    log : Log
    n_joints : int, optional
        The robot's joint count, checked against the log's vectors.
    source : {'auto', 'target', 'actual'}
        ``target`` uses the commanded ``target_q/qd/qdd`` (noise-free, what the program asked
        for); ``actual`` the measured ``actual_q/qd`` with accelerations from a spline of the speed;
        ``auto`` takes target signals when the log has them, else actual ones.

    Raises
    ------
    KinergyError
        No joint positions, a joint count that does not match the robot.
    """
    if source not in ("auto", "target", "actual"):
        raise KinergyError(f"source must be auto, target or actual, got {source!r}")
    if source == "auto":
        source = "target" if "target_q" in log else "actual"
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
