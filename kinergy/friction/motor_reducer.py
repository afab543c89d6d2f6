"""``motor_reducer``: framework Table 1, motor viscous friction plus tanh-smoothed Coulomb
friction of the motor and of the reducer:
``motor_viscous * wm + (motor_coulomb + reducer_coulomb) * tanh(wm / smoothing)``.

The two Coulomb levels share one regressor column: only their sum, ``coulomb``, can be identified;
a fit shares it between motor and reducer in the ratio of the old values (equally when both
were zero)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from kinergy.arrays import Array
from kinergy.friction.model import FrictionModel
from kinergy.friction.viscous_coulomb import columns, sign


def _torque(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    coulomb = p["motor_coulomb"] + p["reducer_coulomb"]
    return p["motor_viscous"] * wm + coulomb * sign(wm, p["smoothing"])


def _linear_values(model: FrictionModel, p: Mapping[str, float]) -> Array:
    return np.array([p["motor_viscous"], p["motor_coulomb"] + p["reducer_coulomb"]])


def _with_linear(model: FrictionModel, p: Mapping[str, float], values: Array) -> dict[str, float]:
    viscous, coulomb = (float(v) for v in values)
    old = p["motor_coulomb"] + p["reducer_coulomb"]
    share = p["motor_coulomb"] / old if old > 0 else 0.5
    return {
        **p,
        "motor_viscous": viscous,
        "motor_coulomb": coulomb * share,
        "reducer_coulomb": coulomb * (1.0 - share),
    }


MODEL = FrictionModel(
    name="motor_reducer",
    parameters=("motor_viscous", "motor_coulomb", "reducer_coulomb", "smoothing"),
    torque=_torque,
    linear=("motor_viscous", "coulomb"),
    columns=columns,
    shape_defaults={"motor_coulomb": 0.5, "reducer_coulomb": 0.5},
    citation="framework Table 1",
    units={
        "motor_viscous": "N m s/rad",
        "motor_coulomb": "N m",
        "reducer_coulomb": "N m",
        "smoothing": "rad/s",
    },
    linear_values=_linear_values,
    with_linear=_with_linear,
    line=lambda p: (p["motor_coulomb"] + p["reducer_coulomb"], p["motor_viscous"]),
)
