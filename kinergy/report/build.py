"""The study report: an identified model, how well it predicts logs, and the energy of motions,
as tables (UR5e doc Tables IV-VIII) and figures (Figs 8-15, framework Fig. 4) in an HTML page.

:func:`report_sections` computes everything and makes the figures; the same tables are printed
by ``kinergy demo`` and ``kinergy report`` and laid out in ``report.html`` by
:func:`kinergy.report.html.write_report`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from kinergy.energy.accounting import EnergyReport, energy
from kinergy.identify.metrics import JointMetrics, fit_metrics
from kinergy.identify.preprocess import IdentData
from kinergy.identify.result import IdentificationResult, predict
from kinergy.model.robot import Robot
from kinergy.report import seed
from kinergy.report.html import Figure, Section, Table
from kinergy.trajectory.motion import Motion

__all__ = ["StudyInputs", "report_sections"]


@dataclass
class StudyInputs:
    """What a report is made of.

    Attributes
    ----------
    model : Robot
        The model the report is about (identified, or the user's).
    validation : mapping of str to IdentData
        Logs to compare the model with, by name (``"test A"``).
    motions : mapping of str to Motion
        Motions to account the energy of, by name.
    result : IdentificationResult, optional
        The identification that produced ``model``.
    truth : Robot, optional
        The model a twin was built with, to compare identified parameters against.
    paper : bool
        Compare with the UR5e doc's tables (its tests A and B: names ``"test A"``, ``"test B"``).
    task : kinergy.io.task.Task, optional
        A movej program whose energy-optimal timing (and Pareto front) the report shows.
    """

    model: Robot
    validation: Mapping[str, IdentData] = field(default_factory=dict)
    motions: Mapping[str, Motion] = field(default_factory=dict)
    result: IdentificationResult | None = None
    truth: Robot | None = None
    paper: bool = False
    task: Any = None


def _f(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}f}"


def _e(x: float) -> str:
    return f"{x:.4e}"


def _paper_key(name: str) -> str | None:
    key = name.replace("test", "").replace("-", "").strip().upper()
    return key if key in ("A", "B") else None


def _parameter_tables(inputs: StudyInputs) -> list[Table]:
    model, truth = inputs.model, inputs.truth
    names = model.joint_names
    inertia_rows, friction_rows = [], []

    def pair(value: str, twin: str | None) -> str:
        return value if twin is None else f"{value} ({twin})"

    for j, joint in enumerate(model.joints):
        d = joint.drive
        t = truth.joints[j].drive if truth is not None else None
        row = [names[j], _e(d.motor_inertia), _e(d.reducer_inertia), _e(d.rotor_inertia)]
        if t is not None:
            row += [_e(t.motor_inertia), f"{100 * (d.rotor_inertia / t.rotor_inertia - 1):+.2f}"]
        inertia_rows.append(row)
        params = d.friction.params
        tp = t.friction.params if t is not None and t.friction.model == d.friction.model else None
        if d.friction.model == "power_flow":
            cells = [
                pair(_e(params["viscous"]), None if tp is None else _e(tp["viscous"])),
                pair(
                    _f(params["coulomb_direct"]), None if tp is None else _f(tp["coulomb_direct"])
                ),
                pair(
                    _f(params["coulomb_reverse"]), None if tp is None else _f(tp["coulomb_reverse"])
                ),
            ]
        else:
            cells = [" ".join(f"{k}={v:.4g}" for k, v in params.items()), "", ""]
        kt = pair(_f(d.torque_constant), None if t is None else _f(t.torque_constant))
        friction_rows.append([names[j], d.friction.model, *cells, kt])
    inertia_headers = ["joint", "J_m [kg m²]", "J_r [kg m²]", "J_m + J_r [kg m²]"]
    friction_headers = [
        "joint",
        "friction model",
        "k_v [N m s/rad]",
        "T_c dir [N m]",
        "T_c rev [N m]",
        "k_t [N m/A]",
    ]
    note_iv = "Motor side. J_r from the reducer catalogue; J_m = identified (J_m + J_r) - J_r."
    note_vi = "Motor side (UR5e eqs 11-17)."
    if truth is not None:
        inertia_headers += ["twin J_m (Table IV)", "J_m + J_r error [%]"]
        note_iv += " The twin was built with the UR5e doc's Table IV."
        note_vi += " In brackets: the value the twin was built with (the UR5e doc's Table VI)."
    return [
        Table("Motor and reducer inertia (UR5e Table IV)", inertia_headers, inertia_rows, note_iv),
        Table(
            "Friction and torque constants (UR5e Table VI)",
            friction_headers,
            friction_rows,
            note_vi,
        ),
    ]


def _accuracy_tables(
    caption: str,
    unit: str,
    metrics: Mapping[str, Sequence[JointMetrics]],
    names: list[str],
    paper: Mapping[str, list[tuple[float, float, float, float]]] | None,
) -> list[Table]:
    """One table per log: mean, max, RMS error and R^2 per joint, with the paper's R^2."""
    out = []
    for test, m in metrics.items():
        key = _paper_key(test) if paper is not None else None
        headers = ["joint", f"mean [{unit}]", f"max [{unit}]", f"RMS [{unit}]", "R²"]
        if key:
            headers += ["RMS (paper)", "R² (paper)"]
        rows = []
        for j, name in enumerate(names):
            row = [name, _f(m[j].mean), _f(m[j].max), _f(m[j].rms), _f(m[j].r2)]
            if key and paper is not None:
                row += [_f(paper[key][j][2], 3), _f(paper[key][j][3], 3)]
            rows.append(row)
        note = "Error = measured - model; R² is the coefficient of determination."
        if key:
            note += f" 'paper': the UR5e doc's value on its own (real) test {key}."
        out.append(Table(f"{caption}, {test}", headers, rows, note))
    return out


def _energy_tables(reports: Mapping[str, EnergyReport], paper: bool) -> list[Table]:
    out = []
    for test, rep in reports.items():
        key = _paper_key(test) if paper else None
        headers = ["joint", "E_mech [J]", "E_elec [J]", "η [%]"]
        if key:
            headers += ["E_mech (paper)", "E_elec (paper)", "η (paper) [%]"]
        rows = []
        for j, name in enumerate(rep.joints):
            row = [
                name,
                f"{rep.e_mech[j]:.1f}",
                f"{rep.e_elec[j]:.1f}",
                f"{100 * rep.efficiency[j]:.1f}",
            ]
            if key:
                pm, pe = seed.TABLE_VIII[key][j]
                row += [f"{pm:.1f}", f"{pe:.1f}", f"{100 * pm / pe:.1f}"]
            rows.append(row)
        total = [
            "overall",
            f"{rep.total_e_mech:.1f}",
            f"{rep.total_e_elec:.1f}",
            f"{100 * rep.total_efficiency:.2f}",
        ]
        if key:
            total += [
                f"{sum(r[0] for r in seed.TABLE_VIII[key]):.1f}",
                f"{sum(r[1] for r in seed.TABLE_VIII[key]):.1f}",
                f"{100 * seed.TABLE_VIII_EFFICIENCY[key]:.2f}",
            ]
        rows.append(total)
        note = f"{rep.duration:.1f} s. UR5e eqs 23-26: signed integrals, braking energy returns to the DC bus."
        if key:
            note += (
                f" 'paper': the UR5e doc's Table VIII for its own test {key}, whose six random points"
                " it does not publish: compare the efficiencies, not the joules per joint."
            )
        out.append(
            Table(
                f"Mechanical and electrical energy (UR5e Table VIII), {test}", headers, rows, note
            )
        )
    return out


def _breakdown_table(reports: Mapping[str, EnergyReport]) -> Table:
    headers = [
        "motion",
        "inertial [J]",
        "gravity [J]",
        "friction [J]",
        "copper [J]",
        "E_elec [J]",
        "peak power [W]",
        "mean power [W]",
    ]
    rows = []
    for name, rep in reports.items():
        b = rep.breakdown
        rows.append(
            [name]
            + [f"{float(b[k].sum()):.1f}" for k in ("inertial", "gravity", "friction", "copper")]
            + [
                f"{rep.total_e_elec:.1f}",
                f"{float(np.max(rep.p_elec.sum(axis=1))):.1f}",
                f"{rep.total_e_elec / rep.duration:.1f}",
            ]
        )
    return Table(
        "Where the electrical energy goes (framework Fig. 4)",
        headers,
        rows,
        "Each motion part (inertial, gravity, friction) includes its share of the non-copper motor "
        "losses (the k_b/k_t factor); inertial and gravity net to about zero on a cycle that returns "
        "to its start.",
    )


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() else "-" for c in name.lower()).strip("-") or "log"


