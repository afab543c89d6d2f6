"""Robot controller logs: UR's RTDE ``record.py`` layout in and out, and headerless files.

``record.py`` writes a header line naming every column, vectors as ``name_0 .. name_5``, values
space separated (comma separated files are read too)::

    timestamp target_q_0 ... target_q_5 actual_q_0 ... actual_current_5 ...

A headerless file needs a column spec (``--columns``), RTDE field names with ``:n`` for an
n-vector::

    timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6

Every problem is one line naming the file and, where it applies, the line and column.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import IO

import numpy as np
from numpy.typing import NDArray

from kinergy.errors import KinergyError
from kinergy.files import atomic_write
from kinergy.io.log import Log

__all__ = ["parse_columns", "read_log", "write_log"]

Array = NDArray[np.float64]

_VECTOR = re.compile(r"^(?P<name>.+)_(?P<index>\d+)$")


def parse_columns(spec: str) -> list[str]:
    """Expand a column spec ``"timestamp,actual_q:6,..."`` into column names.

    Raises
    ------
    KinergyError
        An empty or malformed entry, a bad count, or a repeated name.
    """
    names: list[str] = []
    for raw in spec.split(","):
        item = raw.strip()
        if not item:
            raise KinergyError(f"--columns: empty entry in {spec!r}")
        if ":" in item:
            name, _, count = item.partition(":")
            if not name or not count.isdigit() or int(count) < 1:
                raise KinergyError(
                    f"--columns: {item!r} must be NAME or NAME:COUNT with COUNT >= 1"
                )
            names.extend(f"{name}_{k}" for k in range(int(count)))
        else:
            names.append(item)
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise KinergyError(f"--columns: repeated column(s) {', '.join(dup)}")
    if "timestamp" not in names:
        raise KinergyError("--columns: needs a 'timestamp' column")
    return names


def _group(columns: Sequence[str], path: str) -> dict[str, list[str]]:
    """Group ``name_0..name_k`` columns into vectors; other columns stay scalars."""
    groups: dict[str, dict[int, str]] = {}
    scalars: list[str] = []
    for col in columns:
        m = _VECTOR.match(col)
        if m:
            groups.setdefault(m["name"], {})[int(m["index"])] = col
        else:
            scalars.append(col)
    out: dict[str, list[str]] = {}
    for name, members in groups.items():
        idx = sorted(members)
        if idx != list(range(len(idx))):
            raise KinergyError(
                f"{path}: columns {name}_* are not numbered 0..{len(idx) - 1} (have {idx})"
            )
        out[name] = [members[i] for i in idx]
    for col in scalars:
        if col in out:
            raise KinergyError(f"{path}: column {col!r} is both a scalar and a vector name")
        out[col] = [col]
    return out


def _first_line(path: Path) -> str:
    try:
        with path.open("r", encoding="utf-8", errors="replace") as fh:
            return fh.readline()
    except OSError as exc:
        raise KinergyError(f"{path}: cannot read log ({exc.strerror})") from None


def _good_rows(t: Array, finite: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Rows to keep when repairing: finite, and on one chain of increasing time stamps whose
    steps stay under 50 median periods (garbage rows a recorder wrote fall off it)."""
    idx = np.flatnonzero(finite)
    keep = np.zeros(t.size, dtype=bool)
    if idx.size < 2:
        return keep
    steps = np.diff(t[idx])
    positive = steps[steps > 0]
    if positive.size == 0:
        return keep
    limit = 50.0 * float(np.median(positive))
    ok = (steps > 0) & (steps <= limit)
    # start from the longest clean run, then walk forward and backward from it
    edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.astype(int), [0]])))
    starts, stops = edges[::2], edges[1::2]
    if starts.size == 0:
        keep[idx[0]] = True
        return keep
    k = int(np.argmax(stops - starts))
    first, last = int(starts[k]), int(stops[k])  # rows idx[first..last] are one clean run
    keep[idx[first : last + 1]] = True
    t_last = t[idx[last]]
    for i in idx[last + 1 :]:
        if 0 < t[i] - t_last <= limit:
            keep[i] = True
            t_last = t[i]
    t_first = t[idx[first]]
    for i in idx[:first][::-1]:
        if 0 < t_first - t[i] <= limit:
            keep[i] = True
            t_first = t[i]
    return keep


