"""The fleet report: one HTML page from a fleet's results (:class:`kinergy.fleet.summary.FleetResult`).

An overview (every robot's logs, cycles, energy, measured against the model, where the energy
goes, drift and step changes; a figure of every robot's energy per cycle by day), then a section
per robot: what was found, its days as a table, and a figure of its energy and of the motor work
friction takes per cycle by day, each step change marked. Written with
:func:`kinergy.report.html.write_report` into a folder built beside its target and renamed into
place (:func:`kinergy.files.atomic_folder`); figures are PNGs in ``figures/``.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure as MplFigure

from kinergy.files import atomic_folder
from kinergy.fleet.summary import FleetResult, RobotSummary
from kinergy.report.html import Figure, Section, Table, write_report
from kinergy.report.plots import save

__all__ = ["fleet_figure", "robot_figure", "write_fleet_report"]

_PARTS = ("inertial", "gravity", "friction", "copper", "standby", "shunt")


def _canvas(width: float, height: float, rows: int = 1) -> tuple[MplFigure, list]:
    fig = MplFigure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    axes = list(np.atleast_1d(fig.subplots(rows, 1, sharex=True)))
    for ax in axes:
        ax.tick_params(labelsize=9)
        ax.grid(True, linewidth=0.5, alpha=0.4)
    return fig, axes


def fleet_figure(result: FleetResult) -> MplFigure:
    """Every robot's energy per cycle by day (measured, else predicted), drifting ones bold."""
    fig, (ax,) = _canvas(10.0, 4.5)
    for robot in result.robots:
        days = [d.date for d in robot.days if d.energy_per_cycle_J is not None]
        values = [d.energy_per_cycle_J for d in robot.days if d.energy_per_cycle_J is not None]
        style = (
            {"linewidth": 2.4, "marker": "o"} if robot.drift else {"linewidth": 1.0, "alpha": 0.7}
        )
        label = f"{robot.name} (drift)" if robot.drift else robot.name
        ax.plot(days, values, label=label, **style)
    ax.set_ylabel("Energy per cycle [J]", fontsize=10)
    ax.set_title("Energy per cycle by day, every robot", fontsize=11)
    ax.legend(fontsize=8, ncols=2, loc="best")
    fig.autofmt_xdate()
    return fig


def robot_figure(robot: RobotSummary) -> MplFigure:
    """One robot's energy per cycle (measured and model) and motor work per cycle by day."""
    fig, axes = _canvas(10.0, 6.0, rows=2)
    days = [d.date for d in robot.days]

    def series(name: str) -> list[float]:
        return [np.nan if getattr(d, name) is None else getattr(d, name) for d in robot.days]

    axes[0].plot(
        days, series("energy_per_cycle_J"), "o-", color="tab:green", label="measured (supply)"
    )
    axes[0].plot(days, series("predicted_per_cycle_J"), "s--", color="tab:orange", label="model")
    axes[0].set_ylabel("Energy per cycle [J]", fontsize=10)
    axes[1].plot(days, series("motor_work_per_cycle_J"), "o-", color="tab:red", label="motor work")
    axes[1].set_ylabel("Motor work per cycle [J]", fontsize=10)
    for change in robot.changes:
        for ax in axes:
            ax.axvline(change.date, color="0.3", linestyle=":", linewidth=1.2)
    axes[0].legend(fontsize=9)
    verdict = "drift" if robot.drift else "no drift"
    axes[0].set_title(f"{robot.name}: {verdict}, {len(robot.changes)} step change(s)", fontsize=11)
    fig.autofmt_xdate()
    return fig


def _kj(x: float | None) -> str:
    return "-" if x is None else f"{x / 1e3:.2f}"


