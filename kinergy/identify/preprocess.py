"""From a controller log to the signals identification uses.

Real logs are not the model's equations: the measured motion trails the commanded one by a few
milliseconds, encoder speeds and motor currents are noisy, logs sample irregularly and include
samples where no program runs, and UR's logs carry no measured acceleration. This module decides
which signal feeds which regression (UR5e doc sections 3-4):

- ``target_moment`` is the controller's feed-forward on the *commanded* motion (UR5e eq 7), so the
  rotor-inertia and link regressions against it use ``target_q/qd/qdd`` when the log has them;
- ``actual_current`` is drawn by the *real* motion (eq 17). When the log has the commanded motion,
  the real one is taken as the commanded motion delayed by the lag estimated from
  ``target_qd`` against ``actual_qd`` (noise-free, and exact for a controller that tracks well);
  otherwise the measured ``actual_q/qd`` with the speed low-pass filtered (zero phase, Butterworth)
  and differentiated for the acceleration (nursing eq 24's filtering);
- samples where the program does not run (``runtime_state`` != 2 or ``robot_mode`` != 7, when the
  log has them) are dropped, and irregular time stamps are resampled to a uniform grid.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.io.log import Log

__all__ = [
    "JOINT_SIGNALS",
    "MAX_LAG",
    "MEASURED_TORQUE",
    "IdentData",
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
    "resample",
    "running",
    "running_range",
    "uniform",
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
    """The samples :func:`running` keeps: the longest run of consecutive samples where a
    program runs (all of them when the log has neither column).

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


def running(log: Log) -> Log:
    """Keep the samples where a program runs (``runtime_state`` 2, ``robot_mode`` 7) when the
    log has those columns (:func:`running_range`); the log unchanged otherwise.

    Raises
    ------
    KinergyError
        No sample is left.
    """
    sl = running_range(log)
    if sl.start == 0 and sl.stop == len(log):
        return log
    return Log(log.path, log.t[sl], {name: x[sl] for name, x in log.signals.items()})


def uniform_grid(t: Array, *, tolerance: float = 0.01) -> tuple[float, int] | None:
    """The uniform grid :func:`uniform` resamples time stamps ``t`` (N,) to, as its period (s)
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


def uniform(log: Log, *, tolerance: float = 0.01) -> Log:
    """Resample an irregularly sampled log to a uniform grid at its median period (linear
    interpolation); a log whose periods are within ``tolerance`` of the median is returned as is."""
    spec = uniform_grid(log.t, tolerance=tolerance)
    if spec is None:
        return log
    dt, size = spec
    return resample(log, log.t[0] + dt * np.arange(size))


def check_cutoff(fs: float, cutoff: float) -> None:
    """Raise unless ``0 < cutoff < fs / 2`` (Hz)."""
    if not 0.0 < cutoff < fs / 2.0:
        raise KinergyError(
            f"filter cutoff must be between 0 and {fs / 2:g} Hz (half of {fs:g} Hz), got {cutoff:g}"
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
    spline: CubicSpline, t: Array, measured: Array, dt: float, *, max_lag: float = MAX_LAG
) -> float:
    """The shift (s) of the commanded speeds ``spline`` that best matches ``measured`` (k, n) at
    the times ``t`` (k,): a grid of whole periods ``dt`` then a golden-section refinement."""

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


def _with_torque(log: Log, n_joints: int, torque: Array) -> Log:
    """``log`` carrying measured torques (N, n) as a signal, so they go through the same sample
    selection and resampling as the log's own signals."""
    torque = np.asarray(torque, dtype=float)
    if torque.shape != (len(log), n_joints):
        raise KinergyError(
            f"{log.path}: measured torques have shape {torque.shape}, expected {(len(log), n_joints)}"
        )
    return Log(log.path, log.t, {**log.signals, "_torque": torque}, log.notes)


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


def _motions(log: Log, cutoff: float) -> tuple[_Motion3, _Motion3, float, str]:
    """The commanded and the real motion of a uniform ``log``, the lag (s) and how the real
    motion was obtained (module docstring): the commanded motion delayed by the lag estimated
    from ``target_qd`` against ``actual_qd``; without a target, the measured motion with the
    speed low-pass filtered (``cutoff`` Hz) and differentiated."""
    t = log.t
    fs = 1.0 / float(t[1] - t[0])
    has_target = "target_q" in log and "target_qd" in log
    has_actual = "actual_q" in log and "actual_qd" in log
    if not (has_target or has_actual):
        log.require("actual_q", "actual_qd", purpose="identification")
    if has_actual:
        check_cutoff(fs, cutoff)
    if has_target:
        commanded = commanded_motion(log)
        lag = estimate_lag(t, commanded[1], log["actual_qd"]) if has_actual else 0.0
        q, qd, qdd = (delay(t, x, lag) for x in commanded)
        return commanded, (q, qd, qdd), lag, "delayed target"
    qd_f = lowpass(log["actual_qd"], fs, cutoff)
    measured = (log["actual_q"], qd_f, np.gradient(qd_f, t, axis=0))
    return measured, measured, 0.0, "filtered actual"


def prepare(
    log: Log,
    n_joints: int,
    *,
    cutoff: float | None = None,
    torque: Array | None = None,
) -> IdentData:
    """Turn a log into :class:`IdentData` (see the module docstring).

    Parameters
    ----------
    log : Log
    n_joints : int
        The robot's joint count, checked against the log.
    cutoff : float, optional
        Low-pass cutoff for measured speeds, Hz; default :func:`default_cutoff`.
    torque : ndarray, optional
        Measured joint torques aligned with the log's samples (arms with torque sensors).

    Raises
    ------
    KinergyError
        No joint motion in the log; a joint count that does not match.
    """
    if torque is not None:
        log = _with_torque(log, n_joints, torque)
    log = uniform(running(log))
    torque = log.signals.pop("_torque", None) if torque is not None else None
    cutoff = default_cutoff(log.t) if cutoff is None else cutoff
    check_joints(log, n_joints)
    commanded, real, lag, source = _motions(log, cutoff)
    return ident_data(log, commanded, real, (lag, source), torque=torque)


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
