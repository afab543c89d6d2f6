"""Ridge regression of the minimal (base) inertial parameter set (nursing section 4.2, eqs 16, 26).

The joint torques the links need are regressed on the base-parameter regressor (eq 16; 36
parameters for the nursing arm, as the doc's Table 3) by ridge regression on standardised
columns, as the doc's "once standardised" and scikit-learn's ``Ridge`` do; the first share of the
samples (in time) trains, the rest tests (per-joint RMSE, eq 26, Table 8). The ridge weight is
chosen by generalised cross-validation, computed from the triangle of one QR factorisation
(:func:`kinergy.linalg.reduce`) and its singular values: no scikit-learn needed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.dynamics.regressor import BaseParameters, base_parameters
from kinergy.dynamics.regressor import regressor as full_regressor
from kinergy.errors import KinergyError
from kinergy.identification.metrics import r_squared, rmse
from kinergy.linalg import Reduced, reduce, solve_reduced
from kinergy.model.robot import Robot

__all__ = ["RidgeFit", "gcv_scores", "ridge_minimal"]


@dataclass(frozen=True, eq=False)
class RidgeFit:
    """Ridge regression of the minimal (base) inertial parameter set.

    Attributes
    ----------
    base : BaseParameters
        The minimal set (:func:`kinergy.dynamics.regressor.base_parameters`).
    coef : ndarray, shape (b,)
        Base parameters in physical units (de-standardised): ``tau ~ Y_b coef + intercept``.
    intercept : float
        Constant of the standardised regression (N m, every joint); 0 for an exact model.
    alpha : float
        Chosen ridge weight (on unit-variance columns, per sample).
    alphas, gcv : ndarray
        The candidates and their generalised cross-validation scores.
    split : int
        Samples (time steps) used for training: ``[0, split)``; testing ``[split, N)``.
    rmse_test, rmse_train, r2_test : ndarray, shape (n,)
        Per joint, eq 26 (N m) and R^2.
    predicted : ndarray, shape (N, n)
        Predicted joint torques over all samples, N m.
    condition : float
        Condition number of the standardised training regressor.
    """

    base: BaseParameters
    coef: Array
    intercept: float
    alpha: float
    alphas: Array
    gcv: Array
    split: int
    rmse_test: Array
    rmse_train: Array
    r2_test: Array
    predicted: Array
    condition: float


def gcv_scores(reduced: Reduced, alphas: Array) -> Array:
    """Generalised cross-validation of ridge weights on a reduced problem (Golub, Heath, Wahba,
    Technometrics 21(2), 1979).

    For ``min 1/m |y - X beta|^2 + alpha |beta|^2`` with ``m`` rows, ``GCV = m RSS / (m - df)^2``
    with ``df = sum s^2 / (s^2 + alpha m)`` the effective number of parameters (``s``: singular
    values of ``X``), all from the triangle ``[r_a | r_y]`` of ``[X | y]``.

    Parameters
    ----------
    reduced : Reduced
        ``[X | y]`` reduced (:func:`kinergy.linalg.reduce`), ``rows = m``.
    alphas : ndarray, shape (K,)
        Candidate weights, >= 0.

    Returns
    -------
    ndarray, shape (K,)
    """
    m = reduced.rows
    u, s, _ = np.linalg.svd(reduced.r_a, full_matrices=False)
    uty = u.T @ reduced.r_y
    outside = float(reduced.r_y @ reduced.r_y - uty @ uty)  # the part of y no column reaches
    gcv = np.empty(alphas.size)
    for i, alpha in enumerate(alphas):
        lam = alpha * m
        shrink = lam / (s**2 + lam)
        rss = max(outside, 0.0) + float(np.sum((shrink * uty) ** 2))
        df = float(np.sum(s**2 / (s**2 + lam)))
        gcv[i] = m * rss / max(m - df, 1e-12) ** 2
    return gcv


def _check_ridge(
    robot: Robot, q: Array, tau: Array, split: float, alphas: ArrayLike | None
) -> Array:
    """Shapes, ``split`` in (0, 1] and the candidate weights (default ``logspace(-12, 0, 49)``)."""
    big_n, n = q.shape
    if tau.shape != (big_n, n) or n != robot.n:
        raise KinergyError(f"ridge: q {q.shape} and tau {tau.shape} must both be (N, {robot.n})")
    if not 0.0 < split <= 1.0:
        raise KinergyError(f"split must be in (0, 1], got {split}")
    cand = np.logspace(-12, 0, 49) if alphas is None else np.asarray(alphas, dtype=float)
    if cand.ndim != 1 or cand.size == 0 or np.any(cand < 0):
        raise KinergyError("alphas must be a non-empty list of numbers >= 0")
    return cand


def _standardise(x: Array, y: Array, center: bool) -> tuple[Array, Array, float]:
    """Column means ``mu`` (zero without ``center``), spreads ``sigma`` (standard deviations, or
    root mean squares without ``center``; 1 for constant columns) and the target's mean."""
    mu = x.mean(axis=0) if center else np.zeros(x.shape[1])
    sigma = x.std(axis=0) if center else np.sqrt(np.mean(x**2, axis=0))
    sigma[sigma <= 1e-12 * max(float(sigma.max()), 1e-300)] = 1.0
    return mu, sigma, float(y.mean()) if center else 0.0


