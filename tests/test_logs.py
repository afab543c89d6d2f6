"""Reading and writing controller logs: record.py layout, headerless files, and one clear line for
every kind of malformed input."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from kinergy.cli import main
from kinergy.errors import KinergyError
from kinergy.io.rtde import parse_columns, read_log, write_log

DATASETS = Path(__file__).resolve().parents[2] / "shared" / "datasets"


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def test_write_then_read_round_trip(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    t = np.arange(100) * 0.002
    sig = {"actual_q": rng.normal(size=(100, 6)), "robot_mode": np.full(100, 7.0)}
    write_log(tmp_path / "x.csv", t, sig)
    log = read_log(tmp_path / "x.csv")
    np.testing.assert_allclose(log.t, t)
    np.testing.assert_allclose(log["actual_q"], sig["actual_q"], rtol=1e-9)
    assert log["robot_mode"].shape == (100,)


def test_comma_separated_with_header(tmp_path: Path) -> None:
    p = _write(tmp_path / "c.csv", "timestamp,actual_q_0,actual_q_1\n0.0,1,2\n0.1,3,4\n")
    log = read_log(p)
    np.testing.assert_array_equal(log["actual_q"], [[1, 2], [3, 4]])


def test_headerless_with_columns_and_trailing_delimiter(tmp_path: Path) -> None:
    p = _write(tmp_path / "h.csv", "0.0,1,2,5,\n0.1,3,4,6,\n")
    log = read_log(p, columns="timestamp,actual_q:2,actual_current:1")
    np.testing.assert_array_equal(log["actual_q"], [[1, 2], [3, 4]])
    np.testing.assert_array_equal(log["actual_current"], [[5], [6]])


@pytest.mark.parametrize(
    ("text", "columns", "message"),
    [
        ("0.0 1 2\n0.1 3 4\n", None, "no header line.*--columns"),
        (
            "timestamp actual_q_0 actual_q_1\n0.0 1 2\n0.1 3 x\n",
            None,
            r"line 3, column 3 \(actual_q_1\): not a finite number: 'x'",
        ),
        (
            "timestamp actual_q_0 actual_q_1\n0.0 1 2\n0.1 3 nan\n",
            None,
            r"line 3, column 3 \(actual_q_1\): not a finite number",
        ),
        (
            "timestamp,actual_q_0,actual_q_1\n0.0,1,2\n0.1,3\n",
            None,
            r"line 3, column 3 \(actual_q_1\): missing value \(truncated line\?\)",
        ),
        ("timestamp actual_q_0\n0.0 1\n0.1 2\n0.1 3\n", None, r"line 4: timestamp repeats"),
        ("timestamp actual_q_0\n0.0 1\n0.2 2\n0.1 3\n", None, r"line 4: timestamp goes back"),
        ("actual_q_0 actual_q_1\n1 2\n3 4\n", None, "no 'timestamp' column"),
        ("timestamp actual_q_0\n0.0 1\n", None, "at least 2 samples"),
        (
            "0.0,1\n0.1,2\n",
            "timestamp,actual_q:2",
            "rows have 2 fields but the --columns spec names 3",
        ),
        ("", None, "empty log"),
        (
            "timestamp actual_q_0 actual_q_2\n0.0 1 2\n0.1 3 4\n",
            None,
            r"no column actual_q_1 although actual_q_0, _2 are",
        ),
        (
            "timestamp actual_q_1 actual_qx_0\n0.0 1 2\n0.1 3 4\n",
            None,
            r"no column actual_q_0 .* 'actual_qx_0' misspelled\?",
        ),
    ],
)
def test_malformed_logs_are_one_line(
    tmp_path: Path, text: str, columns: str | None, message: str
) -> None:
    p = _write(tmp_path / "bad.csv", text)
    with pytest.raises(KinergyError, match=message) as info:
        read_log(p, columns=columns)
    assert str(info.value).startswith(str(p)) and "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("timestamp,,actual_q:2", "empty entry"),
        ("timestamp,actual_q:0", "COUNT >= 1"),
        ("timestamp,actual_q:2,actual_q:2", "given twice .did you mean actual_qd"),
        ("actual_q:2", "timestamp"),
        ("timestamp,actual_curent:6", "unknown field 'actual_curent' .did you mean actual_current"),
        ("timestamp,actual_q", "one value per joint"),
        ("timestamp,actual_TCP_pose:3", "actual_TCP_pose has 6 values"),
    ],
)
def test_bad_column_specs(spec: str, message: str) -> None:
    with pytest.raises(KinergyError, match=message):
        parse_columns(spec)


def test_energy_on_a_log_without_joint_signals(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    header = " ".join(f"actual_current_{k}" for k in range(6))
    p = _write(tmp_path / "currents.csv", f"timestamp {header}\n0 {'1 ' * 6}\n0.1 {'1 ' * 6}\n")
    assert main(["energy", "ur5e", str(p)]) == 1
    err = capsys.readouterr().err
    assert "currents.csv: a motion needs actual_q" in err and err.count("\n") == 1


def test_energy_on_a_log_with_the_wrong_joint_count(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    p = _write(
        tmp_path / "seven.csv",
        "timestamp "
        + " ".join(f"target_q_{k}" for k in range(7))
        + "\n0 "
        + "0 " * 7
        + "\n0.1 "
        + "0 " * 7
        + "\n",
    )
    assert main(["energy", "ur5e", str(p)]) == 1
    assert "target_q has 7 joints but the robot has 6" in capsys.readouterr().err


def test_energy_on_a_missing_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["energy", "ur5e", str(tmp_path / "nope.csv")]) == 1
    err = capsys.readouterr().err
    assert "nope.csv: no such file or folder, nor a built-in motion" in err
    assert err.count("\n") == 1


def test_energy_with_an_unknown_friction_model(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import tomli_w

    from kinergy.model import load_robot, robot_to_dict

    data = robot_to_dict(load_robot("ur5e"))
    data["joints"][2]["drive"]["friction"] = {"model": "lubricated", "viscous": 1.0}
    model = tmp_path / "m.toml"
    model.write_text(tomli_w.dumps(data))
    log = _write(
        tmp_path / "l.csv",
        "timestamp "
        + " ".join(f"target_q_{k}" for k in range(6))
        + "\n0 "
        + "0 " * 6
        + "\n0.1 "
        + "0 " * 6
        + "\n",
    )
    assert main(["energy", str(model), str(log)]) == 1
    err = capsys.readouterr().err
    assert "m.toml: joints[2] (elbow).drive.friction: unknown friction model 'lubricated'" in err


@pytest.mark.skipif(not (DATASETS / "ur3e-aurt").exists(), reason="shared datasets not available")
def test_reads_urs_own_record_files() -> None:
    log = read_log(DATASETS / "ur3e-aurt" / "wave_currentData_100v_40a.csv")
    assert log["actual_current"].shape[1] == 6 and len(log) > 1000
    torque = read_log(DATASETS / "ur3e-aurt" / "wave_torqueData_100v_40a.csv")
    assert torque["target_moment"].shape[1] == 6


@pytest.mark.skipif(
    not (DATASETS / "ur10e-innopolis").exists(), reason="shared datasets not available"
)
def test_reads_the_headerless_ur10e_logs() -> None:
    spec = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"
    log = read_log(
        DATASETS / "ur10e-innopolis" / "validation_data" / "ur-20_01_17-ptp_10_points.csv",
        columns=spec,
    )
    assert log["target_moment"].shape == (len(log), 6)


def test_reading_ahead_keeps_the_order_and_raises_where_the_reader_failed() -> None:
    from kinergy.logs.reading import _read_ahead

    def chunks() -> Iterator[int]:
        yield from range(5)
        raise KinergyError("log.csv: line 7: not a number")

    got: list[int] = []
    with pytest.raises(KinergyError, match="line 7"):
        for x in _read_ahead(chunks()):
            got.append(x)
    assert got == [0, 1, 2, 3, 4]
    assert list(_read_ahead(iter(range(1000)))) == list(range(1000))


def test_reading_ahead_stops_the_reader_and_closes_its_files_when_the_caller_stops() -> None:
    from kinergy.logs.reading import _read_ahead

    read: list[int] = []
    closed = threading.Event()

    def chunks() -> Iterator[int]:
        try:
            for i in range(10_000):
                read.append(i)
                yield i
        finally:
            closed.set()

    def readers() -> set[threading.Thread]:
        return {t for t in threading.enumerate() if t.name == "kinergy-log-reader"}

    before = readers()
    ahead = _read_ahead(chunks())
    assert [next(ahead) for _ in range(3)] == [0, 1, 2]
    assert len(readers() - before) == 1
    ahead.close()  # the caller stops early (as on an error)
    assert closed.is_set()  # closed before close() returned: the reader thread has ended
    assert len(read) <= 5  # it read at most one chunk ahead of the caller (and one in hand)
    assert not readers() - before
