"""The panda-gaz layout (kinergy.io.panda_layout): a time file and one-number-per-line files read
as the log numpy reshapes them into, checked for n values per sample, one line per problem."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kinergy.errors import KinergyError
from kinergy.io.formats import iter_log, read_log
from kinergy.io.log import Log

PANDA = Path(__file__).resolve().parents[2] / "shared" / "datasets" / "panda-gaz"


def _layout(folder: Path, samples: int = 30, n: int = 7, stem: str = "run", seed: int = 2) -> Path:
    """Write a seeded log in the layout; return its time file."""
    rng = np.random.default_rng(seed)
    folder.mkdir(exist_ok=True)
    t = np.cumsum(rng.uniform(0.0008, 0.0012, samples))
    np.savetxt(folder / f"{stem}_time.txt", t, fmt="%.9g")
    for name in ("positions", "velocity", "torques"):
        np.savetxt(folder / f"{stem}_{name}.txt", rng.normal(size=samples * n), fmt="%.17g")
    return folder / f"{stem}_time.txt"


@pytest.mark.skipif(not PANDA.exists(), reason="shared datasets not available")
def test_the_panda_run_reads_as_numpy_reshapes_it() -> None:
    log = read_log(PANDA, joints=[f"joint{k}" for k in range(1, 8)])
    t = np.loadtxt(PANDA / "exciting_traj_time.txt")
    assert np.array_equal(log.t, t) and len(log) == 20544
    for signal, name in (
        ("actual_q", "positions"),
        ("actual_qd", "velocity"),
        ("actual_joint_torque", "torques"),
    ):
        expected = np.loadtxt(PANDA / f"exciting_traj_{name}.txt").reshape(-1, 7)
        assert np.array_equal(log[signal], expected), signal
    same = read_log(PANDA / "exciting_traj_time.txt")  # the time file names the log too
    assert np.array_equal(same["actual_q"], log["actual_q"])


def test_chunks_join_to_the_whole_log(tmp_path: Path) -> None:
    time = _layout(tmp_path, samples=25)
    whole = read_log(time)
    chunks = list(iter_log(tmp_path, rows=10))
    assert [len(c) for c in chunks] == [10, 10, 5]
    joined = Log.concatenate(chunks)
    files = {"actual_q": "positions", "actual_qd": "velocity", "actual_joint_torque": "torques"}
    for name, stem in files.items():
        assert np.array_equal(joined[name], whole[name])
        assert np.array_equal(whole[name].ravel(), np.loadtxt(tmp_path / f"run_{stem}.txt"))
    assert set(read_log(time, select=["actual_qd"]).signals) == {"actual_qd"}


def test_values_per_sample_are_checked_before_reading(tmp_path: Path) -> None:
    time = _layout(tmp_path, samples=20)
    with pytest.raises(
        KinergyError,
        match=r"run_positions.txt: 140 values for 20 time stamps in run_time.txt \(7 per sample\); "
        r"expected 6 x 20 = 120 \(the robot's 6 joints\)$",
    ):
        read_log(time, joints=[f"j{k}" for k in range(6)])
    torques = tmp_path / "run_torques.txt"
    torques.write_text("\n".join(torques.read_text().splitlines()[:-3]) + "\n")
    with pytest.raises(
        KinergyError,
        match=r"run_torques.txt: 137 values for 20 time stamps in run_time.txt \(6.85 per "
        r"sample\); expected 7 x 20 = 140 \(run_positions.txt's 7 per sample\)$",
    ):
        read_log(time)


def test_a_bad_number_and_time_going_back_are_named_by_file_and_line(tmp_path: Path) -> None:
    time = _layout(tmp_path, samples=20)
    velocity = tmp_path / "run_velocity.txt"
    lines = velocity.read_text().splitlines()
    lines[12] = "0.3.1"
    velocity.write_text("\n".join(lines) + "\n")
    with pytest.raises(
        KinergyError, match=r"run_velocity.txt, line 13: not a finite number: '0.3.1'$"
    ):
        read_log(time)
    _layout(tmp_path, samples=20)
    stamps = time.read_text().splitlines()
    stamps[5] = stamps[3]
    time.write_text("\n".join(stamps) + "\n")
    with pytest.raises(
        KinergyError, match=r"run_time.txt, line 6: time .* is not after the one before; --repair"
    ):
        read_log(time)
    log = read_log(time, repair=True)
    assert len(log) == 19 and np.all(np.diff(log.t) > 0)
    assert any("1 sample(s) from line 6 on" in n for n in log.notes)


def test_a_folder_of_two_runs_asks_for_one_and_columns_are_refused(tmp_path: Path) -> None:
    _layout(tmp_path, stem="a")
    _layout(tmp_path, stem="b")
    with pytest.raises(
        KinergyError,
        match="2 logs in the panda-gaz layout here; name one by its time file: a_time.txt, b_time.txt",
    ):
        read_log(tmp_path)
    with pytest.raises(KinergyError, match="no --columns"):
        read_log(tmp_path / "a_time.txt", columns="timestamp,actual_q:7")


def test_a_set_is_the_same_log_by_its_folder_or_its_time_file(tmp_path: Path) -> None:
    """The SHA-256 of a set covers its own files, whichever names it: so ``validate`` knows a
    model was identified from it either way; another file in the folder changes nothing, a
    changed signal file changes it."""
    from kinergy.logs.reading import _file_hash

    def sha(path: Path) -> str:
        import threading

        out: list[str] = []
        _file_hash(path, out, threading.Event())
        return out[0]

    time = _layout(tmp_path)
    (tmp_path / "README.txt").write_text("notes")
    assert sha(tmp_path) == sha(time)
    torques = tmp_path / "run_torques.txt"
    before = sha(time)
    text = torques.read_text()
    torques.write_text(text[:-2] + ("1" if text[-2] != "1" else "2") + text[-1])
    assert sha(time) != before
