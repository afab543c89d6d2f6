"""From a controller log to the signals identification uses, chunk by chunk.

Real logs are not the model's equations: the measured motion trails the commanded one by a few
milliseconds, encoder speeds and motor currents are noisy, logs sample irregularly and include
samples where no program runs, and UR's logs carry no measured acceleration. This module decides
which signal feeds which regression (UR5e doc sections 3-4):

- ``target_moment`` is the controller's feed-forward on the *commanded* motion (UR5e eq 7), so the
  rotor-inertia and link regressions against it use ``target_q/qd/qdd`` when the log has them;
- ``actual_current`` is drawn by the *real* motion (eq 17). When the log has the commanded motion,
  the real one is taken as the commanded motion delayed by the lag estimated from ``target_qd``
  against ``actual_qd`` (noise-free, and exact for a controller that tracks well); otherwise the
  measured ``actual_q/qd`` with the speed low-pass filtered (zero phase, Butterworth) and
  differentiated for the acceleration (nursing eq 24's filtering);
- samples where the program does not run (``runtime_state`` != 2 or ``robot_mode`` != 7, when the
  log has them) are left out, and irregular time stamps are resampled to a uniform grid.

One path prepares every log. The reader's chunks (:class:`kinergy.logs.reading.CheckedLog`) are
written once to an unnamed temporary file (:class:`LogSpill`), keeping in memory only the time
stamps and the state columns (``runtime_state``, ``robot_mode``, ``segment``). Those decide the
segments (:func:`kinergy.io.segments.segment_bounds`), the samples a program runs in
(:func:`running_range`) and the uniform grid (:func:`uniform_grid`); :class:`PreparedSegment`
then yields the prepared samples (:class:`IdentData`) in chunks of any size, each read back from
the spill with enough of its neighbours that it equals the whole segment's preparation. A log
already in memory is one chunk (:func:`prepare`).

What reaches across chunk edges, and the pad that makes each chunk equal the whole segment's:

- resampling to the uniform grid is linear interpolation: a grid sample needs the two raw
  samples around it, which the raw rows read for it always include;
- the commanded acceleration, when the log lacks ``target_qdd``, is a central difference: one
  sample each side;
- the real motion is the commanded one delayed by the lag through a cubic spline
  (:func:`delay`). A spline's value at one knot depends on a knot ``k`` samples away with a
  weight that falls as ``(2 - sqrt(3))^k`` (0.27 per knot), so each chunk is splined with
  :data:`~kinergy.io.motion.HALO` (48) samples of its neighbours on each side (1e-27 at
  the far end: the whole segment's spline to round-off), plus the lag in samples; at the
  segment's ends the window ends with the segment, as the whole-segment spline does;
- the lag itself (:func:`estimate_lag`) compares the spline of the commanded speed with the
  measured speed at a few thousand samples (:func:`lag_samples`): splines through the samples
  within ``HALO`` of each of them, in batches of about :data:`LAG_BATCH_ROWS` (a batch's ends
  lie in the gaps between windows), give the same lag;
- the filtered measured speed (a log without the commanded motion) is a zero-phase Butterworth
  filter run forward and back (:func:`lowpass`). Its impulse response decays as
  ``exp(-zeta 2 pi f_c t)`` with ``zeta = sin(pi/8)`` for the 4th order, so a chunk filtered
  with :data:`FILTER_REACH` periods of the cutoff of its neighbours on each side (e^-58 at the
  far end) equals the whole segment's filter to round-off; at the segment's ends the window ends
  with the segment and the filter pads it as it pads the whole segment.
"""

from __future__ import annotations

import itertools
import math
import os
import tempfile
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, fields
from typing import BinaryIO

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.io.formats import CHUNK_ROWS
from kinergy.io.log import Log
from kinergy.io.motion import HALO
from kinergy.io.segments import segment_bounds
from kinergy.logs.reading import CheckedLog

