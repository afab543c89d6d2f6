"""The arm's DC bus and supply: what the arm draws for the motors' electrical powers.

A UR arm's joints hang on one 48 V DC bus fed by the control box's supply (UR5e doc section 5).
kinergy's model of it, for the motors' electrical powers ``W_j`` (UR5e eq 23, positive when drawn):

- the joints share the bus: a joint that brakes feeds the others, ``P_bus = sum_j W_j``;
- what the joints together return (``P_bus < 0``) cannot go back into the supply: the drives
  burn it in the braking (shunt) resistor, ``P_shunt = max(-P_bus, 0)``;
- the arm's electronics and brakes draw a constant ``standby_power`` (robot file; nominal until
  ``kinergy identify`` measures it from ``actual_robot_current``);

so the arm draws ``P_supply = max(P_bus, 0) + standby`` from its supply. Left out: the losses of
the drives' power electronics (folded into the motors' ``R`` and the standing draw), the control
box itself and the supply's own efficiency.

Each joint takes its power from the bus inside the arm: the voltage a UR controller logs for it,
``actual_joint_voltage``, is that bus voltage at the joint (about 48 V whatever the motor does),
not the motor's terminal voltage. The arm's cable drops it by the current the arm draws:
``V_joint = V_supply - r_bus I_supply`` (:func:`joint_bus_voltage`), with ``r_bus``
(:data:`BUS_RESISTANCE`) from a real UR3e's log (the ur3e-rad recording, Gujarati et al., DSN
2022): there each joint's logged voltage falls 0.12-0.30 V per ampere of ``actual_robot_current``
(base to wrist) and sits 0.1-0.4 V under ``actual_robot_voltage``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array

__all__ = ["BUS_RESISTANCE", "SupplyPower", "joint_bus_voltage", "supply_power"]


#: ohm: the arm's bus resistance from its supply to a joint (module docstring)
BUS_RESISTANCE = 0.2


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


def joint_bus_voltage(supply_voltage: ArrayLike, supply_current: ArrayLike, n: int) -> Array:
    """The bus voltage at each of ``n`` joints, what a UR controller logs as
    ``actual_joint_voltage`` (V, shape (N, n)): ``V_supply - r_bus I_supply`` for the supply's
    voltage (V) and current (A), each shape (N,) (module docstring, :data:`BUS_RESISTANCE`)."""
    drop = BUS_RESISTANCE * np.asarray(supply_current, dtype=float)
    at_joint = np.asarray(supply_voltage, dtype=float) - drop
    return np.repeat(at_joint[:, None], n, axis=1)
