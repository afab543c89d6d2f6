"""Time the identification of a 30 s, 500 Hz UR5e log (issue bar: under 2 s).

The twin writes a 30 s Fourier excitation at 500 Hz (15,001 samples) with its realistic lag and
noise to a file; the benchmark then times, over ``--repeats`` runs, reading the file
(``read_log``), preparing it (lag estimate, filtering) and the sequential identification, and, if
``--full`` is given, the full method. The whole command (``kinergy identify``, with Python start-up)
can be timed with ``farm-bench`` on the file this writes (``--keep``).

    python benchmarks/bench_identify.py [--repeats 5] [--keep LOG.csv] [--full]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

import kinergy
from kinergy.identification.full import identify_full
from kinergy.identification.sequential import identify_sequential
from kinergy.io.rtde import read_log, write_log
from kinergy.logs.prepare import prepare
from kinergy.trajectory.fourier import fourier_motion
from kinergy.twin import TwinSettings, simulate


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--keep", type=Path, default=None, help="write the log here and keep it")
    parser.add_argument("--full", action="store_true", help="also time the full method")
    args = parser.parse_args()
    robot = kinergy.load_robot("ur5e")
    rng = np.random.default_rng(0)
    q0 = np.array([0.0, -1.4, 1.2, -1.4, -1.57, 0.0])
    motion = fourier_motion(
        q0,
        rng.normal(0, 0.3, (6, 5)),
        rng.normal(0, 0.3, (6, 5)),
        base_frequency=2 * np.pi / 10,
        periods=3,
    )
    twin = simulate(robot, motion, TwinSettings(seed=1))
    t = twin.t
    folder = Path(tempfile.mkdtemp())
    path = args.keep or folder / "excitation.csv"
    write_log(path, twin.t, twin.signals)
    steps: dict[str, list[float]] = {"read_log": [], "prepare": [], "sequential": [], "total": []}
    if args.full:
        steps["full"] = []
    for k in range(args.repeats + 1):  # the first run warms the numba kernels up
        t0 = time.perf_counter()
        log = read_log(path)
        t1 = time.perf_counter()
        data = prepare(log, robot.n)
        t2 = time.perf_counter()
        identify_sequential(robot, [data])
        t3 = time.perf_counter()
        if k == 0:
            continue
        steps["read_log"].append(t1 - t0)
        steps["prepare"].append(t2 - t1)
        steps["sequential"].append(t3 - t2)
        steps["total"].append(t3 - t0)
        if args.full:
            t4 = time.perf_counter()
            identify_full(robot, [data])
            steps["full"].append(time.perf_counter() - t4)
    print(f"log: {path} ({len(t)} samples, {t[-1] - t[0]:.1f} s at 500 Hz)")
    for name, times in steps.items():
        print(
            f"  {name:<11} min {min(times) * 1e3:7.1f} ms   median {statistics.median(times) * 1e3:7.1f} ms"
        )
    med = statistics.median(steps["total"])
    print(f"read + prepare + identify: {med:.3f} s (bar < 2 s: {'PASS' if med < 2 else 'FAIL'})")


if __name__ == "__main__":
    main()
