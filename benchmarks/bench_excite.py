"""Benchmark ``kinergy excite`` with its defaults (UR5e, 5 harmonics, 4 starts, 100 iterations).

Run::

    python benchmarks/bench_excite.py [--repeats 3]

Each run is a fresh process (start-up, the numba cache load and writing the motion included);
it prints the wall and CPU (user + system) seconds of each run and their medians. The CPU time
says what a quiet machine would take when the wall time is inflated by other load.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def one_run(out: Path) -> tuple[float, float]:
    """Wall and CPU seconds of one ``kinergy excite ur5e`` in a fresh process."""
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(
        [
            sys.executable,
            "-c",
            "import sys; from kinergy.cli import run; sys.exit(run())",
            "excite",
            "ur5e",
            "--out",
            str(out),
            "--quiet",
        ],
        check=True,
        env=env,
        capture_output=True,
    )
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        runs = [one_run(Path(tmp) / f"motion{k}.csv") for k in range(args.repeats)]
    print(f"cpu: {os.cpu_count()} logical CPUs, 1-min load {os.getloadavg()[0]:.1f}")
    for k, (wall, cpu) in enumerate(runs):
        print(f"run {k + 1}: wall {wall:.1f} s, cpu {cpu:.1f} s")
    print(
        f"median: wall {statistics.median(r[0] for r in runs):.1f} s, "
        f"cpu {statistics.median(r[1] for r in runs):.1f} s (bar < 20 s)"
    )


if __name__ == "__main__":
    main()
