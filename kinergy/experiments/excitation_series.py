"""The excitation's parametrisation: nursing eq 22 with its boundary conditions built in.

A finite Fourier series per joint (:mod:`kinergy.trajectory.fourier`)::

    q_i(t) = q_i0 + sum_{l=1..L} ( a_il / (w_f l) sin(w_f l t) - b_il / (w_f l) cos(w_f l t) )

with ``w_f = 2 pi / T``. The offset is fixed by the start pose,
``q_i0 = q_start,i + sum_l b_il / (w_f l)``, so ``q(0) = q_start``; ``qd(0) = sum_l a_il`` and
``qdd(0) = w_f sum_l l b_il``, so the two linear conditions ``sum_l a_il = 0`` and
``sum_l l b_il = 0`` give zero speed and acceleration at the start. The series has period ``T``,
so the same three hold at ``t = T`` and at every repeat (nursing eq 23's rows 4-6). The
coefficients are written ``[a_i; b_i] = E z_i`` with ``E`` (2L, 2L - 2) an orthonormal basis of
the null space of those two conditions: the optimiser moves ``z`` freely, and every ``z`` meets
them exactly. One harmonic leaves nothing to move (``L >= 2``).

The unknowns of all joints are ``Z`` (2L - 2, n); on a time grid the states are linear in them,
``q = q_start + P_q Z``, ``qd = P_qd Z``, ``qdd = P_qdd Z`` (:class:`SeriesGrid`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.trajectory.fourier import fourier_basis

__all__ = ["FourierParametrisation", "SeriesGrid", "sample_times"]


def _null_basis(harmonics: int) -> Array:
    """``E`` (2L, 2L - 2), orthonormal: ``[a; b] = E z`` has ``sum a = 0`` and ``sum l b_l = 0``."""
    cond = np.zeros((2, 2 * harmonics))
    cond[0, :harmonics] = 1.0
    cond[1, harmonics:] = np.arange(1, harmonics + 1)
    return np.asarray(scipy.linalg.null_space(cond))


def sample_times(period: float, dt: float) -> Array:
    """Sample times of one period at ``dt``, s, the way :func:`fourier_motion` lays them out
    (both ends included)."""
    steps = round(period / dt)
    return np.arange(steps + 1, dtype=float) * (period / steps)


@dataclass(frozen=True, eq=False)
class SeriesGrid:
    """The states on a time grid per unknown: ``q = start + q_basis @ Z``, ``qd = qd_basis @ Z``,
    ``qdd = qdd_basis @ Z`` for unknowns ``Z`` (k, n).

    Attributes
    ----------
    t : ndarray, shape (N,)
        Time, s.
    q_basis, qd_basis, qdd_basis : ndarray, shape (N, k)
        rad, rad/s, rad/s^2 per unit unknown.
    """

    t: Array
    q_basis: Array
    qd_basis: Array
    qdd_basis: Array

    @property
    def bases(self) -> tuple[Array, Array, Array]:
        """``(q_basis, qd_basis, qdd_basis)``."""
        return self.q_basis, self.qd_basis, self.qdd_basis

    def states(self, start: Array, zz: Array) -> tuple[Array, Array, Array]:
        """``q``, ``qd``, ``qdd`` (N, n) for unknowns ``zz`` (k, n) and start pose (n,)."""
        return start + self.q_basis @ zz, self.qd_basis @ zz, self.qdd_basis @ zz


@dataclass(frozen=True, eq=False)
class FourierParametrisation:
    """Nursing eq 22 of ``harmonics`` harmonics and period ``period`` (s), at rest in ``start``
    (rad, shape (n,)) at ``t = 0`` and every period (module docstring)."""

    harmonics: int
    period: float
    start: Array

    @property
    def base_frequency(self) -> float:
        """``w_f = 2 pi / T``, rad/s."""
        return 2.0 * np.pi / self.period

    @property
    def null_basis(self) -> Array:
        """``E`` (2L, 2L - 2)."""
        return _null_basis(self.harmonics)

    @property
    def free(self) -> int:
        """Unknowns per joint, ``2L - 2``."""
        return 2 * self.harmonics - 2

    def unknowns(self, z: ArrayLike) -> Array:
        """The flat unknowns ``z`` ((2L - 2) n,) as ``Z`` (2L - 2, n), row by row."""
        return np.asarray(z, dtype=float).reshape(self.free, self.start.size)

    def coefficients(self, z: ArrayLike) -> tuple[Array, Array, Array]:
        """``q0`` (n,), ``a`` and ``b`` (n, L) of nursing eq 22 for unknowns ``z``."""
        ab = (self.null_basis @ self.unknowns(z)).T  # (n, 2L)
        a, b = ab[:, : self.harmonics], ab[:, self.harmonics :]
        return self.start + b @ (1.0 / self._frequencies()), a, b

    def grid(self, t: Array) -> SeriesGrid:
        """The states' bases on the times ``t`` (N,), s (``q - start`` by
        :func:`fourier_basis` from the start pose)."""
        pq, pqd, pqdd = fourier_basis(t, self.base_frequency, self.harmonics, from_start=True)
        e = self.null_basis
        return SeriesGrid(t, pq @ e, pqd @ e, pqdd @ e)

    def _frequencies(self) -> Array:
        """``w_l = w_f l``, rad/s, shape (L,)."""
        return self.base_frequency * np.arange(1, self.harmonics + 1, dtype=float)
