"""``kinergy energy``: what a logged or planned motion draws from the arm's supply, per joint
mechanical and electrical energy, and the log's measured supply energy beside the prediction."""

from __future__ import annotations

import math

import click

from kinergy import api
from kinergy.accounting.uncertainty import NO_UNCERTAINTY
from kinergy.cli.common import (
    as_usage,
    choice_of,
    json_result,
    prose,
    reading_options,
    swapped,
    table,
    tell,
    writes,
)
from kinergy.logs.reading import LogReading

__all__ = ["energy", "energy_text"]

_PARTS = ("inertial", "gravity", "friction", "copper")


def _row(
    name: str,
    e_mech: float,
    e_elec: float,
    efficiency: float,
    mean_power: float,
    peak_power: float,
    parts: dict[str, float],
) -> list[str]:
    eff = "-" if not math.isfinite(efficiency) else f"{100 * efficiency:.1f}"
    return [
        name,
        f"{e_mech:.1f}",
        f"{e_elec:.1f}",
        eff,
        f"{mean_power:.1f}",
        f"{peak_power:.1f}",
        *(f"{parts[k]:.1f}" for k in _PARTS),
    ]


def _supply_lines(result: api.LogEnergy) -> list[str]:
    """What the arm draws from its supply, predicted and (where logged) measured."""
    sup, measured = result.supply, result.measured
    share = f", {100 * sup.standby / sup.drawn:.0f} % of it" if sup.drawn > 0 else ""
    lines = [
        f"Drawn from the arm's supply: {sup.drawn:.1f} J predicted = motors {sup.motors:.1f} J"
        f" + standing draw {sup.standby:.1f} J ({sup.standby_power:.3g} W for "
        f"{result.duration:.1f} s{share}); {sup.shunt:.1f} J of braking burnt in the shunt, "
        f"not drawn. Mean {sup.mean_power:.1f} W, peak {sup.peak_power:.1f} W.",
    ]
    lines += _interval_lines(result)
    if measured is not None:
        error = result.measured_dict().get("error")
        lines.append(
            f"Measured by the log: {measured.drawn:.1f} J (mean {measured.mean_power:.1f} W)"
            + ("" if error is None else f"; predicted {error:+.1f} %")
            + "."
        )
    lines += [f"  predicted: {sup.includes}."]
    if measured is not None:
        lines.append(f"  measured: {measured.includes}.")
    return lines


def _interval_lines(result: api.LogEnergy) -> list[str]:
    """The 95 % intervals from the model's parameter errors, or why there are none."""
    iv = result.intervals
    if iv is None:
        return [f"95 % interval: none: {NO_UNCERTAINTY}."]
    drawn, motors = iv.drawn, iv.motors
    total = result.supply.drawn
    share = f" (±{100 * drawn.half_width / total:.1f} %)" if total else ""
    joints = ", ".join(
        f"{name} {e.low:.1f}..{e.high:.1f}"
        for name, e in zip(result.joints, iv.e_elec, strict=True)
    )
    return [
        f"95 % interval: drawn {drawn.low:.1f}..{drawn.high:.1f} J{share}, motors "
        f"{motors.low:.1f}..{motors.high:.1f} J; E_elec {joints} J ({drawn.method}).",
    ]


def energy_text(result: api.LogEnergy) -> str:
    """The ``energy`` answer: what the arm draws from its supply (predicted, and measured where
    logged), then one row per joint and the total, with what each figure includes."""
    r, duration = result, result.duration
    rows = [
        _row(
            name,
            r.e_mech[i],
            r.e_elec[i],
            r.efficiency[i],
            r.e_elec[i] / duration,
            r.peak_power[i],
            {k: v[i] for k, v in r.breakdown.items()},
        )
        for i, name in enumerate(r.joints)
    ]
    rows.append(
        _row(
            "total",
            r.total_e_mech,
            r.total_e_elec,
            r.total_efficiency,
            r.total_e_elec / duration,
            r.bus_peak,
            {k: v.sum() for k, v in r.breakdown.items()},
        )
    )
    head = f"{r.robot}: {duration:.3f} s, {r.samples} samples; " + (
        "signed integrals (braking energy returns to the bus)"
        if r.recovery
        else "no recovery (negative power clipped)"
    )
    headers = ["joint", "E_mech [J]", "E_elec [J]", "eta [%]", "mean P [W]", "peak P [W]"]
    headers += [f"{k} [J]" for k in _PARTS]
    if r.segments > 1:
        head += f"\n{r.segments} segments; gaps of {r.span - duration:.3f} s not integrated."
    lines = [
        prose(head),
        *(prose(line) for line in _supply_lines(result)),
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
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
@click.option(
    "--no-recovery", is_flag=True, help="Clip negative power: the supply takes no energy back."
)
@click.option(
    "--source",
    type=choice_of(api.MotionSource),
    default=api.MotionSource.AUTO.value,
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
@reading_options("columns", "repair", "accept", "topic", "effort", "payload", "start", "stop")
@writes(files=("trace", "plot"), inputs=("model", "motion_path"))
def energy(
    model: str,
    motion_path: str,
    as_json: bool,
    no_recovery: bool,
    source: api.MotionSource,
    trace: str | None,
    plot: str | None,
    reading: LogReading,
) -> None:
    """What a logged or planned motion draws from the arm's supply, and per-joint mechanical and
    electrical energy; a log's measured supply energy beside the prediction.

    MODEL is a built-in name or a model file; LOG_OR_MOTION a log (record.py layout, or headerless
    with --columns), a motion file, a URScript program (.script) or a built-in motion (test-a,
    test-b: the UR5e doc's tests A and B planned for MODEL).
    """
    swapped(model, [motion_path])
    with as_usage():
        options = api.EnergyOptions(source=source, recovery=not no_recovery)
    result = api.energy(model, motion_path, options, reading=reading, trace=trace, plot=plot)
    assert isinstance(result, api.LogEnergy)  # a file or a built-in motion, not a Motion
    tell(result.notes, result.warnings)
    click.echo(json_result(result) if as_json else energy_text(result))
