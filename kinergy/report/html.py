"""The HTML report: a single self-contained page of sections, tables and figures.

The report is plain data (:class:`Section` holding :class:`Table` and :class:`Figure` values) and
one function, :func:`write_report`, that renders it through a Jinja2 template shipped with the
package (``kinergy/report/templates/report.html.j2``) and writes it atomically. The page needs
nothing from outside: the CSS is inline, there are no fonts, scripts or links to other hosts, and
the figures are PNG files beside it (e.g. written by :func:`kinergy.report.plots.save`) referred
to by relative paths, so the report folder can be moved, zipped or printed as it is.

All text (titles, paragraphs, cells, captions, meta values) is escaped: a report shows the text it
was given, never runs it.

Examples
--------
>>> from kinergy.report.html import Section, Table, write_report
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> table = Table("Energy per joint", ["joint", "E_elec [J]"], [["base", "12.5"]])
>>> write_report(
...     folder / "report.html",
...     title="UR5e energy",
...     subtitle="test A",
...     sections=[Section("Energy", "Signed integrals (UR5e eq 26).", tables=[table])],
... ).name
'report.html'
"""

from __future__ import annotations

import functools
import os
import re
import struct
import unicodedata
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath, PureWindowsPath
from typing import Any
from urllib.parse import quote

from kinergy._version import __version__
from kinergy.errors import KinergyError
from kinergy.files import atomic_write

__all__ = ["Figure", "Section", "Table", "write_report"]

#: Cell text read as "no value" in a numeric column; aligned with the numbers, not counted as text.
_PLACEHOLDERS = frozenset({"", "-", "–", "—", "n/a", "N/A", "na", "NA", "nan", "NaN"})
#: A number as a person writes it: optional sign (ASCII or U+2212 minus), digits with optional
#: thousands separators (comma, thin or no-break space), decimals, exponent, and an optional
#: percent sign; any other unit belongs in the column header.
_NUMBER = re.compile(
    r"""^[+\-\u2212]?
        (?:\d{1,3}(?:[,\u2009\u202f\u00a0]\d{3})+|\d+)?(?:\.\d+)?
        (?:[eE][+\-\u2212]?\d+)?
        \s*%?$""",
    re.VERBOSE,
)


# -- data ---------------------------------------------------------------------------------------


def _check_text(value: object, what: str) -> None:
    if not isinstance(value, str):
        raise KinergyError(f"{what}: expected text, got {type(value).__name__}")


@dataclass(frozen=True)
class Table:
    """A table of already formatted cells.

    Parameters
    ----------
    caption : str
        Shown above the table after its number, e.g. ``"Torque error per joint (test B)"``.
    headers : list of str, length m
        Column headings; put units here, e.g. ``"RMS [N m]"``.
    rows : list of list of str, each of length m
        Cell text, formatted by the caller (``f"{x:.3f}"``). A column whose cells all read as
        numbers (placeholders such as ``"n/a"`` or ``"—"`` aside) is right-aligned.
    note : str, optional
        One sentence under the table, e.g. what the comparison column is.

    Raises
    ------
    KinergyError
        If there is no header, a row's length differs from the headers' or a value is not text.
    """

    caption: str
    headers: list[str]
    rows: list[list[str]]
    note: str = ""

    def __post_init__(self) -> None:
        _check_text(self.caption, "Table.caption")
        _check_text(self.note, "Table.note")
        where = f"table {self.caption!r}"
        if not self.headers:
            raise KinergyError(f"{where}: no column header given")
        for k, h in enumerate(self.headers):
            _check_text(h, f"{where}: header {k}")
        m = len(self.headers)
        for i, row in enumerate(self.rows):
            if len(row) != m:
                raise KinergyError(
                    f"{where}: row {i} has {len(row)} cells, expected {m} like the headers"
                )
            for k, cell in enumerate(row):
                _check_text(cell, f"{where}: row {i}, column {k}")


