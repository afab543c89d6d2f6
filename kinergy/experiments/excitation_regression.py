"""What an excitation is designed for: the regression matrix of the full identification and its
conditioning criterion.

The regression the full identification solves (:mod:`kinergy.identification.full`)::

    tau = Y_b(q, qd, qdd) pi_b + N^T diag(J) N qdd + N^T F(wm) phi

stacked over a grid of samples gives ``W`` (samples x n rows). Its columns are the link base
columns ``Y_b`` (:func:`kinergy.dynamics.regressor.base_parameters`) and, with the drives, every
motor's rotor-inertia column (``N[m, j] (N qdd)_m``, UR5e eq 2; ``N`` and ``wm = N qd`` from
:mod:`kinergy.drives.transmission`) and its friction columns: the
``viscous_coulomb`` columns (:meth:`kinergy.friction.model.FrictionModel.friction_columns`; viscous ``wm``,
Coulomb ``tanh(wm / (|i| * 0.05 rad/s))``, a smooth sign), reflected to the joints by ``N^T``.
A drive column that is a combination of the link base columns for every motion (on a UR arm
``J_1`` multiplies the same ``qdd_1`` on joint 1 as the ``Iyy1`` group) is left out: no trajectory
can separate it (the full method merges it and says so).

``W``'s columns are scaled to unit norm (the units of the parameters do not matter) and the
criterion is

- ``"cond"``: the condition number ``s_max / s_min`` of the scaled ``W`` (nursing section 4.2's
  "minimum condition number"; optimised as its logarithm);
- ``"dopt"``: D-optimality, ``-log det(W_s^T W_s)`` (the log volume of the parameters'
  confidence ellipsoid, up to a constant).

Its gradient is exact in the criterion (eigen-decomposition of ``W_s^T W_s``, the column scaling
included) and goes to the states through
:func:`kinergy.dynamics.regressor.regressor_gradient` (the derivative of ``sum(G * Y)`` in each
sample's states in one compiled pass: exact in ``qd`` and ``qdd``, a central step in ``q``;
nothing of size samples x n x 10 n x 3 n is built).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.drives.transmission import motor_speed, transmission_matrix
from kinergy.dynamics.regressor import (
    BaseParameters,
    base_parameters,
    regressor,
    regressor_gradient,
)
from kinergy.friction.viscous_coulomb import MODEL as VISCOUS_COULOMB
from kinergy.linalg import column_scale, pivoted_rank
from kinergy.model.robot import Robot

__all__ = [
    "COULOMB_SMOOTHING",
    "Criterion",
    "ExcitationRegression",
    "criterion",
    "excitation_regression",
    "scaled_condition",
]


class Criterion(enum.StrEnum):
    """What the excitation design minimises (module docstring): the condition number of the
    scaled regressor, or D-optimality."""

    COND = "cond"
    DOPT = "dopt"


#: joint-side speed (rad/s) of the tanh that stands in for the Coulomb column's sign
COULOMB_SMOOTHING = 0.05
#: a drive column whose part independent of the link base columns is below this is dependent
_DEPENDENT_TOL = 1e-8
#: central-difference step of the friction columns' derivative in qd, rad/s
_FD_STEP = 1e-6


def _motor_columns(smoothing: Array, wm: Array, dwm: Array) -> Array:
    """Rotor-inertia, viscous and Coulomb columns of every motor, motor side, (N, 3, n):
    ``dwm``, then the ``viscous_coulomb`` model's viscous and Coulomb columns of ``wm`` at ``smoothing[m]``."""
    friction = [
        VISCOUS_COULOMB.friction_columns({"viscous": 0.0, "coulomb": 0.0, "smoothing": s}, wm[:, m])
        for m, s in enumerate(smoothing)
    ]  # each (N, 2): viscous, Coulomb
    return np.concatenate([dwm[:, None, :], np.stack(friction, axis=2)], axis=1)


def _reach(robot: Robot) -> Array:
    """``[j, k n + m] = N[m, j]``, (n, 3 n): how motor m's column k reaches joint j."""
    return np.tile(transmission_matrix(robot).T, 3)


