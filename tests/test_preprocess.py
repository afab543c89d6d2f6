"""Preprocessing checked against known truth: program-run selection, resampling of irregular
time stamps, the zero-phase low-pass, the lag estimate and `prepare` on digital-twin logs whose
noise-free real motion is known."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import CubicSpline
from scipy.signal import butter, find_peaks, sosfreqz

import kinergy
from kinergy.errors import KinergyError
from kinergy.io.log import Log
from kinergy.logs.filtering import lowpass
from kinergy.logs.lag import estimate_lag
from kinergy.logs.prepare import prepare
from kinergy.logs.samples import resample, running_range, running_runs, uniform_grid
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import TwinSettings, simulate

DT = 0.002  # the twin's (and a UR controller's) 500 Hz


def _log(t: np.ndarray, **signals: np.ndarray) -> Log:
    return Log("mem.csv", np.asarray(t, dtype=float), signals)


def running(log: Log) -> Log:
    """The samples the preparation keeps (:func:`running_range`)."""
    sl = running_range(log)
    return Log(log.path, log.t[sl], {k: v[sl] for k, v in log.signals.items()})


def uniform(log: Log) -> Log:
    """``log`` on the grid the preparation resamples it to (:func:`uniform_grid`)."""
    spec = uniform_grid(log.t)
    return log if spec is None else resample(log, log.t[0] + spec[0] * np.arange(spec[1]))


# --- running ------------------------------------------------------------------------------------


def _modes(states: list[tuple[int, int, int]]) -> tuple[np.ndarray, np.ndarray]:
    """(safety_mode, robot_mode, count) blocks -> per-sample arrays."""
    sm = np.concatenate([np.full(n, float(r)) for r, _, n in states])
    rm = np.concatenate([np.full(n, float(m)) for _, m, n in states])
    return sm, rm


def test_running_keeps_the_block_where_the_robot_runs() -> None:
    # robot_mode 5 (idle: brakes on) around 7 (running)
    sm, rm = _modes([(1, 5, 30), (1, 7, 50), (1, 5, 20)])
    t = np.arange(sm.size) * DT
    q = np.random.default_rng(0).normal(size=(sm.size, 6))
    out = running(_log(t, actual_q=q, safety_mode=sm, robot_mode=rm))
    np.testing.assert_array_equal(out.t, t[30:80])
    np.testing.assert_array_equal(out["actual_q"], q[30:80])
    np.testing.assert_array_equal(out["robot_mode"], np.full(50, 7.0))
    assert out.path == "mem.csv"


def test_a_stopped_or_paused_program_leaves_no_sample_out() -> None:
    # runtime_state 1 (stopped) and 4 (paused) with the robot running: the arm holds still
    # under control, its torques valid (the ur3e-rad log stops between its moves)
    rs = np.concatenate([np.full(30, 1.0), np.full(50, 2.0), np.full(20, 4.0)])
    log = _log(np.arange(rs.size) * DT, runtime_state=rs, robot_mode=np.full(rs.size, 7.0))
    assert running_range(log) == slice(0, rs.size)
    assert running_runs(log) == [(0, rs.size)]


def test_running_keeps_the_longest_block() -> None:
    # running in three blocks; the middle one is cut in two by a protective stop (safety mode
    # 3), which leaves the last block (40 samples) the longest
    sm, rm = _modes(
        [(1, 7, 25), (1, 5, 5), (2, 7, 30), (3, 7, 3), (1, 7, 30), (1, 4, 4), (1, 7, 40), (1, 5, 2)]
    )
    t = np.arange(sm.size) * DT
    x = np.arange(sm.size, dtype=float)
    log = _log(t, x=x, safety_mode=sm, robot_mode=rm)
    out = running(log)
    start = 25 + 5 + 30 + 3 + 30 + 4
    np.testing.assert_array_equal(out.t, t[start : start + 40])
    np.testing.assert_array_equal(out["x"], x[start : start + 40])
    assert running_runs(log) == [(0, 25), (30, 60), (63, 93), (97, 137)]


@settings(max_examples=80, deadline=None)
@given(
    safe=st.lists(st.booleans(), min_size=2, max_size=60),
    mode_ok=st.lists(st.booleans(), min_size=60, max_size=60),
)
def test_running_keeps_a_longest_maximal_run(safe: list[bool], mode_ok: list[bool]) -> None:
    ok = np.array(safe) & np.array(mode_ok[: len(safe)])
    sm = np.where(safe, 2.0, 3.0)
    rm = np.where(mode_ok[: len(safe)], 7.0, 5.0)
    idx = np.arange(len(safe), dtype=float)
    t = idx * DT
    log = _log(t, idx=idx, safety_mode=sm, robot_mode=rm)
    if not ok.any():
        with pytest.raises(KinergyError, match="no sample where the robot runs"):
            running(log)
        return
    out = running(log)
    longest = max(len(list(g)) for v, g in itertools.groupby(ok) if v)
    kept = out["idx"].astype(int)
    assert kept.size == longest
    np.testing.assert_array_equal(np.diff(kept), 1)  # consecutive samples
    assert ok[kept].all()  # all of them running
    np.testing.assert_array_equal(out.t, t[kept])
    runs = running_runs(log)  # every run, maximal and in order
    assert sum(b - a for a, b in runs) == int(ok.sum())
    assert all(ok[a:b].all() for a, b in runs)


def test_running_raises_when_the_robot_never_runs() -> None:
    # running only while the safety system stops it, and safe only while not running
    sm, rm = _modes([(3, 7, 20), (1, 5, 20)])
    log = _log(np.arange(40) * DT, safety_mode=sm, robot_mode=rm)
    with pytest.raises(KinergyError, match=r"^mem\.csv: no sample where the robot runs"):
        running(log)


def test_running_without_mode_columns_is_the_identity() -> None:
    log = _log(np.arange(10) * DT, x=np.ones(10))
    assert running_range(log) == slice(0, 10)


# --- uniform ------------------------------------------------------------------------------------

FREQ = np.array([0.5, 2.0, 3.0])  # Hz
PHASE = np.array([0.0, 1.0, 2.0])


def _sines(t: np.ndarray) -> np.ndarray:
    return np.sin(2 * np.pi * FREQ * t[:, None] + PHASE)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_uniform_resamples_an_irregular_log_to_its_median_period(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = 3000
    t = (np.arange(n) + rng.uniform(-0.3, 0.3, n)) * DT  # jitter of +-30 % of a period
    keep = rng.random(n) > 0.1  # and 10 % of the samples dropped
    keep[[0, -1]] = True
    t = t[keep]
    scalar = np.cos(2 * np.pi * 1.5 * t)
    out = uniform(_log(t, x=_sines(t), s=scalar))

    period = float(np.median(np.diff(t)))
    np.testing.assert_allclose(np.diff(out.t), period, rtol=1e-9)
    assert out.t[0] == t[0] and t[-1] - period < out.t[-1] <= t[-1]
    assert len(out) == int(np.floor((t[-1] - t[0]) / period)) + 1
    # linear interpolation of f over a gap h errs by at most h^2/8 max|f''| (the classic bound);
    # for a sine of amplitude 1, max|f''| = (2 pi f)^2
    h = float(np.max(np.diff(t)))
    bound = h**2 / 8 * (2 * np.pi * FREQ) ** 2
    err = np.max(np.abs(out["x"] - _sines(out.t)), axis=0)
    assert np.all(err <= bound * 1.001 + 1e-12), (err, bound)
    s_bound = h**2 / 8 * (2 * np.pi * 1.5) ** 2
    assert np.max(np.abs(out["s"] - np.cos(2 * np.pi * 1.5 * out.t))) <= s_bound * 1.001
    assert out["x"].shape == (len(out), 3) and out["s"].shape == (len(out),)


@pytest.mark.parametrize("jitter", [0.0, 0.005])  # within the 1 % tolerance
def test_uniform_leaves_a_regular_log_alone(jitter: float) -> None:
    rng = np.random.default_rng(3)
    t = (np.arange(500) + rng.uniform(-jitter / 2, jitter / 2, 500)) * DT
    x = _sines(t)
    log = _log(t, x=x)
    out = uniform(log)
    assert out is log or (
        np.array_equal(out.t, t) and np.array_equal(out["x"], x) and set(out.signals) == {"x"}
    )


# --- lowpass ------------------------------------------------------------------------------------

FS = 500.0
T_LP = np.arange(5000) / FS  # 10 s
EDGE = 250  # 0.5 s: a 10 Hz 4th-order Butterworth settles well within it


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def test_lowpass_stops_40_hz_and_passes_1_hz_without_phase() -> None:
    high = np.sin(2 * np.pi * 40 * T_LP)
    low = np.sin(2 * np.pi * 1 * T_LP + 0.3)
    out = lowpass(np.column_stack([high, low]), FS, 10.0)
    assert out.shape == (T_LP.size, 2)
    mid = slice(EDGE, -EDGE)
    attenuation = 20 * np.log10(_rms(out[mid, 0]) / _rms(high[mid]))
    assert attenuation < -40.0, attenuation
    # pass band: amplitude within 1 %
    assert np.max(np.abs(out[mid, 1] - low[mid])) < 0.01
    # zero phase: same peaks, sample for sample (a causal filter of this order lags ~20 samples)
    peaks_in = find_peaks(low[mid])[0]
    peaks_out = find_peaks(out[mid, 1])[0]
    assert peaks_in.size == 9
    np.testing.assert_array_equal(peaks_out, peaks_in)
    # and the fitted phase agrees to a millidegree-scale
    basis = np.column_stack([np.sin(2 * np.pi * T_LP[mid]), np.cos(2 * np.pi * T_LP[mid])])
    a_in = np.linalg.lstsq(basis, low[mid], rcond=None)[0]
    a_out = np.linalg.lstsq(basis, out[mid, 1], rcond=None)[0]
    assert abs(np.arctan2(a_out[1], a_out[0]) - np.arctan2(a_in[1], a_in[0])) < 1e-4


def test_lowpass_passes_1_hz_within_1_percent_up_to_the_ends() -> None:
    low = np.sin(2 * np.pi * 1 * T_LP + 0.3)
    out = lowpass(low, FS, 10.0)
    assert np.max(np.abs(out - low)) < 0.01


@pytest.mark.parametrize("cutoff", [250.0, 300.0, 0.0, -5.0, float("nan")])
def test_lowpass_rejects_a_cutoff_outside_the_band(cutoff: float) -> None:
    with pytest.raises(KinergyError, match="cutoff must be between 0 and 250 Hz"):
        lowpass(np.zeros((100, 2)), FS, cutoff)


# --- the twin -----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def motion_a(ur5e: kinergy.Robot) -> Motion:
    return paper_trajectory(ur5e, "test-a")


def _exact(lag: float) -> TwinSettings:
    return TwinSettings(lag=lag, speed_noise=0.0, position_noise=0.0, current_noise=0.0)


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("lag", [0.0, 0.002, 0.004, 0.007])
def test_estimate_lag_finds_the_twins_lag(
    ur5e: kinergy.Robot, motion_a: Motion, lag: float, seed: int
) -> None:
    s = _signals(simulate(ur5e, motion_a, TwinSettings(lag=lag, speed_noise=0.01, seed=seed)))
    estimate = estimate_lag(s["timestamp"], s["target_qd"], s["actual_qd"])
    assert abs(estimate - lag) < 3e-4, (estimate, lag)


def _signals(log: Log) -> dict[str, np.ndarray]:
    """The twin's log as one mapping with its ``timestamp``."""
    return {"timestamp": log.t, **log.signals}


