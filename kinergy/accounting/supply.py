"""What the arm draws from its supply: predicted by the bus model, and measured in a log.

Predicted (:func:`supply_energy`): the motors' electrical powers (UR5e eq 23) summed on the DC
bus, clipped at zero (surplus braking power is burnt in the shunt resistor, not recovered), plus
the arm's standing draw, the robot file's ``standby_power`` (its electronics with the brakes
released, :mod:`kinergy.drives.bus`). On a short UR program the standing draw is most of it: the
UR3e of the ur3e-rad log stands at about 34 W of its 42 W mean. Measured (:func:`measured_supply`):
``actual_robot_voltage * actual_robot_current`` integrated by the trapezoid rule over the log,
the arm's 48 V supply as the controller measures it: motors, drive electronics and brakes; the
control box itself is not on it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import trapezoid

from kinergy.arrays import Array
from kinergy.drives.bus import SupplyPower, supply_power
from kinergy.io.segments import segment_bounds
from kinergy.model.robot import Robot

__all__ = [
    "MEASURED_INCLUDES",
    "PARTS_INCLUDE",
    "PREDICTED_INCLUDES",
    "MeasuredSupply",
    "SupplyEnergy",
    "measured_supply",
    "standing_draw_notes",
    "supply_energy",
]


#: what the predicted supply energy includes, as ``energy`` prints it
PREDICTED_INCLUDES = (
    "motors + standing draw: the motors' electrical power (UR5e eq 23: copper loss, motion and "
    "the k_b/k_t share) summed on the DC bus, braking surplus burnt in the shunt (not recovered), "
    "plus the robot file's standing draw (standby_power: electronics with the brakes released) "
    "over the duration; not the control box or the supply's own losses"
)
#: what each part of the predicted supply energy includes (``supply.parts`` of the JSON)
PARTS_INCLUDE = {
    "motors": "int max(sum_j W_j, 0) dt: the motors' electrical power (UR5e eq 23) summed on the "
    "DC bus, what they draw from the supply",
    "standby": "standby_power x duration: the arm's standing draw, electronics with the brakes "
    "released, whatever the motion",
    "shunt": "int max(-sum_j W_j, 0) dt: braking surplus burnt in the shunt resistor (not part of "
    "what is drawn)",
}
#: what the measured supply energy includes
MEASURED_INCLUDES = (
    "actual_robot_voltage x actual_robot_current over the log (trapezoid): the arm's supply as "
    "its controller measures it: motors, drive electronics and brakes; not the control box"
)


@dataclass(frozen=True)
class SupplyEnergy:
    """The bus model's energy over a motion, J, and its supply power, W.

    Attributes
    ----------
    drawn : float
        ``motors + standby``: what the arm draws from its supply.
    motors : float
        The motors' draw, ``int max(sum_j W_j, 0) dt``.
    standby : float
        The standing draw, ``standby_power * duration``.
    shunt : float
        Braking surplus burnt in the shunt, ``int max(-sum_j W_j, 0) dt``.
    mean_power, peak_power : float
        Of the supply power, W.
    standby_power : float
        The standing draw's power, W.
    includes : str
    parts : dict of str to str
        What ``motors``, ``standby`` and ``shunt`` each include (:data:`PARTS_INCLUDE`).
    """

    drawn: float
    motors: float
    standby: float
    shunt: float
    mean_power: float
    peak_power: float
    standby_power: float = 0.0
    includes: str = PREDICTED_INCLUDES
    parts: dict[str, str] = field(default_factory=lambda: dict(PARTS_INCLUDE))


def _integral(t: Array, power: Array) -> float:
    """``int power dt`` over each stretch of unbroken sampling, never across a gap."""
    return float(sum(trapezoid(power[a:b], t[a:b]) for a, b in segment_bounds(t)))


def _duration(t: Array) -> float:
    """Seconds sampled: the gaps between segments left out."""
    return float(sum(t[b - 1] - t[a] for a, b in segment_bounds(t)))


def supply_energy(t: ArrayLike, power: ArrayLike, standby_power: float = 0.0) -> SupplyEnergy:
    """The bus model's energy (:class:`SupplyEnergy`) for motor powers ``power`` (W, (N, n)) at
    times ``t`` (s, (N,)) and a constant ``standby_power`` (W)."""
    t = np.asarray(t, dtype=float)
    bus: SupplyPower = supply_power(power, standby_power)
    duration = _duration(t)
    motors = _integral(t, bus.motors)
    standby = bus.standby * duration
    drawn = motors + standby
    return SupplyEnergy(
        drawn=drawn,
        motors=motors,
        standby=standby,
        shunt=_integral(t, bus.shunt),
        mean_power=drawn / duration if duration else float("nan"),
        peak_power=float(np.max(bus.supply)),
        standby_power=bus.standby,
    )


def standing_draw_notes(robot: Robot) -> list[str]:
    """A note when ``robot`` has no standing draw (``standby_power`` 0 W): its supply figure is
    then the motors' alone, far under what a real arm draws."""
    if robot.standby_power > 0.0:
        return []
    return [
        f"{robot.name} has no standing draw (standby_power 0 W in its file): the supply figure "
        "is the motors' alone, while a UR arm draws about 34 W standing with its brakes released "
        "(kinergy identify measures it from a log with actual_robot_current)"
    ]


@dataclass(frozen=True)
class MeasuredSupply:
    """The supply energy a log measured, J, with its mean and peak power, W."""

    drawn: float
    mean_power: float
    peak_power: float
    includes: str = MEASURED_INCLUDES


def measured_supply(t: ArrayLike, voltage: ArrayLike, current: ArrayLike) -> MeasuredSupply:
    """``int V I dt`` of a log's ``actual_robot_voltage`` (V) and ``actual_robot_current`` (A),
    each (N,), at times ``t`` (s)."""
    t = np.asarray(t, dtype=float)
    power = np.asarray(voltage, dtype=float) * np.asarray(current, dtype=float)
    drawn = _integral(t, power)
    duration = _duration(t)
    return MeasuredSupply(
        drawn=drawn,
        mean_power=drawn / duration if duration else float("nan"),
        peak_power=float(np.max(power)),
    )