def report_sections(
    inputs: StudyInputs,
    folder: Path,
    progress: Callable[[str], None] | None = None,
) -> tuple[list[Section], dict[str, list[Table]]]:
    """Compute the study and write its figures under ``folder / "figures"``.

    Returns
    -------
    sections : list of Section
        For :func:`kinergy.report.html.write_report`.
    tables : dict of str to list of Table
        The tables by key (``"IV"``, ``"V"``, ``"VI"``, ``"VII"``, ``"VIII"``, ``"breakdown"``),
        for printing.
    """
    from kinergy.report.plots import (
        energy_breakdown,
        error_boxplot,
        power_energy,
        save,
        time_series,
    )

    say = progress or (lambda _msg: None)
    figdir = folder / "figures"
    figdir.mkdir(parents=True, exist_ok=True)
    model = inputs.model
    names = model.joint_names
    tables: dict[str, list[Table]] = {}
    sections: list[Section] = []

    param_tables = _parameter_tables(inputs)
    tables["IV"], tables["VI"] = [param_tables[0]], [param_tables[1]]
    intro = (
        f"Model: {model.name}, {model.n} joints. "
        + (f"Identified by the {inputs.result.method} method. " if inputs.result else "")
        + (
            "The logs come from kinergy's digital twin, built with the UR5e doc's parameters, so "
            "identified values can be checked against the truth."
            if inputs.truth is not None
            else ""
        )
    )
    warnings = inputs.result.warnings if inputs.result else []
    text = intro + ("\n\nWarnings:\n" + "\n".join(warnings) if warnings else "")
    sections.append(Section("Identified drive parameters", text, param_tables, []))

    torque_metrics: dict[str, Sequence[JointMetrics]] = {}
    current_metrics: dict[str, Sequence[JointMetrics]] = {}
    torque_errors: dict[str, np.ndarray] = {}
    current_errors: dict[str, np.ndarray] = {}
    torque_figs: list[Figure] = []
    current_figs: list[Figure] = []
    for name, data in inputs.validation.items():
        say(f"validating on {name}")
        pred = predict(model, data)
        t = data.t - data.t[0]
        if data.tau_ref is not None and pred.torque is not None:
            torque_metrics[name] = fit_metrics(data.tau_ref, pred.torque)
            torque_errors[name] = data.tau_ref - pred.torque
            path = figdir / f"{_slug(name)}_torque.png"
            save(
                time_series(
                    t,
                    data.tau_ref,
                    pred.torque,
                    joint_names=names,
                    quantity="joint torque",
                    unit="N m",
                    measured_label="target_moment",
                    predicted_label="model",
                ),
                path,
            )
            torque_figs.append(
                Figure(
                    f"figures/{path.name}",
                    f"{name}: the controller's target_moment and the model's torque (UR5e Figs 8-9).",
                )
            )
        if data.current is not None and pred.current is not None:
            current_metrics[name] = fit_metrics(data.current, pred.current)
            current_errors[name] = data.current - pred.current
            path = figdir / f"{_slug(name)}_current.png"
            save(
                time_series(
                    t,
                    data.current,
                    pred.current,
                    joint_names=names,
                    quantity="motor current",
                    unit="A",
                    measured_label="actual_current",
                    predicted_label="model",
                ),
                path,
            )
            current_figs.append(
                Figure(
                    f"figures/{path.name}",
                    f"{name}: measured and predicted motor current (UR5e Figs 11-12).",
                )
            )
    paper = inputs.paper and model.n == 6
    if torque_metrics:
        path = figdir / "torque_errors.png"
        save(
            error_boxplot(torque_errors, joint_names=names, quantity="torque error", unit="N m"),
            path,
        )
        torque_figs.append(
            Figure(f"figures/{path.name}", "Torque errors per joint (UR5e Fig. 10).")
        )
        tables["V"] = _accuracy_tables(
            "Torque model accuracy (UR5e Table V)",
            "N m",
            torque_metrics,
            names,
            seed.TABLE_V if paper else None,
        )
        sections.append(
            Section(
                "Torque: model against target_moment",
                "The frictionless model of UR5e eq 2 (rigid body plus motor and reducer inertia) against the controller's reference torque (eq 7)."
                + (
                    " The twin's target_moment is eq 7 on its own link data, which the sequential method keeps, so"
                    " here the fit is exact to round-off; on a real arm the link data are an approximation"
                    " (the UR5e doc's R² 0.997-0.999; a real UR10e's 0.95-1.00 in the README)."
                    if inputs.truth is not None
                    else ""
                ),
                tables["V"],
                torque_figs,
            )
        )
    if current_metrics:
        path = figdir / "current_errors.png"
        save(
            error_boxplot(current_errors, joint_names=names, quantity="current error", unit="A"),
            path,
        )
        current_figs.append(
            Figure(f"figures/{path.name}", "Current errors per joint (UR5e Fig. 13).")
        )
        tables["VII"] = _accuracy_tables(
            "Current model accuracy (UR5e Table VII)",
            "A",
            current_metrics,
            names,
            seed.TABLE_VII if paper else None,
        )
        sections.append(
            Section(
                "Current: model against actual_current",
                "The full model with friction and torque constants (UR5e eq 17) against the measured motor currents.",
                tables["VII"],
                current_figs,
            )
        )

    reports: dict[str, EnergyReport] = {}
    energy_figs: list[Figure] = []
    for name, motion in inputs.motions.items():
        say(f"energy of {name}")
        rep = energy(model, motion)
        reports[name] = rep
        t = motion.t - motion.t[0]
        path = figdir / f"{_slug(name)}_power.png"
        save(power_energy(t, rep.p_elec, joint_names=names), path)
        energy_figs.append(
            Figure(
                f"figures/{path.name}",
                f"{name}: electrical power and energy per motor (UR5e Figs 14-15).",
            )
        )
        path = figdir / f"{_slug(name)}_breakdown.png"
        parts = {k: v.sum(axis=1) for k, v in rep.part_power.items()}
        save(energy_breakdown(t, parts), path)
        energy_figs.append(
            Figure(
                f"figures/{path.name}",
                f"{name}: electrical energy by where it goes (framework Fig. 4).",
            )
        )
    if reports:
        tables["VIII"] = _energy_tables(reports, paper)
        tables["breakdown"] = [_breakdown_table(reports)]
        sections.append(
            Section(
                "Energy",
                "Per-joint mechanical and electrical energy (UR5e eqs 23-26) and the efficiency E_mech / E_elec (eq 24).",
                [*tables["VIII"], *tables["breakdown"]],
                energy_figs,
            )
        )
    if inputs.task is not None:
        say(f"optimising the timing of {inputs.task.name}")
        section, table = _timing_section(model, inputs.task, figdir)
        tables["timing"] = [table]
        sections.append(section)
    return sections, tables


