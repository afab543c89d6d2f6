"""The one path every identification method takes through its logs: prepared chunks, folded.

No method holds its logs whole. :class:`LogChunks` gives it the prepared samples of every log
(segment) in chunks, in time order, and each step folds the chunks it needs into a small
accumulator and drops them: a QR triangle (:meth:`kinergy.linalg.Reduced.stack`, numerically as
good as one factorisation of all rows), running sums (:class:`~kinergy.identification.metrics.MetricSums`),
per-block or per-log accumulators, and the state friction held through standstill carries from
one chunk into the next (:class:`History`). A step that needs several passes (a fixed point, a
shape search, a weighted refit) makes them: the first pass keeps the prepared chunks
(:class:`Store`: an unnamed temporary file for logs read from files, the arrays as they are for
logs already in memory), so a later pass reads them instead of preparing them again, and a step
keeps what it derives per chunk in a store of its own when reading it back costs less than
computing it again.

A log held in memory is one chunk (:class:`WholeSegment`, :meth:`LogChunks.of`): the in-memory
entry points (:func:`~kinergy.identification.sequential.identify_sequential`,
:func:`~kinergy.identification.full.identify_full`, ...) run the very same folds.

The first pass checks every chunk's signals (:func:`~kinergy.identification.sanity.check_signals`) and
summarises each segment (:class:`Summary`: samples, time span, the joints' position ranges and
speeds), then runs the ``check`` it was given on the summaries, before the pass ends: a check's
error reaches the user before anything computed from the chunks.

Friction held through standstill (:mod:`kinergy.friction.standstill`) is the one thing that
reaches back in time without bound: a stopped joint keeps the friction of the last sample it
moved in. :class:`History` carries, per motor, what that needs of the samples before a chunk and
puts it in front of the chunk (the result of those rows is dropped), so the hold sees what it
would see in the whole log; it restarts with each segment, as the hold restarts with each log.
"""

from __future__ import annotations

import collections
import dataclasses
import functools
import itertools
import os
import tempfile
from collections.abc import Callable, Generator, Iterator, Sequence
from dataclasses import dataclass
from typing import Generic, Protocol, TypeVar

import numpy as np
from numpy.typing import NDArray
from threadpoolctl import threadpool_limits

from kinergy.arrays import Array
from kinergy.drives.transmission import transmission_matrix
from kinergy.errors import KinergyError
from kinergy.friction.standstill import MIN_RUN, sustained
from kinergy.identification.sanity import check_signals
from kinergy.io.formats import CHUNK_ROWS
from kinergy.logs.prepare import SAMPLE_FIELDS, IdentData
from kinergy.model.robot import Robot

__all__ = [
    "STILL_SPEED",
    "Asks",
    "History",
    "LogChunks",
    "Segment",
    "Store",
    "Summary",
    "WholeSegment",
    "answer",
    "data_history",
    "one_blas_thread",
    "together",
    "translated",
    "windowed",
]

#: joint speed below which a joint counts as still, rad/s
STILL_SPEED = 0.005


class Segment(Protocol):
    """One log (segment) that yields its prepared samples in chunks, in time order
    (:class:`kinergy.logs.prepare.PreparedSegment`, :class:`WholeSegment`)."""

    @property
    def path(self) -> str: ...

    @property
    def lag(self) -> float: ...

    @property
    def source(self) -> str: ...

    def __len__(self) -> int: ...

    def chunks(self, rows: int = CHUNK_ROWS) -> Iterator[IdentData]: ...


class WholeSegment:
    """A prepared log held in memory (:class:`Segment`), cut into chunks of ``rows`` samples
    (one chunk when ``rows`` is its length)."""

    def __init__(self, data: IdentData):
        self.data = data
        self.path, self.lag, self.source = data.path, data.lag, data.source

    def __len__(self) -> int:
        return len(self.data)

    def chunks(self, rows: int = CHUNK_ROWS) -> Iterator[IdentData]:
        if rows >= len(self.data):
            yield self.data
            return
        for start in range(0, len(self.data), rows):
            yield self.data.sliced(start, min(start + rows, len(self.data)))


