"""The layout of a delimited log file: its column names, delimiter and header lines, found from
its first two lines before any data is read.

A record.py log starts with a header line naming its columns; a headerless one is described by a
column spec (:func:`kinergy.io.columns.parse_columns`). A UTF-8 byte-order mark is skipped.

A header log is read as its logger wrote it: a column is read when its name is an RTDE field
(or one of kinergy's, :mod:`kinergy.io.fields`), after the user's mapping of the header's own
names (:class:`kinergy.io.columns.ColumnMap`), and ignored otherwise (a logger's wall-clock
string, a user's own column), as is a known field that holds no numbers on the first line
(a bit mask a logger wrote as text) unless kinergy uses it. The ignored columns are never
converted; the reader names them in one note.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from kinergy.errors import KinergyError
from kinergy.io.columns import MAX_COLUMNS, ColumnMap, Columns, printable
from kinergy.io.fields import USED, closest, is_known, vector_member

__all__ = ["LogLayout", "first_lines", "log_layout"]

#: the most comment lines (starting with ``#``) a log may begin with
_MAX_COMMENTS = 100
#: the longest first line read to find a layout: MAX_COLUMNS columns of 64 characters each
_MAX_LINE = MAX_COLUMNS * 64


@dataclass(frozen=True)
class LogLayout:
    """How a delimited log is laid out.

    Attributes
    ----------
    path : Path
    names : list of str
        The columns, in file order.
    sep : str
        ``","``, ``";"`` or ``" "`` (any run of white space when not :attr:`plain`).
    skip : int
        Lines before the data: comments (starting with ``#``) and the header line.
    source : str
        What named the columns, for messages: ``"header"`` or ``"--columns spec"``.
    plain : bool
        The first data line has exactly one delimiter between fields (no runs of spaces, no tabs)
        and as many fields as :attr:`names`, or one more that is empty: a fast reader can read it.
    trailing : bool
        Lines end with a delimiter (one more, empty field).
    ignored : tuple of str
        The header's columns that are not read (no RTDE field), as the header names them; in
        :attr:`names` they are skipped columns (``_k``).
    textual : tuple of str
        Known fields ignored because their first value is not a number (text a logger wrote).
    header : tuple of str
        The columns as the file's header names them (empty for a headerless file).
    """

    path: Path
    names: list[str]
    sep: str
    skip: int
    source: str
    plain: bool
    trailing: bool
    ignored: tuple[str, ...] = ()
    textual: tuple[str, ...] = ()
    header: tuple[str, ...] = ()

    def label(self, k: int) -> str:
        """Column ``k`` as messages name it: the header's name, and what it is read as when the
        user mapped it (``--columns``)."""
        name = self.names[k]
        own = self.header[k] if len(self.header) == len(self.names) else name
        if own == name or name.startswith("_"):
            return own
        return f"{own}, read as {name}"

    def note(self) -> str | None:
        """The one note naming the columns not read, or None when every column is."""
        if not (self.ignored or self.textual):
            return None
        parts = []
        if self.ignored:
            shown = ", ".join(printable(n, 40) for n in self.ignored[:8])
            more = f" and {len(self.ignored) - 8} more" if len(self.ignored) > 8 else ""
            parts.append(
                f"{len(self.ignored)} column(s) that are no RTDE field ({shown}{more}); "
                "map a column to a field with --columns FIELD=COLUMN"
            )
        if self.textual:
            parts.append(f"{', '.join(self.textual)} (not numbers, and not used)")
        return f"{self.path}: ignored {'; and '.join(parts)}"


def first_lines(path: Path, count: int) -> list[str]:
    """The first ``count`` lines of ``path`` (each at most ``_MAX_LINE`` characters), decoded
    as UTF-8 with a byte-order mark removed.

    Raises
    ------
    KinergyError
        The file cannot be opened or read, or a first line is longer than the limit.
    """
    _check_encoding(path)
    lines: list[str] = []
    try:
        with path.open("r", encoding="utf-8-sig", errors="replace", newline="") as fh:
            for _ in range(count):
                line = fh.readline(_MAX_LINE + 1)
                if len(line) > _MAX_LINE:
                    raise KinergyError(
                        f"{path}: line {len(lines) + 1} is longer than {_MAX_LINE} characters "
                        f"(at most {MAX_COLUMNS} columns)"
                    )
                lines.append(line)
    except OSError as exc:
        raise KinergyError(f"{path}: cannot read log ({exc.strerror})") from None
    return lines


def _check_encoding(path: Path) -> None:
    """Refuse a log in UTF-16 or UTF-32 (a spreadsheet's "Unicode text"), or a binary file."""
    try:
        with path.open("rb") as fh:
            head = fh.read(4096)
    except OSError as exc:
        raise KinergyError(f"{path}: cannot read log ({exc.strerror})") from None
    if head.startswith((b"\xff\xfe\x00\x00", b"\x00\x00\xfe\xff")):
        raise KinergyError(f"{path}: the log is UTF-32 text; save it as UTF-8")
    if head.startswith((b"\xff\xfe", b"\xfe\xff")) or head[1::2].count(0) > len(head) // 4 > 0:
        raise KinergyError(f"{path}: the log is UTF-16 text; save it as UTF-8")
    if b"\x00" in head:
        raise KinergyError(f"{path}: not a text log (it holds NUL bytes)")


def _separator(path: Path, head: str, data: str) -> str:
    """The field separator of a delimited log from its first lines: ``","``, ``";"`` or ``" "``
    (any run of white space, tabs too).

    Raises
    ------
    KinergyError
        Fields separated by ``;`` whose numbers have decimal commas (a spreadsheet's locale).
    """
    if ";" in head:
        if "," in data or "," in head:
            raise KinergyError(
                f"{path}: fields separated by ';' with decimal commas ({data.strip()[:40]!r}...): "
                "save the log with '.' as the decimal mark (and ',' or spaces between fields)"
            )
        return ";"
    return "," if "," in head else " "


def log_layout(path: Path, columns: Columns | Sequence[str] | None) -> LogLayout:
    """The layout of the log at ``path``; ``columns`` names the columns of a headerless file
    (:func:`kinergy.io.columns.parse_columns` of its ``--columns`` spec) or maps a header's
    names (:class:`kinergy.io.columns.ColumnMap`).

    Raises
    ------
    KinergyError
        Empty file; no header line and no layout; a layout for a file with a header line; more
        than :data:`MAX_COLUMNS` columns; no ``timestamp`` column; a mapping the header does not
        fit (:meth:`kinergy.io.columns.ColumnMap.rename`).
    """
    lines = first_lines(path, _MAX_COMMENTS + 2)
    comments = 0
    while comments < len(lines) and lines[comments].lstrip().startswith("#"):
        comments += 1
    head, data = [*lines[comments:], "", ""][:2]
    if not head.strip():
        raise KinergyError(
            f"{path}: empty log" if not comments else f"{path}: no data after its comments"
        )
    sep = _separator(path, head, data)
    fields = head.strip().replace(sep if sep != " " else ",", " ").split()
    first = fields[0] if fields else ""
    numeric = bool(first) and (first[:1].isdigit() or first[:1] in "+-.")
    ignored: tuple[str, ...] = ()
    textual: tuple[str, ...] = ()
    if columns is None or isinstance(columns, ColumnMap):
        if len(fields) > MAX_COLUMNS:
            raise KinergyError(
                f"{path}: the header names {len(fields)} columns; at most {MAX_COLUMNS}"
            )
        if not first or numeric:
            hint = (
                "FIELD=COLUMN maps a header's names; give this file's layout instead "
                "(--columns timestamp,actual_q:6,...)"
                if columns is not None
                else "give the layout with --columns"
            )
            raise KinergyError(f"{path}: no header line (record.py layout); {hint}")
        named = fields if columns is None else columns.rename(fields, str(path))
        cells = data.strip().replace(sep if sep != " " else ",", " ").split()
        names, ignored, textual = _read_columns(named, fields, cells)
        skip, source = comments + 1, "header"
    else:
        if not numeric and "timestamp" in fields:
            shown = ", ".join(fields[:3])
            raise KinergyError(
                f"{path}: the file names its columns in a header line ({shown}, ...): leave out "
                "--columns, or map its names to RTDE's with --columns FIELD=COLUMN,..."
            )
        names, skip, source, data = list(columns), comments, "--columns spec", head
    if "timestamp" not in names:
        own = list(ignored) or [n for n in names if not n.startswith("_")]
        guess = closest("timestamp", own)
        hint = f" ({guess!r} is not the name kinergy reads)" if guess else ""
        shown = ", ".join(printable(n, 20) for n in (fields if source == "header" else names)[:4])
        raise KinergyError(
            f"{path}: no 'timestamp' column{hint}; the {source} names {shown}, ...: kinergy reads "
            "UR's RTDE names (timestamp, actual_q_0, ...); map others with --columns "
            "timestamp=COLUMN,..."
        )
    if len(set(names)) != len(names):
        raise KinergyError(f"{path}: the {source} repeats a column name")
    cells = data.rstrip("\r\n").split(sep)
    trailing = len(cells) == len(names) + 1 and cells[-1] == ""
    same_width = len(cells) == len(names) + trailing
    single = sep in ",;" or cells == data.split()
    plain = same_width and single and "\t" not in data and '"' not in data
    header = tuple(fields) if source == "header" else ()
    return LogLayout(path, names, sep, skip, source, plain, trailing, ignored, textual, header)


def _number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def _read_columns(
    named: list[str], header: list[str], cells: list[str]
) -> tuple[list[str], tuple[str, ...], tuple[str, ...]]:
    """The column names to read a header log by (``named``: the header after the user's
    mapping), with the columns not read as skipped ones (``_k``, k the column's index), the
    header's names of those that are no field, and the known fields not read because their
    first value (``cells``: the first data line's fields, when it has as many) is no number and
    kinergy does not use them."""
    names: list[str] = []
    ignored: list[str] = []
    textual: set[str] = set()
    first = cells if len(cells) == len(named) else [""] * len(named)
    for k, name in enumerate(named):
        if name == f"_{k}":  # skipped by the user's mapping (``_=COLUMN``): not noted
            names.append(name)
            continue
        member = vector_member(name)
        field = member[0] if member is not None else name
        if not (is_known(name) or member is not None):
            names.append(f"_{k}")
            ignored.append(header[k])
        elif first[k] and not _number(first[k]) and field not in USED:
            names.append(f"_{k}")
            textual.add(field)
        else:
            names.append(name)
    return names, tuple(ignored), tuple(sorted(textual))
