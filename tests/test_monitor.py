"""``kinergy monitor``: cycles found from the repeating program, energy measured against the model.

Relations checked: on the twin repeating a program (started mid-cycle), the period found is the
program's to within one sample and every cycle lasts one period; each cycle's measured supply
energy (the twin's bus voltage times current) equals the model's prediction (the twin is built
from the same model, so only the first cycle, which holds still before the start, may differ); a
gap drops the cycle in progress and the cycles after it stay one period long; without supply
columns only the prediction is given; against the RTDE test server the command prints the cycles
and its JSON; user errors are one line.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

import kinergy
import kinergy.api
from kinergy.cli.app import main
from kinergy.live.monitor import MONITOR_FIELDS, CycleTracker
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.programs import UR_HOME, pad_rest
from kinergy.twin import TwinSettings, simulate

sys.path.insert(0, str(Path(__file__).parent))
from rtde_server import RtdeServer

DT = 0.002


def program(robot) -> Motion:
    """A short pick-and-place-like cycle: home, two poses, home (about 2.5 s)."""
    way = np.vstack(
        [
            UR_HOME,
            UR_HOME + np.array([0.8, 0.3, -0.5, 0.2, 0.6, 0.0]),
            UR_HOME + np.array([-0.5, 0.2, 0.4, 0, 0, 1]),
            UR_HOME,
        ]
    )
    return pad_rest(kinergy.movej(way, speed=2.0, acceleration=5.0, dt=DT), 0.1, DT)


def repeated(robot, cycle: Motion, samples: int, offset: int, seed: int = 0):
    n = len(cycle.t) - 1  # the last sample is the next cycle's first
    idx = (np.arange(samples) + offset) % n
    t = 500.0 + DT * np.arange(samples)
    return simulate(
        robot, Motion(t, cycle.q[idx], cycle.qd[idx], cycle.qdd[idx]), TwinSettings(seed=seed)
    ), n * DT


def feed(tracker, log, rows=None, every=100):
    rows = range(len(log)) if rows is None else rows
    cycles = []
    for i in rows:
        values = [log.t[i]]
        for name in tracker_names(tracker):
            values.extend(np.atleast_1d(log[name][i]))
        tracker.add(values)
        if i % every == 0:
            cycles += tracker.update()
    return cycles + tracker.update()


def tracker_names(tracker):
    return [n for n in tracker._slices if n != "timestamp"]


@pytest.fixture(scope="module")
def ur5e_twin():
    robot = kinergy.load_robot("ur5e")
    return robot, program(robot)


def test_cycles_and_energy(ur5e_twin):
    robot, cycle = ur5e_twin
    log, period = repeated(robot, cycle, 6 * len(cycle.t), offset=333)
    tracker = CycleTracker(robot, MONITOR_FIELDS)
    found = feed(tracker, log)
    assert abs(tracker.period - period) <= DT
    assert len(found) >= 4 and [c.index for c in found] == list(range(1, len(found) + 1))
    for c in found:
        assert abs(c.duration - period) <= DT
    for c in found[1:]:
        assert c.measured == pytest.approx(c.predicted, rel=1e-3)
    starts = np.array([c.start for c in found])
    assert np.allclose(np.diff(starts), period, atol=DT)


def test_gap_drops_the_cycle_in_progress(ur5e_twin):
    robot, cycle = ur5e_twin
    log, period = repeated(robot, cycle, 8 * len(cycle.t), offset=0)
    tracker = CycleTracker(robot, MONITOR_FIELDS)
    cut = 3 * len(cycle.t) + 200
    before = feed(tracker, log, range(cut))
    tracker.gap()
    after = feed(tracker, log, range(cut + 400, len(log)))
    assert len(before) >= 2 and len(after) >= 3
    assert after[0].start > log.t[cut + 400] - DT
    for c in after:
        assert abs(c.duration - period) <= DT
        assert c.measured == pytest.approx(c.predicted, rel=1e-3)


def test_prediction_only_without_supply(ur5e_twin):
    robot, cycle = ur5e_twin
    log, _ = repeated(robot, cycle, 4 * len(cycle.t), offset=10)
    names = ("timestamp", "target_q", "target_qd", "target_qdd")
    tracker = CycleTracker(robot, names)
    found = feed(tracker, log)
    assert (
        not tracker.supply and found and all(c.measured is None and c.error is None for c in found)
    )


def test_monitor_against_the_server(ur5e_twin, capsys):
    robot, cycle = ur5e_twin
    log, period = repeated(robot, cycle, len(cycle.t) - 1, offset=0)
    with RtdeServer(log) as server:
        assert (
            main(["monitor", server.address, "--model", "ur5e", "--duration", "10", "--json"]) == 0
        )
    out = json.loads(capsys.readouterr().out)
    assert out["supply_logged"] and abs(out["period"] - period) <= DT
    assert len(out["cycles"]) >= 2
    for c in out["cycles"]:
        assert abs(c["duration"] - period) <= DT
        assert abs(c["error"]) < 1e-3


def test_monitor_text(ur5e_twin, capsys):
    robot, cycle = ur5e_twin
    log, _ = repeated(robot, cycle, len(cycle.t) - 1, offset=0)
    with RtdeServer(log) as server:
        assert main(["monitor", server.address, "--model", "ur5e", "--duration", "7"]) == 0
    captured = capsys.readouterr()
    lines = captured.out.splitlines()
    assert lines[0].split()[:3] == ["cycle", "start", "[s]"]
    assert len(lines) >= 2 and lines[1].split()[0] == "1"
    assert "cycle(s), period" in captured.err
    # the server runs in real time: the first cycle ends after two periods (5 s); until then a
    # line a second says how much has come, the controller time growing
    waiting = [x for x in captured.err.splitlines() if x.startswith("waiting for the first cycle")]
    assert len(waiting) >= 2, captured.err
    seconds = [float(x.split(": ")[1].split(" s ")[0]) for x in waiting]
    assert seconds == sorted(seconds) and seconds[-1] > seconds[0]
    assert "samples, period" in waiting[-1]


@pytest.mark.parametrize(
    ("argv", "message", "status"),
    [
        (["monitor", "127.0.0.1:1", "--model", "ur5e"], "cannot connect to 127.0.0.1:1", 1),
        (["monitor", "127.0.0.1:1", "--model", "no-such-robot"], "no-such-robot", 1),
        (
            ["monitor", "127.0.0.1", "--model", "ur5e", "--duration", "-1"],
            "--duration: must be a finite number > 0, got -1",
            2,
        ),
    ],
)
def test_monitor_errors(argv, message, status, capsys):
    assert main(argv) == status
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err


def test_the_api_monitors_as_the_command(ur5e_twin, capsys, monkeypatch):
    """The command calls ``kinergy.api.monitor`` and prints its result's ``to_dict()`` as
    ``--json`` (two live runs differ in where the first cycle is found, so the command's own
    run is compared with its JSON)."""
    robot, cycle = ur5e_twin
    log, _ = repeated(robot, cycle, len(cycle.t) - 1, offset=0)
    runs = []
    monitor = kinergy.api.monitor

    def recorded(*args, **kwargs):
        runs.append(monitor(*args, **kwargs))
        return runs[-1]

    monkeypatch.setattr(kinergy.api, "monitor", recorded)
    with RtdeServer(log) as server:
        argv = ["monitor", server.address, "--model", "ur5e", "--duration", "7", "--json"]
        assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out.pop("kinergy")["options"]["duration"] == 7.0 and out.pop("inputs") == []
    assert len(runs) == 1 and len(runs[0].cycles) >= 2
    assert out == json.loads(json.dumps(runs[0].to_dict()))