Record = list[Array | None]


class Store:
    """Records (lists of float arrays, or None) kept once and read back in order: in an unnamed
    temporary file (``spool=True``, removed when closed) or as they are."""

    def __init__(self, spool: bool):
        self.file = tempfile.TemporaryFile() if spool else None
        self.kept: list[Record] = []
        self.index: list[tuple[int, list[tuple[int, ...] | None]]] = []
        self.end = 0

    def __len__(self) -> int:
        return len(self.kept) if self.file is None else len(self.index)

    def put(self, record: Sequence[Array | None]) -> None:
        """Append one record."""
        if self.file is None:
            self.kept.append(list(record))
            return
        arrays = [np.ascontiguousarray(a, dtype=float) for a in record if a is not None]
        data = b"".join(a.tobytes() for a in arrays)
        self.file.write(data)
        self.index.append((self.end, [None if a is None else np.shape(a) for a in record]))
        self.end += len(data)

    def __iter__(self) -> Iterator[Record]:
        if self.file is None:
            yield from self.kept
            return
        self.file.flush()
        for k, (offset, shapes) in enumerate(self.index):
            stop = self.index[k + 1][0] if k + 1 < len(self.index) else self.end
            raw = np.frombuffer(os.pread(self.file.fileno(), stop - offset, offset), dtype=float)
            out: Record = []
            at = 0
            for shape in shapes:
                if shape is None:
                    out.append(None)
                    continue
                size = int(np.prod(shape))
                out.append(raw[at : at + size].reshape(shape))
                at += size
            yield out

    def close(self) -> None:
        """Drop the records (remove the file)."""
        if self.file is not None:
            self.file.close()
        self.kept = []


@dataclass(frozen=True)
class Summary:
    """What the first pass finds in a segment's prepared samples (or several segments',
    :meth:`pooled`).

    Attributes
    ----------
    samples : int
    seconds : float
        The span of the time stamps, s (summed over pooled segments).
    low, high : ndarray, shape (n,)
        Range of the real joint positions, rad.
    peak, peak_cmd : ndarray, shape (n,)
        Largest ``|qd|`` of the real and of the commanded motion, rad/s.
    forward, backward : ndarray of int, shape (n,)
        Samples of the real motion faster than :data:`STILL_SPEED` forward and backward.
    cold, warm : ndarray, shape (n,), or None
        Range of the joint temperatures, deg C (None when not logged).
    has : frozenset of str
        The :class:`IdentData` fields the segment has.
    """

    samples: int
    seconds: float
    low: Array
    high: Array
    peak: Array
    peak_cmd: Array
    forward: NDArray[np.int_]
    backward: NDArray[np.int_]
    cold: Array | None
    warm: Array | None
    has: frozenset[str]

    @classmethod
    def of(cls, chunk: IdentData) -> Summary:
        """The summary of one chunk."""
        temp = chunk.temperature
        has = frozenset(f for f in SAMPLE_FIELDS if getattr(chunk, f) is not None)
        return cls(
            len(chunk),
            float(chunk.t[-1] - chunk.t[0]),
            chunk.q.min(axis=0),
            chunk.q.max(axis=0),
            np.abs(chunk.qd).max(axis=0),
            np.abs(chunk.qd_cmd).max(axis=0),
            (chunk.qd > STILL_SPEED).sum(axis=0),
            (chunk.qd < -STILL_SPEED).sum(axis=0),
            None if temp is None else temp.min(axis=0),
            None if temp is None else temp.max(axis=0),
            has,
        )

    def then(self, later: Summary, gap: float) -> Summary:
        """This summary and the ``later`` one of the same segment, ``gap`` s after it."""
        return self._merge(later, self.seconds + gap + later.seconds)

    def _merge(self, other: Summary, seconds: float) -> Summary:
        def both(
            a: Array | None, b: Array | None, how: Callable[[Array, Array], Array]
        ) -> Array | None:
            return None if a is None or b is None else how(a, b)

        return Summary(
            self.samples + other.samples,
            seconds,
            np.minimum(self.low, other.low),
            np.maximum(self.high, other.high),
            np.maximum(self.peak, other.peak),
            np.maximum(self.peak_cmd, other.peak_cmd),
            self.forward + other.forward,
            self.backward + other.backward,
            both(self.cold, other.cold, np.minimum),
            both(self.warm, other.warm, np.maximum),
            self.has & other.has,
        )

    @classmethod
    def pooled(cls, summaries: Sequence[Summary]) -> Summary:
        """The summary of several segments together."""
        out = summaries[0]
        for s in summaries[1:]:
            out = out._merge(s, out.seconds + s.seconds)
        return out

    @property
    def span(self) -> Array:
        """Range of each joint's position, rad, shape (n,)."""
        return np.asarray(self.high - self.low)


