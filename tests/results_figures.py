"""The figures of ``docs/results.md``, each tied to the command that produces it.

The same mechanism as :mod:`doc_figures` (a :class:`~doc_figures.Figure` is a sentence or a
table row of the page with ``{name}`` where a figure stands): the fast ones run in
``tests/test_doc_figures.py``, all of them in ``benchmarks/bench_doc_figures.py``, and a table a
benchmark script measures (``benchmarks/bench_programs.py``) is checked or rewritten by that
script's ``--check`` / ``--write`` from the figures here whose ``script`` names it.

A placeholder a figure's function does not return (a timing: wall and processor times depend on
the host and its load) matches any number and is not compared; its sentence names the command
and the date that measured it.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Callable
from typing import Any

import numpy as np
from doc_figures import (
    ROOT,
    UR3E,
    UR5E_CALIBRATION,
    Figure,
    Runs,
    Table,
    _calibration,
    _demo,
    _panda_split,
    _ur10e_identify,
    _ur10e_payload,
    _ur10e_validate,
    _worst,
    calibration_energy,
    need,
    test_count,
)
from results_slow import (
    bench,
    default_row,
    method_row,
    place_grid,
    programs_summary,
    programs_table,
    standstill,
)

PAGE = "docs/results.md"
UR3E_RAD = UR3E.parents[1] / "ur3e-rad" / "ur3e_rtde_2021-10-05_120805.csv"
GOLDEN = ROOT / "tests" / "golden"

Produce = Callable[[Runs], dict[str, str]]


def _fig(text: str, produce: Produce, *, slow: bool = False, script: str = "") -> Figure:
    """A sentence or a table row of the results page."""
    return Figure(PAGE, text, produce, slow=slow, script=script)


def _pct(value: float, truth: float, digits: int) -> str:
    return f"{100 * (value / truth - 1):+.{digits}f}"


def _minus(text: str) -> str:
    """A figure as the page prints it: a minus sign, not a hyphen."""
    return text.replace("-", "−")


def _r2(rows: list[dict[str, Any]], digits: int = 3) -> list[str]:
    return [f"{row['r2']:.{digits}f}" for row in rows]


# ---------------------------------------------------------------------------------------------
# energy of test A (the built-in motions on the built-in UR5e)


def _energy(runs: Runs, motion: str) -> Any:
    return runs.json("energy", "ur5e", motion)


def energy_row(j: int | None) -> Produce:
    """Joint ``j``'s (None: the total's) E_mech, E_elec and efficiency on test A."""

    def produce(runs: Runs) -> dict[str, str]:
        e = _energy(runs, "test-a")
        row = e["total"] if j is None else e["joints"][j]
        digits = 2 if j is None else 1
        return {
            "mech": f"{row['e_mech']:.1f}",
            "elec": f"{row['e_elec']:.1f}",
            "eta": f"{100 * row['efficiency']:.{digits}f}",
        }

    return produce


def energy_parts(runs: Runs) -> dict[str, str]:
    a, b = _energy(runs, "test-a"), _energy(runs, "test-b")
    parts = a["total"]["breakdown"]
    return {
        "seconds": f"{a['duration']:.1f}",
        "friction": f"{parts['friction']:.0f}",
        "elec": f"{a['total']['e_elec']:.0f}",
        "copper": f"{parts['copper']:.0f}",
        "b_mech": f"{b['total']['e_mech']:.1f}",
        "b_elec": f"{b['total']['e_elec']:.1f}",
        "b_eta": f"{100 * b['total']['efficiency']:.1f}",
    }


# ---------------------------------------------------------------------------------------------
# identification on the twin: the demo's logs, identified and validated by the command line


def _twin(runs: Runs) -> tuple[Any, Any, Any]:
    """(identified, truth, validation on test B) of test A's log of ``kinergy demo
    --mismatch none``, identified from the built-in ``ur5e``."""
    _demo(runs, "none")
    logs = runs.folder / "demo-none" / "logs"
    identified = runs.json(
        "identify", str(logs / "test-a.csv"), "--robot", "ur5e", "--out", "twin.toml"
    )
    model = str(runs.folder / "twin.toml")
    truth = runs.json("robot", "show", "ur5e")
    return identified, truth, runs.json("validate", model, str(logs / "test-b.csv"))


def _twin_errors(runs: Runs, j: int) -> dict[str, float]:
    identified, truth, _ = _twin(runs)
    m, t = identified["joints"][j], truth["joints"][j]["drive"]
    return {
        "rotor": 100 * (m["rotor_inertia"] / (t["motor_inertia"] + t["reducer_inertia"]) - 1),
        "kt": 100 * (m["torque_constant"] / t["torque_constant"] - 1),
        "viscous": 100 * (m["friction"]["viscous"] / t["friction"]["viscous"] - 1),
        "direct": 1e3 * (m["friction"]["coulomb_direct"] - t["friction"]["coulomb_direct"]),
        "reverse": 1e3 * (m["friction"]["coulomb_reverse"] - t["friction"]["coulomb_reverse"]),
    }


def twin_row(j: int) -> Produce:
    def produce(runs: Runs) -> dict[str, str]:
        e = _twin_errors(runs, j)
        validation = _twin(runs)[2]
        return {
            "rotor": f"{e['rotor']:+.2f}",
            "kt": f"{e['kt']:+.2f}",
            "viscous": f"{e['viscous']:+.1f}",
            "direct": f"{e['direct']:+.2f}",
            "reverse": f"{e['reverse']:+.2f}",
            "torque": f"{validation['torque'][j]['r2']:.4f}",
            "current": f"{validation['current'][j]['r2']:.4f}",
        }

    return produce


def twin_within(runs: Runs) -> dict[str, str]:
    worst = max(
        abs(e[key])
        for e in (_twin_errors(runs, j) for j in range(6))
        for key in ("rotor", "kt", "viscous")
    )
    return {"within": f"{math.ceil(worst)}"}


# ---------------------------------------------------------------------------------------------
# the real UR10e, UR3e and Panda


def ur10e_row(j: int) -> Produce:
    def produce(runs: Runs) -> dict[str, str]:
        joint = _ur10e_identify(runs)["joints"][j]
        fit = _ur10e_identify(runs)["fit"]["current"][j]
        v = _ur10e_validate(runs)
        return {
            "kt": f"{joint['torque_constant']:.4f}",
            "inertia": f"{joint['rotor_inertia']:.3e}",
            "fit": f"{fit['r2']:.3f}",
            "r2": f"{v['current'][j]['r2']:.3f}",
            "rms": f"{v['current'][j]['rms']:.3f}",
            "moving": f"{v['moving']['current'][j]['r2']:.3f}",
            "torque": f"{v['torque'][j]['r2']:.3f}",
        }

    return produce


def ur10e_summary(runs: Runs) -> dict[str, str]:
    return {"r2": ", ".join(_r2(_ur10e_validate(runs)["current"]))}


def ur10e_payload_com(runs: Runs) -> dict[str, str]:
    out = {}
    for tag, name, flags in (
        ("a", "ur-20_02_19_14harm50secLoad", ()),
        ("b", "ur-20_02_19_15harm50secLoad", ("--repair",)),
    ):
        p = _ur10e_payload(runs, name, *flags)["payload"]
        out[f"{tag}_mass"] = f"{p['mass']:.3f}"
        out[f"{tag}_std"] = f"{p['mass_std']:.3f}"
        out[f"{tag}_err"] = _minus(f"{100 * (p['mass'] / 2.805 - 1):.1f}")
        for axis, (c, s) in zip("xyz", zip(p["com"], p["com_std"], strict=True), strict=True):
            out[f"{tag}_{axis}"] = _minus(f"{c:.3f}")
            out[f"{tag}_{axis}s"] = f"{s:.3f}"
    return out


def ur3e_fit(runs: Runs) -> dict[str, str]:
    need(UR3E)
    result = runs.json("identify", str(UR3E), "--robot", "ur3e", "--out", "ur3e-id.toml")
    return {"r2": f"{result['fit']['current'][1]['r2']:.3f}"}


def panda_cli(runs: Runs) -> dict[str, str]:
    validation = _panda_split(runs)[1]
    r2 = [m["r2"] for m in validation["joint_torque"]]
    cut = validation["kinergy"]["options"]["start"]
    return {
        "r2": ", ".join(f"{x:.4f}" if x >= 0.999 else f"{x:.3f}" for x in r2),
        "cut": f"{cut:.4f}",
        "cut2": f"{cut:.4f}",
    }


def panda_summary(runs: Runs) -> dict[str, str]:
    r2 = [m["r2"] for m in _panda_split(runs)[1]["joint_torque"]]
    return {"r2": f"{min(r2):.3f}-{max(r2):.4f}"}


# ---------------------------------------------------------------------------------------------
# drives: the UR5e calibration file, the supply of the real UR3e


def calibration_row(j: int) -> Produce:
    def produce(runs: Runs) -> dict[str, str]:
        joint = _calibration(runs)["joints"][j]
        worst_u = max(abs(p["voltage_model"] / p["voltage"] - 1) for p in joint["points"])
        return {
            "p": f"{joint['friction']['params']['exponent']:.2f}",
            "worst": f"{100 * _worst(joint, 'friction_model'):.2f}",
            "line": f"{100 * _worst(joint, 'friction_contrast'):.1f}",
            "u": f"{100 * worst_u:.2f}",
        }

    return produce


def calibration_summary(runs: Runs) -> dict[str, str]:
    joints = _calibration(runs)["joints"]
    line = [_worst(j, "friction_contrast") for j in joints]
    worst_u = max(abs(p["voltage_model"] / p["voltage"] - 1) for j in joints for p in j["points"])
    return {
        "worst": f"{100 * max(_worst(j, 'friction_model') for j in joints):.1f}",
        "u": f"{100 * worst_u:.1f}",
        "line": f"{100 * min(line):.0f}-{100 * max(line):.0f}",
    }


def _powers(runs: Runs) -> list[dict[str, str]]:
    """Per joint, the power the calibration measured at its fastest point (1.5 U I) against the
    built-in ``ur5e``'s and the calibrated robot's (``bench_drives.py --part calibration``'s
    functions; the calibrated robot the one ``robot import-calibration`` wrote)."""
    _calibration(runs)

    def compute() -> list[dict[str, str]]:
        b = bench("bench_drives")
        built_in = b.kinergy.load_robot("ur5e")
        calibrated = b.kinergy.load_robot(str(runs.folder / "ur5e-cal.toml"))
        rows = []
        for j, joint in enumerate(b.read_ur_calibration(UR5E_CALIBRATION).joints):
            moving = np.abs(joint.speed) >= 0.5
            speed = joint.speed[moving]
            measured = b.DQ_VOLTAGE_FACTOR * joint.voltage[moving] * np.abs(joint.current[moving])
            ours, theirs = (b._point_power(r, j, speed) for r in (built_in, calibrated))
            fast = int(np.argmax(speed))
            err = [100 * np.mean(np.abs(x / measured - 1)) for x in (ours, theirs)]
            rows.append({"measured": f"{measured[fast]:.1f}", "built_in": f"{ours[fast]:.1f}",
                         "calibrated": f"{theirs[fast]:.1f}", "err": f"{err[0]:.0f}",
                         "cal_err": f"{err[1]:.1f}"})  # fmt: skip
        return rows

    rows: list[dict[str, str]] = runs.kept(("powers",), compute)
    return rows


def power_row(j: int) -> Produce:
    return lambda runs: _powers(runs)[j]


def calibration_test_a(runs: Runs) -> dict[str, str]:
    e = calibration_energy(runs)
    return {"cal": e["cal_joints"], "seed": e["seed_joints"]}


def _rad_cut(runs: Runs) -> dict[str, str]:
    """The ur3e-rad log as ``tests/test_supply_real.py`` cuts it (its rows, the columns kinergy
    reads; all, the first 60 % and the last 40 %) and the UR3e with the log's payload."""
    need(UR3E_RAD)
    from test_supply_real import PAYLOAD, _cut

    folder = runs.folder / "rad"
    if not folder.exists():
        folder.mkdir()
        with UR3E_RAD.open(newline="") as f:
            header, *rows = list(csv.reader(f))
        cut = round(0.6 * len(rows))
        _cut(rows, header, folder / "all.csv")
        _cut(rows[:cut], header, folder / "first.csv")
        _cut(rows[cut:], header, folder / "last.csv")
        source = (ROOT / "kinergy" / "model" / "library" / "ur3e.toml").read_text(encoding="utf-8")
        at = source.index("[[joints]]")
        (folder / "ur3e-payload.toml").write_text(
            source[:at] + PAYLOAD + source[at:], encoding="utf-8"
        )
    return {name: str(folder / f"{name}.csv") for name in ("all", "first", "last")} | {
        "model": str(folder / "ur3e-payload.toml")
    }


