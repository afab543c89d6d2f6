"""Joint ranges from the makers' data sheets (issue 34, point 3): every built-in robot's limits
name their source; the UR3e's wrist 3 turns without limit (``continuous``), which its robot file,
the TOML, JSON and URDF round trips keep and the ``units`` check honours."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kinergy.errors import KinergyError
from kinergy.io.log import Log
from kinergy.logs.reading import CheckedLog, LogReading
from kinergy.model import load_robot, robot_from_dict, robot_to_dict, save_robot
from kinergy.model.library import library_names
from kinergy.model.urdf_export import robot_to_urdf
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import TwinSettings, simulate

#: the makers' ranges, deg (UR e-Series and CB3 manuals: +-360; UR3e wrist 3 infinite; Franka's
#: datasheet; the nursing robot's paper, Table 1)
RANGES = {
    "ur5e": [(-360, 360)] * 6,
    "ur10e": [(-360, 360)] * 6,
    "ur16e": [(-360, 360)] * 6,
    "ur5": [(-360, 360)] * 6,
    "ur3e": [(-360, 360)] * 6,
    "panda": [
        (-166.0, 166.0),
        (-101.0, 101.0),
        (-166.0, 166.0),
        (-176.0, -4.0),
        (-166.0, 166.0),
        (-1.0, 215.0),
        (-166.0, 166.0),
    ],
    "nursing-arm": [(-90, 90), (-180, 180)] * 3,
}


@pytest.mark.parametrize("name", sorted(RANGES))
def test_every_built_in_robot_has_its_makers_ranges_with_a_source(name: str) -> None:
    robot = load_robot(name)
    assert name in library_names()
    got = np.degrees([j.limits.position for j in robot.joints])
    np.testing.assert_allclose(got, RANGES[name], atol=0.05)
    assert robot.sources["limits"].ref.strip()
    continuous = [j.name for j in robot.joints if j.limits.continuous]
    assert continuous == (["wrist_3"] if name == "ur3e" else [])


def test_continuous_survives_the_toml_json_and_urdf_round_trips(tmp_path: Path) -> None:
    pytest.importorskip("yourdfpy")
    from kinergy.model.urdf import robot_from_urdf

    ur3e = load_robot("ur3e")
    save_robot(ur3e, tmp_path / "ur3e.toml")
    assert load_robot(tmp_path / "ur3e.toml").joints[5].limits.continuous
    data = robot_to_dict(ur3e)
    assert data["joints"][5]["limits"]["continuous"] is True
    assert "continuous" not in data["joints"][4]["limits"]
    assert robot_from_dict(data).joints[5].limits.continuous
    (tmp_path / "ur3e.urdf").write_text(robot_to_urdf(ur3e).text, encoding="utf-8")
    back = robot_from_urdf(tmp_path / "ur3e.urdf")
    assert [j.limits.continuous for j in back.joints] == [False] * 5 + [True]
    with pytest.raises(KinergyError, match="continuous must be true or false"):
        data["joints"][0]["limits"]["continuous"] = "yes"
        robot_from_dict(data)


def test_a_wrist_that_turned_twice_is_no_unit_error_where_it_turns_without_limit() -> None:
    for name, passes in (("ur3e", True), ("ur5e", False)):
        robot = load_robot(name)
        log = simulate(robot, paper_trajectory(robot, "test-a"), TwinSettings(seed=2))
        turned = {k: v.copy() for k, v in log.signals.items()}
        for key in ("target_q", "actual_q"):
            turned[key][:, 5] += 4.0 * np.pi  # two turns on, as the ur3e-rad log's wrist 3
        checked = CheckedLog(Log(name, log.t, turned), robot, LogReading())
        if passes:
            checked.read()
            continue
        with pytest.raises(KinergyError, match="units check failed: .*wrist_3"):
            checked.read()
