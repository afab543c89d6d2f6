"""Robot models as data: validation on construction, TOML files, the built-in library, errors."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from conftest import random_state

import kinergy
from kinergy.cli import main
from kinergy.errors import KinergyError
from kinergy.model import Friction, Link, Payload, robot_from_dict, robot_to_dict

LIBRARY = kinergy.library_names()
EXPECTED_LIBRARY = {"ur3e", "ur5e", "ur10e", "ur16e", "ur5", "nursing-arm", "panda"}


def test_library_has_the_promised_robots() -> None:
    assert EXPECTED_LIBRARY <= set(LIBRARY)


@pytest.mark.parametrize("name", LIBRARY)
def test_builtin_round_trips_through_toml(name: str, tmp_path: Path) -> None:
    robot = kinergy.load_robot(name)
    path = tmp_path / f"{name}.toml"
    kinergy.save_robot(robot, path, header="written by a test")
    again = kinergy.load_robot(path)
    assert robot_to_dict(again) == robot_to_dict(robot)
    q, qd, qdd = random_state(robot, 5, seed=0)
    np.testing.assert_array_equal(kinergy.rnea(again, q, qd, qdd), kinergy.rnea(robot, q, qd, qdd))


@pytest.mark.parametrize("name", LIBRARY)
def test_builtin_models_are_complete_and_say_where_data_comes_from(name: str) -> None:
    robot = kinergy.load_robot(name)
    for cat, src in robot.sources.items():
        assert src.status in {"published", "seed", "nominal"}, (name, cat)
        assert src.ref, (name, cat)
    for j in robot.joints:
        assert j.limits.speed > 0 and j.limits.torque > 0


def test_ur5e_matches_the_seed_tables(ur5e: kinergy.Robot) -> None:
    # UR5e doc Tables I, II, IV, VI and section 5
    assert [j.d for j in ur5e.joints] == [0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996]
    assert [j.a for j in ur5e.joints] == [0.0, -0.425, -0.3922, 0.0, 0.0, 0.0]
    assert [j.link.mass for j in ur5e.joints] == [3.761, 8.058, 2.846, 1.37, 1.3, 0.365]
    assert [j.drive.torque_constant for j in ur5e.joints] == [
        0.1091,
        0.1071,
        0.1022,
        0.0793,
        0.0744,
        0.0769,
    ]
    assert [j.drive.motor_inertia for j in ur5e.joints] == [
        6.6119e-5,
        4.6147e-5,
        7.9773e-5,
        1.2249e-5,
        1.1868e-5,
        1.1981e-5,
    ]
    assert ur5e.joints[0].drive.friction.params == {
        "viscous": 0.475e-3,
        "coulomb_direct": 0.0938,
        "coulomb_reverse": 0.071,
        "smoothing": 1e-3,
    }
    assert {j.drive.motor_constant for j in ur5e.joints[:3]} == {0.27426}
    assert {j.drive.motor_constant for j in ur5e.joints[3:]} == {0.06632}
    assert {j.drive.kt_over_kb for j in ur5e.joints} == {0.89}
    assert [j.limits.torque for j in ur5e.joints] == [150.0] * 3 + [28.0] * 3


def test_table_iii_link5_izz_as_printed_is_rejected() -> None:
    # the reason the ur5e file reads Izz = 0.0009 (see its header)
    with pytest.raises(KinergyError, match="triangle inequality"):
        Link(mass=1.3, com=[0, 0.0018, 0.01634], inertia=[0.0012, 0.0012, 0.009, 0, 0, 0])


@pytest.mark.parametrize(
    ("inertia", "message"),
    [
        ([0.01, 0.01, -0.01, 0, 0, 0], "positive definite"),
        ([0.01, 0.01, 0.01, 0.02, 0, 0], "positive definite"),
        ([0.001, 0.001, 0.01, 0, 0, 0], "triangle inequality"),
        ([0.01, 0.01, 0.01], "6 finite numbers"),
        ([0.01, 0.01, np.nan, 0, 0, 0], "finite"),
    ],
)
def test_link_inertia_validation(inertia: list[float], message: str) -> None:
    with pytest.raises(KinergyError, match=message):
        Link(mass=1.0, com=[0, 0, 0], inertia=inertia)


def test_link_mass_must_be_positive() -> None:
    with pytest.raises(KinergyError, match="mass: must be a finite number > 0"):
        Link(mass=0.0, com=[0, 0, 0], inertia=[0.01, 0.01, 0.01, 0, 0, 0])


def test_friction_validation() -> None:
    with pytest.raises(KinergyError, match="unknown friction model 'magic'"):
        Friction("magic", {})
    with pytest.raises(KinergyError, match="missing parameter.*coulomb_reverse"):
        Friction("power_flow", {"viscous": 1e-3, "coulomb_direct": 0.1, "smoothing": 1e-3})
    with pytest.raises(KinergyError, match="unknown parameter.*stiction"):
        Friction(
            "viscous_coulomb", {"viscous": 1e-3, "coulomb": 0.1, "smoothing": 1e-3, "stiction": 1}
        )
    with pytest.raises(
        KinergyError, match="friction parameter 'smoothing': must be a finite number > 0, got 0"
    ):
        Friction("viscous_coulomb", {"viscous": 1e-3, "coulomb": 0.1, "smoothing": 0.0})


def test_payload_validation_and_parsing() -> None:
    assert kinergy.model.parse_payload("2.5").mass == 2.5
    p = kinergy.model.parse_payload("2.5,0,0,0.05")
    np.testing.assert_array_equal(p.com, [0, 0, 0.05])
    with pytest.raises(KinergyError, match="payload mass: must be a finite number >= 0"):
        Payload(mass=-1.0)
    with pytest.raises(KinergyError, match="--payload"):
        kinergy.model.parse_payload("1,2")


def _ur5e_dict() -> dict:
    return robot_to_dict(kinergy.load_robot("ur5e"))


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda d: d["joints"][2].pop("mass"), r"joints\[2\] \(elbow\): missing field 'mass'"),
        (
            lambda d: d["joints"][4].update(inertia=[0.0012, 0.0012, 0.009, 0, 0, 0]),
            r"joints\[4\] \(wrist_2\): inertia violates the triangle inequality",
        ),
        (
            lambda d: d["joints"][0].update(mass=-3.0),
            r"joints\[0\] \(shoulder_pan\): mass: must be a finite number > 0",
        ),
        (
            lambda d: d["joints"][1]["drive"].update(gear_ratio=0.0),
            r"joints\[1\] \(shoulder_lift\).drive: gear_ratio must be non-zero",
        ),
        (
            lambda d: d["joints"][1]["drive"]["friction"].update(model="magic"),
            r"drive.friction: unknown friction model 'magic'",
        ),
        (
            lambda d: d["joints"][3]["drive"]["friction"].pop("coulomb_reverse"),
            r"joints\[3\] \(wrist_1\).drive.friction: friction model 'power_flow' is missing parameter\(s\): coulomb_reverse",
        ),
        (
            lambda d: d["joints"][3].update(colour="blue"),
            r"joints\[3\] \(wrist_1\): unknown field\(s\) 'colour'",
        ),
        (lambda d: d.update(convention="euler"), "convention: must be one of dh, mdh, got 'euler'"),
        (
            lambda d: d["joints"][5]["limits"].update(position=[1.0, -1.0]),
            r"limits.position must be \[lower, upper\]",
        ),
        (
            lambda d: d["joints"][5]["limits"].pop("torque"),
            r"joints\[5\] \(wrist_3\).limits: missing field 'torque'",
        ),
        (
            lambda d: d["sources"].update(colour={"status": "published"}),
            "unknown source categories: colour",
        ),
        (lambda d: d["joints"][0].update(com=[0, 0]), r"com: must be 3 finite numbers"),
    ],
)
def test_bad_robot_file_names_file_and_field(tmp_path: Path, edit, message: str) -> None:
    data = _ur5e_dict()
    edit(data)
    path = tmp_path / "bad.toml"
    path.write_text(tomli_w.dumps(data))
    with pytest.raises(KinergyError, match=message) as info:
        kinergy.load_robot(path)
    text = str(info.value)
    assert text.startswith(str(path)) and "\n" not in text


def test_toml_syntax_error_names_line(tmp_path: Path) -> None:
    path = tmp_path / "broken.toml"
    path.write_text('name = "x"\nconvention = \n')
    with pytest.raises(KinergyError, match=r"broken.toml: not valid TOML: .*line 2"):
        kinergy.load_robot(path)


def test_unknown_robot_name_lists_builtins() -> None:
    with pytest.raises(KinergyError, match="unknown robot 'ur99'.*ur5e"):
        kinergy.load_robot("ur99")


def test_dict_round_trip_is_exact() -> None:
    data = _ur5e_dict()
    assert robot_to_dict(robot_from_dict(data)) == data


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ({"q": np.zeros(5)}, r"q: expected shape \(6,\) or \(N, 6\) for ur5e, got \(5,\)"),
        ({"q": np.zeros((3, 6)), "qd": np.zeros((4, 6))}, "qd: shape .* differs"),
        ({"q": np.array([0, 0, np.nan, 0, 0, 0.0])}, "q: not finite .* at joint 3"),
        (
            {"q": np.zeros((2, 6)), "qdd": np.array([[0.0] * 6, [0, np.inf, 0, 0, 0, 0]])},
            "qdd: not finite .* sample 1, joint 2",
        ),
        ({"q": [["a"] * 6]}, "q: must be numbers"),
    ],
)
def test_bad_arrays_name_the_argument(ur5e: kinergy.Robot, args: dict, message: str) -> None:
    with pytest.raises(KinergyError, match=message):
        kinergy.rnea(ur5e, **args)
    with pytest.raises(KinergyError, match=message):
        kinergy.regressor(ur5e, **args)


def test_wrench_shape_is_checked(ur5e: kinergy.Robot) -> None:
    with pytest.raises(KinergyError, match="wrench: expected shape"):
        kinergy.rnea(ur5e, np.zeros((2, 6)), wrench=np.zeros((3, 6)))


# --- command line -------------------------------------------------------------------------------


def test_cli_robot_list(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["robot", "list"]) == 0
    out = capsys.readouterr().out
    for name in LIBRARY:
        assert name in out
    assert "nominal" in out and "published" in out and "seed" in out
    assert main(["robot", "list", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {d["name"] for d in data} == set(LIBRARY)


def test_cli_robot_show_json_has_the_contract_keys(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["robot", "show", "ur5e", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {"name", "convention", "gravity", "joints"} <= set(data)
    joint = data["joints"][0]
    assert {"name", "d", "a", "alpha", "offset", "mass", "com", "inertia", "drive"} <= set(joint)
    drive = joint["drive"]
    assert {
        "gear_ratio",
        "motor_inertia",
        "reducer_inertia",
        "torque_constant",
        "motor_constant",
        "kt_over_kb",
        "friction",
    } <= set(drive)
    assert drive["friction"] == {
        "model": "power_flow",
        "viscous": 0.000475,
        "coulomb_direct": 0.0938,
        "coulomb_reverse": 0.071,
        "smoothing": 0.001,
    }


def test_cli_robot_show_with_payload(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["robot", "show", "ur5e", "--json", "--payload", "2.5,0,0,0.05"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["payload"]["mass"] == 2.5 and data["payload"]["com"] == [0.0, 0.0, 0.05]
    assert main(["robot", "show", "ur5e"]) == 0
    text = capsys.readouterr().out
    assert "shoulder_lift" in text and "power_flow" in text and "Sources" in text


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        (["robot", "show", "ur99"], "unknown robot 'ur99'"),
        (["robot", "show", "ur5e", "--payload", "heavy"], "--payload"),
    ],
)
def test_cli_errors_are_one_line(
    capsys: pytest.CaptureFixture[str], argv: list[str], fragment: str
) -> None:
    assert main(argv) != 0
    err = capsys.readouterr().err
    assert err.startswith("kinergy: error:") and fragment in err
    assert err.count("\n") == 1 and "Traceback" not in err


def test_cli_bad_file_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    data = _ur5e_dict()
    data["joints"][1]["mass"] = -1
    path = tmp_path / "neg.toml"
    path.write_text(tomli_w.dumps(data))
    assert main(["robot", "show", str(path)]) == 1
    err = capsys.readouterr().err
    assert (
        "neg.toml: joints[1] (shoulder_lift): mass: must be a finite number > 0" in err
        and err.count("\n") == 1
    )


def test_saved_file_is_valid_toml_with_header(tmp_path: Path) -> None:
    path = tmp_path / "x.toml"
    kinergy.save_robot(kinergy.load_robot("ur5e"), path, header="line one\nline two")
    text = path.read_text()
    assert text.startswith("# line one\n# line two\n")
    assert tomllib.loads(text)["name"] == "ur5e"
    assert [p.name for p in tmp_path.iterdir()] == ["x.toml"]  # no temporary left behind


def _rz_ry_rx(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """URDF's fixed-axis rpy written out: Rz(yaw) @ Ry(pitch) @ Rx(roll)."""
    c, s = np.cos, np.sin
    rx = np.array([[1, 0, 0], [0, c(roll), -s(roll)], [0, s(roll), c(roll)]])
    ry = np.array([[c(pitch), 0, s(pitch)], [0, 1, 0], [-s(pitch), 0, c(pitch)]])
    rz = np.array([[c(yaw), -s(yaw), 0], [s(yaw), c(yaw), 0], [0, 0, 1]])
    return rz @ ry @ rx


def test_rpy_is_urdfs_fixed_axis_convention_and_round_trips() -> None:
    from kinergy.model.frames import matrix_rpy, rpy_matrix

    rng = np.random.default_rng(4)
    angles = rng.uniform(-np.pi, np.pi, (200, 3)) * np.array([1.0, 0.5, 1.0])
    angles[:2, 1] = [np.pi / 2, -np.pi / 2]  # gimbal lock: other angles, the same rotation
    for a in angles:
        rot = _rz_ry_rx(*a)
        np.testing.assert_allclose(rpy_matrix(a), rot, atol=1e-14)
        np.testing.assert_allclose(rpy_matrix(matrix_rpy(rot)), rot, atol=1e-9)
