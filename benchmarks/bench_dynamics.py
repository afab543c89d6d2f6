"""Benchmark kinergy's batched rigid-body dynamics against Pinocchio.

Run::

    python benchmarks/bench_dynamics.py [--samples 15000] [--repeats 7] [--robot ur5e]
                                        [--threads N] [--warmup 5]

What is compared
----------------
Two operations, each on the same ``N`` seeded random states of the same robot (by default the
UR5e and N = 15,000, i.e. 30 s of a controller log at 500 Hz):

* **RNEA** (inverse dynamics, joint torques):
  ``kinergy.rnea(robot, q, qd, qdd)`` on all samples at once, against
  ``pinocchio.rnea(model, data, q[k], qd[k], qdd[k])`` called for every sample in a Python loop
  that writes into a preallocated ``(N, n)`` array.
* **Joint-torque regressor** ``Y(q, qd, qdd)``, shape ``(N, n, 10 n)``:
  ``kinergy.regressor(robot, q, qd, qdd)`` (a fresh result of the caller's own, whose memory may
  be that of an earlier result no longer referred to: ``kinergy.dynamics.blocks``) against
  ``pinocchio.computeJointTorqueRegressor(model, data, q[k], qd[k], qdd[k])`` in a Python loop
  writing into a freshly allocated ``np.empty((N, n, 10 n))`` each repeat.

Why this is fair
----------------
The task being measured is "dynamics of a whole log", which is how kinergy is used (identification
and prediction over tens of thousands of samples). Pinocchio has no batched API, so a loop over its
per-sample C++ calls is what a Python user of Pinocchio writes; the loop overhead (a few hundred
nanoseconds per call) is part of that cost and is reported, not hidden. Both sides produce the same
output array (same shape, freshly allocated for the regressor), both are warmed up first (numba JIT
and its on-disk cache, Pinocchio's first calls), and the Pinocchio model is built by
``kinergy.dynamics.pinocchio.to_pinocchio`` so that both compute the same physics, which is checked on
the benchmark states before any timing is trusted. The regressor *columns* of the two libraries only
coincide when link frames equal joint frames, so the regressor is checked through its product with
the inertial parameters, ``Y @ inertial_parameters(robot)``, against Pinocchio's RNEA.

kinergy splits the samples over as many threads as numba's thread count (a pool of threads running
the GIL-free kernel); ``--threads 1`` gives a single-thread figure
for a like-for-like comparison with the (single-threaded) Pinocchio loop.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np

import kinergy
from kinergy.dynamics.pinocchio import to_pinocchio

try:
    import pinocchio as pin
except ImportError:  # pragma: no cover - the benchmark needs Pinocchio
    raise SystemExit("this benchmark needs Pinocchio: pip install pin") from None

BAR = 3.0  # kinergy must be at least this many times faster per sample than Pinocchio


@dataclass(frozen=True)
class Timing:
    """Wall-clock and processor times (s, all threads of the process) of the repeated calls of
    one operation on ``samples`` samples."""

    name: str
    times: list[float]
    samples: int
    cpu: list[float]

    @property
    def best(self) -> float:
        return min(self.times)

    @property
    def median(self) -> float:
        return statistics.median(self.times)

    def per_sample_us(self, seconds: float) -> float:
        return seconds / self.samples * 1e6


def random_states(n_joints: int, samples: int, seed: int = 0) -> tuple[np.ndarray, ...]:
    """Seeded states: q uniform in [-pi, pi], qd and qdd standard normal, each (samples, n)."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, size=(samples, n_joints))
    qd = rng.standard_normal((samples, n_joints))
    qdd = rng.standard_normal((samples, n_joints))
    return q, qd, qdd


def pinocchio_rnea(model, data, q, qd, qdd, out: np.ndarray) -> np.ndarray:
    """``pin.rnea`` per sample in a Python loop, into the preallocated ``out`` (N, n)."""
    for k in range(q.shape[0]):
        out[k] = pin.rnea(model, data, q[k], qd[k], qdd[k])
    return out


