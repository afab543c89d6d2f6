"""Physical consistency of identified link parameters, and the standard parameters behind base ones.

A robot file stores each link's mass, centre of mass and inertia (the 10 standard parameters); an
identification finds base parameters (nursing eqs 15-16). This module goes between them and
checks that a link is a real body:

- :func:`standard_from_base`: the standard parameters closest to a prior that reproduce given base
  parameters exactly;
- :func:`pseudo_inertia`: each link's 4x4 pseudo-inertia (Wensing et al. 2018), positive definite
  exactly for physically consistent links;
- :func:`link_consistency`: what, if anything, makes a link unphysical (one line per link).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.dynamics.regressor import BaseParameters
from kinergy.model.robot import Robot

__all__ = [
    "LENGTH_SCALE",
    "PSEUDO_BASIS",
    "base_projection",
    "inertia_vector",
    "link_consistency",
    "link_from_standard",
    "parameter_scale",
    "pseudo_inertia",
    "standard_from_base",
]


#: length (m) that puts masses, first moments and inertias on one scale when "closest" is measured
LENGTH_SCALE = 0.1


def base_projection(base: BaseParameters, p: int) -> Array:
    """``P``, shape (b, p): ``pi -> pi[independent] + beta @ pi[dependent]`` (nursing eq 16)."""
    p_mat = np.zeros((base.size, p))
    p_mat[:, base.independent] = np.eye(base.size)
    p_mat[:, base.dependent] = base.beta
    return p_mat


def parameter_scale(robot: Robot, length: float = LENGTH_SCALE) -> Array:
    """Typical size of each standard parameter: ``m``, ``m L`` and ``m L^2`` per link, shape (10 n,).

    ``m`` is the link's model mass (kg) and ``L`` = ``length`` (m); used to measure "closest" in
    one unit across kg, kg m and kg m^2 (:func:`standard_from_base`).
    """
    per = np.array([1.0, length, length, length] + [length**2] * 6)
    return np.concatenate([j.link.mass * per for j in robot.joints])


def standard_from_base(
    base: BaseParameters, pi_b: ArrayLike, prior: ArrayLike, *, scale: ArrayLike | None = None
) -> Array:
    """The standard parameters closest to ``prior`` that have the base parameters ``pi_b``.

    With ``P`` the base projection ``pi -> pi[independent] + beta @ pi[dependent]`` (nursing
    eq 16) and ``S = diag(scale)``, the smallest change ``|S^-1 (pi - pi0)|`` that reaches
    ``pi_b`` is ::

        pi = pi0 + S^2 P^T (P S^2 P^T)^-1 (pi_b - P pi0)

    (``S = 1``: ``pi0 + P^T (P P^T)^-1 (pi_b - P pi0)``). It reproduces ``pi_b`` exactly, so the
    torques are the identified ones; the directions the data cannot see (the null space of ``P``)
    keep the prior's values.

    Parameters
    ----------
    base : BaseParameters
    pi_b : array_like, shape (b,)
        Base parameters (units of their leading standard parameter: kg, kg m or kg m^2).
    prior : array_like, shape (p,)
        Standard parameters of the model (:func:`kinergy.dynamics.regressor.inertial_parameters`).
    scale : array_like, shape (p,), optional
        Typical size of each parameter (:func:`parameter_scale`); default 1.

    Returns
    -------
    ndarray, shape (p,)
    """
    pi0 = np.asarray(prior, dtype=float)
    w = np.ones_like(pi0) if scale is None else np.asarray(scale, dtype=float) ** 2
    p_mat = base_projection(base, pi0.size)
    gap = np.asarray(pi_b, dtype=float) - p_mat @ pi0
    return np.asarray(pi0 + w * (p_mat.T @ np.linalg.solve((p_mat * w) @ p_mat.T, gap)))


def _pseudo_basis() -> Array:
    """``E`` (10, 4, 4) with ``pseudo_inertia = sum_k pi_k E_k`` for one link."""
    e = np.zeros((10, 4, 4))
    e[0, 3, 3] = 1.0
    for k in range(3):
        e[1 + k, k, 3] = e[1 + k, 3, k] = 1.0
    # Ixx, Ixy, Iyy, Ixz, Iyz, Izz -> Sigma = tr(I)/2 1 - I
    for k, (a, b) in zip(
        range(4, 10), [(0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2)], strict=True
    ):
        unit = np.zeros((3, 3))
        unit[a, b] = unit[b, a] = 1.0
        e[k, :3, :3] = 0.5 * np.trace(unit) * np.eye(3) - unit
    return e


PSEUDO_BASIS = _pseudo_basis()


def pseudo_inertia(standard: ArrayLike) -> Array:
    """Pseudo-inertia matrices ``[[Sigma, h], [h^T, m]]`` of each link, shape (n, 4, 4).

    ``Sigma = tr(I_o)/2 1 - I_o`` (kg m^2) is the second moment of the mass about the link origin,
    ``h = m c`` (kg m). A link is physically consistent (positive mass, inertia about the centre of
    mass positive definite and satisfying the triangle inequality) exactly when its pseudo-inertia
    is positive definite (Wensing, Kim, Slotine, IEEE RA-L 2018).

    Parameters
    ----------
    standard : array_like, shape (10 n,)
        ``[m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`` per link (inertia about the link origin).
    """
    pi = np.asarray(standard, dtype=float).reshape(-1, 10)
    return np.asarray(np.einsum("lk,kab->lab", pi, PSEUDO_BASIS))


def link_from_standard(pi: Array) -> tuple[float, Array, Array]:
    """Mass (kg), centre of mass (m, (3,)) and inertia about it (kg m^2, (3, 3)) of one link's
    ``[m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`` (inertia about the link origin)."""
    m = float(pi[0])
    ixx, ixy, iyy, ixz, iyz, izz = pi[4:10]
    i_o = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    if m <= 0.0:
        return m, np.zeros(3), i_o
    c = pi[1:4] / m
    # parallel-axis theorem: I_o = I_c + m (|c|^2 1 - c c^T)
    return m, c, i_o - m * (float(c @ c) * np.eye(3) - np.outer(c, c))


def inertia_vector(i: Array) -> Array:
    """``[Ixx, Iyy, Izz, Ixy, Iyz, Ixz]`` (the model's 6-vector, kg m^2) of a symmetric 3x3
    inertia matrix ``i``; :func:`kinergy.model.robot.inertia_matrix` goes the other way."""
    return np.array([i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[1, 2], i[0, 2]])


def link_consistency(standard: ArrayLike) -> list[str | None]:
    """Physical consistency of each link's standard parameters.

    A link is physical when its mass is positive and its inertia about the centre of mass,
    ``I_c = I_o - m (|c|^2 1 - c c^T)`` with ``c = h / m``, is positive definite with principal
    moments satisfying the triangle inequality (the checks :class:`kinergy.model.robot.Link`
    makes).

    Parameters
    ----------
    standard : array_like, shape (10 n,)
        ``[m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`` per link (inertia about the link origin).

    Returns
    -------
    list of str or None, length n
        ``None`` for a physical link, else what is wrong with it (one phrase with the numbers).
    """
    out: list[str | None] = []
    for row in np.asarray(standard, dtype=float).reshape(-1, 10):
        m, c, i_c = link_from_standard(row)
        if not m > 0.0:
            out.append(f"identified mass {m:.4g} kg is not physical")
            continue
        eig = np.linalg.eigvalsh(i_c)
        moments = np.array2string(eig, precision=4)
        if eig[0] <= 0.0:
            out.append(
                "identified inertia about the centre of mass is not positive definite "
                f"(principal moments {moments} kg m², centre of mass "
                f"{np.array2string(c, precision=4)} m)"
            )
        elif eig[0] + eig[1] < eig[2] * (1.0 - 1e-9):
            out.append(
                f"identified inertia violates the triangle inequality (principal moments {moments} kg m²)"
            )
        else:
            out.append(None)
    return out