class LogChunks:
    """Prepared logs in chunks: the source every identification method folds over (module
    docstring).

    Parameters
    ----------
    segments : sequence of Segment
    rows : int
        Samples per chunk of the first pass.
    spool : bool
        Keep the prepared chunks in a temporary file (logs read from files) or as they are
        (logs already in memory).
    check : callable, optional
        Called with the segments' summaries at the end of the first pass (raising stops it).
    """

    def __init__(
        self,
        segments: Sequence[Segment],
        rows: int = CHUNK_ROWS,
        *,
        spool: bool = True,
        check: Callable[[list[Summary]], None] | None = None,
    ):
        if not segments:
            raise KinergyError("no log to identify from")
        self.segments = list(segments)
        self.rows, self.spool, self.check = rows, spool, check
        self.store = Store(spool)
        self.owner: list[int] = []  # the segment of each stored chunk
        self._summaries: list[Summary] | None = None
        self.stores: list[Store] = []  # what steps derived, closed with the chunks
        #: the currents a robot predicts on every chunk, kept by its validation for the fit of
        #: its electrics (:func:`kinergy.identification.result.validation_metrics`)
        self.currents: tuple[Robot, Store] | None = None

    @classmethod
    def of(
        cls, datas: Sequence[IdentData], check: Callable[[list[Summary]], None] | None = None
    ) -> LogChunks:
        """Prepared logs held in memory, each one chunk, kept as they are."""
        rows = max((len(d) for d in datas), default=1)
        return cls([WholeSegment(d) for d in datas], rows, spool=False, check=check)

    @property
    def paths(self) -> tuple[str, ...]:
        return tuple(s.path for s in self.segments)

    @property
    def lags(self) -> tuple[float, ...]:
        return tuple(s.lag for s in self.segments)

    @property
    def summaries(self) -> list[Summary]:
        """Each segment's :class:`Summary` (a first pass, unless one was made)."""
        if self._summaries is None:
            for _ in self.chunks():
                pass
        assert self._summaries is not None
        return self._summaries

    def summary(self, *fields: str) -> Summary:
        """The summary of the segments that have every one of ``fields``, pooled."""
        return Summary.pooled([s for s in self.summaries if s.has.issuperset(fields)])

    def every(self, *fields: str) -> bool:
        """Whether every segment has each of ``fields``."""
        return all(s.has.issuperset(fields) for s in self.summaries)

    def any(self, *fields: str) -> bool:
        """Whether some segment has each of ``fields``."""
        return any(s.has.issuperset(fields) for s in self.summaries)

    def which(self, *fields: str) -> list[int]:
        """The segments that have every one of ``fields``."""
        return [k for k, s in enumerate(self.summaries) if s.has.issuperset(fields)]

    def chunks(self, *fields: str) -> Iterator[tuple[int, IdentData]]:
        """(segment number, chunk) of every segment that has each of ``fields``, in time order:
        the first time prepared (and kept), then read back."""
        if self._summaries is None:
            yield from self._first(fields)
            return
        wanted = set(self.which(*fields))
        shells = [_shell(s) for s in self.segments]
        for k, record in zip(self.owner, self.store, strict=True):
            if k in wanted:
                values = dict(zip(SAMPLE_FIELDS, record, strict=True))
                yield k, dataclasses.replace(shells[k], **values)  # type: ignore[arg-type]

    def _first(self, fields: Sequence[str]) -> Iterator[tuple[int, IdentData]]:
        """The first pass (module docstring); left before its end, it keeps nothing."""
        done = False
        summaries: list[Summary] = []
        try:
            for k, segment in enumerate(self.segments):
                summary: Summary | None = None
                last = 0.0
                for chunk in segment.chunks(self.rows):
                    check_signals([chunk])
                    self.store.put([getattr(chunk, f) for f in SAMPLE_FIELDS])
                    self.owner.append(k)
                    this = Summary.of(chunk)
                    gap = float(chunk.t[0]) - last
                    summary = this if summary is None else summary.then(this, gap)
                    last = float(chunk.t[-1])
                    if this.has.issuperset(fields):
                        yield k, chunk
                assert summary is not None
                summaries.append(summary)
            if self.check is not None:
                self.check(summaries)
            done = True
        finally:
            if done:
                self._summaries = summaries
            else:
                self.store.close()
                self.store, self.owner = Store(self.spool), []

    def derived(self) -> Store:
        """A new store for what a step derives per chunk (removed with the chunks)."""
        store = Store(self.spool)
        self.stores.append(store)
        return store

    def close(self) -> None:
        """Remove the kept chunks and every derived store."""
        self.store.close()
        for store in self.stores:
            store.close()


