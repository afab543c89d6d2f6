"""Time ``kinergy identify`` on a 60-minute 500 Hz UR5e twin log (issue 16 bar: under 30 s and under
1 GB peak memory, results equal to the in-memory path to 1e-9 relative).

The log is the digital twin's test A (``kinergy simulate ur5e --trajectory test-a``, 13.5 s) tiled
to ``--minutes`` with a continuous time stamp (1.8 M rows, 1.37 GB for 60 minutes), written to a
temporary folder (or ``--log FILE`` reuses one, ``--keep FILE`` keeps the one written). Then, each
in a fresh process under ``/usr/bin/time -v`` (wall clock and peak resident memory of the whole
command, start-up and numba compilation included):

- ``streamed``: ``kinergy --quiet identify LOG --robot ur5e --out streamed.toml`` (the default
  method, read in chunks: :mod:`kinergy.identify.streamed`);
- ``in-memory`` (with ``--in-memory``): the same identification with the whole log held
  (:func:`kinergy.workflows.logs.prepared_logs` then :func:`kinergy.workflows.identify.identify_model`).

and the largest relative difference between the two written model files over every number. The
1-minute load average before and after each run is printed: on a shared machine the wall clock
says little without it (the processor time is printed too).

    python benchmarks/bench_identify_long.py [--minutes 60] [--in-memory] [--log FILE | --keep FILE]
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

import kinergy
from kinergy.io.rtde import write_log
from kinergy.simulate import simulate
from kinergy.trajectory.programs import paper_trajectory

_IN_MEMORY = """
import sys
import kinergy
from kinergy.workflows.identify import identify_model
from kinergy.workflows.logs import prepared_logs
robot = kinergy.load_robot("ur5e")
identify_model(robot, prepared_logs([sys.argv[1]], n_joints=robot.n), sys.argv[2])
"""


def make_long_log(path: Path, minutes: float) -> int:
    """Write test A's twin log tiled to ``minutes`` (continuous 500 Hz time stamps) to ``path``;
    returns the rows written. One tile is held at a time."""
    robot = kinergy.load_robot("ur5e")
    twin = simulate(robot, paper_trajectory(robot, "test-a", dt=0.002))
    dt = float(twin.t[1] - twin.t[0])
    period = float(twin.t[-1] - twin.t[0]) + dt
    tiles = int(np.ceil(minutes * 60.0 / period))
    with tempfile.TemporaryDirectory() as tmp, path.open("w") as out:
        tile = Path(tmp) / "tile.csv"
        for k in range(tiles):
            write_log(tile, twin.t + k * period, twin.signals)
            with tile.open() as f:
                header = f.readline()
                if k == 0:
                    out.write(header)
                shutil.copyfileobj(f, out)
    return tiles * twin.t.size


def load() -> float:
    """The 1-minute load average."""
    return os.getloadavg()[0]


def timed(command: list[str]) -> dict[str, float]:
    """Wall clock (s), user + system time (s) and peak RSS (MB) of ``command`` (``/usr/bin/time -v``)."""
    before = load()
    done = subprocess.run(
        ["/usr/bin/time", "-v", *command], capture_output=True, text=True, check=True
    )

    def field(name: str) -> str:
        match = re.search(rf"{re.escape(name)}: (.+)", done.stderr)
        assert match is not None, done.stderr
        return match.group(1).strip()

    wall = field("Elapsed (wall clock) time (h:mm:ss or m:ss)").split(":")
    seconds = sum(float(x) * 60**i for i, x in enumerate(reversed(wall)))
    cpu = float(field("User time (seconds)")) + float(field("System time (seconds)"))
    rss = float(field("Maximum resident set size (kbytes)")) / 1024.0
    return {"wall": seconds, "cpu": cpu, "rss": rss, "load": before, "load_after": load()}


def numbers(path: Path) -> dict[str, float]:
    """Every number of a model file, by its place."""
    out: dict[str, float] = {}

    def walk(x: Any, where: str) -> None:
        if isinstance(x, dict):
            for k, v in x.items():
                walk(v, f"{where}.{k}")
        elif isinstance(x, list):
            for i, v in enumerate(x):
                walk(v, f"{where}[{i}]")
        elif isinstance(x, int | float) and not isinstance(x, bool):
            out[where] = float(x)

    walk(tomllib.loads(path.read_text()), "")
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0)
    parser.add_argument("--in-memory", action="store_true", help="also the whole-log path")
    parser.add_argument("--log", type=Path, help="an existing long log to identify")
    parser.add_argument("--keep", type=Path, help="write the long log here and keep it")
    args = parser.parse_args()
    kinergy_cli = str(Path(sys.executable).with_name("kinergy"))
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        log = args.log or args.keep or folder / "long.csv"
        if args.log is None:
            rows = make_long_log(log, args.minutes)
            print(f"wrote {log}: {rows} rows, {log.stat().st_size / 1e9:.2f} GB")
        runs = {
            "streamed": [
                kinergy_cli, "--quiet", "identify", str(log), "--robot", "ur5e",
                "--out", str(folder / "streamed.toml"),
            ],
        }  # fmt: skip
        if args.in_memory:
            code = [sys.executable, "-c", _IN_MEMORY, str(log), str(folder / "in-memory.toml")]
            runs["in-memory"] = code
        print("| path | wall s | CPU s | peak RSS MB | load before / after |")
        print("|---|---:|---:|---:|---|")
        for name, command in runs.items():
            r = timed(command)
            print(
                f"| {name} | {r['wall']:.1f} | {r['cpu']:.1f} | {r['rss']:.0f} | "
                f"{r['load']:.1f} / {r['load_after']:.1f} |"
            )
        if args.in_memory:
            a, b = numbers(folder / "streamed.toml"), numbers(folder / "in-memory.toml")
            assert a.keys() == b.keys()
            worst = max(abs(a[k] - b[k]) / max(abs(a[k]), abs(b[k]), 1e-300) for k in a)
            print(f"{len(a)} numbers in the model files; largest relative difference {worst:.1e}")


if __name__ == "__main__":
    main()
