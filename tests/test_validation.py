"""``validate`` per log and pooled, moving and holding apart; joints that hardly moved."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import kinergy
from kinergy.identification.options import IdentifyOptions, Method
from kinergy.identification.validation import (
    HOLD_SECONDS,
    SignalMetrics,
    _signal_metrics,
    holding_mask,
    validation_report,
)
from kinergy.io.columns import parse_columns
from kinergy.logs.reading import LogReading
from kinergy.workflows.logs import prepared_logs

DATASETS = Path(__file__).resolve().parents[2] / "shared" / "datasets" / "ur10e-innopolis"
UR10E_COLUMNS = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"


def _reading(spec: str = UR10E_COLUMNS) -> LogReading:
    return LogReading(columns=tuple(parse_columns(spec, 6)))


def test_holding_mask_keeps_only_long_holds() -> None:
    t = np.arange(0.0, 3.0, 0.01)
    qd = np.full((t.size, 2), 0.5)
    qd[50:150] = 0.0  # a 1 s hold
    qd[200:220] = 0.0  # a 0.2 s pause: motion
    qd[250:300, 0] = 0.0  # one joint still, the other moving: motion
    mask = holding_mask(t, qd)
    assert mask[50:150].all() and mask.sum() == 100
    assert HOLD_SECONDS > 0.2


def test_a_joint_that_did_not_move_is_not_excited_never_a_bare_nan() -> None:
    rng = np.random.default_rng(0)
    q = np.column_stack([np.linspace(0, 1, 200), np.full(200, 0.3)])
    measured = rng.normal(size=(200, 2))
    metrics = _signal_metrics(measured, measured + 0.1, q)
    assert metrics[0].note is None and metrics[0].r2 > 0.9
    assert metrics[1].note == "not excited" and math.isnan(metrics[1].r2)
    assert metrics[0].nrms == pytest.approx(0.1 / np.sqrt(np.mean(measured[:, 0] ** 2)))


@pytest.mark.skipif(not DATASETS.exists(), reason="shared datasets not available")
def test_real_program_with_holds_is_reported_per_log_and_segment() -> None:
    robot = kinergy.load_robot("ur10e")
    paths = [
        DATASETS / "validation_data" / "ur-20_01_17-ptp_10_points.csv",
        DATASETS / "validation_data" / "ur-20_01_17-p1.csv",
    ]
    datas, _ = prepared_logs(paths, robot, _reading())
    report = validation_report(robot, datas)
    assert [Path(log.log).name for log in report.logs] == [p.name for p in paths]
    assert report.samples == sum(log.samples for log in report.logs)
    assert 0.2 < report.logs[0].holding_fraction < 0.5  # ptp: moves, holds at ten points
    assert report.logs[1].holding_fraction > 0.9 and report.logs[1].moving is None
    assert report.moving is not None and report.holding is not None
    for part in (report, report.moving, report.holding, *report.logs):
        for metrics in (part.torque, part.current):
            assert metrics is not None
            for m in metrics:
                assert isinstance(m, SignalMetrics)
                assert np.isfinite(m.r2) or m.note, "a bare nan"
                assert np.isfinite(m.rms) and m.rms >= 0


@pytest.mark.skipif(not DATASETS.exists(), reason="shared datasets not available")
def test_a_log_shorter_than_a_second_is_refused_and_nothing_written(tmp_path: Path) -> None:
    from kinergy.errors import KinergyError
    from kinergy.workflows.identify import identify_model

    fourier = DATASETS / "identification_data" / "ur-20_02_12-50sec_12harm.csv"
    short = tmp_path / "short.csv"
    short.write_text("".join(fourier.read_text().splitlines(keepends=True)[1000:1080]))
    datas, _ = prepared_logs([short], kinergy.load_robot("ur10e"), _reading())
    with pytest.raises(KinergyError, match=r"span 0\.\d+ s: identification needs at least 1 s"):
        identify_model(kinergy.load_robot("ur10e"), datas, IdentifyOptions(method=Method.FULL))


@pytest.mark.skipif(not DATASETS.exists(), reason="shared datasets not available")
def test_a_corrupted_log_is_refused_in_one_line() -> None:
    from kinergy.errors import KinergyError

    corrupted = DATASETS / "identification_data" / "ur-19_09_27-11_32_02.csv"  # speeds of 1e293
    spec = "timestamp,actual_q:6,actual_qd:6,actual_current:6"
    with pytest.raises(
        KinergyError, match=r"holds 1(\.\d+)?e\+30\d: not a value a robot logs in any unit"
    ):
        prepared_logs([corrupted], kinergy.load_robot("ur10e"), _reading(spec))


@pytest.mark.skipif(not DATASETS.exists(), reason="shared datasets not available")
def test_a_static_log_is_refused_by_every_method(tmp_path: Path) -> None:
    from kinergy.errors import KinergyError
    from kinergy.workflows.identify import identify_logs

    static = DATASETS / "validation_data" / "ur-20_01_17-p1.csv"  # holds only
    for method in Method:
        out = tmp_path / f"{method}.toml"
        with pytest.raises(KinergyError, match="no joint moves in these logs"):
            identify_logs(
                kinergy.load_robot("ur10e"),
                [static],
                out,
                reading=_reading(),
                options=IdentifyOptions(method=method),
            )
        assert not out.exists()


def _holds_reference(t: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """The holding samples found sample by sample: the still run each sample belongs to, its
    duration (first to last time stamp) at least HOLD_SECONDS."""
    from kinergy.identification.validation import HOLD_SPEED

    still = [bool(np.all(np.abs(row) < HOLD_SPEED)) for row in qd]
    out = np.zeros(len(still), dtype=bool)
    for i, s in enumerate(still):
        if not s:
            continue
        a = i
        while a > 0 and still[a - 1]:
            a -= 1
        b = i
        while b + 1 < len(still) and still[b + 1]:
            b += 1
        out[i] = t[b] - t[a] >= HOLD_SECONDS
    return out


def test_holds_found_chunk_by_chunk_are_the_whole_logs() -> None:
    from kinergy.identification.validation import _Holds, _Rows

    rng = np.random.default_rng(11)
    t = np.cumsum(rng.uniform(0.008, 0.012, 3000))
    qd = rng.uniform(0.1, 1.0, (t.size, 2))
    at = 0
    while at < t.size:  # still runs about as long as a hold, some shorter, some much longer
        length = int(rng.choice([5, 40, 49, 50, 51, 60, 400]))
        qd[at : at + length] = 0.0
        at += length + int(rng.integers(1, 80))
    want = _holds_reference(t, qd)
    assert 0.2 < want.mean() < 0.9 and not np.array_equal(want, np.all(qd == 0.0, axis=1))
    assert np.array_equal(holding_mask(t, qd), want)
    for sizes in ([1], [7], [997], [1, 3, 50, 2, 700]):
        holds, got, start, k = _Holds(), [], 0, 0
        while start < t.size:
            stop = min(start + sizes[k % len(sizes)], t.size)
            rows = _Rows(t[start:stop], qd[start:stop], qd[start:stop], {})
            decided, mask = holds.feed(rows)
            assert decided.t.size == mask.size
            got.append(mask)
            start, k = stop, k + 1
        if holds.waiting is not None:
            got.append(np.zeros(holds.waiting.t.size, dtype=bool))
        assert np.array_equal(np.concatenate(got), want), sizes


def _figures(report: object) -> list[float]:
    """Every number of a validation and of its parts, in order."""
    out: list[float] = []
    for part in (report, report.moving, report.holding):  # type: ignore[attr-defined]
        if part is None:
            out.append(-1.0)
            continue
        for key in ("torque", "current", "joint_torque"):
            for m in getattr(part, key) or ():
                out += [m.mean, m.max, m.rms, m.r2, getattr(m, "nrms", 0.0)]
    return out


def _assert_same_report(got: object, want: object) -> None:
    """Equal samples, holds and notes; every figure to round-off of the sums' order."""
    for a, b in zip([got, *got.logs], [want, *want.logs], strict=True):  # type: ignore[attr-defined]
        assert a.samples == b.samples and a.holding_fraction == b.holding_fraction
        assert (a.moving is None) == (b.moving is None)
        assert (a.holding is None) == (b.holding is None)
        for x, y in ((a, b), (a.moving, b.moving), (a.holding, b.holding)):
            if x is None:
                continue
            for key in ("torque", "current"):
                assert [m.note for m in getattr(x, key)] == [m.note for m in getattr(y, key)]
        np.testing.assert_allclose(_figures(a), _figures(b), rtol=1e-9, atol=1e-12)


