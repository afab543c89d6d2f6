"""``kinergy validate``: torque (UR5e Table V) and current (Table VII) errors of a model on logs."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import click
import numpy as np

from kinergy import api
from kinergy.cli.common import (
    json_result,
    prose,
    reading_options,
    swapped,
    table,
    tell,
    writes,
)
from kinergy.identification.metrics import JointMetrics
from kinergy.identification.result import Validation
from kinergy.identification.validation import (
    HOLD_SECONDS,
    HOLD_SPEED,
    SignalMetrics,
    ValidationReport,
)
from kinergy.logs.reading import LogReading
from kinergy.model import load_robot

__all__ = ["band_text", "report_text", "supply_text", "validate", "validation_text"]


def _r2(m: JointMetrics) -> str:
    note = m.note if isinstance(m, SignalMetrics) else None
    return note or (f"{m.r2:.4f}" if np.isfinite(m.r2) else "signal constant")


def _metrics_table(metrics: Sequence[JointMetrics], names: Sequence[str], unit: str) -> str:
    normalised = all(isinstance(m, SignalMetrics) for m in metrics)
    headers = ["joint", f"mean [{unit}]", f"max [{unit}]", f"RMS [{unit}]"]
    rows = []
    for name, m in zip(names, metrics, strict=True):
        row = [name, f"{m.mean:.4f}", f"{m.max:.4f}", f"{m.rms:.4f}"]
        if isinstance(m, SignalMetrics) and normalised:
            row.append(f"{m.nrms:.3f}")
        rows.append([*row, _r2(m)])
    return table(headers + (["NRMS"] if normalised else []) + ["R²"], rows)


#: the tables of a validation: field, title, unit
_TABLES = (
    ("torque", "Torque against target_moment (UR5e Table V)", "N m"),
    ("current", "Current against actual_current (UR5e Table VII)", "A"),
    ("joint_torque", "Joint torque against measured torque", "N m"),
)


def validation_text(report: Validation, names: Sequence[str]) -> str:
    """The torque, current and joint-torque tables of a validation report ('' when it has none)."""
    parts = []
    for key, title, unit in _TABLES:
        metrics = getattr(report, key)
        if metrics:
            parts += [title, _metrics_table(metrics, names, unit), ""]
    return "\n".join(parts).rstrip()


def _per_log_text(report: ValidationReport, names: Sequence[str]) -> str:
    """Per log and signal: R^2 per joint while moving, and the RMS while holding."""
    parts = []
    for key, title, unit in _TABLES:
        rows = []
        for log in report.logs:
            moving = getattr(log.moving, key) if log.moving else None
            holding = getattr(log.holding, key) if log.holding else None
            if moving is None and holding is None:
                continue
            none = [None] * len(names)
            cells = [
                (_r2(m) if m is not None else "-") + (f" / {h.rms:.3g}" if h is not None else "")
                for m, h in zip(moving or none, holding or none, strict=True)
            ]
            rows.append([Path(log.log).stem, f"{log.holding_fraction:.0%}", *cells])
        if rows:
            parts += [
                f"{title}: R² while moving / RMS [{unit}] while holding",
                table(["log", "holding", *names], rows),
                "",
            ]
    return "\n".join(parts).rstrip()


def supply_text(report: ValidationReport) -> str:
    """The supply's power and energy, predicted against measured ('' where no log measures it)."""
    s = report.supply
    if s is None:
        return ""
    return (
        f"Supply power against actual_robot_voltage x actual_robot_current ({s.samples} samples):"
        f" RMSE {s.rms:.2f} W, R² {s.r2:.4f}, mean error {s.mean:+.2f} W; energy predicted "
        f"{s.predicted:.1f} J against {s.measured:.1f} J measured ({s.error:+.1f} %). Predicted: "
        "the motors summed on the DC bus plus the model's standing draw."
    )


def band_text(report: ValidationReport, names: Sequence[str]) -> str:
    """The 95 % prediction band per signal and joint: its mean half-width, the share of the
    measured samples inside it, the RMS error with its spread across the model's error modes;
    or why there is none."""
    band = report.band
    if band is None:
        return ""
    if band.note is not None:
        return f"95 % prediction band: {band.note}"
    parts = [prose(f"95 % prediction band: {band.method}.")]
    for key, title, unit in _TABLES:
        b = getattr(band, key, None)
        if b is None:
            continue
        rows = [
            [name, f"±{h:.4f}", f"{inside:.1%}", f"{rms:.4f} ± {std:.2g}", f"{r2:.2g}"]
            for name, h, inside, rms, std, r2 in zip(
                names, b.half_width, b.inside, b.rms, b.rms_std, b.r2_std, strict=True
            )
        ]
        parts += [
            f"{title.split(' (')[0]} ({b.samples} samples)",
            table(
                ["joint", f"band [{unit}]", "measured inside", f"RMS [{unit}] ± std", "R² std"],
                rows,
            ),
        ]
    return "\n".join(parts)


def report_text(report: ValidationReport, names: Sequence[str]) -> str:
    """``validate``'s text: pooled tables, the supply, the moving and holding segments, and
    each log."""
    text = validation_text(report, names)
    if not text:
        return "the logs have neither target_moment nor actual_current nor measured torques"
    lines = [
        f"{report.samples} samples, {report.holding_fraction:.0%} in static holds (every joint "
        f"below {HOLD_SPEED} rad/s for {HOLD_SECONDS} s or more)\n",
        text,
    ]
    if supply := supply_text(report):
        lines += ["", prose(supply)]
    if band := band_text(report, names):
        lines += ["", band]
    for label, part in (("moving", report.moving), ("holding", report.holding)):
        if part is not None and report.moving is not None and report.holding is not None:
            lines += [f"\n--- {label} samples only ---", validation_text(part, names)]
    if len(report.logs) > 1:
        lines += ["\n--- per log ---", _per_log_text(report, names)]
    return "\n".join(lines)


@click.command()
@click.argument("model", metavar="MODEL")
@click.argument("logs", metavar="LOG...", nargs=-1, required=True)
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
@click.option(
    "--plots",
    "plots",
    type=click.Path(file_okay=False),
    default=None,
    help="Write plots (measured vs predicted with the 95 % band where the model has one, error "
    "box plots) to this folder (new, empty, or one kinergy wrote: it is replaced whole).",
)
@reading_options()
@writes(folders=("plots",), inputs=("model", "logs"))
def validate(
    model: str,
    logs: tuple[str, ...],
    as_json: bool,
    plots: str | None,
    reading: LogReading,
) -> None:
    """How well a model predicts logs: torque (UR5e Table V) and current (Table VII) errors and R^2.

    A model identified from logs (its [uncertainty] table) also gets a 95 % prediction band on
    the current and the reference torque: the share of the measured samples inside it, and the
    RMS error's spread across the model's error modes; a built-in model says "no interval".

    A LOG may also be a built-in motion (test-a, test-b): the log the realistic twin of MODEL
    writes running it (a simulated robot that differs from the model as a real arm does).
    """
    swapped(model, logs)
    r = load_robot(model)
    report = api.validate(r, logs, reading=reading, plots=plots)
    tell(report.notes, report.warnings)
    if as_json:
        click.echo(json_result(report))
        return
    click.echo(f"{r.name} on {', '.join(logs)}\n")
    click.echo(report_text(report, r.joint_names))
    if plots:
        click.echo(f"\nplots in {plots}")
