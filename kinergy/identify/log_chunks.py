"""A log prepared for identification chunk by chunk, equal to :func:`~kinergy.identify.preprocess.prepare`
of each whole segment.

One pass reads the file (:func:`kinergy.io.formats.iter_log`, only the signals identification
uses) and writes its values as raw float64 rows to an unnamed temporary file (the *spill*,
removed when closed), keeping in memory only the time stamps and the state columns
(``runtime_state``, ``robot_mode``, ``segment``: one scalar per sample, 32 bytes). Those decide,
with the in-memory code itself, the segments (:func:`kinergy.io.segments.segment_bounds`), the
samples a program runs in (:func:`~kinergy.identify.preprocess.running_range`) and the uniform
grid (:func:`~kinergy.identify.preprocess.uniform_grid`). Every later pass re-reads the spill in
chunks (:meth:`PreparedSegment.chunks`), at disk-cache speed instead of parsing text again.

What reaches across chunk edges, and the pad that makes each chunk equal the whole segment's:

- resampling to the uniform grid is linear interpolation: a grid sample needs the two raw
  samples around it, which the raw rows read for it always include;
- the commanded acceleration, when the log lacks ``target_qdd``, is a central difference: one
  sample each side;
- the real motion is the commanded one delayed by the lag through a cubic spline
  (:func:`~kinergy.identify.preprocess.delay`). A spline's value at one knot depends on a knot
  ``k`` samples away with a weight that falls as ``(2 - sqrt(3))^k`` (0.27 per knot), so each
  chunk is splined with :data:`~kinergy.io.motion_stream.HALO` (48) samples of its neighbours
  on each side (1e-27 at the far end: the whole segment's spline to round-off), plus the lag in
  samples (the delayed time of a chunk's first sample lies that far back); at the segment's ends
  the window ends with the segment, as the whole-segment spline does;
- the lag itself (:func:`~kinergy.identify.preprocess.estimate_lag`) compares the spline of the
  commanded speed with the measured speed at a few thousand samples
  (:func:`~kinergy.identify.preprocess.lag_samples`): one spline through the samples within
  ``HALO`` of each of them (read from the spill; joined across the gaps between them, which the
  48-sample decay keeps from reaching the compared samples) gives the same lag.

Logs without ``target_q`` (the measured motion low-pass filtered) are not prepared here: a
zero-phase filter reaches much further than a spline (its own padding and initial state);
:func:`streamable` says which logs are.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import BinaryIO

import numpy as np
from scipy.interpolate import CubicSpline

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.identify.preprocess import (
    JOINT_SIGNALS,
    MAX_LAG,
    IdentData,
    check_cutoff,
    check_joints,
    commanded_motion,
    default_cutoff,
    delay,
    ident_data,
    lag_samples,
    lag_search,
    resample,
    running_range,
    uniform_grid,
)
from kinergy.io.formats import CHUNK_ROWS, iter_log
from kinergy.io.log import Log
from kinergy.io.motion_stream import HALO
from kinergy.io.rosbag import BagOptions
from kinergy.io.segments import segment_bounds

__all__ = [
    "SIGNALS",
    "STATE",
    "LogSpill",
    "PreparedSegment",
    "prepare_segment",
    "segment_paths",
    "spill_log",
    "streamable",
]


#: the signals identification takes from a log (those it has are spilled)
SIGNALS = (*JOINT_SIGNALS, "actual_robot_voltage", "actual_robot_current")
#: per-sample state kept in memory: it decides segments and the samples a program runs in
STATE = ("runtime_state", "robot_mode", "segment")


class LogSpill:
    """A log's signals as raw float64 rows in an unnamed temporary file, read back by row range.

    Attributes
    ----------
    path : str
        The log's path (for messages).
    layout : list of (str, int, bool)
        Per signal: name, width, and whether it is a vector (N, width) rather than (N,).
    state : Log
        Time stamps and the :data:`STATE` columns of every sample, in memory.
    notes : list of str
        What reading the file said (rows dropped by ``repair``).
    names : set of str
        Every signal the log has (spilled or not).
    head : Log
        The log's first samples, every signal.
    """

    def __init__(self, path: str, layout: list[tuple[str, int, bool]], file: BinaryIO):
        self.path = path
        self.layout = layout
        self.width = sum(w for _, w, _ in layout)
        self.file = file
        self.state = Log(path, np.empty(0))
        self.notes: list[str] = []
        self.names = {name for name, _, _ in layout}
        self.head = Log(path, np.empty(0))

    def __len__(self) -> int:
        return len(self.state)

    def close(self) -> None:
        """Remove the spill."""
        self.file.close()

    def append(self, chunk: Log) -> None:
        """Write ``chunk``'s signals of :attr:`layout` at the end."""
        rows = np.empty((len(chunk), self.width))
        col = 0
        for name, width, _ in self.layout:
            rows[:, col : col + width] = chunk[name].reshape(len(chunk), width)
            col += width
        self.file.write(rows.tobytes())

    def read(self, start: int, stop: int, names: Sequence[str] | None = None) -> Log:
        """Samples ``start:stop`` as a :class:`Log` (time stamps from :attr:`state`), of the
        signals ``names`` (default all)."""
        size = (stop - start) * self.width * 8
        raw = os.pread(self.file.fileno(), size, start * self.width * 8)
        rows = np.frombuffer(raw, dtype=float).reshape(stop - start, self.width)
        signals, col = {}, 0
        for name, width, vector in self.layout:
            if names is None or name in names:
                block = rows[:, col : col + width]
                signals[name] = block.copy() if vector else block[:, 0].copy()
            col += width
        return Log(self.path, self.state.t[start:stop], signals)