def _log_with_holds(path: Path) -> Path:
    """A realistic twin log of test A at 125 Hz held still for 1 s at each end, twice with a
    gap (two segments), on an arm whose friction is held through standstill."""
    from kinergy.io.rtde import write_log
    from kinergy.trajectory.programs import pad_rest, paper_trajectory
    from kinergy.twin import TwinSettings, realistic_truth, simulate

    robot = kinergy.load_robot("ur5e")
    motion = pad_rest(paper_trajectory(robot, "test-a", dt=0.008, rest=0.0), 1.0, 0.008)
    twin = simulate(realistic_truth(robot, seed=3), motion, TwinSettings.realistic(seed=3))
    t = np.concatenate([twin.t, twin.t + twin.t[-1] + 60.0])
    write_log(path, t, {k: np.concatenate([v, v]) for k, v in twin.signals.items()})
    return path


def _held(robot: kinergy.Robot) -> kinergy.Robot:
    """``robot`` with friction held through standstill below 0.5 rad/s at the motors."""
    import dataclasses

    def held(j: kinergy.model.robot.Joint) -> kinergy.model.robot.Joint:
        friction = j.drive.friction
        friction = dataclasses.replace(friction, params={**friction.params, "standstill": 0.5})
        return dataclasses.replace(j, drive=dataclasses.replace(j.drive, friction=friction))

    return dataclasses.replace(robot, joints=tuple(held(j) for j in robot.joints))