def _overview(result: FleetResult) -> Section:
    rows, parts = [], []
    for r in result.robots:
        ratio = "-" if not r.measured_J else f"{r.predicted_J / r.measured_J:.4f}"
        rows.append(
            [r.name, r.model, str(r.logs), str(r.cycles), _kj(r.energy_J), ratio,
             "yes" if r.drift else "no", str(len(r.changes))]
        )  # fmt: skip
        parts.append([r.name, *(_kj(r.breakdown_J[k]) for k in _PARTS)])
    robots = Table(
        "Robots",
        ["Robot", "Model", "Logs", "Cycles", "Energy [kJ]", "Model / measured", "Drift", "Changes"],
        rows,
        note="Energy is the supply's (voltage x current) where logged, else the model's.",
    )
    breakdown = Table(
        "Where the energy goes (model), per robot",
        ["Robot", *(f"{k} [kJ]" for k in _PARTS)],
        parts,
        note="Joint electrical energy split as in framework Fig. 4, plus standby and the braking surplus burnt in the shunt.",
    )
    drifting = [r.name for r in result.robots if r.drift] or ["none"]
    text = (
        f"{result.logs} logs of {len(result.robots)} robots analysed on {result.workers} Dask "
        f"worker(s) in {result.seconds:.1f} s; {len(result.skipped)} skipped.\n\n"
        f"Drifting (energy or friction per cycle rising beyond its own spread): "
        f"{', '.join(drifting)}."
    )
    return Section(
        "Fleet",
        text,
        tables=[robots, breakdown],
        figures=[Figure("figures/fleet.png", "Energy per cycle by day.")],
    )


def _robot_section(robot: RobotSummary, figure: str) -> Section:
    lines = []
    for p in robot.programs:
        period = "-" if p.period is None else f"{p.period:.2f} s"
        lines.append(
            f"Program {p.program} (period {period}, {p.cycles} cycles): energy per cycle rose "
            f"{100 * p.energy_rise:.1f} %, motor work {100 * p.friction_rise:.1f} % "
            f"({'drift' if p.energy_drift or p.friction_drift else 'no drift'})."
        )
    for c in robot.changes:
        lines.append(
            f"Step change of {c.metric} on {c.date} in program {c.program}: "
            f"{c.before:.1f} -> {c.after:.1f} J ({100 * c.relative:+.1f} %), a change, not drift."
        )
    days = Table(
        f"{robot.name} by day",
        ["Date", "Logs", "Cycles", "Energy [J]", "Measured [J]", "Model [J]", "Energy/cycle [J]",
         "Motor work/cycle [J]"],
        [
            [str(d.date), str(d.logs), str(d.cycles), f"{d.energy_J:.1f}",
             "-" if d.measured_J is None else f"{d.measured_J:.1f}", f"{d.predicted_J:.1f}",
             "-" if d.energy_per_cycle_J is None else f"{d.energy_per_cycle_J:.2f}",
             "-" if d.motor_work_per_cycle_J is None else f"{d.motor_work_per_cycle_J:.2f}"]
            for d in robot.days
        ],
    )  # fmt: skip
    caption = f"{robot.name}: energy and motor work per cycle by day (dotted: step changes)."
    return Section(robot.name, "\n\n".join(lines), tables=[days], figures=[Figure(figure, caption)])


def write_fleet_report(result: FleetResult, folder: str | os.PathLike[str]) -> Path:
    """Write ``folder/report.html`` and its figures; return the page's path.

    The folder is built beside its target and renamed into place: a failure leaves the old
    report as it was.
    """
    target = Path(folder)
    with atomic_folder(target) as building:
        save(fleet_figure(result), building / "figures" / "fleet.png")
        sections = [_overview(result)]
        for k, robot in enumerate(result.robots):
            name = f"figures/robot-{k + 1:03d}.png"
            save(robot_figure(robot), building / name)
            sections.append(_robot_section(robot, name))
        write_report(
            building / "report.html",
            title="Fleet energy",
            subtitle=f"{len(result.robots)} robots, {result.logs} logs",
            sections=sections,
            meta={"robots": str(len(result.robots)), "logs": str(result.logs)},
        )
    return target / "report.html"
