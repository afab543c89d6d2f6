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
  differentiated for the acceleration (nursing eq 24's filtering), or the logged acceleration
  ``actual_qdd`` filtered as the speed is where the log has it;
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

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.io.fields import check_widths
from kinergy.io.formats import CHUNK_ROWS
from kinergy.io.log import Log
from kinergy.io.motion import HALO
from kinergy.logs.filtering import FILTER_REACH, check_cutoff, default_cutoff, lowpass
from kinergy.logs.ident_data import SAMPLE_FIELDS, IdentData, Motion3, ident_data
from kinergy.logs.lag import LAG_BATCH_ROWS, batches, delay, lag_samples, lag_search
from kinergy.logs.payload import with_logged
from kinergy.logs.samples import STATE, resample, running_range, uniform_grid
from kinergy.logs.spill import SIGNALS, LogSpill, spill_chunks, spill_log
from kinergy.model.robot import Robot

__all__ = [
    # the prepared samples' type, also importable from here (identification imports it so)
    "SAMPLE_FIELDS",
    "SIGNALS",
    "STATE",
    "IdentData",
    "PreparedSegment",
    "commanded_motion",
    "prepare",
    "prepare_segment",
    "spill_log",
]


def commanded_motion(log: Log) -> Motion3:
    """``target_q``, ``target_qd`` and ``target_qdd`` of a uniform ``log`` (the acceleration
    differentiated from the speed when the log lacks it: a row depends on its neighbours only)."""
    q_cmd, qd_cmd = log["target_q"], log["target_qd"]
    qdd_cmd = log["target_qdd"] if "target_qdd" in log else np.gradient(qd_cmd, log.t, axis=0)
    return q_cmd, qd_cmd, qdd_cmd


#: how the real motion was obtained (``IdentData.source``)
DELAYED, FILTERED = "delayed target", "filtered actual"


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
    load : ndarray, shape (10,), or None
        The payload the controller logged over the segment (one: a log is cut where it
        changes; :func:`kinergy.logs.payload.payload_columns`), None when it logs none.
    """

    path: str
    spill: LogSpill
    rows: slice
    grid: tuple[float, int] | None
    lag: float
    source: str
    cutoff: float = math.inf
    load: Array | None = None

    def robot(self, robot: Robot) -> Robot:
        """``robot`` carrying the payload the segment logged (:attr:`load`), else as it is."""
        return with_logged(robot, self.load)

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
        if "actual_qdd" in window:  # measured: filtered as the speed is, not differentiated
            qdd = lowpass(window["actual_qdd"], fs, self.cutoff)
        else:
            qdd = np.gradient(qd, window.t, axis=0)
        measured = (window["actual_q"], qd, qdd)
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
    for batch in batches(list(zip(edges[::2], edges[1::2], strict=True)), LAG_BATCH_ROWS):
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
    check_widths(spill.head.signals, n_joints, spill.head.path)
    has_actual = {"actual_q", "actual_qd"} <= names
    if {"target_q", "target_qd"} <= names:
        segment = PreparedSegment(path, spill, rows, grid, 0.0, DELAYED)
        if has_actual:
            head = segment.uniform(0, 2)
            fs = 1.0 / float(head.t[1] - head.t[0])
            check_cutoff(fs, default_cutoff(head.t) if cutoff is None else cutoff)
        lag = _lag(segment)
        return PreparedSegment(path, spill, rows, grid, lag, DELAYED, load=spill.load_at(a))
    if not has_actual:
        spill.head.require("actual_q", "actual_qd", purpose="identification")
    segment = PreparedSegment(path, spill, rows, grid, 0.0, FILTERED)
    head = segment.uniform(0, 2)
    fs = 1.0 / float(head.t[1] - head.t[0])
    cut = default_cutoff(head.t) if cutoff is None else cutoff
    check_cutoff(fs, cut)
    return PreparedSegment(path, spill, rows, grid, 0.0, FILTERED, cut, spill.load_at(a))


def prepare(log: Log, n_joints: int, *, cutoff: float | None = None) -> IdentData:
    """A log held in memory prepared whole, as one chunk of the one path: spilled
    (:class:`LogSpill`) and prepared as its single segment (:func:`prepare_segment`; the log is
    not split at gaps and not checked: a log the twin wrote, say).

    Raises
    ------
    KinergyError
        As :func:`prepare_segment`.
    """
    spill = spill_chunks(log.path, iter([log]), log.notes)
    try:
        return prepare_segment(spill, (0, len(log)), log.path, n_joints, cutoff).whole()
    finally:
        spill.close()
