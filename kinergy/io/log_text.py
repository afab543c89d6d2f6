"""The careful log reader: every cell read as text first, so that every problem names its line
and column, and ``repair`` can drop the rows at fault.

It holds the whole file; :mod:`kinergy.io.log_arrow` is the fast reader of well-formed files,
and the readers fall back to this one to say what is wrong with a file it refuses.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.io.columns import printable
from kinergy.io.log_layout import LogLayout

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["read_text_table"]


def read_text_table(layout: LogLayout, *, repair: bool = False) -> tuple[Array, list[str]]:
    """Every value of the log ``layout`` describes, checked.

    Parameters
    ----------
    layout : LogLayout
    repair : bool
        Drop malformed rows (cut short, non-numeric, time stamps out of order or far off)
        instead of rejecting the file.

    Returns
    -------
    values : ndarray, shape (N, K)
        One column per name of the layout, finite.
    notes : list of str
        The rows ``repair`` dropped.

    Raises
    ------
    KinergyError
        A line with too many or too few fields (a truncated last line included); a non-numeric,
        complex, non-finite or missing value (line and column named); fewer than 2 samples; time
        stamps that repeat or go back.
    """
    path, names, skip = layout.path, layout.names, layout.skip
    frame = _text_frame(layout)
    values = _numbers(frame)
    bad = ~np.isfinite(values)
    # a skipped column may hold anything but must be there (a line cut short is damaged)
    skipped = [k for k, name in enumerate(names) if re.fullmatch(r"_\d+", name)]
    bad[:, skipped] = np.asarray((frame.iloc[:, skipped] == "").to_numpy(), dtype=bool)
    notes: list[str] = []
    t_col = names.index("timestamp")
    if repair:
        keep = _good_rows(values[:, t_col], np.asarray(~bad.any(axis=1), dtype=bool))
        if not keep.all():
            lines = np.flatnonzero(~keep) + skip + 1
            shown = ", ".join(str(x) for x in lines[:8]) + (" ..." if lines.size > 8 else "")
            notes.append(f"{path}: dropped {lines.size} malformed row(s) at line(s) {shown}")
        frame, values, bad = frame.iloc[keep], values[keep], bad[keep]
    if bad.any():
        row, col = (int(x) for x in np.argwhere(bad)[0])
        what = _what(str(frame.iat[row, col]))
        hint = "; the last line is cut short (--repair drops it)" if row == len(frame) - 1 else ""
        raise KinergyError(
            f"{path}: line {row + skip + 1}, column {col + 1} ({printable(layout.label(col))}): "
            f"{what}{hint}"
        )
    check_times(values[:, t_col], layout, first_line=skip + 1)
    return values, notes


def check_times(
    t: Array, layout: LogLayout, *, first_line: int, previous: float | None = None
) -> None:
    """Raise one line if time stamps ``t`` (shape (N,), data starting at file line
    ``first_line``, after ``previous``) repeat or go back, or if the log has fewer than 2."""
    if previous is None and t.size < 2:
        raise KinergyError(f"{layout.path}: needs at least 2 samples, has {t.size}")
    full = t if previous is None else np.concatenate([[previous], t])
    step = np.diff(full)
    if np.any(step <= 0):
        k = int(np.argmax(step <= 0))
        kind = "repeats" if step[k] == 0 else "goes back"
        line = first_line + k + (1 if previous is None else 0)
        raise KinergyError(
            f"{layout.path}: line {line}: timestamp {kind} ({full[k]} then {full[k + 1]})"
        )


def _parser_problem(text: str, layout: LogLayout) -> str:
    """The CSV parser's complaint in the reader's own words (line numbers of the file)."""
    m = re.search(r"Expected (\d+) fields in line (\d+), saw (\d+)", text)
    if m:
        line = int(m[2])
        return (
            f"line {line} has {m[3]} fields where the {layout.source} names {m[1]} (a line cut "
            "short or run together: --repair drops such lines)"
        )
    if "EOF inside string" in text or "quote" in text.lower():
        return "a quote opened and never closed: a log holds numbers, not quoted text"
    return "cannot be read as delimited text: " + printable(text.strip().splitlines()[-1], 80)


def _text_frame(layout: LogLayout) -> pd.DataFrame:
    """The file as a pandas frame of strings, one column per name (a trailing empty column
    dropped)."""
    import pandas as pd  # imported here: slow to import, and only this reader needs it

    path, names = layout.path, layout.names
    try:
        frame = pd.read_csv(
            path,
            sep=layout.sep if layout.sep in ",;" else r"\s+",
            header=None,
            skiprows=layout.skip,
            dtype=str,
            engine="c",
            encoding="utf-8-sig",
            encoding_errors="replace",
            keep_default_na=False,
            skip_blank_lines=True,
        )
    except pd.errors.ParserError as exc:
        raise KinergyError(f"{path}: {_parser_problem(str(exc), layout)}") from None
    except pd.errors.EmptyDataError:
        raise KinergyError(f"{path}: no data rows") from None
    # a trailing delimiter gives one more, empty column
    while frame.shape[1] > len(names) and (frame.iloc[:, -1] == "").all():
        frame = frame.iloc[:, :-1]
    if frame.shape[1] != len(names):
        raise KinergyError(
            f"{path}: rows have {frame.shape[1]} fields but the {layout.source} names {len(names)}"
        )
    return frame


def _numbers(frame: pd.DataFrame) -> Array:
    """The frame's cells as floats; nan where a cell is not a number."""
    import pandas as pd  # imported here: slow to import, and only this reader needs it

    return np.asarray(frame.apply(pd.to_numeric, errors="coerce").to_numpy(dtype=float))


def _what(raw: str) -> str:
    """What is wrong with a cell that is not a finite number."""
    if raw == "":
        return "missing value (truncated line?)"
    what = f"not a finite number: {raw if len(raw) <= 60 else raw[:60] + '...'!r}"
    if "j" in raw.lower():
        try:
            complex(raw)
        except ValueError:
            return what
        return f"{what} (a complex number; a log holds real values)"
    return what


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