def _timing_section(model: Robot, task: Any, figdir: Path) -> tuple[Section, Table]:
    """Energy-optimal timing of a movej program at its own cycle time, and the Pareto front."""
    from kinergy.optimize.timing import optimize_timing, pareto_front, timing_problem
    from kinergy.report.plots import save, timing_pareto

    problem = timing_problem(model, task.waypoints, blends=task.blends)
    common: dict[str, Any] = {
        "speeds": task.speeds,
        "accels": task.accels,
        "blends": task.blends,
        "problem": problem,
    }
    result = optimize_timing(model, task.waypoints, **common)
    front = pareto_front(model, task.waypoints, points=6, **common)
    path = figdir / "pareto.png"
    save(timing_pareto(result, front), path)
    rows = []
    for label, prog in (
        ("program as written", result.program),
        ("uniform scaling", result.uniform),
        ("optimised", result.optimized),
    ):
        b = prog.breakdown
        rows.append(
            [
                label,
                f"{prog.cycle_time:.3f}",
                f"{prog.e_elec:.1f}",
                f"{b.get('friction', float('nan')):.1f}",
                f"{b.get('copper', float('nan')):.1f}",
                "yes" if prog.ok else "no",
            ]
        )
    saving = 100.0 * (1.0 - result.optimized.e_elec / result.program.e_elec)
    table = Table(
        f"Energy-optimal timing of {task.name} at the same cycle time",
        ["timing", "cycle time [s]", "E_elec [J]", "friction [J]", "copper [J]", "within limits"],
        rows,
        f"Saving {saving:.1f} % (re-simulated at 500 Hz, every speed, acceleration, torque and position limit checked at every sample).",
    )
    text = (
        f"Per-move speeds and accelerations of the movej program {task.name} that minimise the model's electrical "
        "energy at the program's own cycle time (kinergy optimize), and the energy against cycle time."
    )
    figure = Figure(
        f"figures/{path.name}",
        "Energy against cycle time: optimised timing, uniform time scaling, the program as written.",
    )
    return Section("Cutting the energy: optimal timing", text, [table], [figure]), table
