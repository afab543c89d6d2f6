"""Reading a user's log: its chunks, checked for plausibility as they pass, and what the log was.

Every command that takes a log reads it through :class:`CheckedLog`: the chunks of
:func:`kinergy.io.formats.iter_log` (or of a log already in memory, as one chunk), each folded
into the checks of :mod:`kinergy.logs.checks` before it is passed on. After the last chunk the
checks give their verdict: a failure the user did not accept raises, so nothing computed from the
chunks is shown. The log's provenance (:class:`Provenance`: SHA-256, size and rows) is recorded
as it is read, for the results to say which data they came from.
"""

from __future__ import annotations

import dataclasses
import hashlib
import os
import queue
import re
import threading
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypeVar

import numpy as np

from kinergy.checks import number
from kinergy.errors import KinergyError
from kinergy.io.columns import (
    ColumnMap,
    Columns,
    check_joint_columns,
    parse_column_spec,
    printable,
)
from kinergy.io.fields import CHECKED_SIGNALS, closest
from kinergy.io.formats import CHUNK_ROWS, iter_log
from kinergy.io.log import Log
from kinergy.io.panda_layout import is_panda_layout, panda_files
from kinergy.io.rosbag import BagOptions, bag_options
from kinergy.logs.checks import Check, LogCheck, LogChecks, parse_accept
from kinergy.logs.payload import PAYLOAD_SIGNALS, describe, from_columns, payload_columns
from kinergy.logs.window import TimeWindow, WindowCut
from kinergy.model.robot import Payload, Robot
from kinergy.model.toml import parse_payload

__all__ = ["MAX_CUTOFF", "CheckedLog", "InputLogs", "LogReading", "Provenance"]

#: Hz: the highest low-pass cutoff ``--cutoff`` takes
MAX_CUTOFF = 1e6


