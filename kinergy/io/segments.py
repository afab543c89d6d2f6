"""Segments of a log: stretches of unbroken sampling, split where nothing was recorded.

A log is cut into segments where its ``segment`` column changes (the recorder counts its
reconnections there, :mod:`kinergy.live.recorder`) and where the time stamps jump by more than
``max_gap`` median sample periods (a recording paused, samples lost). Nothing that integrates or
differentiates over time may join two segments: between them there is no data, only a gap.

Examples
--------
>>> import numpy as np
>>> t = np.array([0.0, 0.002, 0.004, 0.5, 0.502, 0.504])
>>> segment_bounds(t)
[(0, 3), (3, 6)]
>>> segment_bounds(t[:3], np.array([0, 0, 1]))
[(0, 2), (2, 3)]
"""

from __future__ import annotations

import itertools

import numpy as np
from numpy.typing import ArrayLike

from kinergy.io.log import Log

__all__ = ["MAX_GAP", "segment_bounds", "split_segments"]

#: a step in time longer than this many median sample periods is a gap
MAX_GAP = 5.0


def segment_bounds(
    t: ArrayLike, segment: ArrayLike | None = None, *, max_gap: float = MAX_GAP
) -> list[tuple[int, int]]:
    """The ``(start, stop)`` index ranges of a log's segments, in order.

    Parameters
    ----------
    t : array_like, shape (N,)
        Increasing time stamps, s.
    segment : array_like, shape (N,), optional
        The recorder's segment numbers; a change starts a segment.
    max_gap : float
        A step longer than ``max_gap`` times the median step starts a segment.

    Returns
    -------
    list of (int, int)
        Covering ``0 .. N`` without overlap; one range when nothing splits the log.
    """
    tt = np.asarray(t, dtype=float)
    if tt.size < 2:
        return [(0, int(tt.size))]
    step = np.diff(tt)
    positive = step[step > 0]
    cut = np.zeros(step.size, dtype=bool)
    if positive.size:
        cut |= step > max_gap * float(np.median(positive))
    if segment is not None:
        cut |= np.diff(np.asarray(segment, dtype=float)) != 0
    starts = [0, *(np.flatnonzero(cut) + 1).tolist(), int(tt.size)]
    return list(itertools.pairwise(starts))


def split_segments(log: Log, *, max_gap: float = MAX_GAP) -> list[Log]:
    """``log`` as one :class:`Log` per segment (:func:`segment_bounds`), ``path`` marked
    ``#k`` when there is more than one. The ``segment`` column stays in each part."""
    bounds = segment_bounds(log.t, log.signals.get("segment"), max_gap=max_gap)
    if len(bounds) == 1:
        return [log]
    return [
        Log(
            f"{log.path}#{k}",
            log.t[a:b],
            {name: values[a:b] for name, values in log.signals.items()},
            list(log.notes),
        )
        for k, (a, b) in enumerate(bounds)
    ]
