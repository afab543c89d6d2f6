"""The plausibility checks of a log (kinergy.logs.checks), on real logs made wrong in one way each.

Every check is shown failing on a real log from ../shared/datasets changed in exactly the way it
looks for, the same log unchanged passing, and ``--accept`` letting the wrong one through with
the acceptance recorded. Every real log of the datasets passes every check with the layout its
README gives (no false alarm). The tests skip when the datasets are absent.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from kinergy.cli import main
from kinergy.errors import Code, KinergyError
from kinergy.io.columns import parse_columns
from kinergy.io.formats import read_log
from kinergy.io.log import Log
from kinergy.io.rtde import write_log
from kinergy.logs.checks import Check, check_log, parse_accept
from kinergy.logs.reading import CheckedLog, LogReading
from kinergy.model import load_robot

DATASETS = Path(__file__).resolve().parents[2] / "shared" / "datasets"
UR10E = DATASETS / "ur10e-innopolis"
UR3E = DATASETS / "ur3e-aurt"
SPEC = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"
SHORT = "timestamp,actual_q:6,actual_qd:6,actual_current:6"
#: the two 2019 runs are 19 columns wide; the second logs positions of 1e305 rad (corrupted)
SHORT_LOGS = {"ur-19_09_27-11_28_22.csv", "ur-19_09_27-11_32_02.csv"}

needs_data = pytest.mark.skipif(not UR10E.exists(), reason="shared datasets not available")


def _fourier() -> Log:
    return read_log(
        UR10E / "identification_data" / "ur-20_02_12-50sec_12harm.csv",
        columns=parse_columns(SPEC, 6),
    )


def _changed(log: Log, **signals: np.ndarray) -> Log:
    return Log(log.path, log.t, {**log.signals, **signals})


def _fails(robot: str, log: Log, check: Check) -> str:
    """The message of ``check`` failing on ``log`` (read in chunks of 997 rows)."""
    reading = LogReading()
    checked = CheckedLog(log, load_robot(robot), reading, rows=997)
    with pytest.raises(KinergyError, match=f"{check.value} check failed") as info:
        checked.read()
    everything = LogReading(accept=frozenset(Check))
    accepted = CheckedLog(log, load_robot(robot), everything, rows=997)
    accepted.read()
    assert accepted.checks is not None
    assert any(a.startswith(check.value) for a in accepted.checks.accepted)
    return str(info.value)


@needs_data
def test_the_unchanged_log_passes_every_check():
    log = _fourier()
    result = check_log(load_robot("ur10e"), log)
    assert set(result.passed) == {c.value for c in Check if c != Check.FIT}
    assert result.warnings == ()


@needs_data
def test_speeds_swapped_positions_and_speeds():
    log = _fourier()
    wrong = _changed(log, actual_q=log["actual_qd"], actual_qd=log["actual_q"])
    text = _fails("ur10e", wrong, Check.SPEEDS)
    assert "actual_qd is not the derivative of actual_q" in text and "--columns" in text


@needs_data
def test_speeds_layout_shifted_by_one_column():
    log = _fourier()
    names = ("actual_q", "actual_qd", "actual_current", "target_current", "target_moment")
    values = np.roll(np.hstack([log[n] for n in names]), -1, axis=1)
    wrong = _changed(log, **{n: values[:, 6 * k : 6 * k + 6] for k, n in enumerate(names)})
    assert "shifted" in _fails("ur10e", wrong, Check.SPEEDS)


@needs_data
def test_units_positions_in_degrees():
    log = _fourier()
    wrong = _changed(
        log, actual_q=np.degrees(log["actual_q"]), actual_qd=np.degrees(log["actual_qd"])
    )
    assert "degrees?" in _fails("ur10e", wrong, Check.UNITS)


@needs_data
def test_time_period_implausible_and_milliseconds_converted(tmp_path):
    log = _fourier()
    slow = Log(log.path, log.t * 100.0, log.signals)  # 10 ms steps read as 1 s
    assert "sample period" in _fails("ur10e", slow, Check.TIME)
    # time stamps in ms are settled by the data: converted, with a note, and the log passes
    path = tmp_path / "ms.csv"
    write_log(path, log.t * 1000.0, log.signals)
    checked = CheckedLog(path, load_robot("ur10e"))
    checked.read()
    assert any("timestamps are in ms; converted to s" in n for n in checked.notes)


@needs_data
def test_ratings_currents_in_milliamperes_and_torques_in_newton_millimetres():
    log = _fourier()
    assert "mA?" in _fails(
        "ur10e", _changed(log, actual_current=1000 * log["actual_current"]), Check.RATINGS
    )
    assert "N mm?" in _fails(
        "ur10e", _changed(log, target_moment=1000 * log["target_moment"]), Check.RATINGS
    )


@needs_data
def test_constant_current_not_logged():
    log = _fourier()
    current = log["actual_current"].copy()
    current[:, 2] = 0.0
    assert "joint 3 (elbow)" in _fails(
        "ur10e", _changed(log, actual_current=current), Check.CONSTANT
    )
    zero = np.zeros_like(current)
    assert "every joint" in _fails("ur10e", _changed(log, actual_current=zero), Check.CONSTANT)


@needs_data
@pytest.mark.parametrize("model", ["ur5e", "ur3e", "ur16e"])
def test_robot_another_robots_model(model):
    assert "looks like ur10e" in _fails(model, _fourier(), Check.ROBOT)


@needs_data
def test_robot_sign_flipped():
    log = _fourier()
    flipped = {}
    for name in ("target_moment", "actual_current", "target_current"):
        x = log[name].copy()
        x[:, 1] *= -1.0
        flipped[name] = x
    assert "opposite sign" in _fails("ur10e", _changed(log, **flipped), Check.ROBOT)


@needs_data
@pytest.mark.parametrize("every_signal", [True, False])
def test_robot_two_joints_swapped(every_signal):
    log = _fourier()
    names = list(log.signals) if every_signal else ["actual_current", "target_current"]
    swapped = {}
    for name in names:
        x = log[name].copy()
        x[:, [1, 2]] = x[:, [2, 1]]
        swapped[name] = x
    assert "swapped" in _fails("ur10e", _changed(log, **swapped), Check.ROBOT)


@needs_data
def test_robot_a_ur3e_log_read_for_a_ur10e():
    log = read_log(UR3E / "wave_currentData_100v_40a.csv")
    assert "looks like ur3e" in _fails("ur10e", log, Check.ROBOT)


def _dataset_logs() -> list[tuple[str, Path, str | None]]:
    if not DATASETS.exists():
        return []
    out = []
    for path in sorted(UR10E.glob("*/*.csv")):
        if path.name == "ur-19_09_27-11_32_02.csv":
            continue  # positions of 1e305 rad: refused as corrupted (test_real_logs_refused)
        out.append(("ur10e", path, SHORT if path.name in SHORT_LOGS else SPEC))
    out += [("ur3e", path, None) for path in sorted(UR3E.glob("*.csv"))]
    out += [("panda", DATASETS / "panda-gaz", None)]  # its folder, as its README reads it
    out += [("ur3e", path, None) for path in sorted((DATASETS / "ur3e-rad").glob("*.csv"))]
    return out


@needs_data
@pytest.mark.parametrize(
    ("robot", "path", "spec"), _dataset_logs(), ids=lambda x: getattr(x, "name", x)
)
def test_every_real_log_passes(robot, path, spec):
    r = load_robot(robot)
    columns = None if spec is None else tuple(parse_columns(spec, r.n))
    # the loaded 15-harmonic run ends with a cut line: --repair, as its README says
    checked = CheckedLog(
        path, r, LogReading(columns=columns, repair="15harm50secLoad" in path.name)
    )
    checked.read()
    assert checked.checks is not None and checked.checks.accepted == ()


@needs_data
def test_the_corrupted_2019_run_is_refused():
    path = UR10E / "identification_data" / "ur-19_09_27-11_32_02.csv"
    r = load_robot("ur10e")
    with pytest.raises(KinergyError, match=r"holds 1(\.\d+)?e\+30\d: not a value a robot logs"):
        CheckedLog(path, r, LogReading(columns=tuple(parse_columns(SHORT, 6)))).read()


def test_accept_names_are_checked():
    assert parse_accept(["robot", "speeds,units"]) == {Check.ROBOT, Check.SPEEDS, Check.UNITS}
    assert parse_accept(["all"]) == set(Check)
    with pytest.raises(KinergyError, match="unknown check 'robots'"):
        parse_accept(["robots"])


@needs_data
def test_the_command_line_refuses_and_accepts(tmp_path, capsys):
    """`identify` with the speed and position columns swapped in --columns: refused in one line,
    no model written; with --accept speeds it goes on and the result records the acceptance."""
    log = UR10E / "identification_data" / "ur-20_02_12-50sec_12harm.csv"
    swapped = SPEC.replace("actual_q:6,actual_qd:6", "actual_qd:6,actual_q:6")
    out = tmp_path / "m.toml"
    args = ["identify", str(log), "--robot", "ur10e", "--columns", swapped, "--out", str(out)]
    assert main(args) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "speeds check failed" in err and not out.exists()
    assert main([*args, "--accept", "speeds", "--accept", "robot,fit", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert any(a.startswith("speeds:") for a in result["inputs"][0]["checks"]["accepted"])
    assert "accepted" in out.read_text()


def test_a_payload_the_model_lacks_is_named_not_refused():
    """The twin of a UR5e carrying 3 kg: read for the bare ur5e, the log passes with a warning
    that names the payload the torques fit (within 10 %)."""
    from kinergy.model import Payload
    from kinergy.trajectory.programs import paper_trajectory
    from kinergy.twin import TwinSettings, simulate

    ur5e = load_robot("ur5e")
    loaded = ur5e.with_payload(Payload(mass=3.0, com=[0.0, 0.0, 0.08]))
    log = simulate(loaded, paper_trajectory(ur5e, "test-a", dt=0.004), TwinSettings(seed=4))
    result = check_log(ur5e, log)
    assert "robot" in result.passed
    (text,) = [w for w in result.warnings if getattr(w, "code", None) == Code.PAYLOAD_MISSING]
    assert "that the model lacks" in text
    mass = float(text.split("carrying about ")[1].split(" kg")[0])
    assert mass == pytest.approx(3.0, rel=0.1)


@needs_data
def test_joint_torques_read_as_currents_are_named():
    """A ROS 2 bag's effort read as currents though it holds joint torques."""
    log = _fourier()
    wrong = _changed(log, actual_current=log["target_moment"])
    assert "joint torques in N m logged as currents?" in _fails("ur10e", wrong, Check.RATINGS)


def test_energy_and_validate_take_the_built_in_motions(capsys):
    from kinergy.accounting.energy import energy
    from kinergy.trajectory.programs import paper_trajectory

    assert main(["energy", "ur5e", "test-a", "--json"]) == 0
    got = json.loads(capsys.readouterr().out)
    ur5e = load_robot("ur5e")
    want = energy(ur5e, paper_trajectory(ur5e, "test-a")).total_e_elec
    assert got["total"]["e_elec"] == pytest.approx(want, rel=1e-12)
    assert main(["validate", "ur5e", "test-b"]) == 0
    out, err = capsys.readouterr()
    assert "Current against actual_current" in out
    assert "test-b: the realistic twin of ur5e" in err
