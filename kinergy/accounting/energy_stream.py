"""Energy accounting in one pass: the figures of :func:`kinergy.accounting.energy.energy`,
accumulated chunk by chunk so memory is bounded by the chunk, not the motion.

Every integral of the report (per-joint mechanical and electrical energy, the four-way breakdown,
the totals, the supply's motors and shunt, the measured supply) is a column of one matrix of
integrands per chunk, integrated by the same trapezoid rule as the in-memory path; the last
sample of a chunk is carried into the next so the rule runs across chunk boundaries, never across
a segment boundary (:mod:`kinergy.io.segments`). Peaks are running maxima, RMS currents running
sums of squares.
"""

from __future__ import annotations

import itertools

import numpy as np
from scipy.integrate import trapezoid

from kinergy.accounting.energy import BREAKDOWN, part_powers
from kinergy.accounting.figures import EnergyFigures
from kinergy.accounting.supply import MeasuredSupply, SupplyEnergy
from kinergy.arrays import Array
from kinergy.drives.bus import supply_power
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.predict import DriveState

__all__ = ["EnergyAccumulator"]


class EnergyAccumulator:
    """Running sums of an energy report over consecutive chunks of one motion.

    Parameters
    ----------
    robot : Robot
    recovery : bool
        As :func:`kinergy.accounting.energy.energy`.

    Examples
    --------
    ``acc.add(t, drive_state(robot, q, qd, qdd), starts=[0])`` per chunk, then
    ``acc.figures()``.
    """

    def __init__(self, robot: Robot, *, recovery: bool = True) -> None:
        self.robot = robot
        self.recovery = recovery
        n = robot.n
        self._k = 6 * n + 4  # p_mech, p_elec, 4 parts (n each), totals, motors, shunt
        self.sums: Array | None = None
        self.last: tuple[float, Array] | None = None  # the previous sample, for the next chunk
        self.first_t = float("nan")
        self.duration = 0.0
        self.samples = self.segments = 0
        self.peak = np.full(n, -np.inf)
        self.bus_peak = self.supply_peak = self.measured_peak = -np.inf
        self.current_sq = np.zeros(n)
        self.peak_current = np.zeros(n)

    def _integrands(self, state: DriveState, measured: Array | None) -> Array:
        """The chunk's integrands (N, K): every power the report integrates."""
        p_mech, p_elec = state.p_mech, state.power
        parts = part_powers(self.robot, state)
        bus = supply_power(state.power, self.robot.standby_power)
        tot_mech, tot_elec = p_mech.sum(axis=1), p_elec.sum(axis=1)
        if not self.recovery:
            p_mech, p_elec = np.maximum(p_mech, 0.0), np.maximum(p_elec, 0.0)
            tot_mech, tot_elec = np.maximum(tot_mech, 0.0), np.maximum(tot_elec, 0.0)
        self.peak = np.maximum(self.peak, p_elec.max(axis=0))
        self.bus_peak = max(self.bus_peak, float(p_elec.sum(axis=1).max()))
        self.supply_peak = max(self.supply_peak, float(bus.supply.max()))
        cols = [p_mech, p_elec, *(parts[k] for k in BREAKDOWN)]
        cols += [tot_mech[:, None], tot_elec[:, None], bus.motors[:, None], bus.shunt[:, None]]
        if measured is not None:
            self.measured_peak = max(self.measured_peak, float(measured.max()))
            cols.append(measured[:, None])
        return np.hstack(cols)

    def add(
        self,
        t: Array,
        state: DriveState,
        *,
        starts: list[int],
        measured_power: Array | None = None,
    ) -> None:
        """Account the chunk at times ``t`` (s, (N,)) with drive state ``state``.

        Parameters
        ----------
        t : ndarray, shape (N,)
        state : DriveState
            Of the chunk's motion.
        starts : list of int
            Indices into the chunk where a segment begins (``0`` when the chunk does not
            continue the previous one's segment; the first chunk always begins one).
        measured_power : ndarray, shape (N,), optional
            The log's measured supply power (voltage x current), W; in every chunk or none.
        """
        y = self._integrands(state, measured_power)
        if self.sums is None:
            self.sums = np.zeros(y.shape[1])
            self.first_t = float(t[0])
            starts = sorted({0, *starts})
        elif y.shape[1] != self.sums.size:
            raise KinergyError("measured supply columns in some chunks of a log only")
        cuts = sorted(starts)
        tt, yy = t, y
        if self.last is not None and (not cuts or cuts[0] != 0):
            tt = np.concatenate([[self.last[0]], t])  # continue the previous chunk's segment
            yy = np.vstack([self.last[1], y])
            cuts = [c + 1 for c in cuts]
        edges = [0, *(c for c in cuts if c > 0), tt.size]
        for a, b in itertools.pairwise(edges):
            self.sums += trapezoid(yy[a:b], tt[a:b], axis=0)
            self.duration += float(tt[b - 1] - tt[a])
        self.segments += len(starts)
        self.samples += t.size
        self.last = (float(t[-1]), y[-1].copy())
        self.current_sq += np.sum(state.current**2, axis=0)
        self.peak_current = np.maximum(self.peak_current, np.abs(state.current).max(axis=0))

    def figures(self, measured: bool = False) -> EnergyFigures:
        """The figures of everything added (:class:`EnergyFigures`), with the measured supply
        when ``measured`` (chunks added with ``measured_power``)."""
        if self.sums is None:
            raise KinergyError("no samples to account")
        n, s, d = self.robot.n, self.sums, self.duration
        standby = self.robot.standby_power * d
        motors, shunt = float(s[6 * n + 2]), float(s[6 * n + 3])
        drawn = motors + standby
        supply = SupplyEnergy(
            drawn=drawn,
            motors=motors,
            standby=standby,
            shunt=shunt,
            mean_power=drawn / d if d else float("nan"),
            peak_power=self.supply_peak,
        )
        meas = None
        if measured:
            used = float(s[6 * n + 4])
            meas = MeasuredSupply(used, used / d if d else float("nan"), self.measured_peak)
        return EnergyFigures(
            robot=self.robot.name,
            joints=self.robot.joint_names,
            duration=d,
            span=(self.last[0] if self.last else self.first_t) - self.first_t,
            samples=self.samples,
            segments=self.segments,
            recovery=self.recovery,
            e_mech=s[:n].copy(),
            e_elec=s[n : 2 * n].copy(),
            breakdown={k: s[(2 + i) * n : (3 + i) * n].copy() for i, k in enumerate(BREAKDOWN)},
            peak_power=self.peak,
            bus_peak=self.bus_peak,
            rms_current=np.sqrt(self.current_sq / self.samples),
            peak_current=self.peak_current,
            standby=standby,
            total_e_mech=float(s[6 * n]),
            total_e_elec=float(s[6 * n + 1]),
            supply=supply,
            measured=meas,
        )