def _drive_columns(robot: Robot, smoothing: Array, qd: Array, qdd: Array) -> Array:
    """Rotor-inertia, viscous and Coulomb columns of every motor, joint side, (N, n, 3 n).

    Motor ``m`` reaches joint ``j`` through ``N[m, j]``: ``N[m, j] (N qdd)_m`` and
    ``N[m, j] F_m(wm_m)``, ``F_m`` the registry's viscous and Coulomb columns at smoothing
    ``smoothing[m]`` (rad/s, motor side).
    """
    wm, dwm = motor_speed(robot, qd), motor_speed(robot, qdd)  # rad/s, rad/s^2
    motor = _motor_columns(smoothing, wm, dwm)
    return _reach(robot)[None, :, :] * motor.reshape(len(wm), 1, -1)


def _independent_drive_columns(
    robot: Robot, base: BaseParameters, smoothing: Array
) -> NDArray[np.intp]:
    """Indices (into the 3 n drive columns) not in the span of the link base columns and of each
    other (Gautier's pivoted QR rank), on seeded random states (the states
    :func:`base_parameters` uses)."""
    rng = np.random.default_rng(0)
    lo = np.array([max(j.limits.position[0], -np.pi) for j in robot.joints])
    hi = np.array([min(j.limits.position[1], np.pi) for j in robot.joints])
    q = rng.uniform(lo, hi, (300, robot.n))
    qd = rng.standard_normal((300, robot.n))
    qdd = rng.standard_normal((300, robot.n))
    link = base.regressor(regressor(robot, q, qd, qdd)).reshape(-1, base.size)
    extra = _drive_columns(robot, smoothing, qd, qdd).reshape(-1, 3 * robot.n)
    basis, _ = scipy.linalg.qr(link / column_scale(link), mode="economic")
    extra = extra / column_scale(extra)
    rest = extra - basis @ (basis.T @ extra)
    return pivoted_rank(rest, atol=_DEPENDENT_TOL).independent


@dataclass(frozen=True, eq=False)
class ExcitationRegression:
    """The columns of ``W`` (module docstring) for a robot.

    Attributes
    ----------
    robot : Robot
    base : BaseParameters
        The link base parameters.
    drive_columns : ndarray of int
        The drive columns in ``W``, indices into [rotor inertia, viscous, Coulomb] x motors.
    smoothing : ndarray, shape (n,)
        Each motor's Coulomb smoothing speed, rad/s, motor side.
    """

    robot: Robot
    base: BaseParameters = field(repr=False)
    drive_columns: NDArray[np.intp]
    smoothing: Array = field(repr=False)

    @property
    def size(self) -> int:
        """Columns of ``W``: link base parameters plus the independent drive columns."""
        return self.base.size + int(self.drive_columns.size)

    def matrix(self, q: Array, qd: Array, qdd: Array) -> Array:
        """``W`` for states (N, n): (N, n, size), link base columns then drive columns."""
        link = self.base.regressor(regressor(self.robot, q, qd, qdd))
        if self.drive_columns.size == 0:
            return link
        drives = _drive_columns(self.robot, self.smoothing, qd, qdd)[..., self.drive_columns]
        return np.concatenate([link, drives], axis=2)

    def flat(self, q: Array, qd: Array, qdd: Array) -> Array:
        """``W`` for states (N, n) as (N n, size), rows (sample, joint)."""
        return self.matrix(q, qd, qdd).reshape(q.size, -1)

    def criterion_gradient(
        self, q: Array, qd: Array, qdd: Array, kind: Criterion
    ) -> tuple[float, Array, float]:
        """The criterion of ``W`` on the states (N, n), its gradient with respect to them
        (3, N, n: ``q``, ``qd``, ``qdd``) and the condition number.

        With ``G = dF/dW`` (:func:`criterion`), ``dF/dx[s, j] = sum(G[s] * dW[s]/dx[s, j])``:
        the link columns' part is :func:`kinergy.dynamics.regressor.regressor_gradient` (one
        thread: 200 samples of an optimisation loop lose more to a parallel launch on a busy
        machine than they gain) with
        ``G`` scattered onto the base columns (no regressor derivative is stored), the drive
        columns' part :meth:`drive_gradient`.
        """
        big_n, n = q.shape
        w0 = self.matrix(q, qd, qdd)
        value, grad_w, cond = criterion(w0.reshape(big_n * n, -1), kind)
        grad_w = grad_w.reshape(w0.shape)
        b = self.base.size
        weights = np.zeros((big_n, n, 10 * n))
        weights[..., self.base.independent] = grad_w[..., :b]
        sens = regressor_gradient(self.robot, q, qd, qdd, weights, threads=1)
        if self.drive_columns.size:
            sens[1:] += self.drive_gradient(qd, qdd, grad_w[..., b:])
        return value, sens, cond

    def drive_gradient(self, qd: Array, qdd: Array, weights: Array) -> Array:
        """Derivatives of ``sum(weights * D)`` in every sample's ``qd`` and ``qdd``, (2, N, n),
        ``D`` (N, n, k) the drive columns in ``W``.

        Motor m's columns depend on its own speed ``wm_m`` and acceleration only, so one central
        step of :data:`_FD_STEP` of every motor speed at once gives each ``d/dwm_m`` (the
        rotor-inertia column is linear: its weight is the derivative); ``wm = N qd`` carries
        them to the joints (``N^T``).
        """
        robot, n = self.robot, qd.shape[1]
        n_mat = transmission_matrix(robot)
        per_motor = np.zeros((*qd.shape[:1], 3 * n))  # sum_j weights * reach, per motor column
        per_motor[:, self.drive_columns] = np.einsum(
            "sik,ik->sk", weights, _reach(robot)[:, self.drive_columns]
        )
        per_motor = per_motor.reshape(-1, 3, n)
        wm, dwm = qd @ n_mat.T, qdd @ n_mat.T
        up = _motor_columns(self.smoothing, wm + _FD_STEP, dwm)
        down = _motor_columns(self.smoothing, wm - _FD_STEP, dwm)
        d_speed = np.einsum("scm,scm->sm", per_motor[:, 1:], (up - down)[:, 1:]) / (2 * _FD_STEP)
        return np.stack([d_speed @ n_mat, per_motor[:, 0] @ n_mat])


