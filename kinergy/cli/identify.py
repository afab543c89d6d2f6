"""``kinergy identify``: identify a model from controller logs and write it as a robot file."""

from __future__ import annotations

import click

from kinergy import api
from kinergy.cli.common import (
    as_usage,
    choice_of,
    json_result,
    output_file_option,
    progress,
    reading_options,
    table,
    tell,
    writes,
)
from kinergy.cli.validate import validation_text
from kinergy.friction.registry import MODELS
from kinergy.identification.full import FullFit
from kinergy.identification.options import (
    AUTO,
    MAX_RIDGE,
    IdentifyOptions,
    Method,
    Solver,
    Target,
    friction_option,
)
from kinergy.identification.payload import PayloadEstimate
from kinergy.identification.result import FLAGS, IDENTIFIED, DriveEstimate, IdentificationResult
from kinergy.logs.reading import LogReading
from kinergy.model import load_robot

__all__ = ["identify"]


def _payload_text(report: PayloadEstimate, out: str) -> str:
    lines = [
        f"payload: {report.mass:.4f} ± {report.mass_std:.4f} kg at ["
        + ", ".join(f"{c:.4f} ± {sd:.4f}" for c, sd in zip(report.com, report.com_std, strict=True))
        + f"] m (flange frame), from {report.signal}; wrote {out}"
    ]
    return "\n".join(lines)


def _with_std(j: DriveEstimate, key: str, value: float, spec: str) -> str:
    """``value +- std`` of parameter ``key`` of joint ``j``, with its flag when not identified."""
    std = j.std.get(key)
    text = f"{value:{spec}}" + (f" ± {std:.2g}" if std is not None else "")
    flag = j.flags.get(key, IDENTIFIED)
    return text if flag == IDENTIFIED else f"{text} ({flag})"


def _full_text(fit: FullFit) -> list[str]:
    """The full method's base parameters (flags, largest relative standard error) and, when the
    robot was written from the constrained fit, what the physical constraints cost."""
    params = fit.base_parameters
    counts = {f: sum(p.flag == f for p in params) for f in FLAGS}
    rel = [
        (abs(p.rel_std), f"b{k + 1} = {p.name[:40]}{'...' if len(p.name) > 40 else ''}")
        for k, p in enumerate(params)
        if p.flag == IDENTIFIED and p.rel_std is not None
    ]
    lines = [
        f"base parameters: {len(params)} ("
        + ", ".join(f"{c} {f}" for f, c in counts.items() if c)
        + f"), condition {fit.condition:.3g}"
        + (f"; largest relative standard error {max(rel)[0]:.2g} ({max(rel)[1]})" if rel else "")
    ]
    vague = [
        k + 1 for k, p in enumerate(params) if p.flag == IDENTIFIED and abs(p.rel_std or 0.0) > 1
    ]
    if vague:
        lines.append(
            f"poorly determined (standard error above the value): base parameters "
            f"{', '.join(f'b{k}' for k in vague)}; more varied motion would pin them down"
        )
    phys = fit.physical_fit
    if phys is not None:
        before = " ".join(f"{m.rms:.3g}" for m in fit.regression)
        after = " ".join(f"{m.rms:.3g}" for m in phys.regression)
        lines += [
            f"physical fit ({phys.solver}): chi^2 up by {phys.chi2_increase:.3g}; RMS per joint "
            f"[N m] {before} unconstrained, {after} physical",
            *(f"  active: {a}" for a in phys.active),
        ]
    if fit.scale:
        lines.append(f"scale: {fit.scale}")
    return lines


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
                c.model.name,
                f"{c.cv_rms[c.model.name]:.4f}",
                "-" if gain is None else f"{gain:.1f}",
                "-" if margin is None else f"{margin:.1f}",
            ]
        )
    headers = ["joint", "chosen", "CV RMS [A]", "vs Coulomb+viscous [%]", "vs runner-up [%]"]
    title = "\nFriction chosen per joint (--friction auto: 5-block cross-validated current RMS)"
    return [title, table(headers, rows)]


def _friction_tables(result: IdentificationResult) -> list[str]:
    """One table per friction model in the result: a column per parameter with its unit (motor
    side), each value with its standard error and flag."""
    lines: list[str] = []
    models = dict.fromkeys(j.friction.model for j in result.joints)
    for model in models:
        units = model.parameter_units()
        names = [k for k in units if any(k in j.friction.params for j in result.joints)]
        headers = ["joint", *(f"{k} [{units[k]}]" if units[k] else k for k in names)]
        rows = [
            [
                j.name,
                *(
                    _with_std(j, k, j.friction.params[k], ".4g") if k in j.friction.params else "-"
                    for k in names
                ),
            ]
            for j in result.joints
            if j.friction.model is model
        ]
        lines += [f"\nFriction, {model} (motor side)", table(headers, rows)]
    return lines


