"""Analyse a fleet of 500 one-minute twin logs end to end on one, then two Dask workers.

The fleet (:func:`kinergy.fleet.twin.twin_fleet`, seeded): 20 UR5e twins, 25 one-minute logs
each at 500 Hz spread over 7 days, the programs test A and test B dealt out in turn; robot-02's
friction rises 30 % over the week, robot-03 takes a 5 kg payload from the fourth day. It is
written once into ``--folder`` (two processes) and kept for later runs.

Each run is the ``kinergy fleet energy`` workflow (:func:`kinergy.workflows.fleet.fleet_energy`:
manifest, a local Dask cluster of N single-threaded worker processes, per-cycle energies,
summary and drift, Parquet out, HTML report), timed on the wall clock from the call to its
return (cluster start-up included). Printed: wall time per worker count and the speed-up, each
worker process's peak resident memory (its whole process: Python, NumPy, numba, Dask and at most
one log), the robots flagged as drifting and the step changes found.

    python benchmarks/bench_fleet.py [--folder /tmp/kinergy-fleet-500] [--workers 1 2]
        [--robots 20] [--logs 25] [--seconds 60]
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from kinergy.fleet.twin import twin_fleet
from kinergy.workflows.fleet import FleetOptions, fleet_energy


def build(folder: Path, robots: int, logs: int, seconds: float) -> Path:
    """The twin fleet's manifest, writing the fleet first when it is not there yet."""
    manifest = folder / "fleet.toml"
    if manifest.exists() and len(list(folder.glob("robot-*/*.csv"))) == robots * logs:
        return manifest
    start = time.perf_counter()
    with ProcessPoolExecutor(2) as pool:
        twin_fleet(
            folder, map_=pool.map, robots=robots, days=7, logs=logs, seconds=seconds,
            programs=["test-a", "test-b"], wear={"robot-02": 0.30}, payload={"robot-03": (3, 5.0)},
            seed=0,
        )  # fmt: skip
    print(f"wrote {robots * logs} logs in {time.perf_counter() - start:.0f} s")
    return manifest


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--folder", type=Path, default=Path("/tmp/kinergy-fleet-500"))
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--robots", type=int, default=20)
    parser.add_argument("--logs", type=int, default=25, help="logs per robot")
    parser.add_argument("--seconds", type=float, default=60.0)
    args = parser.parse_args()
    manifest = build(args.folder, args.robots, args.logs, args.seconds)
    size = sum(p.stat().st_size for p in args.folder.glob("robot-*/*.csv")) / 1e9
    print(f"fleet: {args.robots * args.logs} logs of {args.seconds:.0f} s, {size:.1f} GB")
    walls = {}
    for n in args.workers:
        out = args.folder / f"out-{n}"
        start = time.perf_counter()
        options = FleetOptions(workers=n)
        result = fleet_energy([], manifest, out / "fleet.parquet", options, report=out / "report")
        walls[n] = time.perf_counter() - start
        drifting = [r.name for r in result.robots if r.drift]
        changes = sorted({(r.name, str(c.date)) for r in result.robots for c in r.changes})
        print(
            f"{n} worker(s): {result.logs} logs, {sum(r.cycles for r in result.robots)} cycles in "
            f"{walls[n]:.1f} s wall; peak memory per worker {result.peak_rss_MB:.0f} MB; "
            f"drift: {', '.join(drifting) or 'none'}; changes: {changes or 'none'}"
        )
    if 1 in walls:
        for n, wall in walls.items():
            print(f"speed-up 1 -> {n} workers: {walls[1] / wall:.2f}x")


if __name__ == "__main__":
    main()
