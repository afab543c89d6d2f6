"""``kinergy energy``: the energy of a logged or planned motion, beside what the log measured."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from kinergy import checks
from kinergy.accounting.energy import EnergyAccumulator, EnergyReport, energy
from kinergy.accounting.figures import EnergyFigures
from kinergy.accounting.supply import standing_draw_notes
from kinergy.accounting.trace import (
    PowerSeries,
    PowerSink,
    TraceWriter,
    supply_predicted,
    trace_format,
)
from kinergy.accounting.uncertainty import Sensitivity
from kinergy.arrays import Array
from kinergy.files import atomic_open
from kinergy.io.log import Log
from kinergy.io.motion import iter_motion, motion_from_log
from kinergy.io.urscript_reader import read_program
from kinergy.logs.payload import PAYLOAD_SIGNALS, logged_loads
from kinergy.logs.reading import CheckedLog, InputLogs, LogReading
from kinergy.model.robot import Robot
from kinergy.model.uncertainty import t_quantile
from kinergy.predict import DriveState, drive_by_payload, drive_state, payload_robots
from kinergy.trajectory.motion import Motion, MotionSource
from kinergy.trajectory.program_motion import payload_index, program_motion
from kinergy.trajectory.program_path import program_path
from kinergy.trajectory.programs import paper_trajectory
from kinergy.trajectory.robot_program import Move
from kinergy.workflows.twin import check_source, is_builtin

__all__ = [
    "ENERGY_ROWS",
    "EnergyOptions",
    "LogEnergy",
    "SupplyBand",
    "energy_of_log",
    "energy_with_outputs",
    "log_energy_report",
    "program_energy",
    "unused_payload",
]


@dataclass(frozen=True)
class EnergyOptions:
    """How ``kinergy energy`` accounts a log, checked on construction.

    Attributes
    ----------
    source : MotionSource
        Which motion of a log: commanded (``target_*``), measured (``actual_*``), or ``auto``:
        the commanded one where the log has it.
    recovery : bool
        Signed integrals: braking energy returns to the bus (UR5e eqs 25-26); False clips
        negative power.
    """

    source: MotionSource = MotionSource.AUTO
    recovery: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "source", checks.choice(self.source, MotionSource, "--source"))
        object.__setattr__(self, "recovery", bool(self.recovery))


@dataclass(frozen=True, eq=False, kw_only=True)
class LogEnergy(EnergyFigures):
    """The energy of a log or motion file (:class:`~kinergy.accounting.figures.EnergyFigures`)
    and what it was: the log by content with its checks, the notes and warnings of reading it.
    :meth:`to_dict` is ``kinergy energy --json`` (without where the command came from)."""

    inputs: InputLogs = field(default_factory=InputLogs)
    said: tuple[str, ...] = ()  # the result's own warnings (a motion beyond the torque limits)

    @property
    def notes(self) -> list[str]:
        return list(self.inputs.notes)

    @property
    def warnings(self) -> list[str]:
        return [*self.inputs.warnings, *self.said]

    def to_dict(self) -> dict[str, Any]:
        out = super().to_dict()
        out.update(inputs=self.inputs.records(), notes=self.notes, warnings=self.warnings)
        return out


def _with(figures: EnergyFigures, inputs: InputLogs, said: Sequence[str] = ()) -> LogEnergy:
    return LogEnergy(
        **{k: getattr(figures, k) for k in EnergyFigures.__dataclass_fields__},
        inputs=inputs,
        said=tuple(said),
    )


#: samples per chunk of the one-pass energy: 20 s at 500 Hz; the drive state of a chunk holds
#: about 40 arrays of (rows, n), and the reader the checks' columns besides (60-minute log:
#: peak 390 MiB, against 401 MiB at 12,000 rows and 409 MiB at 15,000, within 4 % of their time)
ENERGY_ROWS = 10_000


def _temperature(log: Log, motion: Motion) -> Array | None:
    """The log's ``joint_temperatures`` where it has one per joint, else None."""
    if "joint_temperatures" in log and log["joint_temperatures"].shape == motion.q.shape:
        return log["joint_temperatures"]
    return None


