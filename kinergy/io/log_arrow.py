"""The fast log reader: pyarrow's multi-threaded CSV parser, only the wanted columns converted,
in chunks of a bounded number of rows.

It reads well-formed files only: any parse or conversion error, and any value that is not
finite, raises :class:`NotPlain`, and the caller asks :mod:`kinergy.io.log_text` what is wrong
(that reader names the line and column).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import numpy as np
from numpy.typing import NDArray

from kinergy.io.log_layout import LogLayout

__all__ = ["NotPlain", "arrow_chunks"]

Array = NDArray[np.float64]

#: the name given to the empty field after a trailing delimiter
_TRAILING = "\x00trailing"


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
    selected = [layout.names[i] for i in wanted]
    options = {
        "read_options": csv.ReadOptions(
            column_names=names, skip_rows=layout.skip, block_size=_block_size(layout, rows)
        ),
        "parse_options": csv.ParseOptions(delimiter=layout.sep, quote_char=False),
        "convert_options": csv.ConvertOptions(
            column_types=dict.fromkeys(selected, pa.float64()),
            include_columns=selected,
            null_values=[],
            strings_can_be_null=False,
        ),
    }
    try:
        reader = csv.open_csv(layout.path, **options)
        for batch in reader:
            values = np.empty((batch.num_rows, len(selected)))
            for k in range(len(selected)):
                values[:, k] = batch.column(k).to_numpy(zero_copy_only=False)
            if not np.isfinite(values).all():
                raise NotPlain
            for start in range(0, len(values), rows):
                yield values[start : start + rows]
    except (pa.ArrowInvalid, pa.ArrowTypeError, OSError, UnicodeDecodeError):
        raise NotPlain from None


def _block_size(layout: LogLayout, rows: int) -> int:
    """Bytes pyarrow reads per block: about ``rows`` lines of the file's first data lines."""
    size = layout.path.stat().st_size
    with layout.path.open("rb") as fh:
        head = fh.read(1 << 16)
    lines = max(head.count(b"\n"), 1)
    per_line = max(len(head) // lines, 1)
    return int(min(max(per_line * rows, 1 << 16), max(size, 1 << 16), 1 << 30))