__all__ = [
    "FILTER_REACH",
    "JOINT_SIGNALS",
    "MAX_LAG",
    "MEASURED_TORQUE",
    "SAMPLE_FIELDS",
    "SIGNALS",
    "STATE",
    "IdentData",
    "LogSpill",
    "PreparedSegment",
    "check_cutoff",
    "check_joints",
    "commanded_motion",
    "default_cutoff",
    "delay",
    "estimate_lag",
    "ident_data",
    "lag_samples",
    "lag_search",
    "lowpass",
    "prepare",
    "prepare_segment",
    "resample",
    "running_range",
    "segment_paths",
    "spill_log",
    "uniform_grid",
]


#: runtime_state PLAYING and robot_mode RUNNING in RTDE
_PLAYING = 2
_RUNNING = 7


@dataclass(frozen=True, eq=False)
class IdentData:
    """One log, ready for identification. Arrays are (N, n) unless noted.

    Attributes
    ----------
    path : str
    t : ndarray, shape (N,)
        Uniform time stamps, s.
    q_cmd, qd_cmd, qdd_cmd :
        The motion ``target_moment`` refers to (commanded; measured when the log has no target).
    q, qd, qdd :
        The real motion (commanded delayed by ``lag``, or the filtered measured motion).
    tau_ref : ndarray or None
        ``target_moment``, N m.
    current : ndarray or None
        ``actual_current``, A.
    torque : ndarray or None
        Measured joint torques, N m (arms with torque sensors).
    lag : float
        Estimated lag of the real motion behind the commanded one, s.
    source : str
        How the real motion was obtained: ``"delayed target"`` or ``"filtered actual"``.
    temperature : ndarray or None
        ``joint_temperatures``, deg C.
    voltage : ndarray or None
        ``actual_joint_voltage``, V (as the controller logs it).
    supply_voltage, supply_current : ndarray, shape (N,), or None
        ``actual_robot_voltage`` (V) and ``actual_robot_current`` (A): the arm's supply.
    """

    path: str
    t: Array
    q_cmd: Array
    qd_cmd: Array
    qdd_cmd: Array
    q: Array
    qd: Array
    qdd: Array
    tau_ref: Array | None
    current: Array | None
    torque: Array | None
    lag: float
    source: str
    temperature: Array | None = None
    voltage: Array | None = None
    supply_voltage: Array | None = None
    supply_current: Array | None = None

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def dt(self) -> float:
        return float(self.t[1] - self.t[0])

    @classmethod
    def joined(cls, parts: Sequence[IdentData]) -> IdentData:
        """Samples of ``parts`` one after the other (a field is None when any part lacks it);
        the last part's path, lag and source."""
        if len(parts) == 1:
            return parts[0]
        joined: dict[str, Array | None] = {}
        for name in SAMPLE_FIELDS:
            values = [getattr(p, name) for p in parts]
            joined[name] = None if any(v is None for v in values) else np.concatenate(values)
        last = parts[-1]
        return cls(path=last.path, lag=last.lag, source=last.source, **joined)  # type: ignore[arg-type]

    def sliced(self, start: int, stop: int) -> IdentData:
        """Samples ``start:stop`` (for hold-out splits)."""

        def cut(x: Array | None) -> Array | None:
            return None if x is None else x[start:stop]

        return IdentData(
            self.path,
            self.t[start:stop],
            self.q_cmd[start:stop],
            self.qd_cmd[start:stop],
            self.qdd_cmd[start:stop],
            self.q[start:stop],
            self.qd[start:stop],
            self.qdd[start:stop],
            cut(self.tau_ref),
            cut(self.current),
            cut(self.torque),
            self.lag,
            self.source,
            cut(self.temperature),
            cut(self.voltage),
            cut(self.supply_voltage),
            cut(self.supply_current),
        )