def excitation_regression(robot: Robot, *, include_drives: bool = True) -> ExcitationRegression:
    """The columns of ``W`` for ``robot``: its link base parameters and, with ``include_drives``,
    the rotor-inertia and friction columns no trajectory confounds with them."""
    smoothing = np.abs(np.diag(transmission_matrix(robot))) * COULOMB_SMOOTHING
    smoothing = np.where(smoothing > 0, smoothing, COULOMB_SMOOTHING)
    base = base_parameters(robot)
    drives = (
        _independent_drive_columns(robot, base, smoothing)
        if include_drives
        else np.zeros(0, dtype=np.intp)
    )
    return ExcitationRegression(robot, base, drives, smoothing)


def criterion(w: Array, kind: Criterion) -> tuple[float, Array, float]:
    """Criterion of the column-scaled ``w`` (rows, m), its gradient with respect to ``w``, and
    the condition number.

    ``"cond"``: ``log cond(W_s) = (log lambda_max - log lambda_min) / 2`` of ``G = W_s^T W_s``;
    ``"dopt"``: ``-log det G``. With ``W_s = W D^-1`` (``D`` the column norms) and ``Phi`` the
    gradient with respect to ``W_s``, the gradient with respect to ``W`` is, column by column,
    ``(Phi_k - (Phi_k . W_s,k) W_s,k) / d_k`` (the scaling moves with ``W``).
    """
    d = column_scale(w)
    ws = w / d
    # einsum and SciPy's LAPACK: on a busy machine numpy's threaded BLAS and eigh wait tens of
    # milliseconds for their worker threads in every call of the optimisation loop
    lam, vec = scipy.linalg.eigh(np.einsum("ij,ik->jk", ws, ws))
    lam = np.maximum(lam, 1e-300 * max(float(lam[-1]), 1e-300))
    if kind == Criterion.COND:
        value = 0.5 * float(np.log(lam[-1]) - np.log(lam[0]))
        hi, lo = vec[:, -1], vec[:, 0]
        phi = np.outer(ws @ hi, hi) / lam[-1] - np.outer(ws @ lo, lo) / lam[0]
    else:
        value = -float(np.sum(np.log(lam)))
        phi = -2.0 * np.einsum("ij,jk->ik", ws, (vec / lam) @ vec.T)
    grad = (phi - ws * np.sum(phi * ws, axis=0)) / d
    return value, grad, float(np.sqrt(lam[-1] / lam[0]))


def scaled_condition(w: Array) -> tuple[float, float]:
    """Condition number and ``-log det(W_s^T W_s)`` of the column-scaled ``w`` (rows, m), from
    its singular values (inf when rank deficient)."""
    s = scipy.linalg.svdvals(w / column_scale(w))
    if s[-1] <= 0:
        return float("inf"), float("inf")
    return float(s[0] / s[-1]), float(-2.0 * np.sum(np.log(s)))
