"""The realistic twin: a true robot that differs from the model, a controller's imperfections,
and identification on its logs that recovers the truth (not the model)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kinergy
from kinergy.cli import main
from kinergy.identification.options import IdentifyOptions
from kinergy.io.rtde import read_log, write_log
from kinergy.logs.prepare import prepare
from kinergy.trajectory.fourier import fourier_motion
from kinergy.twin import TwinSettings, realistic_truth, simulate
from kinergy.workflows.identify import identify_model


def test_the_truth_is_seeded_and_differs_from_the_model_within_its_spreads(
    ur5e: kinergy.Robot,
) -> None:
    truth = realistic_truth(ur5e, 5)
    again = realistic_truth(ur5e, 5)
    other = realistic_truth(ur5e, 6)
    kt = np.array([j.drive.torque_constant for j in truth.joints])
    kt0 = np.array([j.drive.torque_constant for j in ur5e.joints])
    assert np.array_equal(kt, [j.drive.torque_constant for j in again.joints])
    assert not np.array_equal(kt, [j.drive.torque_constant for j in other.joints])
    assert np.all(np.abs(kt / kt0 - 1) <= 0.04) and np.any(kt != kt0)
    for tj, mj in zip(truth.joints, ur5e.joints, strict=True):
        assert abs(tj.drive.motor_inertia / mj.drive.motor_inertia - 1) <= 0.08
        assert abs(tj.link.mass / mj.link.mass - 1) <= 0.01
        assert tj.drive.friction.name == "load_thermal_power_law"
        p = tj.drive.friction.params
        assert 0.5 <= p["exponent"] <= 0.65 and 0.01 <= p["load"] <= 0.03
        assert p["viscous_temperature"] < 0  # friction falls as the joint warms
    assert 24.0 <= truth.standby_power <= 36.0
    assert truth.sources["friction"].status == "user"


@pytest.fixture(scope="module")
def twin_log(
    ur5e: kinergy.Robot, tmp_path_factory: pytest.TempPathFactory
) -> tuple[Path, kinergy.Robot]:
    rng = np.random.default_rng(0)
    motion = fourier_motion(
        np.array([0.0, -1.4, 1.2, -1.4, -1.57, 0.0]),
        rng.normal(0, 0.3, (6, 5)),
        rng.normal(0, 0.3, (6, 5)),
        base_frequency=2 * np.pi / 10,
        periods=2,
        dt=0.004,
    )
    truth = realistic_truth(ur5e, 1)
    log = simulate(truth, motion, TwinSettings.realistic(1))
    path = tmp_path_factory.mktemp("mismatch") / "twin.csv"
    write_log(path, log.t, log.signals)
    return path, truth


def test_the_twin_logs_a_controllers_imperfections(twin_log: tuple[Path, kinergy.Robot]) -> None:
    log = read_log(twin_log[0])
    steps = log["actual_current"] / 0.005
    assert np.allclose(steps, np.round(steps), atol=1e-6)  # 5 mA current steps
    v = log["actual_robot_voltage"]
    assert 0.1 < np.std(v) < 0.5 and abs(np.mean(v) - 48.0) < 0.1  # ripple on the 48 V bus
    assert log["joint_temperatures"].shape == log["actual_q"].shape
    assert np.all(log["actual_robot_current"] > 0)  # standby at least


def test_identification_recovers_the_truth_not_the_model(
    ur5e: kinergy.Robot, twin_log: tuple[Path, kinergy.Robot]
) -> None:
    path, truth = twin_log
    result = identify_model(ur5e, [prepare(read_log(path), 6)], IdentifyOptions(friction="auto"))
    got, want = result.robot, truth
    for gj, tj, mj in zip(got.joints, want.joints, ur5e.joints, strict=True):
        assert gj.drive.torque_constant == pytest.approx(tj.drive.torque_constant, rel=0.05)
        # a log has no motor voltage: R and k_b stay the model's, whatever actual_joint_voltage says
        assert gj.drive.winding_resistance == mj.drive.winding_resistance
        assert gj.drive.motor_constant == mj.drive.motor_constant
        assert gj.drive.kt_over_kb == mj.drive.kt_over_kb
    assert got.standby_power == pytest.approx(want.standby_power, rel=0.03)
    draw = result.standing_draw
    assert draw is not None and draw.power == got.standby_power
    assert 0.0 < draw.std < 0.02 * draw.power and draw.blocks > 10
    # the bus voltage: the mean of the logged supply voltage (48 V and its ripple)
    assert got.bus_voltage == pytest.approx(48.0, abs=0.05)
    choices = result.fit.friction_choice
    assert choices is not None and all(c is not None for c in choices)
    # the concave truth beats a straight line on every joint
    assert all(
        c.model.name != "viscous_coulomb" and c.gain_over_viscous_coulomb > 0 for c in choices
    )
    assert any("written into the model" in n for n in result.notes)


def test_cli_simulate_mismatch_writes_the_truth(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, truth = tmp_path / "a.csv", tmp_path / "truth.toml"
    argv = ["simulate", "ur5e", "--trajectory", "test-b", "--out", str(out)]
    assert main([*argv, "--mismatch", "realistic", "--truth", str(truth)]) == 0
    assert "mismatch realistic" in capsys.readouterr().out
    robot = kinergy.load_robot(truth)
    assert robot.joints[0].drive.friction.name == "load_thermal_power_law"
    assert main([*argv, "--truth", str(out)]) == 1  # --truth may not overwrite --out
    assert main([*argv[:-2], "--out", str(tmp_path / "b.csv")]) == 0
    assert "mismatch none" in capsys.readouterr().out
    model = tmp_path / "id.toml"
    ident = ["identify", str(out), "--robot", "ur5e", "--friction", "auto", "--out", str(model)]
    assert main(ident) == 0
    out, err = capsys.readouterr()
    assert "Friction chosen per joint" in out and "vs Coulomb+viscous [%]" in out
    assert "kinergy: note: bus voltage 48" in err and "standing draw" in err
    assert "R = " not in err  # R and k_b are never fitted from a log's joint voltages
