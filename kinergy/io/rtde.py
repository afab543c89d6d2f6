"""Robot controller logs: UR's RTDE ``record.py`` layout in and out, and headerless files.

``record.py`` writes a header line naming every column, vectors as ``name_0 .. name_5``, values
space separated (comma separated files are read too)::

    timestamp target_q_0 ... target_q_5 actual_q_0 ... actual_current_5 ...

A headerless file needs a column spec (``--columns``), RTDE field names with ``:n`` for an
n-vector::

    timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6

A header log whose names are not RTDE's is mapped (``--columns "timestamp=time,actual_q=pos_*"``,
:class:`kinergy.io.columns.ColumnMap`); columns that are no RTDE field are not read, and the
first chunk's note names them (:mod:`kinergy.io.log_layout`).

Every problem is one line naming the file and, where it applies, the line and column.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import IO

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.files import atomic_open, atomic_write
from kinergy.io.columns import Columns, group_columns, parse_columns
from kinergy.io.formats import LogFormat, iter_log, read_log, register
from kinergy.io.log import TIME_UNITS, Log, time_unit
from kinergy.io.log_arrow import NotPlain, arrow_chunks
from kinergy.io.log_layout import LogLayout, log_layout
from kinergy.io.log_text import read_text_table

__all__ = [
    "RTDE",
    "exact_text",
    "iter_log",
    "parse_columns",
    "read_log",
    "write_log",
    "write_log_chunks",
]


def _selection(layout: LogLayout, select: Sequence[str] | None) -> dict[str, list[int]]:
    """Signal name -> indices of its columns in the file (``timestamp`` first), for the
    signals ``select`` names (default all)."""
    groups = group_columns(layout.names, str(layout.path), layout.ignored)
    # columns a spec skips (``_`` -> ``_0``, ``_1``, ...) are never read
    groups = {name: cols for name, cols in groups.items() if not re.fullmatch(r"_\d*", name)}
    if select is not None:
        missing = [name for name in select if name not in groups]
        if missing:
            raise KinergyError(
                f"{layout.path}: no column(s) for {', '.join(missing)}; "
                f"the log has: {', '.join(sorted(groups))}"
            )
        groups = {name: groups[name] for name in ["timestamp", *select]}
    index = {name: k for k, name in enumerate(layout.names)}
    return {name: [index[c] for c in cols] for name, cols in groups.items()}


class _Chunker:
    """Turns value arrays of the wanted columns into :class:`Log` chunks: vectors grouped, time
    stamps in s (the unit found from the first chunk), notes on the first chunk only."""

    def __init__(self, layout: LogLayout, selection: dict[str, list[int]], notes: list[str]):
        self.path = str(layout.path)
        note = layout.note()
        self.notes = [*notes, *([note] if note else [])]
        self.ignored: tuple[str, ...] = layout.ignored
        self.scale: float | None = None
        wanted = [i for cols in selection.values() for i in cols]
        position = {i: k for k, i in enumerate(wanted)}
        self.wanted = wanted
        self.signals = {
            name: (
                [position[i] for i in cols],
                len(cols) == 1 and layout.names[cols[0]] == name,
            )
            for name, cols in selection.items()
            if name != "timestamp"
        }
        self.t_col = position[selection["timestamp"][0]]

    def log(self, values: Array) -> Log:
        """``values`` (n, len(wanted)) as a Log."""
        t = values[:, self.t_col]
        if self.scale is None:
            unit = time_unit(t, self.path)
            self.scale = TIME_UNITS[unit]
            if unit != "s":
                self.notes.append(f"{self.path}: timestamps are in {unit}; converted to s")
        if self.scale != 1.0:
            t = t * self.scale
        signals = {
            name: values[:, cols[0]] if scalar else values[:, cols]
            for name, (cols, scalar) in self.signals.items()
        }
        notes, self.notes = self.notes, []
        ignored, self.ignored = self.ignored, ()
        return Log(self.path, np.ascontiguousarray(t), signals, notes, ignored)


def _rtde_chunks(
    path: Path,
    *,
    columns: Columns | Sequence[str] | None,
    repair: bool,
    select: Sequence[str] | None,
    rows: int,
) -> Iterator[Log]:
    """The :class:`~kinergy.io.formats.LogFormat` reader of record.py logs and headerless
    files: the fast reader (:mod:`kinergy.io.log_arrow`) while the file is well formed, the
    careful one (:mod:`kinergy.io.log_text`) to repair it or to say what is wrong with it."""
    layout = log_layout(path, columns)
    selection = _selection(layout, select)
    chunker = _Chunker(layout, selection, [])
    done, previous = 0, None
    if layout.plain and not repair:
        try:
            for values in arrow_chunks(layout, chunker.wanted, rows):
                t = values[:, chunker.t_col]
                if np.any(np.diff(t) <= 0) or (previous is not None and t[0] <= previous):
                    raise NotPlain
                if done == 0 and len(values) < 2:
                    raise NotPlain
                yield chunker.log(values)
                done, previous = done + len(values), float(t[-1])
            if done >= 2:
                return
        except NotPlain:
            pass
    values, notes = read_text_table(layout, repair=repair)
    chunker.notes.extend(notes)
    values = values[:, chunker.wanted]
    for start in range(done, len(values), rows):
        yield chunker.log(values[start : start + rows])


def _any_text(path: Path, head: str) -> bool:
    """record.py logs and headerless files: any text (the reader says what is wrong)."""
    return True


#: UR's RTDE ``record.py`` layout and headerless delimited files
RTDE = register(LogFormat("rtde", _any_text, _rtde_chunks))


def write_log(
    path: str | os.PathLike[str],
    t: Array,
    signals: Mapping[str, Array],
    *,
    order: Iterable[str] | None = None,
) -> None:
    """Write a log in record.py layout (header line, space separated), atomically.

    Parameters
    ----------
    path : path
    t : ndarray, shape (N,)
        Time stamps, s.
    signals : mapping of str to ndarray
        (N, n) vectors (written as ``name_0..name_{n-1}``) or (N,) scalars.
    order : iterable of str, optional
        Signal order; default the mapping's.
    """
    path = Path(path)
    header = ["timestamp"]
    cols = [np.asarray(t, dtype=float)[:, None]]
    for name in order if order is not None else signals:
        arr = np.asarray(signals[name], dtype=float)
        if arr.ndim == 1:
            header.append(name)
            cols.append(arr[:, None])
        else:
            header.extend(f"{name}_{k}" for k in range(arr.shape[1]))
            cols.append(arr)
    data = np.hstack(cols)

    def write(fh: IO[str]) -> None:
        fh.write(" ".join(header) + "\n")
        np.savetxt(fh, data, fmt="%.10g", delimiter=" ")

    atomic_write(path, write)


def exact_text(values: Array) -> list[str]:
    """printf formats for the columns of ``values`` (shape (N, m)): per column the shortest of
    ``%.10g``, ``%.12g``, ``%.15g`` and ``%.17g`` whose text reads back as the same float64, so
    that a log written with them is read back bit for bit."""
    out = []
    for column in np.asarray(values, dtype=float).T:
        for digits in (10, 12, 15, 17):
            fmt = f"%.{digits}g"
            if digits == 17 or np.array_equal(np.char.mod(fmt, column).astype(float), column):
                out.append(fmt)
                break
    return out


def _header(log: Log, order: Sequence[str]) -> list[str]:
    """``timestamp`` and the column names of ``log``'s signals in ``order`` (vectors
    ``name_0..``)."""
    header = ["timestamp"]
    for name in order:
        arr = log[name]
        header += [name] if arr.ndim == 1 else [f"{name}_{k}" for k in range(arr.shape[1])]
    return header


def write_log_chunks(
    path: str | os.PathLike[str], chunks: Iterable[Log], *, order: Sequence[str] | None = None
) -> int:
    """Write a log given in chunks in record.py layout (header line, space separated), whole or
    not at all, each value as the text that reads back as the same float64 (:func:`exact_text`).

    Parameters
    ----------
    path : path
    chunks : iterable of Log
        In time order, each with the signals of the first (in ``order``, default the first
        chunk's).

    Returns
    -------
    int
        The rows written.
    """
    rows = 0
    with atomic_open(path) as fh:
        names: Sequence[str] | None = order
        for chunk in chunks:
            if names is None:
                names = list(chunk.signals)
            if rows == 0:
                fh.write(" ".join(_header(chunk, names)) + "\n")
            data = np.column_stack([chunk.t, *[chunk[n] for n in names]])
            np.savetxt(fh, data, fmt=exact_text(data), delimiter=" ")
            rows += len(chunk)
    return rows
