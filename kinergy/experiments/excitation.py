"""Excitation design: Fourier-series trajectories optimised for identifying the base parameters.

A finite Fourier series per joint (nursing eq 22, :mod:`kinergy.trajectory.fourier`)::

    q_i(t) = q_i0 + sum_{l=1..L} ( a_il / (w_f l) sin(w_f l t) - b_il / (w_f l) cos(w_f l t) )

with ``w_f = 2 pi / T``, is shaped so that the stacked regressor of the identification is as well
conditioned as the robot's limits allow (nursing section 4.2, eq 23, Tables 5-6).

**Boundary conditions, by construction.** The offset is fixed by the start pose,
``q_i0 = q_start,i + sum_l b_il / (w_f l)``, so ``q(0) = q_start``; ``qd(0) = sum_l a_il`` and
``qdd(0) = w_f sum_l l b_il``, so the two linear conditions ``sum_l a_il = 0`` and
``sum_l l b_il = 0`` give zero speed and acceleration at the start. The series has period ``T``,
so the same three hold at ``t = T`` and at every repeat (nursing eq 23's rows 4-6). The
coefficients are written ``[a_i; b_i] = E z_i`` with ``E`` (2L, 2L - 2) an orthonormal basis of
the null space of those two conditions: the optimiser moves ``z`` freely, and every ``z`` meets
them exactly. One harmonic leaves nothing to move (``L >= 2``).

**Objective.** The regression the full identification solves (:mod:`kinergy.identify.full`)::

    tau = Y_b(q, qd, qdd) pi_b + N^T diag(J) N qdd + N^T F(wm) phi

stacked over a grid of ``samples`` points per period, gives ``W`` (``samples * n`` rows). Its
columns are scaled to unit norm (the units of the parameters do not matter) and the criterion is

- ``"cond"``: the condition number ``s_max / s_min`` of the scaled ``W`` (nursing section 4.2's
  "minimum condition number"; optimised as its logarithm);
- ``"dopt"``: D-optimality, ``-log det(W_s^T W_s)`` (the log volume of the parameters'
  confidence ellipsoid, up to a constant).

``include_drives=True`` adds the rotor-inertia columns (``N[m, j] (N qdd)_m``, UR5e eq 2) and the
friction columns (viscous ``wm``, Coulomb ``tanh(wm / (|i| * 0.05 rad/s))``, a smooth sign) of
every motor. A drive column that is a combination of the link base columns for every motion (on a
UR arm ``J_1`` multiplies the same ``qdd_1`` on joint 1 as the ``Iyy1`` group) is left out: no
trajectory can separate it (the full method merges it and says so).

**Constraints** (nursing eq 23), at every grid point: ``lower <= q <= upper`` (the robot's range,
tightened to ``start +- position_range``), ``|qd| <= speed``, ``|qdd| <= acceleration`` (the
robot's; where the model has none, :data:`ACCELERATION_PER_SPEED` times the speed limit), and the
height of the flange (``floor_frames="flange"``) or of the flange and every link frame from the
second on (``"links"``, the default: elbow, wrists, flange on a UR arm) at least ``floor`` above the
base plane (``z = 0`` of the base frame). Self-collision is not modelled: ``position_range``
(default +-90 deg about the start) keeps an arm from folding onto itself. The optimiser sees the
limits 1 % tighter than they are; the result is checked at every ``dt`` sample of a period and,
should a sample still overshoot between grid points, the whole trajectory is scaled toward the
start pose until none does (scaling keeps the boundary conditions).

**Solver.** SLSQP (``scipy.optimize.minimize``) from several random feasible starts, keeping the
best. The linear constraints (positions, speeds, accelerations) have exact constant Jacobians, the
floor's come from the frames' geometric Jacobians, and the objective's gradient is exact in the
criterion (eigen-decomposition of ``W_s^T W_s``, the column scaling included) and uses one forward
difference of the regressor per joint and signal (``3 n`` extra regressor evaluations in one
batch, instead of one per coefficient).

References: nursing eqs 22-23 and Tables 5-6; J. Swevers, C. Ganseman, D. B. Tukel, J. de
Schutter, H. Van Brussel, "Optimal robot excitation and identification", IEEE T-RA 13(5), 1997;
M. Gautier, W. Khalil, "Exciting trajectories for the identification of base inertial
parameters of robots", IJRR 11(4), 1992.

Examples
--------
>>> import kinergy
>>> from kinergy.experiments.excitation import design_excitation, excitation_problem
>>> problem = excitation_problem(kinergy.load_robot("ur5e"), harmonics=3, samples=60)
>>> best = design_excitation(problem, starts=1, maxiter=20)
>>> bool(best.margins["speed"] >= 0 and best.margins["floor"] >= 0)
True
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg
import scipy.optimize
from numpy.typing import ArrayLike, NDArray

from kinergy.drives.transmission import transmission_matrix
from kinergy.dynamics.chain import make_chain
from kinergy.dynamics.kinematics import joint_axes
from kinergy.dynamics.regressor import BaseParameters, base_parameters, regressor
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.trajectory.fourier import fourier_motion
from kinergy.trajectory.motion import Motion

__all__ = [
    "ACCELERATION_PER_SPEED",
    "COULOMB_SMOOTHING",
    "CRITERIA",
    "DEFAULT_RANGE",
    "FLOOR_FRAMES",
    "Excitation",
    "ExcitationProblem",
    "check_motion",
    "design_excitation",
    "excitation_problem",
    "random_feasible",
]

Array = NDArray[np.float64]

#: optimisation criteria: condition number, D-optimality
CRITERIA = ("cond", "dopt")
#: frames kept above the floor: the flange only, or the flange and every link frame from the second
FLOOR_FRAMES = ("flange", "links")
#: default half-width of each joint's range about the start pose, rad (+-90 deg)
DEFAULT_RANGE = np.pi / 2
#: acceleration limit per unit speed limit, 1/s, for joints whose model publishes none
ACCELERATION_PER_SPEED = 2.0
#: joint-side speed (rad/s) of the tanh that stands in for the Coulomb column's sign
COULOMB_SMOOTHING = 0.05
#: the 6-joint start pose when none is given: UR's upright "home" (the twin's test programs' too)
_HOME_6 = np.array([0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0])
#: the optimiser sees the limits this fraction tighter (grid points miss peaks in between)
_GRID_MARGIN = 0.01
#: ... and the floor this much higher, m
_FLOOR_MARGIN = 5e-4
#: local minima of each limit's margin that are constrained (per joint, per checked frame)
_ACTIVE = 6
#: forward-difference step of the regressor derivatives (rad, rad/s, rad/s^2)
_FD_STEP = 1e-6
#: a drive column whose part independent of the link base columns is below this is dependent
_DEPENDENT_TOL = 1e-8

#: progress callback: (start number from 1, SLSQP iteration (0 = the start point), condition number)
Progress = Callable[[int, int, float], None]


# ---------------------------------------------------------------------------------------------
# The parametrisation


def _null_basis(harmonics: int) -> Array:
    """``E`` (2L, 2L - 2), orthonormal: ``[a; b] = E z`` has ``sum a = 0`` and ``sum l b_l = 0``."""
    cond = np.zeros((2, 2 * harmonics))
    cond[0, :harmonics] = 1.0
    cond[1, harmonics:] = np.arange(1, harmonics + 1)
    return np.asarray(scipy.linalg.null_space(cond))


def _series_basis(t: Array, w_f: float, harmonics: int) -> tuple[Array, Array, Array]:
    """``q - q_start``, ``qd``, ``qdd`` per unit coefficient ``[a_1..a_L, b_1..b_L]``, (N, 2L) each.

    With ``q_0 = q_start + sum_l b_l / (w_f l)`` (module docstring)::

        q - q_start = sum_l a_l sin(w_l t) / w_l + b_l (1 - cos(w_l t)) / w_l,   w_l = w_f l
    """
    w = w_f * np.arange(1, harmonics + 1)
    phase = t[:, None] * w[None, :]
    s, c = np.sin(phase), np.cos(phase)
    pq = np.hstack([s / w, (1.0 - c) / w])
    pqd = np.hstack([c, s])
    pqdd = np.hstack([-s * w, c * w])
    return pq, pqd, pqdd


def _drive_columns(n_mat: Array, smoothing: Array, qd: Array, qdd: Array) -> Array:
    """Rotor-inertia, viscous and Coulomb columns of every motor, joint side, (N, n, 3 n).

    Motor ``m`` reaches joint ``j`` through ``N[m, j]``: ``N[m, j] (N qdd)_m``, ``N[m, j] wm_m``,
    ``N[m, j] tanh(wm_m / smoothing_m)``.
    """
    wm = qd @ n_mat.T
    dwm = qdd @ n_mat.T
    reach = n_mat.T[None, :, :]  # [0, j, m] = N[m, j]
    return np.concatenate(
        [
            reach * dwm[:, None, :],
            reach * wm[:, None, :],
            reach * np.tanh(wm / smoothing)[:, None, :],
        ],
        axis=2,
    )


def _independent_drive_columns(
    robot: Robot, base: BaseParameters, n_mat: Array, smoothing: Array
) -> Array:
    """Indices (into the 3 n drive columns) not in the span of the link base columns and of each
    other, on seeded random states (the states :func:`base_parameters` uses)."""
    rng = np.random.default_rng(0)
    lo = np.array([max(j.limits.position[0], -np.pi) for j in robot.joints])
    hi = np.array([min(j.limits.position[1], np.pi) for j in robot.joints])
    q = rng.uniform(lo, hi, (300, robot.n))
    qd = rng.standard_normal((300, robot.n))
    qdd = rng.standard_normal((300, robot.n))
    link = base.regressor(regressor(robot, q, qd, qdd)).reshape(-1, base.size)
    extra = _drive_columns(n_mat, smoothing, qd, qdd).reshape(-1, 3 * robot.n)
    link = link / np.linalg.norm(link, axis=0)
    norms = np.linalg.norm(extra, axis=0)
    extra = extra / np.where(norms > 0, norms, 1.0)
    basis, _ = scipy.linalg.qr(link, mode="economic")
    rest = extra - basis @ (basis.T @ extra)
    _, r, piv = scipy.linalg.qr(rest, mode="economic", pivoting=True)
    rank = int(np.sum(np.abs(np.diag(r)) > _DEPENDENT_TOL))
    return np.sort(piv[:rank])


def _criterion(w: Array, kind: str) -> tuple[float, Array, float]:
    """Criterion of the column-scaled ``w`` (rows, m), its gradient with respect to ``w``, and
    the condition number.

    ``"cond"``: ``log cond(W_s) = (log lambda_max - log lambda_min) / 2`` of ``G = W_s^T W_s``;
    ``"dopt"``: ``-log det G``. With ``W_s = W D^-1`` (``D`` the column norms) and ``Phi`` the
    gradient with respect to ``W_s``, the gradient with respect to ``W`` is, column by column,
    ``(Phi_k - (Phi_k . W_s,k) W_s,k) / d_k`` (the scaling moves with ``W``).
    """
    d = np.linalg.norm(w, axis=0)
    d = np.where(d > 0, d, 1.0)
    ws = w / d
    # einsum and SciPy's LAPACK: on a busy machine numpy's threaded BLAS and eigh wait tens of
    # milliseconds for their worker threads in every call of the optimisation loop
    lam, vec = scipy.linalg.eigh(np.einsum("ij,ik->jk", ws, ws))
    lam = np.maximum(lam, 1e-300 * max(float(lam[-1]), 1e-300))
    if kind == "cond":
        value = 0.5 * float(np.log(lam[-1]) - np.log(lam[0]))
        hi, lo = vec[:, -1], vec[:, 0]
        phi = np.outer(ws @ hi, hi) / lam[-1] - np.outer(ws @ lo, lo) / lam[0]
    else:
        value = -float(np.sum(np.log(lam)))
        phi = -2.0 * np.einsum("ij,jk->ik", ws, (vec / lam) @ vec.T)
    grad = (phi - ws * np.sum(phi * ws, axis=0)) / d
    return value, grad, float(np.sqrt(lam[-1] / lam[0]))


def _scaled_singular_values(w: Array) -> Array:
    d = np.linalg.norm(w, axis=0)
    return np.asarray(scipy.linalg.svdvals(w / np.where(d > 0, d, 1.0)))


# ---------------------------------------------------------------------------------------------
# The problem


@dataclass(frozen=True, eq=False)
class ExcitationProblem:
    """An excitation design problem: the parametrisation, limits and criterion (module docstring).

    Built by :func:`excitation_problem`; its methods are the callables the optimiser uses. The
    unknowns ``z`` (``(2L - 2) * n``) are ``Z`` (2L - 2, n) flattened row by row, and the
    coefficients of joint ``i`` are ``[a_i; b_i] = E Z[:, i]``.

    Attributes
    ----------
    robot : Robot
    harmonics : int
        ``L``.
    period : float
        ``T``, s.
    start : ndarray, shape (n,)
        Start (and end) pose, rad.
    lower, upper : ndarray, shape (n,)
        Position bounds, rad.
    speed, acceleration : ndarray, shape (n,)
        Limits, rad/s and rad/s^2.
    floor : float or None
        Minimum height of the checked frames above the base plane, m (None: no floor).
    floor_frames : {"flange", "links"}
    criterion : {"cond", "dopt"}
    include_drives : bool
    t : ndarray, shape (samples,)
        Grid of one period the criterion is evaluated on, s (the constraints use a grid twice as
        fine).
    dt : float
        Sample time of the motion and of the final constraint check, s.
    drive_columns : ndarray of int
        The drive columns in ``W``, indices into [rotor inertia, viscous, Coulomb] x motors.
    base : BaseParameters
        The link base parameters (:func:`kinergy.dynamics.regressor.base_parameters`).
    """

    robot: Robot
    harmonics: int
    period: float
    start: Array
    lower: Array
    upper: Array
    speed: Array
    acceleration: Array
    floor: float | None
    floor_frames: str
    criterion: str
    include_drives: bool
    t: Array
    dt: float
    drive_columns: Array
    base: BaseParameters = field(repr=False)
    _e: Array = field(repr=False)
    _pq: Array = field(repr=False)
    _pqd: Array = field(repr=False)
    _pqdd: Array = field(repr=False)
    _n_mat: Array = field(repr=False)
    _smoothing: Array = field(repr=False)
    _cq: Array = field(repr=False)
    _cqd: Array = field(repr=False)
    _cqdd: Array = field(repr=False)
    _fq: Array = field(repr=False)
    _fqd: Array = field(repr=False)
    _fqdd: Array = field(repr=False)
    _last: dict[bytes, float] = field(default_factory=dict, init=False, repr=False)

    @property
    def n(self) -> int:
        return self.robot.n

    @property
    def base_frequency(self) -> float:
        """``w_f = 2 pi / T``, rad/s."""
        return 2.0 * np.pi / self.period

    @property
    def size(self) -> int:
        """Number of unknowns, ``(2L - 2) n``."""
        return int(self._e.shape[1]) * self.n

    @property
    def columns(self) -> int:
        """Columns of ``W``: link base parameters plus the independent drive columns."""
        return self.base.size + int(self.drive_columns.size)

    # -- coefficients and states ------------------------------------------------------------

    def _z(self, z: ArrayLike) -> Array:
        return np.asarray(z, dtype=float).reshape(self._e.shape[1], self.n)

    def coefficients(self, z: ArrayLike) -> tuple[Array, Array, Array]:
        """``q0`` (n,), ``a`` and ``b`` (n, L) of nursing eq 22 for unknowns ``z``."""
        ab = (self._e @ self._z(z)).T  # (n, 2L)
        a, b = ab[:, : self.harmonics], ab[:, self.harmonics :]
        w = self.base_frequency * np.arange(1, self.harmonics + 1)
        return self.start + b @ (1.0 / w), a, b

    def states(self, z: ArrayLike) -> tuple[Array, Array, Array]:
        """``q``, ``qd``, ``qdd`` on the grid ``t``, (samples, n) each."""
        zz = self._z(z)
        return self.start + self._pq @ zz, self._pqd @ zz, self._pqdd @ zz

    def regression_matrix(self, q: Array, qd: Array, qdd: Array) -> Array:
        """``W`` for states (N, n): (N, n, columns), link base columns then drive columns."""
        link = self.base.regressor(regressor(self.robot, q, qd, qdd))
        if self.drive_columns.size == 0:
            return link
        drives = _drive_columns(self._n_mat, self._smoothing, qd, qdd)[..., self.drive_columns]
        return np.concatenate([link, drives], axis=2)

    # -- criterion --------------------------------------------------------------------------

    def objective(self, z: ArrayLike) -> tuple[float, Array]:
        """The criterion (log condition number or ``-log det``) and its gradient, shape (size,)."""
        zz = self._z(z)
        q, qd, qdd = self.states(zz)
        big_n, n = q.shape
        # the grid, then each joint's q, qd, qdd pushed by one step at every sample at once
        stack = np.empty((1 + 3 * n, 3, big_n, n))
        stack[:] = np.stack([q, qd, qdd])[None]
        for kind in range(3):
            for j in range(n):
                stack[1 + kind * n + j, kind, :, j] += _FD_STEP
        flat = stack.transpose(1, 0, 2, 3).reshape(3, -1, n)
        w_all = self.regression_matrix(flat[0], flat[1], flat[2]).reshape(1 + 3 * n, big_n, n, -1)
        w0 = w_all[0]
        value, grad_w, cond = _criterion(w0.reshape(big_n * n, -1), self.criterion)
        self._last.clear()
        self._last[zz.tobytes()] = cond
        grad_w = grad_w.reshape(w0.shape)
        # dF/dx[s, j] for x in (q, qd, qdd): sum over rows of sample s and columns
        sens = np.einsum("sik,xsik->xs", grad_w, w_all[1:] - w0[None]) / _FD_STEP
        sens = sens.reshape(3, n, big_n).transpose(0, 2, 1)  # (3, N, n)
        grad = self._pq.T @ sens[0] + self._pqd.T @ sens[1] + self._pqdd.T @ sens[2]
        return value, grad.reshape(-1)

    def condition(self, z: ArrayLike, *, exact: bool = True) -> float:
        """Condition number of the column-scaled ``W`` on the grid: from its singular values, or
        (``exact=False``, for progress reports) from the eigenvalues of ``W_s^T W_s``."""
        if not exact:
            zz = self._z(z)
            if zz.tobytes() in self._last:  # the optimiser has just evaluated it
                return self._last[zz.tobytes()]
            return _criterion(self._w_flat(zz), "cond")[2]
        s = _scaled_singular_values(self._w_flat(z))
        return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")

    def d_criterion(self, z: ArrayLike) -> float:
        """``-log det(W_s^T W_s)`` on the grid (SVD)."""
        s = _scaled_singular_values(self._w_flat(z))
        return float(-2.0 * np.sum(np.log(s))) if s[-1] > 0 else float("inf")

    def _w_flat(self, z: ArrayLike) -> Array:
        q, qd, qdd = self.states(z)
        return self.regression_matrix(q, qd, qdd).reshape(q.size, -1)

    # -- constraints ------------------------------------------------------------------------

    def _tight(self) -> tuple[Array, Array, Array, Array, float | None]:
        half = 0.5 * (self.upper - self.lower)
        lower = np.minimum(self.lower + _GRID_MARGIN * half, self.start)
        upper = np.maximum(self.upper - _GRID_MARGIN * half, self.start)
        speed = (1.0 - _GRID_MARGIN) * self.speed
        acc = (1.0 - _GRID_MARGIN) * self.acceleration
        floor = None if self.floor is None else self.floor + _FLOOR_MARGIN
        return lower, upper, speed, acc, floor

    def _limit_margins(self, z: ArrayLike) -> tuple[Array, Array]:
        """Margins of the six linear limits on the constraint grid, (6, Nc, n), and the angles
        there (Nc, n): ``upper - q``, ``q - lower``, ``v -+ qd``, ``a -+ qdd`` (tightened)."""
        lower, upper, speed, acc, _ = self._tight()
        zz = self._z(z)
        q, qd, qdd = self.start + self._cq @ zz, self._cqd @ zz, self._cqdd @ zz
        margins = np.stack([upper - q, q - lower, speed - qd, speed + qd, acc - qdd, acc + qdd])
        return margins, q

    def constraints(self, z: ArrayLike) -> Array:
        """Inequality constraints, ``>= 0`` when met (limits 1 % tightened).

        Each limit of each joint (and the floor for each checked frame) contributes the margins at
        its :data:`_ACTIVE` lowest local minima on the constraint grid: a peak that approaches a
        limit is constrained wherever it moves, with a few hundred constraints instead of one per
        grid point and limit.
        """
        margins, q = self._limit_margins(z)
        out = [
            np.take_along_axis(m, _lowest_minima(m, _ACTIVE), axis=0).reshape(-1) for m in margins
        ]
        floor = self._tight()[4]
        if floor is not None:
            heights, _ = self._heights(q, jacobian=False)
            room = heights - floor
            out.append(np.take_along_axis(room, _lowest_minima(room, _ACTIVE), axis=0).reshape(-1))
        return np.concatenate(out)

    def constraints_jacobian(self, z: ArrayLike) -> Array:
        """Jacobian of :meth:`constraints`, shape (constraints, size)."""
        margins, q = self._limit_margins(z)
        n, k_free = self.n, self._e.shape[1]
        blocks = []
        for kind, m in enumerate(margins):
            basis = (self._cq, self._cqd, self._cqdd)[kind // 2]
            sign = -1.0 if kind % 2 == 0 else 1.0
            idx = _lowest_minima(m, _ACTIVE)  # (k, n)
            jac = np.zeros((_ACTIVE, n, k_free, n))
            for j in range(n):
                jac[:, j, :, j] = sign * basis[idx[:, j]]
            blocks.append(jac.reshape(_ACTIVE * n, -1))
        floor = self._tight()[4]
        if floor is not None:
            heights, dh = self._heights(q, jacobian=True)
            assert dh is not None
            idx = _lowest_minima(heights - floor, _ACTIVE)  # (k, F)
            frames = np.arange(heights.shape[1])[None, :]
            # d h[s, f] / d Z[k, j] = dh[s, f, j] * cq[s, k]
            jac_f = np.einsum("rfj,rfk->rfkj", dh[idx, frames], self._cq[idx])
            blocks.append(jac_f.reshape(idx.size, -1))
        return np.vstack(blocks)

    def _heights(self, q: Array, *, jacobian: bool) -> tuple[Array, Array | None]:
        """Heights (m) of the checked frames, (N, F), and their derivatives (N, F, n)."""
        chain = make_chain(self.robot)
        axes, points, link = joint_axes(chain, q)
        flange = (link[:, -1] @ chain.flange)[:, :3, 3]
        if self.floor_frames == "links":
            pos = np.concatenate([link[:, 1:, :3, 3], flange[:, None, :]], axis=1)
            moved_by = [*range(2, self.n + 1), self.n]  # frame k is moved by joints 0..k
        else:
            pos = flange[:, None, :]
            moved_by = [self.n]
        heights = pos[:, :, 2]
        if not jacobian:
            return heights, None
        lever = pos[:, :, None, :] - points[:, None, :, :]  # (N, F, n, 3)
        # z component of axis x lever
        dh = axes[:, None, :, 0] * lever[..., 1] - axes[:, None, :, 1] * lever[..., 0]
        for f, count in enumerate(moved_by):
            dh[:, f, count:] = 0.0
        return heights, dh

    # -- checks and feasible draws ----------------------------------------------------------

    def margins(self, z: ArrayLike) -> dict[str, float]:
        """Smallest distance to each limit over every ``dt`` sample of one period (>= 0: met).

        Keys ``position`` (rad), ``speed`` (rad/s), ``acceleration`` (rad/s^2), ``floor`` (m,
        absent without a floor), and ``boundary``: the largest of ``|q - start|``, ``|qd|``,
        ``|qdd|`` at ``t = 0`` and ``t = T`` (zero up to round-off by construction).
        """
        q0, a, b = self.coefficients(z)
        motion = fourier_motion(q0, a, b, base_frequency=self.base_frequency, dt=self.dt)
        return check_motion(self, motion)

    def _linear_scale(self, zz: Array) -> float:
        """Largest factor ``s`` with ``s Z`` inside the position, speed and acceleration limits at
        every ``dt`` sample."""
        dq, qd, qdd = self._fq @ zz, self._fqd @ zz, self._fqdd @ zz
        room_up = np.where(dq > 0, (self.upper - self.start) / np.where(dq > 0, dq, 1.0), np.inf)
        room_lo = np.where(dq < 0, (self.lower - self.start) / np.where(dq < 0, dq, 1.0), np.inf)
        top = [
            float(np.min(room_up)),
            float(np.min(room_lo)),
            float(np.min(self.speed / np.maximum(np.max(np.abs(qd), axis=0), 1e-300))),
            float(np.min(self.acceleration / np.maximum(np.max(np.abs(qdd), axis=0), 1e-300))),
        ]
        return min(top)

    def _above_floor(self, zz: Array, scale: float, *, fine: bool) -> bool:
        """Whether ``scale * Z`` keeps the checked frames above the floor at every ``dt`` sample
        (``fine``) or on the constraint grid."""
        basis = self._fq if fine else self._cq
        heights, _ = self._heights(self.start + scale * (basis @ zz), jacobian=False)
        assert self.floor is not None
        return bool(np.all(heights >= self.floor))

    def fit_into_limits(self, z: ArrayLike, *, safety: float = 1.0 - 1e-9) -> Array:
        """``s z`` with the largest ``s <= 1`` that meets every limit at every ``dt`` sample, times
        ``safety`` when it had to shrink.

        Positions, speeds and accelerations scale linearly. The floor's factor is found by
        bisection on the constraint grid (the start pose is above the floor), then shrunk by 1 %
        steps until every ``dt`` sample is above it too.
        """
        zz = self._z(z)
        s = min(1.0, safety * self._linear_scale(zz))
        if self.floor is not None and not self._above_floor(zz, s, fine=True):
            lo, hi = 0.0, s
            for _ in range(30):
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if self._above_floor(zz, mid, fine=False) else (lo, mid)
            s = safety * lo
            while not self._above_floor(zz, s, fine=True):
                s *= 0.99
        return np.asarray(s * zz).reshape(-1)

    def random_start(self, rng: np.random.Generator) -> Array:
        """A random feasible ``z``: standard normal unknowns (iid normal coefficients projected on
        the boundary conditions), scaled to 99.9 % of the largest factor that meets every limit at
        every ``dt`` sample, so each draw uses the whole room the limits give."""
        zz = rng.standard_normal(self._e.shape[1] * self.n)
        return self.fit_into_limits(1e6 * zz, safety=0.999)  # from far outside: limits set the size


def _lowest_minima(margins: Array, k: int) -> NDArray[np.intp]:
    """Rows (k, m) of the ``k`` lowest local minima of each column of ``margins`` (Nc, m), a
    periodic grid; columns with fewer minima are filled with their lowest other rows."""
    is_min = (margins <= np.roll(margins, 1, axis=0)) & (margins <= np.roll(margins, -1, axis=0))
    span = np.ptp(margins, axis=0) + 1.0
    key = np.where(is_min, margins, margins + span)
    return np.argsort(key, axis=0, kind="stable")[:k]


def _check_grid(period: float, dt: float) -> Array:
    """Sample times of one period at ``dt``, the way :func:`fourier_motion` lays them out."""
    steps = round(period / dt)
    return np.arange(steps + 1, dtype=float) * (period / steps)


def _as_vector(value: ArrayLike, n: int, what: str) -> Array:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise KinergyError(f"{what}: expected a number or {n} finite numbers, got {arr.tolist()}")
    return arr


def excitation_problem(
    robot: Robot,
    *,
    harmonics: int = 5,
    period: float = 10.0,
    start: ArrayLike | None = None,
    position_range: float | ArrayLike | None = DEFAULT_RANGE,
    speed: float | ArrayLike | None = None,
    acceleration: float | ArrayLike | None = None,
    floor: float | None = 0.05,
    floor_frames: str = "links",
    criterion: str = "cond",
    include_drives: bool = True,
    samples: int = 200,
    dt: float = 0.002,
) -> ExcitationProblem:
    """Build an excitation design problem (module docstring).

    Parameters
    ----------
    robot : Robot
    harmonics : int
        ``L`` of nursing eq 22, >= 2.
    period : float
        ``T = 2 pi / w_f``, s.
    start : array_like, shape (n,), optional
        Start and end pose, rad. Default: UR's upright home ``[0, -pi/2, 0, -pi/2, 0, 0]`` for a
        6-joint arm, else the middle of each joint's range (clipped to +-pi); clipped to the limits.
    position_range : float or array_like, shape (n,), optional
        Half-width of each joint's range about ``start``, rad, intersected with the robot's
        limits; ``None`` for the robot's limits alone.
    speed : float or array_like, optional
        Speed limit, rad/s; default and upper bound the robot's.
    acceleration : float or array_like, optional
        Acceleration limit, rad/s^2; default the robot's, or :data:`ACCELERATION_PER_SPEED` times
        the speed limit where the model has none.
    floor : float or None
        Height above the base plane the checked frames must keep, m; ``None``: no floor.
    floor_frames : {"links", "flange"}
        The flange and every link frame from the second on, or the flange alone.
    criterion : {"cond", "dopt"}
        Condition number or D-optimality of the column-scaled regression matrix.
    include_drives : bool
        Add the rotor-inertia and friction columns to the regression matrix.
    samples : int
        Grid points per period for the criterion and the constraints.
    dt : float
        Sample time of the motion and the final check, s (the controller's 0.002).

    Raises
    ------
    KinergyError
        Bad options, a start pose outside the limits or below the floor.
    """
    n = robot.n
    if isinstance(harmonics, bool) or not isinstance(harmonics, int | np.integer):
        raise KinergyError(f"harmonics must be an integer, got {harmonics!r}")
    if harmonics < 2:
        raise KinergyError(
            f"harmonics must be >= 2, got {harmonics}: with zero speed and acceleration at both "
            "ends a single harmonic cannot move"
        )
    if not (np.isfinite(period) and period > 0):
        raise KinergyError(f"period must be > 0 s, got {period}")
    if not (np.isfinite(dt) and 0 < dt < period):
        raise KinergyError(f"dt must be in (0, period), got {dt}")
    if criterion not in CRITERIA:
        raise KinergyError(f"unknown criterion {criterion!r} (known: {', '.join(CRITERIA)})")
    if floor_frames not in FLOOR_FRAMES:
        raise KinergyError(
            f"unknown floor_frames {floor_frames!r} (known: {', '.join(FLOOR_FRAMES)})"
        )
    if floor is not None and not np.isfinite(floor):
        raise KinergyError(f"floor must be a finite height in m, got {floor}")
    if isinstance(samples, bool) or not isinstance(samples, int | np.integer):
        raise KinergyError(f"samples must be an integer, got {samples!r}")
    if samples < 4 * harmonics:
        raise KinergyError(
            f"samples must be >= 4 * harmonics = {4 * harmonics} per period, got {samples}"
        )
    limits = np.array([j.limits.position for j in robot.joints])
    if start is None:
        home = (
            _HOME_6
            if n == 6
            else 0.5 * (np.clip(limits[:, 0], -np.pi, np.pi) + np.clip(limits[:, 1], -np.pi, np.pi))
        )
        q_start = np.clip(home, limits[:, 0], limits[:, 1])
    else:
        q_start = _as_vector(start, n, "start pose")
        outside = np.flatnonzero((q_start < limits[:, 0]) | (q_start > limits[:, 1]))
        if outside.size:
            j = int(outside[0])
            raise KinergyError(
                f"start pose: joint {j + 1} ({robot.joints[j].name}) at {q_start[j]:.4g} rad is "
                f"outside its limits [{limits[j, 0]:.4g}, {limits[j, 1]:.4g}]"
            )
    lower, upper = limits[:, 0].copy(), limits[:, 1].copy()
    if position_range is not None:
        half = _as_vector(position_range, n, "position range")
        if np.any(half <= 0):
            raise KinergyError(f"position range must be > 0 rad, got {half.tolist()}")
        lower = np.maximum(lower, q_start - half)
        upper = np.minimum(upper, q_start + half)
    robot_speed = np.array([j.limits.speed for j in robot.joints])
    v = robot_speed if speed is None else np.minimum(_as_vector(speed, n, "speed"), robot_speed)
    if acceleration is None:
        acc = np.array(
            [
                ACCELERATION_PER_SPEED * v[i]
                if j.limits.acceleration is None
                else j.limits.acceleration
                for i, j in enumerate(robot.joints)
            ]
        )
    else:
        acc = _as_vector(acceleration, n, "acceleration")
    for name, arr, unit in (("speed", v, "rad/s"), ("acceleration", acc, "rad/s^2")):
        if np.any(arr <= 0):
            j = int(np.argmin(arr))
            raise KinergyError(
                f"{name} limit of joint {j + 1} ({robot.joints[j].name}) must be > 0 {unit}, got {arr[j]:g}"
            )
    if np.any(upper - lower <= 0):
        j = int(np.argmin(upper - lower))
        raise KinergyError(f"joint {j + 1} ({robot.joints[j].name}) has no room to move")

    w_f = 2.0 * np.pi / period
    t = np.arange(samples, dtype=float) * (period / samples)
    e = _null_basis(harmonics)
    pq, pqd, pqdd = (p @ e for p in _series_basis(t, w_f, harmonics))
    t_c = np.arange(2 * samples, dtype=float) * (period / (2 * samples))
    cq, cqd, cqdd = (p @ e for p in _series_basis(t_c, w_f, harmonics))
    fq, fqd, fqdd = (p @ e for p in _series_basis(_check_grid(period, dt), w_f, harmonics))
    n_mat = transmission_matrix(robot)
    smoothing = np.abs(np.diag(n_mat)) * COULOMB_SMOOTHING
    smoothing = np.where(smoothing > 0, smoothing, COULOMB_SMOOTHING)
    base = base_parameters(robot)
    drive_cols = (
        _independent_drive_columns(robot, base, n_mat, smoothing)
        if include_drives
        else np.zeros(0, dtype=int)
    )
    problem = ExcitationProblem(
        robot=robot,
        harmonics=int(harmonics),
        period=float(period),
        start=q_start,
        lower=lower,
        upper=upper,
        speed=v,
        acceleration=acc,
        floor=None if floor is None else float(floor),
        floor_frames=floor_frames,
        criterion=criterion,
        include_drives=include_drives,
        t=t,
        dt=float(dt),
        drive_columns=drive_cols,
        base=base,
        _e=e,
        _pq=pq,
        _pqd=pqd,
        _pqdd=pqdd,
        _n_mat=n_mat,
        _smoothing=smoothing,
        _cq=cq,
        _cqd=cqd,
        _cqdd=cqdd,
        _fq=fq,
        _fqd=fqd,
        _fqdd=fqdd,
    )
    if samples * n < 2 * problem.columns:
        raise KinergyError(
            f"samples: {samples} grid points x {n} joints is too few for {problem.columns} "
            f"parameters (need at least {-(-2 * problem.columns // n)})"
        )
    if floor is not None:
        heights, _ = problem._heights(q_start[None, :], jacobian=False)
        if np.min(heights) <= floor:
            raise KinergyError(
                f"the start pose puts a checked frame {np.min(heights):.3f} m above the base "
                f"plane, not above the floor at {floor:g} m: choose another start pose or floor"
            )
    return problem


# ---------------------------------------------------------------------------------------------
# Results


@dataclass(frozen=True, eq=False)
class Excitation:
    """An excitation trajectory (nursing eq 22) and how good it is.

    Attributes
    ----------
    q0 : ndarray, shape (n,)
        Offsets, rad.
    a, b : ndarray, shape (n, L)
        Coefficients, rad/s.
    period : float
        s.
    start : ndarray, shape (n,)
        Start and end pose, rad.
    criterion : str
        What was optimised (``"cond"`` or ``"dopt"``; ``"random"`` for a random draw).
    condition : float
        Condition number of the column-scaled regression matrix on the problem's grid.
    d_criterion : float
        ``-log det(W_s^T W_s)`` on the same grid.
    margins : dict of str to float
        :meth:`ExcitationProblem.margins`: smallest room to each limit at every ``dt`` sample.
    motion : Motion
        One period sampled every ``dt`` (:func:`fourier_motion`).
    iterations : int
        SLSQP iterations of the best start (0 for a random draw).
    seconds : float
        Wall time of the design, s.
    history : list of float
        Condition number after each iteration of the best start.
    """

    q0: Array
    a: Array
    b: Array
    period: float
    start: Array
    criterion: str
    condition: float
    d_criterion: float
    margins: dict[str, float]
    motion: Motion
    iterations: int = 0
    seconds: float = 0.0
    history: list[float] = field(default_factory=list)

    @property
    def harmonics(self) -> int:
        return int(self.a.shape[1])

    @property
    def base_frequency(self) -> float:
        """``w_f``, rad/s."""
        return 2.0 * np.pi / self.period

    def repeated(self, periods: int = 1, *, dt: float | None = None) -> Motion:
        """``periods`` whole periods back to back, sampled every ``dt`` s (default the motion's)."""
        step = float(self.motion.t[1] - self.motion.t[0]) if dt is None else dt
        return fourier_motion(
            self.q0, self.a, self.b, base_frequency=self.base_frequency, periods=periods, dt=step
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "harmonics": self.harmonics,
            "period": self.period,
            "base_frequency": self.base_frequency,
            "criterion": self.criterion,
            "condition": self.condition,
            "d_criterion": self.d_criterion,
            "start": self.start.tolist(),
            "q0": self.q0.tolist(),
            "a": self.a.tolist(),
            "b": self.b.tolist(),
            "margins": dict(self.margins),
            "iterations": self.iterations,
            "seconds": self.seconds,
        }


def check_motion(problem: ExcitationProblem, motion: Motion) -> dict[str, float]:
    """The problem's limits checked at every sample of ``motion`` (see
    :meth:`ExcitationProblem.margins`); ``boundary`` compares the first and last samples with the
    start pose at rest."""
    q, qd, qdd = motion.q, motion.qd, motion.qdd
    out = {
        "position": float(min(np.min(problem.upper - q), np.min(q - problem.lower))),
        "speed": float(np.min(problem.speed - np.abs(qd))),
        "acceleration": float(np.min(problem.acceleration - np.abs(qdd))),
    }
    if problem.floor is not None:
        heights, _ = problem._heights(q, jacobian=False)
        out["floor"] = float(np.min(heights) - problem.floor)
    ends = [q[0] - problem.start, q[-1] - problem.start, qd[0], qd[-1], qdd[0], qdd[-1]]
    out["boundary"] = float(max(np.max(np.abs(x)) for x in ends))
    return out


def _excitation(
    problem: ExcitationProblem,
    z: Array,
    criterion: str,
    *,
    iterations: int = 0,
    seconds: float = 0.0,
    history: list[float] | None = None,
) -> Excitation:
    q0, a, b = problem.coefficients(z)
    motion = fourier_motion(q0, a, b, base_frequency=problem.base_frequency, dt=problem.dt)
    sv = _scaled_singular_values(problem._w_flat(z))
    return Excitation(
        q0=q0,
        a=a,
        b=b,
        period=problem.period,
        start=problem.start.copy(),
        criterion=criterion,
        condition=float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf"),
        d_criterion=float(-2.0 * np.sum(np.log(sv))) if sv[-1] > 0 else float("inf"),
        margins=check_motion(problem, motion),
        motion=motion,
        iterations=iterations,
        seconds=seconds,
        history=list(history or []),
    )


def random_feasible(
    problem: ExcitationProblem, rng: np.random.Generator, count: int = 1
) -> list[Excitation]:
    """``count`` random feasible excitations of the problem's size (:meth:`random_start`).

    Each meets every limit at every ``dt`` sample and uses the whole room they give (scaled to
    99.9 % of the largest feasible size): the baseline an optimised design is compared with.
    """
    if count < 1:
        raise KinergyError(f"count must be >= 1, got {count}")
    return [_excitation(problem, problem.random_start(rng), "random") for _ in range(count)]


def design_excitation(
    problem: ExcitationProblem,
    *,
    starts: int = 4,
    seed: int = 0,
    maxiter: int = 100,
    progress: Progress | None = None,
) -> Excitation:
    """Optimise the problem's criterion with SLSQP from ``starts`` random feasible starts.

    Parameters
    ----------
    problem : ExcitationProblem
    starts : int
        Random feasible starting points (:meth:`ExcitationProblem.random_start`), seeded.
    seed : int
    maxiter : int
        SLSQP iterations per start.
    progress : callable, optional
        ``progress(start, iteration, condition)`` after every iteration (``iteration`` 0 is the
        starting point; start counts from 1).

    Returns
    -------
    Excitation
        The start whose result has the best criterion, checked and if need be scaled so every
        ``dt`` sample meets every limit.
    """
    if isinstance(starts, bool) or not isinstance(starts, int | np.integer) or starts < 1:
        raise KinergyError(f"starts must be an integer >= 1, got {starts!r}")
    if maxiter < 1:
        raise KinergyError(f"maxiter must be >= 1, got {maxiter}")
    clock = time.perf_counter()
    rng = np.random.default_rng(seed)
    best: tuple[float, Array, int, list[float]] | None = None
    constraint = {
        "type": "ineq",
        "fun": problem.constraints,
        "jac": problem.constraints_jacobian,
    }
    for k in range(1, starts + 1):
        z0 = problem.random_start(rng)
        history = [problem.condition(z0, exact=False)]
        if progress is not None:
            progress(k, 0, history[0])

        def step(xk: Array, k: int = k, history: list[float] = history) -> None:
            history.append(problem.condition(xk, exact=False))
            if progress is not None:
                progress(k, len(history) - 1, history[-1])

        res = scipy.optimize.minimize(
            problem.objective,
            z0,
            jac=True,
            method="SLSQP",
            constraints=[constraint],
            callback=step,
            options={"maxiter": int(maxiter), "ftol": 1e-7},
        )
        z = problem.fit_into_limits(res.x if np.all(np.isfinite(res.x)) else z0)
        value = problem.objective(z)[0]
        if best is None or value < best[0]:
            best = (value, z, int(res.nit), history)
    assert best is not None
    _, z, iterations, history = best
    return _excitation(
        problem,
        z,
        problem.criterion,
        iterations=iterations,
        seconds=time.perf_counter() - clock,
        history=history,
    )
