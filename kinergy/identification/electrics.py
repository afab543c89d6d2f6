"""The motors' electrics from a calibration's voltages, and the arm's standing draw from its
supply.

UR5e eq 19 for each motor, ``V = R I + k_b wm``, is linear in the winding resistance ``R`` and the
back-EMF constant ``k_b``: given the voltage ``V`` (the equivalent DC motor's; a UR joint
calibration's ``U`` is 2/3 of it, :mod:`kinergy.drives.electrics`), the current ``I`` and the
motor speed ``wm``, least squares gives both (:func:`fit_electrics`; ``kinergy robot
import-calibration``). :func:`with_electrics` writes them into a model: ``winding_resistance =
R``, ``kt_over_kb = k_t / k_b`` and ``motor_constant = k_t / sqrt(R)``. A controller's log has
no motor voltage (its ``actual_joint_voltage`` is the joint's bus voltage), so ``identify``
never fits them.

The arm's supply (``actual_robot_voltage`` x ``actual_robot_current``) is the motors' bus power
plus a constant standing draw (:mod:`kinergy.drives.bus`); with a model that predicts the motors'
power, the mean of the rest is the standing draw (:class:`StandingDrawSums`), its standard error
from the means of :data:`BLOCK_SECONDS` blocks (batch means: the rest is correlated from sample
to sample, so the samples' own scatter would understate it).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from kinergy.errors import KinergyError
from kinergy.linalg import Reduced, scaled_solution
from kinergy.model.robot import Robot

__all__ = [
    "BLOCK_SECONDS",
    "ElectricsFit",
    "ElectricsSums",
    "StandingDraw",
    "StandingDrawSums",
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
) -> ElectricsFit:
    """``R`` and ``k_b`` of one motor by least squares on UR5e eq 19, ``V = R I + k_b wm``.

    Parameters
    ----------
    current, voltage, wm : array_like, shape (k,)
        Current (A), the equivalent DC motor's voltage (V, signed) and motor speed (rad/s).
    weights : array_like, shape (k,), optional
        Least-squares weights (``1 / |V|`` fits every point to the same relative accuracy).

    Raises
    ------
    KinergyError
        Fewer than 3 points, or points that cannot separate ``R`` from ``k_b`` (the current and
        the speed proportional to each other, or one of them zero throughout).
    """
    sums = ElectricsSums()
    sums.add(current, voltage, wm, weights=weights)
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
    triangle of its weighted rows (and of its rows as they are, for the RMS, when weighted)."""

    problem: Reduced = field(default_factory=lambda: Reduced.empty(2))
    plain: Reduced | None = None

    def add(
        self,
        current: ArrayLike,
        voltage: ArrayLike,
        wm: ArrayLike,
        *,
        weights: ArrayLike | None = None,
    ) -> None:
        """Fold in a block of samples, each (k,): A, V, rad/s and the weights, as
        :func:`fit_electrics` takes them."""
        i, v, w = (np.asarray(x, dtype=float).ravel() for x in (current, voltage, wm))
        a = np.column_stack([i, w])
        wt = np.ones(i.size) if weights is None else np.asarray(weights, dtype=float).ravel()
        self.problem = self.problem.stack(a * wt[:, None], v * wt)
        if weights is not None:
            self.plain = (self.plain or Reduced.empty(2)).stack(a, v)

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


#: s: the length of the blocks whose means give the standing draw's standard error
BLOCK_SECONDS = 2.0


@dataclass(frozen=True)
class StandingDraw:
    """The arm's standing draw found from a measured supply: ``power`` (W), its standard error
    ``std`` (W, batch means of :data:`BLOCK_SECONDS` blocks; NaN from fewer than 2 blocks), over
    ``samples`` samples in ``blocks`` blocks, and what it includes."""

    power: float
    std: float
    samples: int
    blocks: int
    includes: str = (
        "actual_robot_voltage x actual_robot_current less the motors' predicted draw (UR5e eq 23 "
        "summed on the bus), averaged: the arm's electronics with the brakes released, and "
        "whatever the model leaves out of the motors (a tool's draw too)"
    )


@dataclass
class StandingDrawSums:
    """:class:`StandingDraw` folded chunk by chunk: per block of :data:`BLOCK_SECONDS` of each
    log (segment), the sum and count of the supply power less the motors' draw."""

    blocks: dict[tuple[int, int], list[float]] = field(default_factory=dict)
    origin: dict[int, float] = field(default_factory=dict)

    def add(self, segment: int, t: ArrayLike, rest: ArrayLike) -> None:
        """Fold in samples of log ``segment`` at times ``t`` (s, (k,)) whose supply power less
        the motors' draw is ``rest`` (W, (k,))."""
        t, rest = np.asarray(t, dtype=float), np.asarray(rest, dtype=float)
        if t.size == 0:
            return
        start = self.origin.setdefault(segment, float(t[0]))
        index = np.floor((t - start) / BLOCK_SECONDS).astype(int)
        for b in np.unique(index):
            inside = rest[index == b]
            acc = self.blocks.setdefault((segment, int(b)), [0.0, 0.0])
            acc[0] += float(inside.sum())
            acc[1] += inside.size

    def fit(self) -> StandingDraw:
        """The mean over every sample and its batch-means standard error:
        ``sqrt(B / (B - 1) sum_b n_b^2 (m_b - m)^2) / N`` for blocks ``b`` of ``n_b`` samples
        with mean ``m_b``, ``N = sum n_b``.

        Raises
        ------
        KinergyError
            No samples.
        """
        sums = np.array(list(self.blocks.values())).reshape(-1, 2)
        total = float(sums[:, 1].sum())
        if total == 0:
            raise KinergyError("no samples of the supply to find the standing draw from")
        mean = float(sums[:, 0].sum()) / total
        k = len(sums)
        std = float("nan")
        if k > 1:
            dev = sums[:, 0] - sums[:, 1] * mean  # n_b (m_b - m)
            std = float(np.sqrt(k / (k - 1) * np.sum(dev**2)) / total)
        return StandingDraw(mean, std, int(total), k)