def _shell(segment: Segment) -> IdentData:
    """The segment's chunk without samples (its path, lag and how its motion was found)."""
    values: dict[str, Array | None] = dict.fromkeys(SAMPLE_FIELDS, np.empty((0, 1)))
    return IdentData(path=segment.path, lag=segment.lag, source=segment.source, **values)  # type: ignore[arg-type]


T = TypeVar("T")
F = TypeVar("F", bound=Callable[..., object])


def one_blas_thread(method: F) -> F:
    """``method`` run with BLAS and LAPACK on one thread: a fold factorises thousands of small
    blocks (:meth:`kinergy.linalg.Reduced.stack`), and OpenBLAS's threads wait for each other
    at every step of each; on a machine with other work each wait can cost a time slice
    (measured: a QR of 8254 x 62 takes 11 ms on one thread, 780 ms on two, load 7 on two
    cores)."""

    @functools.wraps(method)
    def limited(*args: object, **kwargs: object) -> object:
        with threadpool_limits(limits=1, user_api="blas"):
            return method(*args, **kwargs)

    return limited  # type: ignore[return-value]


class History(Generic[T]):
    """What friction held through standstill (:func:`kinergy.friction.standstill.hold`) needs
    of the samples before a chunk, whatever their number: per motor the run of the last
    sustained motion (its last :data:`~kinergy.friction.standstill.MIN_RUN` samples: the held
    friction is that run's last sample's) and the last ``MIN_RUN - 1`` samples (a run that goes
    on into the chunk). :meth:`ahead` puts them in front of a chunk in time order, a sample at
    rest for every motor (speeds and accelerations zero) between stretches that are not
    contiguous, so no run joins across a left-out stretch. A run seen in part is never longer
    than it is, and each remembered run is seen whole enough to count as sustained, so every
    sample of the chunk is held as in the whole log (``tests/test_identify_chunks.py``).

    Rows of any sample container ``T`` with ``take(x, index)`` (those rows, in order),
    ``join(parts)``, ``at_rest(x)`` (one row, speeds zeroed) and ``speeds(x)`` ((N, m) motor
    speeds, rad/s); ``still`` (m,) the speeds below which each motor is at rest (0: no hold).
    """

    def __init__(
        self,
        still: Sequence[float],
        take: Callable[[T, NDArray[np.int64]], T],
        join: Callable[[Sequence[T]], T],
        at_rest: Callable[[T], T],
        speeds: Callable[[T], Array],
    ):
        self.still = np.asarray(still, dtype=float)
        self.take, self.join, self.at_rest, self.speeds = take, join, at_rest, speeds
        self.segment = -1
        self.rows: T | None = None  # the remembered samples, in time order
        self.index = np.empty(0, dtype=np.int64)  # their sample numbers in the segment
        self.seen = 0

    @property
    def active(self) -> bool:
        return bool(np.any(self.still > 0.0))

    def ahead(self, segment: int, chunk: T) -> tuple[T, int]:
        """``chunk`` (of segment number ``segment``; a new segment holds nothing yet) with the
        remembered samples in front, and how many rows were put there."""
        if segment != self.segment:
            self.segment, self.rows, self.seen = segment, None, 0
            self.index = np.empty(0, dtype=np.int64)
        if not self.active or self.rows is None:
            return chunk, 0
        parts: list[T] = []
        cuts = np.flatnonzero(np.diff(self.index) > 1) + 1
        for k, (lo, hi) in enumerate(itertools.pairwise([0, *cuts.tolist(), self.index.size])):
            if k > 0:
                parts.append(self.at_rest(self.take(self.rows, np.array([lo]))))
            parts.append(self.take(self.rows, np.arange(lo, hi)))
        joined = self.join([*parts, chunk])
        return joined, self._length(joined) - self._length(chunk)

    def update(self, joined: T, skip: int) -> None:
        """Remember what the samples so far leave for the next chunk (``joined`` as
        :meth:`ahead` gave it, ``skip`` rows in front)."""
        if not self.active:
            return
        rows = self._length(joined) - skip
        numbers = np.full(self._length(joined), -1, dtype=np.int64)
        numbers[skip:] = self.seen + np.arange(rows)
        if skip:  # the remembered samples' numbers; rest rows between stretches stay -1
            cuts = np.flatnonzero(np.diff(self.index) > 1)
            real = np.ones(skip, dtype=bool)
            real[cuts + 1 + np.arange(cuts.size)] = False
            numbers[:skip][real] = self.index
        wm = self.speeds(joined)
        keep = set(range(max(0, self.seen + rows - (MIN_RUN - 1)), self.seen + rows))
        for m, still in enumerate(self.still):
            if still <= 0.0:
                continue
            moving = sustained(np.abs(wm[:, m]) >= still, wm[:, m])
            if moving.any():
                last = int(numbers[np.flatnonzero(moving)[-1]])
                keep.update(range(last - MIN_RUN + 1, last + 1))
        wanted = np.array(sorted(keep), dtype=np.int64)
        where = {int(n): k for k, n in enumerate(numbers) if n >= 0}
        self.rows = self.take(joined, np.array([where[int(n)] for n in wanted], dtype=np.int64))
        self.index = wanted
        self.seen += rows

    def _length(self, x: T) -> int:
        return int(self.speeds(x).shape[0])


