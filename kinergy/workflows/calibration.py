"""``kinergy robot import-calibration``: a robot file from a UR joint calibration summary.

For every joint of the summary (:mod:`kinergy.io.ur_calibration`):

1. the torque constant is its ``K_tau``;
2. the friction model is fitted to its friction points (speeds turned motor side with the
   robot's gear ratio: ``wm = gear_ratio * speed``; ``Tau`` is motor side already), by default
   the model that cross-validates best (leave one point out) among
   :data:`CALIBRATION_CANDIDATES`, every point weighted to the same relative accuracy
   (:mod:`kinergy.identification.friction_curve`); Coulomb + viscous is fitted beside it, for contrast;
3. the motor's winding resistance and back-EMF constant by least squares on UR5e eq 19 from its
   ``U``, ``I`` and motor speed, ``U`` read as the controller's dq voltage (the equivalent DC
   motor's voltage is ``1.5 U``, :mod:`kinergy.drives.electrics`).

The result is ``ROBOT`` with these drives, their provenance ``calibration``; link data, gear
ratios, inertias and limits stay the robot's.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from kinergy.drives.electrics import controller_voltage, equivalent_voltage
from kinergy.errors import KinergyError
from kinergy.friction.model import FrictionModel
from kinergy.friction.registry import MODELS
from kinergy.identification.electrics import ElectricsFit, fit_electrics, with_electrics
from kinergy.identification.friction_curve import (
    CurveFit,
    FrictionPoints,
    choose_model,
    fit_curve,
    points_from,
)
from kinergy.identification.options import AUTO, FrictionSearch
from kinergy.io.ur_calibration import JointCalibration, read_ur_calibration
from kinergy.jsonable import to_jsonable
from kinergy.model.library import library_names, load_robot
from kinergy.model.robot import Friction, Robot, Source
from kinergy.model.toml import save_robot

__all__ = [
    "CALIBRATION_CANDIDATES",
    "CalibrationImport",
    "CalibrationJoint",
    "CalibrationPoint",
    "import_calibration",
]


#: models ``--friction auto`` chooses from: those a calibration's points (no load torque, a few
#: kelvin of temperature spread) can fit
CALIBRATION_CANDIDATES = tuple(
    MODELS[name] for name in ("viscous_coulomb", "power_law", "directional_power_law", "stribeck")
)
#: the model shown beside the chosen one, for contrast
CONTRAST = MODELS["viscous_coulomb"]
#: points are weighted by 1 / max(|tau|, this), N m: the same relative accuracy at every speed
WEIGHT_FLOOR = 1e-3


@dataclass(frozen=True)
class CalibrationPoint:
    """One speed point: the joint speed (rad/s), the measured friction (N m, motor side), the
    chosen model's and the Coulomb + viscous contrast's, and the measured and modelled ``U``
    (V, the controller's dq voltage, as the file writes it)."""

    speed: float
    friction: float
    friction_model: float
    friction_contrast: float
    voltage: float
    voltage_model: float


@dataclass(frozen=True)
class CalibrationJoint:
    """One joint's import: the torque constant, the fitted friction (and every candidate tried,
    with its cross-validated RMS), the contrast fit, the electrics (equivalent DC motor) and the
    points with the models' values."""

    name: str
    torque_constant: float
    friction: CurveFit
    candidates: tuple[CurveFit, ...]
    contrast: CurveFit
    electrics: ElectricsFit
    kt_over_kb: float
    points: tuple[CalibrationPoint, ...]


@dataclass(frozen=True, eq=False)
class CalibrationImport:
    """A calibration import: the robot written, the file read and each joint's fit."""

    robot: Robot = field(metadata={"json": lambda r: r.name})
    file: str
    joints: tuple[CalibrationJoint, ...]

    def to_dict(self) -> dict[str, Any]:
        """``kinergy robot import-calibration --json`` (without where the command came from)."""
        out: dict[str, Any] = to_jsonable(self)
        return out


def _points(robot: Robot, j: int, cal: JointCalibration) -> FrictionPoints:
    wm = robot.joints[j].drive.gear_ratio * cal.speed
    return points_from(
        wm, cal.friction, temperature=cal.point_temperature, tolerance=(1.0, WEIGHT_FLOOR)
    )


def _electrics(robot: Robot, j: int, cal: JointCalibration) -> ElectricsFit:
    wm = robot.joints[j].drive.gear_ratio * cal.speed
    signed = equivalent_voltage(np.sign(cal.speed) * cal.voltage)
    return fit_electrics(cal.current, signed, wm, weights=1.0 / np.abs(signed))


def _joint(
    robot: Robot, j: int, cal: JointCalibration, friction: FrictionModel | FrictionSearch
) -> CalibrationJoint:
    points = _points(robot, j, cal)
    if isinstance(friction, FrictionModel):
        chosen, tried = choose_model([friction], points)
    else:
        chosen, tried = choose_model(CALIBRATION_CANDIDATES, points)
    contrast = fit_curve(CONTRAST, points)
    electrics = _electrics(robot, j, cal)
    wm = points.wm
    u_model = controller_voltage(electrics.resistance * cal.current + electrics.back_emf * wm)
    rows = tuple(
        CalibrationPoint(float(s), float(t), float(m), float(c), float(u), float(um))
        for s, t, m, c, u, um in zip(
            cal.speed,
            cal.friction,
            chosen.torque(points),
            contrast.torque(points),
            cal.voltage,
            np.abs(u_model),
            strict=True,
        )
    )
    return CalibrationJoint(
        name=robot.joints[j].name,
        torque_constant=cal.torque_constant,
        friction=chosen,
        candidates=tried,
        contrast=contrast,
        electrics=electrics,
        kt_over_kb=cal.torque_constant / electrics.back_emf,
        points=rows,
    )


def _calibrated(robot: Robot, joints: list[CalibrationJoint], ref: str) -> Robot:
    """``robot`` with the imported torque constants, friction and electrics, sources marked."""
    new = []
    for joint, fit in zip(robot.joints, joints, strict=True):
        friction = Friction(fit.friction.model, fit.friction.params)
        drive = dataclasses.replace(
            joint.drive, torque_constant=fit.torque_constant, friction=friction
        )
        new.append(dataclasses.replace(joint, drive=drive))
    staged = with_electrics(robot.with_joints(new), [j.electrics for j in joints])
    sources = dict(robot.sources)
    for cat in ("torque_constant", "friction", "motor_constant"):
        sources[cat] = Source("calibration", ref)
    return dataclasses.replace(staged, sources=sources)


#: a calibrated torque constant more than this factor from the model's is another robot's
KT_FACTOR = 2.0


def _check_robot(robot: Robot, path: str, k_tau: list[float]) -> None:
    """Refuse a calibration whose torque constants are not ``robot``'s (more than
    :data:`KT_FACTOR` from the model's on some joint), naming the joint and the built-in robots
    whose torque constants it matches."""
    model = np.array([j.drive.torque_constant for j in robot.joints])
    ratio = np.asarray(k_tau) / model
    off = np.flatnonzero((ratio > KT_FACTOR) | (ratio < 1.0 / KT_FACTOR))
    if not off.size:
        return
    j = int(off[np.argmax(np.abs(np.log(ratio[off])))])
    fits = []
    for name in library_names():
        other = load_robot(name)
        if other.n == robot.n and name != robot.name:
            r = np.asarray(k_tau) / [jt.drive.torque_constant for jt in other.joints]
            if np.all((r <= 1.25) & (r >= 0.8)):
                fits.append(name)
    hint = f" (it fits {', '.join(fits)})?" if fits else "?"
    raise KinergyError(
        f"{path}: joint {j + 1} ({robot.joint_names[j]}): K_tau {k_tau[j]:.4g} N m/A is "
        f"{ratio[j]:.2g} times {robot.name}'s {model[j]:.4g}: a calibration of another robot"
        f"{hint}"
    )


def import_calibration(
    robot: Robot,
    path: str | os.PathLike[str],
    *,
    friction: FrictionModel | FrictionSearch = AUTO,
    out: str | os.PathLike[str] | None = None,
) -> CalibrationImport:
    """Import a UR joint calibration summary into ``robot`` (module docstring); write the robot
    file to ``out`` when given.

    Raises
    ------
    KinergyError
        A bad calibration file (the line and what was expected), a joint count that differs
        from the robot's, a friction model the points cannot fit.
    """
    cal = read_ur_calibration(path)
    if len(cal.joints) != robot.n:
        raise KinergyError(f"{cal.path}: {len(cal.joints)} joints but {robot.name} has {robot.n}")
    _check_robot(robot, cal.path, [c.torque_constant for c in cal.joints])
    joints = [_joint(robot, j, c, friction) for j, c in enumerate(cal.joints)]
    revision = cal.joints[0].revision
    ref = f"UR joint calibration summary {os.path.basename(cal.path)} (revision {revision})"
    calibrated = _calibrated(robot, joints, ref)
    if out is not None:
        save_robot(
            calibrated,
            out,
            header=f"{robot.name} with drives from the joint calibration {cal.path}",
        )
    return CalibrationImport(calibrated, cal.path, tuple(joints))