@dataclass(frozen=True)
class LogReading:
    """How a command reads its logs, parsed once from its options (:meth:`parse`: from the
    command line's flags), checked on construction: one line naming the flag at fault.

    Attributes
    ----------
    columns : tuple of str, ColumnMap or None
        The columns of a headerless file (:func:`kinergy.io.columns.parse_columns` of the
        ``--columns`` spec), or a header log's names mapped to RTDE's
        (:class:`kinergy.io.columns.ColumnMap`); a spec given as text is parsed on construction
        (:func:`kinergy.io.columns.parse_column_spec`). None: the file names them in a header
        line by RTDE's names (UR's record.py layout).
    repair : bool
        Drop rows that cannot be read (each drop noted) instead of refusing the file.
    cutoff : float or None
        Low-pass cutoff for measured speeds, Hz; None: min(10 Hz, a fifth of the sample rate).
    accept : frozenset of Check
        Checks whose failure the user accepts (``--accept``; names, ``all`` or comma-separated
        lists parsed on construction); the results record them.
    bag : BagOptions or None
        How to read a ROS 2 bag (``--topic``, ``--effort``); None: its defaults. Refused for a
        log that is not a bag.
    payload : Payload or None
        The payload at the flange (``--payload``): it replaces the one the controller logged
        (``payload``, ``payload_cog``, ``payload_inertia``, :mod:`kinergy.logs.payload`) and the
        robot file's. None: the log's where it logs one, else the robot file's. Text
        (``MASS[,CX,CY,CZ[,...]]``) is parsed on construction.
    window : TimeWindow or None
        The samples read (``--from``/``--to``, s on the log's own time axis); None: all. A pair
        ``(start, stop)`` becomes a :class:`~kinergy.logs.window.TimeWindow` on construction.
    """

    columns: Columns | None = None
    repair: bool = False
    cutoff: float | None = None
    accept: frozenset[Check] = frozenset()
    bag: BagOptions | None = None
    payload: Payload | None = None
    window: TimeWindow | None = None

    def loaded(self, robot: Robot) -> Robot:
        """``robot`` with the payload :attr:`payload` gives, when it gives one."""
        return robot if self.payload is None else robot.with_payload(self.payload)

    def __post_init__(self) -> None:
        columns = self.columns
        if isinstance(columns, str):
            columns = parse_column_spec(columns)
        if columns is not None and not isinstance(columns, ColumnMap):
            columns = tuple(columns)
        object.__setattr__(self, "columns", columns)
        if self.cutoff is not None:
            cutoff = number(self.cutoff, "--cutoff", gt=0.0, le=MAX_CUTOFF)
            object.__setattr__(self, "cutoff", cutoff)
        accept = [self.accept] if isinstance(self.accept, str) else self.accept
        names = (c.value if isinstance(c, Check) else c for c in accept)
        object.__setattr__(self, "accept", parse_accept(names))
        object.__setattr__(self, "repair", bool(self.repair))
        if isinstance(self.payload, str):
            object.__setattr__(self, "payload", parse_payload(self.payload))
        if isinstance(self.window, tuple):
            window = None if self.window == (None, None) else TimeWindow(*self.window)
            object.__setattr__(self, "window", window)

    @classmethod
    def parse(
        cls,
        *,
        columns: str | None = None,
        repair: bool = False,
        cutoff: float | None = None,
        accept: str | Iterable[str] = (),
        topic: str | None = None,
        effort: str | None = None,
        payload: str | None = None,
        start: float | None = None,
        stop: float | None = None,
    ) -> LogReading:
        """The reading options as a command's flags give them, each parsed once: ``columns`` a
        column spec (``"timestamp,actual_q:6,..."`` or ``"timestamp=time,actual_q=pos_*"``,
        :func:`kinergy.io.columns.parse_column_spec`), ``accept`` check names (``--accept``,
        repeatable or comma-separated, ``all``), ``topic`` and ``effort`` a ROS 2 bag's
        (:func:`kinergy.io.rosbag.bag_options`), ``payload`` ``MASS[,CX,CY,CZ[,...]]``
        (:func:`kinergy.model.toml.parse_payload`), ``start`` and ``stop`` the window, s.

        The parameters are the command line's flags (``--columns``, ``--repair``,
        ``--cutoff``, ``--accept``, ``--topic``, ``--effort``, ``--payload``, ``--from``,
        ``--to``), which the commands build from this signature.

        Raises
        ------
        KinergyError
            One line naming the flag at fault.
        """
        return cls(
            columns=columns,  # type: ignore[arg-type]  # parsed on construction
            repair=repair,
            cutoff=cutoff,
            accept=accept,  # type: ignore[arg-type]
            bag=bag_options(topic, effort),
            payload=payload,  # type: ignore[arg-type]
            window=(start, stop),  # type: ignore[arg-type]
        )


@dataclass(frozen=True)
class Provenance:
    """What a log was, by content: enough to tell later whether two results came from the same
    data.

    Attributes
    ----------
    path : str
    sha256 : str
        Of the file's bytes (of the samples' bytes for a log held in memory).
    size : int
        Bytes.
    rows : int
        Samples read (after ``repair``).
    """

    path: str
    sha256: str
    size: int
    rows: int


def _files(path: Path) -> tuple[Path, list[Path]]:
    """The files a log is and the folder their names are taken relative to: the file itself;
    the files of a panda-gaz set (its time file and the signals' files beside it), whether
    named by its folder or its time file; a ROS 2 bag's storage files (``.mcap``, ``.db3``),
    whether named by its folder, its ``metadata.yaml`` or a storage file; every file of another
    folder; in sorted order."""
    if is_panda_layout(path):
        found = panda_files(path)
        return found.time.parent, sorted([found.time, *found.signals.values()])
    folder = path.parent if path.name == "metadata.yaml" else path
    if folder.is_dir() and (folder / "metadata.yaml").is_file():  # a ROS 2 bag: its storage
        storage = sorted(p for p in folder.iterdir() if p.suffix in (".mcap", ".db3"))
        if storage:
            return folder, storage
    if path.is_dir():
        return path, sorted(p for p in path.rglob("*") if p.is_file())
    return path.parent, [path]