def _measured_power(log: Log) -> Array | None:
    """``actual_robot_voltage x actual_robot_current`` where the log has both, W, else None."""
    if "actual_robot_voltage" in log and "actual_robot_current" in log:
        return np.asarray(log["actual_robot_voltage"] * log["actual_robot_current"])
    return None


#: the signals besides the motion that the energy of a log uses
_EXTRAS = (
    "joint_temperatures",
    "actual_robot_voltage",
    "actual_robot_current",
    "segment",
    *PAYLOAD_SIGNALS,
)


def _signals_used(log: CheckedLog, source: MotionSource) -> list[str] | None:
    """The signals of ``log`` its energy uses (the others are never converted): the motion of
    ``source`` (``auto`` as :func:`kinergy.io.motion.motion_from_log`) and :data:`_EXTRAS`,
    those the log has; None (all) when it has no joint positions, so the error lists what it
    has."""
    names = log.names()
    if source == MotionSource.AUTO:
        source = MotionSource.TARGET if "target_q" in names else MotionSource.ACTUAL
    if f"{source}_q" not in names:
        return None
    wanted = [f"{source}_{x}" for x in ("q", "qd", "qdd")] + list(_EXTRAS)
    return [name for name in wanted if name in names]


def _derived(signals: list[str] | None) -> str | None:
    """What the motion of a log read for ``signals`` (:func:`_signals_used`) takes from a
    spline rather than from the log, when that is not routine (a measured motion's accelerations
    always are: RTDE logs no ``actual_qdd``); None when nothing is."""
    if not signals:
        return None
    q = signals[0]
    source = q.removesuffix("_q")
    if f"{source}_qd" not in signals:
        return f"{source}_qd not in the log: speeds and accelerations from a spline of {q}"
    if source == "target" and "target_qdd" not in signals:
        return "target_qdd not in the log: accelerations from a spline of target_qd"
    return None


def _drive(robot: Robot, log: Log, motion: Motion) -> DriveState:
    """The drive model over a chunk's motion, each sample with the payload the log says it
    carried (:func:`kinergy.logs.payload.logged_loads`), else with the robot's own; friction at
    the log's joint temperatures where it has them."""
    temperature = _temperature(log, motion)
    loads = logged_loads(log)
    if loads is None:
        return drive_state(robot, motion.q, motion.qd, motion.qdd, temperature=temperature)
    m = motion
    payloads, load = loads
    robots = payload_robots(robot, payloads)
    return drive_by_payload(robots, load, m.q, m.qd, m.qdd, temperature=temperature)


#: how far past a joint's torque limit the modelled torque of a motion may go before the
#: energy says the arm cannot run it (a model's peaks overshoot a real arm's a little)
TORQUE_MARGIN = 1.5


def _beyond_limits(robot: Robot, peak: Array) -> list[str]:
    """A warning when the motion needs more than :data:`TORQUE_MARGIN` times a joint's torque
    limit (``peak``: the largest joint-side torque of the model, (n,) N m): a payload the arm
    cannot carry or a motion it cannot run, whose energy the figures give all the same."""
    limits = np.array([j.limits.torque for j in robot.joints])
    ratio = peak / limits
    j = int(np.argmax(ratio))
    if not ratio[j] > TORQUE_MARGIN:
        return []
    load = f" with a {robot.payload.mass:g} kg payload" if robot.payload is not None else ""
    return [
        f"the motion needs {peak[j]:.0f} N m at {robot.joint_names[j]}{load}, "
        f"{ratio[j]:.1f} times its {limits[j]:.0f} N m limit: the arm cannot run it (a payload "
        "too heavy, a motion too fast?); the energy is the model's all the same"
    ]


def program_energy(
    robot: Robot, path: str | os.PathLike[str], *, recovery: bool = True
) -> EnergyReport:
    """The energy of a URScript program run once as the controller runs it (500 Hz, from where
    it ends; :func:`kinergy.trajectory.program_motion.program_motion`), each sample with the load
    the program's ``set_payload`` gives it from there on (the robot's own before the first), as
    ``kinergy optimize`` accounts the program as written."""
    program = program_path(robot, read_program(path))
    motion, sched = program_motion(robot, program)
    load = payload_index(program, sched, motion.t)[0]
    state = drive_by_payload(program.robots, load, motion.q, motion.qd, motion.qdd)
    return energy(robot, motion, recovery=recovery, state=state)


