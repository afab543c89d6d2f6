"""The study report's sections and figures, from a computed :class:`Study`.

A :class:`Study` holds results only (the model, its identification, its predictions on logs,
energy reports, an optimal timing); :mod:`kinergy.workflows.study` computes one. Here it becomes
the sections of ``report.html`` (UR5e doc Tables IV-VIII, Figs 8-15, framework Fig. 4) with their
figures written under ``folder / "figures"``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from kinergy.accounting.energy import EnergyReport
from kinergy.accounting.trace import SupplyTrace
from kinergy.arrays import Array
from kinergy.identification.metrics import JointMetrics
from kinergy.identification.result import IdentificationResult
from kinergy.model.robot import Robot
from kinergy.report import seed
from kinergy.report.html import Figure, Section, Table
from kinergy.report.plots import (
    energy_breakdown,
    error_boxplot,
    power_energy,
    save,
    supply_power,
    time_series,
    timing_pareto,
)
from kinergy.report.tables import (
    accuracy_tables,
    breakdown_table,
    energy_tables,
    parameter_tables,
    timing_table,
)

__all__ = ["Comparison", "Study", "Timing", "study_sections"]


@dataclass(frozen=True, eq=False)
class Comparison:
    """One signal of one log against the model's prediction.

    Attributes
    ----------
    t : ndarray, shape (N,)
        s from the log's start.
    measured, predicted : ndarray, shape (N, n)
    metrics : tuple of JointMetrics
    """

    t: Array
    measured: Array
    predicted: Array
    metrics: tuple[JointMetrics, ...]


@dataclass(frozen=True, eq=False)
class Timing:
    """An energy-optimal timing (:class:`kinergy.optimize.TimingResult`) and its Pareto front."""

    task: str
    result: Any
    front: Sequence[Any]


@dataclass(frozen=True, eq=False)
class Study:
    """What a study report shows: results only.

    Attributes
    ----------
    model : Robot
        The model the report is about (identified, or the user's).
    result : IdentificationResult, optional
        The identification that produced ``model``.
    truth : Robot, optional
        The model a twin was built with, to compare identified parameters against.
    paper : bool
        Compare with the UR5e doc's tables (its tests A and B: logs named ``"test A"``, ``"test B"``).
    torque, current : mapping of str to Comparison
        Per log name, the reference torque (against ``target_moment``) and the motor current
        (against ``actual_current``).
    energy : mapping of str to EnergyReport
        Per motion name.
    timing : Timing, optional
    supply : mapping of str to SupplyTrace
        Per log name, the supply's power over the log, predicted and (where logged) measured.
    """

    model: Robot
    result: IdentificationResult | None = None
    truth: Robot | None = None
    paper: bool = False
    torque: Mapping[str, Comparison] = field(default_factory=dict)
    current: Mapping[str, Comparison] = field(default_factory=dict)
    energy: Mapping[str, EnergyReport] = field(default_factory=dict)
    timing: Timing | None = None
    supply: Mapping[str, SupplyTrace] = field(default_factory=dict)


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() else "-" for c in name.lower()).strip("-") or "log"


def _figure(fig: Any, figdir: Path, name: str, caption: str) -> Figure:
    path = save(fig, figdir / name)
    return Figure(f"figures/{path.name}", caption)


def _parameters_section(study: Study) -> tuple[Section, list[Table]]:
    model = study.model
    tables = parameter_tables(model, study.truth)
    intro = (
        f"Model: {model.name}, {model.n} joints. "
        + (f"Identified by the {study.result.method} method. " if study.result else "")
        + (
            "The logs come from kinergy's digital twin, so identified values can be checked "
            "against the robot it was built with (its truth)."
            if study.truth is not None
            else ""
        )
    )
    warnings = study.result.warnings if study.result else []
    # each warning a paragraph of its own (the report joins the lines of a paragraph)
    text = "\n\n".join([intro, *(f"Warning: {w}" for w in warnings)])
    return Section("Identified drive parameters", text, tables, []), tables


#: per compared signal: plot labels, units, table caption, figure numbers in the UR5e doc
_SIGNALS = {
    "torque": {
        "quantity": "Joint torque",
        "unit": "N m",
        "label": "target_moment",
        "series": "the controller's target_moment and the model's torque (UR5e Figs 8-9).",
        "errors": "Torque errors per joint (UR5e Fig. 10).",
        "caption": "Torque model accuracy (UR5e Table V)",
        "title": "Torque: model against target_moment",
        "text": "The frictionless model of UR5e eq 2 (rigid body plus motor and reducer inertia) "
        "against the controller's reference torque (eq 7).",
    },
    "current": {
        "quantity": "Motor current",
        "unit": "A",
        "label": "actual_current",
        "series": "measured and predicted motor current (UR5e Figs 11-12).",
        "errors": "Current errors per joint (UR5e Fig. 13).",
        "caption": "Current model accuracy (UR5e Table VII)",
        "title": "Current: model against actual_current",
        "text": "The full model with friction and torque constants (UR5e eq 17) against the "
        "measured motor currents.",
    },
}

_TWIN_TORQUE_NOTE = (
    " The twin's target_moment is eq 7 on its own link data, which the sequential method keeps, so"
    " here the fit is exact to round-off; on a real arm the link data are an approximation"
    " (the UR5e doc's R² 0.997-0.999; a real UR10e's 0.95-1.00 in the README)."
)


def _same_links(model: Robot, truth: Robot) -> bool:
    """Whether the twin's truth has the model's link data (then its target_moment is the
    model's eq 7 exactly)."""
    return all(
        a.link.mass == b.link.mass
        and np.array_equal(a.link.com, b.link.com)
        and np.array_equal(a.link.inertia, b.link.inertia)
        for a, b in zip(model.joints, truth.joints, strict=True)
    )


def _accuracy_section(
    study: Study, key: str, comparisons: Mapping[str, Comparison], figdir: Path
) -> tuple[Section, list[Table]]:
    """Per log the measured-against-predicted figure, the error box plots and the accuracy
    tables of one signal (``key``: ``torque`` or ``current``)."""
    info = _SIGNALS[key]
    names = study.model.joint_names
    figures = [
        _figure(
            time_series(
                c.t,
                c.measured,
                c.predicted,
                joint_names=names,
                quantity=info["quantity"],
                unit=info["unit"],
                measured_label=info["label"],
                predicted_label="model",
            ),
            figdir,
            f"{_slug(name)}_{key}.png",
            f"{name}: {info['series']}",
        )
        for name, c in comparisons.items()
    ]
    errors = {name: c.measured - c.predicted for name, c in comparisons.items()}
    box = error_boxplot(errors, joint_names=names, quantity=key, unit=info["unit"])
    figures.append(_figure(box, figdir, f"{key}_errors.png", info["errors"]))
    paper = study.paper and study.model.n == 6
    published = seed.TABLE_V if key == "torque" else seed.TABLE_VII
    tables = accuracy_tables(
        info["caption"],
        info["unit"],
        {name: c.metrics for name, c in comparisons.items()},
        names,
        published if paper else None,
    )
    exact = study.truth is not None and _same_links(study.model, study.truth)
    text = info["text"] + (_TWIN_TORQUE_NOTE if key == "torque" and exact else "")
    return Section(info["title"], text, tables, figures), tables


def _energy_section(study: Study, figdir: Path) -> tuple[Section, list[Table], list[Table]]:
    figures = []
    for name, rep in study.energy.items():
        t = rep.t - rep.t[0]
        figures.append(
            _figure(
                power_energy(t, rep.p_elec, joint_names=study.model.joint_names),
                figdir,
                f"{_slug(name)}_power.png",
                f"{name}: electrical power and energy per motor (UR5e Figs 14-15).",
            )
        )
        parts = {k: v.sum(axis=1) for k, v in rep.part_power.items()}
        figures.append(
            _figure(
                energy_breakdown(t, parts),
                figdir,
                f"{_slug(name)}_breakdown.png",
                f"{name}: electrical energy by where it goes (framework Fig. 4).",
            )
        )
    for name, trace in study.supply.items():
        measured = "against the measured (actual_robot_voltage x actual_robot_current)"
        figures.append(
            _figure(
                supply_power(
                    trace.t,
                    trace.predicted,
                    energy=trace.energy,
                    measured=trace.measured,
                    measured_energy=trace.measured_energy,
                    standing=trace.standing,
                ),
                figdir,
                f"{_slug(name)}_supply.png",
                f"{name}: the power drawn from the arm's supply, predicted (the motors on the DC "
                f"bus plus the standing draw){'' if trace.measured is None else ' ' + measured}.",
            )
        )
    viii = energy_tables(study.energy, study.paper and study.model.n == 6)
    breakdown = [breakdown_table(study.energy)]
    text = (
        "Per-joint mechanical and electrical energy (UR5e eqs 23-26) and the efficiency "
        "E_mech / E_elec (eq 24)."
    )
    return Section("Energy", text, [*viii, *breakdown], figures), viii, breakdown


def _timing_section(timing: Timing, figdir: Path) -> tuple[Section, Table]:
    table = timing_table(timing.result, timing.task)
    figure = _figure(
        timing_pareto(timing.result, timing.front),
        figdir,
        "pareto.png",
        "Energy against cycle time: optimised timing, uniform time scaling, the program as written.",
    )
    text = (
        f"Per-move speeds and accelerations of the movej program {timing.task} that minimise the "
        "model's electrical energy at the program's own cycle time (kinergy optimize), and the "
        "energy against cycle time."
    )
    return Section("Cutting the energy: optimal timing", text, [table], [figure]), table


def study_sections(study: Study, folder: Path) -> tuple[list[Section], dict[str, list[Table]]]:
    """The report's sections, with their figures written under ``folder / "figures"``.

    Returns
    -------
    sections : list of Section
        For :func:`kinergy.report.html.write_report`.
    tables : dict of str to list of Table
        The tables by key (``"IV"``, ``"V"``, ``"VI"`` (one per friction model), ``"VII"``,
        ``"VIII"``, ``"breakdown"``, ``"timing"``), for printing.
    """
    figdir = folder / "figures"
    figdir.mkdir(parents=True, exist_ok=True)
    section, (iv, *vi) = _parameters_section(study)
    sections, tables = [section], {"IV": [iv], "VI": vi}
    for key, number in (("torque", "V"), ("current", "VII")):
        comparisons = getattr(study, key)
        if comparisons:
            section, tables[number] = _accuracy_section(study, key, comparisons, figdir)
            sections.append(section)
    if study.energy:
        section, tables["VIII"], tables["breakdown"] = _energy_section(study, figdir)
        sections.append(section)
    if study.timing is not None:
        section, table = _timing_section(study.timing, figdir)
        sections.append(section)
        tables["timing"] = [table]
    return sections, tables
