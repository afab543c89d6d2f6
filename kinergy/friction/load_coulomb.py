"""``load_coulomb``: a Coulomb level that grows with the torque the joint carries, plus viscous
friction: ``(coulomb + load |tau_load|) tanh(wm / smoothing) + viscous wm``.

A harmonic drive's teeth and bearings press harder under load, so its Coulomb friction rises in
proportion to the transmitted torque (AURT, INTO-CPS Association, fits Coulomb friction
proportional to the joint load; Bittencourt and Gunnarsson 2012 find the same in robot joints).
``tau_load`` is the torque the motor delivers to the load without friction (motor side,
:func:`kinergy.predict.drive_state`). Linear in all three levels.

Units (motor side): ``coulomb`` N m, ``load`` 1 (N m of friction per N m of load),
``viscous`` N m s/rad, ``smoothing`` rad/s.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from kinergy.arrays import Array
from kinergy.friction.model import FrictionModel, needed
from kinergy.friction.viscous_coulomb import sign

__all__ = ["MODEL"]


def _torque(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    load = np.abs(needed(tau_load, "load_coulomb", "the load torque"))
    return (p["coulomb"] + p["load"] * load) * sign(wm, p["smoothing"]) + p["viscous"] * wm


def _columns(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    s = sign(wm, p["smoothing"])
    load = np.abs(needed(tau_load, "load_coulomb", "the load torque"))
    return np.column_stack([s, s * load, wm])


MODEL = FrictionModel(
    name="load_coulomb",
    parameters=("coulomb", "load", "viscous", "smoothing"),
    torque=_torque,
    linear=("coulomb", "load", "viscous"),
    columns=_columns,
    needs_load=True,
    citation="AURT (INTO-CPS Association); Bittencourt and Gunnarsson 2012",
    units={"coulomb": "N m", "load": "1", "viscous": "N m s/rad", "smoothing": "rad/s"},
)