def _twin_log(signals: dict[str, np.ndarray], names: tuple[str, ...] | None = None) -> Log:
    keep = {k: v for k, v in signals.items() if k != "timestamp" and (names is None or k in names)}
    return Log("twin.csv", signals["timestamp"], keep)


def _max_slope(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Per column, max |d/dt| of the cubic spline through x (sampled 8 times per interval)."""
    fine = np.linspace(t[0], t[-1], 8 * (t.size - 1) + 1)
    return np.max(np.abs(CubicSpline(t, x, axis=0)(fine, 1)), axis=0)


def _held_delay(t: np.ndarray, x: np.ndarray, lag: float) -> np.ndarray:
    """x(t - lag) by cubic spline, held at x[0] before the start (the twin's definition)."""
    return CubicSpline(t, x, axis=0)(np.clip(t - lag, t[0], t[-1]))


def _steady(qdd: np.ndarray, margin: int) -> np.ndarray:
    """Samples whose acceleration is constant for `margin` samples either side (no corner)."""
    n = qdd.shape[0]
    out = np.zeros(qdd.shape, dtype=bool)
    out[margin : n - margin] = True
    for k in range(1, margin + 1):
        out[margin : n - margin] &= qdd[margin - k : n - margin - k] == qdd[margin : n - margin]
        out[margin : n - margin] &= qdd[margin + k : n - margin + k] == qdd[margin : n - margin]
    return out


@pytest.mark.parametrize("lag", [0.004, 0.007])
def test_prepare_delays_the_target_by_the_estimated_lag(
    ur5e: kinergy.Robot, motion_a: Motion, lag: float
) -> None:
    s = _signals(simulate(ur5e, motion_a, TwinSettings(lag=lag, speed_noise=0.01, seed=5)))
    truth = simulate(ur5e, motion_a, _exact(lag))  # the same real motion, without noise
    d = prepare(_twin_log(s), ur5e.n)
    t = s["timestamp"]

    assert d.source == "delayed target"
    assert abs(d.lag - lag) < 3e-4
    np.testing.assert_array_equal(d.t, t)
    np.testing.assert_array_equal(d.q_cmd, s["target_q"])
    np.testing.assert_array_equal(d.qd_cmd, s["target_qd"])
    np.testing.assert_array_equal(d.qdd_cmd, s["target_qdd"])
    assert d.tau_ref is not None and d.current is not None and d.torque is None
    np.testing.assert_array_equal(d.tau_ref, s["target_moment"])
    np.testing.assert_array_equal(d.current, s["actual_current"])

    # The real motion is the target's spline shifted by the true lag, prepare shifts it by the
    # estimate: by the mean value theorem they differ by at most max|spline'| * |estimate - lag|
    # (+5 % for sampling the spline's slope on a grid, +1e-9 for rounding).
    miss = abs(d.lag - lag)
    for got, true, cmd in (
        (d.q, truth["actual_q"], s["target_q"]),
        (d.qd, truth["actual_qd"], s["target_qd"]),
        (d.qdd, _held_delay(t, s["target_qdd"], lag), s["target_qdd"]),
    ):
        bound = 1.05 * _max_slope(t, cmd) * miss + 1e-9
        assert np.all(np.max(np.abs(got - true), axis=0) <= bound)
    # away from the trapezoid's corners the real acceleration is the target's, exactly: the
    # spline's ringing from a step decays by 2 - sqrt(3) per sample, 10 samples leave < 1e-4
    shift = round(lag / DT)
    true_qdd = np.vstack([np.repeat(s["target_qdd"][:1], shift, axis=0), s["target_qdd"]])[: t.size]
    steady = _steady(true_qdd, 10)
    assert steady.mean() > 0.8
    assert np.max(np.abs(d.qdd - true_qdd)[steady]) < 1e-4


def _filtered_noise_std(sigma: float, fs: float, cutoff: float, derivative: bool) -> float:
    """Std of white noise (std sigma, sampled at fs) after the zero-phase 4th-order Butterworth
    (|H|^4: the filter is run forward and back) and, if asked, np.gradient's central difference
    (gain sin(w dt)/dt)."""
    sos = butter(4, cutoff / (fs / 2), output="sos")
    f = np.linspace(0.0, fs / 2, 100_001)
    gain = np.abs(sosfreqz(sos, worN=f, fs=fs)[1]) ** 4
    if derivative:
        gain = gain * (np.sin(2 * np.pi * f / fs) * fs) ** 2
    return float(sigma * np.sqrt(np.mean(gain)))  # white noise: variance spread evenly to fs/2


@pytest.mark.parametrize("seed", [0, 1])
def test_prepare_filters_the_measured_motion_without_a_target(
    ur5e: kinergy.Robot, motion_a: Motion, seed: int
) -> None:
    lag, noise = 0.004, 0.01
    s = _signals(simulate(ur5e, motion_a, TwinSettings(lag=lag, speed_noise=noise, seed=seed)))
    truth = _signals(simulate(ur5e, motion_a, _exact(lag)))
    d = prepare(_twin_log(s, ("actual_q", "actual_qd", "actual_current")), ur5e.n)

    assert d.source == "filtered actual" and d.lag == 0.0
    assert d.tau_ref is None
    np.testing.assert_array_equal(d.q, s["actual_q"])
    np.testing.assert_array_equal(d.current, s["actual_current"])

    # the injected noise really is there, and the filter removes most of it
    raw = _rms(s["actual_qd"] - truth["actual_qd"])
    assert 0.95 * noise < raw < 1.05 * noise
    assert _rms(d.qd - truth["actual_qd"]) < 0.5 * noise  # corners included

    # away from the corners (0.1 s, the filter's settling time) only filtered noise is left:
    # theory (default cutoff 10 Hz at 500 Hz) gives 0.19 noise for the speed and 0.065 rad/s^2
    # for the acceleration; 30 % margin covers the RMS estimate's spread and corner leftovers
    shift = round(lag / DT)
    true_qdd = np.vstack([np.repeat(motion_a.qdd[:1], shift, axis=0), motion_a.qdd])[: d.t.size]
    steady = _steady(true_qdd, 50)
    assert steady.mean() > 0.5
    qd_std = _filtered_noise_std(noise, 1 / DT, 10.0, derivative=False)
    qdd_std = _filtered_noise_std(noise, 1 / DT, 10.0, derivative=True)
    assert qd_std < 0.25 * noise
    assert _rms((d.qd - truth["actual_qd"])[steady]) < 1.3 * qd_std
    qdd_err = (d.qdd - true_qdd)[steady]
    assert _rms(qdd_err) < 1.3 * qdd_std
    assert np.max(np.abs(qdd_err)) < 8 * qdd_std  # < 0.6 rad/s^2 against peaks of 6


# --- joint counts -------------------------------------------------------------------------------


def _random_log(widths: dict[str, int], n: int = 200) -> Log:
    rng = np.random.default_rng(7)
    return _log(np.arange(n) * DT, **{k: rng.normal(size=(n, w)) for k, w in widths.items()})


@pytest.mark.parametrize(
    "widths",
    [
        {"actual_q": 5, "actual_qd": 5},
        {"target_q": 5, "target_qd": 5, "target_qdd": 5},
        {"target_q": 5, "target_qd": 5, "actual_q": 5, "actual_qd": 5, "target_moment": 5},
    ],
)
def test_prepare_rejects_a_five_joint_log_for_a_six_joint_robot(widths: dict[str, int]) -> None:
    with pytest.raises(KinergyError, match=r"^mem\.csv: \w+ has 5 joints but the robot has 6$"):
        prepare(_random_log(widths), 6)


@pytest.mark.parametrize(
    "widths",
    [
        {"actual_q": 6, "actual_qd": 5},
        {"target_q": 6, "target_qd": 5},
        {"target_q": 6, "target_qd": 6, "target_qdd": 5},
        {"target_q": 6, "target_qd": 6, "actual_q": 6, "actual_qd": 5},
    ],
)
def test_prepare_rejects_a_five_joint_speed_or_acceleration(widths: dict[str, int]) -> None:
    with pytest.raises(KinergyError, match="has 5 joints but the robot has 6"):
        prepare(_random_log(widths), 6)


def test_prepare_cuts_measured_torques_with_the_log() -> None:
    log = _random_log({"actual_q": 6, "actual_qd": 6})
    state = np.r_[np.full(50, 5.0), np.full(150, 7.0)]  # idle, then running
    log = _log(log.t, robot_mode=state, **log.signals)
    torque = np.random.default_rng(8).normal(size=(200, 6))
    d = prepare(_log(log.t, actual_joint_torque=torque, **log.signals), 6)
    assert d.torque is not None
    np.testing.assert_array_equal(d.torque, torque[50:])
