"""A log's signals written once to an unnamed temporary file (:class:`LogSpill`) and read back
by row range, so that identification never holds a log whole; the time stamps and the state
columns (:data:`~kinergy.logs.samples.STATE`) stay in memory."""

from __future__ import annotations

import itertools
import os
import tempfile
from collections.abc import Iterator, Sequence
from typing import BinaryIO

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.io.log import Log
from kinergy.logs.ident_data import JOINT_SIGNALS
from kinergy.logs.payload import payload_columns
from kinergy.logs.reading import CheckedLog
from kinergy.logs.samples import STATE

__all__ = ["SIGNALS", "LogSpill", "spill_chunks", "spill_log"]

#: the signals identification takes from a log (those it has are spilled)
SIGNALS = (*JOINT_SIGNALS, "actual_robot_voltage", "actual_robot_current")


class LogSpill:
    """A log's signals as raw float64 rows in an unnamed temporary file, read back by row range,
    and where its logged payload changes.

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
        #: where the logged payload changes: (first sample, its columns (10,)) in order; empty
        #: when the log has no payload (:func:`kinergy.logs.payload.payload_columns`)
        self.loads: list[tuple[int, Array]] = []

    def load_at(self, sample: int) -> Array | None:
        """The logged payload's columns at ``sample`` (None: the log has none)."""
        found = None
        for start, row in self.loads:
            if start > sample:
                break
            found = row
        return found

    def _add_loads(self, chunk: Log, start: int) -> None:
        """Note where ``chunk`` (its first sample the log's ``start``-th) changes payload."""
        cols = payload_columns(chunk)
        if cols is None:
            return
        prev = self.loads[-1][1] if self.loads else None
        same = np.all(cols[1:] == cols[:-1], axis=1)
        changes = [0] if prev is None or not np.array_equal(cols[0], prev) else []
        changes += [int(k) + 1 for k in np.flatnonzero(~same)]
        self.loads += [(start + k, cols[k].copy()) for k in changes]

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


def spill_chunks(path: str, chunks: Iterator[Log], notes: Sequence[str]) -> LogSpill:
    """``chunks`` (consecutive, of one log) written to a :class:`LogSpill`."""
    first = next(chunks, None)
    if first is None:
        raise KinergyError(f"{path}: the log has no samples")
    names = first.signals
    # with the commanded motion, the measured positions are not used (only looked for)
    skip = {"actual_q", "actual_qdd"} if {"target_q", "target_qd"} <= set(names) else set()
    layout = [
        (s, 1 if names[s].ndim == 1 else names[s].shape[1], names[s].ndim == 2)
        for s in SIGNALS
        if s in names and s not in skip
    ]
    spill = LogSpill(path, layout, tempfile.TemporaryFile())
    spill.names, spill.head = set(names), first
    times: list[Array] = []
    state: dict[str, list[Array]] = {s: [] for s in STATE if s in names}
    try:
        done = 0
        for chunk in itertools.chain([first], chunks):
            spill.append(chunk)
            spill._add_loads(chunk, done)
            done += len(chunk)
            # copies: a view would keep the chunk's whole block of values alive
            times.append(np.array(chunk.t, dtype=float))
            for name, parts in state.items():
                parts.append(np.array(chunk[name], dtype=float))
        spill.file.flush()
    except BaseException:
        spill.close()
        raise
    spill.notes = list(notes)
    spill.state = Log(
        spill.path, np.concatenate(times), {k: np.concatenate(v) for k, v in state.items()}
    )
    return spill


def spill_log(log: CheckedLog) -> LogSpill:
    """Read ``log`` once, in its chunks (through its checks), into a :class:`LogSpill` (the
    caller closes it). ``log`` should select the signals identification uses (:data:`SIGNALS`)
    and the state (:data:`STATE`)."""
    chunks = log.chunks()
    first = next(chunks, None)
    spill = spill_chunks(log.path, itertools.chain([] if first is None else [first], chunks), ())
    spill.notes = list(log.notes)
    return spill
