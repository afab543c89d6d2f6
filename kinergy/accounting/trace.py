"""The power of a motion sample by sample: the supply's, predicted and measured, and each
joint's electrical power, for ``energy --trace`` (streamed to CSV or Parquet) and ``energy
--plot`` (a bounded copy of the supply's).

Columns of a trace (:func:`trace_columns`), one row per sample:

- ``time``: s, as the log stamps it;
- ``supply_predicted``: W, what the bus model says the arm draws (:mod:`kinergy.drives.bus`:
  ``max(sum_j W_j, 0) + standby_power``);
- ``supply_measured``: W, ``actual_robot_voltage x actual_robot_current``, where the log has them;
- ``p_elec_<joint>``: W, each motor's electrical power ``W_j`` (UR5e eq 23, signed: negative
  while it brakes).

A :class:`TraceWriter` writes each chunk as it comes (a Parquet row group, or CSV lines), so the
memory it takes does not grow with the log; a :class:`PowerSeries` keeps at most
:data:`MAX_POINTS` samples of the supply's powers for a plot, every ``stride``-th, the stride
doubling whenever they would be more.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, Protocol

import numpy as np
import pyarrow as pa
import pyarrow.csv as pa_csv
import pyarrow.parquet as pq

from kinergy.arrays import Array
from kinergy.drives.bus import supply_power
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.predict import DriveState

__all__ = [
    "MAX_POINTS",
    "TRACE_FORMATS",
    "PowerSeries",
    "PowerSink",
    "SupplyTrace",
    "TraceWriter",
    "supply_predicted",
    "trace_columns",
    "trace_format",
]

#: trace formats by the file's extension
TRACE_FORMATS = {".csv": "csv", ".parquet": "parquet"}
#: the most samples a :class:`PowerSeries` keeps (a plot's resolution, whatever the log's length)
MAX_POINTS = 20_000


def trace_format(path: str | os.PathLike[str], flag: str = "--trace") -> str:
    """``csv`` or ``parquet`` by ``path``'s extension.

    Raises
    ------
    KinergyError
        Another extension, naming ``flag``.
    """
    suffix = Path(path).suffix.lower()
    if suffix not in TRACE_FORMATS:
        raise KinergyError(
            f"{flag} {path}: the trace is written as CSV (.csv) or Parquet (.parquet), by its "
            f"extension; got {suffix or 'none'!r}"
        )
    return TRACE_FORMATS[suffix]


def trace_columns(robot: Robot, measured: bool) -> list[str]:
    """The trace's column names (module docstring)."""
    head = ["time", "supply_predicted", *(["supply_measured"] if measured else [])]
    return head + [f"p_elec_{name}" for name in robot.joint_names]


def supply_predicted(robot: Robot, state: DriveState) -> Array:
    """What the arm draws from its supply at each sample, W, (N,): the motors' powers summed
    on the bus, clipped at zero, plus the standing draw (:func:`kinergy.drives.bus.supply_power`)."""
    return supply_power(state.power, robot.standby_power).supply


class PowerSink(Protocol):
    """What takes the power of a motion chunk by chunk (a trace file, a plot's series)."""

    def add(self, t: Array, predicted: Array, measured: Array | None, joints: Array) -> None:
        """Samples at times ``t`` (s, (N,)): the predicted supply power (W, (N,)), the measured
        one (W, (N,), or None where the log does not measure it) and each motor's electrical
        power (W, (N, n))."""
        ...  # pragma: no cover


class TraceWriter:
    """Writes a trace (module docstring) to an open binary ``handle`` as ``fmt`` (``csv`` or
    ``parquet``), chunk by chunk; :meth:`close` finishes the file (a Parquet footer carries
    ``written_by: kinergy``)."""

    def __init__(self, handle: IO[Any], robot: Robot, fmt: str) -> None:
        self.handle, self.robot, self.fmt = handle, robot, fmt
        self.rows = 0
        self._measured: bool | None = None
        self._writer: Any = None

    def add(self, t: Array, predicted: Array, measured: Array | None, joints: Array) -> None:
        if self._measured is None:
            self._measured = measured is not None
        elif self._measured != (measured is not None):
            raise KinergyError("the log measures its supply in some chunks only")
        names = trace_columns(self.robot, self._measured)
        columns = [t, predicted, *([measured] if measured is not None else []), *joints.T]
        table = pa.table(
            {n: pa.array(np.asarray(c, dtype=float)) for n, c in zip(names, columns, strict=True)}
        )
        if self._writer is None:
            self._open(table.schema)
        self._writer.write_table(table)
        self.rows += len(t)

    def _open(self, schema: pa.Schema) -> None:
        if self.fmt == "parquet":
            marked = schema.with_metadata({"written_by": "kinergy energy --trace"})
            self._writer = pq.ParquetWriter(self.handle, marked)
        else:
            self._writer = pa_csv.CSVWriter(self.handle, schema)

    def close(self) -> None:
        """Finish the file (the header alone when no sample came)."""
        if self._writer is None:
            names = trace_columns(self.robot, bool(self._measured))
            self._open(pa.schema([(n, pa.float64()) for n in names]))
        self._writer.close()


class PowerSeries:
    """At most :data:`MAX_POINTS` samples of the supply's predicted and measured power over a
    motion (module docstring): ``t``, ``predicted``, ``measured`` (None where not measured)."""

    def __init__(self, limit: int = MAX_POINTS) -> None:
        self.limit, self.stride, self.seen = limit, 1, 0
        self._t: list[Array] = []
        self._p: list[Array] = []
        self._m: list[Array] | None = []

    def add(self, t: Array, predicted: Array, measured: Array | None, joints: Array) -> None:
        keep = (self.seen + np.arange(len(t))) % self.stride == 0
        self.seen += len(t)
        self._t.append(t[keep])
        self._p.append(predicted[keep])
        if measured is None or self._m is None:
            self._m = None
        else:
            self._m.append(measured[keep])
        while sum(len(x) for x in self._t) > self.limit:
            self._thin()

    def _thin(self) -> None:
        """Keep every other sample kept so far (by its index among all samples) and double the
        stride."""
        self.stride *= 2
        t, p = np.concatenate(self._t), np.concatenate(self._p)
        every = np.arange(len(t)) % 2 == 0
        self._t, self._p = [t[every]], [p[every]]
        if self._m is not None:
            self._m = [np.concatenate(self._m)[every]]

    @property
    def t(self) -> Array:
        return np.concatenate(self._t) if self._t else np.zeros(0)

    @property
    def predicted(self) -> Array:
        return np.concatenate(self._p) if self._p else np.zeros(0)

    @property
    def measured(self) -> Array | None:
        return None if not self._m else np.concatenate(self._m)


@dataclass(frozen=True, eq=False)
class SupplyTrace:
    """What a plot of the supply's power shows: the kept samples of a :class:`PowerSeries`
    (``t`` s, ``predicted`` and ``measured`` W, (N,); ``measured`` None where not measured), the
    energies of the whole motion (J) and the model's standing draw (W)."""

    t: Array
    predicted: Array
    measured: Array | None
    energy: float
    measured_energy: float | None
    standing: float
