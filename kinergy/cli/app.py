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
    r = _load(robot_name, payload)
    if as_json:
        click.echo(json.dumps(robot_to_dict(r), indent=2))
    else:
        click.echo(_show_text(r))


def _load(robot_name: str, payload: str | None) -> Robot:
    return load_robot(robot_name, payload=None if payload is None else parse_payload(payload))


_payload_option = click.option(
    "--payload",
    metavar="MASS[,CX,CY,CZ[,IXX,IYY,IZZ,IXY,IYZ,IXZ]]",
    help="Payload at the flange (replaces the model's): kg, m (flange frame), kg m^2.",
)
_columns_option = click.option(
    "--columns",
    metavar="SPEC",
    help='Layout of a headerless log, e.g. "timestamp,actual_q:6,actual_qd:6,actual_current:6".',
)


@cli.command()
@click.argument("robot_name", metavar="ROBOT")
@click.option(
    "--trajectory",
    required=True,
    metavar="test-a|test-b|FILE",
    help="The UR5e doc's test programs, or a motion file (record.py layout with target_q).",
)
@click.option("--out", "out", required=True, type=click.Path(dir_okay=False), help="Log to write.")
@click.option("--exact", is_flag=True, help="No lag and no noise: the model's equations exactly.")
@click.option("--lag", type=float, default=None, help="Real motion behind the target, s [0.004].")
@click.option(
    "--speed-noise", type=float, default=None, help="Measured speed noise std, rad/s [0.01]."
)
@click.option(
    "--current-noise", type=float, default=None, help="Measured current noise std, A [0.04]."
)
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the noise.")
@_payload_option
@_columns_option
def simulate(
    robot_name: str,
    trajectory: str,
    out: str,
    exact: bool,
    lag: float | None,
    speed_noise: float | None,
    current_noise: float | None,
    seed: int,
    payload: str | None,
    columns: str | None,
) -> None:
    """Run the digital twin: write the log a UR controller would record (record.py layout, 500 Hz).

    ROBOT is a built-in name or a model file; it is the twin's "true" model.
    """
    from kinergy.io.motion import motion_from_log
    from kinergy.io.rtde import read_log, write_log
    from kinergy.simulate import TwinSettings
    from kinergy.simulate import simulate as run_twin
    from kinergy.trajectory.programs import TEST_TRAJECTORIES, paper_trajectory

    r = _load(robot_name, payload)
    if trajectory in TEST_TRAJECTORIES:
        motion = paper_trajectory(r, trajectory)
    else:
        motion = motion_from_log(
            read_log(trajectory, columns=columns), n_joints=r.n, source="target"
        )
    base = TwinSettings.exact() if exact else TwinSettings()
    settings = TwinSettings(
        lag=base.lag if lag is None else lag,
        speed_noise=base.speed_noise if speed_noise is None else speed_noise,
        position_noise=base.position_noise,
        current_noise=base.current_noise if current_noise is None else current_noise,
        seed=seed,
    )
    twin = run_twin(r, motion, settings)
    t = twin.t
    write_log(out, t, twin.signals)
    click.echo(
        f"wrote {out}: {len(t)} samples, {t[-1] - t[0]:.3f} s, {r.name}, trajectory {trajectory}, "
        f"lag {settings.lag * 1e3:g} ms, speed noise {settings.speed_noise:g} rad/s, "
        f"current noise {settings.current_noise:g} A"
    )


