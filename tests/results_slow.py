"""The slow figures of ``docs/results.md`` (minutes each): the programs' benchmark
(``benchmarks/bench_programs.py``, whose ``--check`` / ``--write`` checks its table), every
identification method on the real UR10e logs (``benchmarks/bench_real_identification.py ur10e``),
``kinergy optimize`` with its default settings on every program, the placement recipe's grid.
Used by :mod:`results_figures` (checked by ``benchmarks/bench_doc_figures.py --slow``).
"""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
from doc_figures import PROGRAMS, ROOT, UR10E_HELD_OUT, Runs, need, place

Produce = Callable[[Runs], dict[str, str]]

# ---------------------------------------------------------------------------------------------
# the slow ones: the programs' benchmark, the default settings, the placement (minutes each)


def bench(name: str) -> ModuleType:
    """``benchmarks/NAME.py`` as a module (the one already running, under ``--check``)."""
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, ROOT / "benchmarks" / f"{name}.py")
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


def programs_rows(runs: Runs) -> list[dict[str, Any]]:
    """``bench_programs.run`` on every program, via points kept then free (once per session)."""

    def measure() -> list[dict[str, Any]]:
        b = bench("bench_programs")
        return [b.run(name, via) for via in ("keep", "free") for name in b.SETTINGS]

    rows: list[dict[str, Any]] = runs.kept(("bench_programs",), measure)
    return rows


def programs_table(runs: Runs) -> str:
    return str(bench("bench_programs").table(programs_rows(runs)))


def programs_summary(runs: Runs) -> dict[str, str]:
    rows = programs_rows(runs)
    free = [r for r in rows if r["via"] == "free"]
    kept = [r for r in rows if r["via"] == "keep"]
    saving = [100 * r["saving"] for r in free]
    share = [100 * r["share"] for r in free]
    kept_saving = [100 * r["saving"] for r in kept]
    back = [100 * r["readback_error"] for r in free]
    return {
        "mean": f"{np.mean(saving):.1f}",
        "range": f"{min(saving):.1f}-{max(saving):.1f}",
        "share": f"{min(share):.0f}-{max(share):.0f}",
        "kept": f"{np.mean(kept_saving):.1f}",
        "kept_range": f"{min(kept_saving):.1f}-{max(kept_saving):.1f}",
        "kept_each": ", ".join(f"{x:.1f}" for x in kept_saving),
        "back": f"{max(abs(x) for x in back):.2f}",
        "programs": f"{len(free)}",
        "standing": _span([100 * r["standing"] / r["e_program"] for r in free], 0),
        "ratio": _span([r["saving"] / _motors_saving(r) for r in free], 2),
    }


def _motors_saving(row: dict[str, Any]) -> float:
    """A program's saving of the motors' energy alone (its supply less the standing draw)."""
    return 1.0 - (row["e_optimized"] - row["standing"]) / (row["e_program"] - row["standing"])


def _span(values: list[float], digits: int) -> str:
    return f"{min(values):.{digits}f}-{max(values):.{digits}f}"


def _methods(runs: Runs) -> dict[str, Any]:
    """``bench_real_identification.py ur10e``: the 10 unloaded Fourier runs by each method,
    validated on ``ptp_10_points``, and where wrists 2 and 3 lose it."""
    need(Path(UR10E_HELD_OUT))
    folder = runs.folder / "methods"
    folder.mkdir(exist_ok=True)
    return dict(
        runs.kept(("methods",), lambda: bench("bench_real_identification").bench_ur10e(folder))
    )


def method_row(label: str) -> Produce:
    def produce(runs: Runs) -> dict[str, str]:
        return {f"j{j + 1}": f"{x:.3f}" for j, x in enumerate(_methods(runs)[label]["pooled"])}

    return produce


def standstill(runs: Runs) -> dict[str, str]:
    e = _methods(runs)["standstill"]
    w2, w3 = e["joint 5"], e["joint 6"]
    return {
        "still": f"{100 * w3['still']:.0f}",
        "share": f"{100 * w3['error_share_still']:.0f}",
        "still2": f"{100 * w2['still']:.0f}",
        "share2": f"{100 * w2['error_share_still']:.0f}",
        "moving": f"{w3['r2_moving']:.3f}",
        "ceiling": f"{w3['ceiling']:.3f}",
        "ceiling2": f"{w2['ceiling']:.3f}",
    }


def default_row(program: str) -> Produce:
    """``kinergy optimize ROBOT PROGRAM --tool-symmetry z``: supply before and after, the
    supply's and the motors' saving."""

    def produce(runs: Runs) -> dict[str, str]:
        robot = program.split("_")[0]
        r = runs.json(
            "optimize", robot, str(PROGRAMS / f"{program}.script"), "--tool-symmetry", "z"
        )
        return {
            "before": f"{r['program']['e_supply']:.1f}",
            "after": f"{r['optimized']['e_supply']:.1f}",
            "supply": f"{100 * r['saving_supply']:.1f}",
            "motors": f"{100 * r['saving_motors']:.1f}",
        }

    return produce


def place_grid(runs: Runs) -> dict[str, str]:
    """The depalletising recipe's placement grid (the recipe's command, :func:`doc_figures.place`)."""
    place(runs)
    result = runs.json(
        "place", "ur10e", str(PROGRAMS / "ur10e_depalletising.script"), "--x", "-0.4:0.4",
        "--y", "-0.4:0.4", "--step", "0.2", "--tool-symmetry", "z4", "--configurations", "free",
        "--via", "free",
    )  # fmt: skip
    cells = result["candidates"]
    today, best = result["today"], result["best"]
    return {
        "reachable": f"{sum(c['reachable'] for c in cells)}",
        "cells": f"{len(cells)}",
        "cycle": f"{sum(c['reason'] == 'cannot run at the cycle time' for c in cells)}",
        "reach": f"{sum(c['reason'] == 'out of reach' for c in cells)}",
        "written": f"{today['e_program']:.1f}",
        "today": f"{today['e_supply']:.1f}",
        "x": f"{best['x']:+.1f}",
        "best": f"{best['e_supply']:.1f}",
        "saving": f"{100 * result['saving_beyond_levers']:.1f}",
        "motors": f"{100 * result['saving_beyond_levers_motors']:.1f}",
        "best_motors": f"{best['e_motors']:.1f}",
        "today_motors": f"{today['e_motors']:.1f}",
    }