def data_history(robot: Robot) -> History[IdentData]:
    """A :class:`History` of prepared samples (:class:`IdentData`) for ``robot``'s friction."""
    n_mat = transmission_matrix(robot)
    still = [float(j.drive.friction.params.get("standstill", 0.0)) for j in robot.joints]

    def take(x: IdentData, index: NDArray[np.int64]) -> IdentData:
        return (
            IdentData.joined([x.sliced(int(k), int(k) + 1) for k in index])
            if index.size
            else x.sliced(0, 0)
        )

    def at_rest(x: IdentData) -> IdentData:
        zero = np.zeros_like(x.qd)
        return dataclasses.replace(x, qd=zero, qdd=zero, qd_cmd=zero, qdd_cmd=zero)

    return History(still, take, IdentData.joined, at_rest, lambda x: x.qd @ n_mat.T)


A = TypeVar("A")
B = TypeVar("B")
R = TypeVar("R")

#: a computation that asks for a batch of values at a time (yields what it needs, is sent what
#: it gets, in the same order) and returns its result: a step that needs passes over the chunks
#: and can share them with others (:func:`together`)
Asks = Generator[list[A], list[B], R]


def together(asks: Sequence[Asks[A, B, R]]) -> Asks[A, B, list[R]]:
    """Several computations in lockstep: each batch asks for what every one still running asks
    for, so one pass over the chunks serves them all; returns their results in order."""
    results: list[R | None] = [None] * len(asks)
    pending: dict[int, list[A]] = {}

    def advance(k: int, answer: list[B] | None) -> None:
        try:
            pending[k] = next(asks[k]) if answer is None else asks[k].send(answer)
        except StopIteration as stop:
            results[k] = stop.value

    for k in range(len(asks)):
        advance(k, None)
    while pending:
        order = list(pending.items())
        pending = {}
        answers = yield [a for _, asked in order for a in asked]
        at = 0
        for k, asked in order:
            advance(k, answers[at : at + len(asked)])
            at += len(asked)
    return results  # type: ignore[return-value]


