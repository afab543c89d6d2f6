"""A time window on a log (``--from``/``--to``): the samples a command reads, in seconds on the
log's own time axis.

The log's own axis is its time stamps in seconds as the reader gives them: a UR log's
``timestamp`` (the controller's time, converted from ms, µs or ns where the log holds those), a
ROS 2 bag's stamps counted from its first message. Every command that reads a log takes the
window (:class:`~kinergy.logs.reading.LogReading`); the checks then judge the window alone, as
every result is computed from it. A bound outside the log, or ``--from`` not before ``--to``, is
refused in one line.

Examples
--------
>>> w = TimeWindow(1.0, 2.0)
>>> import numpy as np
>>> w.keep(np.array([0.5, 1.0, 1.5, 2.0, 2.5])).tolist()
[False, True, True, True, False]
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.io.log import Log

__all__ = ["TimeWindow", "WindowCut"]


@dataclass(frozen=True)
class TimeWindow:
    """Samples ``start <= t <= stop`` (s, the log's own time axis); None: from the log's
    first sample, to its last.

    Raises
    ------
    KinergyError
        A bound that is not finite, or ``start`` not before ``stop``.
    """

    start: float | None = None
    stop: float | None = None

    def __post_init__(self) -> None:
        for flag, value in (("--from", self.start), ("--to", self.stop)):
            if value is not None and not math.isfinite(value):
                raise KinergyError(f"{flag} {value}: not a finite number of seconds")
        if self.start is not None and self.stop is not None and not self.start < self.stop:
            raise KinergyError(
                f"--from {self.start:.12g} s is not before --to {self.stop:.12g} s: the window holds "
                "no time"
            )

    def __str__(self) -> str:
        parts = [f"--from {self.start:.12g} s" if self.start is not None else ""]
        parts += [f"--to {self.stop:.12g} s" if self.stop is not None else ""]
        return " ".join(p for p in parts if p)

    def keep(self, t: Array) -> NDArray[np.bool_]:
        """Which time stamps ``t`` (s) lie in the window."""
        ok = np.ones(t.shape, dtype=bool)
        if self.start is not None:
            ok &= t >= self.start
        if self.stop is not None:
            ok &= t <= self.stop
        return ok


class WindowCut:
    """A log's chunks cut to a :class:`TimeWindow` as they pass (:meth:`cut`), and the refusal
    of a window that lies outside the log (:meth:`finish`).

    Parameters
    ----------
    window : TimeWindow
    path : str
        The log's name, for messages.
    """

    def __init__(self, window: TimeWindow, path: str):
        self.window, self.path = window, path
        self.first = math.nan  # the log's first time stamp
        self.last = math.nan  # the last time stamp read
        self.period = math.nan
        self.kept = 0
        self.done = False  # past the window's end: nothing more to read

    def cut(self, chunk: Log) -> Log:
        """``chunk``'s samples within the window (perhaps none).

        Raises
        ------
        KinergyError
            ``--from`` before the log's first sample.
        """
        if not len(chunk):
            return chunk
        if math.isnan(self.first):
            self.first = float(chunk.t[0])
            if len(chunk) > 1:
                self.period = float(np.median(np.diff(chunk.t)))
            start = self.window.start
            if start is not None and start < self.first - self._slack():
                raise KinergyError(
                    f"{self.path}: --from {start:.12g} s is before the log's first sample at "
                    f"{self.first:.10g} s (seconds on the log's own time axis)"
                )
        self.last = float(chunk.t[-1])
        stop = self.window.stop
        if stop is not None and self.last > stop:
            self.done = True
        keep = self.window.keep(chunk.t)
        self.kept += int(keep.sum())
        if keep.all():
            return chunk
        signals = {k: v[keep] for k, v in chunk.signals.items()}
        return Log(chunk.path, chunk.t[keep], signals, chunk.notes, chunk.ignored)

    def _slack(self) -> float:
        """Half a sample period (a bound given to the printed digits of a time stamp)."""
        return 0.5 * self.period if math.isfinite(self.period) else 0.0

    def finish(self) -> str:
        """A note of what was kept, after the last chunk.

        Raises
        ------
        KinergyError
            ``--to`` after the log's last sample, or fewer than 2 samples in the window.
        """
        span = f"the log spans {self.first:.10g} to {self.last:.10g} s on its own time axis"
        stop = self.window.stop
        if stop is not None and not self.done and stop > self.last + self._slack():
            raise KinergyError(
                f"{self.path}: --to {stop:.12g} s is after the log's last sample ({span})"
            )
        if self.kept < 2:
            raise KinergyError(
                f"{self.path}: {self.window} holds {self.kept} sample(s) ({span}); a log needs 2"
            )
        return f"{self.path}: {self.window}: {self.kept} samples read"
