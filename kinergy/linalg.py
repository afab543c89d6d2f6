"""Least squares and numerical rank, shared by every regression in kinergy.

- :func:`pivoted_rank`: Gautier's numerical rank by QR with column pivoting (base parameters,
  dependent regressor columns, excitation design);
- :func:`scaled_lstsq`: least squares on unit-norm columns with standard errors and the condition
  number (the sequential method, the payload);
- :class:`Reduced` and :func:`reduce`: the triangle ``R`` of ``[A | y] = Q R`` from which every
  least-squares and ridge quantity follows (``|y - A z| = |r_y - r_a z|``), so a regression with
  millions of rows is solved from a (p + 1) x (p + 1) matrix; :meth:`Reduced.stack` folds in
  more rows, so it can be built chunk by chunk;
- :func:`solve_reduced`: least squares or ridge on a reduced problem, with standard errors.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError

__all__ = [
    "Rank",
    "Reduced",
    "ReducedSolution",
    "column_scale",
    "pivoted_rank",
    "reduce",
    "scaled_lstsq",
    "scaled_solution",
    "solve_reduced",
]


@dataclass(frozen=True)
class Rank:
    """Numerical rank of a matrix ``A`` (m, p) from ``A[:, piv] = Q R``.

    Attributes
    ----------
    rank : int
    independent, dependent : ndarray of int
        Column indices, sorted; ``independent`` has ``rank`` entries.
    r : ndarray, shape (min(m, p), p)
        The triangle, columns in pivot order.
    pivots : ndarray of int, shape (p,)
    """

    rank: int
    independent: NDArray[np.intp]
    dependent: NDArray[np.intp]
    r: Array
    pivots: NDArray[np.intp]


def pivoted_rank(a: Array, *, rtol: float | None = None, atol: float | None = None) -> Rank:
    """Numerical rank by QR with column pivoting: a column counts while ``|R_kk|`` is above
    ``rtol * |R_00|`` or ``atol`` (Gautier's method; give one of the two).

    Parameters
    ----------
    a : ndarray, shape (m, p)
    rtol, atol : float
        Relative (to the largest pivot) or absolute threshold on the pivots.
    """
    if (rtol is None) == (atol is None):
        raise ValueError("give exactly one of rtol and atol")
    _, r, piv = scipy.linalg.qr(a, mode="economic", pivoting=True)
    diag = np.abs(np.diag(r))
    if atol is not None:
        limit = atol
    else:
        assert rtol is not None
        limit = rtol * max(float(diag[0]) if diag.size else 0.0, 1e-300)
    rank = int(np.sum(diag > limit))
    return Rank(rank, np.sort(piv[:rank]), np.sort(piv[rank:]), r, piv)


def column_scale(a: Array) -> Array:
    """Euclidean norm of each column of ``a`` (m, p), 1 for all-zero columns, shape (p,)."""
    scale = np.linalg.norm(a, axis=0)
    scale[scale == 0.0] = 1.0
    return scale


def scaled_lstsq(a: Array, y: Array) -> tuple[Array, Array, float]:
    """Least squares on unit-norm columns.

    Parameters
    ----------
    a : ndarray, shape (m, p)
    y : ndarray, shape (m,)

    Returns
    -------
    x : ndarray, shape (p,)
    std : ndarray, shape (p,)
        Standard errors ``sqrt(diag(sigma^2 (A^T A)^+))``, ``sigma^2`` the residual variance over
        ``m - p`` degrees of freedom.
    cond : float
        Condition number of the column-scaled ``a`` (inf when rank deficient).
    """
    scale = column_scale(a)
    a_s = a / scale
    sol, _, _, sv = np.linalg.lstsq(a_s, y, rcond=None)
    cond = float(sv[0] / sv[-1]) if sv.size and sv[-1] > 0 else float("inf")
    x = sol / scale
    dof = max(a.shape[0] - a.shape[1], 1)
    sigma2 = float(np.sum((y - a @ x) ** 2) / dof)
    cov = sigma2 * np.linalg.pinv(a_s.T @ a_s) / np.outer(scale, scale)
    return x, np.sqrt(np.clip(np.diag(cov), 0.0, None)), cond


@dataclass(frozen=True)
class Reduced:
    """``[A_s | y] = Q r`` with ``A_s = A / scale``: ``r`` (p + 1, p + 1) upper triangular.

    ``rows`` counts the equations folded in.
    """

    r: Array
    scale: Array
    rows: int

    @property
    def r_a(self) -> Array:
        """(p + 1, p): the regressor's part."""
        return self.r[:, :-1]

    @property
    def r_y(self) -> Array:
        """(p + 1,): the target's part."""
        return self.r[:, -1]

    def stack(self, a: Array, y: Array) -> Reduced:
        """This problem with the rows ``a`` (m, p), ``y`` (m,) added (same column scale)."""
        more = np.column_stack([a / self.scale, y])
        return Reduced(_triangle(np.vstack([self.r, more])), self.scale, self.rows + a.shape[0])

    @classmethod
    def empty(cls, p: int) -> Reduced:
        """No equation yet in ``p`` unknowns, unit column scale: :meth:`stack` chunks of rows
        onto it (a streaming QR), then :meth:`unit_columns`."""
        return cls(np.zeros((0, p + 1)), np.ones(p), 0)

    def unit_columns(self) -> Reduced:
        """This problem with the regressor's columns scaled to unit norm (:func:`column_scale`
        of ``A``: ``|A e_k| = |R e_k|``), as :func:`reduce` scales them."""
        norms = column_scale(self.r_a)
        r = self.r.copy()
        r[:, :-1] /= norms
        return Reduced(r, self.scale * norms, self.rows)

    def combine(self, t: Array) -> Reduced:
        """The problem whose ``[A' | y']`` is this one's ``[A | y] t``, ``t`` (p + 1, k + 1), unit
        column scale (``|[A | y] t v| = |R t v|``): columns left out, moved into the target
        or mixed, with no pass over the rows. This problem's scale must be 1."""
        return Reduced(_triangle(self.r @ t), np.ones(t.shape[1] - 1), self.rows)

    def norm2(self, v: Array) -> float:
        """``|[A_s | y] v|^2`` for ``v`` (p + 1,), e.g. the residual ``|y - A_s z|^2`` with
        ``v = [-z, 1]``."""
        return float(np.sum((self.r @ v) ** 2))


def _triangle(m: Array) -> Array:
    """The upper triangle R (k, k) of ``m = Q R`` (m, k), m >= k, by LAPACK's geqrf."""
    qr, _, _, info = scipy.linalg.lapack.dgeqrf(np.asfortranarray(m), overwrite_a=True)
    if info != 0:  # pragma: no cover - LAPACK argument error
        raise KinergyError(f"QR factorisation failed (LAPACK info {info})")
    return np.triu(qr[: m.shape[1]])


def reduce(a: Array, y: Array, scale: Array | None = None) -> Reduced:
    """One QR factorisation of the column-scaled regressor with the target appended.

    Parameters
    ----------
    a : ndarray, shape (m, p)
    y : ndarray, shape (m,)
    scale : ndarray, shape (p,), optional
        Column scale; default :func:`column_scale` of ``a``.
    """
    scale = column_scale(a) if scale is None else scale
    if a.shape[0] < a.shape[1] + 1:
        raise KinergyError(f"{a.shape[0]} equations for {a.shape[1]} parameters")
    m = np.empty((a.shape[0], a.shape[1] + 1), order="F")
    np.divide(a, scale, out=m[:, :-1])
    m[:, -1] = y
    return Reduced(_triangle(m), scale, a.shape[0])


@dataclass(frozen=True)
class ReducedSolution:
    """Solution ``x``, standard errors, condition number of the column-scaled regressor and
    residual sum of squares (all in the scaled coordinates the problem was given in)."""

    x: Array
    std: Array
    cond: float
    sse: float


def scaled_solution(problem: Reduced) -> tuple[Array, Array, float]:
    """:func:`scaled_lstsq` of a problem folded into its triangle (chunk by chunk,
    :meth:`Reduced.stack`): the same ``x``, standard errors and condition number, to round-off.

    Parameters
    ----------
    problem : Reduced
        ``[A | y]`` with unit column scale (as :meth:`Reduced.empty` starts it).
    """
    unit = problem.unit_columns()
    sol = solve_reduced(unit.r_a, unit.r_y, unit.rows)
    return sol.x / unit.scale, sol.std / unit.scale, sol.cond


def solve_reduced(
    r_a: Array, r_y: Array, rows: int, z0: Array | None = None, lam: float = 0.0
) -> ReducedSolution:
    """Least squares (``lam = 0``) or ridge toward ``z0`` on a reduced problem.

    ``r_a`` (k, m) and ``r_y`` (k,) are a :class:`Reduced` problem (columns possibly a subset).
    Ridge minimises ``|y - A_s z|^2 + lam |z - z0|^2``. Covariances: ``sigma^2 (A_s^T A_s)^-1``
    for least squares, the ridge estimator's ``sigma^2 V diag(s^2 / (s^2 + lam)^2) V^T``
    otherwise, ``sigma^2`` the residual sum of squares over ``rows - effective parameters``.
    """
    u, s, vt = np.linalg.svd(r_a, full_matrices=False)
    cond = float(s[0] / s[-1]) if s[-1] > 0 else float("inf")
    base = np.zeros(r_a.shape[1]) if z0 is None or lam == 0.0 else z0
    uty = u.T @ (r_y - r_a @ base)
    with np.errstate(divide="ignore"):
        gain = s / (s**2 + lam) if lam > 0.0 else np.where(s > 0, 1.0 / s, 0.0)
    z = base + vt.T @ (gain * uty)
    p_eff = float(np.sum(s * gain))
    resid = r_y - r_a @ z
    sse = float(resid @ resid)
    sigma2 = sse / max(rows - p_eff, 1.0)
    std = np.sqrt(sigma2 * np.sum((vt.T * gain) ** 2, axis=1))
    return ReducedSolution(z, std, cond, sse)
