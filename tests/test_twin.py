"""The digital twin: its signals are the seed's equations exactly without noise and lag, and
behave like a real controller's with them."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import kinergy
from kinergy.cli import main
from kinergy.io.rtde import read_log
from kinergy.trajectory.programs import paper_trajectory, paper_waypoints
from kinergy.twin import TwinSettings, simulate

pin = pytest.importorskip("pinocchio")
from kinergy.dynamics.pinocchio import to_pinocchio  # noqa: E402


@pytest.fixture(scope="module")
def test_a(ur5e: kinergy.Robot) -> kinergy.trajectory.motion.Motion:  # type: ignore[name-defined]
    return paper_trajectory(ur5e, "test-a", dt=0.004)


def _eq7_and_eq17(
    robot: kinergy.Robot, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """UR5e eq 7 (target_moment) and eq 17 (current) written out, Pinocchio for f_link."""
    model = to_pinocchio(robot)
    data = model.createData()
    moment = np.empty_like(q)
    current = np.empty_like(q)
    for k in range(len(q)):
        f_link = pin.rnea(model, data, q[k], qd[k], qdd[k])
        for j, joint in enumerate(robot.joints):
            d, i = joint.drive, joint.drive.gear_ratio
            moment[k, j] = f_link[j] + i * (d.motor_inertia + d.reducer_inertia) * i * qdd[k, j]
            p = d.friction.params
            wm = i * qd[k, j]
            flow = qd[k, j] * moment[k, j]
            w_dir = wm if flow > 0 else 0.0
            w_rev = wm if flow < 0 else 0.0
            current[k, j] = (
                moment[k, j] / i
                + wm * p["viscous"]
                + np.tanh(w_dir / p["smoothing"]) * p["coulomb_direct"]
                + np.tanh(w_rev / p["smoothing"]) * p["coulomb_reverse"]
            ) / d.torque_constant
    return moment, current


def test_exact_twin_is_the_seed_equations(ur5e: kinergy.Robot, test_a) -> None:
    sig = simulate(ur5e, test_a, TwinSettings.exact()).signals
    moment, current = _eq7_and_eq17(ur5e, test_a.q, test_a.qd, test_a.qdd)
    scale = np.max(np.abs(moment), axis=0)
    assert np.max(np.abs(sig["target_moment"] - moment) / scale) < 1e-6
    np.testing.assert_allclose(sig["actual_current"], current, rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(sig["actual_q"], test_a.q)
    np.testing.assert_array_equal(sig["actual_qd"], test_a.qd)


def test_realistic_twin_lags_and_is_noisy(ur5e: kinergy.Robot, test_a) -> None:
    settings = TwinSettings(
        lag=0.008, speed_noise=0.02, position_noise=0.0, current_noise=0.05, seed=3
    )
    sig = simulate(ur5e, test_a, settings).signals
    # actual = target two samples (8 ms at 4 ms) later
    np.testing.assert_allclose(sig["actual_q"][2:], test_a.q[:-2], atol=1e-9)
    noise = sig["actual_qd"][2:] - test_a.qd[:-2]
    assert np.std(noise) == pytest.approx(0.02, rel=0.05)
    _, current = _eq7_and_eq17(
        ur5e,
        sig["actual_q"],
        test_a.qd[np.r_[0, 0, : len(test_a) - 2]],
        test_a.qdd[np.r_[0, 0, : len(test_a) - 2]],
    )
    assert np.std(sig["actual_current"][2:] - current[2:]) == pytest.approx(0.05, rel=0.05)
    # the bus current carries the motors' electrical power
    assert np.all(sig["actual_robot_voltage"] == 48.0)


def test_paper_programs_are_reproducible_and_clear_the_table(ur5e: kinergy.Robot) -> None:
    a1, a2 = paper_waypoints(ur5e, 1), paper_waypoints(ur5e, 1)
    np.testing.assert_array_equal(a1, a2)
    assert not np.array_equal(a1, paper_waypoints(ur5e, 2))
    assert a1.shape == (8, 6)
    motion = paper_trajectory(ur5e, "test-b", dt=0.01)
    heights = kinergy.link_poses(ur5e, motion.q)[:, 2:, 2, 3]
    assert np.all(heights > 0.05)
    assert np.max(np.abs(motion.qd)) <= 3.0 + 1e-9 and np.max(np.abs(motion.qdd)) <= 6.0 + 1e-9


def test_cli_simulate_then_energy(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = tmp_path / "a.csv"
    assert main(["simulate", "ur5e", "--trajectory", "test-a", "--out", str(log), "--exact"]) == 0
    capsys.readouterr()
    data = read_log(log)
    assert len(data) > 5000 and np.allclose(np.diff(data.t), 0.002)
    for name in (
        "target_q",
        "actual_q",
        "target_qd",
        "actual_qd",
        "target_qdd",
        "target_moment",
        "actual_current",
        "actual_joint_voltage",
    ):
        assert data[name].shape == (len(data), 6)
    assert main(["energy", "ur5e", str(log), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) >= {"duration", "joints", "total"}
    assert all({"e_mech", "e_elec"} <= set(j) for j in out["joints"])
    assert {"e_mech", "e_elec", "efficiency"} <= set(out["total"])
    assert out["total"]["e_mech"] == pytest.approx(
        sum(j["e_mech"] for j in out["joints"]), rel=1e-9
    )
    assert main(["energy", "ur5e", str(log)]) == 0
    text = capsys.readouterr().out
    assert "E_mech [J]" in text and "total" in text


def test_cli_simulate_a_motion_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    t = np.arange(0, 2.0, 0.002)
    q = np.column_stack([0.3 * np.sin(np.pi * t)] * 6)
    motion = tmp_path / "m.csv"
    lines = ["timestamp " + " ".join(f"target_q_{k}" for k in range(6))]
    lines += [f"{ti} " + " ".join(f"{v:.12g}" for v in row) for ti, row in zip(t, q, strict=True)]
    motion.write_text("\n".join(lines) + "\n")
    out = tmp_path / "log.csv"
    assert (
        main(["simulate", "ur5e", "--trajectory", str(motion), "--out", str(out), "--payload", "2"])
        == 0
    )
    log = read_log(out)
    # derivatives come from a spline through target_q
    np.testing.assert_allclose(
        log["target_qd"][50:-50, 0], 0.3 * np.pi * np.cos(np.pi * t[50:-50]), atol=1e-4
    )


def test_cli_errors_leave_no_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "never.csv"
    assert main(["simulate", "ur5e", "--trajectory", "test-z", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "test-z" in err and err.count("\n") == 1
    assert not out.exists()
    assert main(["simulate", "panda", "--trajectory", "test-a", "--out", str(out)]) == 1
    assert "6-joint" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
