"""Issue 13's acceptance figures: drives as real robots have them.

Each part prints its figures and a markdown-ready line; ``--part`` runs one of them.

- ``calibration``: ``import-calibration`` on the UR5e calibration file: the chosen friction model
  and Coulomb + viscous against the measured friction at every speed point, and the motor
  voltage against the measured ``U``.
- ``ur10e``: identify the UR10e on its unloaded Fourier runs with ``--friction auto`` and with
  Coulomb + viscous, predict the held-out ``ptp_10_points`` log: current RMS per joint.
- ``twin``: a realistic twin (:func:`kinergy.twin.realistic_truth`), one 60 s excitation log
  (the one ``kinergy excite`` designs, then a random Fourier one for contrast), identified
  (sequential with ``friction="auto"``, then the standing draw from the logged supply): each
  drive parameter against the truth (R and k_b are the model's: a log has no motor voltage); the full method's base parameters
  against the truth's, with their standard errors.
- ``supply``: the model identified on that log predicts test A run on the same twin: predicted
  against logged supply energy.
- ``warmup``: two 60-minute warm-up logs of the twin from cold (50 Hz, a designed excitation
  repeated): identify on one with and without the temperature term, predict the other's
  currents.

    python benchmarks/bench_drives.py [--part all|calibration|ur10e|twin|supply|warmup]
"""

from __future__ import annotations

import argparse
import glob
import time
from pathlib import Path

import numpy as np

import kinergy
from kinergy.accounting.energy import energy
from kinergy.drives.electrics import DQ_VOLTAGE_FACTOR, back_emf_constants, winding_resistances
from kinergy.dynamics.regressor import base_parameters, inertial_parameters
from kinergy.identification.full import FullFit, identify_full
from kinergy.identification.options import AUTO, IdentifyOptions
from kinergy.identification.result import IdentificationResult, predict
from kinergy.io.rtde import read_log, write_log
from kinergy.io.ur_calibration import read_ur_calibration
from kinergy.logs.prepare import IdentData, prepare
from kinergy.model.robot import Robot
from kinergy.predict import drive_state
from kinergy.trajectory.fourier import fourier_motion
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import TwinSettings, realistic_truth, simulate
from kinergy.workflows.calibration import import_calibration
from kinergy.workflows.energy import energy_of_log
from kinergy.workflows.excite import ExciteOptions, run_excite
from kinergy.workflows.identify import identify_model

DATA = Path(__file__).resolve().parents[1] / ".." / "shared" / "datasets"
UR10E = DATA / "ur10e-innopolis"
UR10E_COLUMNS = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"
SEED = 1


def _pct(a: float, b: float) -> float:
    return 100.0 * (a / b - 1.0)


def calibration() -> None:
    """import-calibration on the UR5e file: worst errors per joint, then the electrical power
    at the calibration's speed points."""
    result = import_calibration(
        kinergy.load_robot("ur5e"), DATA / "ur5e-calibration" / ("robot_calibration_summary.txt")
    )
    print("joint  model  worst friction err [%]  worst |err| [N m]  C+V worst [%]  worst U err [%]")
    for j in result.joints:
        tau = np.array([p.friction for p in j.points])
        model = np.array([p.friction_model for p in j.points])
        contrast = np.array([p.friction_contrast for p in j.points])
        u = np.array([p.voltage for p in j.points])
        u_model = np.array([p.voltage_model for p in j.points])
        ok = np.all(np.abs(model - tau) <= np.maximum(0.05 * np.abs(tau), 0.005))
        print(
            f"{j.name:14s} {j.friction.model:22s} {np.max(np.abs(model / tau - 1)) * 100:6.2f} "
            f"{np.max(np.abs(model - tau)):.4f}  C+V {np.max(np.abs(contrast / tau - 1)) * 100:6.1f}"
            f"  U {np.max(np.abs(u_model / u - 1)) * 100:5.2f}  within tolerance: {ok}"
        )
    calibration_power(result.robot)


def _point_power(robot: Robot, j: int, speed: np.ndarray) -> np.ndarray:
    """The electrical power (W, UR5e eqs 19-23) ``robot``'s joint ``j`` draws turning at the
    joint ``speed`` (rad/s) against its friction alone, the motor driving (power flows to the
    load), as in a calibration run."""
    joint = robot.joints[j]
    wm = joint.drive.gear_ratio * speed
    fr = joint.drive.friction
    tau = fr.model.friction_torque(fr.params, wm, 1e-6 * np.sign(wm), temperature=None)
    current = tau / joint.drive.torque_constant
    return winding_resistances(robot)[j] * current**2 + back_emf_constants(robot)[j] * wm * current


