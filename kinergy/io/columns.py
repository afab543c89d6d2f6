"""Log columns: the ``--columns`` spec of a headerless file, and vectors grouped by name.

RTDE writes an n-vector as columns ``name_0 .. name_{n-1}``; a column spec names them
``name:n``. Both are capped (:data:`MAX_COLUMNS`) and checked before anything is allocated.

Examples
--------
>>> parse_columns("timestamp,actual_q:2,robot_mode")
['timestamp', 'actual_q_0', 'actual_q_1', 'robot_mode']
>>> group_columns(["timestamp", "a_0", "a_1"], "log.csv")
{'a': ['a_0', 'a_1'], 'timestamp': ['timestamp']}
"""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Sequence

from kinergy.errors import KinergyError

__all__ = ["MAX_COLUMNS", "group_columns", "parse_columns", "printable"]

#: the most columns a log may have (RTDE's whole output recipe is a few hundred)
MAX_COLUMNS = 2000

_VECTOR = re.compile(r"^(?P<name>.+)_(?P<index>\d+)$")
_CONTROL = re.compile(r"[\x00-\x1f\x7f]")


def printable(text: str, limit: int = 60) -> str:
    """``text`` safe to print on one line: control characters (NUL included) escaped, cut at
    ``limit`` characters."""
    short = text if len(text) <= limit else text[:limit] + "..."
    return _CONTROL.sub(lambda m: repr(m.group())[1:-1], short)


def parse_columns(spec: str) -> list[str]:
    """Expand a column spec ``"timestamp,actual_q:6,..."`` into column names.

    Raises
    ------
    KinergyError
        An empty or malformed entry, a bad count, more than :data:`MAX_COLUMNS` columns (refused
        before they are expanded), a repeated name, or no ``timestamp``.
    """
    names: list[str] = []
    for raw in spec.split(","):
        item = raw.strip()
        if not item:
            raise KinergyError(f"--columns: empty entry in {printable(spec)!r}")
        name, colon, count = item.partition(":")
        if colon and (not name or not count.isdigit() or int(count) < 1):
            raise KinergyError(
                f"--columns: {printable(item)!r} must be NAME or NAME:COUNT with COUNT >= 1"
            )
        width = int(count) if colon else 1
        if len(names) + width > MAX_COLUMNS:
            raise KinergyError(
                f"--columns: the spec expands to more than {MAX_COLUMNS} columns "
                f"(at {printable(item)!r})"
            )
        names.extend([f"{name}_{k}" for k in range(width)] if colon else [item])
    dup = sorted(n for n, times in Counter(names).items() if times > 1)
    if dup:
        raise KinergyError(f"--columns: repeated column(s) {printable(', '.join(dup))}")
    if "timestamp" not in names:
        raise KinergyError("--columns: needs a 'timestamp' column")
    return names


def group_columns(columns: Sequence[str], path: str) -> dict[str, list[str]]:
    """Group ``name_0..name_k`` columns into vectors; other columns stay scalars.

    Returns
    -------
    dict of str to list of str
        Signal name -> its columns in order (vectors first, in order of appearance, then
        scalars), linear in the number of columns.
    """
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
            shown = idx if len(idx) <= 8 else [*idx[:8], "..."]
            raise KinergyError(
                f"{path}: columns {printable(name)}_* are not numbered 0..{len(idx) - 1} "
                f"(have {shown})"
            )
        out[name] = [members[i] for i in idx]
    for col in scalars:
        if col in out:
            raise KinergyError(
                f"{path}: column {printable(col)!r} is both a scalar and a vector name"
            )
        out[col] = [col]
    return out
