"""``kinergy robot list``, ``show``, ``import-calibration``, ``export`` and ``import-urdf``: the
built-in library and robot files."""

from __future__ import annotations

import os

import click
import numpy as np

from kinergy import api
from kinergy.cli.common import (
    choice_of,
    fmt,
    fmt_vector,
    json_result,
    load,
    note,
    output_file_option,
    payload_option,
    table,
    writes,
)
from kinergy.model import SOURCE_CATEGORIES, Robot

__all__ = ["robot"]

#: `robot list` groups the provenance categories into these columns
_PROVENANCE_COLUMNS = {
    "kinematics": ("kinematics",),
    "mass/com": ("mass", "com"),
    "inertia": ("inertia",),
    "drive": ("drive_inertia", "torque_constant", "motor_constant"),
    "friction": ("friction",),
    "limits": ("limits",),
}


@click.group()
def robot() -> None:
    """Robot models: the built-in library and robot files."""


@robot.command("list")
@click.option("--json", "as_json", is_flag=True, help="Print JSON instead of a table.")
def robot_list(as_json: bool) -> None:
    """List the built-in robots and where each model's parameters come from.

    published: the maker's data; seed: a reference paper's tables; identified: fitted by kinergy
    from logs; calibration: fitted to the maker's joint calibration; nominal: an estimate,
    identify before trusting.
    """
    robots = api.robot_list()
    if as_json:
        click.echo(json_result([r.to_dict() for r in robots]))
        return
    headers = ["name", "joints", "conv", *_PROVENANCE_COLUMNS, "description"]
    rows = [
        [r.robot.name, str(r.robot.n), r.robot.convention]
        + [r.status(cats) for cats in _PROVENANCE_COLUMNS.values()]
        + [r.robot.description]
        for r in robots
    ]
    click.echo(table(headers, rows))
    click.echo(
        "\npublished = maker's data; seed = a reference paper's tables; identified = fitted from "
        "logs;\nnominal = estimated, identify before trusting. `kinergy robot show NAME` gives the references."
    )


def _summary(r: Robot) -> list[str]:
    lines = [
        f"{r.name}: {r.description}" if r.description else r.name,
        f"convention: {r.convention}   joints: {r.n}   gravity: {fmt_vector(r.gravity)} m/s²",
    ]
    if r.payload is not None:
        p = r.payload
        lines.append(
            f"payload: {fmt(p.mass)} kg at {fmt_vector(p.com)} m (flange), "
            f"inertia {fmt_vector(p.inertia)} kg m²"
        )
    if not np.array_equal(r.base, np.eye(4)):
        lines.append(f"base: frame 0 at {fmt_vector(r.base[:3, 3])} m")
    if not np.array_equal(r.flange, np.eye(4)):
        lines.append(f"flange: at {fmt_vector(r.flange[:3, 3])} m in the last link frame")
    assert r.coupling is not None
    if not np.array_equal(r.coupling, np.eye(r.n)):
        lines.append("coupling (motor input angles = C q):")
        lines.extend("  " + fmt_vector(row) for row in r.coupling)
    return lines


def _links(r: Robot) -> str:
    a_name = "a_{i-1} [m]" if r.convention == "mdh" else "a [m]"
    al_name = "alpha_{i-1} [deg]" if r.convention == "mdh" else "alpha [deg]"
    headers = ["joint", "d [m]", a_name, al_name, "offset [deg]", "mass [kg]", "com [m]"]
    headers.append("inertia Ixx Iyy Izz Ixy Iyz Ixz [kg m²]")
    rows = [
        [
            j.name,
            fmt(j.d),
            fmt(j.a),
            fmt(np.degrees(j.alpha)),
            fmt(np.degrees(j.offset)),
            fmt(j.link.mass),
            fmt_vector(j.link.com),
            fmt_vector(j.link.inertia),
        ]
        for j in r.joints
    ]
    return table(headers, rows)


def _drives(r: Robot) -> str:
    headers = ["joint", "gear", "J_m [kg m²]", "J_r [kg m²]", "k_t [N m/A]"]
    headers += ["k_m [N m/sqrt(W)]", "k_t/k_b", "friction"]
    rows = []
    for j in r.joints:
        d = j.drive
        friction = " ".join(f"{k}={fmt(v)}" for k, v in d.friction.params.items())
        rows.append(
            [
                j.name,
                fmt(d.gear_ratio),
                fmt(d.motor_inertia),
                fmt(d.reducer_inertia),
                fmt(d.torque_constant),
                fmt(d.motor_constant),
                fmt(d.kt_over_kb),
                f"{d.friction.name} {friction}",
            ]
        )
    return table(headers, rows)