def pinocchio_regressor(model, data, q, qd, qdd) -> np.ndarray:
    """``pin.computeJointTorqueRegressor`` per sample, into a fresh (N, n, 10 n) array."""
    n = model.nv
    out = np.empty((q.shape[0], n, 10 * n))
    for k in range(q.shape[0]):
        out[k] = pin.computeJointTorqueRegressor(model, data, q[k], qd[k], qdd[k])
    return out


def time_call(name: str, fn: Callable[[], object], repeats: int, samples: int) -> Timing:
    """Time ``fn()`` ``repeats`` times with ``time.perf_counter`` and ``time.process_time``."""
    times, cpu = [], []
    for _ in range(repeats):
        start, start_cpu = time.perf_counter(), time.process_time()
        fn()
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    return Timing(name, times, samples, cpu)


def max_relative_difference(a: np.ndarray, b: np.ndarray) -> float:
    """``max |a - b| / max |b|`` over all entries (relative to the torque scale)."""
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def cpu_description() -> str:
    """CPU model, logical CPU count (and how many this process may use), load average."""
    model = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            model = next(ln.split(":", 1)[1].strip() for ln in f if ln.startswith("model name"))
    except (OSError, StopIteration):
        pass
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    load = f"1-min load {os.getloadavg()[0]:.2f}" if hasattr(os, "getloadavg") else "no load"
    return f"{os.cpu_count()} logical CPUs ({usable} usable), {model}; {load}"


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, default=15_000, help="states per call (15000)")
    parser.add_argument("--repeats", type=int, default=7, help="timed runs per operation (7)")
    parser.add_argument("--robot", default="ur5e", help="built-in robot name or model file")
    parser.add_argument(
        "--warmup", type=int, default=5, help="untimed full-size runs of each operation (5)"
    )
    parser.add_argument(
        "--threads", type=int, default=None, help="numba threads for kinergy (default: all)"
    )
    return parser.parse_args()


