"""Time the energy-optimal timing of a movej program on the UR5e (issue bar: under 10 s).

Test A of the UR5e doc (:func:`kinergy.trajectory.programs.paper_waypoints`, seed 1): home, six random
points, home, at 3 rad/s and 6 rad/s^2 -- seven moves with the return home -- and the six-move
task without the return. Each run is what ``kinergy optimize`` does for one cycle time: build the
problem (caps, the torque-limited accelerations), solve it at the program's own cycle time, and
re-simulate the program, uniform scaling and the optimum at 500 Hz with every limit checked at
every sample. A warm-up run first (numba kernels), then min and median of ``--repeats`` runs;
the Pareto front (``--points`` cycle times, each solved and verified) is timed once.

    python benchmarks/bench_optimize.py [--repeats 5] [--points 8]
"""

from __future__ import annotations

import argparse
import statistics
import time

import kinergy
from kinergy.optimize import optimize_timing, pareto_front, timing_problem
from kinergy.trajectory.programs import paper_waypoints


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--points", type=int, default=8)
    args = parser.parse_args()
    robot = kinergy.load_robot("ur5e")
    test_a = paper_waypoints(robot, 1)
    tasks = {"test A, 7 moves": test_a, "test A without the return, 6 moves": test_a[:-1]}
    optimize_timing(robot, test_a[:3], speeds=3.0, accels=6.0)  # warm-up: numba kernels
    for name, waypoints in tasks.items():
        times = []
        for _ in range(args.repeats):
            start = time.perf_counter()
            result = optimize_timing(robot, waypoints, speeds=3.0, accels=6.0)
            times.append(time.perf_counter() - start)
        med, best = statistics.median(times), min(times)
        print(
            f"{name}: cycle time {result.cycle_time:.3f} s, program {result.program.e_elec:.1f} J,"
            f" optimised {result.optimized.e_elec:.1f} J (saving {100 * result.saving:.1f} %),"
            f" {result.iterations} iterations, within limits: {result.optimized.ok}"
        )
        print(
            f"  optimize_timing(): min {best:.2f} s, median {med:.2f} s"
            f"  (bar < 10 s: {'PASS' if med < 10.0 else 'FAIL'})"
        )
    problem = timing_problem(robot, test_a)
    start = time.perf_counter()
    front = pareto_front(robot, test_a, speeds=3.0, accels=6.0, points=args.points, problem=problem)
    print(f"Pareto front of test A, {len(front)} cycle times: {time.perf_counter() - start:.2f} s")
    for p in front:
        uniform = f"{p.uniform:.1f} J" + ("" if p.uniform_ok else " (over a limit)")
        print(f"  {p.cycle_time:7.3f} s  optimised {p.optimized:7.1f} J  uniform {uniform}")


if __name__ == "__main__":
    main()
