"""Benchmark the log reader: a long UR ``record.py`` log read in chunks and whole, against pandas.

Run::

    python benchmarks/bench_read.py [--minutes 60] [--rate 500] [--repeats 3] [--keep FILE]

What is measured
----------------
A seeded log in UR's record.py layout (header line, space separated, 10 significant digits) of
``--minutes`` at ``--rate`` Hz (default 60 min at 500 Hz: 1.8 million rows) with the 31 columns of
the UR10e recipe (timestamp, actual_q, actual_qd, actual_current, target_current, target_moment)
is written once, then each reader runs in a fresh process (so its peak memory is its own):

* ``kinergy.io.formats.iter_log``: chunks of 50,000 rows, each dropped after use (what a
  streaming step holds);
* ``kinergy.io.formats.read_log``: the whole log in memory;
* ``pandas.read_csv(sep=" ", engine="c")`` and ``engine="pyarrow"``: the best alternatives.

It prints the wall time (median of ``--repeats``) and the peak resident memory of each, and a
markdown row per reader.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

SPEC = ("actual_q", "actual_qd", "actual_current", "target_current", "target_moment")

READERS = {
    "kinergy iter_log (chunks)": (
        "from kinergy.io.formats import iter_log\nrows = sum(len(c) for c in iter_log(PATH))\n"
    ),
    "kinergy read_log (whole)": (
        "from kinergy.io.formats import read_log\nrows = len(read_log(PATH))\n"
    ),
    "pandas read_csv (c)": (
        "import pandas as pd\nrows = len(pd.read_csv(PATH, sep=' ', engine='c'))\n"
    ),
    "pandas read_csv (pyarrow)": (
        "import pandas as pd\nrows = len(pd.read_csv(PATH, sep=' ', engine='pyarrow'))\n"
    ),
}

_CHILD = """
import resource, sys, time
PATH = sys.argv[1]
start = time.perf_counter()
{body}
seconds = time.perf_counter() - start
print(rows, seconds, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
"""


def write_log(path: Path, minutes: float, rate: float, seed: int = 0) -> int:
    """Write the benchmark log in chunks (bounded memory); return its rows."""
    rng = np.random.default_rng(seed)
    rows = int(minutes * 60 * rate)
    names = ["timestamp"] + [f"{s}_{k}" for s in SPEC for k in range(6)]
    with path.open("w") as fh:
        fh.write(" ".join(names) + "\n")
        for start in range(0, rows, 100_000):
            n = min(100_000, rows - start)
            t = (start + np.arange(n)) / rate
            phase = 2 * np.pi * 0.1 * t[:, None]
            values = np.sin(phase + np.arange(30)[None, :]) + 0.01 * rng.standard_normal((n, 30))
            np.savetxt(fh, np.column_stack([t, values]), fmt="%.10g", delimiter=" ")
    return rows


def prepared_log(args: argparse.Namespace, tmp: Path) -> Path:
    """The benchmark log: ``--keep`` (written if missing) or one written in ``tmp``; prints
    what was written and the machine's CPUs and load."""
    path: Path = args.keep or tmp / "long.csv"
    if not path.exists():
        t0 = time.perf_counter()
        rows = write_log(path, args.minutes, args.rate)
        print(
            f"wrote {rows} rows, {path.stat().st_size / 1e6:.0f} MB in "
            f"{time.perf_counter() - t0:.0f} s"
        )
    print(f"cpu: {os.cpu_count()} logical CPUs, 1-min load {os.getloadavg()[0]:.1f}")
    return path


def run_python(code: str, *args: str) -> str:
    """Run ``code`` in a fresh interpreter with this tree first on the path; its stdout."""
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    return subprocess.run(
        [sys.executable, "-c", code, *args],
        check=True,
        capture_output=True,
        text=True,
        env=env,
    ).stdout


def run_reader(body: str, path: Path) -> tuple[int, float, float]:
    """Run one reader in a fresh interpreter: rows, seconds, peak RSS in MB."""
    out = run_python(_CHILD.format(body=body), str(path)).split()
    return int(out[0]), float(out[1]), float(out[2])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=60.0)
    parser.add_argument("--rate", type=float, default=500.0)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--keep", type=Path, help="write the log here and keep it")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = prepared_log(args, Path(tmp))
        print("| reader | s (median) | s (all) | peak RSS MB |")
        print("|---|---:|---:|---:|")
        for name, body in READERS.items():
            runs = [run_reader(body, path) for _ in range(args.repeats)]
            seconds = [r[1] for r in runs]
            shown = ", ".join(f"{s:.2f}" for s in seconds)
            print(
                f"| {name} | {statistics.median(seconds):.2f} | {shown} | "
                f"{max(r[2] for r in runs):.0f} |"
            )


if __name__ == "__main__":
    main()
