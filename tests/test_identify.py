"""Identification: the UR5e sequential procedure and payload identification, checked on twin logs
(where the truth is known) and on real robot logs (where the dataset's authors state the payload
and the controller's own signals are the reference)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

import kinergy
from kinergy.cli import main
from kinergy.errors import KinergyError
from kinergy.identification.options import Hold
from kinergy.identification.payload import identify_payload
from kinergy.identification.result import validation_metrics
from kinergy.identification.sequential import identify_sequential
from kinergy.io.log import Log
from kinergy.io.rtde import read_log
from kinergy.logs.prepare import prepare
from kinergy.model.robot import TorqueSensor
from kinergy.model.toml import save_robot
from kinergy.trajectory.fourier import fourier_motion
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import TwinSettings, simulate

DATASETS = Path(__file__).resolve().parents[2] / "shared" / "datasets"
UR10E = DATASETS / "ur10e-innopolis"
UR10E_SPEC = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"


def _twin(
    robot: kinergy.Robot,
    motion: kinergy.trajectory.motion.Motion,
    settings: TwinSettings,
    name: str,
) -> Log:  # type: ignore[name-defined]
    return simulate(robot, motion, settings, name=name)


@pytest.fixture(scope="module")
def twin_result(ur5e: kinergy.Robot):
    """Identify on a realistic twin test A (lag 4 ms, speed and current noise), keep test B unseen."""
    a = prepare(_twin(ur5e, paper_trajectory(ur5e, "test-a"), TwinSettings(seed=11), "test-a"), 6)
    b = prepare(_twin(ur5e, paper_trajectory(ur5e, "test-b"), TwinSettings(seed=12), "test-b"), 6)
    return identify_sequential(ur5e, [a]), b


def test_twin_parameters_within_the_issue_tolerances(ur5e: kinergy.Robot, twin_result) -> None:
    result, _ = twin_result
    for true, found in zip(ur5e.joints, result.robot.joints, strict=True):
        t, f = true.drive, found.drive
        assert f.rotor_inertia == pytest.approx(t.rotor_inertia, rel=0.03)
        assert f.torque_constant == pytest.approx(t.torque_constant, rel=0.02)
        tp, fp = t.friction.params, f.friction.params
        assert fp["viscous"] == pytest.approx(tp["viscous"], rel=0.10)
        for name in ("coulomb_direct", "coulomb_reverse"):
            assert abs(fp[name] - tp[name]) <= max(0.10 * tp[name], 0.005)


def test_twin_predicts_an_unseen_log(twin_result) -> None:
    result, unseen = twin_result
    metrics = validation_metrics(result.robot, [unseen])
    assert min(m.r2 for m in metrics.current) >= 0.98
    assert min(m.r2 for m in metrics.torque) >= 0.99


def test_result_json_has_the_contract_keys(twin_result) -> None:
    result, _ = twin_result
    data = json.loads(json.dumps(result.to_dict(), default=float))
    assert data["method"] == "sequential" and data["robot"] == "ur5e"
    for joint in data["joints"]:
        assert {"rotor_inertia", "motor_inertia", "torque_constant", "friction"} <= set(joint)
    assert {"current", "torque"} <= set(data["fit"])


def test_exact_twin_is_recovered_to_round_off(ur5e: kinergy.Robot) -> None:
    # without noise and lag the regression is exact: the seed's Table IV and VI values come back
    log = _twin(ur5e, paper_trajectory(ur5e, "test-a", dt=0.004), TwinSettings.exact(), "exact")
    result = identify_sequential(ur5e, [prepare(log, 6)], hold=Hold.NONE)
    for true, found in zip(ur5e.joints, result.robot.joints, strict=True):
        assert found.drive.rotor_inertia == pytest.approx(true.drive.rotor_inertia, rel=1e-6)
        assert found.drive.torque_constant == pytest.approx(true.drive.torque_constant, rel=1e-6)
        for name, value in true.drive.friction.params.items():
            assert found.drive.friction.params[name] == pytest.approx(value, rel=1e-5, abs=1e-9)


def test_a_joint_that_never_moves_gets_a_message_not_numbers(ur5e: kinergy.Robot) -> None:
    motion = paper_trajectory(ur5e, "test-a", dt=0.004)
    frozen = motion.q.copy()
    frozen[:, 3] = frozen[0, 3]
    still = dataclasses.replace(
        motion,
        q=frozen,
        qd=np.where(np.arange(6) == 3, 0.0, motion.qd),
        qdd=np.where(np.arange(6) == 3, 0.0, motion.qdd),
    )
    log = _twin(ur5e, still, TwinSettings.exact(), "still")
    result = identify_sequential(ur5e, [prepare(log, 6)])
    entry = result.joints[3]
    assert entry.identified is False and "never moves" in entry.problem
    assert entry.torque_constant == ur5e.joints[3].drive.torque_constant  # the model's, untouched
    assert any("joint 4 (wrist_1) never moves" in w for w in result.notes)
    assert all(j.identified for k, j in enumerate(result.joints) if k != 3)


def test_nothing_identifiable_is_one_error(ur5e: kinergy.Robot) -> None:
    t = np.arange(400) * 0.002
    q = np.tile([0.0, -1.57, 0.0, -1.57, 0.0, 0.0], (400, 1))
    still = kinergy.trajectory.motion.Motion(t, q, np.zeros_like(q), np.zeros_like(q))
    log = _twin(ur5e, still, TwinSettings.exact(), "still")
    with pytest.raises(
        KinergyError, match=r"joint 1 \(shoulder_pan\) never moves.*joint 6 \(wrist_3\) never moves"
    ):
        identify_sequential(ur5e, [prepare(log, 6)])
    with pytest.raises(KinergyError, match="only 20 samples"):
        identify_sequential(
            ur5e, [prepare(Log("short", t[:20], {k: v[:20] for k, v in log.signals.items()}), 6)]
        )


def _fourier(robot: kinergy.Robot, seed: int, duration_periods: int = 2):
    rng = np.random.default_rng(seed)
    q0 = np.array([0.0, -1.4, 1.2, -1.4, -1.57, 0.0])
    a = rng.normal(0.0, 0.35, (6, 4))
    b = rng.normal(0.0, 0.35, (6, 4))
    return fourier_motion(
        q0, a, b, base_frequency=2 * np.pi / 8.0, periods=duration_periods, dt=0.004
    )


# noise-free, the payload is recovered to 1e-3: not to round-off, because it moves the power-flow
# direction of samples with almost no load torque, a step in the friction (UR5e eqs 12-13)
@pytest.mark.parametrize(
    ("settings", "tolerance"), [(TwinSettings.exact(), 1e-3), (TwinSettings(seed=5), 0.02)]
)
def test_payload_from_a_twin_log(
    ur5e: kinergy.Robot, settings: TwinSettings, tolerance: float
) -> None:
    truth = kinergy.Payload(mass=2.4, com=[0.03, -0.02, 0.09])
    log = _twin(ur5e.with_payload(truth), _fourier(ur5e, 3), settings, "loaded")
    payload, report = identify_payload(ur5e, [prepare(log, 6)])
    assert payload.mass == pytest.approx(2.4, rel=tolerance)
    np.testing.assert_allclose(payload.com, truth.com, atol=max(0.002, 0.5 * tolerance))
    assert report.signal == "current"


def test_payload_needs_a_payload(ur5e: kinergy.Robot) -> None:
    log = _twin(ur5e, _fourier(ur5e, 4, 1), TwinSettings(seed=2), "bare")
    with pytest.raises(KinergyError, match="do not show a payload"):
        identify_payload(ur5e, [prepare(log, 6)])


def test_cli_identify_validate_and_payload(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    assert main(["simulate", "ur5e", "--trajectory", "test-a", "--out", str(a)]) == 0
    assert main(["simulate", "ur5e", "--trajectory", "test-b", "--out", str(b), "--seed", "3"]) == 0
    model = tmp_path / "ur5e-id.toml"
    assert main(["identify", str(a), "--robot", "ur5e", "--out", str(model), "--json"]) == 0
    out = capsys.readouterr().out
    data = json.loads(out[out.index("{") :])
    assert data["method"] == "sequential" and len(data["joints"]) == 6
    identified = kinergy.load_robot(model)
    assert identified.sources["torque_constant"].status == "identified"
    assert model.read_text().startswith("# kinergy")
    assert main(["validate", str(model), str(b), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert set(report) >= {"torque", "current"}
    assert all(m["r2"] > 0.98 for m in report["current"])
    assert main(["validate", str(model), str(b)]) == 0
    assert "UR5e Table VII" in capsys.readouterr().out


def test_cli_identify_bad_log_leaves_no_model(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("timestamp actual_q_0\n0 1\n0.1 x\n")
    out = tmp_path / "m.toml"
    assert main(["identify", str(bad), "--robot", "ur5e", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "bad.csv: line 3, column 2 (actual_q_0)" in err and err.count("\n") == 1
    assert not out.exists()


def test_a_torque_log_is_sent_to_the_method_that_can_use_it(
    ur5e: kinergy.Robot, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A log with measured joint torques but neither target_moment nor actual_current (the
    Panda's): the default method says which method and target can use it, and that one does."""
    log = _twin(ur5e, paper_trajectory(ur5e, "test-a"), TwinSettings.exact(), "a")
    path = tmp_path / "torques.csv"
    signals = {k: log[k] for k in ("actual_q", "actual_qd")}
    kinergy.io.rtde.write_log(path, log.t, {**signals, "actual_joint_torque": log["target_moment"]})
    # target_moment carries the rotors' inertia torque: what motor-side sensors read (read as
    # link-side sensors, the default, the wrists' fit is refused: R^2 -0.11 and -2.95)
    motor = ur5e.with_joints(
        [dataclasses.replace(j, torque_sensor=TorqueSensor("motor")) for j in ur5e.joints]
    )
    save_robot(motor, tmp_path / "ur5e-motor.toml")
    args = [
        "identify",
        str(path),
        "--robot",
        str(tmp_path / "ur5e-motor.toml"),
        "--accept",
        "robot",
    ]
    assert main([*args, "--out", str(tmp_path / "m.toml")]) == 1
    err = [
        line
        for line in capsys.readouterr().err.splitlines()
        if "preparing the dynamics" not in line
    ]
    assert len(err) == 1 and "use --method full --target torque" in err[0]
    assert not (tmp_path / "m.toml").exists()
    full = ["--method", "full", "--target", "torque", "--out", str(tmp_path / "f.toml")]
    assert main([*args, *full]) == 0, capsys.readouterr().err
    assert (tmp_path / "f.toml").exists()


