"""Issue 36: do the 95 % energy intervals hold what they claim? Coverage, measured.

- ``twin``: over ``--seeds`` (default 30) seeded true robots of the realistic twin
  (``kinergy simulate --mismatch realistic``: :func:`kinergy.twin.realistic_truth` of the UR5e,
  a realistic controller's noise), each model is identified (``kinergy identify --friction
  auto``, the sequential method, its standing draw from the logged supply) on the twin's logs of
  the UR5e doc's identification run (test A) and of a random feasible Fourier excitation (20 s,
  seeded), then asked the supply energy of motions it has not seen: test B and the UR5e
  programs of ``benchmarks/programs`` run by the same twin. The twin's logged supply
  (``actual_robot_voltage x actual_robot_current``) is the truth. Reported: how often the 95 %
  interval holds it, and the median half-width (% of the energy).
- ``ur3e``: the real UR3e of ``../shared/datasets/ur3e-rad`` (35.5 s, its supply measured),
  cut into ``--windows`` held-out windows; each window's energy is predicted by a model
  identified on the rest of the log (two halves: a model from each half predicts the other
  half's windows), against the measured supply.

- ``ur10e``: the real UR10e of ``../shared/datasets/ur10e-innopolis`` (no supply logged: the
  band is not calibrated there), identified on the README's three Fourier runs, its 95 %
  prediction band (``kinergy validate``) against the held-out point-to-point program's measured
  currents: the share of samples inside per joint (the columns and files of the README's
  recipe).
- ``cost``: what the errors cost ``identify`` and ``energy`` on the 60-minute 500 Hz twin log
  of ``benchmarks/bench_identify_long.py`` (made in ``--logs DIR``, or reused from there): each
  command in a fresh process under ``/usr/bin/time -v``, with and without the errors taken in
  turn ``--pairs`` times: ``identify`` through the Python API with
  ``IdentifyOptions(errors=True)`` and ``errors=False``, ``kinergy energy`` of the model
  identified with them against the same model with its ``[uncertainty]`` table removed.

Every model goes through ``kinergy.identify`` and every figure through ``kinergy.energy`` (the
commands' own code), and ``--json`` prints the figures.

    python benchmarks/bench_uncertainty.py [twin ur3e cost] [--seeds 30] [--logs DIR] [--json]
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import kinergy
from kinergy.experiments.excitation_design import random_feasible
from kinergy.experiments.excitation_problem import excitation_problem
from kinergy.io.rtde import write_log
from kinergy.io.urscript_reader import read_program
from kinergy.trajectory.program_motion import program_motion
from kinergy.trajectory.program_path import program_path
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import TwinSettings, realistic_truth, simulate

DATA = Path(__file__).resolve().parents[2] / "shared" / "datasets"
PROGRAMS = Path(__file__).resolve().parent / "programs"
UR3E_RAD = DATA / "ur3e-rad"
UR10E = DATA / "ur10e-innopolis"
#: the README's recipe: the three Fourier runs, the held-out program, the columns of the files
UR10E_RUNS = tuple(
    UR10E / "identification_data" / f"{name}.csv"
    for name in ("ur-20_02_19_15harm50sec", "ur-20_02_19_14harm50sec", "ur-20_02_12-50sec_12harm")
)
UR10E_HELD_OUT = UR10E / "validation_data" / "ur-20_01_17-ptp_10_points.csv"
UR10E_COLUMNS = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"
#: the friction option of the twin's identification
FRICTION: str | None = "auto"


def _unseen(robot: kinergy.Robot) -> dict[str, kinergy.Motion]:
    """The motions the models have not seen: test B and the UR5e programs."""
    out = {"test-b": paper_trajectory(robot, "test-b")}
    for path in sorted(PROGRAMS.glob("ur5e_*.script")):
        out[path.stem] = program_motion(robot, program_path(robot, read_program(path)))[0]
    return out


def _case(held: bool, figures, truth: float) -> dict:
    iv = figures.intervals
    return {
        "predicted": figures.supply.drawn,
        "truth": truth,
        "low": None if iv is None else iv.drawn.low,
        "high": None if iv is None else iv.drawn.high,
        "holds": held,
        "half_width_percent": None
        if iv is None
        else 100.0 * iv.drawn.half_width / figures.supply.drawn,
    }


def excitation(robot: kinergy.Robot, seed: int) -> kinergy.Motion:
    """A random feasible Fourier excitation (nursing eq 22; 5 harmonics, 20 s, the UR5e's
    limits about its home pose), seeded: the baseline ``kinergy excite --compare`` draws."""
    problem = excitation_problem(robot, harmonics=5, period=20.0)
    return random_feasible(problem, np.random.default_rng(seed))[0].motion


def bench_twin(seeds: int, folder: Path) -> dict:
    """Coverage over ``seeds`` realistic true robots (module docstring)."""
    robot = kinergy.load_robot("ur5e")
    identification = paper_trajectory(robot, "test-a")
    unseen = _unseen(robot)
    cases = []
    for seed in range(seeds):
        truth = realistic_truth(robot, seed)
        motions = [identification, excitation(robot, seed)]
        logs = [
            simulate(truth, motion, TwinSettings.realistic(1000 * seed + k))
            for k, motion in enumerate(motions)
        ]
        model = kinergy.identify(logs, robot, kinergy.IdentifyOptions(friction=FRICTION)).robot
        for k, (name, motion) in enumerate(unseen.items()):
            path = folder / f"{seed}-{name}.csv"
            log = simulate(truth, motion, TwinSettings.realistic(1000 * seed + 10 + k))
            write_log(path, log.t, log.signals)
            figures = kinergy.energy(model, path)
            measured = figures.measured.drawn
            iv = figures.intervals
            case = _case(iv is not None and iv.drawn.holds(measured), figures, measured)
            cases.append({"seed": seed, "motion": name, **case})
            print(json.dumps(cases[-1]), file=sys.stderr)  # a cut run keeps what it measured
            path.unlink()
        print(f"seed {seed}: {sum(c['holds'] for c in cases)}/{len(cases)} held", file=sys.stderr)
    return _summary(cases)


def _summary(cases: list[dict]) -> dict:
    held = [c["holds"] for c in cases]
    widths = [c["half_width_percent"] for c in cases if c["half_width_percent"] is not None]
    errors = [100.0 * (c["predicted"] / c["truth"] - 1.0) for c in cases]
    return {
        "cases": len(cases),
        "coverage_percent": 100.0 * float(np.mean(held)),
        "median_half_width_percent": float(np.median(widths)) if widths else None,
        "median_abs_error_percent": float(np.median(np.abs(errors))),
        "detail": cases,
    }


def bench_ur3e(windows: int) -> dict:
    """Held-out windows of the UR3e rad log against its measured supply (module docstring)."""
    log = UR3E_RAD / "ur3e_rad.csv"
    if not log.exists():
        found = sorted(UR3E_RAD.glob("*.csv"))
        if not found:
            return {"skipped": f"{UR3E_RAD} not found"}
        log = found[0]
    whole = kinergy.read_log(log, robot="ur3e")
    t0, t1 = float(whole.t[0]), float(whole.t[-1])  # --from/--to are on the log's own time axis
    edges = np.linspace(t0, t1, windows + 1)
    middle = 0.5 * (t0 + t1)
    cases = []
    for _half, (lo, hi) in enumerate(((t0, middle), (middle, t1))):
        model = kinergy.identify([log], "ur3e", reading=kinergy.LogReading(window=(lo, hi))).robot
        for a, b in itertools.pairwise(edges):
            if lo <= a < hi:  # a window of this half: predicted by the other half's model
                continue
            figures = kinergy.energy(model, log, reading=kinergy.LogReading(window=(a, b)))
            measured = figures.measured.drawn
            iv = figures.intervals
            case = _case(iv is not None and iv.drawn.holds(measured), figures, measured)
            cases.append({"window": [a - t0, b - t0], "model_from": [lo - t0, hi - t0], **case})
    return _summary(cases)


def bench_ur10e() -> dict:
    """The UR10e's held-out currents against the prediction band (module docstring)."""
    if not all(p.exists() for p in (*UR10E_RUNS, UR10E_HELD_OUT)):
        return {"skipped": f"{UR10E} not found"}
    reading = kinergy.LogReading(columns=UR10E_COLUMNS)
    model = kinergy.identify(list(UR10E_RUNS), "ur10e", reading=reading).robot
    report = kinergy.validate(model, [UR10E_HELD_OUT], reading=reading)
    out: dict = {"method": report.band.method if report.band else None}
    for signal in ("current", "torque"):
        band = getattr(report.band, signal, None)
        if band is not None:
            out[signal] = {
                "samples": band.samples,
                "inside_percent": [100.0 * x for x in band.inside],
                "half_width": list(band.half_width),
                "rms": list(band.rms),
                "rms_std": list(band.rms_std),
                "r2_std": list(band.r2_std),
            }
    out["residual"] = {k: list(v) for k, v in model.uncertainty.residual.items()}
    out["dof"] = model.uncertainty.dof
    return out


