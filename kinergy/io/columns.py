"""Log columns: the ``--columns`` spec of a headerless file, and vectors grouped by name.

RTDE writes an n-vector as columns ``name_0 .. name_{n-1}``; a column spec names them
``name:n``. Both are capped (:data:`MAX_COLUMNS`) and checked before anything is allocated.

Examples
--------
>>> parse_columns("timestamp,actual_q:2,_,robot_mode")
['timestamp', 'actual_q_0', 'actual_q_1', '_0', 'robot_mode']
>>> group_columns(["timestamp", "a_0", "a_1"], "log.csv")
{'a': ['a_0', 'a_1'], 'timestamp': ['timestamp']}
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from kinergy.errors import KinergyError
from kinergy.io.fields import FIELDS, JOINTS, SKIP, closest, is_known

__all__ = [
    "MAX_COLUMNS",
    "check_joint_columns",
    "compact_columns",
    "group_columns",
    "parse_columns",
    "printable",
]

#: the most columns a log may have (RTDE's whole output recipe is a few hundred)
MAX_COLUMNS = 2000

_VECTOR = re.compile(r"^(?P<name>.+)_(?P<index>\d+)$")
_CONTROL = re.compile(r"[\x00-\x1f\x7f]")


def printable(text: str, limit: int = 60) -> str:
    """``text`` safe to print on one line: control characters (NUL included) escaped, cut at
    ``limit`` characters."""
    short = text if len(text) <= limit else text[:limit] + "..."
    return _CONTROL.sub(lambda m: repr(m.group())[1:-1], short)


def parse_columns(spec: str, n_joints: int | None = None) -> list[str]:
    """Expand a column spec ``"timestamp,actual_q:6,..."`` into column names.

    Every entry is a known field (:mod:`kinergy.io.fields`: UR's RTDE names and kinergy's own),
    ``NAME`` for one column or ``NAME:COUNT`` for a vector; ``_`` or ``_:COUNT`` skips columns
    (named ``_0``, ``_1``, ... in the result, which readers leave out).

    Parameters
    ----------
    spec : str
    n_joints : int, optional
        The robot's joint count: a joint field (``actual_q``) must have exactly this many columns.

    Raises
    ------
    KinergyError
        An empty or malformed entry, an unknown name (with the closest known one), a count that
        does not fit the field, more than :data:`MAX_COLUMNS` columns (refused before they are
        expanded), a repeated name, or no ``timestamp``.
    """
    names: list[str] = []
    seen: dict[str, str] = {}
    skipped = 0
    for raw in spec.split(","):
        item = raw.strip()
        if not item:
            raise KinergyError(f"--columns: empty entry in {printable(spec)!r}")
        name, colon, count = item.partition(":")
        name = name.strip()
        if colon and (not name or not count.strip().isdigit() or int(count) < 1):
            raise KinergyError(
                f"--columns: {printable(item)!r} must be NAME or NAME:COUNT with COUNT >= 1"
            )
        width = int(count) if colon else 1
        if len(names) + width > MAX_COLUMNS:
            raise KinergyError(
                f"--columns: the spec expands to more than {MAX_COLUMNS} columns "
                f"(at {printable(item)!r})"
            )
        if name == SKIP:
            names.extend(f"_{skipped + k}" for k in range(width))
            skipped += width
            continue
        _check_entry(name, colon == ":", width, n_joints, seen)
        seen[name] = item
        names.extend([f"{name}_{k}" for k in range(width)] if colon else [name])
    if "timestamp" not in names:
        raise KinergyError("--columns: needs a 'timestamp' column")
    return names


def _check_entry(
    name: str, vector: bool, width: int, n_joints: int | None, seen: dict[str, str]
) -> None:
    """Refuse a spec entry that is unknown, repeated or of the wrong width, in one line."""
    if not is_known(name):
        guess = closest(name)
        hint = f" (did you mean {guess}?)" if guess else ""
        raise KinergyError(
            f"--columns: unknown field {printable(name)!r}{hint}; give UR's RTDE names "
            f"(timestamp, actual_q:N, actual_qd:N, actual_current:N, target_moment:N, ...) and "
            f"skip a column with _ (or _:N)"
        )
    if name in seen:
        guess = closest(name, [f for f in FIELDS if f != name and f not in seen])
        hint = f" (did you mean {guess} for one of them?)" if guess else ""
        raise KinergyError(f"--columns: {printable(name)!r} is given twice{hint}")
    kind = FIELDS.get(name, 1)
    if kind == JOINTS:
        if not vector:
            joints = n_joints if n_joints is not None else "N"
            raise KinergyError(f"--columns: {name} has one value per joint: write {name}:{joints}")
        _joint_width(name, width, n_joints)
    elif isinstance(kind, int) and (width != kind or vector != (kind > 1)):
        shown = f"{name}:{kind}" if kind > 1 else name
        raise KinergyError(
            f"--columns: {name} has {kind} value{'s' if kind > 1 else ''}: write {shown}"
        )


def _joint_width(name: str, width: int, n_joints: int | None) -> None:
    if n_joints is not None and width != n_joints:
        raise KinergyError(
            f"--columns: {name}:{width} but the robot has {n_joints} joints "
            f"(write {name}:{n_joints})"
        )


def check_joint_columns(names: Sequence[str], n_joints: int) -> None:
    """Refuse column ``names`` (a parsed spec, :func:`parse_columns`) whose per-joint fields
    (``actual_q:N``) do not have ``n_joints`` columns, in one line naming the spec's entry."""
    for name, members in group_columns(names, "--columns").items():
        if FIELDS.get(name) == JOINTS:
            _joint_width(name, len(members), n_joints)


def compact_columns(names: Sequence[str]) -> str:
    """A column spec for ``names`` (the inverse of :func:`parse_columns`): runs of
    ``name_0 .. name_{k-1}`` as ``name:k``, skipped columns as ``_`` or ``_:k``."""
    out: list[str] = []
    k = 0
    while k < len(names):
        if re.fullmatch(r"_\d+", names[k]):
            width = 1
            while k + width < len(names) and re.fullmatch(r"_\d+", names[k + width]):
                width += 1
            out.append("_" if width == 1 else f"_:{width}")
            k += width
            continue
        m = _VECTOR.match(names[k])
        base = m["name"] if m else None
        if base is not None and m is not None and m["index"] == "0":
            width = 1
            while k + width < len(names) and names[k + width] == f"{base}_{width}":
                width += 1
            out.append(f"{base}:{width}")
            k += width
        else:
            out.append(names[k])
            k += 1
    return ",".join(out)


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
            missing = [f"{name}_{i}" for i in range(idx[-1] + 1) if i not in members]
            shown = idx if len(idx) <= 8 else [*idx[:8], "..."]
            index = missing[0].rsplit("_", 1)[1]
            others = [  # a column of another known vector is not a misspelling
                c for c in columns if c.endswith(f"_{index}") and not is_known(c.rsplit("_", 1)[0])
            ]
            near = [c for c in [closest(missing[0], others)] if c is not None]
            hint = f"; {printable(near[0])!r} misspelled?" if near else ""
            raise KinergyError(
                f"{path}: no column {printable(missing[0])} although {printable(name)}_"
                f"{', _'.join(map(str, shown))} are there (numbered from 0){hint}"
            )
        out[name] = [members[i] for i in idx]
    for col in scalars:
        if col in out:
            raise KinergyError(
                f"{path}: column {printable(col)!r} is both a scalar and a vector name"
            )
        out[col] = [col]
    return out
