"""The constant transforms of a serial chain under kinergy's two conventions.

``dh`` (standard Denavit-Hartenberg): frame i = frame i-1 · Rz(q_i + offset_i) · Tz(d_i) · Tx(a_i)
· Rx(alpha_i). ``mdh`` (Craig's modified DH): frame i = frame i-1 · Rx(alpha_{i-1}) · Tx(a_{i-1}) ·
Rz(q_i + offset_i) · Tz(d_i); a robot file stores a_{i-1} and alpha_{i-1} with joint i. The dynamics
(:mod:`kinergy.dynamics.chain`), the URDF reader and the exports all place links with these.
"""

from __future__ import annotations

import numpy as np

from kinergy.arrays import Array
from kinergy.model.robot import Robot

__all__ = ["dh_transform", "joint_transforms", "mdh_transform", "robot_transforms"]


def mdh_transform(a: float, alpha: float, offset: float, d: float) -> Array:
    """``Rx(alpha) · Tx(a) · Rz(offset) · Tz(d)``, shape (4, 4): frame i in frame i-1 at q_i = 0.

    Parameters
    ----------
    a, d : float
        a_{i-1} and d_i, m.
    alpha, offset : float
        alpha_{i-1} and offset_i, rad.
    """
    ca, sa, ct, st = np.cos(alpha), np.sin(alpha), np.cos(offset), np.sin(offset)
    return np.array(
        [
            [ct, -st, 0.0, a],
            [ca * st, ca * ct, -sa, -sa * d],
            [sa * st, sa * ct, ca, ca * d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def dh_transform(a: float, alpha: float, offset: float, d: float) -> Array:
    """``Rz(offset) · Tz(d) · Tx(a) · Rx(alpha)``, shape (4, 4): standard DH frame i in frame i-1
    at q_i = 0.

    Parameters
    ----------
    a, d : float
        a_i and d_i, m.
    alpha, offset : float
        alpha_i and offset_i, rad.
    """
    ca, sa, ct, st = np.cos(alpha), np.sin(alpha), np.cos(offset), np.sin(offset)
    return np.array(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0.0, sa, ca, d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def joint_transforms(convention: str, rows: Array) -> tuple[Array, Array]:
    """The constant transforms of a chain: link frame i is ``F_{i-1} · P_i · Rz(q_i) · C_i``.

    ``dh``: ``P_i = I``, ``C_i`` = :func:`dh_transform`; ``mdh``: ``P_i`` = :func:`mdh_transform`,
    ``C_i = I`` (:func:`kinergy.dynamics.chain.make_chain` builds its chain from them).
    Joint i turns about the z axis of ``F_{i-1} · P_i``.

    Parameters
    ----------
    convention : {'dh', 'mdh'}
    rows : ndarray, shape (n, 4)
        ``(a, alpha, offset, d)`` of each joint as the robot stores them (m, rad).

    Returns
    -------
    pre, post : ndarray, shape (n, 4, 4)
        ``P_i`` and ``C_i``.
    """
    n = len(rows)
    pre = np.tile(np.eye(4), (n, 1, 1))
    post = np.tile(np.eye(4), (n, 1, 1))
    for i, (a, alpha, offset, d) in enumerate(rows):
        if convention == "dh":
            post[i] = dh_transform(a, alpha, offset, d)
        else:
            pre[i] = mdh_transform(a, alpha, offset, d)
    return pre, post


def robot_transforms(robot: Robot) -> tuple[Array, Array]:
    """:func:`joint_transforms` of ``robot``'s joints: ``P_i`` and ``C_i``, each (n, 4, 4)."""
    rows = np.array([(j.a, j.alpha, j.offset, j.d) for j in robot.joints])
    return joint_transforms(robot.convention, rows)