def ur3e_supply(runs: Runs) -> dict[str, str]:
    files = _rad_cut(runs)
    built_in = runs.json("energy", "ur3e", files["all"])
    s, measured = built_in["supply"], built_in["measured"]["drawn"]
    zero = runs.json("energy", "ur3e", files["all"], "--payload", "0")["supply"]["drawn"]
    model = runs.file(
        "rad-id.toml", "identify", files["first"], "--robot", files["model"], "--out", "rad-id.toml"
    )
    held = runs.json("energy", model, files["last"], "--trace", "rad-trace.csv")
    trace = np.genfromtxt(runs.folder / "rad-trace.csv", delimiter=",", names=True)
    rmse = float(np.sqrt(np.mean((trace["supply_predicted"] - trace["supply_measured"]) ** 2)))
    validation = runs.json("validate", model, files["last"])
    return {
        "zero": f"{zero:.1f}",
        "drawn": f"{s['drawn']:.1f}",
        "measured": f"{measured:.1f}",
        "error": _minus(_pct(s["drawn"], measured, 1)),
        "motors": f"{s['motors']:.1f}",
        "standing": f"{s['standby']:.1f}",
        "power": f"{s['standby_power']:.1f}",
        "share": f"{100 * s['standby'] / s['drawn']:.0f}",
        "under": f"{100 * (1 - s['motors'] / measured):.0f}",
        "held": f"{held['supply']['drawn']:.1f}",
        "held_measured": f"{held['measured']['drawn']:.1f}",
        "held_error": _minus(_pct(held["supply"]["drawn"], held["measured"]["drawn"], 1)),
        "rmse": f"{rmse:.2f}",
        "r2": f"{validation['supply']['r2']:.3f}",
    }


