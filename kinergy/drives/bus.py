"""The arm's DC bus and supply: what the arm draws for the motors' electrical powers.

A UR arm's joints hang on one 48 V DC bus fed by the control box's supply (UR5e doc section 5).
kinergy's model of it, for the motors' electrical powers ``W_j`` (UR5e eq 23, positive when drawn):

- the joints share the bus: a joint that brakes feeds the others, ``P_bus = sum_j W_j``;
- what the joints together return (``P_bus < 0``) cannot go back into the supply: the drives
  burn it in the braking (shunt) resistor, ``P_shunt = max(-P_bus, 0)``;
- the arm's electronics and brakes draw a constant ``standby_power`` (robot file; nominal until
  ``kinergy identify`` measures it from ``actual_robot_current``);

so the arm draws ``P_supply = max(P_bus, 0) + standby`` from its supply. Left out: the losses of
the drives' power electronics (folded into the motors' ``R`` and ``k_b`` when these come from
measured voltages), the control box itself and the supply's own efficiency.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array

__all__ = ["SupplyPower", "supply_power"]


@dataclass(frozen=True, eq=False)
class SupplyPower:
    """The bus and supply powers over a run, W, each shape (N,).

    Attributes
    ----------
    bus : ndarray
        ``sum_j W_j``: the motors' net electrical power on the bus.
    motors : ndarray
        ``max(bus, 0)``: what the motors draw from the supply.
    shunt : ndarray
        ``max(-bus, 0)``: surplus braking power burnt in the shunt resistor.
    standby : float
        The electronics' and brakes' constant power.
    """

    bus: Array
    motors: Array
    shunt: Array
    standby: float

    @property
    def supply(self) -> Array:
        """``motors + standby``: what the arm draws from its supply, W, shape (N,)."""
        return self.motors + self.standby


def supply_power(power: ArrayLike, standby: float = 0.0) -> SupplyPower:
    """The bus model (module docstring) for motor powers ``power`` (W, shape (N, n)) and a
    constant ``standby`` (W)."""
    bus = np.asarray(power, dtype=float).sum(axis=1)
    return SupplyPower(
        bus=bus, motors=np.maximum(bus, 0.0), shunt=np.maximum(-bus, 0.0), standby=float(standby)
    )
