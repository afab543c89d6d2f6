"""UR joint calibration summaries: reading them, fitting friction curves and motor electrics to
them, and ``kinergy robot import-calibration`` (issue 13, "Done when" 1)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import kinergy
from kinergy.cli import main
from kinergy.errors import KinergyError
from kinergy.friction.registry import get_model
from kinergy.identification.electrics import fit_electrics
from kinergy.identification.friction_curve import choose_model, fit_curve, points_from
from kinergy.io.ur_calibration import read_ur_calibration
from kinergy.workflows.calibration import import_calibration

CALIBRATION = (
    Path(__file__).resolve().parents[2]
    / "shared"
    / "datasets"
    / "ur5e-calibration"
    / "robot_calibration_summary.txt"
)
real = pytest.mark.skipif(not CALIBRATION.exists(), reason="shared datasets not available")

SMALL = """**** Joint 0 :
  Calibration revision : v1
  K_tau    tau_avg  Stiction-  Stiction+  TauMax-  TauMax+  Avg. temp.
  +0.1000   0.1000  -0.05      +0.05      -0.18    0.18     +40.00

  Ang. vel.    U        I      Temp     Tau       Km
    -1.00   +10.000   -1.000  +45.00   -0.100   +0.070
    +0.00    +0.000   +0.000   +0.00   +0.000     -nan
    +1.00   +10.000   +1.000  +45.00   +0.100   +0.070