# ---------------------------------------------------------------------------------------------
# cutting the energy: test A's optimisation (the golden file, which test_golden_json keeps equal
# to what `kinergy optimize ur5e test-a --json` prints)


def optimize_test_a(runs: Runs) -> dict[str, str]:
    g = json.loads((GOLDEN / "optimize_test_a.json").read_text(encoding="utf-8"))
    p, o = g["program"], g["optimized"]
    saved = {lever["name"]: lever["saved"] for lever in g["levers"]}
    return {
        "cycle": f"{p['cycle_time']:.3f}",
        "cycle2": f"{o['cycle_time']:.3f}",
        "cycle3": f"{p['cycle_time']:.3f}",
        "supply": f"{p['e_supply']:.1f}",
        "motors": f"{p['e_elec']:.1f}",
        "friction": f"{p['breakdown']['friction']:.1f}",
        "copper": f"{p['breakdown']['copper']:.1f}",
        "o_supply": f"{o['e_supply']:.1f}",
        "o_saving": f"{100 * g['saving_supply']:.1f}",
        "o_motors": f"{o['e_elec']:.1f}",
        "o_msaving": f"{100 * g['saving_motors']:.1f}",
        "o_friction": f"{o['breakdown']['friction']:.1f}",
        "o_copper": f"{o['breakdown']['copper']:.1f}",
        "standby": f"{p['e_standby']:.0f}",
        "turns": f"{saved['2pi']:.0f}",
        "blends": f"{saved['blends']:.0f}",
        "timing": f"{saved['timing']:.0f}",
    }


