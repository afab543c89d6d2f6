"""Time ``kinergy identify`` on a 60-minute 500 Hz UR5e twin log against the 5-minute one (issue 25:
every method peaks under 1 GB and takes at most 12 times its 5-minute time; the default method
within its issue-16 figures).

The logs are the digital twin's test A (``kinergy simulate ur5e --trajectory test-a``, 13.5 s)
tiled to 5 and to 60 minutes with a continuous time stamp (155,710 and 1,800,820 rows; 1.37 GB
for 60 minutes), and the same with a 2 kg payload at (0.01, -0.02, 0.05) m in the flange frame
for the payload case; written to a temporary folder (``--logs DIR`` reuses or keeps them there).
Each case runs the command in a fresh process under ``/usr/bin/time -v`` (wall clock, user +
system time and peak resident memory of the whole command, start-up included), the 5-minute log
then the 60-minute log, back to back:

- ``sequential``: ``kinergy --quiet identify LOG --robot ur5e`` (the default method);
- ``full``: ``--method full`` (target_moment, the twin's log has it);
- ``full current``: ``--method full --target current``;
- ``friction auto``: ``--friction auto``;
- ``payload``: ``--payload-only`` on the loaded logs, the model without the payload.

The 1-minute load average before and after each run is printed: on a shared machine the wall
clock says little without it (the processor time says more).

    python benchmarks/bench_identify_long.py [--cases sequential,full,...] [--logs DIR]
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

import kinergy
from kinergy.io.rtde import write_log
from kinergy.model import Payload
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import simulate

#: the payload of the payload case
PAYLOAD = Payload(mass=2.0, com=[0.01, -0.02, 0.05])
#: case -> (loaded logs, the command's options)
CASES = {
    "sequential": (False, []),
    "full": (False, ["--method", "full"]),
    "full current": (False, ["--method", "full", "--target", "current"]),
    "friction auto": (False, ["--friction", "auto"]),
    "payload": (True, ["--payload-only"]),
}


def make_long_log(path: Path, minutes: float, payload: Payload | None = None) -> int:
    """Write test A's twin log (with ``payload`` at the flange, if given) tiled to ``minutes``
    (continuous 500 Hz time stamps) to ``path``; returns the rows written. One tile is held at
    a time."""
    robot = kinergy.load_robot("ur5e")
    truth = robot.with_payload(payload) if payload is not None else robot
    twin = simulate(truth, paper_trajectory(robot, "test-a", dt=0.002))
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
        ["/usr/bin/time", "-v", *command], capture_output=True, text=True, check=False
    )
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(command)} failed:\n{done.stderr[-2000:]}")

    def field(name: str) -> str:
        match = re.search(rf"{re.escape(name)}: (.+)", done.stderr)
        assert match is not None, done.stderr
        return match.group(1).strip()

    wall = field("Elapsed (wall clock) time (h:mm:ss or m:ss)").split(":")
    seconds = sum(float(x) * 60**i for i, x in enumerate(reversed(wall)))
    cpu = float(field("User time (seconds)")) + float(field("System time (seconds)"))
    rss = float(field("Maximum resident set size (kbytes)")) / 1024.0
    return {"wall": seconds, "cpu": cpu, "rss": rss, "load": before, "load_after": load()}


def logs_in(folder: Path) -> dict[tuple[int, bool], Path]:
    """The four logs (minutes, loaded) in ``folder``, written where missing."""
    out = {}
    for minutes in (5, 60):
        for loaded in (False, True):
            path = folder / f"test-a-{minutes}min{'-payload' if loaded else ''}.csv"
            if not path.exists():
                rows = make_long_log(path, minutes, PAYLOAD if loaded else None)
                print(f"wrote {path}: {rows} rows, {path.stat().st_size / 1e9:.2f} GB")
            out[minutes, loaded] = path
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--cases", default=",".join(CASES), help="comma-separated, of: " + ", ".join(CASES)
    )
    parser.add_argument("--logs", type=Path, help="a folder to keep (or find) the logs in")
    args = parser.parse_args()
    cases = [c.strip() for c in args.cases.split(",")]
    unknown = [c for c in cases if c not in CASES]
    if unknown:
        parser.error(f"unknown cases {unknown}")
    kinergy_cli = str(Path(sys.executable).with_name("kinergy"))
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.logs or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        logs = logs_in(folder)
        print(
            "| case | log | wall s | CPU s | peak RSS MB | load before / after | 60 / 5 min (wall, CPU) |"
        )
        print("|---|---|---:|---:|---:|---|---|")
        for case in cases:
            loaded, options = CASES[case]
            runs = {}
            for minutes in (5, 60):
                out = Path(tmp) / f"{case.replace(' ', '-')}-{minutes}.toml"
                command = [
                    kinergy_cli, "--quiet", "identify", str(logs[minutes, loaded]),
                    "--robot", "ur5e", "--out", str(out), *options,
                ]  # fmt: skip
                r = runs[minutes] = timed(command)
                ratio = ""
                if minutes == 60:
                    ratio = (
                        f"{r['wall'] / runs[5]['wall']:.1f} x, {r['cpu'] / runs[5]['cpu']:.1f} x"
                    )
                print(
                    f"| {case} | {minutes} min | {r['wall']:.1f} | {r['cpu']:.1f} | {r['rss']:.0f} | "
                    f"{r['load']:.1f} / {r['load_after']:.1f} | {ratio} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