def spill_log(
    path: str | os.PathLike[str],
    *,
    columns: str | None = None,
    repair: bool = False,
    rows: int = CHUNK_ROWS,
    joints: Sequence[str] | None = None,
    bag: BagOptions | None = None,
) -> LogSpill:
    """Read the log at ``path`` once, in chunks of ``rows``, into a :class:`LogSpill` (the
    caller closes it); ``joints`` and ``bag`` as :func:`kinergy.io.formats.iter_log` takes
    them."""
    first = next(
        iter_log(path, columns=columns, repair=repair, rows=2, joints=joints, bag=bag), None
    )
    if first is None:
        raise KinergyError(f"{path}: the log has no samples")
    names = first.signals
    # with the commanded motion, the measured positions are not used (only looked for)
    skip = {"actual_q"} if {"target_q", "target_qd"} <= set(names) else set()
    wanted = [s for s in (*SIGNALS, *STATE) if s in names and s not in skip]
    layout = [
        (s, 1 if names[s].ndim == 1 else names[s].shape[1], names[s].ndim == 2)
        for s in SIGNALS
        if s in wanted
    ]
    spill = LogSpill(os.fspath(path), layout, tempfile.TemporaryFile())
    spill.names, spill.head = set(names), first
    times: list[Array] = []
    state: dict[str, list[Array]] = {s: [] for s in STATE if s in names}
    try:
        chunks = iter_log(
            path, columns=columns, repair=repair, select=wanted, rows=rows, joints=joints, bag=bag
        )
        for chunk in chunks:
            spill.notes += chunk.notes
            spill.append(chunk)
            # copies: a view would keep the chunk's whole block of values alive
            times.append(np.array(chunk.t, dtype=float))
            for name, parts in state.items():
                parts.append(np.array(chunk[name], dtype=float))
        spill.file.flush()
    except BaseException:
        spill.close()
        raise
    spill.state = Log(
        spill.path, np.concatenate(times), {k: np.concatenate(v) for k, v in state.items()}
    )
    return spill


def streamable(spill: LogSpill) -> bool:
    """Whether :func:`prepare_segment` prepares this log (it has ``target_q`` and
    ``target_qd``); others are prepared in memory (module docstring)."""
    names = spill.names
    return {"target_q", "target_qd"} <= names


@dataclass(frozen=True, eq=False)
class PreparedSegment:
    """One segment of a spilled log, prepared: :meth:`chunks` yields its :class:`IdentData` in
    consecutive pieces equal to :func:`~kinergy.identify.preprocess.prepare` of the whole segment.

    Attributes
    ----------
    path : str
        As the in-memory path names the segment.
    spill : LogSpill
    rows : slice
        The raw samples (of the spill) the segment keeps (the program running).
    grid : (float, int) or None
        The uniform grid's period (s) and size when the samples are resampled; None when they are
        uniform already.
    lag : float
        Lag of the real motion behind the commanded one, s.
    source : str
        ``"delayed target"``.
    """

    path: str
    spill: LogSpill
    rows: slice
    grid: tuple[float, int] | None
    lag: float
    source: str

    def __len__(self) -> int:
        return self.rows.stop - self.rows.start if self.grid is None else self.grid[1]

    @property
    def t0(self) -> float:
        return float(self.spill.state.t[self.rows.start])

    @property
    def dt(self) -> float:
        if self.grid is not None:
            return self.grid[0]
        t = self.spill.state.t
        return float(t[self.rows.start + 1] - t[self.rows.start])

    @property
    def span(self) -> tuple[float, float]:
        """The first and last uniform time stamps, s."""
        if self.grid is None:
            return self.t0, float(self.spill.state.t[self.rows.stop - 1])
        return self.t0, self.t0 + self.grid[0] * (self.grid[1] - 1)

    def uniform(self, start: int, stop: int, names: Sequence[str] | None = None) -> Log:
        """Uniform samples ``start:stop`` of the segment (resampled where the log is not), of
        the signals ``names`` (default all)."""
        a = self.rows.start
        if self.grid is None:
            log = self.spill.read(a + start, a + stop, names)
        else:
            grid = np.asarray(self.t0 + self.grid[0] * np.arange(start, stop), dtype=float)
            raw = self.spill.state.t[self.rows]
            lo = max(int(np.searchsorted(raw, grid[0], side="right")) - 1, 0)
            hi = min(int(np.searchsorted(raw, grid[-1], side="left")) + 1, raw.size)
            log = resample(self.spill.read(a + lo, a + hi, names), grid)
        return Log(self.path, log.t, log.signals)

    def halo(self) -> int:
        """Samples of context each chunk is prepared with (module docstring)."""
        return HALO + int(np.ceil(abs(self.lag) / self.dt)) + 2

    def chunks(self, rows: int = CHUNK_ROWS) -> Iterator[IdentData]:
        """The prepared segment in pieces of at most ``rows`` samples, in time order."""
        size, pad = len(self), self.halo()
        for start in range(0, size, rows):
            stop = min(start + rows, size)
            lo, hi = max(start - pad, 0), min(stop + pad, size)
            window = self.uniform(lo, hi)
            commanded = commanded_motion(window)
            # one spline through the three signals' columns: each column as its own
            both = delay(window.t, np.hstack(commanded), self.lag, self.span)
            real = np.hsplit(both, 3)
            data = ident_data(window, commanded, real, (self.lag, self.source))  # type: ignore[arg-type]
            yield data.sliced(start - lo, stop - lo)