def _file_hash(path: Path, out: list[str], stop: threading.Event) -> None:
    """SHA-256 of the log at ``path`` into ``out`` (nothing when ``stop`` is set first): of the
    file's bytes, or of a log of several files (:func:`_files`), each by its relative name and
    bytes."""
    digest = hashlib.sha256()
    try:
        base, files = _files(path)
        for part in files:
            if len(files) > 1:  # one file is its bytes alone, however it was named
                digest.update(part.relative_to(base).as_posix().encode() + b"\0")
            with part.open("rb") as fh:
                while block := fh.read(1 << 20):
                    if stop.is_set():
                        return
                    digest.update(block)
    except (OSError, KinergyError):
        return
    out.append(digest.hexdigest())


T = TypeVar("T")

#: what the reader thread puts last: the end of its chunks
_END = object()


def _read_ahead(chunks: Iterator[T]) -> Iterator[T]:
    """``chunks`` in order, each read in a thread while the caller works on the one before:
    parsing (pyarrow) and the caller's numerical work (numpy, numba) release the interpreter
    lock, so the two overlap on two cores; one chunk waits at most, so memory grows by one chunk.

    An exception the reader raises is raised here after the chunks before it, as without the
    thread. When the caller stops early (an error, or it closes this generator), the reader
    stops after the chunk it is reading and its files are closed in its own thread.
    """
    ready: queue.Queue[object] = queue.Queue(maxsize=1)
    stop = threading.Event()

    def put(item: object) -> bool:
        while not stop.is_set():
            try:
                ready.put(item, timeout=0.05)
                return True
            except queue.Full:
                continue
        return False

    def read() -> None:
        try:
            for chunk in chunks:
                if not put(chunk):
                    break
            else:
                put(_END)
        except BaseException as exc:  # handed to the caller, raised there
            put(exc)
        finally:
            close = getattr(chunks, "close", None)
            if close is not None:
                close()

    reader = threading.Thread(target=read, name="kinergy-log-reader", daemon=True)
    reader.start()
    try:
        while (item := ready.get()) is not _END:
            if isinstance(item, BaseException):
                raise item
            yield item  # type: ignore[misc]
    finally:
        stop.set()
        reader.join()


def _log_hash(log: Log) -> tuple[str, int]:
    """SHA-256 and size of a log's samples: its time stamps and signals, by name."""
    digest = hashlib.sha256()
    size = 0
    for name, x in [("timestamp", log.t), *sorted(log.signals.items())]:
        data = np.ascontiguousarray(x, dtype=float).tobytes()
        digest.update(name.encode())
        digest.update(data)
        size += len(data)
    return digest.hexdigest(), size