def _fit(
    base: BaseParameters, y_all: Array, tau: Array, n_train: int, cand: Array, center: bool
) -> RidgeFit:
    """Standardise the training rows, pick the weight by GCV, solve and score on the rest."""
    x_tr = y_all[:n_train].reshape(-1, base.size)
    y_tr = tau[:n_train].reshape(-1)
    mu, sigma, y_mean = _standardise(x_tr, y_tr, center)
    reduced = reduce((x_tr - mu) / sigma, y_tr - y_mean, scale=np.ones(base.size))
    gcv = gcv_scores(reduced, cand)
    best = int(np.argmin(gcv))
    sol = solve_reduced(reduced.r_a, reduced.r_y, reduced.rows, lam=cand[best] * reduced.rows)
    coef = sol.x / sigma
    intercept = y_mean - float(mu @ coef)
    predicted = y_all @ coef + intercept
    big_n = tau.shape[0]
    test = slice(n_train, big_n) if n_train < big_n else slice(0, big_n)
    return RidgeFit(
        base=base,
        coef=coef,
        intercept=intercept,
        alpha=float(cand[best]),
        alphas=cand,
        gcv=gcv,
        split=n_train,
        rmse_test=rmse(tau[test], predicted[test]),
        rmse_train=rmse(tau[:n_train], predicted[:n_train]),
        r2_test=r_squared(tau[test], predicted[test]),
        predicted=predicted,
        condition=sol.cond,
    )


def ridge_minimal(
    robot: Robot,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    tau: ArrayLike,
    *,
    split: float = 0.7,
    alphas: ArrayLike | None = None,
    base: BaseParameters | None = None,
    center: bool = True,
) -> RidgeFit:
    """Ridge regression of the minimal parameter set on standardised data (section 4.2, eq 16).

    Rows are (sample, joint): ``tau[k, j] = Y_b[k, j, :] @ pi_b``. The first ``split`` of the
    samples (in time) train, the rest test. Each column of the training regressor is
    standardised (zero mean, unit variance over the training rows; the target centred), as the
    doc's "once standardised" and scikit-learn's ``Ridge`` do, and the ridge problem ::

        min_beta  1/m |y_c - X_s beta|^2 + alpha |beta|^2

    is solved in closed form from the triangle of one QR factorisation of ``[X_s | y_c]`` for
    every candidate ``alpha``. ``alpha`` is chosen by generalised cross-validation
    (:func:`gcv_scores`). The coefficients are mapped back to physical base parameters,
    ``pi_b = beta / sigma``, with the intercept ``mean(y) - mu . pi_b``. As ``alpha -> 0`` the
    solution is the ordinary least-squares one (with an intercept; ``center=False`` leaves the
    columns uncentred and fits no intercept).

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity for the regressor.
    q, qd, qdd : array_like, shape (N, n)
        rad, rad/s, rad/s^2.
    tau : array_like, shape (N, n)
        Joint torques the links need (N m): measured less friction and drive inertia (eq 25).
    split : float
        Training share, in (0, 1]. With 1 the test metrics are those of the training data.
    alphas : array_like, optional
        Candidate ridge weights; default ``logspace(-12, 0, 49)``.
    base : BaseParameters, optional
        Default :func:`base_parameters` of ``robot``.

    Returns
    -------
    RidgeFit
    """
    qq = np.asarray(q, dtype=float)
    y3 = np.asarray(tau, dtype=float)
    cand = _check_ridge(robot, qq, y3, split, alphas)
    base = base or base_parameters(robot)
    big_n, n = qq.shape
    n_train = max(1, round(split * big_n))
    if n_train * n < base.size + 1:
        raise KinergyError(f"ridge: {n_train * n} training rows for {base.size} base parameters")
    y_all = base.regressor(full_regressor(robot, qq, qd, qdd))  # (N, n, b)
    return _fit(base, y_all, y3, n_train, cand, center)
