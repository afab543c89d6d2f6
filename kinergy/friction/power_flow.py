"""``power_flow``: UR5e eqs 11-16, viscous friction plus a Coulomb level that depends on the
direction of power flow through the harmonic drive:
``viscous * wm + tanh(wm / smoothing) * Tc``, ``Tc = coulomb_direct`` when power flows from the
motor to the load (``wm * tau_load > 0``), else ``coulomb_reverse``."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from kinergy.arrays import Array
from kinergy.friction.model import FrictionModel, needed
from kinergy.friction.viscous_coulomb import sign


def _load(tau_load: Array | None) -> Array:
    return needed(tau_load, "power_flow", "the load torque to tell the direction of power flow")


def _torque(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    direct = wm * _load(tau_load) > 0.0
    coulomb = np.where(direct, p["coulomb_direct"], p["coulomb_reverse"])
    return p["viscous"] * wm + coulomb * sign(wm, p["smoothing"])


def _columns(
    p: Mapping[str, float], wm: Array, tau_load: Array | None, temperature: Array | None
) -> Array:
    """UR5e eq 18's columns ``[wm, tanh(wm_dir / e), tanh(wm_rev / e)]`` (eqs 15-16)."""
    flow = wm * _load(tau_load)
    w_dir = np.where(flow > 0.0, wm, 0.0)  # UR5e eq 15
    w_rev = np.where(flow < 0.0, wm, 0.0)  # UR5e eq 16
    return np.column_stack([wm, sign(w_dir, p["smoothing"]), sign(w_rev, p["smoothing"])])


MODEL = FrictionModel(
    name="power_flow",
    parameters=("viscous", "coulomb_direct", "coulomb_reverse", "smoothing"),
    torque=_torque,
    linear=("viscous", "coulomb_direct", "coulomb_reverse"),
    columns=_columns,
    needs_load=True,
    citation="UR5e eqs 11-16",
    units={
        "viscous": "N m s/rad",
        "coulomb_direct": "N m",
        "coulomb_reverse": "N m",
        "smoothing": "rad/s",
    },
)
