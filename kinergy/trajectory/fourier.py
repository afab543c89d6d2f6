"""Finite Fourier-series joint trajectories (nursing eq 22), the usual excitation for identification.

    q_i(t) = q_i0 + sum_{l=1..L} ( a_il / (w_f l) sin(w_f l t) - b_il / (w_f l) cos(w_f l t) )

with base frequency ``w_f`` (rad/s; the period is ``2 pi / w_f``). Speeds and accelerations are the
exact derivatives. The series is periodic, so a run can repeat it for cycle averaging (nursing eq 24).
The series is linear in its coefficients: :func:`fourier_basis` gives the columns that multiply
them, which :func:`fourier_series` evaluates and the excitation design optimises over
(:mod:`kinergy.experiments.excitation_series`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from kinergy import checks
from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.trajectory.motion import CONTROLLER_DT, Motion

__all__ = ["fourier_basis", "fourier_motion", "fourier_series"]


def fourier_basis(
    t: Array, base_frequency: float, harmonics: int, *, from_start: bool = False
) -> tuple[Array, Array, Array]:
    """Nursing eq 22 per unit coefficient: the columns that multiply ``[a_1..a_L, b_1..b_L]``.

    ::

        q - q0 = sum_l a_l sin(w_l t) / w_l - b_l cos(w_l t) / w_l,   w_l = w_f l
        qd     = sum_l a_l cos(w_l t)       + b_l sin(w_l t)
        qdd    = sum_l -a_l w_l sin(w_l t)  + b_l w_l cos(w_l t)

    Parameters
    ----------
    t : ndarray, shape (N,)
        Time, s.
    base_frequency : float
        ``w_f``, rad/s.
    harmonics : int
        ``L``.
    from_start : bool
        ``pq`` gives ``q(t) - q(0)`` instead of ``q(t) - q0``: the ``b`` columns are
        ``(1 - cos(w_l t)) / w_l`` (a series anchored at its start pose,
        ``q0 = q(0) + sum_l b_l / w_l``).

    Returns
    -------
    pq, pqd, pqdd : ndarray, shape (N, 2 L)
        rad, rad/s and rad/s^2 per unit coefficient (rad/s).
    """
    w = base_frequency * np.arange(1, harmonics + 1)  # (L,)
    phase = t[:, None] * w[None, :]  # (N, L)
    s, c = np.sin(phase), np.cos(phase)
    pq = np.hstack([s / w, (1.0 - c) / w if from_start else -c / w])
    return pq, np.hstack([c, s]), np.hstack([-s * w, c * w])


def fourier_series(
    t: ArrayLike, q0: ArrayLike, a: ArrayLike, b: ArrayLike, base_frequency: float
) -> tuple[Array, Array, Array]:
    """Evaluate nursing eq 22 and its derivatives.

    Parameters
    ----------
    t : array_like, shape (N,)
        Time, s.
    q0 : array_like, shape (n,)
        Offsets, rad.
    a, b : array_like, shape (n, L)
        Coefficients of harmonic l = 1..L, rad/s.
    base_frequency : float
        ``w_f``, rad/s.

    Returns
    -------
    q, qd, qdd : ndarray, shape (N, n)
        rad, rad/s, rad/s^2.
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
    q0 = np.asarray(q0, dtype=float)
    a = np.atleast_2d(np.asarray(a, dtype=float))
    b = np.atleast_2d(np.asarray(b, dtype=float))
    if a.shape != b.shape or a.shape[0] != q0.size:
        raise KinergyError(
            f"Fourier coefficients: a and b must both have shape ({q0.size}, L), got {a.shape} and {b.shape}"
        )
    base_frequency = checks.number(base_frequency, "base frequency", gt=0.0)
    pq, pqd, pqdd = fourier_basis(t, base_frequency, a.shape[1])
    ab = np.hstack([a, b]).T  # (2L, n)
    return q0 + pq @ ab, pqd @ ab, pqdd @ ab


def fourier_motion(
    q0: ArrayLike,
    a: ArrayLike,
    b: ArrayLike,
    *,
    base_frequency: float,
    periods: int = 1,
    dt: float = CONTROLLER_DT,
) -> Motion:
    """A Fourier-series motion over ``periods`` whole periods, sampled every ``dt`` s.

    Examples
    --------
    >>> m = fourier_motion([0.0], [[0.2]], [[0.0]], base_frequency=0.2 * np.pi, dt=0.1)
    >>> round(m.duration, 6), abs(round(float(m.q[0, 0]), 6)), abs(round(float(m.q[-1, 0]), 6))
    (10.0, 0.0, 0.0)
    """
    if periods < 1:
        raise KinergyError(f"periods must be >= 1, got {periods}")
    period = 2.0 * np.pi / base_frequency
    steps = round(periods * period / dt)
    t = np.arange(steps + 1, dtype=float) * (periods * period / steps)
    q, qd, qdd = fourier_series(t, q0, a, b, base_frequency)
    return Motion(t, q, qd, qdd)