def _result_text(result: IdentificationResult, logs: int, out: str) -> str:
    rows = [
        [
            j.name,
            _with_std(j, "rotor_inertia", j.rotor_inertia, ".4e"),
            f"{j.motor_inertia:.4e}",
            _with_std(j, "torque_constant", j.torque_constant, ".4f"),
        ]
        for j in result.joints
    ]
    samples = result.fit.samples
    headers = ["joint", "J_m+J_r [kg m²]", "J_m [kg m²]", "k_t [N m/A]"]
    offsets = [getattr(j, "torque_sensor_offset", None) for j in result.joints]
    if any(o is not None for o in offsets):  # against measured torques: the sensors' offsets
        headers.append("sensor offset [N m]")
        for row, j, o in zip(rows, result.joints, offsets, strict=True):
            row.append("-" if o is None else _with_std(j, "torque_sensor_offset", o, ".4f"))
    lines = [
        f"{result.robot.name}: {result.method} identification from {logs} log(s), {samples} samples",
        table(headers, rows),
        *_friction_tables(result),
    ]
    if isinstance(result.fit, FullFit):
        lines += _full_text(result.fit)
    lines += _choice_text(result)
    text = validation_text(result.fit, result.robot.joint_names)
    if text:
        lines.append("\nFit on the identification logs\n" + text)
    lines += [f"accepted: {a}" for a in result.accepted]
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
    type=choice_of(Method),
    default=Method.SEQUENTIAL.value,
    show_default=True,
    help="sequential: the UR5e doc's procedure (drives from the currents); full: base-parameter "
    "regression (links and drives); nursing: the nursing doc's method (friction from constant-"
    "speed runs, Makkar curves, ridge regression on filtered, period-averaged excitation "
    "logs).",
)
@output_file_option("--out", "Model file to write (TOML).", required=True)
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
@click.option(
    "--friction",
    "friction",
    type=click.Choice([*sorted(MODELS), AUTO.value]),
    default=None,
    help="Friction model for every joint (default: the model's own), e.g. power_law, "
    "load_coulomb, thermal_viscous; auto: per joint, the model with the lowest "
    "cross-validated current RMS (sequential and full methods; the logs need actual_current). "
    "The nursing method fits its own (Makkar) friction and takes none.",
)
@click.option(
    "--target",
    type=choice_of(Target),
    default=Target.AUTO.value,
    show_default=True,
    help="Full method: regress against target_moment, currents or measured torques (as the "
    "robot file's torque_sensor says they are measured, with each sensor's offset).",
)
@click.option(
    "--solver",
    type=choice_of(Solver),
    default=Solver.OLS.value,
    show_default=True,
    help="Full method: ordinary, weighted or ridge least squares.",
)
@click.option(
    "--ridge",
    "ridge",
    type=float,
    default=0.0,
    show_default=True,
    help=f"Full method: ridge weight (0 to {MAX_RIDGE:g}).",
)
@click.option(
    "--payload-only",
    is_flag=True,
    help="Identify only the payload from logs taken with it; ROBOT is the model identified without it.",
)
@reading_options()
@writes(files=("out",), inputs=("logs", "robot_name"))
def identify(
    logs: tuple[str, ...],
    robot_name: str,
    method: Method,
    out: str,
    as_json: bool,
    friction: str | None,
    target: Target,
    solver: Solver,
    ridge: float,
    payload_only: bool,
    reading: LogReading,
) -> None:
    """Identify a model from controller logs and write it as a robot file.

    The sequential method (default, UR5e doc sections 3-4) keeps the model's link data and
    identifies rotor inertias from target_moment and torque constants with friction from
    actual_current; the full method regresses the base inertial parameters too. Where the logs
    measure the arm's supply (actual_robot_voltage, actual_robot_current), the standing draw
    (electronics with the brakes released) is identified with its standard error; the motors' R
    and k_b stay the model's (actual_joint_voltage is each joint's bus voltage).
    """
    with as_usage():
        options = IdentifyOptions(
            method=method,
            friction=friction_option(friction),
            target=target,
            solver=solver,
            ridge=ridge,
        )
    r = load_robot(robot_name)
    with progress() as say:
        if payload_only:
            say(f"reading {len(logs)} log(s) and identifying the payload")
            run = api.identify_payload(logs, r, out=out, reading=reading)
        else:
            result = api.identify(logs, r, options, reading=reading, out=out, progress=say)
    if payload_only:
        tell(run.notes, run.warnings)
        click.echo(json_result(run) if as_json else _payload_text(run.payload, out))
        return
    tell(result.notes, result.warnings)
    click.echo(json_result(result) if as_json else _result_text(result, len(logs), out))
