"""The one log type: time stamps and named signals, whatever file or stream they came from.

Readers (:mod:`kinergy.io.rtde`), the twin (:mod:`kinergy.simulate`) and the recorder all produce a
:class:`Log`; preprocessing, identification and energy accounting take one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from kinergy.errors import KinergyError

__all__ = ["Log"]

Array = NDArray[np.float64]


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
    """

    path: str
    t: Array
    signals: dict[str, Array] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

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