def _limits(r: Robot) -> str:
    headers = ["joint", "position [deg]", "speed [deg/s]", "acceleration [deg/s²]", "torque [N m]"]
    rows = [
        [
            j.name,
            fmt_vector(np.degrees(j.limits.position))
            + (" (turns without limit)" if j.limits.continuous else ""),
            fmt(np.degrees(j.limits.speed)),
            "-" if j.limits.acceleration is None else fmt(np.degrees(j.limits.acceleration)),
            fmt(j.limits.torque),
        ]
        for j in r.joints
    ]
    return table(headers, rows)


def show_text(r: Robot) -> str:
    """The model as text: summary, links, drives, limits and where each group comes from."""
    sources = table(
        ["parameters", "status", "reference"],
        [[c, r.sources[c].status, r.sources[c].ref] for c in SOURCE_CATEGORIES],
    )
    return "\n".join(
        [
            *_summary(r),
            "",
            "Kinematics and links (centre of mass and inertia in the link frame)",
            _links(r),
            "",
            "Drives (motor side)",
            _drives(r),
            "",
            "Limits (joint side)",
            _limits(r),
            "",
            "Sources",
            sources,
        ]
    )


@robot.command("show")
@click.argument("robot_name", metavar="ROBOT")
@click.option("--json", "as_json", is_flag=True, help="Print the model as JSON.")
@payload_option
@writes(inputs=("robot_name",))
def robot_show(robot_name: str, as_json: bool, payload: str | None) -> None:
    """Show a robot model: a built-in name (ur5e) or a robot file (.toml, .urdf)."""
    shown = api.robot_show(load(robot_name, payload))
    click.echo(json_result(shown) if as_json else show_text(shown.robot))


def _calibration_text(result: api.CalibrationImport, out: str, points: bool) -> str:
    rows = []
    for j in result.joints:
        measured = np.array([p.friction for p in j.points])
        tol = np.maximum(0.05 * np.abs(measured), 0.005)
        model = np.array([p.friction_model for p in j.points])
        contrast = np.array([p.friction_contrast for p in j.points])
        u = np.array([p.voltage for p in j.points])
        u_model = np.array([p.voltage_model for p in j.points])
        params = " ".join(f"{k}={v:.4g}" for k, v in j.friction.params.items() if k != "smoothing")
        rows.append(
            [
                j.name,
                f"{j.torque_constant:.4f}",
                f"{j.friction.model.name} {params}",
                f"{100 * np.max(np.abs(model / measured - 1)):.1f}",
                "yes" if np.all(np.abs(model - measured) <= tol) else "NO",
                f"{100 * np.max(np.abs(contrast / measured - 1)):.1f}",
                f"{j.electrics.resistance:.3f}",
                f"{j.electrics.back_emf:.4f}",
                f"{j.kt_over_kb:.3f}",
                f"{100 * np.max(np.abs(u_model / u - 1)):.1f}",
            ]
        )
    headers = ["joint", "k_t [N m/A]", "friction (motor side)", "max err [%]", "within 5 %"]
    headers += ["Coulomb+viscous max err [%]", "R [ohm]", "k_b [V s/rad]", "k_t/k_b"]
    headers += ["U max err [%]"]
    lines = [
        f"{result.robot.name}: drives from the joint calibration {result.file}",
        table(headers, rows),
        "",
        "Friction: the chosen model (cross-validated, leave one point out) against the "
        "calibration's Tau at every speed; 'within 5 %': every point within 5 % or 0.005 N m.",
        "R, k_b: the equivalent DC motor (UR5e eq 19; the file's U is the controller's dq "
        "voltage, V = 1.5 U); U max err: the model's U against the file's.",
    ]
    if points:
        for j in result.joints:
            lines += ["", f"{j.name}: speed points (speed joint side, torques motor side)"]
            lines.append(
                table(
                    ["speed [rad/s]", "Tau [N m]", "model", "Coulomb+viscous", "U [V]", "model U"],
                    [
                        [
                            f"{p.speed:+.2f}",
                            f"{p.friction:+.4f}",
                            f"{p.friction_model:+.4f}",
                            f"{p.friction_contrast:+.4f}",
                            f"{p.voltage:.3f}",
                            f"{p.voltage_model:.3f}",
                        ]
                        for p in j.points
                    ],
                )
            )
    lines.append(f"\nwrote {out}")
    return "\n".join(lines)