def test_validation_does_not_depend_on_the_chunks(tmp_path: Path) -> None:
    from kinergy.workflows.logs import chunked_logs

    robot = _held(kinergy.load_robot("ur5e"))
    path = _log_with_holds(tmp_path / "holds.csv")
    datas, _ = prepared_logs([path], robot, LogReading())
    whole = validation_report(robot, datas)
    assert len(whole.logs) == 2 and 0.1 < whole.holding_fraction < 0.5
    for rows in (1, 997):
        with chunked_logs([path], robot, LogReading()) as (segments, _):
            _assert_same_report(validation_report(robot, segments, rows=rows), whole)


@pytest.mark.skipif(not DATASETS.exists(), reason="shared datasets not available")
def test_a_real_program_with_holds_validates_the_same_in_chunks() -> None:
    from kinergy.workflows.logs import chunked_logs

    robot = kinergy.load_robot("ur10e")
    paths = [
        DATASETS / "validation_data" / "ur-20_01_17-ptp_10_points.csv",
        DATASETS / "validation_data" / "ur-20_01_17-p1.csv",
    ]
    whole = validation_report(robot, prepared_logs(paths, robot, _reading())[0])
    for rows in (1, 7, 997):
        with chunked_logs(paths, robot, _reading()) as (segments, _):
            _assert_same_report(validation_report(robot, segments, rows=rows), whole)


def test_plots_of_a_long_log_show_every_kth_sample_and_say_so(tmp_path: Path) -> None:
    from kinergy.workflows import validate

    robot = kinergy.load_robot("ur5e")
    path = _log_with_holds(tmp_path / "holds.csv")
    full = validate.validate_logs(robot, [path], plots=tmp_path / "all")
    few = validation_report(robot, prepared_logs([path], robot, LogReading())[0], plot_samples=500)
    series = few.logs[0].series["current"]
    first = full.logs[0].series["current"]
    assert first.step == 1 and first.t.size == full.logs[0].samples
    assert series.step == -(-few.logs[0].samples // 500) and series.t.size <= 500
    np.testing.assert_array_equal(series.measured, first.measured[:: series.step])
    np.testing.assert_array_equal(series.t, first.t[:: series.step])
    assert not any("plots show" in n for n in full.notes)
    assert {p.name for p in (tmp_path / "all").iterdir()} - {".kinergy-output"} == {
        "holds#0_torque.png",
        "holds#0_current.png",
        "holds#1_torque.png",
        "holds#1_current.png",
        "torque_errors.png",
        "current_errors.png",
    }
    validate.PLOT_SAMPLES, old = 500, validate.PLOT_SAMPLES
    try:
        cut = validate.validate_logs(robot, [path], plots=tmp_path / "cut")
    finally:
        validate.PLOT_SAMPLES = old
    assert any(
        n.endswith("(the figures use every sample)") and "one sample in" in n for n in cut.notes
    )
    np.testing.assert_array_equal(_figures(cut), _figures(full))
