"""Record a controller's RTDE stream to files in UR's record.py layout.

Every package the controller sends becomes one line: a header line names the columns
(``timestamp target_q_0 .. target_q_5 ...``, vectors as ``name_0..name_5``), values are space
separated and written exactly as received (the controller's raw ``timestamp`` included), and a
last ``segment`` column counts the connections: after a dropped connection the recorder
reconnects (:class:`kinergy.live.stream.Stream`) and the rows from the new connection carry the
next segment number, so readers (:func:`kinergy.io.segments.split_segments`) never join the two
sides of the gap. ``rotate`` starts a new numbered file every so many seconds of controller time
or bytes, and so does a controller restart (its clock starting again).

Lines are written whole and flushed twice a second; when recording stops (the duration reached,
SIGINT or SIGTERM through :func:`kinergy.live.stream.stop_on_signals`) the packages already
received are written and the file is flushed and closed, so it is complete and readable.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

from kinergy.errors import KinergyError
from kinergy.live.rtde import Recipe
from kinergy.live.stream import Gap, Stream

__all__ = ["FIELDS", "OPTIONAL_FIELDS", "LogWriter", "Recording", "column_names", "record"]

#: What the recorder subscribes to: every field kinergy reads (timestamp first).
FIELDS = (
    "timestamp",
    "target_q",
    "target_qd",
    "target_qdd",
    "target_current",
    "target_moment",
    "actual_q",
    "actual_qd",
    "actual_current",
    "joint_temperatures",
    "actual_joint_voltage",
    "actual_robot_voltage",
    "actual_robot_current",
    "robot_mode",
    "runtime_state",
)
#: Fields left out (with a message) when a controller does not know them.
OPTIONAL_FIELDS = tuple(f for f in FIELDS if f not in ("timestamp", "actual_q", "actual_qd"))


def column_names(recipe: Recipe) -> list[str]:
    """The header of a recipe's rows: scalars by name, vectors as ``name_0..name_{n-1}``."""
    names: list[str] = []
    for name, width in zip(recipe.names, recipe.widths, strict=True):
        names.extend([name] if width == 1 else [f"{name}_{k}" for k in range(width)])
    return names


class LogWriter:
    """Rows into one file, or numbered files when rotating.

    Parameters
    ----------
    out : Path
        The file (``run.csv``); numbered files are ``run-001.csv``, ``run-002.csv``, ...
    header : list of str
        Column names.
    numbered : bool
        Number the files from the first one (rotation asked for).
    """

    def __init__(self, out: Path, header: Sequence[str], *, numbered: bool) -> None:
        self.out = out
        self.header = " ".join(header) + "\n"
        self.numbered = numbered
        self.files: list[Path] = []
        self.bytes = 0
        self._fh: IO[str] | None = None
        self.open_next()

    def _name(self, index: int) -> Path:
        if not self.numbered and index == 1:
            return self.out
        return self.out.with_name(f"{self.out.stem}-{index:03d}{self.out.suffix}")

    def open_next(self) -> Path:
        """Close the current file and start the next one with the header line."""
        self.close()
        path = self._name(len(self.files) + 1)
        try:
            self._fh = path.open("w", encoding="ascii", newline="\n")
        except OSError as exc:
            raise KinergyError(f"{path}: cannot write ({exc.strerror})") from None
        self._fh.write(self.header)
        self.bytes = len(self.header)
        self.files.append(path)
        return path

    def write(self, lines: str) -> None:
        """Whole lines (each ending in a newline)."""
        assert self._fh is not None
        self._fh.write(lines)
        self.bytes += len(lines)

    def flush(self) -> None:
        if self._fh is not None:
            self._fh.flush()

    def close(self) -> None:
        """Flush, sync to disk and close the current file."""
        if self._fh is None:
            return
        self._fh.flush()
        os.fsync(self._fh.fileno())
        self._fh.close()
        self._fh = None


@dataclass
class Recording:
    """What a recording wrote.

    Attributes
    ----------
    files : list of str
    rows : int
        Data lines over all files.
    segments : int
        Connections the rows came from (1 + reconnections).
    first, last : float or None
        The controller's first and last ``timestamp``, s.
    stopped : str
        ``duration``, ``SIGINT``, ``SIGTERM`` or ``stream ended``.
    left_out : list of str
        Fields the controller did not know.
    """

    files: list[str] = field(default_factory=list)
    rows: int = 0
    segments: int = 1
    first: float | None = None
    last: float | None = None
    stopped: str = "stream ended"
    left_out: list[str] = field(default_factory=list)