@robot.command("import-calibration")
@click.argument("robot_name", metavar="ROBOT")
@click.argument("calibration", metavar="CALIBRATION.txt", type=click.Path(dir_okay=False))
@output_file_option("--out", "Robot file to write.", required=True)
@click.option(
    "--friction",
    default="auto",
    show_default=True,
    metavar="auto|MODEL",
    help="Friction model to fit; auto: the one that cross-validates best on the points.",
)
@click.option("--points", is_flag=True, help="Print every speed point with the models' values.")
@click.option("--json", "as_json", is_flag=True, help="Print the import as JSON.")
def robot_import_calibration(
    robot_name: str, calibration: str, out: str, friction: str, points: bool, as_json: bool
) -> None:
    """Drives from a UR joint calibration summary: torque constants, friction and the motor
    electrics, written into ROBOT as a robot file (provenance 'calibration').

    The summary's speeds are joint side, its friction torques motor side; its U is the
    controller's dq voltage (docs/FRICTION.md).
    """
    result = api.import_calibration(robot_name, calibration, friction=friction, out=out)
    click.echo(json_result(result) if as_json else _calibration_text(result, out, points))


def _source(model: str) -> str:
    """What an exported file says it was made from: a robot file's name, or the built-in
    name."""
    return os.path.basename(model) if os.path.exists(model) else model


@robot.command("export")
@click.argument("model", metavar="MODEL")
@click.option(
    "--format",
    "format_name",
    type=choice_of(api.ExportFormat),
    required=True,
    help="urdf: kinematics, link inertials, limits and joint-side friction, with the robot file "
    "itself in a <kinergy:robot> element (robot import-urdf reads it back); mjcf: a MuJoCo model with the "
    "reflected rotor inertia as armature, the friction as damping and frictionloss, torque "
    "actuators.",
)
@output_file_option("--out", "File to write.", required=True)
@payload_option
@writes(files=("out",), inputs=("model",))
def robot_export(model: str, format_name: api.ExportFormat, out: str, payload: str | None) -> None:
    """Write MODEL (a built-in name or a robot file) as URDF or MuJoCo MJCF.

    What the format cannot hold exactly (a friction model that is not Coulomb + viscous, a
    coupled transmission in URDF, link inertials completed from base parameters) is said in the
    file's comments and in a note here; docs/EXPORT.md has the details.
    """
    r = load(model, payload)
    export = api.export_robot(r, format_name, out, source=_source(model))
    for message in export.notes:
        note(message)
    click.echo(f"wrote {out}: {r.name}, {r.n} joints, {format_name.value.upper()}")


@robot.command("import-urdf")
@click.argument("urdf", metavar="URDF", type=click.Path(dir_okay=False))
@output_file_option("--out", "Robot file to write (TOML).", required=True, metavar="MODEL.toml")
@click.option("--root", metavar="LINK", help="Link the arm is mounted on [the URDF's root].")
@click.option("--tip", metavar="LINK", help="Link at the end of the arm [the chain's leaf].")
@click.option("--name", metavar="NAME", help="Robot name [the URDF's].")
@writes(files=("out",), inputs=("urdf",))
def robot_import_urdf(
    urdf: str, out: str, root: str | None, tip: str | None, name: str | None
) -> None:
    """Read a URDF serial chain into a robot file (TOML).

    A URDF written by `kinergy robot export` gives back the robot file it was written from (its
    <kinergy:robot> element holds it), after checking the standard elements against it. Any other
    URDF, as published (meshes and the like are skipped), gives modified-DH kinematics, the link
    inertials and limits, gear ratios from <transmission> (ROS or ros2_control
    SimpleTransmission; Drake's drake:gear_ratio), rotor inertias where a transmission gives them
    (drake:rotor_inertia) and Coulomb + viscous friction from <dynamics>; the rest of the drives
    is nominal: identify it from logs before trusting energy predictions.
    """
    result = api.import_urdf(urdf, out, root=root, tip=tip, name=name)
    r = result.robot
    for text in result.notes:
        note(text)
    if not result.restored:
        note(
            "the drives not in the URDF are nominal (marked so in the robot file): identify them "
            "from logs before trusting energy predictions"
        )
    click.echo(f"wrote {out}: {r.name}, {r.n} joints ({r.convention}); {result.drives}")
