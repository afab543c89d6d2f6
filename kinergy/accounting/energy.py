"""Energy accounting of a motion: where each joule drawn by the motors goes.

Per joint j (UR5e section 5):

- mechanical power ``P_mech = tau_m wm`` and energy ``E_mech = int P_mech dt`` (eq 25),
- electrical power ``W_elec = tau_m^2 / k_m^2 + (k_b / k_t) wm tau_m`` and ``E_elec = int W_elec dt``
  (eqs 23, 26),
- efficiency ``eta = E_mech / E_elec`` (eq 24), mean and peak electrical power.

The electrical energy splits exactly into four parts (framework Fig. 4): the motor torque is
``tau_m = tau_inertial + tau_gravity + tau_friction`` (motor side; inertial includes the
Coriolis/centrifugal terms and the rotor inertia), and ``W_elec`` is the copper loss
``tau_m^2 / k_m^2`` plus ``(k_b / k_t) wm tau_m``, linear in the torque, so::

    E_elec = E_inertial + E_gravity + E_friction + E_copper

where each motion part includes its share of the non-copper motor losses (the ``k_b / k_t`` factor).
Integrals run over each stretch of unbroken sampling (:mod:`kinergy.io.segments`), never
across a gap in the time stamps. They are signed by default, as in the seed: braking energy
returns to the DC bus and is counted negative. ``recovery=False`` clips negative power: per
joint for the joint figures, and on the summed bus power for the total (joints braking can still
feed joints driving; the supply takes nothing back).

What the arm draws from its supply -- the answer to "how much did it cost" -- is the report's
``supply`` (:mod:`kinergy.accounting.supply`): the joints' powers shared on the DC bus, the
surplus burnt in the shunt, plus the arm's standing draw (``drawn = motors + standby``). Where
a log measured its supply, ``measured`` holds that figure beside it.

One accounting serves every motion: :class:`EnergyAccumulator` folds chunks of a motion into
running sums (every integral is a column of one matrix of integrands, integrated by the trapezoid
rule; the last sample of a chunk is carried into the next, never across a segment boundary), so
a long log is accounted in one pass in memory bounded by the chunk; :func:`energy` of a motion
held in memory is the same fold over one chunk, and keeps the time series too.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from kinergy.accounting.figures import EnergyFigures
from kinergy.accounting.supply import MeasuredSupply, SupplyEnergy
from kinergy.accounting.uncertainty import EnergyIntervals, Sensitivity
from kinergy.arrays import Array
from kinergy.drives.bus import supply_power
from kinergy.drives.transmission import transmission_matrix
from kinergy.errors import KinergyError
from kinergy.io.segments import segment_bounds
from kinergy.model.robot import Robot
from kinergy.predict import DriveState, drive_state
from kinergy.trajectory.motion import Motion

__all__ = ["BREAKDOWN", "EnergyAccumulator", "EnergyReport", "energy", "part_powers"]


BREAKDOWN = ("inertial", "gravity", "friction", "copper")


@dataclass(frozen=True, eq=False, kw_only=True)
class EnergyReport(EnergyFigures):
    """:class:`~kinergy.accounting.figures.EnergyFigures` of one motion held in memory, with its
    time series.

    Attributes
    ----------
    t : ndarray, shape (N,)
        s.
    p_mech, p_elec : ndarray, shape (N, n)
        Mechanical and electrical power per motor, W (clipped at 0 when ``recovery`` is False).
    part_power : dict of str to ndarray, shape (N, n)
        The electrical power of each part over time, W (framework Fig. 4).
    drive : DriveState
        The drive model's torques, currents, voltages over the motion.
    """

    t: Array
    p_mech: Array
    p_elec: Array
    part_power: dict[str, Array]
    drive: DriveState = field(repr=False)

    def figures(self) -> EnergyFigures:
        """The report's figures without its time series (what ``energy`` prints)."""
        names = EnergyFigures.__dataclass_fields__
        return EnergyFigures(**{k: getattr(self, k) for k in names})


def part_powers(robot: Robot, state: DriveState) -> dict[str, Array]:
    """The electrical power of each part of the motor torque (framework Fig. 4), W, each
    (N, n): ``inertial``, ``gravity``, ``friction`` (motor side, each with its ``k_b / k_t``
    share) and ``copper`` (``W_elec`` minus those three); they add up to ``state.power``."""
    n_mat = transmission_matrix(robot)
    tau_gravity_m = np.linalg.solve(n_mat.T, state.tau_gravity.T).T
    tau_inertial_m = state.tau_load - tau_gravity_m
    kt_over_kb = np.array([j.drive.kt_over_kb for j in robot.joints])
    return {
        "inertial": state.wm * tau_inertial_m / kt_over_kb,
        "gravity": state.wm * tau_gravity_m / kt_over_kb,
        "friction": state.wm * state.tau_friction / kt_over_kb,
        "copper": state.power - state.wm * state.tau_m / kt_over_kb,
    }


def trapezoid_weights(t: Array) -> Array:
    """The trapezoid rule as weights, (N,): ``w @ y`` is the integral of samples ``y`` (N, ...)
    at times ``t`` (s, (N,)) over ``[t[0], t[-1]]``: ``w_i = (t[i+1] - t[i-1]) / 2``, half a
    step at either end; zero for a single sample. (The accumulator sums ``w[:, None] * y``
    rather than calling BLAS: a threaded BLAS's workers spin after each call, taking the cores
    the log's reader needs.)"""
    w = np.zeros(t.size)
    if t.size > 1:
        dt = 0.5 * np.diff(t)
        w[:-1] += dt
        w[1:] += dt
    return w