def main() -> None:
    args = parse_args()
    if args.threads is not None:
        numba.set_num_threads(args.threads)

    robot = kinergy.load_robot(args.robot)
    model = to_pinocchio(robot)
    data = model.createData()
    n, N = robot.n, args.samples
    q, qd, qdd = random_states(n, N)
    theta = kinergy.inertial_parameters(robot)

    print("kinergy dynamics benchmark")
    print(f"  robot        {robot.name} ({n} joints), {N} samples, {args.repeats} repeats")
    print(
        f"  threads      numba {numba.get_num_threads()} (of {numba.config.NUMBA_NUM_THREADS}),"
        f" Pinocchio 1 (Python loop)"
    )
    print(f"  cpu          {cpu_description()}")
    print(
        f"  versions     python {platform.python_version()}, numpy {np.__version__}, "
        f"numba {numba.__version__}, pinocchio {pin.__version__}, kinergy {kinergy.__version__}"
    )

    pin_tau = np.empty((N, n))
    y_out = np.empty((N, n, 10 * n))
    operations: list[tuple[str, Callable[[], object]]] = [
        ("kinergy.rnea", lambda: kinergy.rnea(robot, q, qd, qdd)),
        ("pin.rnea loop", lambda: pinocchio_rnea(model, data, q, qd, qdd, pin_tau)),
        ("kinergy.regressor", lambda: kinergy.regressor(robot, q, qd, qdd)),
        (
            "pin.computeJointTorqueRegressor loop",
            lambda: pinocchio_regressor(model, data, q, qd, qdd),
        ),
        ("kinergy.regressor out=", lambda: kinergy.regressor(robot, q, qd, qdd, out=y_out)),
    ]

    # Correctness on the benchmark states, before timing anything. (These first calls also make
    # numba compile its kernels, or load them from its on-disk cache.)
    tau = kinergy.rnea(robot, q, qd, qdd)
    y = kinergy.regressor(robot, q, qd, qdd)
    pinocchio_rnea(model, data, q, qd, qdd, pin_tau)
    rel_rnea = max_relative_difference(tau, pin_tau)
    rel_reg = max_relative_difference(y @ theta, pin_tau)
    del y
    print("\ncorrectness (max |difference| / max |Pinocchio rnea|, over all samples and joints)")
    print(f"  kinergy.rnea                              vs pin.rnea: {rel_rnea:.2e}")
    print(f"  kinergy.regressor @ inertial_parameters   vs pin.rnea: {rel_reg:.2e}")
    if max(rel_rnea, rel_reg) > 1e-9:
        raise SystemExit("kinergy and Pinocchio disagree: timings would be meaningless")

    # Warm-up: every timed call, at full size, --warmup times (JIT and first-call costs). A fresh
    # kinergy.regressor result reuses the memory of the previous one once that is dropped
    # (kinergy.dynamics.blocks), as it is here and in a loop of a user's; Pinocchio's loop
    # allocates np.empty each time (fresh pages: glibc maps anything over 32 MB anew).
    for _ in range(args.warmup):
        for _, fn in operations:
            fn()

    timings = [time_call(name, fn, args.repeats, N) for name, fn in operations]

    print("\ntimings (min / median over repeats; processor time of all threads, median)")
    print(f"  {'operation':<38} {'per call (ms)':>17} {'per sample (µs)':>19} {'cpu (ms)':>9}")
    for t in timings:
        print(
            f"  {t.name:<38} {t.best * 1e3:8.2f} /{t.median * 1e3:8.2f}"
            f" {t.per_sample_us(t.best):9.3f} /{t.per_sample_us(t.median):8.3f}"
            f" {statistics.median(t.cpu) * 1e3:9.2f}"
        )

    rows = []
    print(
        f"\nspeed-up Pinocchio / kinergy (per sample: medians, and kinergy's worst run against"
        f" Pinocchio's median; bar ≥ {BAR:g}×)"
    )
    for label, ours, theirs in (
        ("RNEA", timings[0], timings[1]),
        ("regressor", timings[2], timings[3]),
        ("regressor out=", timings[4], timings[3]),
    ):
        ratio = theirs.median / ours.median
        worst = theirs.median / max(ours.times)
        verdict = "PASS" if worst >= BAR else "FAIL"
        print(f"  {label:<15} {ratio:6.1f}× (worst run {worst:5.1f}×)   {verdict}")
        rows.append((label, ours, theirs, ratio))
    print("\none sample (µs per call, min / median of 5 x 2000 calls)")
    for label, fn in (
        ("kinergy.rnea", lambda: kinergy.rnea(robot, q[0], qd[0], qdd[0])),
        ("pin.rnea", lambda: pin.rnea(model, data, q[0], qd[0], qdd[0])),
        ("kinergy.regressor", lambda: kinergy.regressor(robot, q[0], qd[0], qdd[0])),
        (
            "pin.computeJointTorqueRegressor",
            lambda: pin.computeJointTorqueRegressor(model, data, q[0], qd[0], qdd[0]),
        ),
    ):
        one = time_call(label, lambda fn=fn: [fn() for _ in range(2000)], 5, 2000)
        print(
            f"  {label:<32} {one.per_sample_us(one.best):7.2f} / "
            f"{one.per_sample_us(one.median):7.2f}"
        )

    threads = numba.get_num_threads()
    print(
        f"\nmarkdown ({robot.name}, N = {N}, kinergy on {threads} numba thread"
        f"{'s' if threads != 1 else ''}, medians of {args.repeats})\n"
    )
    print("| operation | kinergy µs/sample | Pinocchio µs/sample | ratio |")
    print("|---|---:|---:|---:|")
    for label, ours, theirs, ratio in rows:
        print(
            f"| {label} | {ours.per_sample_us(ours.median):.3f}"
            f" | {theirs.per_sample_us(theirs.median):.3f} | {ratio:.1f}× |"
        )


if __name__ == "__main__":
    main()
