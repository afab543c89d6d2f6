"""95 % intervals on the energy figures, from the model's parameter errors.

An energy figure ``E`` (a joint's electrical energy, the motors' draw on the supply, what the arm
draws) is an integral over the motion of powers that depend on the model's identified
parameters ``theta`` (:mod:`kinergy.model.uncertainty`). Its gradient is the integral of the
powers' gradients, taken sample by sample in the same fold as the figures (same trapezoid
weights, same segments, one pass, memory bounded by the chunk)::

    dE_elec,j / dtheta_i = int dW_j/dtheta_i dt                        (theta_i a joint-j parameter)
    dE_motors / dtheta_i = int 1[sum_j W_j > 0] dW_j/dtheta_i dt         (the bus: UR5e eq 23 summed)
    dE_drawn / dtheta_i  = dE_motors / dtheta_i  (+ duration for standby_power)

``dW_j/dtheta_i`` analytic (:class:`Sensitivity`): the link torques do not depend on ``theta``,
so a chunk costs one evaluation of each joint's friction columns and a few products, never the
rigid-body dynamics. The interval is then the delta method's (``|D g|``, Student's t).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from kinergy.arrays import Array
from kinergy.drives.electrics import motor_constants
from kinergy.model.robot import Robot
from kinergy.model.uncertainty import Interval, Uncertainty, interval
from kinergy.predict import DriveState

__all__ = ["NO_UNCERTAINTY", "EnergyIntervals", "Sensitivity", "interval_dict"]

#: what a figure says instead of an interval when its model carries no uncertainty
NO_UNCERTAINTY = (
    "the model carries no parameter errors (a built-in or data-sheet model): no interval; "
    "identify a model from logs for one"
)


def _joint(name: str) -> int | None:
    return int(name[7 : name.index("]")]) if name.startswith("joints[") else None


class Sensitivity:
    """The per-sample gradients of the joints' powers over ``robot.uncertainty``'s parameters
    (module docstring), analytic: with ``h = dW/dtau_m = 2 tau_m / k_m^2 + wm / (k_t/k_b)``,
    a rotor inertia's is ``h dwm`` (the load torque moves by ``dJ dwm``; a friction that
    depends on the load is taken at the nominal load), a friction level's ``h`` times its
    regressor column (the friction is linear in its levels), a torque constant's
    ``-2 R tau_m^2 / k_t^3`` where the drive gives its winding resistance (else the power does
    not depend on it: ``R = (k_t / k_m)^2``).

    Parameters
    ----------
    robot : Robot
        With ``uncertainty`` set.
    """

    def __init__(self, robot: Robot) -> None:
        assert robot.uncertainty is not None
        self.robot = robot
        self.uncertainty = robot.uncertainty
        names = self.uncertainty.parameters
        self.p = len(names)
        # per joint: (parameter index, what: -1 rotor inertia, -2 torque constant, else the
        # friction level's column)
        self.by_joint: dict[int, list[tuple[int, int]]] = {}
        for i, name in enumerate(names):
            j = _joint(name)
            if j is None:
                continue
            what = name.split(".", 1)[1]
            linear = robot.joints[j].drive.friction.model.linear
            code = {"rotor_inertia": -1, "torque_constant": -2}.get(what)
            if code is None:
                code = linear.index(what.removeprefix("friction."))
            self.by_joint.setdefault(j, []).append((i, code))
        self.km2 = motor_constants(robot) ** 2
        self.kt_over_kb = np.array([joint.drive.kt_over_kb for joint in robot.joints])

    def rows(self, state: DriveState, temperature: Array | None = None) -> Array:
        """The chunk's gradient integrands (2p, N), one row per parameter: ``dW_j(i)/dtheta_i``,
        then the same where the bus draws (``sum_j W_j > 0``), W per parameter unit."""
        n_samples = state.wm.shape[0]
        out = np.zeros((2 * self.p, n_samples))
        h = (2.0 * state.tau_m / self.km2 + state.wm / self.kt_over_kb).T.copy()  # (n, N)
        dwm, tau_m = state.dwm.T, state.tau_m.T
        for j, params in self.by_joint.items():
            drive = self.robot.joints[j].drive
            friction = drive.friction
            cols = None
            for i, code in params:
                if code == -1:  # rotor inertia
                    np.multiply(h[j], dwm[j], out=out[i])
                elif code == -2:  # torque constant
                    if drive.winding_resistance is not None:
                        kt = drive.torque_constant
                        out[i] = -2.0 * drive.winding_resistance * tau_m[j] ** 2 / kt**3
                else:
                    if cols is None:
                        temp = None if temperature is None else temperature[:, j]
                        cols = friction.model.friction_columns(
                            friction.params,
                            state.wm[:, j],
                            state.tau_load[:, j],
                            state.dwm[:, j],
                            temperature=temp,
                        ).T.copy()
                    np.multiply(h[j], cols[code], out=out[i])
        drawing = state.power.sum(axis=1) > 0.0
        np.multiply(out[: self.p], drawing, out=out[self.p :])
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
        """From the integrated gradient rows ``sums`` (2p,) of :meth:`Sensitivity.rows`,
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