class _Rows:
    """The recording loop's state: current segment, rotation and the duration limit."""

    def __init__(
        self,
        writer: LogWriter,
        result: Recording,
        *,
        duration: float | None,
        period: float,
        rotate_seconds: float | None,
        rotate_bytes: int | None,
        status: Callable[[str], None],
    ) -> None:
        self.writer, self.result, self.status = writer, result, status
        self.end = None if duration is None else duration - 0.5 * period
        self.rotate_seconds, self.rotate_bytes = rotate_seconds, rotate_bytes
        self.segment = 0
        self.file_start: float | None = None
        self.lines: list[str] = []

    def add(self, values: Sequence[float | int]) -> bool:
        """Queue one row; False once the duration is reached (the row is not kept)."""
        t = float(values[0])
        r = self.result
        if r.first is None:
            r.first = t
        elif self.end is not None and t - r.first > self.end:
            return False
        if r.last is not None and t <= r.last:
            self.status(f"the controller's clock went back ({r.last} then {t}): a new file")
            self.rotate()
        elif self.file_start is not None and self._full(t):
            self.rotate()
        if self.file_start is None:
            self.file_start = t
        self.lines.append(" ".join(map(str, values)) + f" {self.segment}\n")
        r.last = t
        r.rows += 1
        return True

    def _full(self, t: float) -> bool:
        assert self.file_start is not None
        by_time = self.rotate_seconds is not None and t - self.file_start >= self.rotate_seconds
        by_size = self.rotate_bytes is not None and self.writer.bytes >= self.rotate_bytes
        return by_time or by_size

    def rotate(self) -> None:
        self.flush()
        path = self.writer.open_next()
        self.file_start = None
        self.status(f"continuing in {path}")

    def gap(self, gap: Gap) -> None:
        self.segment += 1
        self.result.segments = self.segment + 1
        self.status(f"segment {self.segment} starts after a {gap.seconds:.2f} s gap")

    def flush(self) -> None:
        if self.lines:
            self.writer.write("".join(self.lines))
            self.lines.clear()
        self.writer.flush()


def record(
    stream: Stream,
    out: str | os.PathLike[str],
    *,
    stop: threading.Event,
    duration: float | None = None,
    rotate_seconds: float | None = None,
    rotate_bytes: int | None = None,
    status: Callable[[str], None] | None = None,
    every: float = 5.0,
) -> Recording:
    """Write ``stream``'s packages to ``out`` until ``duration`` s of controller time have been
    recorded, ``stop`` is set or the stream ends; the stream is closed on the way out.

    Parameters
    ----------
    stream : Stream
        Subscribed to :data:`FIELDS` (timestamp first).
    out : path
        The file; with rotation ``out``'s stem numbered ``-001``, ``-002``...
    stop : threading.Event
        Set by :func:`kinergy.live.stream.stop_on_signals` on SIGINT or SIGTERM.
    duration : float, optional
        Seconds of controller time: ``duration * frequency`` rows when nothing is lost.
    rotate_seconds, rotate_bytes : optional
        Start a new file after this much controller time or this many bytes.
    status : callable, optional
        Progress lines (every ``every`` s) and connection news.

    Returns
    -------
    Recording
    """
    say = status or (lambda message: None)
    result = Recording(left_out=[n for n in FIELDS if n not in stream.recipe.names])
    writer = LogWriter(
        Path(out),
        [*column_names(stream.recipe), "segment"],
        numbered=rotate_seconds is not None or rotate_bytes is not None,
    )
    rows = _Rows(
        writer,
        result,
        duration=duration,
        period=1.0 / stream.frequency,
        rotate_seconds=rotate_seconds,
        rotate_bytes=rotate_bytes,
        status=say,
    )
    flushed = reported = time.monotonic()
    try:
        while not stop.is_set():
            item = stream.get(timeout=0.1)
            if isinstance(item, Gap):
                rows.gap(item)
            elif item is not None and not rows.add(item):
                result.stopped = "duration"
                break
            elif item is None and stream.ended:
                break
            now = time.monotonic()
            if now - flushed >= 0.5:
                rows.flush()
                flushed = now
            if now - reported >= every:
                span = 0.0 if result.first is None else (result.last or 0.0) - result.first
                say(f"{result.rows} rows, {span:.1f} s, segment {rows.segment}")
                reported = now
        stream.close()
        if result.stopped != "duration":
            _drain(stream, rows)
    finally:
        stream.close()
        rows.flush()
        writer.close()
        result.files = [str(p) for p in writer.files]
    return result


def _drain(stream: Stream, rows: _Rows) -> None:
    """Write what the closed stream had already received."""
    while True:
        item = stream.get(timeout=0.0)
        if item is None:
            return
        if isinstance(item, Gap):
            rows.gap(item)
        elif not rows.add(item):
            return
