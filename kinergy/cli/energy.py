"""``kinergy energy``: what a logged or planned motion draws from the arm's supply, per joint
mechanical and electrical energy, and the log's measured supply energy beside the prediction."""

from __future__ import annotations

from typing import Any

import click

from kinergy.accounting.supply import MEASURED_INCLUDES, PREDICTED_INCLUDES
from kinergy.cli.common import (
    accept_option,
    columns_option,
    effort_option,
    json_result,
    load,
    log_reading,
    payload_option,
    prose,
    repair_option,
    swapped,
    table,
    tell,
    topic_option,
    window_options,
    writes,
)
from kinergy.workflows.energy import energy_with_outputs

__all__ = ["energy", "energy_text"]

_PARTS = ("inertial", "gravity", "friction", "copper")


def _row(name: str, e: dict[str, Any], efficiency: float | None, mean_power: float) -> list[str]:
    eff = "-" if efficiency is None else f"{100 * efficiency:.1f}"
    return [
        name,
        f"{e['e_mech']:.1f}",
        f"{e['e_elec']:.1f}",
        eff,
        f"{mean_power:.1f}",
        f"{e['peak_power']:.1f}",
        *(f"{e['breakdown'][k]:.1f}" for k in _PARTS),
    ]


def _supply_lines(report: dict[str, Any]) -> list[str]:
    """What the arm draws from its supply, predicted and (where logged) measured."""
    sup = report["supply"]
    share = f", {100 * sup['standby'] / sup['drawn']:.0f} % of it" if sup["drawn"] > 0 else ""
    lines = [
        f"Drawn from the arm's supply: {sup['drawn']:.1f} J predicted = motors {sup['motors']:.1f} J"
        f" + standing draw {sup['standby']:.1f} J ({sup['standby_power']:.3g} W for "
        f"{report['duration']:.1f} s{share}); {sup['shunt']:.1f} J of braking burnt in the shunt, "
        f"not drawn. Mean {sup['mean_power']:.1f} W, peak {sup['peak_power']:.1f} W.",
    ]
    measured = report.get("measured")
    if measured is not None:
        error = measured.get("error")
        lines.append(
            f"Measured by the log: {measured['drawn']:.1f} J (mean {measured['mean_power']:.1f} W)"
            + ("" if error is None else f"; predicted {error:+.1f} %")
            + "."
        )
    lines += [f"  predicted: {PREDICTED_INCLUDES}."]
    if measured is not None:
        lines.append(f"  measured: {MEASURED_INCLUDES}.")
    return lines


def energy_text(report: dict[str, Any]) -> str:
    """The ``energy`` answer: what the arm draws from its supply (predicted, and measured where
    logged), then one row per joint and the total, with what each figure includes."""
    rows = [_row(j["name"], j, j["efficiency"], j["mean_power"]) for j in report["joints"]]
    tot = report["total"]
    rows.append(_row("total", tot, tot["efficiency"], tot["e_elec"] / report["duration"]))
    head = f"{report['robot']}: {report['duration']:.3f} s, {report['samples']} samples; " + (
        "signed integrals (braking energy returns to the bus)"
        if report["recovery"]
        else "no recovery (negative power clipped)"
    )
    headers = ["joint", "E_mech [J]", "E_elec [J]", "eta [%]", "mean P [W]", "peak P [W]"]
    headers += [f"{k} [J]" for k in _PARTS]
    if "segments" in report:
        head += f"\n{report['segments']} segments; gaps of {report['gaps']:.3f} s not integrated."
    lines = [
        prose(head),
        *(prose(line) for line in _supply_lines(report)),
        "",
        table(headers, rows),
        "",
        "E_mech = int tau_m wm dt, E_elec = int W_elec dt (UR5e eqs 23, 25, 26); eta = E_mech / E_elec.",
        "E_elec = inertial + gravity + friction + copper (each motion part includes its k_b/k_t share).",
    ]
    return "\n".join(lines)


@click.command()
@click.argument("model", metavar="MODEL")
@click.argument("motion_path", metavar="LOG_OR_MOTION", type=click.Path())
@columns_option
@repair_option
@accept_option
@topic_option
@effort_option
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
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
@click.option(
    "--trace",
    type=click.Path(dir_okay=False),
    default=None,
    help="Write the power sample by sample: time, supply_predicted, supply_measured (where the "
    "log measures it) and each joint's electrical power, W; CSV or Parquet by the extension.",
)
@click.option(
    "--plot",
    type=click.Path(dir_okay=False),
    default=None,
    help="Draw the supply's power over time, predicted against measured, with the energy of "
    "each (PNG).",
)
@payload_option
@window_options
@writes(files=("trace", "plot"), inputs=("model", "motion_path"))
def energy(
    model: str,
    motion_path: str,
    columns: str | None,
    repair: bool,
    as_json: bool,
    no_recovery: bool,
    source: str,
    payload: str | None,
    accept: tuple[str, ...],
    topic: str | None,
    effort: str | None,
    start: float | None,
    stop: float | None,
    trace: str | None,
    plot: str | None,
) -> None:
    """What a logged or planned motion draws from the arm's supply, and per-joint mechanical and
    electrical energy; a log's measured supply energy beside the prediction.

    MODEL is a built-in name or a model file; LOG_OR_MOTION a log (record.py layout, or headerless
    with --columns), a motion file, a URScript program (.script) or a built-in motion (test-a,
    test-b: the UR5e doc's tests A and B planned for MODEL).
    """
    swapped(model, [motion_path])
    r = load(model, None)
    reading = log_reading(
        r,
        columns=columns,
        repair=repair,
        accept=accept,
        topic=topic,
        effort=effort,
        payload=payload,
        start=start,
        stop=stop,
    )
    result = energy_with_outputs(
        r, motion_path, reading, source=source, recovery=not no_recovery, trace=trace, plot=plot
    )
    tell(result.notes, result.warnings)
    report = result.to_dict()
    click.echo(json_result(report, result.inputs) if as_json else energy_text(report))