def read_log(
    path: str | os.PathLike[str], *, columns: str | None = None, repair: bool = False
) -> Log:
    """Read a controller log (record.py layout, or headerless with a column spec).

    Parameters
    ----------
    path : path
    columns : str, optional
        Column spec of a headerless file (see the module docstring).
    repair : bool
        Drop malformed rows (cut short, non-numeric, time stamps out of order or far off) instead
        of rejecting the file; the log's ``notes`` say how many and which lines.

    Returns
    -------
    Log

    Raises
    ------
    KinergyError
        Unreadable file; no ``timestamp``; a line with too many or too few fields (a truncated
        last line included); a non-numeric or missing value (line and column named); time stamps
        that repeat or go back.
    """
    import pandas as pd  # imported here: it is slow to import and only reading needs it

    path = Path(path)
    head = _first_line(path)
    if not head.strip():
        raise KinergyError(f"{path}: empty log")
    sep = "," if "," in head else r"\s+"
    if columns is None:
        names = head.strip().replace(",", " ").split()
        if not names or names[0][:1].isdigit() or names[0][:1] in "+-.":
            raise KinergyError(
                f"{path}: no header line (record.py layout); give the layout with --columns"
            )
        skip = 1
    else:
        names = parse_columns(columns)
        skip = 0
    if "timestamp" not in names:
        raise KinergyError(f"{path}: no 'timestamp' column")
    try:
        frame = pd.read_csv(
            path,
            sep=sep,
            header=None,
            skiprows=skip,
            dtype=str,
            engine="c",
            keep_default_na=False,
            skip_blank_lines=True,
        )
    except pd.errors.ParserError as exc:
        raise KinergyError(f"{path}: {str(exc).strip().splitlines()[-1]}") from None
    except pd.errors.EmptyDataError:
        raise KinergyError(f"{path}: no data rows") from None
    # a trailing delimiter gives one more, empty column
    while frame.shape[1] > len(names) and (frame.iloc[:, -1] == "").all():
        frame = frame.iloc[:, :-1]
    if frame.shape[1] != len(names):
        raise KinergyError(
            f"{path}: rows have {frame.shape[1]} fields but the "
            f"{'header' if columns is None else '--columns spec'} names {len(names)}"
        )
    frame.columns = names
    values = frame.apply(pd.to_numeric, errors="coerce").to_numpy(dtype=float)
    bad = ~np.isfinite(values)
    notes: list[str] = []
    if repair:
        keep = _good_rows(values[:, names.index("timestamp")], ~bad.any(axis=1))
        if not keep.all():
            lines = np.flatnonzero(~keep) + skip + 1
            shown = ", ".join(str(x) for x in lines[:8]) + (" ..." if lines.size > 8 else "")
            notes.append(f"{path}: dropped {lines.size} malformed row(s) at line(s) {shown}")
        frame, values, bad = frame.iloc[keep], values[keep], bad[keep]
    if bad.any():
        row, col = np.argwhere(bad)[0]
        line = int(row) + skip + 1
        raw = frame.iat[int(row), int(col)]
        what = "missing value (truncated line?)" if raw == "" else f"not a finite number: {raw!r}"
        hint = "; the last line is cut short (--repair drops it)" if row == len(frame) - 1 else ""
        raise KinergyError(f"{path}: line {line}, column {col + 1} ({names[col]}): {what}{hint}")
    t = values[:, names.index("timestamp")]
    if t.size < 2:
        raise KinergyError(f"{path}: needs at least 2 samples, has {t.size}")
    step = np.diff(t)
    if np.any(step <= 0):
        k = int(np.argmax(step <= 0))
        kind = "repeats" if step[k] == 0 else "goes back"
        raise KinergyError(
            f"{path}: line {k + 2 + skip}: timestamp {kind} ({t[k]} then {t[k + 1]})"
        )
    signals: dict[str, Array] = {}
    for name, cols in _group(names, str(path)).items():
        if name == "timestamp":
            continue
        idx = [names.index(c) for c in cols]
        is_vector = not (len(cols) == 1 and cols[0] == name)
        signals[name] = values[:, idx] if is_vector else values[:, idx[0]]
    return Log(str(path), t, signals, notes)


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