def _energy_text(report: dict[str, Any]) -> str:
    rows = []
    for j in report["joints"]:
        b = j["breakdown"]
        eff = "-" if j["efficiency"] is None else f"{100 * j['efficiency']:.1f}"
        rows.append(
            [
                j["name"],
                f"{j['e_mech']:.1f}",
                f"{j['e_elec']:.1f}",
                eff,
                f"{j['mean_power']:.1f}",
                f"{j['peak_power']:.1f}",
                f"{b['inertial']:.1f}",
                f"{b['gravity']:.1f}",
                f"{b['friction']:.1f}",
                f"{b['copper']:.1f}",
            ]
        )
    tot = report["total"]
    b = tot["breakdown"]
    rows.append(
        [
            "total",
            f"{tot['e_mech']:.1f}",
            f"{tot['e_elec']:.1f}",
            f"{100 * tot['efficiency']:.1f}",
            f"{tot['e_elec'] / report['duration']:.1f}",
            f"{tot['peak_power']:.1f}",
            f"{b['inertial']:.1f}",
            f"{b['gravity']:.1f}",
            f"{b['friction']:.1f}",
            f"{b['copper']:.1f}",
        ]
    )
    head = f"{report['robot']}: {report['duration']:.3f} s, {report['samples']} samples; " + (
        "signed integrals (braking energy returns to the bus)"
        if report["recovery"]
        else "no recovery (negative power clipped)"
    )
    lines = [
        head,
        "",
        _table(
            [
                "joint",
                "E_mech [J]",
                "E_elec [J]",
                "eta [%]",
                "mean P [W]",
                "peak P [W]",
                "inertial [J]",
                "gravity [J]",
                "friction [J]",
                "copper [J]",
            ],
            rows,
        ),
        "",
        "E_mech = int tau_m wm dt, E_elec = int W_elec dt (UR5e eqs 23, 25, 26); eta = E_mech / E_elec.",
        "E_elec = inertial + gravity + friction + copper (each motion part includes its k_b/k_t share).",
    ]
    if tot["standby"]:
        lines.append(
            f"standby: {tot['standby']:.1f} J; total drawn {tot['e_elec_with_standby']:.1f} J"
        )
    return "\n".join(lines)


@cli.command()
@click.argument("model", metavar="MODEL")
@click.argument("motion_path", metavar="LOG_OR_MOTION", type=click.Path(dir_okay=False))
@_columns_option
@click.option("--json", "as_json", is_flag=True, help="Print JSON (DESIGN.md shape).")
@click.option(
    "--no-recovery", is_flag=True, help="Clip negative power: the supply takes no energy back."
)
@click.option(
    "--source",
    type=click.Choice(["auto", "target", "actual"]),
    default="auto",
    show_default=True,
    help="Which motion of a log: commanded (target_*) or measured (actual_*).",
)
@_payload_option
def energy(
    model: str,
    motion_path: str,
    columns: str | None,
    as_json: bool,
    no_recovery: bool,
    source: str,
    payload: str | None,
) -> None:
    """Per-joint mechanical and electrical energy of a logged or planned motion.

    MODEL is a built-in name or a model file; LOG_OR_MOTION a log (record.py layout, or headerless
    with --columns) or a motion file.
    """
    from kinergy.energy.accounting import energy as account
    from kinergy.io.motion import motion_from_log
    from kinergy.io.rtde import read_log

    r = _load(model, payload)
    motion = motion_from_log(read_log(motion_path, columns=columns), n_joints=r.n, source=source)
    report = account(r, motion, recovery=not no_recovery).to_dict()
    if as_json:
        click.echo(json.dumps(report, indent=2))
    else:
        click.echo(_energy_text(report))


_repair_option = click.option(
    "--repair",
    is_flag=True,
    help="Drop malformed rows (cut short, non-numeric, time out of order) instead of rejecting.",
)


def _read_logs(
    paths: Sequence[str], columns: str | None, repair: bool, n_joints: int, cutoff: float | None
) -> list[Any]:
    from kinergy.identify.preprocess import prepare
    from kinergy.io.rtde import read_log

    datas = []
    for path in paths:
        log = read_log(path, columns=columns, repair=repair)
        for note in log.notes:
            click.echo(f"kinergy: note: {note}", err=True)
        datas.append(prepare(log, n_joints, cutoff=cutoff))
    return datas


def _metrics_table(metrics: list[dict[str, float]], names: Sequence[str], unit: str) -> str:
    return _table(
        ["joint", f"mean [{unit}]", f"max [{unit}]", f"RMS [{unit}]", "R^2"],
        [
            [name, f"{m['mean']:.4f}", f"{m['max']:.4f}", f"{m['rms']:.4f}", f"{m['r2']:.4f}"]
            for name, m in zip(names, metrics, strict=True)
        ],
    )


