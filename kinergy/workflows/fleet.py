"""``kinergy fleet energy``: a fleet's logs on Dask -> cycles in Parquet, summary, HTML report."""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Callable, Sequence
from pathlib import Path

from kinergy.errors import KinergyError
from kinergy.files import check_output, check_outputs
from kinergy.fleet.analysis import LogResult
from kinergy.fleet.manifest import fleet_logs, read_manifest
from kinergy.fleet.parquet import write_cycles
from kinergy.fleet.run import run_on_dask
from kinergy.fleet.summary import FleetResult, summarise
from kinergy.io.rosbag import BagOptions
from kinergy.logs.checks import Check
from kinergy.logs.window import TimeWindow
from kinergy.model.library import load_robot
from kinergy.model.robot import Payload
from kinergy.report.fleet import write_fleet_report

__all__ = ["fleet_energy"]


def fleet_energy(
    logs: Sequence[str | os.PathLike[str]],
    manifest: str | os.PathLike[str],
    out: str | os.PathLike[str],
    *,
    report: str | os.PathLike[str] | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    min_rise: float = 0.05,
    progress: Callable[[int, int, LogResult], None] | None = None,
    bag: BagOptions | None = None,
    accept: frozenset[Check] = frozenset(),
    payload: Payload | None = None,
    window: TimeWindow | None = None,
) -> FleetResult:
    """Analyse every log the manifest and ``logs`` name, write the cycles to ``out`` (Parquet)
    and, with ``report``, the HTML fleet report into that folder. ROS 2 bags are read with their
    robot entry's ``topic`` and ``effort``, else ``bag``'s. Every log passes the plausibility
    checks (:mod:`kinergy.logs.checks`) but those in ``accept``; a log that fails one is
    reported with the check's line as its error. ``payload`` (``--payload``) replaces each log's
    logged payload and its model's; ``window`` (``--from``/``--to``) cuts every log.

    Raises
    ------
    KinergyError
        A bad manifest, a glob matching nothing, a log no robot owns, an unknown model, an
        output that is an input, an unreachable scheduler, or no log that could be analysed.
    """
    fleet = read_manifest(manifest)
    items = [
        dataclasses.replace(i, accept=accept, payload=payload, window=window)
        for i in fleet_logs(fleet, logs, bag)
    ]
    inputs = [Path(manifest), *(Path(i.path) for i in items)]
    inputs += [Path(m) for m in {i.model for i in items} if Path(m).is_file()]
    check_outputs([("--out", out), ("--report", report)], inputs)
    check_output(out)
    if workers is not None and workers < 1:
        raise KinergyError(f"--workers must be >= 1, got {workers}")
    for model in sorted({i.model for i in items}):
        load_robot(model)  # an unknown model is one line here, not an error in every worker
    start = time.perf_counter()
    results, count = run_on_dask(items, scheduler=scheduler, workers=workers, progress=progress)
    result = summarise(
        items, results, workers=count, seconds=time.perf_counter() - start, min_rise=min_rise
    )
    if result.logs == 0:
        raise KinergyError(f"no log could be analysed; the first: {result.skipped[0]['error']}")
    write_cycles(out, result.cycles_table)
    if report is not None:
        write_fleet_report(result, report)
    return result