def calibration_power(calibrated: Robot) -> None:
    """The power the UR5e's calibration measured at each speed point (1.5 U I: its U is the dq
    voltage) against the built-in ur5e's and the calibrated robot's prediction."""
    built_in = kinergy.load_robot("ur5e")
    cal = read_ur_calibration(DATA / "ur5e-calibration" / "robot_calibration_summary.txt")
    print(
        "| joint | measured at 3.2 rad/s [W] | built-in ur5e | calibrated | mean abs error built-in / calibrated (|speed| >= 0.5) [%] |"
    )
    for j, joint in enumerate(cal.joints):
        moving = np.abs(joint.speed) >= 0.5
        speed = joint.speed[moving]
        measured = DQ_VOLTAGE_FACTOR * joint.voltage[moving] * np.abs(joint.current[moving])
        ours, theirs = (_point_power(r, j, speed) for r in (built_in, calibrated))
        fast = int(np.argmax(speed))
        err = [100 * np.mean(np.abs(x / measured - 1)) for x in (ours, theirs)]
        print(
            f"| {built_in.joints[j].name} | {measured[fast]:.1f} | {ours[fast]:.1f} | "
            f"{theirs[fast]:.1f} | {err[0]:.0f} / {err[1]:.1f} |"
        )
    motion = paper_trajectory(built_in, "test-a")
    e0 = energy(built_in, motion).total_e_elec
    e1 = energy(calibrated, motion).total_e_elec
    print(
        f"test A electrical energy: built-in ur5e {e0:.0f} J, calibrated friction and motors {e1:.0f} J"
    )


def _ur10e_logs(pattern: str) -> list[IdentData]:
    robot_n = 6
    return [
        prepare(read_log(p, columns=UR10E_COLUMNS), robot_n)
        for p in sorted(glob.glob(str(pattern)))
        if "Load" not in p
    ]


def _current_rms(robot: Robot, data: IdentData) -> np.ndarray:
    pred = predict(robot, data).current
    assert pred is not None and data.current is not None
    return np.sqrt(np.mean((pred - data.current) ** 2, axis=0))


#: a joint counts as moving on the held-out log where its speed exceeds this, rad/s
MOVING = 0.01


def ur10e() -> None:
    """--friction auto against Coulomb + viscous on the held-out UR10e log, and every candidate
    model fitted alone; each RMS over the whole log, and split where the joint moves and where
    it is at rest (a friction-versus-speed model sets the first; the standstill hold the second)."""
    model = kinergy.load_robot("ur10e")
    logs = _ur10e_logs(UR10E / "identification_data" / "*harm*.csv")
    held = _ur10e_logs(UR10E / "validation_data" / "ur-20_01_17-ptp_10_points.csv")[0]
    assert held.current is not None
    moving = np.abs(held.qd) > MOVING
    runs = ("viscous_coulomb", "auto", "power_law", "stribeck", "load_coulomb", "power_flow")
    err = {}
    for friction in runs:
        t0 = time.perf_counter()
        result = identify_model(model, logs, friction=friction)
        err[friction] = predict(result.robot, held).current - held.current
        print(f"{friction}: identified from {len(logs)} logs in {time.perf_counter() - t0:.1f} s")
        if friction == "auto":
            chosen = [c.model if c else "-" for c in result.fit.friction_choice or ()]

    def rms(e: np.ndarray, where: np.ndarray) -> np.ndarray:
        return np.sqrt(np.sum(np.where(where, e, 0.0) ** 2, axis=0) / np.sum(where, axis=0))

    for label, where in (
        ("whole log", np.ones_like(moving)),
        ("moving", moving),
        ("at rest", ~moving),
    ):
        share = 100 * np.mean(where, axis=0)
        print(f"\n{label}: current RMS [A] (share of samples per joint: {share.round(0)} %)")
        print("| joint | chosen | " + " | ".join(runs) + " | auto vs C+V [%] |")
        table = {f: rms(err[f], where) for f in runs}
        for j, name in enumerate(model.joint_names):
            cells = " | ".join(f"{table[f][j]:.4f}" for f in runs)
            gain = 100 * (1 - table["auto"][j] / table["viscous_coulomb"][j])
            print(f"| {name} | {chosen[j]} | {cells} | {-gain:+.1f} |")


def excitation(robot: Robot, seconds: float = 60.0, rate: float = 500.0, seed: int = 0) -> Motion:
    """A seeded Fourier excitation about a UR pose, ``seconds`` long (three 20 s periods)."""
    rng = np.random.default_rng(seed)
    q0 = np.array([0.0, -1.4, 1.2, -1.4, -1.57, 0.0])[: robot.n]
    period = 20.0
    return fourier_motion(
        q0,
        rng.normal(0, 0.3, (robot.n, 5)),
        rng.normal(0, 0.3, (robot.n, 5)),
        base_frequency=2 * np.pi / period,
        periods=round(seconds / period),
        dt=1.0 / rate,
    )


