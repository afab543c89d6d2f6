"""``kinergy place`` on the benchmark cells (benchmarks/programs/): the placement as a lever.

For every program: the base placements of a grid around today's (default x and y from -0.4 to
0.4 m in steps of 0.2 m: 25 candidates), each checked for reach and optimised with the program's
levers (the settings of ``bench_programs.py``, via points free) at today's cycle time within
today's caps; the best placement's program written, read back by kinergy's reader and simulated
again, beside today's optimised program read back the same way; the share of the grid that is
reachable and why the rest is not. The energy maps go to ``--maps DIR``. ``--around
FIRST.json --half D`` searches each cell again around the best placement of a first search
(x and y within D of it; z as ``--z`` gives), a second, finer search as a user would refine
one. Run::

    PYTHONPATH=. python benchmarks/bench_place.py [--x=MIN:MAX] [--y=MIN:MAX] [--z=MIN:MAX]
        [--step S] [--around FIRST.json --half D] [--via keep|free] [--maps DIR]
        [--json OUT.json] [NAME ...]
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import sys
import time
from pathlib import Path
from typing import Any

from bench_programs import HERE, SETTINGS

from kinergy.cli.place import parse_range
from kinergy.model.library import load_robot
from kinergy.optimize.options import Configurations, ProgramOptions, ToolSymmetry, ViaPoints
from kinergy.optimize.placement import PlacementGrid, Range
from kinergy.workflows.place import run_place


def run(name: str, grid: PlacementGrid, via: str, maps: Path | None) -> dict[str, Any]:
    symmetry, configurations = SETTINGS[name]
    robot = load_robot(name.split("_")[0])
    options = ProgramOptions(
        configurations=Configurations(configurations),
        tool_symmetry=ToolSymmetry(symmetry),
        via=ViaPoints(via),
    )
    t0, c0 = time.perf_counter(), _cpu()
    plot = None if maps is None else maps / f"{name}.png"
    result = run_place(
        robot,
        HERE / f"{name}.script",
        grid,
        options=options,
        plot=plot,
        progress=lambda m: print(f"  {time.perf_counter() - t0:6.1f} s {m}", file=sys.stderr),
    )
    search = result.search
    reasons: dict[str, int] = {}
    for c in search.candidates:
        if not c.reachable:
            reasons[c.reason.value] = reasons.get(c.reason.value, 0) + 1
    best = search.best
    assert best.result is not None and search.today.result is not None
    return {
        "program": name,
        "via": via,
        "candidates": len(search.candidates),
        "reachable": sum(c.reachable for c in search.candidates),
        "unreachable": reasons,
        "best": {
            "x": best.placement.x,
            "y": best.placement.y,
            "z": best.placement.z,
            "yaw": math.degrees(best.placement.yaw),
        },
        "e_today_written": search.today.result.program.result.e_supply,
        "e_today": search.today.e_supply,
        "e_today_readback": result.today_readback,
        "e_best": best.e_supply,
        "e_best_readback": result.readback,
        "saving_beyond_levers": result.saving,
        "best_within_limits": best.result.optimized.result.ok,
        "best_targets_met": best.result.targets_met,
        "map": [c.to_dict() for c in search.candidates],
        "seconds": time.perf_counter() - t0,
        "cpu_seconds": _cpu() - c0,
    }


def _cpu() -> float:
    """Processor time of this process and of its finished children (the placements' pool), s."""
    own, pool = (
        resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)
    )
    return own.ru_utime + own.ru_stime + pool.ru_utime + pool.ru_stime


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("names", nargs="*", default=list(SETTINGS))
    parser.add_argument("--x", default="-0.4:0.4")
    parser.add_argument("--y", default="-0.4:0.4")
    parser.add_argument("--z", default="0:0")
    parser.add_argument("--step", type=float, default=0.2)
    parser.add_argument("--around")
    parser.add_argument("--half", type=float, default=0.1)
    parser.add_argument("--via", choices=["keep", "free"], default="free")
    parser.add_argument("--maps")
    parser.add_argument("--json")
    args = parser.parse_args()
    z = parse_range(args.z, "--z", "m")
    first = (
        {}
        if args.around is None
        else {r["program"]: r for r in json.loads(Path(args.around).read_text())}
    )
    maps = None if args.maps is None else Path(args.maps)
    rows = []
    for name in args.names:
        if name in first:
            b = first[name]["best"]
            x = Range(b["x"] - args.half, b["x"] + args.half)
            y = Range(b["y"] - args.half, b["y"] + args.half)
        else:
            x, y = parse_range(args.x, "--x", "m"), parse_range(args.y, "--y", "m")
        grid = PlacementGrid(x=x, y=y, z=z, step=args.step)
        row = run(name, grid, args.via, maps)
        row["grid"] = {
            "x": [x.low, x.high],
            "y": [y.low, y.high],
            "z": [z.low, z.high],
            "step": args.step,
        }
        rows.append(row)
        b = row["best"]
        print(
            f"{name:24s} {row['reachable']:3d}/{row['candidates']} reachable "
            f"{row['unreachable'] or ''}  today {row['e_today_written']:.1f} J as written, "
            f"{row['e_today']:.1f} J optimised (read back {row['e_today_readback']:.1f} J); best "
            f"x {b['x']:+.2f} y {b['y']:+.2f} z {b['z']:+.2f} m: {row['e_best']:.1f} J (read back "
            f"{row['e_best_readback']:.1f} J), {100 * row['saving_beyond_levers']:.1f} % beyond "
            f"the levers; limits {row['best_within_limits']}, targets {row['best_targets_met']}; "
            f"{row['seconds']:.0f} s wall, {row['cpu_seconds']:.0f} s processor",
            flush=True,
        )
    hits = sum(r["saving_beyond_levers"] >= 0.10 for r in rows)
    print(f"{hits} of {len(rows)} cells save >= 10 % beyond the program levers")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
