"""``kinergy identify``: identify a model from controller logs and write it as a robot file."""

from __future__ import annotations

import click

from kinergy.cli.common import columns_option, fmt, fmt_vector, note, repair_option, table
from kinergy.cli.validate import validation_text
from kinergy.identify.payload import PayloadEstimate
from kinergy.identify.result import IdentificationResult
from kinergy.jsonable import dumps
from kinergy.model import load_robot
from kinergy.workflows.identify import METHODS, identify_model, identify_payload_model
from kinergy.workflows.logs import prepared_logs

__all__ = ["identify"]


def _payload_text(report: PayloadEstimate, out: str) -> str:
    lines = [
        f"payload: {report.mass:.4f} +- {report.mass_std:.4f} kg at "
        f"{fmt_vector(report.com)} m (flange frame), from {report.signal}; wrote {out}"
    ]
    lines += [f"note: {n}" for n in report.notes]
    return "\n".join(lines)


def _choice_text(result: IdentificationResult) -> list[str]:
    """``--friction auto``: the model each joint chose and how much its cross-validated current
    RMS beats Coulomb + viscous and the runner-up (empty for a fixed model)."""
    choices = getattr(result.fit, "friction_choice", None)
    if not choices:
        return []
    rows = []
    for name, c in zip(result.robot.joint_names, choices, strict=True):
        if c is None:
            continue
        gain, margin = c.gain_over_viscous_coulomb, c.margin
        rows.append(
            [
                name,
                c.model,
                f"{c.cv_rms[c.model]:.4f}",
                "-" if gain is None else f"{gain:.1f}",
                "-" if margin is None else f"{margin:.1f}",
            ]
        )
    headers = ["joint", "chosen", "CV RMS [A]", "vs Coulomb+viscous [%]", "vs runner-up [%]"]
    title = "\nFriction chosen per joint (--friction auto: 5-block cross-validated current RMS)"
    return [title, table(headers, rows)]


def _result_text(result: IdentificationResult, logs: int, out: str) -> str:
    rows = []
    for j in result.joints:
        fr = " ".join(f"{k}={fmt(v)}" for k, v in j.friction.items() if k != "model")
        rows.append(
            [
                j.name,
                f"{j.rotor_inertia:.4e}",
                f"{j.motor_inertia:.4e}",
                f"{j.torque_constant:.4f}",
                f"{j.friction['model']} {fr}",
            ]
        )
    samples = result.fit.samples
    headers = ["joint", "J_m+J_r [kg m^2]", "J_m [kg m^2]", "k_t [N m/A]", "friction (motor side)"]
    lines = [
        f"{result.robot.name}: {result.method} identification from {logs} log(s), {samples} samples",
        table(headers, rows),
    ]
    lines += _choice_text(result)
    text = validation_text(result.fit, result.robot.joint_names)
    if text:
        lines.append("\nFit on the identification logs\n" + text)
    lines += [f"warning: {w}" for w in result.warnings]
    lines.append(f"wrote {out}")
    return "\n".join(lines)


@click.command()
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
    type=click.Choice(METHODS),
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
@columns_option
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON (DESIGN.md shape).")
@click.option(
    "--friction",
    "friction",
    default=None,
    metavar="MODEL",
    help="Friction model for every joint (default: the model's own), e.g. power_law, "
    "load_coulomb, thermal_viscous; auto: per joint, the model with the lowest "
    "cross-validated current RMS (sequential method).",
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
@repair_option
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
    r = load_robot(robot_name)
    datas = prepared_logs(
        logs, n_joints=r.n, columns=columns, repair=repair, cutoff=cutoff, note=note
    )
    if payload_only:
        _, report = identify_payload_model(r, datas, out)
        summary = {"robot": r.name, "method": "payload", "payload": report}
        click.echo(dumps(summary) if as_json else _payload_text(report, out))
        return
    result = identify_model(
        r, datas, out, method=method, friction=friction, target=target, solver=solver, ridge=ridge
    )
    click.echo(dumps(result.to_dict()) if as_json else _result_text(result, len(logs), out))