def _validation_text(report: dict[str, Any], names: Sequence[str]) -> str:
    parts = []
    for key, title, unit in (
        ("torque", "Torque against target_moment (UR5e Table V)", "N m"),
        ("current", "Current against actual_current (UR5e Table VII)", "A"),
        ("joint_torque", "Joint torque against measured torque", "N m"),
    ):
        if report.get(key):
            parts += [title, _metrics_table(report[key], names, unit), ""]
    return "\n".join(parts).rstrip()


@cli.command()
@click.argument("logs", metavar="LOG...", nargs=-1, required=True)
@click.option(
    "--robot",
    "robot_name",
    required=True,
    metavar="ROBOT",
    help="Starting model: a built-in name or a model file.",
)
@click.option(
    "--method",
    type=click.Choice(["sequential", "full", "nursing"]),
    default="sequential",
    show_default=True,
    help="sequential: the UR5e doc's procedure; full: base-parameter regression.",
)
@click.option(
    "--out",
    "out",
    required=True,
    type=click.Path(dir_okay=False),
    help="Model file to write (TOML).",
)
@_columns_option
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON (DESIGN.md shape).")
@click.option(
    "--friction",
    "friction",
    default=None,
    metavar="MODEL",
    help="Friction model for every joint (default: the model's own).",
)
@click.option(
    "--target",
    type=click.Choice(["auto", "moment", "current", "torque"]),
    default="auto",
    show_default=True,
    help="Full method: regress against target_moment, currents or measured torques.",
)
@click.option(
    "--solver",
    type=click.Choice(["ols", "wls", "ridge"]),
    default="ols",
    show_default=True,
    help="Full method: ordinary, weighted or ridge least squares.",
)
@click.option(
    "--ridge",
    "ridge",
    type=float,
    default=0.0,
    show_default=True,
    help="Full method: ridge weight.",
)
@click.option(
    "--payload-only",
    is_flag=True,
    help="Identify only the payload from logs taken with it; ROBOT is the model identified without it.",
)
@click.option(
    "--cutoff",
    type=float,
    default=None,
    help="Low-pass cutoff for measured speeds, Hz [min(10, fs/5)].",
)
@_repair_option
def identify(
    logs: tuple[str, ...],
    robot_name: str,
    method: str,
    out: str,
    columns: str | None,
    as_json: bool,
    friction: str | None,
    target: str,
    solver: str,
    ridge: float,
    payload_only: bool,
    cutoff: float | None,
    repair: bool,
) -> None:
    """Identify a model from controller logs and write it as a robot file.

    The sequential method (default, UR5e doc sections 3-4) keeps the model's link data and
    identifies rotor inertias from target_moment and torque constants with friction from
    actual_current; the full method regresses the base inertial parameters too.
    """
    import datetime

    from kinergy import __version__
    from kinergy.model import save_robot

    r = load_robot(robot_name)
    datas = _read_logs(logs, columns, repair, r.n, cutoff)
    stamp = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    if payload_only:
        from kinergy.identify.payload import identify_payload

        payload, report = identify_payload(r, datas)
        save_robot(
            r.with_payload(payload),
            out,
            header=f"kinergy {__version__}: {r.name} with the payload identified from {', '.join(logs)} ({stamp})",
        )
        if as_json:
            click.echo(
                json.dumps({"robot": r.name, "method": "payload", "payload": report}, indent=2)
            )
        else:
            click.echo(
                f"payload: {report['mass']:.4f} +- {report['mass_std']:.4f} kg at {_vec(report['com'])} m "
                f"(flange frame), from {report['signal']}; wrote {out}"
            )
            for note in report["notes"]:
                click.echo(f"note: {note}")
        return
    if method == "sequential":
        from kinergy.identify.sequential import identify_sequential

        result = identify_sequential(r, datas, friction=friction)
    elif method == "nursing":
        from kinergy.identify.nursing import identify_nursing

        result = identify_nursing(r, datas)
    else:
        from kinergy.identify.full import identify_full

        result = identify_full(
            r, datas, target=target, solver=solver, ridge=ridge, friction=friction
        )
    header = (
        f"kinergy {__version__}: {r.name} identified ({result.method} method) from "
        f"{', '.join(logs)} on {stamp}"
    )
    save_robot(result.robot, out, header=header)
    if as_json:
        click.echo(json.dumps(result.to_dict(), indent=2, default=float))
        return
    names = result.robot.joint_names
    rows = []
    for j in result.joints:
        fr = {k: v for k, v in j["friction"].items() if k != "model"}
        rows.append(
            [
                j["name"],
                f"{j['rotor_inertia']:.4e}",
                f"{j['motor_inertia']:.4e}",
                f"{j['torque_constant']:.4f}",
                j["friction"]["model"] + " " + " ".join(f"{k}={_g(v)}" for k, v in fr.items()),
            ]
        )
    click.echo(
        f"{r.name}: {result.method} identification from {len(logs)} log(s), {result.fit.get('samples', 0)} samples"
    )
    click.echo(
        _table(
            ["joint", "J_m+J_r [kg m^2]", "J_m [kg m^2]", "k_t [N m/A]", "friction (motor side)"],
            rows,
        )
    )
    text = _validation_text(result.fit, names)
    if text:
        click.echo("\nFit on the identification logs\n" + text)
    for warning in result.warnings:
        click.echo(f"warning: {warning}")
    click.echo(f"wrote {out}")


