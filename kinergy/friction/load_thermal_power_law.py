"""``load_thermal_power_law``: the power-law model with a Coulomb level that grows with the load
and a speed term that falls as the joint warms:
``(coulomb + load |tau_load| + (viscous + viscous_temperature (T - reference_temperature))
|wm|^exponent) tanh(wm / smoothing)``.

It joins ``power_law`` (concave in speed), ``load_coulomb`` (AURT) and ``thermal_viscous``
(Raviola et al. 2021); the realistic twin's true joints have it (:mod:`kinergy.twin`).
Linear in ``coulomb``, ``load``, ``viscous`` and ``viscous_temperature`` for a fixed exponent,
which fits find by a 1-D search. Without a temperature it is evaluated at
``reference_temperature``.

Units (motor side): ``coulomb`` N m, ``load`` 1, ``viscous`` N m (s/rad)^exponent,
``viscous_temperature`` N m (s/rad)^exponent / K, ``exponent`` 1, ``reference_temperature``
deg C, ``smoothing`` rad/s.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from kinergy.arrays import Array
from kinergy.friction.model import FrictionModel, needed
from kinergy.friction.power_law import EXPONENT, EXPONENT_SEARCH, speed_power
from kinergy.friction.thermal_viscous import REFERENCE_TEMPERATURE, warming
from kinergy.friction.viscous_coulomb import sign

__all__ = ["MODEL"]


def _columns(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    s = sign(wm, p["smoothing"])
    load = np.abs(needed(tau_load, "load_thermal_power_law", "the load torque"))
    speed = s * speed_power(wm, p["exponent"])
    return np.column_stack([s, s * load, speed, speed * warming(p, wm, temperature)])


def _torque(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    values = np.array([p["coulomb"], p["load"], p["viscous"], p["viscous_temperature"]])
    return np.asarray(_columns(p, wm, tau_load, temperature) @ values, dtype=float)


MODEL = FrictionModel(
    name="load_thermal_power_law",
    parameters=(
        "coulomb",
        "load",
        "viscous",
        "viscous_temperature",
        "exponent",
        "reference_temperature",
        "smoothing",
    ),
    torque=_torque,
    linear=("coulomb", "load", "viscous", "viscous_temperature"),
    columns=_columns,
    positive=frozenset({"exponent"}),
    bounds={"viscous_temperature": (-np.inf, np.inf)},
    shape_defaults={"exponent": EXPONENT, "reference_temperature": REFERENCE_TEMPERATURE},
    search={"exponent": EXPONENT_SEARCH},
    needs_load=True,
    needs_temperature=True,
    citation="power_law + load_coulomb + thermal_viscous (docs/FRICTION.md)",
    units={
        "coulomb": "N m",
        "load": "1",
        "viscous": "N m (s/rad)^exponent",
        "viscous_temperature": "N m (s/rad)^exponent/K",
        "exponent": "1",
        "reference_temperature": "°C",
        "smoothing": "rad/s",
    },
)
