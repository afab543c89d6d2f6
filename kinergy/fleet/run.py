"""A fleet's logs analysed on Dask: a local cluster by default, a user's cluster by address.

Each log is one task (:func:`kinergy.fleet.analysis.analyse_log`): a worker reads one log,
works out its cycles and sends back a few numbers per cycle, so a worker holds one log at a time
and the client only small results. A local cluster runs one single-threaded worker process per
core (the compiled dynamics run on one thread inside each, :func:`kinergy.dynamics.threads
.kernel_threads`), so the processes are the parallelism.
"""

from __future__ import annotations

import os
import socket
import urllib.parse
from collections.abc import Callable, Sequence

from kinergy.errors import KinergyError
from kinergy.fleet.analysis import LogResult, analyse_log
from kinergy.fleet.manifest import FleetLog

__all__ = ["run_on_dask"]


def _reachable(scheduler: str) -> None:
    """Fail at once, in one line, when nothing listens at a TCP scheduler address (Dask's
    client would retry until its timeout)."""
    where = urllib.parse.urlsplit(scheduler if "://" in scheduler else f"tcp://{scheduler}")
    try:
        host, port = where.hostname, where.port
    except ValueError as exc:
        raise KinergyError(f"--scheduler {scheduler}: not an address ({exc})") from None
    if where.scheme not in ("tcp", "tls") or host is None or port is None:
        return  # another transport: leave it to Dask
    try:
        socket.create_connection((host, port), timeout=5.0).close()
    except OSError as exc:
        raise KinergyError(f"--scheduler {scheduler}: cannot reach it ({exc})") from None


def _client(scheduler: str | None, workers: int | None) -> tuple[object, object | None, int]:
    """A Dask client (and the local cluster it owns, if any) and its worker count."""
    from distributed import Client, LocalCluster  # the fleet extra: pip install 'kinergy[fleet]'

    if scheduler is not None:
        _reachable(scheduler)
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise KinergyError(f"--scheduler {scheduler}: cannot reach it ({exc})") from None
        return client, None, max(1, len(client.scheduler_info()["workers"]))
    count = workers or os.cpu_count() or 1
    cluster = LocalCluster(
        n_workers=count,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=40,  # errors only
    )
    return Client(cluster), cluster, count


def run_on_dask(
    logs: Sequence[FleetLog],
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[int, int, LogResult], None] | None = None,
) -> tuple[list[LogResult], int]:
    """Analyse every log on Dask; return the results (in completion order) and the number of
    workers.

    Parameters
    ----------
    logs : sequence of FleetLog
    scheduler : str, optional
        A running Dask scheduler's address (``tcp://host:8786``); default a local cluster.
    workers : int, optional
        Worker processes of the local cluster; default one per core.
    progress : callable, optional
        Called with (done, total, result) as each log finishes.
    """
    try:
        from distributed import as_completed  # the fleet extra
    except ImportError:  # pragma: no cover - depends on the installation
        raise KinergyError("the fleet commands need Dask: pip install 'kinergy[fleet]'") from None
    client, cluster, count = _client(scheduler, workers)
    results: list[LogResult] = []
    try:
        futures = client.map(analyse_log, list(logs), pure=False)  # type: ignore[attr-defined]
        for future in as_completed(futures):
            result = future.result()
            results.append(result)
            if progress is not None:
                progress(len(results), len(logs), result)
    finally:
        client.close()  # type: ignore[attr-defined]
        if cluster is not None:
            cluster.close()  # type: ignore[attr-defined]
    return results, count