@dataclass(eq=False)
class CheckedLog:
    """One log, read through the plausibility checks (module docstring).

    Parameters
    ----------
    source : path or Log
        A log file, or a log already in memory (one chunk).
    robot : Robot
        The robot the log is read for (the checks compare it with the log).
    reading : LogReading
    select : sequence of str, optional
        The signals the command uses, of those the log has (default all); the checks' signals
        are read too.
    rows : int
        The most samples per chunk.
    ahead : bool
        Read a file one chunk ahead in a thread (:func:`_read_ahead`): for a consumer whose work
        per chunk is heavy and whose chunks are small (energy: the 60-minute log 9.7-10.4 s ->
        7.6 s, the same peak). Off by default: identification's peak rose by up to 65 MiB with
        it (the reader thread's allocations stay in a malloc arena of their own).

    Attributes
    ----------
    path : str
    checks : LogChecks or None
        The checks' verdict, once :meth:`chunks` has run to the end.
    provenance : Provenance or None
        Likewise.
    notes : list of str
        What reading changed (time stamps converted, rows dropped by ``repair``).
    """

    source: str | os.PathLike[str] | Log
    robot: Robot
    reading: LogReading = field(default_factory=LogReading)
    select: Sequence[str] | None = None
    rows: int = CHUNK_ROWS
    ahead: bool = False
    checks: LogChecks | None = None
    provenance: Provenance | None = None
    notes: list[str] = field(default_factory=list)
    _told: bool = field(default=False, repr=False)

    def __post_init__(self) -> None:
        columns = self.reading.columns
        if isinstance(columns, ColumnMap) and columns.n_joints is None:
            mapped = dataclasses.replace(columns, n_joints=self.robot.n)
            self.reading = dataclasses.replace(self.reading, columns=mapped)
        elif isinstance(columns, tuple):
            check_joint_columns(columns, self.robot.n)

    @property
    def path(self) -> str:
        return self.source.path if isinstance(self.source, Log) else os.fspath(self.source)

    def _raw(self, select: Sequence[str] | None) -> Iterator[Log]:
        if isinstance(self.source, Log):
            log = self.source
            names = log.signals if select is None else [s for s in select if s in log.signals]
            for start in range(0, len(log), self.rows):
                stop = min(start + self.rows, len(log))
                yield Log(
                    log.path,
                    log.t[start:stop],
                    {k: log.signals[k][start:stop] for k in names},
                    list(log.notes) if start == 0 else [],
                )
            return
        chunks = iter_log(
            self.source,
            columns=self.reading.columns,
            repair=self.reading.repair,
            select=select,
            rows=self.rows,
            joints=self.robot.joint_names,
            bag=self.reading.bag,
        )
        yield from _read_ahead(chunks) if self.ahead else chunks

    def names(self) -> set[str]:
        """The signals the log has (its first rows read to tell)."""
        head = self._head()
        return set() if head is None else set(head.signals)

    def _head(self) -> Log | None:
        if isinstance(self.source, Log):
            return self.source
        reading = self.reading
        chunks = iter_log(
            self.source,
            columns=reading.columns,
            repair=reading.repair,
            rows=2,
            joints=self.robot.joint_names,
            bag=reading.bag,
        )
        return next(chunks, None)

    def _check_names(self) -> None:
        """Refuse a column the reader ignored (no field kinergy knows) whose name is a
        misspelling of a field the command needs and the log lacks (``actual_curent_0`` for
        ``actual_current`` when currents are needed): the command would otherwise find nothing,
        or quietly do without. Other ignored columns pass (a recorder may log anything)."""
        head = self._head()
        if head is None or not head.ignored:
            return
        have = set(head.signals)
        needed = set(CHECKED_SIGNALS) if self.select is None else set(self.select)
        lacking = sorted(needed - have)
        for column in head.ignored:
            base = re.sub(r"_\d+$", "", column)
            guess = closest(base, lacking) or closest(column, lacking)
            if guess is not None:
                mapped = re.sub(r"_\d+$", "_*", column)
                raise KinergyError(
                    f"{self.path}: column {printable(column)} is not a field kinergy knows (did you "
                    f"mean {guess}?): name it as UR's RTDE does, or map it with --columns "
                    f"{guess}={printable(mapped)}"
                )

    def _wanted(self) -> list[str] | None:
        """The signals to read: those selected and those the checks use, of the log's."""
        if self.select is None:
            return None
        have = self.names()
        return [s for s in dict.fromkeys([*self.select, *CHECKED_SIGNALS]) if s in have]

    def _given_payload(self, chunk: Log) -> Log:
        """``chunk`` without the logged payload when ``--payload`` replaces it (noted once)."""
        if self.reading.payload is None or not any(s in chunk for s in PAYLOAD_SIGNALS):
            return chunk
        if not self._told:
            cols = payload_columns(chunk)
            logged = "" if cols is None else f" ({describe(from_columns(cols[0]))} first)"
            self.notes.append(
                f"{self.path}: the controller's logged payload{logged} is not used: --payload "
                f"gives {describe(self.reading.payload)}"
            )
            self._told = True
        keep = {k: v for k, v in chunk.signals.items() if k not in PAYLOAD_SIGNALS}
        return Log(chunk.path, chunk.t, keep, chunk.notes, chunk.ignored)

    def _selected(self, chunk: Log) -> Log:
        """``chunk`` with only the selected signals: those only the checks read are not
        carried on (a consumer joining chunks would copy them for nothing)."""
        if self.select is None:
            return chunk
        keep = {k: v for k, v in chunk.signals.items() if k in self.select}
        if len(keep) == len(chunk.signals):
            return chunk
        return Log(chunk.path, chunk.t, keep, chunk.notes)

    def chunks(self) -> Iterator[Log]:
        """The log's chunks in order, each folded into the checks first; after the last one,
        the checks' verdict (:attr:`checks`, :attr:`provenance`).

        Raises
        ------
        KinergyError
            When the file cannot be read, and after the last chunk when a check failed that
            the user did not accept (:meth:`kinergy.logs.checks.LogCheck.finish`).
        """
        self._check_names()
        check = LogCheck(self.reading.loaded(self.robot), self.path, self.reading.accept)
        hashed: list[str] = []
        stop = threading.Event()
        hasher = None
        if not isinstance(self.source, Log):
            args = (Path(self.source), hashed, stop)
            hasher = threading.Thread(target=_file_hash, args=args, daemon=True)
        rows = 0
        window = self.reading.window
        cut = None if window is None else WindowCut(window, self.path)
        try:
            for raw in self._raw(self._wanted()):
                if hasher is not None and hasher.ident is None:
                    hasher.start()  # the file opened: hash it beside the reading
                self.notes.extend(raw.notes)
                chunk = self._given_payload(raw if cut is None else cut.cut(raw))
                if len(chunk):
                    check.add(chunk)
                    rows += len(chunk)
                    yield self._selected(chunk)
                if cut is not None and cut.done:
                    break
        except BaseException:
            stop.set()
            raise
        if cut is not None:
            self.notes.append(cut.finish())
        if rows == 0:
            raise KinergyError(f"{self.path}: the log has no samples")
        self.checks = check.finish()
        if isinstance(self.source, Log):
            digest, size = _log_hash(self.source)
        else:
            assert hasher is not None
            hasher.join()
            size = sum(p.stat().st_size for p in _files(Path(self.source))[1])
            digest = hashed[0] if hashed else ""
        self.provenance = Provenance(self.path, digest, size, rows)

    def read(self) -> Log:
        """The whole log, checked (its chunks joined)."""
        return Log.concatenate(list(self.chunks()))