def answer(asks: Asks[A, B, R], provide: Callable[[list[A]], list[B]]) -> R:
    """Run a computation to its end, ``provide`` answering each batch it asks for."""
    try:
        asked = next(asks)
        while True:
            asked = asks.send(provide(asked))
    except StopIteration as stop:
        return stop.value


C = TypeVar("C")
D = TypeVar("D")


def translated(
    asks: Asks[A, B, R], ask: Callable[[A], C], back: Callable[[A, D], B]
) -> Asks[C, D, R]:
    """``asks`` asking for ``ask(a)`` instead of each ``a`` and given ``back(a, d)`` for each
    answer ``d``."""
    try:
        asked = next(asks)
        while True:
            found = yield [ask(a) for a in asked]
            asked = asks.send([back(a, d) for a, d in zip(asked, found, strict=True)])
    except StopIteration as stop:
        return stop.value


def windowed(
    chunks: Iterator[tuple[int, IdentData]], reach: int
) -> Iterator[tuple[int, IdentData, IdentData, int]]:
    """Each chunk with up to ``reach`` samples of the same segment's chunks on either side, for
    a step whose value at a sample depends on its neighbours (a zero-phase filter): (segment
    number, chunk, window, where the chunk starts in the window). Holds the chunks ``reach``
    samples ahead of the one it yields."""
    ahead: collections.deque[tuple[int, IdentData]] = collections.deque()
    source = iter(chunks)
    behind: IdentData | None = None
    done = False
    while True:
        while not done and (not ahead or _short(ahead, reach)):
            try:
                ahead.append(next(source))
            except StopIteration:
                done = True
        if not ahead:
            return
        k, chunk = ahead.popleft()
        after: list[IdentData] = []
        rows = 0
        for kk, later in ahead:
            if kk != k or rows >= reach:
                break
            after.append(later.sliced(0, min(len(later), reach - rows)))
            rows += len(after[-1])
        before = [] if behind is None else [behind]
        window = IdentData.joined([*before, chunk, *after])
        yield k, chunk, window, 0 if behind is None else len(behind)
        same = bool(ahead) and ahead[0][0] == k
        kept = IdentData.joined([*before, chunk]) if same else None
        behind = None if kept is None else kept.sliced(max(len(kept) - reach, 0), len(kept))


def _short(ahead: collections.deque[tuple[int, IdentData]], reach: int) -> bool:
    """Whether fewer than ``reach`` samples of the first chunk's segment follow it."""
    k = ahead[0][0]
    if any(kk != k for kk, _ in ahead):
        return False
    return sum(len(c) for _, c in itertools.islice(ahead, 1, None)) < reach