@cli.command()
@click.argument("model", metavar="MODEL")
@click.argument("logs", metavar="LOG...", nargs=-1, required=True)
@_columns_option
@click.option("--json", "as_json", is_flag=True, help="Print JSON (DESIGN.md shape).")
@click.option(
    "--plots",
    "plots",
    type=click.Path(file_okay=False),
    default=None,
    help="Write plots (measured vs predicted, error box plots) to this folder.",
)
@click.option("--cutoff", type=float, default=None, help="Low-pass cutoff for measured speeds, Hz.")
@_payload_option
@_repair_option
def validate(
    model: str,
    logs: tuple[str, ...],
    columns: str | None,
    as_json: bool,
    plots: str | None,
    cutoff: float | None,
    payload: str | None,
    repair: bool,
) -> None:
    """How well a model predicts logs: torque (UR5e Table V) and current (Table VII) errors and R^2."""
    from kinergy.identify.result import validation_metrics

    r = _load(model, payload)
    datas = _read_logs(logs, columns, repair, r.n, cutoff)
    report = validation_metrics(r, datas)
    if plots:
        _validation_plots(r, datas, plots)
    if as_json:
        click.echo(json.dumps(report, indent=2))
        return
    click.echo(f"{r.name} on {', '.join(logs)}\n")
    text = _validation_text(report, r.joint_names)
    click.echo(
        text or "the logs have neither target_moment nor actual_current nor measured torques"
    )
    if plots:
        click.echo(f"\nplots in {plots}")


def _validation_plots(r: Robot, datas: list[Any], folder: str) -> None:
    from pathlib import Path

    from kinergy.identify.result import predict
    from kinergy.report.plots import error_boxplot, save, time_series

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    errors: dict[str, dict[str, Any]] = {"torque": {}, "current": {}}
    for k, data in enumerate(datas):
        pred = predict(r, data)
        stem = Path(data.path).stem or f"log{k}"
        for key, measured, predicted, unit, label in (
            ("torque", data.tau_ref, pred.torque, "N m", "target_moment"),
            ("current", data.current, pred.current, "A", "actual_current"),
        ):
            if measured is None or predicted is None:
                continue
            fig = time_series(
                data.t - data.t[0],
                measured,
                predicted,
                joint_names=r.joint_names,
                quantity=key,
                unit=unit,
                measured_label=label,
                predicted_label="model",
            )
            save(fig, out / f"{stem}_{key}.png")
            errors[key][stem] = measured - predicted
    for key, unit in (("torque", "N m"), ("current", "A")):
        if errors[key]:
            save(
                error_boxplot(errors[key], joint_names=r.joint_names, quantity=key, unit=unit),
                out / f"{key}_errors.png",
            )


def _progress() -> Any:
    import time

    start = time.perf_counter()

    def say(message: str) -> None:
        click.echo(f"[{time.perf_counter() - start:5.1f} s] {message}", err=True)

    return say