def _twin_log(
    truth: Robot, motion: Motion, seed: int, path: Path, *, reuse: bool = False
) -> IdentData:
    """The realistic twin's log of ``motion``, written to ``path`` (``reuse``: read it when it
    is there) and prepared."""
    if not (reuse and path.exists()):
        log = simulate(truth, motion, TwinSettings.realistic(seed), name=str(path))
        write_log(path, log.t, log.signals)
    return prepare(read_log(path), truth.n)


def _in_std(err_pct: float, value: float, std: float | None) -> str:
    """An error (%) of ``value`` in its standard errors ``std``: ``"(+1.2 sd)"``."""
    if std is None or not std > 0.0:
        return ""
    return f" ({err_pct / 100.0 * value / std:+.1f} sd)"


def _drive_table(truth: Robot, result: IdentificationResult, data: IdentData) -> float:
    """Each drive parameter against the truth (k_t and J_m + J_r with their errors in standard
    errors of the fit); returns the worst error (%)."""
    ident = result.robot
    t_state = drive_state(truth, data.q, data.qd, data.qdd, temperature=data.temperature)
    i_state = drive_state(ident, data.q, data.qd, data.qdd, temperature=data.temperature)
    worst = 0.0
    print(
        "| joint | k_t [%] | J_m+J_r [%] | R, the model's [%] | k_b, the model's [%] | friction RMS [%] |"
    )
    for j, (tj, ij) in enumerate(zip(truth.joints, ident.joints, strict=True)):
        td, idd = tj.drive, ij.drive
        std = result.joints[j].std
        errs = [
            _pct(idd.torque_constant, td.torque_constant),
            _pct(idd.rotor_inertia, td.rotor_inertia),
            _pct(winding_resistances(ident)[j], winding_resistances(truth)[j]),
            _pct(back_emf_constants(ident)[j], back_emf_constants(truth)[j]),
        ]
        tf, f = t_state.tau_friction[:, j], i_state.tau_friction[:, j]
        errs.append(100.0 * np.sqrt(np.mean((f - tf) ** 2) / np.mean(tf**2)))
        # R and k_b are the model's (not identified): left out of the worst identified error
        worst = max(worst, *(abs(e) for k, e in enumerate(errs) if k not in (2, 3)))
        notes = [
            _in_std(errs[0], idd.torque_constant, std.get("torque_constant")),
            _in_std(errs[1], idd.rotor_inertia, std.get("rotor_inertia")),
            "",
            "",
            "",
        ]
        cells = [f"{e:+.2f}{note}" for e, note in zip(errs, notes, strict=True)]
        print(f"| {tj.name} | " + " | ".join(cells) + " |")
    return worst


def _effective_truth(truth: Robot, base_true: np.ndarray, fit: FullFit) -> np.ndarray:
    """The truth's base parameters as the regression can see them: a rotor inertia whose column
    is merged into link base columns keeps the model's value, and the parameters it merges into
    carry ``coefficient * (J_true - J_model)`` (``fit.merged``); comparing with the links' own
    base parameters alone would count that share as an error."""
    out = base_true.copy()
    b = out.size
    index = {p.name: k for k, p in enumerate(fit.parameters)}
    for merged in fit.merged:
        k = index.get(merged.parameter)
        if k is None or fit.parameters[k].group != "rotor":
            continue
        delta = truth.joints[k - b].drive.rotor_inertia - merged.value
        for into in merged.into:
            if into.index < b:
                out[into.index] += into.coefficient * delta
    return out


def _verdict(rel: float, z: float) -> str:
    """Within 10 %; else badly excited (within 2 standard errors of the truth) or biased."""
    if rel <= 0.10:
        return "ok"
    return "badly excited" if abs(z) <= 2.0 else "biased"


