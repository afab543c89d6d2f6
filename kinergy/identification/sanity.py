"""Logs whose signals cannot be a robot's: refused before any fit (a least-squares solver fed
non-finite or absurd values can loop for minutes and return nonsense)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from kinergy.errors import KinergyError
from kinergy.logs.prepare import IdentData

__all__ = ["LIMITS", "STILL_SPAN", "check_motion", "check_signals"]

#: largest plausible magnitude per signal (attribute of IdentData, log name, limit, unit)
#: rad: logs in which no joint's position spans this much show no motion to identify from
STILL_SPAN = 0.02

LIMITS = (
    ("q", "actual_q", 1e3, "rad"),
    ("qd", "actual_qd", 1e2, "rad/s"),
    ("current", "actual_current", 1e3, "A"),
    ("tau_ref", "target_moment", 1e5, "N m"),
    ("torque", "actual_joint_torque", 1e5, "N m"),
)


def check_signals(datas: Sequence[IdentData]) -> None:
    """Raise when a log's joint signal is not finite or beyond :data:`LIMITS`.

    Raises
    ------
    KinergyError
        One line naming the log, the signal, the joint and the value.
    """
    for d in datas:
        for attr, name, limit, unit in LIMITS:
            x = getattr(d, attr)
            if x is None:
                continue
            size = np.where(np.isfinite(x), np.abs(x), np.inf)
            row, joint = np.unravel_index(int(np.argmax(size)), size.shape)
            if size[row, joint] > limit:
                raise KinergyError(
                    f"{d.path}: {name} of joint {joint + 1} is {x[row, joint]:.3g} {unit} at "
                    f"t = {d.t[row]:.3f} s, not a value a robot logs (beyond {limit:g} {unit}): "
                    "a corrupted log"
                )


def check_motion(span: float) -> None:
    """Raise when no joint moves in any log: ``span`` (rad), the largest range of a joint's
    position within one log, is below :data:`STILL_SPAN` (no method can identify anything from
    a static log).

    Raises
    ------
    KinergyError
        One line naming the largest span found.
    """
    if span < STILL_SPAN:
        raise KinergyError(
            f"no joint moves in these logs (largest position span {span:.2g} rad, below "
            f"{STILL_SPAN} rad): nothing to identify from"
        )