# ---------------------------------------------------------------------------------------------
# experiments, the nursing arm, the test suite


def excite(runs: Runs) -> dict[str, str]:
    e = runs.json("excite", "ur5e", "--compare", "50", "--out", "excite.csv")
    return {
        "cond": f"{e['condition']:.1f}",
        "median": f"{e['random']['median']:.1f}",
        "ratio": f"{e['ratio']:.1f}",
    }


def nursing(runs: Runs) -> dict[str, str]:
    """``kinergy nursing --exact`` and ``kinergy nursing`` (the twin's noise, seed 0)."""
    exact, noisy = runs.json("nursing", "--exact"), runs.json("nursing")
    curve = min(f["pso"]["curve_r2_vs_twin"] for f in exact["friction"])
    means = [f[fit]["r2"] for f in noisy["friction"] for fit in ("pso", "lsq")]
    samples = [f[fit]["r2_samples"] for f in noisy["friction"] for fit in ("pso", "lsq")]
    return {
        "lsq": f"{min(f['lsq']['r2'] for f in exact['friction']):.4f}",
        "pso": f"{math.floor(curve * 1e4) / 1e4:.4f}",
        "means": f"{min(means):.4f}-{max(means):.4f}",
        "samples": f"{min(samples):.2f}-{max(samples):.2f}",
        "exact": f"{max(exact['ridge']['rmse_test']):.4f}",
        "noisy": f"{min(noisy['ridge']['rmse_test']):.2f}-{max(noisy['ridge']['rmse_test']):.2f}",
    }


