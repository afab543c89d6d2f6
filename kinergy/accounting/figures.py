"""The figures of an energy report: what ``energy`` prints and its ``--json`` holds.

What :class:`kinergy.accounting.energy.EnergyAccumulator` gives of a motion, however long (a
motion held in memory adds its time series: :class:`kinergy.accounting.energy.EnergyReport`).
Only scalars and per-joint vectors.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from kinergy.accounting.supply import MeasuredSupply, SupplyEnergy
from kinergy.accounting.uncertainty import NO_UNCERTAINTY, EnergyIntervals
from kinergy.arrays import Array
from kinergy.jsonable import to_jsonable

__all__ = ["EnergyFigures"]


@dataclass(frozen=True, eq=False)
class EnergyFigures:
    """Energy figures of one motion on one robot, J, W, A, s.

    Attributes
    ----------
    robot : str
    joints : list of str
    duration : float
        Seconds sampled: the sum of the segments' durations (gaps left out), s.
    span : float
        Last time stamp minus the first, s (``span - duration`` is the gaps' total).
    samples, segments : int
    recovery : bool
    e_mech, e_elec : ndarray, shape (n,)
        Per joint (UR5e eqs 25, 26; clipped at 0 without ``recovery``).
    breakdown : dict of str to ndarray, shape (n,)
        ``inertial``, ``gravity``, ``friction``, ``copper`` parts of ``e_elec`` (signed).
    peak_power : ndarray, shape (n,)
        Peak electrical power per joint, W.
    bus_peak : float
        Peak of the summed electrical power, W.
    rms_current, peak_current : ndarray, shape (n,)
        A.
    standby, total_e_mech, total_e_elec : float
        J.
    supply : SupplyEnergy
    measured : MeasuredSupply or None
    intervals : EnergyIntervals or None
        95 % intervals of ``supply.drawn``, ``supply.motors`` and each ``e_elec`` from the model's
        parameter errors (None: the model carries none, :mod:`kinergy.accounting.uncertainty`).
    """

    robot: str
    joints: list[str]
    duration: float
    span: float
    samples: int
    segments: int
    recovery: bool
    e_mech: Array
    e_elec: Array
    breakdown: dict[str, Array]
    peak_power: Array
    bus_peak: float
    rms_current: Array
    peak_current: Array
    standby: float
    total_e_mech: float
    total_e_elec: float
    supply: SupplyEnergy
    measured: MeasuredSupply | None = None
    intervals: EnergyIntervals | None = None

    @property
    def efficiency(self) -> Array:
        """Per joint ``E_mech / E_elec`` (UR5e eq 24); NaN where ``E_elec`` is 0."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.e_elec != 0.0, self.e_mech / self.e_elec, np.nan)

    @property
    def total_efficiency(self) -> float:
        """``sum E_mech / sum E_elec`` over the joints (standby excluded), the seed's eta."""
        return float(self.total_e_mech / self.total_e_elec) if self.total_e_elec else float("nan")

    def _joint(self, i: int) -> dict[str, Any]:
        eff = self.efficiency[i]
        return {
            "name": self.joints[i],
            "e_mech": float(self.e_mech[i]),
            "e_elec": float(self.e_elec[i]),
            "efficiency": None if np.isnan(eff) else float(eff),
            "mean_power": float(self.e_elec[i] / self.duration) if self.duration else None,
            "peak_power": float(self.peak_power[i]),
            "breakdown": {k: float(v[i]) for k, v in self.breakdown.items()},
            "rms_current": float(self.rms_current[i]),
            "peak_current": float(self.peak_current[i]),
        }

    def to_dict(self) -> dict[str, Any]:
        """The ``energy --json`` shape (its documented keys and more); ``segments`` and
        ``gaps`` (s not integrated) only when the log had gaps."""
        total_elec = self.total_e_elec + self.standby
        split = (
            {"segments": self.segments, "gaps": self.span - self.duration}
            if self.segments > 1
            else {}
        )
        return {
            "robot": self.robot,
            "duration": self.duration,
            "samples": self.samples,
            **split,
            "recovery": self.recovery,
            "joints": [self._joint(i) for i in range(len(self.joints))],
            "total": {
                "e_mech": self.total_e_mech,
                "e_elec": self.total_e_elec,
                "efficiency": self.total_efficiency,
                "standby": self.standby,
                "e_elec_with_standby": total_elec,
                "mean_power": total_elec / self.duration if self.duration else None,
                "peak_power": self.bus_peak,
                "breakdown": {k: float(v.sum()) for k, v in self.breakdown.items()},
            },
            "supply": to_jsonable(self.supply),
            **({"measured": self.measured_dict()} if self.measured is not None else {}),
            "intervals": (
                self.intervals.to_dict() if self.intervals is not None else {"note": NO_UNCERTAINTY}
            ),
        }

    def measured_dict(self) -> dict[str, Any]:
        """The ``measured`` object of the JSON: the log's supply energy and the predicted one's
        error against it (%)."""
        assert self.measured is not None
        out = to_jsonable(self.measured)
        if self.measured.drawn:
            out["error"] = 100.0 * (self.supply.drawn / self.measured.drawn - 1.0)
        return dict(out)
