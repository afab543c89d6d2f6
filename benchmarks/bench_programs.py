"""The program optimiser on the URScript benchmark programs (benchmarks/programs/): per lever.

For every program: the supply energy (model-predicted: motor electrical energy summed on the DC
bus, braking surplus lost, no standby) of the program as written, after each lever in turn (2 pi
wraps, IK configurations, tool symmetry, via-point blends, timing), and of re-timing alone, all
re-simulated at 500 Hz at the program's own cycle time; the optimised program written as URScript,
read back and simulated again; limits and targets checked. Where the energy goes after
optimisation (per joint: friction, copper) and what no lever touches
(:func:`kinergy.optimize.program_floor.energy_floor`: the friction floor of the optimised joint
path at one constant speed over the moving time, plus the copper loss of holding the arm against
gravity): ``ceiling`` is one minus that over the program's figure. Run::

    PYTHONPATH=. python benchmarks/bench_programs.py [--json OUT.json] [NAME ...]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from kinergy.io.urscript import program_script
from kinergy.io.urscript_reader import parse_program, read_program
from kinergy.model.library import load_robot
from kinergy.optimize.program_floor import energy_floor
from kinergy.optimize.program_verify import simulate_path
from kinergy.optimize.programs import optimize_program
from kinergy.trajectory.program_path import program_path

HERE = Path(__file__).parent / "programs"

#: each program's tool symmetry, as its header declares, and its IK configurations option
SETTINGS = {
    "ur5e_conveyor_to_tray": ("z", "free"),
    "ur5e_machine_tending": ("z2", "keep"),
    "ur5e_sorting": ("z", "free"),
    "ur10e_bin_to_fixture": ("z2", "keep"),
    "ur10e_depalletising": ("z4", "free"),
    "ur10e_palletising": ("z2", "free"),
}


def run(name: str) -> dict[str, object]:
    symmetry, configurations = SETTINGS[name]
    robot = load_robot(name.split("_")[0])
    program = read_program(HERE / f"{name}.script")
    t0 = time.perf_counter()
    result = optimize_program(
        robot,
        program,
        configurations=configurations,
        tool_symmetry=symmetry,
        compare_timing=True,
        progress=lambda m: print(f"  {time.perf_counter() - t0:6.1f} s {m}", file=sys.stderr),
    )
    seconds = time.perf_counter() - t0
    text = program_script(result.written)
    back = parse_program(text, path=f"{name}_optimized.script")
    again = simulate_path(robot, program_path(robot, back), objective=None)
    own = result.program.result.score
    out = {
        "program": name,
        "moves": len(program.moves),
        "symmetry": symmetry,
        "configurations": configurations,
        "cycle_time": result.program.result.cycle_time,
        "e_program": own,
        "levers": [(lv.name, lv.result.score, lv.kept, lv.result.ok) for lv in result.levers],
        "e_optimized": result.optimized.result.score,
        "saving": result.saving,
        "timing_only_saving": 1.0 - result.levers[-1].result.score / own,
        "readback_e": again.result.score,
        "readback_error": again.result.score / result.optimized.result.score - 1.0,
        "within_limits": result.optimized.result.ok,
        "targets_met": result.targets_met,
        "seconds": seconds,
        "floor_program": energy_floor(robot, result.program).to_dict(),
        "floor_optimized": energy_floor(robot, result.optimized).to_dict(),
    }
    out["ceiling"] = 1.0 - out["floor_optimized"]["untouched"] / own
    return out


def _print_floor(row: dict) -> None:
    """Per joint, as written and optimised: path, friction, copper; the floor and the ceiling."""
    for tag in ("program", "optimized"):
        f = row[f"floor_{tag}"]
        fmt = lambda xs: " ".join(f"{x:6.1f}" for x in xs)  # noqa: E731
        print(f"    {tag:9s} path rad  {fmt(f['path_length'])}")
        print(
            f"    {'':9s} friction  {fmt(f['parts']['friction'])}  floor {fmt(f['friction_floor'])}"
        )
        print(
            f"    {'':9s} copper    {fmt(f['parts']['copper'])}  holding {f['holding_copper']:.1f} J"
        )
    print(
        f"    untouched by any lever {row['floor_optimized']['untouched']:.1f} J: ceiling "
        f"{100 * row['ceiling']:.1f} % saving"
    )


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("names", nargs="*", default=list(SETTINGS))
    parser.add_argument("--json")
    args = parser.parse_args()
    rows = []
    for name in args.names:
        row = run(name)
        rows.append(row)
        print(
            f"{name:24s} {row['moves']:3d} moves  {row['e_program']:8.1f} J -> "
            f"{row['e_optimized']:8.1f} J  saving {100 * row['saving']:5.1f} % "
            f"(timing only {100 * row['timing_only_saving']:5.1f} %)  read back "
            f"{100 * row['readback_error']:+.2f} %  limits {row['within_limits']}  "
            f"targets {row['targets_met']}  {row['seconds']:.0f} s"
        )
        for lever, e, kept, ok in row["levers"]:
            print(f"    {lever:15s} {e:8.1f} J  kept {kept}  within limits {ok}")
        _print_floor(row)
    mean = sum(r["saving"] for r in rows) / len(rows)
    print(f"mean saving {100 * mean:.1f} % over {len(rows)} programs")
    ceiling = sum(r["ceiling"] for r in rows) / len(rows)
    print(f"mean ceiling {100 * ceiling:.1f} % (friction floor + holding copper untouched)")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
