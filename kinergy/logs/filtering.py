"""The zero-phase low-pass filter of measured speeds (nursing eq 24's filtering) and its cutoff."""

from __future__ import annotations

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError

__all__ = ["FILTER_REACH", "check_cutoff", "default_cutoff", "lowpass"]

#: periods of the low-pass cutoff each chunk of a filtered log is filtered with on either side
FILTER_REACH = 24.0


def check_cutoff(fs: float, cutoff: float) -> None:
    """Raise unless ``0 < cutoff < fs / 2`` (Hz)."""
    if not 0.0 < cutoff < fs / 2.0:
        raise KinergyError(
            f"--cutoff: the filter cutoff must be between 0 and {fs / 2:g} Hz (half of the log's "
            f"{fs:g} Hz), got {cutoff:g}"
        )


def lowpass(x: Array, fs: float, cutoff: float, order: int = 4) -> Array:
    """Zero-phase Butterworth low-pass of ``x`` (N, ...) along time; ``cutoff`` Hz, ``fs`` Hz."""
    from scipy.signal import butter, sosfiltfilt  # slow to import; only filtering needs it

    check_cutoff(fs, cutoff)
    sos = butter(order, cutoff / (fs / 2.0), output="sos")
    # pad by several periods of the cutoff so the ends have settled
    padlen = min(int(np.ceil(6.0 * fs / cutoff)), x.shape[0] - 1)
    return np.asarray(sosfiltfilt(sos, x, axis=0, padlen=padlen), dtype=float)


def default_cutoff(t: Array) -> float:
    """The low-pass cutoff for measured speeds of uniform time stamps ``t``: min(10 Hz, a fifth
    of the sample rate)."""
    fs = 1.0 / float(t[1] - t[0])
    return min(10.0, fs / 5.0)