def unused_payload(robot: Robot, path: str | os.PathLike[str]) -> list[str]:
    """A warning when the program sets its payload before it moves, so the robot's own payload
    (``--payload`` or the robot file's) is carried by no sample of it."""
    if robot.payload is None:
        return []
    steps = read_program(path).steps
    first = next((s for s in steps if getattr(s, "kind", "") == "payload"), None)
    moves = [s for s in steps if isinstance(s, Move)]
    if first is None or (moves and moves[0].line < first.line):
        return []
    return [
        f"{path}:{first.line}: the program sets its payload before its first move, so the "
        f"robot's own ({robot.payload.mass:g} kg, --payload or the robot file) is carried by "
        "none of it"
    ]


class SupplyBand:
    """The 95 % band's half-width of the predicted supply power, sample by sample, for a model
    that carries errors: ``t c |D g_n|`` with ``g_n`` the sample's gradient of the power the arm
    draws (:meth:`~kinergy.accounting.uncertainty.Sensitivity.rows` where the bus draws, plus 1
    for the standing draw), W; handed to ``sink`` as its "predicted" power."""

    def __init__(self, robot: Robot, sink: PowerSink) -> None:
        self.sensitivity = Sensitivity(robot)
        u = self.sensitivity.uncertainty
        self.sink, self.t = sink, t_quantile(u.dof)
        self.standby = np.array([name == "standby_power" for name in u.parameters], dtype=float)

    def add(self, t: Array, state: DriveState, temperature: Array | None) -> None:
        s = self.sensitivity
        g = s.rows(state, temperature)[s.p :] + self.standby[:, None]  # (p, N)
        half = self.t * s.uncertainty.calibration * np.linalg.norm(s.uncertainty.modes @ g, axis=0)
        self.sink.add(t, half, None, state.power)


def energy_of_log(
    robot: Robot,
    path: str | os.PathLike[str],
    reading: LogReading | None = None,
    options: EnergyOptions | None = None,
    *,
    rows: int = ENERGY_ROWS,
    sinks: Sequence[PowerSink] = (),
    band: SupplyBand | None = None,
) -> LogEnergy:
    """The energy of the motion in a log or motion file and what the log was (what ``kinergy
    energy`` prints: :class:`LogEnergy`): the log read in one
    pass through its checks, in chunks of ``rows`` samples
    (:class:`~kinergy.logs.reading.CheckedLog`), their motion as the whole log's
    (:func:`kinergy.io.motion.iter_motion`), predicted (friction at the log's
    ``joint_temperatures`` where it has them) and accumulated
    (:class:`kinergy.accounting.energy.EnergyAccumulator`, with the supply energy the log
    measured, ``actual_robot_voltage`` x ``actual_robot_current``, beside the predicted one);
    memory bounded by the chunk. Segments (a time gap or a ``segment`` change) are never
    integrated across. A URScript program (``*.script``) is run as the controller would, with
    the loads it sets (:func:`program_energy`). Each of ``sinks`` gets the power of every chunk
    (:class:`~kinergy.accounting.trace.PowerSink`: the supply's, predicted and measured, and each
    motor's); ``band``, the supply power's 95 % band (:class:`SupplyBand`), each chunk of a
    log's."""
    options = options or EnergyOptions()
    source, recovery = options.source, options.recovery
    inputs = InputLogs()
    reading = reading or LogReading()
    robot = reading.loaded(robot)
    inputs.notes.extend(standing_draw_notes(robot))
    check_source(path)
    if is_builtin(path) or os.fspath(path).endswith(".script"):
        if is_builtin(path):  # test-a, test-b: the motion as planned for the robot
            motion = paper_trajectory(robot, os.fspath(path))
            inputs.notes.append(f"{path}: the built-in motion {path} planned for {robot.name}")
            report = energy(robot, motion, recovery=recovery)
        else:
            report = program_energy(robot, path, recovery=recovery)
        for sink in sinks:
            sink.add(report.t, supply_predicted(robot, report.drive), None, report.drive.power)
        said = _beyond_limits(robot, np.abs(report.drive.tau_sim).max(axis=0))
        if not is_builtin(path):
            said += unused_payload(robot, path)
        return _with(report.figures(), inputs, said)
    acc = EnergyAccumulator(robot, recovery=recovery)
    measured = False
    peak = np.zeros(robot.n)
    log = CheckedLog(path, robot, reading, rows=rows, ahead=True)
    log.select = _signals_used(log, source)
    for part in iter_motion(log.chunks(), n_joints=robot.n, source=source):
        m = part.motion
        state = _drive(robot, part.log, m)
        power = _measured_power(part.log)
        measured = power is not None
        temperature = _temperature(part.log, m)
        acc.add(m.t, state, starts=part.starts, measured_power=power, temperature=temperature)
        for sink in sinks:
            sink.add(m.t, supply_predicted(robot, state), power, state.power)
        if band is not None:
            band.add(m.t, state, temperature)
        if len(m.t):
            peak = np.maximum(peak, np.abs(state.tau_sim).max(axis=0))
    inputs.add(log)
    if derived := _derived(log.select):
        inputs.notes.append(f"{log.path}: {derived}")
    return _with(acc.figures(measured=measured), inputs, _beyond_limits(robot, peak))