def _print_tables(tables: dict[str, Any], keys: Sequence[str]) -> None:
    for key in keys:
        for table in tables.get(key, []):
            click.echo(f"\n{table.caption}")
            click.echo(_table(table.headers, table.rows))
            if table.note:
                click.echo(table.note)


@cli.command()
@click.option(
    "--out",
    "out",
    type=click.Path(file_okay=False),
    default="kinergy-demo",
    show_default=True,
    help="Folder for the logs, figures and report.html.",
)
def demo(out: str) -> None:
    """The UR5e study on the built-in twin: simulate tests A and B, identify on A, validate on A
    and B, compute the energy, print UR5e Tables IV-VIII and write an HTML report."""
    from pathlib import Path

    from kinergy.workflows.demo import run_demo

    _sections, tables, report, seconds = run_demo(Path(out), _progress())
    _print_tables(tables, ["IV", "V", "VI", "VII", "VIII", "breakdown", "timing"])
    click.echo(f"\nreport: {report} ({seconds:.1f} s)")


@cli.command()
@click.argument("model", metavar="MODEL")
@click.option(
    "--identify",
    "identify_logs",
    multiple=True,
    metavar="LOG",
    help="Identify the model from this log first (sequential method; repeatable).",
)
@click.option(
    "--validate",
    "validate_logs",
    multiple=True,
    metavar="LOG",
    help="Compare the model with this log (repeatable).",
)
@click.option(
    "--energy",
    "energy_logs",
    multiple=True,
    metavar="LOG_OR_MOTION",
    help="Account the energy of this log's or motion file's motion (repeatable).",
)
@click.option(
    "--out",
    "out",
    type=click.Path(file_okay=False),
    default="kinergy-report",
    show_default=True,
    help="Folder for the figures and report.html.",
)
@_columns_option
@_payload_option
@_repair_option
def report(
    model: str,
    identify_logs: tuple[str, ...],
    validate_logs: tuple[str, ...],
    energy_logs: tuple[str, ...],
    out: str,
    columns: str | None,
    payload: str | None,
    repair: bool,
) -> None:
    """Build the study report (tables, figures, report.html) from your own model and logs."""
    import time
    from pathlib import Path

    from kinergy import __version__
    from kinergy.io.motion import motion_from_log
    from kinergy.io.rtde import read_log
    from kinergy.report.build import StudyInputs, report_sections
    from kinergy.report.html import write_report

    if not (identify_logs or validate_logs or energy_logs):
        raise KinergyError("report: give logs with --identify, --validate or --energy")
    say = _progress()
    r = _load(model, payload)
    result = None
    if identify_logs:
        from kinergy.identify.sequential import identify_sequential

        say("identifying")
        result = identify_sequential(r, _read_logs(identify_logs, columns, repair, r.n, None))
        r = result.robot
    validation = {
        Path(p).name: d
        for p, d in zip(
            validate_logs, _read_logs(validate_logs, columns, repair, r.n, None), strict=True
        )
    }
    motions = {
        Path(p).name: motion_from_log(read_log(p, columns=columns, repair=repair), n_joints=r.n)
        for p in energy_logs
    }
    folder = Path(out)
    sections, tables = report_sections(
        StudyInputs(model=r, validation=validation, motions=motions, result=result), folder, say
    )
    path = write_report(
        folder / "report.html",
        title=f"kinergy report: {r.name}",
        subtitle="Model parameters, accuracy on logs and energy of motions",
        sections=sections,
        meta={
            "model": model,
            "kinergy": __version__,
            "date": time.strftime("%Y-%m-%d %H:%M"),
            "logs": ", ".join(identify_logs + validate_logs + energy_logs),
        },
    )
    _print_tables(tables, ["IV", "V", "VI", "VII", "VIII", "breakdown"])
    click.echo(f"\nreport: {path}")


def _register_commands() -> None:
    """Commands that live in their own modules (kinergy.commands)."""
    from kinergy.cli.excite import excite
    from kinergy.cli.nursing import nursing
    from kinergy.cli.optimize import optimize

    cli.add_command(excite)
    cli.add_command(optimize)
    cli.add_command(nursing)


_register_commands()


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
