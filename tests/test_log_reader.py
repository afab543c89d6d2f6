"""The chunked log reader (issue 16) and log sanity (issue 15): the format registry, chunks,
column selection, byte-order marks, time stamp units, complex cells, limits, NUL bytes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kinergy.errors import KinergyError
from kinergy.io import log_arrow
from kinergy.io.columns import MAX_COLUMNS, parse_columns
from kinergy.io.formats import formats, iter_log, read_log
from kinergy.io.log import gaps, sample_period, time_unit
from kinergy.io.rtde import write_log

DATASETS = Path(__file__).resolve().parents[2] / "shared" / "datasets"


def _log(tmp_path: Path, n: int = 1000, period: float = 0.002, name: str = "x.csv") -> Path:
    rng = np.random.default_rng(1)
    t = np.arange(n) * period
    write_log(tmp_path / name, t, {"actual_q": rng.normal(size=(n, 6)), "robot_mode": np.ones(n)})
    return tmp_path / name


def test_chunks_join_to_the_whole_log(tmp_path: Path) -> None:
    path = _log(tmp_path, 1000)
    chunks = list(iter_log(path, rows=128))
    assert all(len(c) <= 128 for c in chunks) and sum(len(c) for c in chunks) == 1000
    whole = read_log(path)
    np.testing.assert_array_equal(
        np.concatenate([c["actual_q"] for c in chunks]), whole["actual_q"]
    )
    np.testing.assert_array_equal(np.concatenate([c.t for c in chunks]), whole.t)


def test_a_well_formed_file_is_read_by_the_fast_reader(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _log(tmp_path, 300)

    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("the careful reader was asked")

    monkeypatch.setattr("kinergy.io.rtde.read_text_table", refuse)
    assert len(read_log(path)) == 300


def test_a_bad_cell_after_the_first_chunk_names_its_line(tmp_path: Path) -> None:
    path = _log(tmp_path, 400)
    lines = path.read_text().splitlines()
    lines[351] = lines[351].replace(" ", " x", 1).replace(" x", " ", 1).rsplit(" ", 1)[0] + " x"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(
        KinergyError, match=r"line 352, column 8 \(robot_mode\): not a finite number: 'x'"
    ):
        list(iter_log(path, rows=100))


def test_select_reads_only_the_named_signals(tmp_path: Path) -> None:
    log = read_log(_log(tmp_path), select=["robot_mode"])
    assert set(log.signals) == {"robot_mode"}
    with pytest.raises(KinergyError, match="no column.*nothing"):
        read_log(_log(tmp_path), select=["nothing"])


def test_the_registry_names_its_formats() -> None:
    assert [f.name for f in formats()] == ["rosbag", "panda", "rtde"]
    with pytest.raises(
        KinergyError, match="unknown log format 'parquet'; known: rosbag, panda, rtde"
    ):
        read_log("x.csv", format="parquet")


def test_a_byte_order_mark_is_skipped(tmp_path: Path) -> None:
    path = tmp_path / "bom.csv"
    path.write_bytes("\ufefftimestamp,actual_q_0\n0,1\n0.1,2\n".encode())
    np.testing.assert_array_equal(read_log(path)["actual_q"], [[1], [2]])
    headerless = tmp_path / "bom2.csv"
    headerless.write_bytes("\ufeff0,1\n0.1,2\n".encode())
    np.testing.assert_array_equal(read_log(headerless, columns="timestamp,actual_q:1").t, [0, 0.1])


@pytest.mark.parametrize(("unit", "scale"), [("s", 1.0), ("ms", 1e3), ("us", 1e6), ("ns", 1e9)])
@pytest.mark.parametrize("rate", [125.0, 500.0])
def test_time_stamp_units_are_found_from_the_sample_period(
    tmp_path: Path, unit: str, scale: float, rate: float
) -> None:
    path = _log(tmp_path, 50, period=scale / rate)
    log = read_log(path)
    np.testing.assert_allclose(np.diff(log.t), 1.0 / rate, rtol=1e-9)
    assert (unit == "s") == (not log.notes)
    assert unit == "s" or f"timestamps are in {unit}; converted to s" in log.notes[0]


@pytest.mark.parametrize("period", [1.01, 1000.0, 1e6, 1e10])
def test_ambiguous_or_impossible_periods_are_refused(period: float) -> None:
    t = np.arange(10) * period
    with pytest.raises(KinergyError, match="x.csv: timestamp"):
        time_unit(t, "x.csv")


def test_gaps_are_found() -> None:
    t = np.concatenate([np.arange(100) * 0.002, 3600 + np.arange(100) * 0.002])
    assert sample_period(t) == pytest.approx(0.002)
    assert gaps(t).tolist() == [99]


def test_a_complex_cell_is_named(tmp_path: Path) -> None:
    path = tmp_path / "c.csv"
    path.write_text("timestamp actual_q_0\n0 1\n0.1 1+2j\n")
    with pytest.raises(KinergyError, match=r"line 3, column 2 \(actual_q_0\).*'1\+2j' \(a complex"):
        read_log(path)


def test_repair_drops_a_complex_cell_and_counts_it(tmp_path: Path) -> None:
    path = tmp_path / "c.csv"
    path.write_text("timestamp actual_q_0\n0 1\n0.1 1+2j\n0.2 3\n0.3 4\n")
    log = read_log(path, repair=True)
    assert len(log) == 3 and "dropped 1 malformed row(s) at line(s) 3" in log.notes[0]


def test_nul_bytes_are_never_echoed(tmp_path: Path) -> None:
    path = tmp_path / "nul.csv"
    path.write_bytes(b"timestamp actual_q_0\n0 1\n0.1 \x00\x00\n")
    with pytest.raises(KinergyError) as info:
        read_log(path)
    assert "\x00" not in str(info.value) and "NUL bytes" in str(info.value)


def test_column_limits_are_refused_before_allocation(tmp_path: Path) -> None:
    with pytest.raises(KinergyError, match=f"more than {MAX_COLUMNS} columns"):
        parse_columns("timestamp,actual_q:999999999")
    wide = tmp_path / "wide.csv"
    wide.write_text("timestamp " + " ".join(f"a_{k}" for k in range(200_000)) + "\n")
    with pytest.raises(KinergyError, match=f"longer than .* characters .at most {MAX_COLUMNS}"):
        read_log(wide)


def test_fast_reader_falls_back_on_runs_of_spaces(tmp_path: Path) -> None:
    path = tmp_path / "s.csv"
    path.write_text("timestamp  actual_q_0\n0   1\n0.1\t2\n")
    np.testing.assert_array_equal(read_log(path)["actual_q"], [[1], [2]])
    assert log_arrow.NotPlain.__doc__


@pytest.mark.skipif(
    not (DATASETS / "ur10e-innopolis").exists(), reason="shared datasets not available"
)
def test_the_19_column_ur10e_files_say_both_counts() -> None:
    spec = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"
    path = DATASETS / "ur10e-innopolis" / "identification_data" / "ur-19_09_27-11_28_22.csv"
    with pytest.raises(KinergyError, match="rows have 19 fields but the --columns spec names 31"):
        read_log(path, columns=spec)


def test_leading_comment_lines_are_skipped_and_named_in_line_numbers(tmp_path: Path) -> None:
    path = tmp_path / "commented.csv"
    path.write_text("# recorded on cell 3\n# 500 Hz\ntimestamp actual_q_0\n0 1\n0.002 2\n0.004 x\n")
    with pytest.raises(KinergyError, match=r"line 6, column 2 \(actual_q_0\): not a finite number"):
        read_log(path)
    path.write_text("# recorded on cell 3\ntimestamp actual_q_0\n0 1\n0.002 2\n")
    np.testing.assert_array_equal(read_log(path)["actual_q"], [[1], [2]])


def test_a_header_read_as_a_headerless_file_and_a_missing_timestamp_are_named(
    tmp_path: Path,
) -> None:
    path = tmp_path / "h.csv"
    path.write_text("timestamp actual_q_0\n0 1\n0.002 2\n")
    with pytest.raises(
        KinergyError, match="names its columns in a header line .*leave out --columns"
    ):
        read_log(path, columns="timestamp,actual_q:1")
    path.write_text("time actual_q_0\n0 1\n0.002 2\n")
    with pytest.raises(
        KinergyError, match="no 'timestamp' column; the header names time, actual_q_0"
    ):
        read_log(path)