@dataclass(frozen=True)
class Figure:
    """An image file shown with a caption.

    Parameters
    ----------
    path : str
        The image's path relative to the report's folder, with ``/`` between folders, e.g.
        ``"figures/test-a_current.png"``. Absolute paths and URLs are refused: the report must
        not depend on where it is opened or on a network.
    caption : str
        Shown under the image after its number; also the image's alternative text.

    Raises
    ------
    KinergyError
        If the path is empty, absolute or a URL, or a value is not text.
    """

    path: str
    caption: str

    def __post_init__(self) -> None:
        _check_text(self.path, "Figure.path")
        _check_text(self.caption, "Figure.caption")
        p = self.path
        if not p.strip():
            raise KinergyError(f"figure {self.caption!r}: empty path")
        if (
            PurePosixPath(p).is_absolute()
            or PureWindowsPath(p).is_absolute()
            or PureWindowsPath(p).drive
            or re.match(r"^[A-Za-z][A-Za-z0-9+.\-]*:", p)
        ):
            raise KinergyError(
                f"figure {p!r}: expected a path relative to the report's folder, "
                "not an absolute path or a URL"
            )


@dataclass(frozen=True)
class Section:
    """A titled part of the report: text, then its tables, then its figures.

    Parameters
    ----------
    title : str
        Heading, also the entry in the table of contents.
    text : str, optional
        Plain text (escaped, not HTML); paragraphs are separated by blank lines, and the line
        breaks inside a paragraph are kept as spaces.
    tables : list of Table, optional
    figures : list of Figure, optional

    Raises
    ------
    KinergyError
        If the title is blank or an entry has the wrong type.
    """

    title: str
    text: str = ""
    tables: list[Table] = field(default_factory=list)
    figures: list[Figure] = field(default_factory=list)

    def __post_init__(self) -> None:
        _check_text(self.title, "Section.title")
        _check_text(self.text, "Section.text")
        if not self.title.strip():
            raise KinergyError("section: empty title")
        for t in self.tables:
            if not isinstance(t, Table):
                raise KinergyError(
                    f"section {self.title!r}: expected Table in tables, got {type(t).__name__}"
                )
        for f in self.figures:
            if not isinstance(f, Figure):
                raise KinergyError(
                    f"section {self.title!r}: expected Figure in figures, got {type(f).__name__}"
                )


# -- helpers ------------------------------------------------------------------------------------


def _is_number(text: str) -> bool:
    """Whether ``text`` reads as one number: ``"-1.5"``, ``"1,234.5"``, ``"2.1e-3"``, ``"97 %"``.

    >>> [_is_number(s) for s in ("0.981", "−3", "1 234", "12.5 %", "inf", "base", "")]
    [True, True, False, True, True, False, False]
    """
    s = text.strip()
    if s.lower().lstrip("+-\u2212") in {"inf", "infinity"}:
        return True
    return bool(_NUMBER.match(s)) and any(c.isdigit() for c in s)


def _numeric_columns(table: Table) -> list[bool]:
    """Per column: every cell is a number or a placeholder, and at least one is a number."""
    flags = []
    for k in range(len(table.headers)):
        cells = [row[k].strip() for row in table.rows]
        values = [c for c in cells if c not in _PLACEHOLDERS]
        flags.append(bool(values) and all(_is_number(c) for c in values))
    return flags


def _slug(title: str, taken: set[str]) -> str:
    """An HTML id from a title: ASCII lower case words joined by '-', unique among ``taken``."""
    ascii_ = unicodedata.normalize("NFKD", title).encode("ascii", "ignore").decode()
    base = re.sub(r"[^a-z0-9]+", "-", ascii_.lower()).strip("-") or "section"
    base = f"s-{base}" if base[0].isdigit() else base
    slug, k = base, 2
    while slug in taken:
        slug, k = f"{base}-{k}", k + 1
    taken.add(slug)
    return slug


def _paragraphs(text: str) -> list[str]:
    """Paragraphs of plain text: split at blank lines, inner line breaks become spaces."""
    blocks = re.split(r"\n[ \t]*\n", text.replace("\r\n", "\n").strip())
    return [" ".join(line.strip() for line in b.splitlines()) for b in blocks if b.strip()]


def _png_size(path: Path) -> tuple[int, int] | None:
    """Width and height in pixels from a PNG's header, or None if the file is not a PNG."""
    with open(path, "rb") as fh:
        head = fh.read(24)
    if len(head) < 24 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        return None
    width, height = struct.unpack(">II", head[16:24])
    return int(width), int(height)