def running_range(log: Log) -> slice:
    """The samples identification keeps: the longest run of consecutive samples where a program
    runs (``runtime_state`` 2 and ``robot_mode`` 7; all of them when the log has neither column).

    Raises
    ------
    KinergyError
        No sample is left.
    """
    keep = np.ones(len(log), dtype=bool)
    if "runtime_state" in log:
        keep &= log["runtime_state"] == _PLAYING
    if "robot_mode" in log:
        keep &= log["robot_mode"] == _RUNNING
    if keep.all():
        return slice(0, len(log))
    if not keep.any():
        raise KinergyError(
            f"{log.path}: no sample where the program runs (runtime_state 2, robot_mode 7)"
        )
    # keep the longest run of consecutive running samples: gaps would join unrelated motions
    edges = np.flatnonzero(np.diff(np.concatenate([[0], keep.astype(int), [0]])))
    starts, stops = edges[::2], edges[1::2]
    k = int(np.argmax(stops - starts))
    return slice(int(starts[k]), int(stops[k]))


def uniform_grid(t: Array, *, tolerance: float = 0.01) -> tuple[float, int] | None:
    """The uniform grid irregular time stamps ``t`` (N,) are resampled to, as its period (s)
    and size (the grid is ``t[0] + period * arange(size)``); None when every period is within
    ``tolerance`` of the median (the log is kept as is)."""
    step = np.diff(t)
    dt = float(np.median(step))
    if np.max(np.abs(step - dt)) <= tolerance * dt:
        return None
    return dt, int(np.floor((t[-1] - t[0]) / dt + 1e-9)) + 1


def resample(log: Log, grid: Array) -> Log:
    """``log``'s signals at the times ``grid`` (linear interpolation; a row depends only on the
    two samples around it)."""
    signals = {}
    for name, x in log.signals.items():
        if x.ndim == 1:
            signals[name] = np.interp(grid, log.t, x)
        else:
            signals[name] = np.column_stack(
                [np.interp(grid, log.t, x[:, k]) for k in range(x.shape[1])]
            )
    return Log(log.path, grid, signals)


def check_cutoff(fs: float, cutoff: float) -> None:
    """Raise unless ``0 < cutoff < fs / 2`` (Hz)."""
    if not 0.0 < cutoff < fs / 2.0:
        raise KinergyError(
            f"--cutoff: the filter cutoff must be between 0 and {fs / 2:g} Hz (half of the log's "
            f"{fs:g} Hz), got {cutoff:g}"
        )


def lowpass(x: Array, fs: float, cutoff: float, order: int = 4) -> Array:
    """Zero-phase Butterworth low-pass of ``x`` (N, ...) along time; ``cutoff`` Hz, ``fs`` Hz."""
    from scipy.signal import butter, sosfiltfilt  # slow to import; only filtering needs it

    check_cutoff(fs, cutoff)
    sos = butter(order, cutoff / (fs / 2.0), output="sos")
    # pad by several periods of the cutoff so the ends have settled
    padlen = min(int(np.ceil(6.0 * fs / cutoff)), x.shape[0] - 1)
    return np.asarray(sosfiltfilt(sos, x, axis=0, padlen=padlen), dtype=float)


#: s: the largest lag :func:`estimate_lag` looks for
MAX_LAG = 0.05


