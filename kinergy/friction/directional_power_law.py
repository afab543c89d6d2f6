"""``directional_power_law``: ``power_law`` with its own levels for each direction of rotation:
``(coulomb_positive + viscous_positive |wm|^exponent) max(s, 0)
+ (coulomb_negative + viscous_negative |wm|^exponent) min(s, 0)``, ``s = tanh(wm / smoothing)``.

For joints whose friction differs between the two directions (a UR5e's calibration has up to
8 % between them at 3.2 rad/s; gravity-loaded joints and worn gears more). All levels are
positive for friction that opposes the motion; linear in the four levels for a fixed exponent.

Units (motor side): ``coulomb_*`` N m, ``viscous_*`` N m (s/rad)^exponent, ``exponent`` 1,
``smoothing`` rad/s.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from kinergy.arrays import Array
from kinergy.friction.model import FrictionModel
from kinergy.friction.power_law import EXPONENT, EXPONENT_SEARCH, speed_power
from kinergy.friction.viscous_coulomb import sign

__all__ = ["MODEL"]


_LINEAR = ("coulomb_positive", "coulomb_negative", "viscous_positive", "viscous_negative")


def _columns(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    s = sign(wm, p["smoothing"])
    up, down = np.maximum(s, 0.0), np.minimum(s, 0.0)
    speed = speed_power(wm, p["exponent"])
    return np.column_stack([up, down, up * speed, down * speed])


def _torque(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    values = np.array([p[name] for name in _LINEAR])
    return np.asarray(_columns(p, wm, tau_load, temperature) @ values, dtype=float)


MODEL = FrictionModel(
    name="directional_power_law",
    parameters=(*_LINEAR, "exponent", "smoothing"),
    torque=_torque,
    linear=_LINEAR,
    columns=_columns,
    positive=frozenset({"exponent"}),
    shape_defaults={"exponent": EXPONENT},
    search={"exponent": EXPONENT_SEARCH},
    citation="power_law per direction of rotation (docs/FRICTION.md)",
    units={
        "coulomb_positive": "N m",
        "coulomb_negative": "N m",
        "viscous_positive": "N m (s/rad)^exponent",
        "viscous_negative": "N m (s/rad)^exponent",
        "exponent": "1",
        "smoothing": "rad/s",
    },
)
