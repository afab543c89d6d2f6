"""The study's tables (UR5e doc Tables IV-VIII, the energy breakdown, optimal timing) from results.

Every function takes computed results (a robot, metrics, energy reports, a timing result) and
returns :class:`~kinergy.report.html.Table` s of formatted cells; ``kinergy demo`` and
``kinergy report`` print them, ``report.html`` lays them out.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from kinergy.accounting.energy import EnergyReport
from kinergy.friction.model import FrictionModel
from kinergy.identification.metrics import JointMetrics
from kinergy.model.robot import Robot
from kinergy.report import seed
from kinergy.report.html import Table

__all__ = [
    "accuracy_tables",
    "breakdown_table",
    "energy_tables",
    "friction_table",
    "parameter_tables",
    "timing_table",
]


def _f(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}f}"


def _e(x: float) -> str:
    return f"{x:.4e}"


def _paper_key(name: str) -> str | None:
    key = name.replace("test", "").replace("-", "").strip().upper()
    return key if key in ("A", "B") else None


def parameter_tables(model: Robot, truth: Robot | None = None) -> list[Table]:
    """UR5e Table IV (motor and reducer inertia) of ``model`` and its Table VI (friction and
    torque constants), one friction table per friction model the joints use, with a column per
    parameter of that model and its unit; the twin's ``truth`` in brackets where given."""
    names = model.joint_names
    inertia_rows = []
    for j, joint in enumerate(model.joints):
        d = joint.drive
        row = [names[j], _e(d.motor_inertia), _e(d.reducer_inertia), _e(d.rotor_inertia)]
        if truth is not None:
            t = truth.joints[j].drive
            row += [_e(t.motor_inertia), f"{100 * (d.rotor_inertia / t.rotor_inertia - 1):+.2f}"]
        inertia_rows.append(row)
    inertia_headers = ["joint", "J_m [kg m²]", "J_r [kg m²]", "J_m + J_r [kg m²]"]
    note_iv = "Motor side. J_r from the reducer catalogue; J_m = identified (J_m + J_r) - J_r."
    if truth is not None:
        inertia_headers += ["twin J_m (Table IV)", "J_m + J_r error [%]"]
        note_iv += " 'twin': the value the twin was built with (its true robot)."
    inertia = Table(
        "Motor and reducer inertia (UR5e Table IV)", inertia_headers, inertia_rows, note_iv
    )
    families = dict.fromkeys(joint.drive.friction.model for joint in model.joints)
    return [inertia, *(friction_table(model, family, truth) for family in families)]


def friction_table(model: Robot, family: FrictionModel, truth: Robot | None = None) -> Table:
    """UR5e Table VI for the joints of ``model`` whose friction model is ``family``: the torque
    constant, then one column per parameter of the model that any of them has (units from the
    friction registry; "-" where a joint lacks an optional one); a joint of ``truth`` with the
    same friction model in brackets."""
    joints = [j for j, joint in enumerate(model.joints) if joint.drive.friction.model is family]
    units = family.parameter_units()
    used = {p for j in joints for p in model.joints[j].drive.friction.params}
    params = [p for p in units if p in used]

    def cell(value: float | None, twin: float | None) -> str:
        text = "-" if value is None else f"{value:.4g}"
        return text if twin is None else f"{text} ({twin:.4g})"

    rows = []
    for j in joints:
        d = model.joints[j].drive
        t = truth.joints[j].drive if truth is not None else None
        twin = t.friction.params if t is not None and t.friction.model is family else {}
        rows.append(
            [
                model.joint_names[j],
                cell(d.torque_constant, None if t is None else t.torque_constant),
                *(cell(d.friction.params.get(p), twin.get(p)) for p in params),
            ]
        )
    headers = ["joint", "k_t [N m/A]", *(f"{p} [{units[p]}]" for p in params)]
    note = f"Motor side. {family.name}: {family.citation}."
    if truth is not None:
        note += " In brackets: the value the twin was built with (its true robot)."
    caption = "Friction and torque constants (UR5e Table VI)"
    if family.name != "power_flow":  # the seed's own model, UR5e Table VI
        caption += f", {family.name} friction"
    return Table(caption, headers, rows, note)


def accuracy_tables(
    caption: str,
    unit: str,
    metrics: Mapping[str, Sequence[JointMetrics]],
    names: list[str],
    paper: Mapping[str, list[tuple[float, float, float, float]]] | None,
) -> list[Table]:
    """One table per log: mean, max, RMS error and R^2 per joint, with the paper's R^2 (UR5e
    Tables V, VII) where ``paper`` holds them."""
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


def energy_tables(reports: Mapping[str, EnergyReport], paper: bool) -> list[Table]:
    """UR5e Table VIII per motion: mechanical and electrical energy and efficiency per joint,
    with the paper's values for its tests A and B when ``paper``."""
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
                f"{seed.TABLE_VIII_TOTAL[key][0]:.1f}",
                f"{seed.TABLE_VIII_TOTAL[key][1]:.1f}",
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


def breakdown_table(reports: Mapping[str, EnergyReport]) -> Table:
    """Where each motion's electrical energy goes (framework Fig. 4)."""
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


def timing_table(result: Any, task_name: str) -> Table:
    """The program as written, uniform time scaling and the energy-optimal timing at one cycle
    time (:class:`kinergy.optimize.TimingResult`)."""
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
    return Table(
        f"Energy-optimal timing of {task_name} at the same cycle time",
        ["timing", "cycle time [s]", "E_elec [J]", "friction [J]", "copper [J]", "within limits"],
        rows,
        f"Saving {saving:.1f} % (re-simulated at 500 Hz, every speed, acceleration, torque and "
        "position limit checked at every sample).",
    )
