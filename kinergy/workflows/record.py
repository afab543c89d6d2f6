"""``kinergy record``: a controller's RTDE stream to log files until a duration, Ctrl-C or SIGTERM."""

from __future__ import annotations

import os
import threading
from collections.abc import Callable

from kinergy.files import check_output
from kinergy.live.recorder import FIELDS, OPTIONAL_FIELDS, Recording, record
from kinergy.live.rtde import parse_address
from kinergy.live.stream import RecordOptions, Stream, stop_on_signals

__all__ = ["record_to_file"]


def record_to_file(
    address: str,
    out: str | os.PathLike[str],
    options: RecordOptions | None = None,
    *,
    status: Callable[[str], None] | None = None,
) -> Recording:
    """Record every field kinergy uses from the controller at ``address`` (``HOST[:PORT]``) as
    ``options`` say (default: 500 Hz until Ctrl-C, one file).

    SIGINT and SIGTERM end the recording with complete files (``Recording.stopped`` names the
    signal); see :func:`kinergy.live.recorder.record`.

    Raises
    ------
    KinergyError
        A bad address, host or output path, a refused connection, a controller that refuses the
        protocol or the recipe.
    """
    options = options or RecordOptions()
    frequency, minutes, megabytes = (
        options.frequency,
        options.rotate_minutes,
        options.rotate_megabytes,
    )
    host, port = parse_address(address)
    check_output(out)
    stop = threading.Event()
    with stop_on_signals(stop) as seen:
        stream = Stream(host, port, FIELDS, frequency, optional=OPTIONAL_FIELDS, status=status)
        if status is not None:
            major, minor, bugfix, build = stream.version
            status(
                f"connected to {host}:{port} (controller {major}.{minor}.{bugfix}.{build}), "
                f"{len(stream.recipe.names)} fields at {frequency:g} Hz"
            )
        result = record(
            stream,
            out,
            stop=stop,
            duration=options.duration,
            rotate_seconds=None if minutes is None else 60.0 * minutes,
            rotate_bytes=None if megabytes is None else int(megabytes * 1e6),
            status=status,
        )
    if "signal" in seen:
        result.stopped = seen["signal"]
    return result
