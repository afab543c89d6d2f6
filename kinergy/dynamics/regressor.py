"""The joint-torque regressor, linear in the standard inertial parameters, and the base
(identifiable) parameter set.

Standard parameters: 10 per link, in link frame i (the frame the robot file uses), ordered ::

    [m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]

with ``(mx, my, mz) = m c`` (kg m) and the inertia about the link frame *origin* (kg m^2), the
order Pinocchio uses for its dynamic parameters. ``regressor(robot, q, qd, qdd) @
inertial_parameters(robot) == rnea(robot, q, qd, qdd)`` (nursing eq 15).

Base parameters (nursing eq 16): the columns of the stacked regressor that are linearly
independent, found by QR with column pivoting on random states; every other column is a fixed
linear combination of them, so ``regressor[..., independent] @ base == regressor @ standard`` with
``base = standard[independent] + beta @ standard[dependent]``.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray

from kinergy.arrays import Array
from kinergy.dynamics.blocks import result_array
from kinergy.dynamics.chain import (
    check_state,
    contiguous_state,
    gravity_in_frame0,
    kernel_data,
    link_inertials,
    output_array,
)
from kinergy.dynamics.launch import regressor_gradient_into, regressor_into
from kinergy.errors import KinergyError
from kinergy.linalg import pivoted_rank
from kinergy.model.robot import Robot

__all__ = [
    "GRADIENT_STEP_Q",
    "PARAMETER_NAMES",
    "BaseParameters",
    "base_parameters",
    "inertial_parameters",
    "parameter_names",
    "regressor",
    "regressor_chunks",
    "regressor_gradient",
]


#: Names of the 10 standard parameters of one link, in order.
PARAMETER_NAMES = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")


def parameter_names(robot: Robot) -> list[str]:
    """``["m1", "mx1", ..., "Izz{n}"]``, the names of the 10 n standard parameters."""
    return [f"{p}{i + 1}" for i in range(robot.n) for p in PARAMETER_NAMES]


def inertial_parameters(robot: Robot, *, include_payload: bool = True) -> Array:
    """Standard inertial parameters, shape (10 n,), in :data:`PARAMETER_NAMES` order per link.

    The payload, if any, is merged into the last link (``include_payload=False`` leaves it out).
    """
    body = link_inertials(robot, include_payload=include_payload)
    h = body.first_moment
    i_o = body.inertia_origin
    per_link = np.column_stack(
        [
            body.mass,
            h,
            i_o[:, 0, 0],
            i_o[:, 0, 1],
            i_o[:, 1, 1],
            i_o[:, 0, 2],
            i_o[:, 1, 2],
            i_o[:, 2, 2],
        ]
    )
    return per_link.reshape(-1)


def regressor(
    robot: Robot,
    q: ArrayLike,
    qd: ArrayLike | None = None,
    qdd: ArrayLike | None = None,
    *,
    gravity: ArrayLike | None = None,
    out: Array | None = None,
    threads: int | None = None,
) -> Array:
    """Joint-torque regressor Y with ``Y @ inertial_parameters(robot) == rnea(...)`` (nursing eq 15).

    Parameters
    ----------
    robot : Robot
        Only the kinematics and gravity are used.
    q, qd, qdd : array_like, shape (n,) or (N, n)
        rad, rad/s, rad/s^2; ``None`` means zero.
    gravity : array_like, shape (3,), optional
        Overrides ``robot.gravity``.
    out : ndarray, shape (n, 10 n) or (N, n, 10 n), optional
        C-contiguous float64 array the regressor is written to (any contents on entry). Without
        it the result is a new array of the caller's own; a large one reuses the memory of an
        earlier result that nothing refers to any more (:mod:`kinergy.dynamics.blocks`), which
        spares the page faults of fresh memory.
    threads : int, optional
        numba threads for this call (:func:`kinergy.dynamics.threads.kernel_threads`).

    Returns
    -------
    ndarray, shape (n, 10 n) or (N, n, 10 n)
        N m per unit parameter (``out`` when given).
    """
    single, s = check_state(robot, q=q, qd=qd, qdd=qdd)
    n = robot.n
    shape = (s["q"].shape[0], n, 10 * n)
    # a fresh result may reuse the memory of one nothing refers to any more (no page faults):
    # its contents are arbitrary, so the kernel writes the structural zeros too
    y = result_array(shape) if out is None else output_array(out, shape, single)
    g0 = gravity_in_frame0(robot, gravity)
    regressor_into(kernel_data(robot), contiguous_state(s), y, g0, threads)
    if out is not None:
        return out
    return y[0] if single else y


def regressor_chunks(
    robot: Robot,
    q: ArrayLike,
    qd: ArrayLike | None = None,
    qdd: ArrayLike | None = None,
    *,
    rows: int = 4096,
    threads: int | None = None,
) -> Iterator[tuple[slice, Array]]:
    """The regressor of a long batch in blocks of at most ``rows`` samples, all written into
    one reused (rows, n, 10 n) buffer: memory bounded by ``rows``, whatever N.

    Yields
    ------
    (slice, ndarray)
        The samples of the block and their regressor, shape (k, n, 10 n), k <= rows; valid
        until the next block is asked for (copy it to keep it).
    """
    _, s = check_state(robot, q=q, qd=qd, qdd=qdd)
    n, big_n = robot.n, s["q"].shape[0]
    buffer = np.zeros((min(rows, big_n), n, 10 * n))  # its structural zeros stay
    data = kernel_data(robot)
    for start in range(0, big_n, rows):
        part = slice(start, min(start + rows, big_n))
        block = buffer[: part.stop - start]
        state = tuple(np.ascontiguousarray(s[k][part]) for k in ("q", "qd", "qdd"))
        regressor_into(data, state, block, None, threads, clear=False)  # type: ignore[arg-type]
        yield part, block


#: central step in q of :func:`regressor_gradient`, rad (truncation error about 1e-10)
GRADIENT_STEP_Q = 1e-5


def regressor_gradient(
    robot: Robot,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    weights: ArrayLike,
    *,
    threads: int | None = None,
) -> Array:
    """Derivatives of ``f = sum(weights * Y(q, qd, qdd))`` in every sample's states: what a
    criterion of the regressor needs (chain rule through ``dF/dY = weights``) without building
    ``dY/dx``, (N, n, 10 n, 3 n) per batch.

    ``Y`` is linear in ``qdd`` and quadratic in ``qd``: their derivatives are exact (a unit
    forward and a unit central difference, nursing eq 15's structure); ``q`` takes a central
    step of :data:`GRADIENT_STEP_Q`. One sample costs ``5 n + 1`` regressor evaluations in
    registers, nothing stored.

    Parameters
    ----------
    q, qd, qdd : array_like, shape (N, n)
        rad, rad/s, rad/s^2.
    weights : array_like, shape (N, n, 10 n)
        ``dF/dY``.

    Returns
    -------
    ndarray, shape (3, N, n)
        ``df/dq``, ``df/dqd``, ``df/dqdd`` per sample and joint.
    """
    _, s = check_state(robot, q=q, qd=qd, qdd=qdd)
    big_n, n = s["q"].shape
    w = np.ascontiguousarray(weights, dtype=float)
    if w.shape != (big_n, n, 10 * n):
        raise KinergyError(f"weights: expected shape {(big_n, n, 10 * n)}, got {w.shape}")
    sens = np.empty((3, big_n, n))
    regressor_gradient_into(
        kernel_data(robot), contiguous_state(s), w, sens, GRADIENT_STEP_Q, threads
    )
    return sens


@dataclass(frozen=True)
class BaseParameters:
    """The base (identifiable) parameter set of a robot's standard inertial parameters.

    Attributes
    ----------
    independent : ndarray of int, shape (b,)
        Indices of the standard parameters that form the base set (sorted).
    dependent : ndarray of int, shape (p - b,)
        The remaining indices.
    beta : ndarray, shape (b, p - b)
        ``Y[:, dependent] = Y[:, independent] @ beta`` for every state.
    names : list of str
        Standard parameter names (length p).
    """

    independent: NDArray[np.int_]
    dependent: NDArray[np.int_]
    beta: Array
    names: list[str]

    @property
    def size(self) -> int:
        return len(self.independent)

    def project(self, standard: ArrayLike) -> Array:
        """Base parameters from standard ones: ``pi[ind] + beta @ pi[dep]``, shape (b,)."""
        pi = np.asarray(standard, dtype=float)
        return pi[self.independent] + self.beta @ pi[self.dependent]

    def regressor(self, full: Array) -> Array:
        """Base regressor: the independent columns of a full regressor (..., n, p) -> (..., n, b)."""
        return full[..., self.independent]

    def expressions(self, tol: float = 1e-10) -> list[str]:
        """Each base parameter as a readable combination, e.g. ``Izz2 + 0.1806*m3 + ...``."""
        out = []
        for row, k in enumerate(self.independent):
            terms = [self.names[k]]
            for col, d in enumerate(self.dependent):
                c = self.beta[row, col]
                if abs(c) > tol:
                    terms.append(f"{c:+.6g}*{self.names[d]}")
            out.append(" ".join(terms))
        return out


def base_parameters(
    robot: Robot,
    *,
    samples: int = 300,
    seed: int = 0,
    rtol: float = 1e-9,
) -> BaseParameters:
    """Find the base parameter set by numerical QR with column pivoting (Gautier's method).

    The regressor is stacked over ``samples`` random states (angles uniform over the joint
    ranges clipped to [-pi, pi], speeds and accelerations standard normal), seeded so the set is
    reproducible. Columns whose pivoted R diagonal falls below ``rtol`` times the largest are
    dependent.

    Returns
    -------
    BaseParameters
    """
    rng = np.random.default_rng(seed)
    lo = np.array([max(j.limits.position[0], -np.pi) for j in robot.joints])
    hi = np.array([min(j.limits.position[1], np.pi) for j in robot.joints])
    q = rng.uniform(lo, hi, (samples, robot.n))
    qd = rng.standard_normal((samples, robot.n))
    qdd = rng.standard_normal((samples, robot.n))
    w = regressor(robot, q, qd, qdd).reshape(-1, 10 * robot.n)
    scale = np.linalg.norm(w, axis=0)
    nonzero = scale > 1e-9 * scale.max()  # columns that are zero up to round-off
    ws = np.where(nonzero, w / np.where(nonzero, scale, 1.0), 0.0)
    found = pivoted_rank(ws, rtol=rtol)
    rank, r, piv = found.rank, found.r, found.pivots
    ind, dep = piv[:rank], piv[rank:]
    # ws[:, dep] = ws[:, ind] @ beta_s (in scaled columns), then undo the scaling
    beta_s = scipy.linalg.solve_triangular(r[:rank, :rank], r[:rank, rank:])
    beta = beta_s * scale[dep][None, :] / scale[ind][:, None]
    beta[:, ~nonzero[dep]] = 0.0
    order = np.argsort(ind)
    dep_order = np.argsort(dep)
    beta = beta[order][:, dep_order]
    beta[np.abs(beta) < 1e-12] = 0.0
    return BaseParameters(
        independent=ind[order],
        dependent=dep[dep_order],
        beta=beta,
        names=parameter_names(robot),
    )