_IDENTIFY = (
    "import sys, kinergy; kinergy.identify([sys.argv[1]], 'ur5e', "
    "kinergy.IdentifyOptions(errors=sys.argv[3] == 'on'), out=sys.argv[2])"
)


def bench_cost(
    folder: Path, pairs: int, commands: tuple[str, ...] = ("identify", "energy")
) -> dict:
    """Processor time, wall clock and peak memory of ``identify`` and ``energy`` on the 60-minute
    log with and without the errors, in turn (module docstring); ``energy`` alone reuses the
    model an earlier run left in ``folder``."""
    from bench_identify_long import make_long_log, timed

    from kinergy.model.toml import robot_from_dict, robot_to_dict, save_robot

    folder.mkdir(parents=True, exist_ok=True)
    log = folder / "test-a-60min.csv"
    if not log.exists():
        make_long_log(log, 60.0)
    runs: dict[str, list[dict]] = {k: [] for k in ("identify on", "identify off")}
    for _ in range(pairs if "identify" in commands else 0):
        for errors in ("on", "off"):
            model = folder / f"model-{errors}.toml"
            command = [sys.executable, "-c", _IDENTIFY, str(log), str(model), errors]
            runs[f"identify {errors}"].append(timed(command))
            print(f"identify {errors}: {runs[f'identify {errors}'][-1]}", file=sys.stderr)
    data = robot_to_dict(kinergy.load_robot(folder / "model-on.toml"))
    data.pop("uncertainty")
    save_robot(robot_from_dict(data), folder / "model-none.toml")
    runs.update({"energy on": [], "energy off": []})
    kinergy_cli = str(Path(sys.executable).with_name("kinergy"))
    for _ in range(pairs if "energy" in commands else 0):
        for errors, name in (("on", "model-on.toml"), ("off", "model-none.toml")):
            command = [kinergy_cli, "--quiet", "energy", str(folder / name), str(log)]
            runs[f"energy {errors}"].append(timed(command))
            print(f"energy {errors}: {runs[f'energy {errors}'][-1]}", file=sys.stderr)
    out: dict = {"runs": runs}
    for what in commands:
        on = np.mean([r["cpu"] for r in runs[f"{what} on"]])
        off = np.mean([r["cpu"] for r in runs[f"{what} off"]])
        out[f"{what}_cpu_percent"] = 100.0 * (on / off - 1.0)
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("parts", nargs="*", default=["twin", "ur3e"])
    parser.add_argument("--seeds", type=int, default=30)
    parser.add_argument("--windows", type=int, default=6)
    parser.add_argument("--pairs", type=int, default=2, help="cost: runs with and without")
    parser.add_argument("--logs", type=Path, default=None, help="cost: where the long log is")
    parser.add_argument("--commands", default="identify,energy", help="cost: which to time")
    parser.add_argument("--json", action="store_true", help="print every case as JSON")
    args = parser.parse_args(argv)
    out: dict = {"load_before": os.getloadavg()[0]}
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        if "twin" in args.parts:
            out["twin"] = bench_twin(args.seeds, Path(tmp))
            print(
                json.dumps({k: v for k, v in out["twin"].items() if k != "detail"}), file=sys.stderr
            )
        if "ur3e" in args.parts:
            out["ur3e"] = bench_ur3e(args.windows)
        if "ur10e" in args.parts:
            out["ur10e"] = bench_ur10e()
        if "cost" in args.parts:
            folder = args.logs or Path(tmp) / "logs"
            out["cost"] = bench_cost(folder, args.pairs, tuple(args.commands.split(",")))
    out["seconds"] = time.perf_counter() - start
    out["load_after"] = os.getloadavg()[0]
    if args.json:
        print(json.dumps(out, indent=1))
        return
    if "ur10e" in out and "current" in out["ur10e"]:
        for signal in ("current", "torque"):
            b = out["ur10e"].get(signal)
            if b:
                inside = ", ".join(f"{x:.1f}" for x in b["inside_percent"])
                print(f"ur10e {signal}: {b['samples']} samples, inside the 95 % band: {inside} %")
    if "cost" in out:
        c = out["cost"]
        for what in ("identify", "energy"):
            if f"{what}_cpu_percent" in c:
                print(f"cost: {what} +{c[f'{what}_cpu_percent']:.1f} % processor time")
        print(f"cost runs: {json.dumps(c['runs'])}")
    for part in ("twin", "ur3e"):
        if part in out and "cases" in out[part]:
            s = out[part]
            print(
                f"{part}: {s['cases']} cases, 95 % interval held {s['coverage_percent']:.1f} %, "
                f"median half-width {s['median_half_width_percent']:.2f} % of the energy, "
                f"median |error| {s['median_abs_error_percent']:.2f} %"
            )
        elif part in out:
            print(f"{part}: {out[part]}")
    print(f"{out['seconds']:.0f} s, load {out['load_before']:.1f} -> {out['load_after']:.1f}")


if __name__ == "__main__":
    main()
