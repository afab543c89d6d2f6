"""The ``kinergy`` command.

Every user error (bad file, unknown robot, malformed input) ends as one line on stderr,
``kinergy: error: ...``, and exit status 1; usage errors exit with 2 (click's convention).
No traceback is shown for either.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from typing import Any

import click
import numpy as np

from kinergy.errors import KinergyError
from kinergy.model import (
    SOURCE_CATEGORIES,
    Robot,
    library_names,
    load_robot,
    parse_payload,
    robot_to_dict,
)

__all__ = ["cli", "main", "run"]

#: `robot list` groups the provenance categories into these columns
_PROVENANCE_COLUMNS = {
    "kinematics": ("kinematics",),
    "mass/com": ("mass", "com"),
    "inertia": ("inertia",),
    "drive": ("drive_inertia", "torque_constant", "motor_constant"),
    "friction": ("friction",),
    "limits": ("limits",),
}


def _status(robot: Robot, cats: Sequence[str]) -> str:
    statuses = {robot.sources[c].status for c in cats}
    return statuses.pop() if len(statuses) == 1 else "mixed"


def _table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    widths = [max(len(str(x)) for x in col) for col in zip(headers, *rows, strict=False)]
    lines = ["  ".join(str(h).ljust(w) for h, w in zip(headers, widths, strict=True)).rstrip()]
    for row in rows:
        lines.append("  ".join(str(x).ljust(w) for x, w in zip(row, widths, strict=True)).rstrip())
    return "\n".join(lines)


def _g(x: float) -> str:
    return f"{x:.6g}"


def _vec(v: Any) -> str:
    return "[" + ", ".join(_g(float(x)) for x in np.asarray(v)) + "]"


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="kinergy")
def cli() -> None:
    """Electro-mechanical models of robot arms from controller logs."""


@cli.group()
def robot() -> None:
    """Robot models: the built-in library and robot files."""


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
        click.echo(json.dumps(out, indent=2))
        return
    headers = ["name", "joints", "conv", *_PROVENANCE_COLUMNS, "description"]
    rows = [
        [r.name, str(r.n), r.convention]
        + [_status(r, cats) for cats in _PROVENANCE_COLUMNS.values()]
        + [r.description]
        for r in robots
    ]
    click.echo(_table(headers, rows))
    click.echo(
        "\npublished = maker's data; seed = a reference paper's tables; identified = fitted from "
        "logs;\nnominal = estimated, identify before trusting. `kinergy robot show NAME` gives the references."
    )


def _show_text(r: Robot) -> str:
    lines = [
        f"{r.name}: {r.description}" if r.description else r.name,
        f"convention: {r.convention}   joints: {r.n}   gravity: {_vec(r.gravity)} m/s^2",
    ]
    if r.payload is not None:
        p = r.payload
        lines.append(
            f"payload: {_g(p.mass)} kg at {_vec(p.com)} m (flange), inertia {_vec(p.inertia)} kg m^2"
        )
    if not np.array_equal(r.base, np.eye(4)):
        lines.append(f"base: frame 0 at {_vec(r.base[:3, 3])} m")
    if not np.array_equal(r.flange, np.eye(4)):
        lines.append(f"flange: at {_vec(r.flange[:3, 3])} m in the last link frame")
    assert r.coupling is not None
    if not np.array_equal(r.coupling, np.eye(r.n)):
        lines.append("coupling (motor input angles = C q):")
        lines.extend("  " + _vec(row) for row in r.coupling)
    a_name = "a_{i-1} [m]" if r.convention == "mdh" else "a [m]"
    al_name = "alpha_{i-1} [deg]" if r.convention == "mdh" else "alpha [deg]"
    lines += ["", "Kinematics and links (centre of mass and inertia in the link frame)"]
    lines.append(
        _table(
            [
                "joint",
                "d [m]",
                a_name,
                al_name,
                "offset [deg]",
                "mass [kg]",
                "com [m]",
                "inertia Ixx Iyy Izz Ixy Iyz Ixz [kg m^2]",
            ],
            [
                [
                    j.name,
                    _g(j.d),
                    _g(j.a),
                    _g(np.degrees(j.alpha)),
                    _g(np.degrees(j.offset)),
                    _g(j.link.mass),
                    _vec(j.link.com),
                    _vec(j.link.inertia),
                ]
                for j in r.joints
            ],
        )
    )
    lines += ["", "Drives (motor side)"]
    lines.append(
        _table(
            [
                "joint",
                "gear",
                "J_m [kg m^2]",
                "J_r [kg m^2]",
                "k_t [N m/A]",
                "k_m [N m/sqrt(W)]",
                "k_t/k_b",
                "friction",
            ],
            [
                [
                    j.name,
                    _g(j.drive.gear_ratio),
                    _g(j.drive.motor_inertia),
                    _g(j.drive.reducer_inertia),
                    _g(j.drive.torque_constant),
                    _g(j.drive.motor_constant),
                    _g(j.drive.kt_over_kb),
                    j.drive.friction.model
                    + " "
                    + " ".join(f"{k}={_g(v)}" for k, v in j.drive.friction.params.items()),
                ]
                for j in r.joints
            ],
        )
    )
    lines += ["", "Limits (joint side)"]
    lines.append(
        _table(
            ["joint", "position [deg]", "speed [deg/s]", "acceleration [deg/s^2]", "torque [N m]"],
            [
                [
                    j.name,
                    _vec(np.degrees(j.limits.position)),
                    _g(np.degrees(j.limits.speed)),
                    "-" if j.limits.acceleration is None else _g(np.degrees(j.limits.acceleration)),
                    _g(j.limits.torque),
                ]
                for j in r.joints
            ],
        )
    )
    lines += ["", "Sources"]
    lines.append(
        _table(
            ["parameters", "status", "reference"],
            [[c, r.sources[c].status, r.sources[c].ref] for c in SOURCE_CATEGORIES],
        )
    )
    return "\n".join(lines)


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
    r = load_robot(robot_name, payload=None if payload is None else parse_payload(payload))
    if as_json:
        click.echo(json.dumps(robot_to_dict(r), indent=2))
    else:
        click.echo(_show_text(r))


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: run the CLI, turning user errors into one line and a non-zero exit."""
    try:
        cli.main(
            args=list(argv) if argv is not None else None,
            prog_name="kinergy",
            standalone_mode=False,
        )
    except KinergyError as exc:
        click.echo(f"kinergy: error: {exc}", err=True)
        return 1
    except click.exceptions.Abort:
        click.echo("kinergy: aborted", err=True)
        return 1
    except click.ClickException as exc:
        exc.show()
        return exc.exit_code
    except click.exceptions.Exit as exc:
        return exc.exit_code
    except BrokenPipeError:
        return 0
    return 0


def run() -> None:
    """Console-script entry point."""
    sys.exit(main())


if __name__ == "__main__":
    run()
