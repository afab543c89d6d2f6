"""The fast log reader: pyarrow's multi-threaded CSV parser, only the wanted columns converted,
in chunks of a bounded number of rows.

It reads well-formed files only: any parse or conversion error, and any value that is not
finite, raises :class:`NotPlain`, and the caller asks :mod:`kinergy.io.log_text` what is wrong
(that reader names the line and column).
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Sequence

import numpy as np

from kinergy.arrays import Array
from kinergy.io.log_layout import LogLayout

__all__ = ["NotPlain", "arrow_chunks"]


#: the name given to the empty field after a trailing delimiter
_TRAILING = "\x00trailing"


#: the names of skipped columns (``_`` in a column spec)
_SKIPPED = re.compile(r"_\d+")


class NotPlain(Exception):
    """The fast reader cannot read this file as it is; the careful reader must look."""


def arrow_chunks(layout: LogLayout, wanted: Sequence[int], rows: int) -> Iterator[Array]:
    """The columns ``wanted`` (indices into ``layout.names``) of a plain log, as float arrays of
    shape (n <= rows, len(wanted)), in file order.

    Raises
    ------
    NotPlain
        A line the parser or the float conversion refuses, or a value that is not finite.
    """
    import pyarrow as pa  # imported here: heavy, and only reading a file needs it
    from pyarrow import csv

    names = list(layout.names) + ([_TRAILING] if layout.trailing else [])
    # every column is converted (a cell that is not a number anywhere is a damaged line), the
    # skipped ones (``_0``, ``_1``, ...) excepted; the wanted ones are returned
    checked = [n for n in layout.names if not _SKIPPED.fullmatch(n)]
    position = {name: k for k, name in enumerate(checked)}
    keep = [position[layout.names[i]] for i in wanted]
    options = {
        "read_options": csv.ReadOptions(column_names=names, block_size=1 << 20),
        "parse_options": csv.ParseOptions(delimiter=layout.sep, quote_char=False),
        "convert_options": csv.ConvertOptions(
            column_types=dict.fromkeys(checked, pa.float64()),
            include_columns=checked,
            null_values=[],
            strings_can_be_null=False,
        ),
    }
    try:
        blocks = _line_blocks(layout, _block_size(layout, rows))
        tables = (_values(csv.read_csv(pa.py_buffer(text), **options))[:, keep] for text in blocks)
        yield from _rebatched(tables, rows)
    except (pa.ArrowInvalid, pa.ArrowTypeError, OSError, UnicodeDecodeError):
        raise NotPlain from None


def _line_blocks(layout: LogLayout, size: int) -> Iterator[bytes]:
    """The file after its header, in blocks of about ``size`` bytes cut after a newline: what
    is parsed at once (pyarrow's own streaming reader reads far ahead of its consumer)."""
    with layout.path.open("rb") as fh:
        for _ in range(layout.skip):
            fh.readline()
        rest = b""
        while block := fh.read(size):
            data = rest + block
            cut = data.rfind(b"\n") + 1
            rest = data[cut:]
            if cut:
                yield data[:cut]
        if rest.strip():
            yield rest


def _values(batch: object) -> Array:
    """A record batch's columns as one float array (n, k); NotPlain if any is not finite."""
    columns = [batch.column(k).to_numpy(zero_copy_only=False) for k in range(batch.num_columns)]  # type: ignore[attr-defined]
    values = np.column_stack(columns) if columns else np.empty((0, 0))
    if not np.isfinite(values).all():
        raise NotPlain
    return values


def _rebatched(parts: Iterator[Array], rows: int) -> Iterator[Array]:
    """``parts`` joined and cut into arrays of exactly ``rows`` rows (the last one shorter)."""
    held: list[Array] = []
    count = 0
    for part in parts:
        held.append(part)
        count += len(part)
        while count >= rows:
            joined = np.concatenate(held) if len(held) > 1 else held[0]
            yield joined[:rows]
            held, count = [joined[rows:]], count - rows
    if count:
        yield np.concatenate(held)


def _block_size(layout: LogLayout, rows: int) -> int:
    """Bytes parsed at once: about ``rows`` lines of the file (from its first 64 kB), 64 kB to
    4 MB (parsing takes about 15 times the text's size)."""
    with layout.path.open("rb") as fh:
        head = fh.read(1 << 16)
    per_line = max(len(head) // max(head.count(b"\n"), 1), 1)
    return int(min(max(per_line * rows, 1 << 16), 1 << 22))
