"""95 % intervals on the energy figures, from the model's parameter errors.

An energy figure ``E`` (a joint's electrical energy, the motors' draw on the supply, what the arm
draws) is an integral over the motion of powers that depend on the model's identified
parameters ``theta`` (:mod:`kinergy.model.uncertainty`). Its gradient is the integral of the
powers' gradients, taken sample by sample in the same fold as the figures (same trapezoid
weights, same segments, one pass, memory bounded by the chunk)::

    dE_elec,j / dtheta_i = int dW_j/dtheta_i dt                        (theta_i a joint-j parameter)
    dE_motors / dtheta_i = int 1[sum_j W_j > 0] dW_j/dtheta_i dt         (the bus: UR5e eq 23 summed)
    dE_drawn / dtheta_i  = dE_motors / dtheta_i  (+ duration for standby_power)

``dW_j/dtheta_i`` by central differences of the drive model from the load torque on (the link
torques do not depend on ``theta``; a rotor inertia moves the load torque by ``dJ * dwm``),
exact for the power's quadratic dependence on the motor torque. A joint's power depends on its
own parameters only, so one evaluation moves one parameter of every joint at once: a chunk costs
``2 x`` (the most parameters of any joint) evaluations of friction and electrics, never of the
rigid-body dynamics. The interval is then the delta method's (``|D g|``, Student's t).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from kinergy.arrays import Array
from kinergy.drives.electrics import electrical_power, friction_torques
from kinergy.model.robot import Robot
from kinergy.model.uncertainty import Interval, Uncertainty, interval, perturbed
from kinergy.predict import DriveState

__all__ = ["NO_UNCERTAINTY", "EnergyIntervals", "Sensitivity", "interval_dict"]

#: what a figure says instead of an interval when its model carries no uncertainty
NO_UNCERTAINTY = (
    "the model carries no parameter errors (a built-in or data-sheet model): no interval; "
    "identify a model from logs for one"
)
#: a parameter is moved by this fraction of its standard deviation for its derivative
_STEP = 1e-3


def _joint(name: str) -> int | None:
    return int(name[7 : name.index("]")]) if name.startswith("joints[") else None


class Sensitivity:
    """The per-sample gradients of the joints' powers over ``robot.uncertainty``'s parameters
    (module docstring).

    Parameters
    ----------
    robot : Robot
        With ``uncertainty`` set.
    """

    def __init__(self, robot: Robot) -> None:
        assert robot.uncertainty is not None
        self.uncertainty = robot.uncertainty
        names = self.uncertainty.parameters
        self.p = len(names)
        self.joint = [_joint(name) for name in names]
        std = self.uncertainty.std
        self.step = np.where(std > 0, _STEP * std, 0.0)
        # group the parameters so that each group moves at most one per joint
        groups: list[list[int]] = []
        for i, j in enumerate(self.joint):
            if j is None or self.step[i] == 0.0:
                continue
            free = [g for g in groups if all(self.joint[k] != j for k in g)]
            if free:
                free[0].append(i)
            else:
                groups.append([i])
        self.groups = groups
        self.moved = [
            tuple(perturbed(robot, {names[i]: s * self.step[i] for i in g}) for s in (1.0, -1.0))
            for g in groups
        ]
        self.rotor = [
            np.array(
                [
                    sum(self.step[i] for i in g if self.joint[i] == j and "rotor" in names[i])
                    for j in range(robot.n)
                ]
            )
            for g in groups
        ]

    def columns(self, state: DriveState, temperature: Array | None = None) -> Array:
        """The chunk's gradient integrands (N, 2p): ``dW_j(i)/dtheta_i`` then the same where
        the bus draws (``sum_j W_j > 0``), W per parameter unit."""
        out = np.zeros((state.wm.shape[0], 2 * self.p))
        drawing = state.power.sum(axis=1) > 0.0
        for g, moved, rotor in zip(self.groups, self.moved, self.rotor, strict=True):
            powers = []
            for robot, sign in zip(moved, (1.0, -1.0), strict=True):
                tau_load = state.tau_load + sign * rotor * state.dwm
                tau_f = friction_torques(robot, state.wm, tau_load, state.dwm, temperature)
                powers.append(electrical_power(robot, tau_load + tau_f, state.wm))
            for i in g:
                j = self.joint[i]
                d = (powers[0][:, j] - powers[1][:, j]) / (2.0 * self.step[i])
                out[:, i] = d
                out[:, self.p + i] = np.where(drawing, d, 0.0)
        return out


@dataclass(frozen=True, eq=False)
class EnergyIntervals:
    """The 95 % intervals of a report's figures and the gradients they came from.

    Attributes
    ----------
    drawn, motors : Interval
        What the arm draws from its supply, and the motors' part of it, J.
    e_elec : tuple of Interval, length n
        Each joint's electrical energy, J.
    gradients : dict of str to ndarray, shape (p,)
        ``drawn`` and ``motors``: dE/dtheta over ``uncertainty.parameters`` (for a difference
        of two figures from the same model: :func:`difference`).
    uncertainty : Uncertainty
    """

    drawn: Interval
    motors: Interval
    e_elec: tuple[Interval, ...]
    gradients: dict[str, Array]
    uncertainty: Uncertainty

    @classmethod
    def of(
        cls,
        uncertainty: Uncertainty,
        sums: Array,
        duration: float,
        values: tuple[float, float, Array],
    ) -> EnergyIntervals:
        """From the integrated gradient columns ``sums`` (2p,) of :meth:`Sensitivity.columns`,
        the duration (s) and the figures ``(drawn, motors, e_elec)``."""
        names = uncertainty.parameters
        p = len(names)
        motors = sums[p:].copy()
        drawn = motors.copy()
        if "standby_power" in names:
            drawn[names.index("standby_power")] += duration
        drawn_value, motors_value, e_elec = values
        per_joint = []
        for j, value in enumerate(e_elec):
            g = np.array([sums[i] if _joint(n) == j else 0.0 for i, n in enumerate(names)])
            per_joint.append(interval(uncertainty, float(value), g))
        out = cls(
            drawn=interval(uncertainty, drawn_value, drawn),  # type: ignore[arg-type]
            motors=interval(uncertainty, motors_value, motors),  # type: ignore[arg-type]
            e_elec=tuple(per_joint),  # type: ignore[arg-type]
            gradients={"drawn": drawn, "motors": motors},
            uncertainty=uncertainty,
        )
        return out

    def difference(self, other: EnergyIntervals, value: float, figure: str = "drawn") -> Interval:
        """The interval of ``value`` = this figure minus ``other``'s (the same model's, on another
        motion): the gradients' difference, so that errors both share cancel."""
        g = self.gradients[figure] - other.gradients[figure]
        out = interval(self.uncertainty, value, g)
        assert out is not None
        return out

    def to_dict(self) -> dict[str, Any]:
        """``intervals`` of the ``energy --json``."""
        return {
            "level": self.drawn.level,
            "method": self.drawn.method,
            "drawn": interval_dict(self.drawn),
            "motors": interval_dict(self.motors),
            "e_elec": [interval_dict(i) for i in self.e_elec],
        }


def interval_dict(i: Interval) -> dict[str, float]:
    """An interval's ``{"low", "high", "std"}`` (J or the figure's units)."""
    return {"low": i.low, "high": i.high, "std": i.std}
