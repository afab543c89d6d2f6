"""The program optimiser on the URScript benchmark programs (benchmarks/programs/): per lever.

For every program: the supply energy (model-predicted: motor electrical energy summed on the DC
bus, braking surplus lost, plus the robot file's standing draw over the cycle) of the program as
written, after each lever in turn (2 pi
wraps, IK configurations, tool symmetry, via points, via-point blends, timing), and of re-timing
alone, all re-simulated at 500 Hz at the program's own cycle time; the optimised program written
as URScript, read back and simulated again; limits and targets checked. Where the energy goes
after optimisation (per joint: friction, copper) and what no lever touches
(:func:`kinergy.optimize.program_floor.energy_floor`: the friction floor of a joint path at one
constant speed over the moving time, plus the copper loss of holding the arm against gravity),
for the program's own path and the optimised one: the **floor** is the lower of the two plus the
standing draw over the cycle, the
**headroom** one minus the floor over the program's figure, and the **share** the saving over
the headroom. Each program runs with the via points kept and free (``--via``). Run::

    PYTHONPATH=. python benchmarks/bench_programs.py [--via keep|free|both] [--slow F]
        [--json OUT.json] [--check | --write] [--rows RUN.json] [NAME ...]

``--check`` compares ``docs/results.md``'s table of the programs (and the figures its text takes
from it: ``tests/results_figures.py``, the mechanism of ``tests/doc_figures.py``) with this run,
exit status 1 where they differ; ``--write`` puts this run's figures into the page. ``--rows
RUN.json`` takes the rows of an earlier ``--json`` run of every program instead of measuring.

``--slow F`` runs on a host F times slower as the optimiser sees it: every clock of the process
runs F times fast and every evaluation of the drive model sleeps F - 1 times its own duration.
The figures must not change (the optimiser stops on iterations and tolerances only).
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from kinergy.io.urscript import program_script
from kinergy.io.urscript_reader import parse_program, read_program
from kinergy.model.library import load_robot
from kinergy.optimize.floor import energy_floor
from kinergy.optimize.options import Configurations, ProgramOptions, ToolSymmetry, ViaPoints
from kinergy.optimize.programs import optimize_program
from kinergy.optimize.verify import simulate_path
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
    "ur10e_palletising_layer": ("z2", "free"),
    "ur5e_kitting": ("z", "free"),
}


def slow_host(factor: float) -> None:
    """Make this process a host ``factor`` times slower, as the optimiser can tell: every clock
    runs ``factor`` times fast, and every drive-model evaluation of the optimiser sleeps
    ``factor - 1`` times its own duration."""
    import kinergy.optimize.path_costs as path_costs
    import kinergy.optimize.samples as samples

    for name in ("process_time", "perf_counter", "monotonic", "time", "thread_time"):
        real = getattr(time, name)
        start = real()

        def fast(real: Callable[[], float] = real, start: float = start) -> float:
            return start + factor * (real() - start)

        setattr(time, name, fast)
    sleep, clock = time.sleep, time.thread_time_ns

    def slowed(func: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(func)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            t0 = clock()
            out = func(*args, **kwargs)
            sleep((factor - 1.0) * (clock() - t0) * 1e-9)
            return out

        return wrapper

    for module in (path_costs, samples):
        module.drive_by_payload = slowed(module.drive_by_payload)  # type: ignore[attr-defined]


def _floor(robot: Any, run: Any) -> dict[str, Any]:
    return energy_floor(robot, run).to_dict()


def run(name: str, via: str) -> dict[str, Any]:
    symmetry, configurations = SETTINGS[name]
    robot = load_robot(name.split("_")[0])
    program = read_program(HERE / f"{name}.script")
    options = ProgramOptions(
        configurations=Configurations(configurations),
        tool_symmetry=ToolSymmetry(symmetry),
        via=ViaPoints(via),
    )
    t0, c0 = time.perf_counter(), time.process_time()
    result = optimize_program(
        robot,
        program,
        options,
        progress=lambda m: print(f"  {time.perf_counter() - t0:6.1f} s {m}", file=sys.stderr),
    )
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    text = program_script(result.written)
    back = parse_program(text, path=f"{name}_optimized.script")
    again = simulate_path(robot, program_path(robot, back), standby=result.settings.standby)
    own = result.program.result.score
    assert own is not None and again.result.score is not None
    opt = result.optimized.result.score
    assert opt is not None
    out: dict[str, Any] = {
        "program": name,
        "via": via,
        "moves": len(program.moves),
        "symmetry": symmetry,
        "configurations": configurations,
        "cycle_time": result.program.result.cycle_time,
        "optimized_cycle_time": result.optimized.result.cycle_time,
        "e_program": own,
        "levers": [
            {
                "name": lv.name,
                "e": lv.result.score,
                "status": lv.status.value,
                "saved": lv.saved,
                "repaired": lv.repaired,
                "ok": lv.result.ok,
                "note": lv.note,
            }
            for lv in result.levers
        ],
        "e_optimized": opt,
        "saving": result.saving,
        "timing_only_saving": 1.0 - (result.levers[-1].result.score or own) / own,
        "readback_e": again.result.score,
        "readback_error": again.result.score / opt - 1.0,
        "within_limits": result.optimized.result.ok,
        "targets_met": result.targets_met,
        "worst_target": {
            "mm": 1e3 * max(c.distance for c in result.targets if c.stop),
            "deg": math.degrees(max(c.angle for c in result.targets if c.stop)),
            "rad_s": max(c.speed for c in result.targets if c.stop),
        },
        "left_out": [c.line for c in result.targets if c.left_out],
        "seconds": seconds,
        "cpu_seconds": cpu,
        "floor_program": _floor(robot, result.program),
        "floor_optimized": _floor(robot, result.optimized),
    }
    # what no lever touches includes the standing draw over the cycle (the robot file's, in the
    # supply energy the optimiser minimises)
    standing = result.settings.standby * result.program.result.cycle_time
    floor = min(out["floor_program"]["untouched"], out["floor_optimized"]["untouched"]) + standing
    out["standing"] = standing
    out["floor"] = floor
    out["headroom"] = 1.0 - floor / own
    out["share"] = out["saving"] / out["headroom"]
    return out


def _print_floor(row: dict[str, Any]) -> None:
    """Per joint, as written and optimised: path, friction, copper; the floor and headroom."""

    def fmt(xs: list[float]) -> str:
        return " ".join(f"{x:6.1f}" for x in xs)

    for tag in ("program", "optimized"):
        f = row[f"floor_{tag}"]
        print(f"    {tag:9s} path rad  {fmt(f['path_length'])}")
        print(
            f"    {'':9s} friction  {fmt(f['parts']['friction'])}  floor {fmt(f['friction_floor'])}"
        )
        print(
            f"    {'':9s} copper    {fmt(f['parts']['copper'])}  holding {f['holding_copper']:.1f} J"
            f"  untouched {f['untouched']:.1f} J"
        )
    print(
        f"    floor {row['floor']:.1f} J: headroom {100 * row['headroom']:.1f} %, "
        f"share taken {100 * row['share']:.0f} %"
    )


def _minus(text: str) -> str:
    return text.replace("-", "−")


def table(rows: list[dict[str, Any]]) -> str:
    """The page's table of the programs (``docs/results.md``) from the rows of every program
    with the via points free and kept: per lever the program after it ("–" where it changed
    nothing, the repair in brackets), the floor, headroom and share, the saving with the via
    points kept, re-timing alone, limits and targets, the read-back error; then the means."""
    free = [r for r in rows if r["via"] == "free"]
    kept = {r["program"]: r for r in rows if r["via"] == "keep"}
    lines = [
        "| program | moves | symmetry, IK | cycle [s] | as written [J] | tool symmetry | via points "
        "| blends | timing | optimised [J] | saving | floor [J] | headroom | share | via kept: "
        "saving | re-timing alone | limits, targets | read back |",
        "| --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: "
        "| ---: | ---: | ---: | --- | ---: |",
    ]
    for r in free:
        levers = {lv["name"]: lv for lv in r["levers"]}
        cells = []
        for name in ("tool symmetry", "via points", "blends", "timing"):
            lv = levers.get(name)
            if lv is None or lv["status"] != "kept":
                cells.append("–")
            else:
                cells.append(f"{lv['e']:.1f}" + (f" ({lv['repaired']})" if lv["repaired"] else ""))
        yes = ", ".join("yes" if x else "no" for x in (r["within_limits"], r["targets_met"]))
        alone = _minus(f"{100 * r['timing_only_saving']:.1f}")
        back = _minus(f"{100 * r['readback_error']:+.2f}")
        lines.append(
            f"| `{r['program']}` | {r['moves']} | {r['symmetry']}, {r['configurations']} | "
            f"{r['cycle_time']:.2f} | {r['e_program']:.1f} | {' | '.join(cells)} | "
            f"**{r['e_optimized']:.1f}** | **{100 * r['saving']:.1f} %** | {r['floor']:.1f} | "
            f"{100 * r['headroom']:.1f} % | {100 * r['share']:.0f} % | "
            f"{100 * kept[r['program']]['saving']:.1f} % | "
            f"{alone} % | {yes} | {back} % |"
        )

    def mean(key: str, of: list[dict[str, Any]]) -> float:
        return 100 * sum(r[key] for r in of) / len(of)

    lines.append(
        f"| mean | | | | | | | | | | **{mean('saving', free):.1f} %** | | "
        f"{mean('headroom', free):.1f} % | {mean('share', free):.0f} % | "
        f"{mean('saving', list(kept.values())):.1f} % | {mean('timing_only_saving', free):.1f} % "
        "| | |"
    )
    return "\n".join(lines) + "\n"


def check_page(rows: list[dict[str, Any]] | None, *, write: bool) -> int:
    """``docs/results.md``'s figures from this script (``--check`` / ``--write``), measured
    now (``rows`` None) or from ``rows``; the number that differ."""
    sys.modules.setdefault("bench_programs", sys.modules[__name__])
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from doc_figures import Runs, check
    from results_figures import RESULTS
    from results_slow import programs_rows

    with tempfile.TemporaryDirectory() as tmp:
        runs = Runs(Path(tmp))
        if rows is not None:
            runs.kept(("bench_programs",), lambda: rows)
        programs_rows(runs)
        return check([f for f in RESULTS if f.script == "bench_programs"], runs, write=write)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("names", nargs="*", default=list(SETTINGS))
    parser.add_argument("--via", choices=["keep", "free", "both"], default="both")
    parser.add_argument("--slow", type=float, default=1.0)
    parser.add_argument("--json")
    page = parser.add_mutually_exclusive_group()
    page.add_argument("--check", action="store_true", help="compare docs/results.md with this run")
    page.add_argument("--write", action="store_true", help="put this run into docs/results.md")
    parser.add_argument("--rows", type=Path, help="the rows of an earlier --json run")
    args = parser.parse_args()
    if args.check or args.write:
        rows = json.loads(args.rows.read_text()) if args.rows else None
        sys.exit(1 if check_page(rows, write=args.write) and not args.write else 0)
    if args.slow != 1.0:
        slow_host(args.slow)
    rows = []
    modes = ["keep", "free"] if args.via == "both" else [args.via]
    for via in modes:
        for name in args.names:
            row = run(name, via)
            rows.append(row)
            print(
                f"{name:24s} via {via:4s} {row['moves']:3d} moves  {row['e_program']:8.1f} J -> "
                f"{row['e_optimized']:8.1f} J  saving {100 * row['saving']:5.1f} % "
                f"(timing only {100 * row['timing_only_saving']:5.1f} %)  read back "
                f"{100 * row['readback_error']:+.2f} %  limits {row['within_limits']}  "
                f"targets {row['targets_met']}  {row['seconds']:.1f} s wall, "
                f"{row['cpu_seconds']:.1f} s processor"
            )
            for lv in row["levers"]:
                print(
                    f"    {lv['name']:15s} {lv['e']:8.1f} J  {lv['status']:15s} saved "
                    f"{lv['saved']:7.1f} J  {lv['repaired'] or '':8s} within limits {lv['ok']}  "
                    f"{lv['note']}"
                )
            _print_floor(row)
        chosen = [r for r in rows if r["via"] == via]
        mean = sum(r["saving"] for r in chosen) / len(chosen)
        share = sum(r["share"] for r in chosen) / len(chosen)
        print(
            f"via {via}: mean saving {100 * mean:.2f} % over {len(chosen)} programs, mean share "
            f"of the headroom {100 * share:.0f} %"
        )
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
