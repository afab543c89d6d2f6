"""Tables that read: the CLI's one text-table printer keeps every line within 120 characters,
and the report's friction table has a column per parameter of each friction model, with units.
"""

from __future__ import annotations

import dataclasses

import pytest

import kinergy
from kinergy.cli.common import TABLE_WIDTH, table
from kinergy.friction.registry import MODELS, get_model
from kinergy.model.robot import Friction
from kinergy.report.tables import parameter_tables


def test_a_narrow_table_prints_as_before() -> None:
    text = table(["joint", "E [J]"], [["shoulder_pan", "1.5"], ["elbow", "-22.25"]])
    assert text == "joint         E [J]\nshoulder_pan  1.5\nelbow         -22.25"


def test_a_wide_table_prints_in_blocks_led_by_the_row_names() -> None:
    headers = ["joint", *(f"parameter_{k} [N m (s/rad)^exponent]" for k in range(7))]
    rows = [[f"joint_{j}", *(f"{j * 10 + k:.4e}" for k in range(7))] for j in range(6)]
    text = table(headers, rows)
    lines = text.splitlines()
    assert max(len(line) for line in lines) <= TABLE_WIDTH
    blocks = [b.splitlines() for b in text.split("\n\n")]
    assert len(blocks) == 3  # 5 + 38 per column: three columns a block
    seen_headers, seen_cells = [], set()
    for block in blocks:
        assert len(block) == 1 + len(rows)
        assert block[0].startswith("joint ")
        assert [line.split()[0] for line in block[1:]] == [r[0] for r in rows]
        seen_headers += [h for h in headers[1:] if h in block[0]]
        seen_cells |= {cell for line in block[1:] for cell in line.split()[1:]}
    assert seen_headers == headers[1:]  # every column once, in order
    assert seen_cells == {cell for r in rows for cell in r[1:]}


def test_a_cell_wider_than_the_line_wraps_within_its_row() -> None:
    note = " ".join(f"word{k}" for k in range(60))
    text = table(["joint", "note"], [["elbow", note], ["wrist_1", "short"]])
    lines = text.splitlines()
    assert max(len(line) for line in lines) <= TABLE_WIDTH
    assert lines[1].split()[:2] == ["elbow", "word0"] and lines[-1].split() == ["wrist_1", "short"]
    assert " ".join(w for line in lines[1:-1] for w in line.split() if w != "elbow") == note


@pytest.mark.parametrize("name", sorted(MODELS))
def test_every_friction_parameter_has_a_unit(name: str) -> None:
    units = get_model(name).parameter_units()
    spec = MODELS[name]
    assert set(spec.units) == set(spec.parameters)
    assert list(units)[: len(spec.parameters)] == list(spec.parameters)
    assert all(units.values())


POWER_LAW = {"coulomb": 0.02, "viscous": 0.004, "exponent": 0.6, "smoothing": 0.001}


def test_friction_tables_one_per_model_with_its_parameters_and_units() -> None:
    robot = kinergy.load_robot("ur5e")
    joints = list(robot.joints)
    families = {
        1: Friction("power_law", {**POWER_LAW, "coulomb": 0.1, "exponent": 0.55}),
        4: Friction("power_law", POWER_LAW),
        5: Friction("makkar", {f"gamma{k}": float(k) for k in range(1, 7)}),
    }
    for j, friction in families.items():
        joints[j] = dataclasses.replace(
            joints[j], drive=dataclasses.replace(joints[j].drive, friction=friction)
        )
    model = robot.with_joints(joints)
    inertia, *friction_tables = parameter_tables(model, truth=robot)
    assert inertia.caption == "Motor and reducer inertia (UR5e Table IV)"
    by_caption = {t.caption: t for t in friction_tables}
    assert list(by_caption) == [
        "Friction and torque constants (UR5e Table VI)",
        "Friction and torque constants (UR5e Table VI), power_law friction",
        "Friction and torque constants (UR5e Table VI), makkar friction",
    ]
    doc, power, makkar = friction_tables
    assert [r[0] for r in doc.rows] == ["shoulder_pan", "elbow", "wrist_1"]
    assert [r[0] for r in power.rows] == ["shoulder_lift", "wrist_2"]
    assert power.headers == [
        "joint",
        "k_t [N m/A]",
        "coulomb [N m]",
        "viscous [N m (s/rad)^exponent]",
        "exponent [1]",
        "smoothing [rad/s]",
    ]
    assert power.rows[0][2:5] == ["0.1", "0.004", "0.55"]
    assert makkar.headers[2:5] == ["gamma1 [N m]", "gamma2 [s/rad]", "gamma3 [s/rad]"]
    # the truth in brackets only where it has the same model: power_flow for the doc's joints
    viscous = robot.joints[0].drive.friction.params["viscous"]
    assert doc.rows[0][2] == f"{viscous:.4g} ({viscous:.4g})"
    assert "(" not in power.rows[0][2] and "(" in power.rows[0][1]  # k_t has its truth
    assert "power_law:" in power.note and "nursing eq 13" in makkar.note


def test_identify_prints_one_friction_table_per_model_within_the_width(
    tmp_path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``kinergy identify --friction auto`` on the twin: each chosen model's table has its own
    parameters with units, and no line of the text passes 120 characters."""
    from kinergy.cli import main

    log = tmp_path / "a.csv"
    assert (
        main(
            [
                "simulate",
                "ur5e",
                "--trajectory",
                "test-a",
                "--mismatch",
                "realistic",
                "--out",
                str(log),
            ]
        )
        == 0
    )
    capsys.readouterr()
    out = tmp_path / "m.toml"
    assert (
        main(["identify", str(log), "--robot", "ur5e", "--friction", "auto", "--out", str(out)])
        == 0
    )
    text = capsys.readouterr().out
    assert max(len(line) for line in text.splitlines()) <= TABLE_WIDTH
    models = {j.drive.friction.model for j in kinergy.load_robot(out).joints}
    for model in models:
        assert f"Friction, {model} (motor side)" in text
        units = get_model(model).parameter_units()
        for name in get_model(model).parameters:  # each parameter a column, with its unit
            assert (f"{name} [{units[name]}]" if units[name] else name) in text
    assert "friction (motor side)" not in text  # no longer one run-on column
