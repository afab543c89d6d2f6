"""The motors' electrics from measured voltages, and the arm's standby power from its supply.

UR5e eq 19 for each motor, ``V = R I + k_b wm``, is linear in the winding resistance ``R`` and the
back-EMF constant ``k_b``: given the voltage ``V`` (the equivalent DC motor's; a UR controller's
logged ``actual_joint_voltage`` and its calibration's ``U`` are 2/3 of it,
:mod:`kinergy.drives.electrics`), the current ``I`` and the motor speed ``wm``, least squares
gives both (:func:`fit_electrics`). :func:`with_electrics` writes them into a model:
``winding_resistance = R``, ``kt_over_kb = k_t / k_b`` and ``motor_constant = k_t / sqrt(R)``.

The arm's supply (``actual_robot_voltage`` x ``actual_robot_current``) is the motors' bus power
plus a constant standby (:mod:`kinergy.drives.bus`); with a model that predicts the motors' power,
the mean of the rest is the standby power (:func:`kinergy.workflows.identify.measured_electrics`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.linalg import Reduced, scaled_solution
from kinergy.model.robot import Robot

__all__ = [
    "ElectricsFit",
    "ElectricsSums",
    "fit_electrics",
    "with_electrics",
]


@dataclass(frozen=True)
class ElectricsFit:
    """One motor's ``R`` (ohm) and ``k_b`` (V s/rad) of the equivalent DC motor, their standard
    errors, and the RMS of the voltage error (V) over ``samples`` points."""

    resistance: float
    back_emf: float
    resistance_std: float
    back_emf_std: float
    rms: float
    samples: int


def fit_electrics(
    current: ArrayLike,
    voltage: ArrayLike,
    wm: ArrayLike,
    *,
    weights: ArrayLike | None = None,
    instrument: ArrayLike | None = None,
) -> ElectricsFit:
    """``R`` and ``k_b`` of one motor by least squares on UR5e eq 19, ``V = R I + k_b wm``.

    Parameters
    ----------
    current, voltage, wm : array_like, shape (k,)
        Current (A), the equivalent DC motor's voltage (V, signed) and motor speed (rad/s).
    weights : array_like, shape (k,), optional
        Least-squares weights (``1 / |V|`` fits every point to the same relative accuracy).
    instrument : array_like, shape (k,), optional
        A noise-free stand-in for the current (a model's predicted current, A), used as the
        instrumental variable of the current column: noise in a logged current biases
        ordinary least squares' ``R`` low (errors in variables; 5 % on a UR wrist with 0.04 A
        of noise), the instrument does not. Points and standard errors as without it.

    Raises
    ------
    KinergyError
        Fewer than 3 points, or points that cannot separate ``R`` from ``k_b`` (the current and
        the speed proportional to each other, or one of them zero throughout).
    """
    sums = ElectricsSums()
    sums.add(current, voltage, wm, weights=weights, instrument=instrument)
    return sums.fit()


def _check_separable(cond: float) -> None:
    """Raise unless eq 19's column-scaled condition number ``cond`` separates ``R`` from ``k_b``."""
    if not np.isfinite(cond) or cond > 1e8:
        raise KinergyError(
            "the voltages cannot separate the winding resistance from the back-EMF constant "
            "(current and speed move together)"
        )


@dataclass
class ElectricsSums:
    """:func:`fit_electrics` of one motor folded block by block: eq 19's least squares in a
    triangle of its weighted rows (and of its rows as they are, for the RMS, when weighted) and,
    with an instrument, the instrumental normal equations ``Z^T W^2 A`` (2, 2) and
    ``Z^T W^2 V`` (2,), ``Z = [instrument, wm]``, ``A = [I, wm]``, ``W`` the weights."""

    problem: Reduced = field(default_factory=lambda: Reduced.empty(2))
    plain: Reduced | None = None
    zta: Array | None = None
    ztv: Array | None = None

    def add(
        self,
        current: ArrayLike,
        voltage: ArrayLike,
        wm: ArrayLike,
        *,
        weights: ArrayLike | None = None,
        instrument: ArrayLike | None = None,
    ) -> None:
        """Fold in a block of samples, each (k,): A, V, rad/s, the weights and the
        instrument (A), as :func:`fit_electrics` takes them."""
        i, v, w = (np.asarray(x, dtype=float).ravel() for x in (current, voltage, wm))
        a = np.column_stack([i, w])
        wt = np.ones(i.size) if weights is None else np.asarray(weights, dtype=float).ravel()
        self.problem = self.problem.stack(a * wt[:, None], v * wt)
        if weights is not None:
            self.plain = (self.plain or Reduced.empty(2)).stack(a, v)
        if instrument is not None:
            z = np.column_stack([np.asarray(instrument, dtype=float).ravel(), w]) * wt[:, None]
            zta, ztv = z.T @ (a * wt[:, None]), z.T @ (v * wt)
            self.zta = zta if self.zta is None else self.zta + zta
            self.ztv = ztv if self.ztv is None else self.ztv + ztv

    def fit(self) -> ElectricsFit:
        """The :class:`ElectricsFit` of every block.

        Raises
        ------
        KinergyError
            As :func:`fit_electrics`.
        """
        samples = self.problem.rows
        if samples < 3:
            raise KinergyError(f"fitting R and k_b needs at least 3 points, got {samples}")
        x, std, cond = scaled_solution(self.problem)
        _check_separable(cond)
        if self.zta is not None and self.ztv is not None:
            x = np.asarray(np.linalg.solve(self.zta, self.ztv), dtype=float)
        rows = self.plain or self.problem
        rms = float(np.sqrt(rows.norm2(np.append(x, -1.0)) / samples))
        return ElectricsFit(float(x[0]), float(x[1]), float(std[0]), float(std[1]), rms, samples)


def with_electrics(robot: Robot, fits: Sequence[ElectricsFit | None]) -> Robot:
    """``robot`` with each fitted motor's ``R`` and ``k_b`` (None: unchanged): its
    ``winding_resistance``, ``kt_over_kb = k_t / k_b`` and ``motor_constant = k_t / sqrt(R)``.

    Raises
    ------
    KinergyError
        A fitted resistance or back-EMF constant that is not positive (naming the joint).
    """
    joints = []
    for joint, fit in zip(robot.joints, fits, strict=True):
        if fit is None:
            joints.append(joint)
            continue
        if fit.resistance <= 0 or fit.back_emf <= 0:
            raise KinergyError(
                f"joint {joint.name}: fitted R = {fit.resistance:.4g} ohm and k_b = "
                f"{fit.back_emf:.4g} V s/rad must both be > 0"
            )
        kt = joint.drive.torque_constant
        drive = dataclasses.replace(
            joint.drive,
            winding_resistance=fit.resistance,
            kt_over_kb=kt / fit.back_emf,
            motor_constant=kt / np.sqrt(fit.resistance),
        )
        joints.append(dataclasses.replace(joint, drive=drive))
    return robot.with_joints(joints)