def lag_samples(t: Array, *, max_lag: float = MAX_LAG) -> NDArray[np.intp]:
    """The samples of uniform time stamps ``t`` (N,) :func:`estimate_lag` compares: those more
    than ``max_lag`` from either end, thinned to a few thousand (empty: too few to tell)."""
    inner = np.flatnonzero((t > t[0] + max_lag) & (t < t[-1] - max_lag))
    if inner.size < 10:
        return inner[:0]
    # a few thousand samples pin a lag of milliseconds down; evaluating every one is waste
    return inner[:: max(1, inner.size // 4000)]


def estimate_lag(t: Array, commanded: Array, measured: Array, *, max_lag: float = MAX_LAG) -> float:
    """Delay of ``measured`` behind ``commanded`` (both (N, n) speeds), s, by least squares over
    sub-sample shifts up to ``max_lag`` (a coarse grid then a golden-section refinement) at the
    samples :func:`lag_samples` picks."""
    inner = lag_samples(t, max_lag=max_lag)
    if inner.size == 0:
        return 0.0
    spline = CubicSpline(t, commanded, axis=0)
    return lag_search(spline, t[inner], measured[inner], float(t[1] - t[0]), max_lag=max_lag)


def lag_search(
    spline: Callable[[Array], Array],
    t: Array,
    measured: Array,
    dt: float,
    *,
    max_lag: float = MAX_LAG,
) -> float:
    """The shift (s) of the commanded speeds ``spline`` (times (k,) -> speeds (k, n)) that best
    matches ``measured`` (k, n) at the times ``t`` (k,): a grid of whole periods ``dt`` then a
    golden-section refinement."""

    def cost(lag: float) -> float:
        return float(np.sum((spline(t - lag) - measured) ** 2))

    grid = np.arange(-2, int(np.ceil(max_lag / dt)) + 1) * dt
    best = grid[int(np.argmin([cost(g) for g in grid]))]
    lo, hi = best - dt, best + dt
    ratio = (np.sqrt(5.0) - 1.0) / 2.0
    for _ in range(40):
        a, b = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
        if cost(a) < cost(b):
            hi = b
        else:
            lo = a
    return float(0.5 * (lo + hi))


def delay(t: Array, x: Array, lag: float, span: tuple[float, float] | None = None) -> Array:
    """``x(t - lag)`` by a cubic spline through ``t`` (N,), ``x`` (N, n), held at the value at
    the start of ``span`` (default ``t``'s ends: the whole log) before it."""
    lo, hi = (t[0], t[-1]) if span is None else span
    spline = CubicSpline(t, x, axis=0)
    return np.asarray(spline(np.clip(t - lag, lo, hi)), dtype=float)


#: the log signal of measured joint torques, N m (RTDE-style name, ``actual_joint_torque_k``)
MEASURED_TORQUE = "actual_joint_torque"

#: (N, n) signals whose joint count must match the robot's
JOINT_SIGNALS = (
    "target_q",
    "target_qd",
    "target_qdd",
    "actual_q",
    "actual_qd",
    "target_moment",
    "actual_current",
    MEASURED_TORQUE,
    "joint_temperatures",
    "actual_joint_voltage",
)


def check_joints(log: Log, n_joints: int) -> None:
    """Raise when a joint signal of ``log`` does not have ``n_joints`` columns."""
    for name in JOINT_SIGNALS:
        if name in log and (log[name].ndim != 2 or log[name].shape[1] != n_joints):
            width = 1 if log[name].ndim == 1 else log[name].shape[1]
            raise KinergyError(
                f"{log.path}: {name} has {width} joints but the robot has {n_joints}"
            )


#: (q, qd, qdd), each (N, n)
_Motion3 = tuple[Array, Array, Array]


def commanded_motion(log: Log) -> _Motion3:
    """``target_q``, ``target_qd`` and ``target_qdd`` of a uniform ``log`` (the acceleration
    differentiated from the speed when the log lacks it: a row depends on its neighbours only)."""
    q_cmd, qd_cmd = log["target_q"], log["target_qd"]
    qdd_cmd = log["target_qdd"] if "target_qdd" in log else np.gradient(qd_cmd, log.t, axis=0)
    return q_cmd, qd_cmd, qdd_cmd


def default_cutoff(t: Array) -> float:
    """The low-pass cutoff for measured speeds of uniform time stamps ``t``: min(10 Hz, a fifth
    of the sample rate)."""
    fs = 1.0 / float(t[1] - t[0])
    return min(10.0, fs / 5.0)


def ident_data(
    log: Log,
    commanded: _Motion3,
    real: _Motion3,
    how: tuple[float, str],
    *,
    torque: Array | None = None,
) -> IdentData:
    """:class:`IdentData` of a uniform ``log`` with its ``commanded`` and ``real`` motions (each
    (q, qd, qdd)), ``how`` = (lag in s, how the real motion was obtained); measured joint
    torques from ``torque`` or else the log's :data:`MEASURED_TORQUE`."""
    if torque is None and MEASURED_TORQUE in log:  # arms with joint torque sensors
        torque = np.asarray(log[MEASURED_TORQUE], dtype=float)
    q_cmd, qd_cmd, qdd_cmd = (np.asarray(x, dtype=float) for x in commanded)
    q, qd, qdd = (np.asarray(x, dtype=float) for x in real)
    return IdentData(
        path=log.path,
        t=log.t,
        q_cmd=q_cmd,
        qd_cmd=qd_cmd,
        qdd_cmd=qdd_cmd,
        q=q,
        qd=qd,
        qdd=qdd,
        tau_ref=log["target_moment"] if "target_moment" in log else None,
        current=log["actual_current"] if "actual_current" in log else None,
        torque=torque,
        lag=how[0],
        source=how[1],
        temperature=_signal(log, "joint_temperatures"),
        voltage=_signal(log, "actual_joint_voltage"),
        supply_voltage=_signal(log, "actual_robot_voltage"),
        supply_current=_signal(log, "actual_robot_current"),
    )


def _signal(log: Log, name: str) -> Array | None:
    """A measured signal of the log, or None when it lacks it."""
    return np.asarray(log[name], dtype=float) if name in log else None


#: the signals identification takes from a log (those it has are spilled)
SIGNALS = (*JOINT_SIGNALS, "actual_robot_voltage", "actual_robot_current")
#: per-sample state kept in memory: it decides segments and the samples a program runs in
STATE = ("runtime_state", "robot_mode", "segment")
#: IdentData fields that hold samples, (N, ...) each
SAMPLE_FIELDS = tuple(f.name for f in fields(IdentData) if f.name not in ("path", "lag", "source"))
#: periods of the low-pass cutoff each chunk of a filtered log is filtered with on either side
FILTER_REACH = 24.0

#: how the real motion was obtained (``IdentData.source``)
DELAYED, FILTERED = "delayed target", "filtered actual"


class LogSpill:
    """A log's signals as raw float64 rows in an unnamed temporary file, read back by row range.

    Attributes
    ----------
    path : str
        The log's path (for messages).
    layout : list of (str, int, bool)
        Per signal: name, width, and whether it is a vector (N, width) rather than (N,).
    state : Log
        Time stamps and the :data:`STATE` columns of every sample, in memory.
    notes : list of str
        What reading the file said (rows dropped by ``repair``).
    names : set of str
        Every signal the log has (spilled or not).
    head : Log
        The log's first samples, every signal.
    """

    def __init__(self, path: str, layout: list[tuple[str, int, bool]], file: BinaryIO):
        self.path = path
        self.layout = layout
        self.width = sum(w for _, w, _ in layout)
        self.file = file
        self.state = Log(path, np.empty(0))
        self.notes: list[str] = []
        self.names = {name for name, _, _ in layout}
        self.head = Log(path, np.empty(0))

    def __len__(self) -> int:
        return len(self.state)

    def close(self) -> None:
        """Remove the spill."""
        self.file.close()

    def append(self, chunk: Log) -> None:
        """Write ``chunk``'s signals of :attr:`layout` at the end."""
        rows = np.empty((len(chunk), self.width))
        col = 0
        for name, width, _ in self.layout:
            rows[:, col : col + width] = chunk[name].reshape(len(chunk), width)
            col += width
        self.file.write(rows.tobytes())

    def read(self, start: int, stop: int, names: Sequence[str] | None = None) -> Log:
        """Samples ``start:stop`` as a :class:`Log` (time stamps from :attr:`state`), of the
        signals ``names`` (default all)."""
        size = (stop - start) * self.width * 8
        raw = os.pread(self.file.fileno(), size, start * self.width * 8)
        rows = np.frombuffer(raw, dtype=float).reshape(stop - start, self.width)
        signals, col = {}, 0
        for name, width, vector in self.layout:
            if names is None or name in names:
                block = rows[:, col : col + width]
                signals[name] = block.copy() if vector else block[:, 0].copy()
            col += width
        return Log(self.path, self.state.t[start:stop], signals)


def _spill(path: str, chunks: Iterator[Log], notes: Sequence[str]) -> LogSpill:
    """``chunks`` (consecutive, of one log) written to a :class:`LogSpill`."""
    first = next(chunks, None)
    if first is None:
        raise KinergyError(f"{path}: the log has no samples")
    names = first.signals
    # with the commanded motion, the measured positions are not used (only looked for)
    skip = {"actual_q"} if {"target_q", "target_qd"} <= set(names) else set()
    layout = [
        (s, 1 if names[s].ndim == 1 else names[s].shape[1], names[s].ndim == 2)
        for s in SIGNALS
        if s in names and s not in skip
    ]
    spill = LogSpill(path, layout, tempfile.TemporaryFile())
    spill.names, spill.head = set(names), first
    times: list[Array] = []
    state: dict[str, list[Array]] = {s: [] for s in STATE if s in names}
    try:
        for chunk in itertools.chain([first], chunks):
            spill.append(chunk)
            # copies: a view would keep the chunk's whole block of values alive
            times.append(np.array(chunk.t, dtype=float))
            for name, parts in state.items():
                parts.append(np.array(chunk[name], dtype=float))
        spill.file.flush()
    except BaseException:
        spill.close()
        raise
    spill.notes = list(notes)
    spill.state = Log(
        spill.path, np.concatenate(times), {k: np.concatenate(v) for k, v in state.items()}
    )
    return spill


def spill_log(log: CheckedLog) -> LogSpill:
    """Read ``log`` once, in its chunks (through its checks), into a :class:`LogSpill` (the
    caller closes it). ``log`` should select the signals identification uses (:data:`SIGNALS`)
    and the state (:data:`STATE`)."""
    chunks = log.chunks()
    first = next(chunks, None)
    spill = _spill(log.path, itertools.chain([] if first is None else [first], chunks), ())
    spill.notes = list(log.notes)
    return spill


@dataclass(frozen=True, eq=False)
class PreparedSegment:
    """One segment of a spilled log, prepared: :meth:`chunks` yields its :class:`IdentData` in
    consecutive pieces equal to :func:`~kinergy.logs.prepare.prepare` of the whole segment.

    Attributes
    ----------
    path : str
        As the in-memory path names the segment.
    spill : LogSpill
    rows : slice
        The raw samples (of the spill) the segment keeps (the program running).
    grid : (float, int) or None
        The uniform grid's period (s) and size when the samples are resampled; None when they are
        uniform already.
    lag : float
        Lag of the real motion behind the commanded one, s (0 for a filtered log).
    source : str
        ``"delayed target"`` or ``"filtered actual"`` (module docstring).
    cutoff : float
        The low-pass cutoff of a filtered log's speeds, Hz.
    """

    path: str
    spill: LogSpill
    rows: slice
    grid: tuple[float, int] | None
    lag: float
    source: str
    cutoff: float = math.inf

    def __len__(self) -> int:
        return self.rows.stop - self.rows.start if self.grid is None else self.grid[1]

    @property
    def t0(self) -> float:
        return float(self.spill.state.t[self.rows.start])

    @property
    def dt(self) -> float:
        if self.grid is not None:
            return self.grid[0]
        t = self.spill.state.t
        return float(t[self.rows.start + 1] - t[self.rows.start])

    @property
    def span(self) -> tuple[float, float]:
        """The first and last uniform time stamps, s."""
        if self.grid is None:
            return self.t0, float(self.spill.state.t[self.rows.stop - 1])
        return self.t0, self.t0 + self.grid[0] * (self.grid[1] - 1)

    def uniform(self, start: int, stop: int, names: Sequence[str] | None = None) -> Log:
        """Uniform samples ``start:stop`` of the segment (resampled where the log is not), of
        the signals ``names`` (default all)."""
        a = self.rows.start
        if self.grid is None:
            log = self.spill.read(a + start, a + stop, names)
        else:
            grid = np.asarray(self.t0 + self.grid[0] * np.arange(start, stop), dtype=float)
            raw = self.spill.state.t[self.rows]
            lo = max(int(np.searchsorted(raw, grid[0], side="right")) - 1, 0)
            hi = min(int(np.searchsorted(raw, grid[-1], side="left")) + 1, raw.size)
            log = resample(self.spill.read(a + lo, a + hi, names), grid)
        return Log(self.path, log.t, log.signals)

    def halo(self) -> int:
        """Samples of context each chunk is prepared with (module docstring)."""
        if self.source == FILTERED:
            return int(np.ceil(FILTER_REACH / (self.cutoff * self.dt))) + 2
        return HALO + int(np.ceil(abs(self.lag) / self.dt)) + 2

    def _prepared(self, window: Log) -> IdentData:
        """The uniform samples ``window`` prepared (module docstring)."""
        if self.source == DELAYED:
            commanded = commanded_motion(window)
            # one spline through the three signals' columns: each column as its own
            both = delay(window.t, np.hstack(commanded), self.lag, self.span)
            real = tuple(np.hsplit(both, 3))
            return ident_data(window, commanded, real, (self.lag, self.source))  # type: ignore[arg-type]
        fs = 1.0 / self.dt
        qd = lowpass(window["actual_qd"], fs, self.cutoff)
        measured = (window["actual_q"], qd, np.gradient(qd, window.t, axis=0))
        return ident_data(window, measured, measured, (0.0, self.source))

    def chunks(self, rows: int = CHUNK_ROWS) -> Iterator[IdentData]:
        """The prepared segment in pieces of at most ``rows`` samples, in time order."""
        size, pad = len(self), self.halo()
        for start in range(0, size, rows):
            stop = min(start + rows, size)
            lo, hi = max(start - pad, 0), min(stop + pad, size)
            yield self._prepared(self.uniform(lo, hi)).sliced(start - lo, stop - lo)

    def whole(self) -> IdentData:
        """The whole segment prepared: one chunk."""
        return self._prepared(self.uniform(0, len(self)))


def _lag(segment: PreparedSegment) -> float:
    """:func:`~kinergy.logs.prepare.estimate_lag` of ``segment`` from the samples near
    the compared ones (module docstring)."""
    names = segment.spill.names
    if not {"actual_q", "actual_qd"} <= names:
        return 0.0
    size, t0, dt = len(segment), segment.t0, segment.dt
    if segment.grid is None:
        t = segment.spill.state.t[segment.rows]
    else:
        t = np.asarray(t0 + dt * np.arange(size), dtype=float)
    inner = lag_samples(t)
    if inner.size == 0:
        return 0.0
    near = np.zeros(size + 1, dtype=int)
    np.add.at(near, np.clip(inner - HALO, 0, size), 1)
    np.add.at(near, np.clip(inner + HALO + 1, 0, size), -1)
    covered = np.cumsum(near[:-1]) > 0
    edges = np.flatnonzero(np.diff(np.concatenate([[0], covered.astype(int), [0]])))
    speeds = ("target_qd", "actual_qd")
    times = t[inner]
    splines: list[tuple[CubicSpline, int, int]] = []
    measured: list[Array] = []
    done = 0
    for batch in _batches(list(zip(edges[::2], edges[1::2], strict=True)), LAG_BATCH_ROWS):
        window = Log.concatenate([segment.uniform(a, b, speeds) for a, b in batch])
        stop = int(np.searchsorted(inner, batch[-1][1]))
        splines.append((CubicSpline(window.t, window["target_qd"], axis=0), done, stop))
        measured.append(window["actual_qd"][np.searchsorted(window.t, times[done:stop])])
        done = stop

    def commanded(x: Array) -> Array:
        """The commanded speeds at ``x`` (the compared samples' times, shifted), each sample
        from the spline of its own batch of windows."""
        return np.concatenate([spline(x[a:b]) for spline, a, b in splines])

    return lag_search(commanded, times, np.concatenate(measured), float(t[1] - t[0]))


#: samples splined at once by the lag estimate (the windows around the compared samples, in
#: batches: the spline of a batch's windows needs a few times its samples while it is built)
LAG_BATCH_ROWS = 50_000


def _batches(windows: list[tuple[int, int]], rows: int) -> Iterator[list[tuple[int, int]]]:
    """Consecutive ``windows`` (start, stop) grouped into batches of about ``rows`` samples."""
    batch: list[tuple[int, int]] = []
    size = 0
    for a, b in windows:
        batch.append((a, b))
        size += b - a
        if size >= rows:
            yield batch
            batch, size = [], 0
    if batch:
        yield batch


def prepare_segment(
    spill: LogSpill, bounds: tuple[int, int], path: str, n_joints: int, cutoff: float | None
) -> PreparedSegment:
    """Samples ``bounds`` (a segment) of a spilled log, prepared (module docstring): the
    commanded motion delayed by the estimated lag when the log has ``target_q`` and
    ``target_qd``, else the measured motion low-pass filtered at ``cutoff`` Hz (default
    :func:`default_cutoff`).

    Raises
    ------
    KinergyError
        No sample where the program runs, no motion, a joint count that does not match, a
        cutoff outside the sample rate's band.
    """
    a, b = bounds
    state = Log(path, spill.state.t[a:b], {k: v[a:b] for k, v in spill.state.signals.items()})
    keep = running_range(state)
    rows = slice(a + keep.start, a + keep.stop)
    if rows.stop - rows.start < 2:
        raise KinergyError(f"{path}: fewer than 2 samples where the program runs")
    grid = uniform_grid(spill.state.t[rows])
    names = spill.names
    check_joints(spill.head, n_joints)
    has_actual = {"actual_q", "actual_qd"} <= names
    if {"target_q", "target_qd"} <= names:
        segment = PreparedSegment(path, spill, rows, grid, 0.0, DELAYED)
        if has_actual:
            head = segment.uniform(0, 2)
            fs = 1.0 / float(head.t[1] - head.t[0])
            check_cutoff(fs, default_cutoff(head.t) if cutoff is None else cutoff)
        return PreparedSegment(path, spill, rows, grid, _lag(segment), DELAYED)
    if not has_actual:
        spill.head.require("actual_q", "actual_qd", purpose="identification")
    segment = PreparedSegment(path, spill, rows, grid, 0.0, FILTERED)
    head = segment.uniform(0, 2)
    fs = 1.0 / float(head.t[1] - head.t[0])
    cut = default_cutoff(head.t) if cutoff is None else cutoff
    check_cutoff(fs, cut)
    return PreparedSegment(path, spill, rows, grid, 0.0, FILTERED, cut)


def prepare(log: Log, n_joints: int, *, cutoff: float | None = None) -> IdentData:
    """A log held in memory prepared whole, as one chunk of the one path: spilled
    (:class:`LogSpill`) and prepared as its single segment (:func:`prepare_segment`; the log is
    not split at gaps and not checked: a log the twin wrote, say).

    Raises
    ------
    KinergyError
        As :func:`prepare_segment`.
    """
    spill = _spill(log.path, iter([log]), log.notes)
    try:
        return prepare_segment(spill, (0, len(log)), log.path, n_joints, cutoff).whole()
    finally:
        spill.close()


def segment_paths(spill: LogSpill) -> list[tuple[tuple[int, int], str]]:
    """The segments of a spilled log (:func:`kinergy.io.segments.segment_bounds`) and the path
    each is named by (``#k`` when there are several, as :func:`~kinergy.io.segments.split_segments`)."""
    bounds = segment_bounds(spill.state.t, spill.state.signals.get("segment"))
    if len(bounds) == 1:
        return [(bounds[0], spill.path)]
    return [(ab, f"{spill.path}#{k}") for k, ab in enumerate(bounds)]