def _lag(segment: PreparedSegment) -> float:
    """:func:`~kinergy.identify.preprocess.estimate_lag` of ``segment`` from the samples near
    the compared ones (module docstring)."""
    names = segment.spill.names
    if not {"actual_q", "actual_qd"} <= names:
        return 0.0
    size, t0, dt = len(segment), segment.t0, segment.dt
    if segment.grid is None:
        t = segment.spill.state.t[segment.rows]
    else:
        t = np.asarray(t0 + dt * np.arange(size), dtype=float)
    inner = lag_samples(t)
    if inner.size == 0:
        return 0.0
    near = np.zeros(size + 1, dtype=int)
    np.add.at(near, np.clip(inner - HALO, 0, size), 1)
    np.add.at(near, np.clip(inner + HALO + 1, 0, size), -1)
    covered = np.cumsum(near[:-1]) > 0
    edges = np.flatnonzero(np.diff(np.concatenate([[0], covered.astype(int), [0]])))
    speeds = ("target_qd", "actual_qd")
    parts = [segment.uniform(a, b, speeds) for a, b in zip(edges[::2], edges[1::2], strict=True)]
    window = Log.concatenate(parts)
    spline = CubicSpline(window.t, window["target_qd"], axis=0)
    measured = np.vstack([p["actual_qd"] for p in parts])[np.searchsorted(window.t, t[inner])]
    return lag_search(spline, t[inner], measured, float(t[1] - t[0]), max_lag=MAX_LAG)


def prepare_segment(
    spill: LogSpill, bounds: tuple[int, int], path: str, n_joints: int, cutoff: float | None
) -> PreparedSegment:
    """Samples ``bounds`` (a segment) of a spilled log, prepared as
    :func:`~kinergy.identify.preprocess.prepare` prepares them (module docstring).

    Raises
    ------
    KinergyError
        As :func:`~kinergy.identify.preprocess.prepare`: no sample where the program runs, a
        joint count that does not match, a cutoff outside the sample rate's band.
    """
    a, b = bounds
    state = Log(path, spill.state.t[a:b], {k: v[a:b] for k, v in spill.state.signals.items()})
    keep = running_range(state)
    rows = slice(a + keep.start, a + keep.stop)
    grid = uniform_grid(spill.state.t[rows])
    segment = PreparedSegment(path, spill, rows, grid, 0.0, "delayed target")
    head = segment.uniform(0, min(len(segment), 2))
    check_joints(spill.head, n_joints)
    names = spill.names
    if {"actual_q", "actual_qd"} <= names:
        fs = 1.0 / float(head.t[1] - head.t[0])
        check_cutoff(fs, default_cutoff(head.t) if cutoff is None else cutoff)
    return PreparedSegment(path, spill, rows, grid, _lag(segment), "delayed target")


def segment_paths(spill: LogSpill) -> list[tuple[tuple[int, int], str]]:
    """The segments of a spilled log (:func:`kinergy.io.segments.segment_bounds`) and the path
    each is named by (``#k`` when there are several, as :func:`~kinergy.io.segments.split_segments`)."""
    bounds = segment_bounds(spill.state.t, spill.state.signals.get("segment"))
    if len(bounds) == 1:
        return [(bounds[0], spill.path)]
    return [(ab, f"{spill.path}#{k}") for k, ab in enumerate(bounds)]
