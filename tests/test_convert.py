"""``kinergy convert``: a log as a ROS 2 bag and back (kinergy.io.bag_write,
kinergy.workflows.convert). A UR10e log converted to a bag reads back as its CSV bit for bit,
and back to CSV it is the same log again; identification on the bag is identification on the
CSV; an existing output is never replaced."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosbags")

from bags import write_bag as write_test_bag
from clicase import run_case

from kinergy.errors import KinergyError
from kinergy.io.bag_write import bag_joint_names, effort_signal, write_bag
from kinergy.io.formats import iter_log, read_log
from kinergy.io.log import Log
from kinergy.io.rosbag import Effort
from kinergy.model import load_robot
from kinergy.workflows.convert import LogKind, convert_log

DATASETS = Path(__file__).resolve().parents[2] / "shared" / "datasets" / "ur10e-innopolis"
PTP = DATASETS / "validation_data" / "ur-20_01_17-ptp_10_points.csv"
FULL = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"
#: what a bag of the UR10e logs holds: the motion and the currents
ONLY = "timestamp,actual_q:6,actual_qd:6,actual_current:6,_:12"
UR = tuple(load_robot("ur10e").joint_names)
real = pytest.mark.skipif(not PTP.exists(), reason="shared datasets not available")


def _log(samples: int = 300, n: int = 6, seed: int = 3) -> Log:
    """A seeded log: controller time from 1234.5 s at 500 Hz, motion, currents, torques."""
    rng = np.random.default_rng(seed)
    t = 1234.5 + 0.002 * np.arange(samples)
    signals = {
        name: rng.normal(0.0, 1.0, (samples, n))
        for name in ("actual_q", "actual_qd", "actual_current", "actual_joint_torque")
    }
    signals["robot_mode"] = np.where(np.arange(samples) < 100, 5.0, 7.0)
    return Log("seeded", t, signals)


def test_a_log_to_a_bag_and_back_is_the_same_log_bit_for_bit(tmp_path: Path) -> None:
    log = _log()
    written = write_bag(tmp_path / "b", [log], UR)
    assert written.messages == len(log) and written.effort == "actual_current"
    assert written.left_out == ("actual_joint_torque",)
    back = read_log(tmp_path / "b", joints=UR)
    np.testing.assert_allclose(back.t, log.t - log.t[0], rtol=0, atol=1e-12)
    for name in ("actual_q", "actual_qd", "actual_current", "robot_mode"):
        assert np.array_equal(back[name], log[name]), name
    out = convert_log(tmp_path / "b", tmp_path / "b.csv", LogKind.CSV, UR)
    again = read_log(out.path)
    assert np.array_equal(again.t, log.t)  # the stamps as written: the log's own time
    for name in back.signals:
        assert np.array_equal(again[name], log[name]), name


def test_the_effort_is_the_log_s_currents_or_its_torques_as_asked(tmp_path: Path) -> None:
    log = _log()
    write_bag(tmp_path / "t", [log], UR, effort=Effort.TORQUE)
    back = read_log(tmp_path / "t", joints=UR, bag=None)
    # a UR bag's effort is read as currents unless told: the torques are there, by value
    assert np.array_equal(back["actual_current"], log["actual_joint_torque"])
    assert effort_signal(["actual_q", "target_moment"], None, "x") is None
    with pytest.raises(KinergyError, match="--effort torque: the log has no actual_joint_torque"):
        effort_signal(["actual_q", "actual_current"], Effort.TORQUE, "x")
    assert bag_joint_names(UR)[0] == "shoulder_pan_joint"
    assert bag_joint_names(["a", "b"]) == ("a", "b")


def test_chunks_write_one_bag_and_stamps_must_increase(tmp_path: Path) -> None:
    log = _log(500)
    parts = [
        Log(log.path, log.t[a:b], {k: v[a:b] for k, v in log.signals.items()})
        for a, b in ((0, 200), (200, 450), (450, 500))
    ]
    write_bag(tmp_path / "c", parts, UR)
    chunks = list(iter_log(tmp_path / "c", joints=UR, rows=200))
    assert np.array_equal(Log.concatenate(chunks)["actual_q"], log["actual_q"])
    bad = Log("bad", np.array([1.0, 1.0 + 1e-10, 2.0]), {"actual_q": np.zeros((3, 6))})
    with pytest.raises(KinergyError, match=r"bad: time .* is not after the sample before"):
        write_bag(tmp_path / "d", [bad], UR)
    assert not (tmp_path / "d").exists() and not list(tmp_path.glob(".d.*"))  # nothing left


def test_an_existing_output_is_refused_in_one_line_and_kept(tmp_path: Path) -> None:
    log = _log()
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "mine.txt").write_text("keep")
    with pytest.raises(KinergyError, match="exists; kinergy never replaces it"):
        write_bag(tmp_path / "b", [log], UR)
    assert (tmp_path / "b" / "mine.txt").read_text() == "keep"
    write_test_bag(tmp_path / "bag", log.t, log["actual_q"], log["actual_qd"])
    (tmp_path / "x.csv").write_text("mine\n")
    refused = run_case(["convert", "bag", "--to", "csv", "x.csv"], tmp_path, refuse=True)
    assert "x.csv: exists; kinergy never replaces it" in refused.err
    refused = run_case(["convert", "bag", "--to", "bag", "no/such"], tmp_path, refuse=True)
    assert "no such folder" in refused.err


def _run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[str, str]:
    """``kinergy ARGS``, which must succeed: its stdout and stderr."""
    from kinergy.cli import main

    code = main(args)
    out, err = capsys.readouterr()
    assert code == 0, err
    return out, err


@real
def test_the_ur10e_log_to_a_bag_and_back_to_csv_is_the_same_log(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag, back = str(tmp_path / "ptp"), tmp_path / "ptp.csv"
    out, err = _run(
        ["convert", str(PTP), "--to", "bag", bag, "--robot", "ur10e", "--columns", FULL], capsys
    )
    assert "5347 samples of actual_q, actual_qd, actual_current" in out
    assert "target_current, target_moment" in err  # left out, and said
    _run(["convert", bag, "--to", "csv", str(back), "--robot", "ur10e"], capsys)
    csv, again = read_log(PTP, columns=ONLY), read_log(back)
    assert set(again.signals) == set(csv.signals)
    assert np.array_equal(again.t, csv.t)
    for name in csv.signals:
        assert np.array_equal(again[name], csv[name]), name


FOURIER = [
    DATASETS / "identification_data" / f"ur-20_02_{name}.csv"
    for name in ("19_14harm50sec", "12-50sec_12harm")
]


@real
def test_the_bag_recipe_on_converted_ur10e_logs_prints_the_csv_figures(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """docs/recipes.md's ROS 2 bag recipe on bags `kinergy convert` made of the UR10e runs:
    identify, validate and energy print what the CSV logs read with the bag's fields print
    (the paths aside), and the model files hold the same values to round-off (a bag's time
    starts at 0 s, the CSV's at 1141.591 s)."""
    import tomllib

    bags = [str(tmp_path / p.stem) for p in (*FOURIER, PTP)]
    for path, bag in zip((*FOURIER, PTP), bags, strict=True):
        _run(
            ["convert", str(path), "--to", "bag", bag, "--robot", "ur10e", "--columns", FULL],
            capsys,
        )
    printed = {}
    for route, logs, extra in (
        ("csv", [str(p) for p in (*FOURIER, PTP)], ["--columns", ONLY]),
        ("bag", bags, []),
    ):
        model = str(tmp_path / f"{route}.toml")
        steps = [
            ["identify", *logs[:2], "--robot", "ur10e", "--out", model],
            ["validate", model, logs[2]],
            ["energy", model, logs[2]],
        ]
        printed[route] = [
            line
            for step in steps
            for line in _run([*step, *extra], capsys)[0].splitlines()
            if str(tmp_path) not in line and str(DATASETS) not in line
        ]
    assert printed["bag"] == printed["csv"]
    assert sum("R²" in line for line in printed["bag"]) >= 2
    values = {r: tomllib.loads((tmp_path / f"{r}.toml").read_text()) for r in printed}
    errors = {r: v.pop("uncertainty", {}) for r, v in values.items()}
    for v in values.values():
        v.pop("identified")
    assert _numbers(values["bag"]) == pytest.approx(_numbers(values["csv"]), rel=1e-9, abs=1e-15)
    # the parameter errors' modes (a jackknife over time blocks: differences of nearly equal
    # fits) carry the bag's nanosecond stamps' round-off up to about 1e-5 relative
    assert _numbers(errors["bag"]) == pytest.approx(_numbers(errors["csv"]), rel=1e-4, abs=1e-9)


def _numbers(value: object) -> list[float]:
    """The numbers of nested TOML data, in order (other leaves as 0)."""
    if isinstance(value, dict):
        return [x for v in value.values() for x in _numbers(v)]
    if isinstance(value, list):
        return [x for v in value for x in _numbers(v)]
    return [float(value) if isinstance(value, int | float) else 0.0]


@real
def test_a_window_on_a_converted_bag_is_the_window_on_the_csv(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--from/--to on a bag: seconds from its first stamp (the CSV's 1141.591 s): the energy of
    a window of the bag is the energy of the same window of the CSV."""
    bag = str(tmp_path / "ptp")
    _run(["convert", str(PTP), "--to", "bag", bag, "--robot", "ur10e", "--columns", FULL], capsys)
    start = float(read_log(PTP, columns=ONLY).t[0])
    bag_json = _run(["energy", "ur10e", bag, "--from", "10", "--to", "20", "--json"], capsys)[0]
    window = ["--from", repr(start + 10.0), "--to", repr(start + 20.0)]
    csv_json = _run(["energy", "ur10e", str(PTP), "--columns", ONLY, *window, "--json"], capsys)[0]
    import json

    bag_out, csv_out = json.loads(bag_json), json.loads(csv_json)
    assert bag_out["samples"] == csv_out["samples"] and 900 < bag_out["samples"] < 1100
    assert bag_out["total"]["e_elec"] == pytest.approx(csv_out["total"]["e_elec"], rel=1e-9)