def _base_errors(truth: Robot, model: Robot, data: IdentData, *, table: bool = False) -> None:
    """The full method's base parameters against the truth's (merged rotor inertias included,
    :func:`_effective_truth`), regressed against the twin's ``target_moment`` (computed from its
    truth without noise) and against its currents, with the model's own friction and with the
    truth's friction family (``load_thermal_power_law``); with ``table``, every parameter above
    1 % of the largest with its standard error."""
    base = base_parameters(model)
    true = base.project(inertial_parameters(truth))
    names = base.expressions()
    big = np.abs(true) > 0.01 * np.max(np.abs(true))
    runs = (
        ("moment", None),
        ("current", None),
        ("current", "power_law"),
        ("current", "load_thermal_power_law"),
    )
    for target, friction in runs:
        label = f"against {target}" + (f", friction {friction}" if friction else "")
        try:
            result = identify_full(model, [data], target=target, friction=friction)
        except Exception as exc:  # report, do not stop the benchmark
            print(f"full method {label}: failed: {exc}")
            continue
        assert isinstance(result.fit, FullFit)
        eff = _effective_truth(truth, true, result.fit)
        got = np.array([p.value for p in result.fit.base_parameters])
        std = np.array([np.nan if p.std is None else p.std for p in result.fit.base_parameters])
        rel = np.abs(got - eff) / np.maximum(np.abs(eff), 1e-12)
        z = (got - eff) / std
        verdicts = [_verdict(float(r), float(s)) for r, s in zip(rel[big], z[big], strict=True)]
        print(
            f"full method {label}: {np.sum(rel[big] <= 0.10)} of {big.sum()} base parameters "
            f"above 1 % of the largest within 10 % (median error {100 * np.median(rel[big]):.2f} "
            f"%, worst {100 * np.max(rel[big]):.1f} %; outside 10 %: "
            f"{verdicts.count('badly excited')} badly excited, {verdicts.count('biased')} "
            f"biased); all {rel.size}: {np.sum(rel <= 0.10)} within 10 %"
        )
        if table:
            print(
                "| base parameter | truth | identified | error [%] | std error | error / std | verdict |"
            )
            for k in np.flatnonzero(big)[np.argsort(-np.abs(true[big]))]:
                print(
                    f"| {names[k][:40]} | {eff[k]:+.4f} | {got[k]:+.4f} | "
                    f"{100 * (got[k] / eff[k] - 1):+.1f} | {std[k]:.2g} | {z[k]:+.1f} | "
                    f"{_verdict(float(rel[k]), float(z[k]))} |"
                )


def designed_excitation(robot: Robot, folder: Path, seconds: float = 60.0, seed: int = 0) -> Motion:
    """The excitation ``kinergy excite ROBOT --periods N --seed SEED`` designs (default options:
    5 harmonics, period 10 s, minimum condition number), ``seconds`` long; its motion file is
    kept in ``folder``."""
    options = ExciteOptions(
        out=folder / f"designed-{seed}.csv", periods=round(seconds / 10.0), seed=seed
    )
    return run_excite(robot, options).motion


def _identify_excitation(truth: Robot, motion: Motion, path: Path, *, table: bool) -> Robot:
    """One excitation log of the twin, identified: drives and base parameters against the
    truth; returns the identified model."""
    model = kinergy.load_robot("ur5e")
    data = _twin_log(truth, motion, SEED, path)
    t0 = time.perf_counter()
    result = identify_model(model, [data], IdentifyOptions(friction=AUTO))
    print(f"sequential + standing draw identified in {time.perf_counter() - t0:.1f} s")
    worst = _drive_table(truth, result, data)
    print(f"worst drive-parameter error {worst:.2f} % (bar 5 %)")
    draw = result.standing_draw
    std = f" +- {draw.std:.2g}" if draw is not None else ""
    print(
        f"standing draw: {result.robot.standby_power:.2f}{std} W against the truth's "
        f"{truth.standby_power:.2f} W ({_pct(result.robot.standby_power, truth.standby_power):+.2f} %)"
    )
    _base_errors(truth, model, data, table=table)
    return result.robot


def twin(folder: Path) -> Robot:
    """The realistic twin's 60 s excitation logs (the designed one ``kinergy excite`` writes,
    then the random Fourier one), identified; returns the model identified on the designed."""
    model = kinergy.load_robot("ur5e")
    truth = realistic_truth(model, SEED)
    print("## designed excitation (kinergy excite ur5e --periods 6), 60 s")
    designed = designed_excitation(model, folder)
    identified = _identify_excitation(truth, designed, folder / "excitation.csv", table=True)
    print("## random Fourier excitation, 60 s")
    _identify_excitation(truth, excitation(model), folder / "random.csv", table=False)
    return identified


