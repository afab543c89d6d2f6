"""The one log type: time stamps and named signals, whatever file or stream they came from.

Readers (:mod:`kinergy.io.rtde`), the twin (:mod:`kinergy.twin`) and the recorder all produce a
:class:`Log`; preprocessing, identification and energy accounting take one.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError

__all__ = ["TIME_UNITS", "Log", "gaps", "sample_period", "time_unit"]


@dataclass(frozen=True, eq=False)
class Log:
    """A controller log: time and named signals.

    Attributes
    ----------
    path : str
        Where it was read from (for messages).
    t : ndarray, shape (N,)
        ``timestamp``, s.
    signals : dict of str to ndarray
        Vectors as (N, n) arrays under their RTDE name (``actual_q``), scalars as (N,) arrays.
    notes : list of str
        What reading changed (rows dropped by ``repair``), for the user to see.
    ignored : tuple of str
        The file's columns that were not read (no RTDE field), as the file names them; a
        reader sets them on the first chunk only.
    """

    path: str
    t: Array
    signals: dict[str, Array] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    ignored: tuple[str, ...] = ()

    def __contains__(self, name: str) -> bool:
        return name in self.signals

    def __getitem__(self, name: str) -> Array:
        return self.signals[name]

    def __len__(self) -> int:
        return int(self.t.size)

    def require(self, *names: str, purpose: str) -> None:
        """Raise one clear line if any of ``names`` is missing."""
        missing = [n for n in names if n not in self.signals]
        if missing:
            have = ", ".join(sorted(self.signals)) or "none"
            raise KinergyError(
                f"{self.path}: {purpose} needs {', '.join(missing)} (columns "
                f"{', '.join(m + '_0..' for m in missing)}); the log has: {have}"
            )

    @classmethod
    def concatenate(cls, parts: Sequence[Log]) -> Log:
        """One log of ``parts`` (chunks of one file, in order): the first part's path, the
        notes of all."""
        if len(parts) == 1:
            return parts[0]
        first = parts[0]
        return cls(
            first.path,
            np.concatenate([p.t for p in parts]),
            {name: np.concatenate([p.signals[name] for p in parts]) for name in first.signals},
            [note for p in parts for note in p.notes],
            first.ignored,
        )


#: seconds per unit of a time stamp column
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
#: a period within this fraction of 1, 1e3 or 1e6 fits two units (1 Hz in one, 1 kHz in the next)
_AMBIGUOUS = 0.02


def sample_period(t: ArrayLike) -> float:
    """The median positive step of time stamps ``t`` (shape (N,), any unit); nan without one."""
    step = np.diff(np.asarray(t, dtype=float))
    positive = step[step > 0]
    return float(np.median(positive)) if positive.size else float("nan")


def time_unit(t: ArrayLike, where: str) -> str:
    """The unit of time stamps ``t`` from their sample period: ``"s"``, ``"ms"``, ``"us"`` or
    ``"ns"``.

    A period up to 1 is in seconds (a log of 1 Hz or faster). Above it, the unit is the one that
    puts the rate between 1 Hz and 1 kHz: 500 Hz is a period of 2 in ms, 2000 in us, 2e6 in ns.

    Raises
    ------
    KinergyError
        A period over 1e9 (slower than 1 Hz in ns), or one within 2 % of 1, 1e3 or 1e6 above it
        (1 Hz in one unit or 1 kHz in the next: ambiguous).
    """
    period = sample_period(t)
    if not np.isfinite(period) or period <= 1.0:
        return "s"
    units = list(TIME_UNITS)
    for k in range(3):
        edge = 1000.0**k  # 1 Hz in units[k], 1 kHz in units[k + 1]
        if period <= edge * (1.0 + _AMBIGUOUS):
            raise KinergyError(
                f"{where}: timestamp unit is ambiguous: steps of {period:g} are 1 Hz in "
                f"{units[k]} or 1 kHz in {units[k + 1]}"
            )
        if period <= 1000.0 * edge * (1.0 - _AMBIGUOUS):
            return units[k + 1]
    if period <= 1e9 * (1.0 + _AMBIGUOUS):
        return "ns"
    raise KinergyError(f"{where}: timestamp steps of {period:g} are slower than 1 Hz in ns")


def gaps(t: ArrayLike, max_gap: float = 5.0) -> NDArray[np.intp]:
    """Where time stamps ``t`` (shape (N,)) jump by more than ``max_gap`` sample periods: the
    indices ``i`` of the steps ``t[i] -> t[i + 1]`` that are gaps (nothing may integrate across
    one)."""
    tt = np.asarray(t, dtype=float)
    period = sample_period(tt)
    if not np.isfinite(period):
        return np.zeros(0, dtype=np.intp)
    return np.flatnonzero(np.diff(tt) > max_gap * period)
