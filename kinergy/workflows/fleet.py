"""``kinergy fleet energy``: a fleet's logs on Dask -> cycles in Parquet, summary, HTML report."""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from kinergy.checks import integer, number
from kinergy.errors import KinergyError
from kinergy.files import check_output, check_outputs
from kinergy.fleet.analysis import LogResult
from kinergy.fleet.manifest import fleet_logs, read_manifest
from kinergy.fleet.parquet import write_cycles
from kinergy.fleet.run import run_on_dask
from kinergy.fleet.summary import FleetResult, summarise
from kinergy.logs.reading import LogReading
from kinergy.model.library import load_robot
from kinergy.report.fleet import write_fleet_report

__all__ = ["FleetOptions", "fleet_energy"]


@dataclass(frozen=True)
class FleetOptions:
    """How ``kinergy fleet energy`` runs, checked on construction (one line naming the option).

    Attributes
    ----------
    scheduler : str or None
        The address of a Dask scheduler; None: a local cluster.
    workers : int or None
        The local cluster's worker processes, >= 1; None: one per core.
    min_rise : float
        The smallest rise of a robot's energy or friction per cycle called drift (a fraction,
        >= 0).
    """

    scheduler: str | None = None
    workers: int | None = None
    min_rise: float = 0.05

    def __post_init__(self) -> None:
        if self.workers is not None:
            object.__setattr__(self, "workers", integer(self.workers, "--workers", ge=1))
        object.__setattr__(self, "min_rise", number(self.min_rise, "--min-rise", ge=0.0))


def fleet_energy(
    logs: Sequence[str | os.PathLike[str]],
    manifest: str | os.PathLike[str],
    out: str | os.PathLike[str],
    options: FleetOptions | None = None,
    *,
    reading: LogReading | None = None,
    report: str | os.PathLike[str] | None = None,
    progress: Callable[[int, int, LogResult], None] | None = None,
) -> FleetResult:
    """Analyse every log the manifest and ``logs`` name, write the cycles to ``out`` (Parquet)
    and, with ``report``, the HTML fleet report into that folder. ROS 2 bags are read with their
    robot entry's ``topic`` and ``effort``, else ``reading.bag``'s. Every log passes the
    plausibility checks (:mod:`kinergy.logs.checks`) but those in ``reading.accept``; a log that
    fails one is reported with the check's line as its error. ``reading.payload`` (``--payload``)
    replaces each log's logged payload and its model's; ``reading.window`` (``--from``/``--to``)
    cuts every log.

    Raises
    ------
    KinergyError
        A bad manifest, a glob matching nothing, a log no robot owns, an unknown model, an
        output that is an input, an unreachable scheduler, or no log that could be analysed.
    """
    options = options or FleetOptions()
    reading = reading or LogReading()
    fleet = read_manifest(manifest)
    items = [
        dataclasses.replace(
            i, accept=reading.accept, payload=reading.payload, window=reading.window
        )
        for i in fleet_logs(fleet, logs, reading.bag)
    ]
    inputs = [Path(manifest), *(Path(i.path) for i in items)]
    inputs += [Path(m) for m in {i.model for i in items} if Path(m).is_file()]
    check_outputs([("--out", out), ("--report", report)], inputs)
    check_output(out)
    for model in sorted({i.model for i in items}):
        load_robot(model)  # an unknown model is one line here, not an error in every worker
    start = time.perf_counter()
    results, count = run_on_dask(
        items, scheduler=options.scheduler, workers=options.workers, progress=progress
    )
    seconds = time.perf_counter() - start
    result = summarise(items, results, workers=count, seconds=seconds, min_rise=options.min_rise)
    if result.logs == 0:
        raise KinergyError(f"no log could be analysed; the first: {result.skipped[0]['error']}")
    write_cycles(out, result.cycles_table)
    if report is not None:
        write_fleet_report(result, report)
    return result
