"""Log columns: the ``--columns`` spec, and vectors grouped by name.

``--columns`` says one of two things, told apart by its entries:

- the layout of a headerless file (:func:`parse_columns`): RTDE's field names in file order,
  ``name:n`` for an n-vector (its columns ``name_0 .. name_{n-1}``), ``_`` or ``_:n`` for
  columns to skip;
- how a header log's own names map to RTDE's (:class:`ColumnMap`): entries ``FIELD=COLUMN``,
  ``*`` in ``COLUMN`` standing for a vector's index (``actual_q=positions_*`` reads the columns
  ``positions_0``, ``positions_1``, ... as ``actual_q``, in the order of their numbers, whatever
  the first one is); ``_=COLUMN`` leaves the column(s) unread, as ``_`` skips columns of a
  headerless file. Columns the header names by RTDE's names stay as they are.

Both are capped (:data:`MAX_COLUMNS`) and checked before anything is allocated.

Examples
--------
>>> parse_columns("timestamp,actual_q:2,_,robot_mode")
['timestamp', 'actual_q_0', 'actual_q_1', '_0', 'robot_mode']
>>> spec = parse_column_spec("timestamp=time,actual_q=pos_*", 2)
>>> spec.rename(["time", "pos_1", "pos_2", "note"], "log.csv")
['timestamp', 'actual_q_0', 'actual_q_1', 'note']
>>> group_columns(["timestamp", "a_0", "a_1"], "log.csv")
{'a': ['a_0', 'a_1'], 'timestamp': ['timestamp']}
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from kinergy.errors import KinergyError
from kinergy.io.fields import FIELDS, JOINTS, SKIP, closest, is_known

__all__ = [
    "MAX_COLUMNS",
    "ColumnMap",
    "Columns",
    "check_joint_columns",
    "compact_columns",
    "group_columns",
    "parse_column_spec",
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


@dataclass(frozen=True)
class ColumnMap:
    """A header log's own column names mapped to RTDE fields (``--columns
    "timestamp=time,actual_q=positions_*"``; module docstring).

    Attributes
    ----------
    entries : tuple of (str, str)
        ``(field, column)`` pairs: an RTDE field (or one of kinergy's) and the header's name for
        it, ``*`` in the name standing for a vector's index.
    n_joints : int or None
        The robot's joint count: a joint field must map exactly this many columns.
    """

    entries: tuple[tuple[str, str], ...]
    n_joints: int | None = None

    def __str__(self) -> str:
        return ",".join(f"{name}={column}" for name, column in self.entries)

    def rename(self, header: Sequence[str], path: str) -> list[str]:
        """``header`` with the mapped columns under their RTDE names (a vector's members in the
        order of their numbers as ``field_0``, ``field_1``, ...), the others as they are.

        Raises
        ------
        KinergyError
            A mapped name the header lacks (naming a few it has), a vector whose numbers are not
            consecutive or whose count does not fit the field, a field the header names already.
        """
        out = list(header)
        taken: dict[int, str] = {}
        for name, column in self.entries:
            if name == SKIP:
                for member in self._members(name, column, header, path):
                    out[member] = f"{SKIP}{member}"  # a skipped column (never read)
                continue
            if name in header or f"{name}_0" in header:
                raise KinergyError(
                    f"{path}: --columns maps {printable(column)} to {name}, but the header names "
                    f"{name} itself; map one of them only"
                )
            for k, member in enumerate(self._members(name, column, header, path)):
                if member in taken:
                    raise KinergyError(
                        f"{path}: --columns maps column {printable(header[member])} twice "
                        f"({taken[member]} and {name})"
                    )
                taken[member] = name
                out[member] = name if "*" not in column else f"{name}_{k}"
        return out

    def _members(self, name: str, column: str, header: Sequence[str], path: str) -> list[int]:
        """The header's columns (indices, in order of their numbers) that ``column`` names."""
        shown = ", ".join(printable(h, 20) for h in header[:6]) + (
            ", ..." if len(header) > 6 else ""
        )
        if "*" not in column:
            if column not in header:
                raise KinergyError(
                    f"{path}: --columns {name}={printable(column)}: the header has no column "
                    f"{printable(column)} (it names {shown})"
                )
            return [list(header).index(column)]
        pattern = re.compile("^" + re.escape(column).replace(r"\*", r"(\d+)") + "$")
        found = sorted(
            (int(m[1]), k) for k, h in enumerate(header) if (m := pattern.match(h)) is not None
        )
        if not found:
            raise KinergyError(
                f"{path}: --columns {name}={printable(column)}: no column of the header matches "
                f"(it names {shown}); * stands for the index"
            )
        numbers = [i for i, _ in found]
        if numbers != list(range(numbers[0], numbers[0] + len(numbers))):
            raise KinergyError(
                f"{path}: --columns {name}={printable(column)} matches columns numbered "
                f"{', '.join(map(str, numbers[:8]))}: not consecutive"
            )
        want = FIELDS.get(name, 1)
        count = self.n_joints if want == JOINTS else want
        if name != SKIP and isinstance(count, int) and len(found) != count:
            what = "the robot's joints" if want == JOINTS else f"the values of {name}"
            raise KinergyError(
                f"{path}: --columns {name}={printable(column)} matches {len(found)} columns, but "
                f"{name} has {count} ({what})"
            )
        return [k for _, k in found]


#: what ``--columns`` says (:func:`parse_column_spec`): the column names of a headerless file,
#: or a header log's names mapped to RTDE's
Columns = tuple[str, ...] | ColumnMap


def parse_column_spec(spec: str, n_joints: int | None = None) -> Columns:
    """``--columns`` as what it says: entries ``FIELD=COLUMN`` map a header log's names
    (:class:`ColumnMap`), others lay out a headerless file (:func:`parse_columns`).

    Raises
    ------
    KinergyError
        Both kinds of entry in one spec; an entry of either kind that :func:`parse_columns` or
        the mapping refuses: an unknown field (with the closest known one), a vector field mapped
        without ``*`` or a scalar with it, a field or column given twice.
    """
    items = [item.strip() for item in spec.split(",")]
    mapped = [item for item in items if "=" in item]
    if not mapped:
        return tuple(parse_columns(spec, n_joints))
    if len(mapped) != len(items):
        plain = next(item for item in items if "=" not in item)
        raise KinergyError(
            f"--columns: {printable(plain)!r} beside FIELD=COLUMN entries: a spec either maps a "
            "header log's names (FIELD=COLUMN, ...) or lays out a headerless file (FIELD:N, ...)"
        )
    if len(items) > MAX_COLUMNS:
        raise KinergyError(f"--columns: more than {MAX_COLUMNS} entries")
    entries: list[tuple[str, str]] = []
    for item in items:
        name, _, column = (part.strip() for part in item.partition("="))
        _check_mapped(name, column, item, entries)
        entries.append((name, column))
    return ColumnMap(tuple(entries), n_joints)


def _check_mapped(name: str, column: str, item: str, seen: list[tuple[str, str]]) -> None:
    """Refuse a mapping entry that names no known field, maps a vector without ``*`` (or a
    scalar with it), or repeats a field or a column."""
    if not name or not column:
        raise KinergyError(f"--columns: {printable(item)!r} must be FIELD=COLUMN")
    if name == SKIP:  # _=COLUMN: not read
        return
    if not is_known(name):
        guess = closest(name)
        hint = f" (did you mean {guess}?)" if guess else ""
        raise KinergyError(
            f"--columns: unknown field {printable(name)!r}{hint}; map a column to one of UR's "
            "RTDE names (timestamp, actual_q, actual_qd, actual_current, target_moment, ...)"
        )
    vector = FIELDS.get(name, 1) != 1
    if vector and column.count("*") != 1:
        raise KinergyError(
            f"--columns: {name} is a vector: write {name}={printable(column)}_* (* stands for "
            "the index in the column names)"
        )
    if not vector and "*" in column:
        raise KinergyError(f"--columns: {name} is one value: map it to one column, without *")
    for other, col in seen:
        if other == name:
            raise KinergyError(f"--columns: {name} is mapped twice")
        if col == column:
            raise KinergyError(f"--columns: column {printable(column)} is mapped twice")


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


def group_columns(
    columns: Sequence[str], path: str, others: Sequence[str] = ()
) -> dict[str, list[str]]:
    """Group ``name_0..name_k`` columns into vectors; other columns stay scalars (the known
    scalars of RTDE too, ``output_bit_registers0_to_31``). ``others``: the file's columns not
    read (no field), looked at for a misspelling where a vector lacks a member.

    Returns
    -------
    dict of str to list of str
        Signal name -> its columns in order (vectors first, in order of appearance, then
        scalars), linear in the number of columns.
    """
    groups: dict[str, dict[int, str]] = {}
    scalars: list[str] = []
    for col in columns:
        m = None if is_known(col) else _VECTOR.match(col)  # a known scalar: one column
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
            pool = [*columns, *others]
            candidates = [  # a column of another known vector is not a misspelling
                c for c in pool if c.endswith(f"_{index}") and not is_known(c.rsplit("_", 1)[0])
            ]
            near = [c for c in [closest(missing[0], candidates)] if c is not None]
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
