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
