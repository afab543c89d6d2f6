"""What an identification returns, and the model's predictions on a log."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from kinergy.drives.transmission import joint_torque
from kinergy.identify.metrics import fit_metrics
from kinergy.identify.preprocess import IdentData
from kinergy.model.robot import Robot
from kinergy.predict import drive_state

__all__ = ["IdentificationResult", "Prediction", "predict", "validation_metrics"]

Array = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class IdentificationResult:
    """An identified model with what the fit says about it.

    Attributes
    ----------
    robot : Robot
        The identified model (the input model with the identified parameters replaced).
    method : str
    joints : list of dict
        Per joint: ``rotor_inertia``, ``motor_inertia``, ``torque_constant`` (motor side),
        ``friction`` ({model, parameters}) and, where estimated, their standard deviations.
    fit : dict
        Fit statistics on the identification logs (``torque``, ``current`` metrics per joint,
        condition numbers, the lag found, the number of samples) and ``warnings``.
    """

    robot: Robot
    method: str
    joints: list[dict[str, Any]]
    fit: dict[str, Any] = field(default_factory=dict)

    @property
    def warnings(self) -> list[str]:
        return list(self.fit.get("warnings", []))

    def to_dict(self) -> dict[str, Any]:
        """The ``identify --json`` shape of DESIGN.md."""
        return {
            "robot": self.robot.name,
            "method": self.method,
            "joints": self.joints,
            "fit": self.fit,
        }


@dataclass(frozen=True, eq=False)
class Prediction:
    """A model's predictions on one log, each (N, n) or None when the log cannot be compared.

    ``torque`` is the controller's reference torque (UR5e eq 7, against ``target_moment``),
    ``current`` the motor current (eq 17, against ``actual_current``), ``joint_torque`` the torque
    at the joints with friction (against measured joint torques).
    """

    torque: Array | None
    current: Array | None
    joint_torque: Array | None


def predict(robot: Robot, data: IdentData) -> Prediction:
    """Predict what ``data``'s log recorded: reference torques on the commanded motion, currents
    and joint torques on the real motion."""
    torque = None
    if data.tau_ref is not None:
        torque = drive_state(robot, data.q_cmd, data.qd_cmd, data.qdd_cmd).tau_sim
    current = joint = None
    if data.current is not None or data.torque is not None:
        state = drive_state(robot, data.q, data.qd, data.qdd)
        current = state.current if data.current is not None else None
        joint = joint_torque(robot, state.tau_m) if data.torque is not None else None
    return Prediction(torque, current, joint)


def validation_metrics(robot: Robot, datas: list[IdentData]) -> dict[str, Any]:
    """UR5e Tables V and VII over several logs: per joint mean, max, RMS error and R^2 of the
    torque (against ``target_moment``), the current (against ``actual_current``) and, for arms
    with torque sensors, the joint torque; ``None`` where no log has the signal.

    Returns
    -------
    dict
        ``{"torque": [...] | None, "current": [...] | None, "joint_torque": [...] | None}``.
    """
    pairs: dict[str, tuple[list[Array], list[Array]]] = {
        "torque": ([], []),
        "current": ([], []),
        "joint_torque": ([], []),
    }
    for data in datas:
        pred = predict(robot, data)
        for key, measured, predicted in (
            ("torque", data.tau_ref, pred.torque),
            ("current", data.current, pred.current),
            ("joint_torque", data.torque, pred.joint_torque),
        ):
            if measured is not None and predicted is not None:
                pairs[key][0].append(measured)
                pairs[key][1].append(predicted)
    out: dict[str, Any] = {}
    for key, (meas, preds) in pairs.items():
        out[key] = fit_metrics(np.vstack(meas), np.vstack(preds)) if meas else None
    return out
