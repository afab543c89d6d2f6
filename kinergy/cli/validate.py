"""``kinergy validate``: torque (UR5e Table V) and current (Table VII) errors of a model on logs."""

from __future__ import annotations

from collections.abc import Sequence

import click

from kinergy.cli.common import (
    columns_option,
    load,
    note,
    payload_option,
    repair_option,
    table,
    writes,
)
from kinergy.identify.metrics import JointMetrics
from kinergy.identify.result import Validation
from kinergy.jsonable import dumps
from kinergy.workflows.logs import prepared_logs
from kinergy.workflows.validate import validate_logs

__all__ = ["validate", "validation_text"]


def _metrics_table(metrics: Sequence[JointMetrics], names: Sequence[str], unit: str) -> str:
    return table(
        ["joint", f"mean [{unit}]", f"max [{unit}]", f"RMS [{unit}]", "R^2"],
        [
            [name, f"{m.mean:.4f}", f"{m.max:.4f}", f"{m.rms:.4f}", f"{m.r2:.4f}"]
            for name, m in zip(names, metrics, strict=True)
        ],
    )


def validation_text(report: Validation, names: Sequence[str]) -> str:
    """The torque, current and joint-torque tables of a validation report ('' when it has none)."""
    parts = []
    for metrics, title, unit in (
        (report.torque, "Torque against target_moment (UR5e Table V)", "N m"),
        (report.current, "Current against actual_current (UR5e Table VII)", "A"),
        (report.joint_torque, "Joint torque against measured torque", "N m"),
    ):
        if metrics:
            parts += [title, _metrics_table(metrics, names, unit), ""]
    return "\n".join(parts).rstrip()


@click.command()
@click.argument("model", metavar="MODEL")
@click.argument("logs", metavar="LOG...", nargs=-1, required=True)
@columns_option
@click.option("--json", "as_json", is_flag=True, help="Print JSON (DESIGN.md shape).")
@click.option(
    "--plots",
    "plots",
    type=click.Path(file_okay=False),
    default=None,
    help="Write plots (measured vs predicted, error box plots) to this folder.",
)
@click.option(
    "--cutoff",
    type=click.FloatRange(0.0, 1e6, min_open=True),
    help="Low-pass cutoff for measured speeds, Hz.",
)
@payload_option
@repair_option
@writes(into=("plots",), inputs=("model", "logs"))
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
    r = load(model, payload)
    datas = prepared_logs(
        logs, n_joints=r.n, columns=columns, repair=repair, cutoff=cutoff, note=note
    )
    report = validate_logs(r, datas, plots=plots)
    if as_json:
        click.echo(dumps(report))
        return
    click.echo(f"{r.name} on {', '.join(logs)}\n")
    text = validation_text(report, r.joint_names)
    click.echo(
        text or "the logs have neither target_moment nor actual_current nor measured torques"
    )
    if plots:
        click.echo(f"\nplots in {plots}")
