"""Time the one optimiser on the UR5e doc's test A, a movej program (task), on the UR5e.

Test A (:func:`kinergy.trajectory.programs.paper_waypoints`, seed 1): home, six random points,
home, at 3 rad/s and 6 rad/s^2 -- seven moves with the return home -- read as a task (the same
program type as a URScript program) and optimised as ``kinergy optimize ur5e test-a`` does at
its own cycle time: every lever (2 pi wraps, blends, timing), each re-simulated at 500 Hz with
every limit checked at every sample; then with the timing lever alone (``--no-blends``), and the
Pareto front (``--points`` cycle times, each re-timed and verified) once. A warm-up run first
(numba kernels), then min and median of ``--repeats`` runs of processor and wall time.

    python benchmarks/bench_optimize.py [--repeats 3] [--points 8]
"""

from __future__ import annotations

import argparse
import statistics
import time

import kinergy
from kinergy.io.task import load_task
from kinergy.optimize import ProgramOptions, optimize_program, pareto_front


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--points", type=int, default=8)
    args = parser.parse_args()
    robot = kinergy.load_robot("ur5e")
    task = load_task("test-a", robot=robot)
    optimize_program(robot, task)  # warm-up: numba kernels
    for name, options in (
        ("test A, every lever", ProgramOptions()),
        ("test A, timing alone (--no-blends)", ProgramOptions(blends=False)),
    ):
        walls, cpus = [], []
        for _ in range(args.repeats):
            w0, c0 = time.perf_counter(), time.process_time()
            result = optimize_program(robot, task, options)
            walls.append(time.perf_counter() - w0)
            cpus.append(time.process_time() - c0)
        print(
            f"{name}: cycle time {result.program.result.cycle_time:.3f} s, supply "
            f"{result.program.result.e_supply:.1f} J -> {result.optimized.result.e_supply:.1f} J "
            f"({100 * result.saving_supply:.1f} %; the motors' {100 * result.saving_motors:.1f} "
            f"%), within limits: {result.optimized.result.ok}"
        )
        print(
            f"  processor min {min(cpus):.2f} s, median {statistics.median(cpus):.2f} s; wall "
            f"median {statistics.median(walls):.2f} s"
        )
    start = time.perf_counter()
    front = pareto_front(robot, result, points=args.points)
    print(f"Pareto front of test A, {len(front)} cycle times: {time.perf_counter() - start:.2f} s")
    for p in front:
        opt = "-" if p.optimized is None else f"{p.optimized:.1f} J"
        uniform = f"{p.uniform:.1f} J" + ("" if p.uniform_ok else " (over a limit)")
        print(f"  {p.cycle_time:7.3f} s  optimised {opt:>10s}  uniform {uniform}")


if __name__ == "__main__":
    main()