------------------------------------------------------------------
"""


def test_reader_takes_every_joint_and_drops_the_zero_row(tmp_path: Path) -> None:
    path = tmp_path / "cal.txt"
    path.write_text(SMALL)
    cal = read_ur_calibration(path)
    (joint,) = cal.joints
    assert joint.torque_constant == 0.1 and joint.revision == "v1"
    assert joint.stiction == (-0.05, 0.05) and joint.temperature == 40.0
    np.testing.assert_array_equal(joint.speed, [-1.0, 1.0])
    np.testing.assert_array_equal(joint.voltage, [10.0, 10.0])
    np.testing.assert_array_equal(joint.friction, [-0.1, 0.1])


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("**** Joint 0 :", "** Joint zero", r"cal.txt:1: expected '\*\*\*\* Joint N :'"),
        ("+0.1000   0.1000", "+0.1000", r"cal.txt:4: expected 7 numbers \(K_tau"),
        ("+1.00   +10.000", "+1.00   ten", r"cal.txt:9: expected 6 numbers \(Ang. vel."),
        ("  Ang. vel.", "  Speed", r"cal.txt:6: expected the header Ang. vel."),
        ("Calibration revision", "Revision", r"cal.txt:2: expected 'Calibration revision"),
    ],
)
def test_bad_files_name_the_line_and_what_was_expected(
    tmp_path: Path, old: str, new: str, message: str
) -> None:
    path = tmp_path / "cal.txt"
    path.write_text(SMALL.replace(old, new, 1))
    with pytest.raises(KinergyError, match=message):
        read_ur_calibration(path)


def test_a_cut_file_and_a_missing_file_are_one_line(tmp_path: Path) -> None:
    path = tmp_path / "cal.txt"
    path.write_text("\n".join(SMALL.splitlines()[:3]))
    with pytest.raises(KinergyError, match="ends early; expected the K_tau line"):
        read_ur_calibration(path)
    with pytest.raises(KinergyError, match="cannot read calibration file"):
        read_ur_calibration(tmp_path / "missing.txt")


def test_friction_curve_recovers_a_power_law_and_cross_validation_prefers_it() -> None:
    wm = np.array([-320.0, -150, -50, -1, 1, 50, 150, 320])
    truth = {"coulomb": 0.05, "viscous": 0.004, "exponent": 0.58, "smoothing": 1e-3}
    tau = get_model("power_law").friction_torque(truth, wm)
    points = points_from(wm, tau, tolerance=(1.0, 1e-3))
    fit = fit_curve(get_model("power_law"), points)
    assert fit.params["exponent"] == pytest.approx(0.58, abs=1e-3)
    assert fit.params["coulomb"] == pytest.approx(0.05, rel=1e-3)
    best, tried = choose_model([get_model("viscous_coulomb"), get_model("power_law")], points)
    assert best.model.name == "power_law" and len(tried) == 2
    assert tried[0].cv_rms is not None and best.cv_rms is not None
    assert best.cv_rms < 0.1 * tried[0].cv_rms


def test_electrics_fit_is_eq_19_exactly() -> None:
    rng = np.random.default_rng(4)
    current, wm = rng.normal(0, 2, 50), rng.normal(0, 200, 50)
    fit = fit_electrics(current, 0.3 * current + 0.11 * wm, wm)
    assert fit.resistance == pytest.approx(0.3) and fit.back_emf == pytest.approx(0.11)
    with pytest.raises(KinergyError, match="cannot separate"):
        fit_electrics(current, current, 2 * current)


@real
def test_ur5e_calibration_meets_the_issue_tolerances() -> None:
    # friction within 5 % (or 0.005 N m) at every point of every joint, U within 5 %
    result = import_calibration(kinergy.load_robot("ur5e"), CALIBRATION)
    for joint in result.joints:
        tau = np.array([p.friction for p in joint.points])
        model = np.array([p.friction_model for p in joint.points])
        contrast = np.array([p.friction_contrast for p in joint.points])
        assert np.all(np.abs(model - tau) <= np.maximum(0.05 * np.abs(tau), 0.005)), joint.name
        # the straight line is further off than the chosen curve on every joint
        assert np.max(np.abs(contrast / tau - 1)) > 2 * np.max(np.abs(model / tau - 1))
        u = np.array([p.voltage for p in joint.points])
        u_model = np.array([p.voltage_model for p in joint.points])
        assert np.all(np.abs(u_model / u - 1) < 0.05), joint.name
        # the equivalent DC motor creates no energy: k_t / k_b <= 1 (docs/FRICTION.md)
        assert 0.85 < joint.kt_over_kb < 1.0
    concave = [j.friction.params["exponent"] for j in result.joints]
    assert all(0.45 < p < 0.7 for p in concave)


@real
def test_cli_import_calibration_writes_a_calibration_robot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "ur5e-cal.toml"
    argv = ["robot", "import-calibration", "ur5e", str(CALIBRATION), "--out", str(out)]
    assert main([*argv, "--json", "--friction", "power_law"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert [j["friction"]["model"] for j in report["joints"]] == ["power_law"] * 6
    robot = kinergy.load_robot(out)
    assert robot.sources["friction"].status == "calibration"
    assert robot.joints[0].drive.torque_constant == 0.1005
    assert robot.joints[3].drive.winding_resistance == pytest.approx(1.6, rel=0.05)
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "within 5 %" in text and "Coulomb+viscous" in text
    assert main(["robot", "import-calibration", "ur5e", str(out), "--out", str(out)]) == 1
    assert "is also an input" in capsys.readouterr().err
    bad = tmp_path / "bad.txt"
    bad.write_text(SMALL.replace("+1.00   +10.000", "+1.00   ten"))
    assert (
        main(["robot", "import-calibration", "ur5e", str(bad), "--out", str(tmp_path / "x.toml")])
        == 1
    )
    assert "bad.txt:9: expected 6 numbers" in capsys.readouterr().err
    assert not (tmp_path / "x.toml").exists()
    unknown = ["robot", "import-calibration", "ur5e", str(bad), "--friction", "dahl"]
    assert main([*unknown, "--out", str(tmp_path / "x.toml")]) == 1
    err = capsys.readouterr().err  # the family is judged before the file is read
    assert "--friction: must be one of" in err and "got 'dahl'" in err and "bad.txt" not in err
    assert not (tmp_path / "x.toml").exists()


@real
def test_a_calibration_of_another_robot_is_refused_naming_the_one_it_fits(tmp_path: Path) -> None:
    """The UR5e's calibration imported into a UR3e or a UR10e model: refused, naming the joint
    whose torque constant is off and the built-in robots it fits; nothing written."""
    from kinergy.errors import KinergyError
    from kinergy.model.library import load_robot
    from kinergy.workflows.calibration import import_calibration

    for name in ("ur3e", "ur10e"):
        out = tmp_path / f"{name}.toml"
        with pytest.raises(
            KinergyError, match=r"a calibration of another robot \(it fits ur5, ur5e\)"
        ):
            import_calibration(load_robot(name), CALIBRATION, out=out)
        assert not out.exists()