def tests(runs: Runs) -> dict[str, str]:
    return test_count(runs)


_PAPER_VIII = (
    ("1", "220.6", "251.6", "87.7"),
    ("2", "49.36", "72.0", "68.6"),
    ("3", "228.7", "264.2", "86.6"),
    ("4", "44.2", "55.5", "79.6"),
    ("5", "71.1", "83.7", "84.9"),
    ("6", "97.3", "117.2", "83.0"),
)
_UR10E_JOINTS = ("shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3")


def _only(produce: Produce, *keys: str) -> Produce:
    return lambda runs: {k: v for k, v in produce(runs).items() if k in keys}


RESULTS: tuple[Figure, ...] = (
    # the summary
    _fig(
        "| UR5e twin, test A: overall efficiency against the paper's Table VIII | {eta} % "
        "against 84.17 % |",
        _only(energy_row(None), "eta"),
    ),
    _fig(
        "| UR5e twin: drive parameters identified from test A, against the truth | within "
        "{within} % (rotor inertia, k_t, friction) |",
        twin_within,
    ),
    _fig(
        "| UR10e, real: held-out current R² on the point-to-point program | {r2} |",
        ur10e_summary,
    ),
    _fig(
        "| Panda, real: held-out joint-torque R² (last 30 % of the run) | {r2} |",
        panda_summary,
    ),
    _fig(
        "| UR5e calibration file: friction model against every measured point | within {worst} "
        "% (Coulomb + viscous: {line} %) |",
        _only(calibration_summary, "worst", "line"),
    ),
    # energy of test A
    *(
        _fig(
            f"| {n} | {{mech}} | {{elec}} | {{eta}} | {m} | {e} | {eta} |",
            energy_row(int(n) - 1),
        )
        for n, m, e, eta in _PAPER_VIII
    ),
    _fig(
        "| overall | {mech} | {elec} | **{eta}** | 711.3 | 845.1 | **84.17** |",
        energy_row(None),
    ),
    _fig("The overall efficiency agrees ({eta} % against 84.17 %)", _only(energy_row(None), "eta")),
    _fig(
        "our test A is a {seconds} s program whose shoulder and wrist 1 travel much further",
        _only(energy_parts, "seconds"),
    ),
    _fig(
        "Nearly all of the energy is friction ({friction} of the {elec} J; copper losses "
        "{copper} J)",
        _only(energy_parts, "friction", "elec", "copper"),
    ),
    _fig(
        "Test B: {b_mech} J / {b_elec} J, η {b_eta} % (doc 83.83 %).",
        _only(energy_parts, "b_mech", "b_elec", "b_eta"),
    ),
    # identification on the twin
    *(
        _fig(
            f"| {j + 1} | {{rotor}} | {{kt}} | {{viscous}} | {{direct}} | {{reverse}} | "
            "{torque} | {current} |",
            twin_row(j),
        )
        for j in range(6)
    ),
    # the real UR10e
    *(
        _fig(
            f"| {j + 1} {name} | {{kt}} | {{inertia}} | {{fit}} | "
            + ("**{r2}**" if j == 5 else "{r2}")
            + " | {rms} | {moving} | {torque} |",
            ur10e_row(j),
        )
        for j, name in enumerate(_UR10E_JOINTS)
    ),
    _fig(
        "shoulder (joint 2) moves, so the sequential method identifies joint 2 (current R² {r2} "
        "on the log)",
        ur3e_fit,
    ),
    _fig(
        "`kinergy validate` on the last 30 %: joint-torque R² {r2} (the folder read as it comes "
        "with `--to {cut}` and `--from {cut2}`",
        panda_cli,
    ),
    _fig(
        "`14harm50secLoad` {a_mass} ± {a_std} kg ({a_err} %), centre of mass ({a_x} ± {a_xs}, "
        "{a_y} ± {a_ys}, {a_z} ± {a_zs}) m; `15harm50secLoad` {b_mass} ± {b_std} kg ({b_err} %), "
        "({b_x} ± {b_xs}, {b_y} ± {b_ys}, {b_z} ± {b_zs}) m.",
        ur10e_payload_com,
    ),
    # drives
    _fig(
        "On the UR5e file the chosen model is within {worst} % of the measured friction at "
        "every speed point of every joint (bar: 5 % or 0.005 N m), the motor voltage within "
        "{u} %; Coulomb + viscous on the same points is {line} % off at its worst point per "
        "joint.",
        calibration_summary,
    ),
    *(
        _fig(
            f"| {name} | {model} (p {{p}}) | {{worst}} | {{line}} | {{u}} |",
            calibration_row(j),
        )
        for j, (name, model) in enumerate(
            zip(_UR10E_JOINTS, ["power_law"] * 5 + ["directional_power_law"], strict=True)
        )
    ),
    *(
        _fig(
            f"| {name} | {{measured}} | {{built_in}} | {{calibrated}} | {{err}} / {{cal_err}} |",
            power_row(j),
        )
        for j, name in enumerate(_UR10E_JOINTS)
    ),
    _fig(
        "With the calibrated friction and motors, test A's electrical energy is {cal} J instead "
        "of the built-in model's {seed} J.",
        calibration_test_a,
    ),
    _fig(
        "`--payload 0` gives the {zero} J this page said before), predicts {drawn} J drawn against "
        "{measured} J measured ({error} %): "
        "motors {motors} J and the standing draw {standing} J ({power} W, {share} %). The motors "
        "alone, what kinergy said before the standing draw was in the robot files, are {under} % "
        "under.",
        _only(
            ur3e_supply,
            "zero",
            "drawn",
            "measured",
            "error",
            "motors",
            "standing",
            "power",
            "share",
            "under",
        ),
    ),
    _fig(
        "model predicts the last 40 %: {held} J against {held_measured} J ({held_error} %; bar "
        "3 %), a supply-power RMSE of {rmse} W (from `energy --trace`; bar 5 W, EcBot's "
        "published test range 1.45-5.25 W) and R² {r2} (`validate`).",
        _only(ur3e_supply, "held", "held_measured", "held_error", "rmse", "r2"),
    ),
    # cutting the energy: test A
    _fig(
        "| program as written (3 rad/s, 6 rad/s²) | {cycle} | {supply} | {motors} | {friction} | "
        "{copper} |",
        _only(optimize_test_a, "cycle", "supply", "motors", "friction", "copper"),
    ),
    _fig(
        "| optimised | {cycle2} | **{o_supply}** (−{o_saving} %) | **{o_motors}** (−{o_msaving} "
        "%) | {o_friction} | {o_copper} |",
        _only(
            optimize_test_a,
            "cycle2",
            "o_supply",
            "o_saving",
            "o_motors",
            "o_msaving",
            "o_friction",
            "o_copper",
        ),
    ),
    _fig(
        "On the UR5e with test A's waypoints at the program's own cycle time ({cycle3} s;",
        _only(optimize_test_a, "cycle3"),
    ),
    _fig(
        "34.4 W over the cycle ({standby} J), which no lever changes at the same cycle time;",
        _only(optimize_test_a, "standby"),
    ),
    _fig(
        "Most of the saving is the smaller 2π turns ({turns} J: a joint target a full turn away "
        "from the shortest is the same pose) and the blends at the via points ({blends} J); the "
        "timing adds {timing} J.",
        _only(optimize_test_a, "turns", "blends", "timing"),
    ),
    # experiments
    _fig(
        "UR5e, 5 harmonics, 10 s period: condition number **{cond}**, against a median of "
        "**{median}** over 50 random feasible trajectories of the same size ({ratio}× lower);",
        excite,
    ),
    # the nursing arm
    _fig(
        "least squares recovers the twin's parameters exactly (R² {lsq}); PSO's curve R² ≥ {pso} "
        "(its parameters wander in Makkar's flat valleys unless polished). With the twin's "
        "current noise: R² {means} against the mean friction per speed, {samples} against "
        "every sample",
        _only(nursing, "lsq", "pso", "means", "samples"),
    ),
    _fig(
        "Ridge, per-joint RMSE on the held-out 30 %: at most {exact} N m noise-free; {noisy} N m "
        "with noise,",
        _only(nursing, "exact", "noisy"),
    ),
    # the test suite
    _fig("`pytest` (the README's second command) runs about {tests} tests.", tests),
    # the programs' benchmark (benchmarks/bench_programs.py --check / --write)
    Table(PAGE, "| program | moves | symmetry, IK |", programs_table, script="bench_programs"),
    _fig(
        "| URScript programs: supply energy saved at the same cycle time | {mean} % mean "
        "({range} %; {share} % of the headroom the energy floor leaves) with via points free, "
        "{kept} % with them kept |",
        _only(programs_summary, "mean", "range", "share", "kept"),
        slow=True,
        script="bench_programs",
    ),
    _fig(
        "With the via points kept (`--via keep`) the mean saving is {kept} % ({kept_each} % in "
        "the table's order);",
        _only(programs_summary, "kept", "kept_each"),
        slow=True,
        script="bench_programs",
    ),
    _fig(
        "With the standing draw in the supply figure ({standing} % of it on these cycles) the "
        "savings are {ratio} of the motors' alone:",
        _only(programs_summary, "standing", "ratio"),
        slow=True,
        script="bench_programs",
    ),
    _fig(
        "read back by kinergy's own reader and simulated again, gives the reported energy within "
        "{back} %",
        _only(programs_summary, "back"),
        slow=True,
        script="bench_programs",
    ),
    _fig(
        "via points free: {mean} % mean ({range} %), {share} % of the headroom",
        _only(programs_summary, "mean", "range", "share"),
        slow=True,
        script="bench_programs",
    ),
    _fig(
        "kept: {kept} % ({kept_range} %); every program within its limits and targets, read back "
        "within {back} %",
        _only(programs_summary, "kept", "kept_range", "back"),
        slow=True,
        script="bench_programs",
    ),
    # the default settings (kinergy optimize ROBOT PROGRAM --tool-symmetry z)
    *(
        _fig(
            f"| `{name}` | {moves} | {{cpu}} | {{wall}} | {{before}} → {{after}} | {{supply}} % | "
            "{motors} % |",
            default_row(name),
            slow=True,
        )
        for name, moves in (
            ("ur5e_conveyor_to_tray", 8),
            ("ur5e_machine_tending", 14),
            ("ur5e_sorting", 17),
            ("ur5e_kitting", 20),
            ("ur10e_bin_to_fixture", 8),
            ("ur10e_depalletising", 14),
            ("ur10e_palletising", 20),
            ("ur10e_palletising_layer", 30),
        )
    ),
    # every method on the real logs (benchmarks/bench_real_identification.py ur10e)
    *(
        _fig(
            f"| {label} | {{j1}} | {{j2}} | {{j3}} | {{j4}} | {{j5}} | **{{j6}}** |",
            method_row(key),
            slow=True,
        )
        for key, label in (
            ("sequential", "sequential"),
            (
                "full",
                "full (default: drives fitted on the currents; was 0.69 / 0.71 on joints 1-2)",
            ),
            ("full --target current", "full `--target current` (scale from the published masses)"),
        )
    ),
    _fig(
        "it stands still for {still} % of the program and {share} % of its squared current "
        "error falls there (wrist 2: {still2} %, {share2} %); where it moves its R² is {moving}.",
        _only(standstill, "still", "share", "still2", "share2", "moving"),
        slow=True,
    ),
    _fig(
        "caps wrist 3's R² at {ceiling} for any model that predicts a steady current at rest "
        "(wrist 2: {ceiling2})",
        _only(standstill, "ceiling", "ceiling2"),
        slow=True,
    ),
    # the placement recipe's grid
    _fig(
        "{reachable} of {cells} reachable ({cycle} cannot keep the cycle time, {reach} out of "
        "reach); today's {written} J as written from the supply, {today} J optimised; the best "
        "placement x {x} m, {best} J, {saving} % beyond the levers of the supply ({motors} % of "
        "the motors': {best_motors} against {today_motors} J).",
        place_grid,
        slow=True,
    ),
)