# --- real robots ----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def ur10e_model():
    """The model of issue 12's acceptance: every unloaded Fourier run. (On three of them the
    15harm payload mass reads -6.1 % since the standstill-hold fixes (was -4.4 %);
    the pair of runs of the same motion with and without the load reads -4.6 % with no
    model at all, see benchmarks/bench_real_identification.py payload.)"""
    if not UR10E.exists():
        pytest.skip("shared datasets not available")
    robot = kinergy.load_robot("ur10e")
    runs = sorted(
        p for p in (UR10E / "identification_data").glob("*harm*.csv") if "Load" not in p.name
    )
    datas = [prepare(read_log(run, columns=UR10E_SPEC), 6) for run in runs]
    return identify_sequential(robot, datas).robot


def test_ur10e_predicts_the_held_out_point_to_point_program(ur10e_model) -> None:
    val = prepare(
        read_log(UR10E / "validation_data" / "ur-20_01_17-ptp_10_points.csv", columns=UR10E_SPEC), 6
    )
    metrics = validation_metrics(ur10e_model, [val])
    r2 = [m.r2 for m in metrics.current]
    # measured (README): 0.964 0.995 0.997 0.977 0.957 0.826 -- wrist 3 rests 64 % of this run and
    # its standstill current wanders under the position loop (see README)
    assert min(r2[:5]) >= 0.95
    assert r2[5] >= 0.78
    assert min(m.r2 for m in metrics.torque) >= 0.95


def test_ur10e_payload_within_five_percent(ur10e_model) -> None:
    log = read_log(
        UR10E / "identification_data" / "ur-20_02_19_15harm50secLoad.csv",
        columns=UR10E_SPEC,
        repair=True,
    )
    assert log.notes and "dropped" in log.notes[0]  # the recorder wrote garbage rows at the start
    payload, _ = identify_payload(ur10e_model, [prepare(log, 6)])
    assert payload.mass == pytest.approx(2.805, rel=0.05)
