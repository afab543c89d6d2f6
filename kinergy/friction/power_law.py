"""``power_law``: Coulomb friction plus a speed term that grows as a power of the motor speed:
``(coulomb + viscous |wm|^exponent) tanh(wm / smoothing)``.

With ``exponent`` 1 this is ``viscous_coulomb``; real harmonic-drive joints are concave in speed:
a UR5e's factory calibration (``datasets/ur5e-calibration``) follows it with exponents 0.52-0.65
on every joint, where a straight line is 6-30 % off (docs/FRICTION.md). The model is linear in
``coulomb`` and ``viscous`` for a fixed exponent; fits find the exponent by a 1-D search
(:attr:`~kinergy.friction.model.FrictionModel.search`).

Units (motor side): ``coulomb`` N m, ``viscous`` N m (s/rad)^exponent, ``exponent`` 1,
``smoothing`` rad/s.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from kinergy.arrays import Array
from kinergy.friction.model import FrictionModel
from kinergy.friction.viscous_coulomb import sign

__all__ = ["EXPONENT", "EXPONENT_SEARCH", "MODEL", "speed_power"]

#: the speed exponent fits start from (a UR5e's calibration: 0.52-0.65) ...
EXPONENT = 0.6
#: ... and the range their 1-D search looks in, for every model with a power-law speed term
EXPONENT_SEARCH = (0.2, 1.5)


def speed_power(wm: Array, exponent: float) -> Array:
    """``|wm|^exponent`` (rad/s to the power), shape like ``wm``: the speed term of the power-law
    models."""
    return np.asarray(np.abs(wm) ** exponent, dtype=float)


def _torque(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    return (p["coulomb"] + p["viscous"] * speed_power(wm, p["exponent"])) * sign(wm, p["smoothing"])


def _columns(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    s = sign(wm, p["smoothing"])
    return np.column_stack([s, s * speed_power(wm, p["exponent"])])


MODEL = FrictionModel(
    name="power_law",
    parameters=("coulomb", "viscous", "exponent", "smoothing"),
    torque=_torque,
    linear=("coulomb", "viscous"),
    columns=_columns,
    positive=frozenset({"exponent"}),
    shape_defaults={"exponent": EXPONENT},
    search={"exponent": EXPONENT_SEARCH},
    citation="power-law speed term (docs/FRICTION.md; fitted to a UR5e's factory calibration)",
    units={
        "coulomb": "N m",
        "viscous": "N m (s/rad)^exponent",
        "exponent": "1",
        "smoothing": "rad/s",
    },
)
