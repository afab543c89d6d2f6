"""Time the energy accounting of a 30 s, 500 Hz motion on the UR5e (issue bar: under 50 ms).

The motion is a Fourier-series excitation (nursing eq 22) of 30 s sampled at 500 Hz (15,001
samples) on all six joints; ``kinergy.accounting.energy.energy`` runs the whole drive model on it
(RNEA, reflected rotor inertia, power-flow friction, currents, voltages, eq 23 power) and integrates
per joint with the four-way breakdown. Warm-up first (numba kernels), then min and median of
``--repeats`` runs.

    python benchmarks/bench_energy.py [--repeats 15]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

import kinergy
from kinergy.accounting.energy import energy
from kinergy.trajectory.fourier import fourier_motion


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15)
    args = parser.parse_args()
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
