"""A time window on every log (``--from``/``--to``, issue 37 point 5): the samples read are those
within it, on the log's own time axis, the checks judge the window alone, and a window outside
the log is refused in one line; ROS 2 bags too."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from clicase import run_case

from kinergy.api import energy
from kinergy.errors import KinergyError
from kinergy.io.log import Log
from kinergy.io.rtde import write_log
from kinergy.logs.reading import CheckedLog, LogReading
from kinergy.logs.window import TimeWindow
from kinergy.model import load_robot
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import TwinSettings, simulate


def _twin(t0: float = 0.0) -> Log:
    robot = load_robot("ur5e")
    log = simulate(robot, paper_trajectory(robot, "test-a"), TwinSettings(seed=5))
    return Log("twin.csv", log.t + t0, log.signals)


@pytest.mark.parametrize("rows", [97, 50_000])
def test_the_window_is_the_samples_within_it_whatever_the_chunks(rows: int) -> None:
    log = _twin(t0=100.0)  # a controller's clock: the log's own axis does not start at 0
    window = TimeWindow(102.0, 105.5)
    read = CheckedLog(log, load_robot("ur5e"), LogReading(window=window), rows=rows).read()
    keep = (log.t >= 102.0) & (log.t <= 105.5)
    np.testing.assert_array_equal(read.t, log.t[keep])
    np.testing.assert_array_equal(read["actual_current"], log["actual_current"][keep])


def test_the_energy_of_a_window_is_the_energy_of_the_cut_log(tmp_path: Path) -> None:
    log = _twin()
    write_log(tmp_path / "whole.csv", log.t, log.signals)
    keep = (log.t >= 2.0) & (log.t <= 6.0)
    write_log(tmp_path / "cut.csv", log.t[keep], {k: v[keep] for k, v in log.signals.items()})
    window = energy("ur5e", tmp_path / "whole.csv", reading=LogReading(window=(2.0, 6.0))).to_dict()
    cut = energy("ur5e", tmp_path / "cut.csv").to_dict()
    assert window["total"]["e_elec"] == pytest.approx(cut["total"]["e_elec"], rel=1e-12)
    assert window["samples"] == cut["samples"] == int(keep.sum())


@pytest.mark.parametrize(
    ("start", "stop", "message"),
    [
        (5.0, 5.0, r"--from 5 s is not before --to 5 s"),
        (7.0, 2.0, r"--from 7 s is not before --to 2 s"),
        (-3.0, None, r"--from -3 s is before the log's first sample at 0 s"),
        (None, 60.0, r"--to 60 s is after the log's last sample \(the log spans 0 to 13.5\d* s"),
        (13.537, None, r"holds 1 sample\(s\)"),
    ],
)
def test_a_window_outside_the_log_is_refused(
    tmp_path: Path, start: float | None, stop: float | None, message: str
) -> None:
    log = _twin()
    write_log(tmp_path / "log.csv", log.t, log.signals)
    args = ["energy", "ur5e", "log.csv"]
    args += [] if start is None else ["--from", str(start)]
    args += [] if stop is None else ["--to", str(stop)]
    case = run_case(args, tmp_path, refuse=True)
    assert __import__("re").search(message, case.err), case.err


@pytest.mark.parametrize("command", ["identify", "validate", "energy", "report"])
def test_every_command_that_reads_a_log_takes_the_window(tmp_path: Path, command: str) -> None:
    log = _twin()
    write_log(tmp_path / "log.csv", log.t, log.signals)
    args = {
        "identify": ["identify", "log.csv", "--robot", "ur5e", "--out", "m.toml"],
        "validate": ["validate", "ur5e", "log.csv"],
        "energy": ["energy", "ur5e", "log.csv"],
        "report": ["report", "ur5e", "--energy", "log.csv", "--out", "rep"],
    }[command]
    case = run_case([*args, "--from", "1", "--to", "40"], tmp_path, refuse=True)
    assert "--to 40 s is after the log's last sample" in case.err


def test_a_short_window_of_the_twin_is_accepted_and_judged_on_what_it_shows() -> None:
    log = _twin()
    checked = CheckedLog(log, load_robot("ur5e"), LogReading(window=TimeWindow(None, 1.2)))
    checked.read()
    assert checked.checks is not None
    assert "robot" in checked.checks.passed and "speeds" in checked.checks.passed


def test_a_bag_takes_the_window_on_its_own_time_axis(tmp_path: Path) -> None:
    pytest.importorskip("rosbags")
    from bags import write_bag

    log = _twin()
    q, qd, current = log["actual_q"], log["actual_qd"], log["actual_current"]
    bag = write_bag(tmp_path / "bag", 1.7e9 + log.t, q, qd, current)
    robot = load_robot("ur5e")
    read = CheckedLog(bag, robot, LogReading(window=TimeWindow(3.0, 4.0))).read()
    assert read.t[0] >= 3.0 and read.t[-1] <= 4.0  # s from the bag's first message
    np.testing.assert_allclose(read.t, log.t[(log.t >= 3.0) & (log.t <= 4.0)], atol=1e-9)
    with pytest.raises(KinergyError, match="--to 99 s is after the log's last sample"):
        CheckedLog(bag, robot, LogReading(window=TimeWindow(None, 99.0))).read()
