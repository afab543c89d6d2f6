"""A joint-space motion: time stamps and joint angles, speeds and accelerations."""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError

__all__ = ["CONTROLLER_DT", "MAX_SAMPLES", "Motion", "MotionSource", "sample_times"]


class MotionSource(enum.StrEnum):
    """Which of a log's joint signals a motion is read from: the commanded ``target_q/qd/qdd``
    (noise-free, what the program asked for), the measured ``actual_q/qd`` (accelerations from a
    spline of the speed), or ``AUTO``: target signals when the log has them, else actual ones."""

    AUTO = "auto"
    TARGET = "target"
    ACTUAL = "actual"


#: the UR controller's cycle, s (e-Series: 500 Hz): the period it logs, plans and servos at
CONTROLLER_DT = 0.002
#: the most samples a planned program takes (1000 s at the controller's 500 Hz): its drive state
#: holds about 40 arrays of (samples, joints) in memory
MAX_SAMPLES = 500_000


def sample_times(duration: float, dt: float, longest: str = "") -> Array:
    """The sample times of a planned program, ``0, dt, ...`` up to the first at or after
    ``duration`` (s), shape (N,).

    Raises
    ------
    KinergyError
        More than :data:`MAX_SAMPLES` samples (a speed or acceleration far too small), the
        message naming the program's length and ``longest`` (what takes longest, in words).
    """
    steps = np.ceil(duration / dt - 1e-9)
    if not steps < MAX_SAMPLES:
        what = f" ({longest})" if longest else ""
        raise KinergyError(
            f"the program lasts {duration:.4g} s{what}: sampled every {dt:g} s it would take "
            f"{steps:.4g} samples, more than the {MAX_SAMPLES:,} kinergy plans "
            f"({MAX_SAMPLES * dt / 60:.0f} min); a speed or acceleration far too small? "
            "(rad/s and rad/s², m/s and m/s² for a linear move)"
        )
    return np.arange(int(steps) + 1, dtype=float) * dt


@dataclass(frozen=True, eq=False)
class Motion:
    """A sampled joint-space motion.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Time, s, strictly increasing.
    q, qd, qdd : ndarray, shape (N, n)
        Joint angles (rad), speeds (rad/s), accelerations (rad/s^2).
    """

    t: Array
    q: Array
    qd: Array
    qdd: Array

    def __post_init__(self) -> None:
        t = np.asarray(self.t, dtype=float)
        if t.ndim != 1 or t.size < 1:
            raise KinergyError(f"motion time must be a 1-D array, got shape {t.shape}")
        if t.size > 1 and not np.all(np.diff(t) > 0):
            k = int(np.argmax(np.diff(t) <= 0))
            raise KinergyError(f"motion time must increase strictly; it does not at sample {k + 1}")
        arrays = {}
        for name in ("q", "qd", "qdd"):
            arr = np.asarray(getattr(self, name), dtype=float)
            if arr.ndim != 2 or arr.shape[0] != t.size:
                raise KinergyError(f"motion {name} must have shape ({t.size}, n), got {arr.shape}")
            if not np.all(np.isfinite(arr)):
                raise KinergyError(f"motion {name} has non-finite values")
            arrays[name] = arr
        shapes = {a.shape for a in arrays.values()}
        if len(shapes) != 1:
            raise KinergyError(f"motion q, qd, qdd shapes differ: {sorted(shapes)}")
        object.__setattr__(self, "t", t)
        for name, arr in arrays.items():
            object.__setattr__(self, name, arr)

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.q.shape[1])

    @property
    def duration(self) -> float:
        """``t[-1] - t[0]``, s."""
        return float(self.t[-1] - self.t[0])

    def __len__(self) -> int:
        return int(self.t.size)

    def sliced(self, start: int, stop: int) -> Motion:
        """Samples ``start:stop``."""
        return Motion(
            self.t[start:stop], self.q[start:stop], self.qd[start:stop], self.qdd[start:stop]
        )