def supply(folder: Path, identified: Robot) -> None:
    """Test A on the same twin, predicted by the model identified on the excitation."""
    model = kinergy.load_robot("ur5e")
    truth = realistic_truth(model, SEED)
    path = folder / "test-a.csv"
    log = simulate(truth, paper_trajectory(model, "test-a"), TwinSettings.realistic(SEED + 1))
    write_log(path, log.t, log.signals)
    report = energy_of_log(identified, path)
    assert report.measured is not None
    err = _pct(report.supply.drawn, report.measured.drawn)
    print(
        f"test A: predicted {report.supply.drawn:.1f} J drawn (motors {report.supply.motors:.1f} "
        f"+ standing draw {report.supply.standby:.1f}), logged {report.measured.drawn:.1f} J: "
        f"{err:+.2f} % (bar 3 %)"
    )
    plain = energy_of_log(model, path)
    print(
        f"the un-identified ur5e model on the same log: {plain.supply.drawn:.1f} J "
        f"({_pct(plain.supply.drawn, report.measured.drawn):+.1f} %)"
    )


def _tiled(motion: Motion, minutes: float, rate: float) -> Motion:
    """``motion`` (periodic) repeated for ``minutes``, resampled at ``rate`` Hz."""
    from scipy.interpolate import CubicSpline

    period = float(motion.t[-1] - motion.t[0])
    t = np.arange(0.0, minutes * 60.0, 1.0 / rate)
    phase = np.mod(t, period) + motion.t[0]
    parts = [CubicSpline(motion.t, x, axis=0)(phase) for x in (motion.q, motion.qd, motion.qdd)]
    return Motion(t, *parts)


def warmup(folder: Path, minutes: float = 60.0) -> None:
    """Two warm-up logs of ``minutes`` from a cold start: each the designed excitation of
    ``kinergy excite`` (seeds 0 and 1, one 10 s period) repeated, as the warm-up studies repeat
    their identification trajectory; identify on one with and without the temperature term,
    predict the other's currents (per joint and over the whole log)."""
    model = kinergy.load_robot("ur5e")
    truth = realistic_truth(model, SEED)
    rate = 50.0
    one, two = (
        _tiled(designed_excitation(model, folder, 10.0, seed=s), minutes, rate) for s in (0, 1)
    )
    ident = _twin_log(truth, one, SEED, folder / "warm1.csv", reuse=True)
    held = _twin_log(truth, two, SEED + 1, folder / "warm2.csv", reuse=True)
    assert ident.temperature is not None and held.temperature is not None
    print(
        f"warm-up: joints warm by {np.ptp(ident.temperature, axis=0).round(1)} K (held-out log "
        f"{np.ptp(held.temperature, axis=0).round(1)} K) over {minutes:g} min"
    )
    # Coulomb + viscous with and without its temperature term (the one difference), and the
    # power law without, and with the load and temperature terms
    runs = ("viscous_coulomb", "thermal_viscous", "power_law", "load_thermal_power_law")
    rms = {f: _current_rms(identify_model(model, [ident], friction=f).robot, held) for f in runs}
    floor = _current_rms(truth, held)  # the truth itself: the current noise and quantisation
    print(
        "| joint | warms by [K] | "
        + " | ".join(f"{k} [A]" for k in runs)
        + " | C+V lower by [%] | power law lower by [%] | the truth [A] |"
    )
    rows = [
        (name, float(np.ptp(held.temperature[:, j]))) for j, name in enumerate(model.joint_names)
    ]
    for j, (name, warm) in enumerate(rows):
        a, b, c, d = (rms[f][j] for f in runs)
        print(
            f"| {name} | {warm:.1f} | {a:.4f} | {b:.4f} | {c:.4f} | {d:.4f} | "
            f"{100 * (1 - b / a):.1f} | {100 * (1 - d / c):.1f} | {floor[j]:.4f} |"
        )
    whole = {f: float(np.sqrt(np.mean(rms[f] ** 2))) for f in runs}
    a, b, c, d = (whole[f] for f in runs)
    print(
        f"| whole log | | {a:.4f} | {b:.4f} | {c:.4f} | {d:.4f} | {100 * (1 - b / a):.1f} | "
        f"{100 * (1 - d / c):.1f} | {np.sqrt(np.mean(floor**2)):.4f} |"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parts = ["all", "calibration", "ur10e", "twin", "supply", "warmup"]
    parser.add_argument("--part", choices=parts, default="all")
    parser.add_argument("--folder", type=Path, default=None, help="keep the twin logs here")
    args = parser.parse_args()
    import tempfile

    folder = args.folder or Path(tempfile.mkdtemp())
    folder.mkdir(parents=True, exist_ok=True)
    part = args.part
    if part in ("all", "calibration"):
        calibration()
    if part in ("all", "twin", "supply"):
        identified = twin(folder)
        if part in ("all", "supply"):
            supply(folder, identified)
    if part in ("all", "warmup"):
        warmup(folder)
    if part in ("all", "ur10e"):
        ur10e()


if __name__ == "__main__":
    main()
