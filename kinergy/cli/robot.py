"""``kinergy robot list`` and ``kinergy robot show``: the built-in library and robot files."""

from __future__ import annotations

from collections.abc import Sequence

import click
import numpy as np

from kinergy.cli.common import fmt, fmt_vector, load, table
from kinergy.jsonable import dumps
from kinergy.model import SOURCE_CATEGORIES, Robot, library_names, load_robot, robot_to_dict

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


def _status(r: Robot, cats: Sequence[str]) -> str:
    statuses = {r.sources[c].status for c in cats}
    return statuses.pop() if len(statuses) == 1 else "mixed"


@robot.command("list")
@click.option("--json", "as_json", is_flag=True, help="Print JSON instead of a table.")
def robot_list(as_json: bool) -> None:
    """List the built-in robots and where each model's parameters come from.

    published: the maker's data; seed: a reference paper's tables; identified: fitted by kinergy
    from logs; nominal: an estimate, identify before trusting.
    """
    robots = [load_robot(name) for name in library_names()]
    if as_json:
        out = [
            {
                "name": r.name,
                "description": r.description,
                "joints": r.n,
                "convention": r.convention,
                "sources": {
                    c: {"status": r.sources[c].status, "ref": r.sources[c].ref}
                    for c in SOURCE_CATEGORIES
                },
            }
            for r in robots
        ]
        click.echo(dumps(out))
        return
    headers = ["name", "joints", "conv", *_PROVENANCE_COLUMNS, "description"]
    rows = [
        [r.name, str(r.n), r.convention]
        + [_status(r, cats) for cats in _PROVENANCE_COLUMNS.values()]
        + [r.description]
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
        f"convention: {r.convention}   joints: {r.n}   gravity: {fmt_vector(r.gravity)} m/s^2",
    ]
    if r.payload is not None:
        p = r.payload
        lines.append(
            f"payload: {fmt(p.mass)} kg at {fmt_vector(p.com)} m (flange), "
            f"inertia {fmt_vector(p.inertia)} kg m^2"
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
    headers.append("inertia Ixx Iyy Izz Ixy Iyz Ixz [kg m^2]")
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
    headers = ["joint", "gear", "J_m [kg m^2]", "J_r [kg m^2]", "k_t [N m/A]"]
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
                f"{d.friction.model} {friction}",
            ]
        )
    return table(headers, rows)


def _limits(r: Robot) -> str:
    headers = ["joint", "position [deg]", "speed [deg/s]", "acceleration [deg/s^2]", "torque [N m]"]
    rows = [
        [
            j.name,
            fmt_vector(np.degrees(j.limits.position)),
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
@click.option("--json", "as_json", is_flag=True, help="Print the model as JSON (DESIGN.md shape).")
@click.option(
    "--payload",
    metavar="MASS[,CX,CY,CZ[,IXX,IYY,IZZ,IXY,IYZ,IXZ]]",
    help="Payload at the flange: kg, m (flange frame), kg m^2 about its centre of mass.",
)
def robot_show(robot_name: str, as_json: bool, payload: str | None) -> None:
    """Show a robot model: a built-in name (ur5e) or a robot file (.toml, .urdf)."""
    r = load(robot_name, payload)
    click.echo(dumps(robot_to_dict(r)) if as_json else show_text(r))
