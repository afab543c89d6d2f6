"""Time the energy accounting of a 30 s, 500 Hz motion on the UR5e (issue bar: under 50 ms).

The motion is a Fourier-series excitation (nursing eq 22) of 30 s sampled at 500 Hz (15,001
samples) on all six joints; ``kinergy.accounting.energy.energy`` runs the whole drive model on it
(RNEA, reflected rotor inertia, power-flow friction, currents, voltages, eq 23 power) and integrates
per joint with the four-way breakdown. Warm-up first (numba kernels), then min and median of
``--repeats`` runs.

    python benchmarks/bench_energy.py [--repeats 15]

``--long``: the energy of a long UR log (issue 16 bar: a 60-minute 500 Hz log under 10 s and
under 500 MB), ``energy_of_log`` in chunks of ``ENERGY_ROWS`` (10,000) rows (``one-pass``) against the same with
the whole log as one chunk (``in-memory``), each in a fresh process
(so its peak resident memory is its own), on the log of ``benchmarks/bench_read.py`` (actual_q
and actual_qd: accelerations from a spline of the speed). Prints the seconds of the call (after a
numba warm-up), the process's peak RSS and the largest relative difference of the two results.

    python benchmarks/bench_energy.py --long [--minutes 60] [--rate 500] [--keep FILE]
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import kinergy
from kinergy.accounting.energy import energy
from kinergy.trajectory.fourier import fourier_motion

_CHILD = """
import json, resource, sys, time
import numpy as np
import kinergy
from kinergy.predict import drive_state
from kinergy.workflows.energy import ENERGY_ROWS, energy_of_log
robot = kinergy.load_robot("ur5e")
drive_state(robot, np.zeros((8, 6)), np.ones((8, 6)), np.ones((8, 6)))  # numba warm-up
start = time.perf_counter()
rows = ENERGY_ROWS if sys.argv[2] == "one-pass" else 10**9  # whole: one chunk
out = energy_of_log(robot, sys.argv[1], rows=rows).to_dict()
seconds = time.perf_counter() - start
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"seconds": seconds, "rss": rss, "report": out}))
"""


def _leaves(d: object, where: str = "") -> dict[str, float]:
    if isinstance(d, dict):
        return {k: v for key, x in d.items() for k, v in _leaves(x, f"{where}.{key}").items()}
    if isinstance(d, list):
        return {k: v for i, x in enumerate(d) for k, v in _leaves(x, f"{where}[{i}]").items()}
    return {where: d} if isinstance(d, float) else {}


def run_path(path: Path, which: str) -> dict[str, object]:
    """One path in a fresh interpreter: seconds of the call, peak RSS (MB), the report; and
    the process's wall time."""
    from bench_read import run_python  # the benchmarks' fresh-interpreter runner

    start = time.perf_counter()
    result: dict[str, object] = json.loads(run_python(_CHILD, str(path), which))
    result["process"] = time.perf_counter() - start
    return result


def long_log(args: argparse.Namespace) -> None:
    """The ``--long`` mode: one pass against in memory on a long log."""
    from bench_read import prepared_log  # the benchmark log's generator

    with tempfile.TemporaryDirectory() as tmp:
        path = prepared_log(args, Path(tmp))
        print("| path | call s | process s | peak RSS MB |")
        print("|---|---:|---:|---:|")
        reports = {}
        for which in ("one-pass", "in-memory"):
            r = run_path(path, which)
            reports[which] = r["report"]
            print(f"| {which} | {r['seconds']:.2f} | {r['process']:.2f} | {r['rss']:.0f} |")
        a, b = _leaves(reports["one-pass"]), _leaves(reports["in-memory"])
        worst = max(abs(a[k] - b[k]) / max(abs(b[k]), 1e-12) for k in b)
        print(f"largest relative difference of the two reports: {worst:.1e}")


def main() -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parent))  # bench_read beside this file
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--long", action="store_true", help="a long log, one pass vs in memory")
    parser.add_argument("--minutes", type=float, default=60.0)
    parser.add_argument("--rate", type=float, default=500.0)
    parser.add_argument("--keep", type=Path, help="write the long log here and keep it")
    args = parser.parse_args()
    if args.long:
        long_log(args)
        return
    robot = kinergy.load_robot("ur5e")
    rng = np.random.default_rng(0)
    a = rng.normal(0.0, 0.3, (6, 5))
    b = rng.normal(0.0, 0.3, (6, 5))
    q0 = np.array([0.0, -1.57, 1.0, -1.57, 0.0, 0.0])
    motion = fourier_motion(q0, a, b, base_frequency=2 * np.pi / 10.0, periods=3, dt=0.002)
    energy(robot, motion)  # warm-up: numba kernels
    times = []
    for _ in range(args.repeats):
        start = time.perf_counter()
        report = energy(robot, motion)
        times.append(time.perf_counter() - start)
    print(f"motion: {motion.duration:.1f} s, {len(motion)} samples, {robot.name}")
    print(
        f"E_elec total {report.total_e_elec:.1f} J, efficiency {100 * report.total_efficiency:.1f} %"
    )
    med, best = statistics.median(times) * 1e3, min(times) * 1e3
    print(
        f"energy(): min {best:.1f} ms, median {med:.1f} ms  (bar < 50 ms: {'PASS' if med < 50 else 'FAIL'})"
    )


if __name__ == "__main__":
    main()