def log_energy_report(
    robot: Robot,
    path: str | os.PathLike[str],
    reading: LogReading | None = None,
    *,
    source: MotionSource = MotionSource.AUTO,
) -> tuple[EnergyReport, InputLogs]:
    """The energy of a log's motion with its time series (:class:`EnergyReport`, as the study
    report plots it), each sample with the payload the log's controller logged (else the
    robot's, or ``--payload``'s), and what the log was; the log read whole through its checks."""
    reading = reading or LogReading()
    robot = reading.loaded(robot)
    checked = CheckedLog(path, robot, reading)
    log = checked.read()
    inputs = InputLogs()
    inputs.add(checked)
    motion = motion_from_log(log, n_joints=robot.n, source=source)
    return energy(robot, motion, state=_drive(robot, log, motion)), inputs


def energy_with_outputs(
    robot: Robot,
    path: str | os.PathLike[str],
    reading: LogReading | None = None,
    options: EnergyOptions | None = None,
    *,
    trace: str | os.PathLike[str] | None = None,
    plot: str | os.PathLike[str] | None = None,
) -> LogEnergy:
    """:func:`energy_of_log`, writing the power trace to ``trace`` (CSV or Parquet by its
    extension, :mod:`kinergy.accounting.trace`; streamed chunk by chunk, whole or not at all)
    and the plot of the supply's power, predicted against measured, to ``plot`` (PNG,
    :func:`kinergy.report.plots.supply_power`), each when given.

    Raises
    ------
    KinergyError
        A trace file that is neither ``.csv`` nor ``.parquet`` (before any work), and whatever
        :func:`energy_of_log` raises; nothing is written then.
    """
    fmt = trace_format(trace) if trace is not None else None
    series = PowerSeries() if plot is not None else None
    halves = PowerSeries() if plot is not None and robot.uncertainty is not None else None
    band = (
        None if halves is None else SupplyBand(reading.loaded(robot) if reading else robot, halves)
    )
    with contextlib.ExitStack() as stack:
        sinks: list[PowerSink] = [] if series is None else [series]
        writer = None
        if trace is not None and fmt is not None:
            writer = TraceWriter(stack.enter_context(atomic_open(trace, binary=True)), robot, fmt)
            sinks.append(writer)
        result = energy_of_log(robot, path, reading, options, sinks=sinks, band=band)
        if writer is not None:
            writer.close()
    if plot is not None and series is not None:
        from kinergy.report.plots import save, supply_power  # matplotlib: only for a plot

        measured = result.measured
        figure = supply_power(
            series.t,
            series.predicted,
            energy=result.supply.drawn,
            measured=series.measured,
            measured_energy=None if measured is None else measured.drawn,
            standing=robot.standby_power,
            band=None if halves is None or halves.t.size != series.t.size else halves.predicted,
        )
        save(figure, plot)
    return result
