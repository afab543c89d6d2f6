"""What the checks keep of a log as it passes, in memory that does not grow with it: running
sums of pairs per joint (:class:`Moments`) and an evenly thinned sample of rows
(:class:`Thinned`)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array

__all__ = ["Moments", "Noise", "Thinned"]


class Moments:
    """Running sums of pairs ``(x, y)`` per joint: counts, sums, squares and cross products."""

    def __init__(self, n: int):
        self.n = np.zeros(n)
        self.sx = np.zeros(n)
        self.sy = np.zeros(n)
        self.sxx = np.zeros(n)
        self.syy = np.zeros(n)
        self.sxy = np.zeros(n)

    def add(self, x: Array, y: Array) -> None:
        self.n += x.shape[0]
        self.sx += x.sum(axis=0)
        self.sy += y.sum(axis=0)
        self.sxx += np.einsum("ij,ij->j", x, x)
        self.syy += np.einsum("ij,ij->j", y, y)
        self.sxy += np.einsum("ij,ij->j", x, y)

    def slope(self) -> Array:
        """Least-squares slope of y on x through the origin."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.asarray(self.sxy / self.sxx, dtype=float)

    def correlation(self) -> Array:
        with np.errstate(invalid="ignore", divide="ignore"):
            cxx = self.sxx - self.sx**2 / self.n
            cyy = self.syy - self.sy**2 / self.n
            cxy = self.sxy - self.sx * self.sy / self.n
            return np.asarray(cxy / np.sqrt(cxx * cyy), dtype=float)

    def rms_x(self) -> Array:
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.asarray(np.sqrt(self.sxx / self.n), dtype=float)


class Thinned:
    """Rows of a long log evenly thinned to at most ``size``: every ``stride``-th sample, the
    stride doubling (and every other kept row dropped) when the rows fill up."""

    def __init__(self, size: int, stride: int):
        self.size, self.stride = size, max(1, stride)
        self.rows: dict[str, list[Array]] = {}
        self.index: list[NDArray[np.intp]] = []
        self.count = 0

    def candidates(self, start: int, lo: int, hi: int) -> NDArray[np.intp]:
        """The rows ``lo <= k < hi`` of a chunk starting at sample ``start`` that fall on the
        stride."""
        first = lo + (-(start + lo)) % self.stride
        return np.arange(first, hi, self.stride)

    def add(self, numbers: NDArray[np.intp], rows: dict[str, Array]) -> None:
        """Rows of samples ``numbers`` (on the stride)."""
        if numbers.size:
            self.index.append(numbers)
            for name, x in rows.items():
                self.rows.setdefault(name, []).append(x)
            self.count += numbers.size
        while self.count > self.size:
            self._halve()

    def _halve(self) -> None:
        self.stride *= 2
        index = np.concatenate(self.index)
        keep = index % self.stride == 0
        self.index = [index[keep]]
        self.rows = {name: [np.concatenate(x)[keep]] for name, x in self.rows.items()}
        self.count = int(keep.sum())

    def get(self, name: str) -> Array:
        return np.concatenate(self.rows[name]) if name in self.rows else np.empty((0, 0))


class Noise:
    """A signal's white noise per column from its second differences over consecutive samples
    (a smooth signal keeps them near 0; white noise of deviation s gives them a mean square of
    6 s^2): running sums of their squares."""

    def __init__(self, n: int):
        self.ss = np.zeros(n)
        self.count = 0

    def add(self, x: Array) -> None:
        """Consecutive samples ``x`` (k, n) of one segment."""
        if len(x) < 3:
            return
        d2 = x[2:] - 2.0 * x[1:-1] + x[:-2]
        self.ss += np.einsum("ij,ij->j", d2, d2)
        self.count += len(d2)

    def sigma(self) -> Array:
        """The noise's standard deviation per column (0 before any sample)."""
        if not self.count:
            return np.zeros_like(self.ss)
        return np.asarray(np.sqrt(self.ss / self.count / 6.0), dtype=float)
