"""``makkar``: Makkar's continuously differentiable friction (nursing eq 13):
``gamma1 (tanh(gamma2 wm) - tanh(gamma3 wm)) + gamma4 tanh(gamma5 wm) + gamma6 wm``.

``gamma1`` scales the Stribeck hump (rates ``gamma2``, ``gamma3``), ``gamma4`` the Coulomb level
(rate ``gamma5``) and ``gamma6`` is the viscous coefficient; the model is linear in
``gamma1``, ``gamma4`` and ``gamma6``."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.friction.model import FrictionModel

__all__ = ["MODEL", "PARAMETERS", "makkar", "makkar_columns"]

PARAMETERS = tuple(f"gamma{k}" for k in range(1, 7))


def makkar(gamma: Sequence[float] | ArrayLike, speed: ArrayLike) -> Array:
    """Nursing eq 13 at ``speed`` (any shape) for ``gamma`` = ``[gamma1, ..., gamma6]``."""
    g1, g2, g3, g4, g5, g6 = (float(g) for g in np.asarray(gamma, dtype=float))
    v = np.asarray(speed, dtype=float)
    return g1 * (np.tanh(g2 * v) - np.tanh(g3 * v)) + g4 * np.tanh(g5 * v) + g6 * v


def makkar_columns(rates: ArrayLike, speed: ArrayLike) -> Array:
    """Nursing eq 13's columns for its gains ``gamma1, gamma4, gamma6``, one set per row of rates.

    Parameters
    ----------
    rates : array_like, shape (3,) or (P, 3)
        ``gamma2, gamma3, gamma5``, s/rad.
    speed : array_like, shape (M,)
        rad/s.

    Returns
    -------
    ndarray, shape (M, 3) or (P, M, 3)
        ``[tanh(gamma2 v) - tanh(gamma3 v), tanh(gamma5 v), v]``: the curve is this times
        ``[gamma1, gamma4, gamma6]``.
    """
    r = np.asarray(rates, dtype=float)
    v = np.asarray(speed, dtype=float)
    g2, g3, g5 = (r[..., k, None] for k in range(3))
    hump = np.tanh(g2 * v) - np.tanh(g3 * v)
    return np.stack([hump, np.tanh(g5 * v), np.broadcast_to(v, hump.shape)], axis=-1)


def _torque(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    return makkar([p[name] for name in PARAMETERS], wm)


def _columns(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    return makkar_columns([p["gamma2"], p["gamma3"], p["gamma5"]], wm)


MODEL = FrictionModel(
    name="makkar",
    parameters=PARAMETERS,
    torque=_torque,
    linear=("gamma1", "gamma4", "gamma6"),
    columns=_columns,
    bounds={"gamma1": (-np.inf, np.inf)},  # its sign goes with gamma2 - gamma3
    shape_defaults={"gamma2": 50.0, "gamma3": 5.0, "gamma5": 100.0},
    citation="nursing eq 13 (Makkar et al.)",
    units={
        "gamma1": "N m",
        "gamma2": "s/rad",
        "gamma3": "s/rad",
        "gamma4": "N m",
        "gamma5": "s/rad",
        "gamma6": "N m s/rad",
    },
)