class EnergyAccumulator:
    """Running sums of an energy report over consecutive chunks of one motion.

    Parameters
    ----------
    robot : Robot
    recovery : bool
        As :func:`energy`.

    Examples
    --------
    ``acc.add(t, drive_state(robot, q, qd, qdd), starts=[0])`` per chunk, then
    ``acc.figures()``.
    """

    def __init__(self, robot: Robot, *, recovery: bool = True, intervals: bool = True) -> None:
        self.robot = robot
        self.recovery = recovery
        self.sensitivity = (
            Sensitivity(robot) if intervals and robot.uncertainty is not None else None
        )
        self.gradient: Array | None = None  # the sensitivities' integrals (2p,)
        self.last_rows: Array | None = None  # the previous sample's sensitivities
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
        temperature: Array | None = None,
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
        temperature : ndarray, shape (N, n), optional
            The joint temperatures the drive state was computed at (deg C), for the intervals'
            gradients (:mod:`kinergy.accounting.uncertainty`).
        """
        y = self._integrands(state, measured_power)
        if self.sums is None:
            self.sums = np.zeros(y.shape[1])
            self.first_t = float(t[0])
            starts = sorted({0, *starts})
        elif y.shape[1] != self.sums.size:
            raise KinergyError("measured supply columns in some chunks of a log only")
        cuts = sorted(starts)
        rows = None if self.sensitivity is None else self.sensitivity.rows(state, temperature)
        if self.last is not None and (not cuts or cuts[0] != 0):
            t0, y0 = self.last  # the previous chunk's segment goes on: the step between them
            self.sums += 0.5 * (t[0] - t0) * (y0 + y[0])
            self.duration += float(t[0] - t0)
            if rows is not None and self.last_rows is not None:
                self._gradient(0.5 * (t[0] - t0) * (self.last_rows + rows[:, 0]))
        edges = [0, *(c for c in cuts if c > 0), t.size]
        for a, b in itertools.pairwise(edges):
            weights = trapezoid_weights(t[a:b])
            self.sums += np.sum(weights[:, None] * y[a:b], axis=0)
            self.duration += float(t[b - 1] - t[a])
            if rows is not None:
                self._gradient(rows[:, a:b] @ weights)
        self.last_rows = None if rows is None else rows[:, -1].copy()
        self.segments += len(starts)
        self.samples += t.size
        self.last = (float(t[-1]), y[-1].copy())
        self.current_sq += np.sum(state.current**2, axis=0)
        self.peak_current = np.maximum(self.peak_current, np.abs(state.current).max(axis=0))

    def _gradient(self, add: Array) -> None:
        self.gradient = add if self.gradient is None else self.gradient + add

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
            standby_power=self.robot.standby_power,
        )
        meas = None
        if measured:
            used = float(s[6 * n + 4])
            meas = MeasuredSupply(used, used / d if d else float("nan"), self.measured_peak)
        intervals = None
        if self.sensitivity is not None and self.gradient is not None:
            values = (drawn, motors, s[n : 2 * n])
            intervals = EnergyIntervals.of(self.sensitivity.uncertainty, self.gradient, d, values)
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
            intervals=intervals,
        )


def energy(
    robot: Robot,
    motion: Motion,
    *,
    recovery: bool = True,
    temperature: Array | None = None,
    state: DriveState | None = None,
) -> EnergyReport:
    """Per-joint and total mechanical and electrical energy of ``motion`` (UR5e eqs 23-26): the
    accumulation of :class:`EnergyAccumulator` over the motion as one chunk, with the time series.

    Parameters
    ----------
    robot : Robot
        The model (link data, payload, drives, friction, motor constants, standby power).
    motion : Motion
        Joint angles, speeds and accelerations over time; a step longer than five sample periods
        is a gap, never integrated across (:func:`kinergy.io.segments.segment_bounds`).
    recovery : bool
        True (default, as the seed): signed integrals, braking energy returns to the bus.
        False: negative power is clipped (see the module docstring).
    temperature : ndarray, shape (N, n), optional
        Joint temperatures over the motion, deg C (a log's ``joint_temperatures``), for
        temperature-dependent friction.
    state : DriveState, optional
        The drives along ``motion`` when computed otherwise (say, each sample with the load a
        program's ``set_payload`` gives it); default :func:`kinergy.predict.drive_state`.

    Returns
    -------
    EnergyReport
    """
    if state is None:
        state = drive_state(robot, motion.q, motion.qd, motion.qdd, temperature=temperature)
    acc = EnergyAccumulator(robot, recovery=recovery)
    starts = [a for a, _ in segment_bounds(motion.t)]
    acc.add(motion.t, state, starts=starts, temperature=temperature)
    figures = acc.figures()
    p_mech, p_elec = state.p_mech, state.power
    if not recovery:
        p_mech, p_elec = np.maximum(p_mech, 0.0), np.maximum(p_elec, 0.0)
    return EnergyReport(
        **{k: getattr(figures, k) for k in EnergyFigures.__dataclass_fields__},
        t=motion.t,
        p_mech=p_mech,
        p_elec=p_elec,
        part_power=part_powers(robot, state),
        drive=state,
    )