def _breakable(text: str) -> Any:
    """``text`` escaped, with a line-break opportunity (``<wbr>``) after each ``_`` and ``/``:
    a table cell such as ``coulomb_positive [N m]`` may wrap at ``coulomb_`` rather than
    overflow its card."""
    import markupsafe

    parts = re.split(r"(?<=[_/])(?=.)", text)
    return markupsafe.Markup("<wbr>").join(markupsafe.escape(part) for part in parts)


@functools.cache
def _template() -> Any:
    """The Jinja2 template, loaded once on first use (no work at import)."""
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("kinergy.report", "templates"),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )
    env.filters["breakable"] = _breakable
    return env.get_template("report.html.j2")


def _context(
    folder: Path,
    title: str,
    subtitle: str,
    sections: Sequence[Section],
    meta: Mapping[str, str],
) -> dict[str, Any]:
    """What the template shows, numbered and checked; raises before anything is written."""
    taken: set[str] = set()
    n_table = n_figure = 0
    missing: list[str] = []
    view_sections = []
    for number, section in enumerate(sections, start=1):
        tables = []
        for t in section.tables:
            n_table += 1
            tables.append(
                {
                    "number": n_table,
                    "caption": t.caption,
                    "headers": t.headers,
                    "rows": t.rows,
                    "note": t.note,
                    "numeric": _numeric_columns(t),
                }
            )
        figures = []
        for f in section.figures:
            n_figure += 1
            file = folder / f.path
            if not file.is_file():
                missing.append(f.path)
                continue
            size = _png_size(file)
            figures.append(
                {
                    "number": n_figure,
                    "src": quote(PureWindowsPath(f.path).as_posix(), safe="/"),
                    "caption": f.caption,
                    "width": size[0] if size else None,
                    "height": size[1] if size else None,
                }
            )
        view_sections.append(
            {
                "id": _slug(section.title, taken),
                "number": number,
                "title": section.title,
                "paragraphs": _paragraphs(section.text),
                "tables": tables,
                "figures": figures,
            }
        )
    if missing:
        names = ", ".join(repr(m) for m in missing)
        raise KinergyError(f"{folder}: figure file not found: {names}")
    return {
        "version": __version__,
        "title": title,
        "subtitle": subtitle,
        "meta": list(meta.items()),
        "sections": view_sections,
    }


# -- output -------------------------------------------------------------------------------------


def write_report(
    path: str | os.PathLike[str],
    *,
    title: str,
    subtitle: str,
    sections: Sequence[Section],
    meta: Mapping[str, str] | None = None,
) -> Path:
    """Render the report as one HTML page and write it atomically.

    The page has a header (title, subtitle and the ``meta`` key/value block), a table of
    contents linking to each section, then the numbered sections with their numbered tables
    (numeric columns right-aligned) and figures (scaled to the text width). Everything is
    escaped; the CSS is inline and the page loads nothing from outside but its figures.

    Parameters
    ----------
    path : str or os.PathLike
        The HTML file to write, e.g. ``"out/report.html"``; its folder is created if missing.
        Figure paths are relative to this folder.
    title : str
    subtitle : str
        One line under the title, e.g. what was identified from which logs.
    sections : sequence of Section
    meta : mapping of str to str, optional
        Small facts shown at the top, in order: robot, date, kinergy version, logs...

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    KinergyError
        If a figure file does not exist (naming it), a value is not text, or the file cannot be
        written. Nothing is written then: an earlier report at ``path`` stays as it was.
    """
    target = Path(path)
    _check_text(title, "title")
    _check_text(subtitle, "subtitle")
    meta = dict(meta or {})
    for k, v in meta.items():
        _check_text(k, "meta key")
        _check_text(v, f"meta[{k!r}]")
    for s in sections:
        if not isinstance(s, Section):
            raise KinergyError(f"sections: expected Section, got {type(s).__name__}")

    context = _context(target.parent, title, subtitle, sections, meta)
    text = _template().render(**context)

    return atomic_write(target, lambda fh: fh.write(text))
