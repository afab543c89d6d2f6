"""The fleet's cycles as a Parquet table (pyarrow), written atomically."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from kinergy.errors import KinergyError
from kinergy.files import atomic_write

__all__ = ["COLUMNS", "write_cycles"]

#: the table's columns: who, when, which cycle, and its energies (J) and times (s)
COLUMNS = (
    "robot", "log", "date", "program", "segment", "cycle", "start", "duration", "measured",
    "predicted", "inertial", "gravity", "friction", "copper", "standby", "shunt",
    "motor_work",
)  # fmt: skip


def write_cycles(path: str | os.PathLike[str], rows: Sequence[dict[str, object]]) -> Path:
    """Write one row per cycle (:func:`kinergy.fleet.summary.cycles_table`) to ``path``.

    Energies are J (supply side: ``measured`` from the logged supply, ``predicted`` by the
    model: its ``inertial``/``gravity``/``friction``/``copper`` parts, ``standby`` and ``shunt``;
    ``motor_work`` from the currents), ``start`` is controller time and ``duration`` s; ``cycle``
    is -1 for a stretch with no repeating program. Missing measurements are nulls.
    """
    try:
        import pyarrow as pa  # the fleet extra: pip install 'kinergy[fleet]'
        import pyarrow.parquet as pq
    except ImportError:  # pragma: no cover - depends on the installation
        raise KinergyError("writing Parquet needs pyarrow: pip install 'kinergy[fleet]'") from None
    schema = pa.schema(
        [
            ("robot", pa.string()),
            ("log", pa.string()),
            ("date", pa.date32()),
            ("program", pa.string()),
            ("segment", pa.int32()),
            ("cycle", pa.int32()),
            *((name, pa.float64()) for name in COLUMNS[6:]),
        ],
        metadata={"written_by": "kinergy"},  # in the footer: kinergy may replace the file
    )
    table = pa.Table.from_pylist(list(rows), schema=schema)
    return atomic_write(path, lambda fh: pq.write_table(table, fh), binary=True)