@dataclass
class InputLogs:
    """What a command's logs were, besides their samples: what the results record and the user
    is told.

    Attributes
    ----------
    provenance : list of Provenance
        Each log, by content.
    checks : list of LogChecks
        Each log's checks.
    notes : list of str
        What reading changed (time stamps converted, rows dropped, segments): routine.
    """

    provenance: list[Provenance] = field(default_factory=list)
    checks: list[LogChecks] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    @property
    def warnings(self) -> list[str]:
        """What passed the checks but may still make a result wrong."""
        return [w for c in self.checks for w in c.warnings]

    def records(self) -> list[dict[str, object]]:
        """Per log, as ``--json`` gives it: ``path``, ``sha256``, ``size`` (bytes), ``rows`` and
        ``checks`` (``passed``, ``accepted``, ``not_checked``)."""
        out: list[dict[str, object]] = []
        for p, c in zip(self.provenance, self.checks, strict=True):
            checks = {"passed": list(c.passed), "accepted": list(c.accepted)}
            checks["not_checked"] = list(c.not_checked)
            out.append(
                {
                    "path": p.path,
                    "sha256": p.sha256,
                    "size": p.size,
                    "rows": p.rows,
                    "checks": checks,
                }
            )
        return out

    def add(self, log: CheckedLog) -> None:
        """Record ``log`` once it has been read to the end.

        Raises
        ------
        KinergyError
            The same log given twice (the same SHA-256 as one recorded before): it would count
            twice and make every standard error look smaller than it is.
        """
        assert log.provenance is not None and log.checks is not None
        for seen in self.provenance:
            if seen.sha256 == log.provenance.sha256 and log.provenance.size > 0:
                raise KinergyError(
                    f"{log.provenance.path}: the same log as {seen.path} (same SHA-256): given "
                    "twice, it would count twice; give each log once"
                )
        self.provenance.append(log.provenance)
        self.checks.append(log.checks)
        self.notes.extend([*log.notes, *log.checks.notes])
