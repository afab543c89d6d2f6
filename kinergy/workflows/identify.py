"""``kinergy identify``: a model (or a payload) from logs, written as a robot file."""

from __future__ import annotations

import contextlib
import dataclasses
import datetime
import os
from collections.abc import Mapping, Sequence
from typing import Any, Protocol

import numpy as np

from kinergy.drives.electrics import equivalent_voltage
from kinergy.drives.transmission import transmission_matrix
from kinergy.errors import KinergyError
from kinergy.identify.electrics import ElectricsFit, fit_electrics, fit_standby, with_electrics
from kinergy.identify.full import identify_full
from kinergy.identify.nursing import identify_nursing
from kinergy.identify.options import IdentifyOptions, Method
from kinergy.identify.payload import PayloadEstimate, identify_payload
from kinergy.identify.result import IDENTIFIED, IdentificationResult
from kinergy.identify.sanity import check_motion, check_signals
from kinergy.identify.sequential import identify_sequential, sequential_from
from kinergy.identify.streamed import LogsInChunks, streams
from kinergy.io.columns import compact_columns
from kinergy.io.formats import CHUNK_ROWS
from kinergy.io.log import Log
from kinergy.logs.checks import Check
from kinergy.logs.prepare import IdentData
from kinergy.logs.reading import InputLogs, LogReading
from kinergy.model import Payload, Robot, save_robot
from kinergy.model.robot import Identified, InputRecord, Source
from kinergy.predict import drive_state
from kinergy.workflows.logs import chunked_logs, prepared_logs

__all__ = [
    "METHODS",
    "MIN_SECONDS",
    "ElectricsLogs",
    "identify_logs",
    "identify_model",
    "identify_payload_model",
    "measured_electrics",
    "unsupported_fit",
]

#: identification methods by the name ``--method`` takes
METHODS = tuple(m.value for m in Method)
#: s: the shortest logs (all together) an identification accepts
MIN_SECONDS = 1.0


def _header(what: str, logs: Sequence[str | os.PathLike[str]]) -> str:
    from kinergy import __version__

    stamp = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    return f"kinergy {__version__}: {what} from {', '.join(os.fspath(p) for p in logs)} on {stamp}"


def _check_seconds(seconds: float) -> None:
    """Raise when the logs span less than :data:`MIN_SECONDS` together."""
    if seconds < MIN_SECONDS:
        raise KinergyError(
            f"the logs span {seconds:.2f} s: identification needs at least {MIN_SECONDS:g} s of "
            "motion (a few periods of every joint's excitation)"
        )


def identify_model(
    robot: Robot,
    datas: Sequence[IdentData],
    options: IdentifyOptions | None = None,
) -> IdentificationResult:
    """Identify ``robot`` from prepared logs as ``options`` say, then the motor electrics and the
    standby power where the logs have voltages and the supply (:func:`measured_electrics`).

    Raises
    ------
    KinergyError
        Logs spanning less than :data:`MIN_SECONDS` together, with signals no robot logs or
        without motion (:mod:`kinergy.identify.sanity`).
    """
    options = options or IdentifyOptions()
    check_signals(datas)
    check_motion(datas)
    _check_seconds(sum(float(d.t[-1] - d.t[0]) for d in datas))
    if options.method == Method.SEQUENTIAL:
        result = identify_sequential(robot, list(datas), friction=options.friction)
    elif options.method == Method.NURSING:
        result = identify_nursing(robot, list(datas))
    else:
        result = identify_full(
            robot,
            list(datas),
            target=options.target,
            solver=options.solver,
            ridge=options.ridge,
            friction=options.friction,
        )
    return measured_electrics(result, datas)


def unsupported_fit(result: IdentificationResult) -> str:
    """Why the identified model is not supported by its own logs, or "": no drive parameter
    identified, or an R^2 below 0 on the identification logs for a joint that moved (module
    docstring of :mod:`kinergy.logs.checks`, check ``fit``)."""
    flags = [f for j in result.joints for k, f in j.flags.items()]
    if flags and all(f != IDENTIFIED for f in flags):
        return (
            "no drive parameter could be identified from these logs (every one kept from the "
            "model): nothing in them excites the drives, or their layout is wrong"
        )
    moved = [getattr(j, "identified", True) for j in result.joints]
    worst = []
    for key, unit in (("torque", "target_moment"), ("current", "actual_current")):
        metrics = getattr(result.fit, key)
        if metrics is None:
            continue
        for k, m in enumerate(metrics):
            if moved[k] and m.r2 < 0:
                worst.append(f"{result.robot.joints[k].name} {unit} R^2 {m.r2:.2f}")
    if worst:
        return (
            f"the identified model does not explain its own logs ({', '.join(worst)}): the "
            "logs' layout, units or robot are likely wrong (check --columns and --robot)"
        )
    return ""


def _record(
    robot: Robot, inputs: InputLogs, options: Mapping[str, Any], accepted: Sequence[str]
) -> Robot:
    """``robot`` with where it was identified from (:class:`~kinergy.model.robot.Identified`)."""
    from kinergy import __version__

    plain = {k: v for k, v in options.items() if isinstance(v, str | float | int | bool)}
    records = tuple(InputRecord(p.path, p.sha256, p.size, p.rows) for p in inputs.provenance)
    ident = Identified(__version__, "identify", plain, records, tuple(accepted))
    return dataclasses.replace(robot, identified=ident)


def identify_logs(
    robot: Robot,
    logs: Sequence[str | os.PathLike[str] | Log],
    out: str | os.PathLike[str] | None,
    *,
    reading: LogReading | None = None,
    options: IdentifyOptions | None = None,
    rows: int = CHUNK_ROWS,
) -> IdentificationResult:
    """Read (through the checks), prepare and identify ``logs`` (files or logs in memory) and
    write the model to ``out`` when given.

    ``reading`` says how to read the logs (:class:`~kinergy.logs.reading.LogReading`),
    ``options`` what to identify. When the method streams
    (:func:`kinergy.identify.streamed.streams`: the sequential method with a fixed friction
    model) the logs are read in chunks of ``rows`` samples and never held whole
    (:func:`~kinergy.workflows.logs.chunked_logs`); other methods prepare them in memory.

    Raises
    ------
    KinergyError
        A log that fails its checks, logs that cannot identify the model, and a model the logs
        do not support (:func:`unsupported_fit`) unless ``reading.accept`` holds ``fit``;
        nothing is written then.
    """
    reading = reading or LogReading()
    options = options or IdentifyOptions()
    if not streams(robot, options.method, options.friction):
        datas, inputs = prepared_logs(logs, robot, reading)
        result = identify_model(robot, datas, options)
    else:
        with chunked_logs(logs, robot, reading, rows=rows) as (segments, inputs):
            with contextlib.closing(LogsInChunks(robot, segments, rows)) as chunked:
                _check_seconds(chunked.seconds)
                result = sequential_from(robot, chunked, friction=options.friction)
                result = measured_electrics(result, chunked)
    accepted = [a for c in inputs.checks for a in c.accepted]
    problem = unsupported_fit(result)
    if problem:
        if Check.FIT not in reading.accept:
            raise KinergyError(
                f"fit check failed: {problem}; no model written (if the logs are right, "
                "--accept fit)"
            )
        accepted.append(f"fit: {problem}")
    result = dataclasses.replace(result, inputs=inputs, accepted=tuple(accepted))
    if out is not None:
        columns = compact_columns(reading.columns) if reading.columns else None
        settings = {**vars(options), "columns": columns}
        model = _record(result.robot, inputs, settings, accepted)
        what = f"{robot.name} identified ({result.method} method)"
        save_robot(model, out, header=_header(what, [p.path for p in inputs.provenance]))
        result = dataclasses.replace(result, robot=model)
    return result


class ElectricsLogs(Protocol):
    """What :func:`measured_electrics` needs of the logs, however they are held (in memory,
    :class:`_InMemory`, or in chunks, :class:`~kinergy.identify.streamed.LogsInChunks`)."""

    @property
    def has_voltage(self) -> bool:
        """Every log has joint voltages and currents."""

    @property
    def has_supply(self) -> bool:
        """Every log has the supply's voltage and current."""

    def electrics(self, robot: Robot) -> list[ElectricsFit | KinergyError]:
        """Per motor, eq 19's fit with ``robot``'s predicted current as the instrument, or why
        it cannot be made."""

    def standby(self, robot: Robot) -> float:
        """The mean supply power the motors of ``robot`` leave over, W."""


class _InMemory:
    """Prepared logs held whole (:class:`ElectricsLogs`)."""

    def __init__(self, logs: Sequence[IdentData]):
        self.logs = list(logs)
        self.has_voltage = bool(logs) and all(
            d.voltage is not None and d.current is not None for d in logs
        )
        self.has_supply = bool(logs) and all(
            d.supply_voltage is not None and d.supply_current is not None for d in logs
        )

    def _motion(self) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], np.ndarray | None]:
        """The logs' real motion (q, qd, qdd), stacked, and their joint temperatures (None
        unless every log has them)."""
        logs = self.logs
        q, qd, qdd = (np.vstack([getattr(d, k) for d in logs]) for k in ("q", "qd", "qdd"))
        temps = [d.temperature for d in logs if d.temperature is not None]
        return (q, qd, qdd), (np.vstack(temps) if len(temps) == len(logs) else None)

    def electrics(self, robot: Robot) -> list[ElectricsFit | KinergyError]:
        n_mat = transmission_matrix(robot)
        current = np.vstack([d.current for d in self.logs if d.current is not None])
        voltage = equivalent_voltage(
            np.vstack([d.voltage for d in self.logs if d.voltage is not None])
        )
        (q, qd, qdd), temperature = self._motion()
        # the identified model's current, free of the log's noise: the instrument of the fit
        predicted = drive_state(robot, q, qd, qdd, temperature=temperature).current
        wm = qd @ n_mat.T
        fits: list[ElectricsFit | KinergyError] = []
        for m in range(robot.n):
            try:
                fits.append(
                    fit_electrics(
                        current[:, m], voltage[:, m], wm[:, m], instrument=predicted[:, m]
                    )
                )
            except KinergyError as exc:
                fits.append(exc)
        return fits

    def standby(self, robot: Robot) -> float:
        motion, temperature = self._motion()
        supply = np.concatenate([_supply_power(d) for d in self.logs])
        fit = fit_standby(robot, motion, supply, temperature=temperature, dt=self.logs[0].dt)
        return fit.standby


def _electrics_fits(
    robot: Robot, logs: ElectricsLogs, notes: list[str]
) -> list[ElectricsFit | None]:
    """Each motor's R and k_b from the logs' voltages, currents and motor speeds (None where
    they cannot separate the two, with a note)."""
    fits: list[ElectricsFit | None] = []
    for m, (joint, fit) in enumerate(zip(robot.joints, logs.electrics(robot), strict=True)):
        if isinstance(fit, KinergyError):
            notes.append(f"joint {m + 1} ({joint.name}): electrics kept from the model: {fit}")
            fits.append(None)
        else:
            fits.append(fit)
    return fits


def _supply_power(data: IdentData) -> np.ndarray:
    """``actual_robot_voltage * actual_robot_current`` of a log that has both, W."""
    assert data.supply_voltage is not None and data.supply_current is not None
    return np.asarray(data.supply_voltage * data.supply_current, dtype=float)


def measured_electrics(
    result: IdentificationResult, datas: Sequence[IdentData] | ElectricsLogs
) -> IdentificationResult:
    """``result`` with the motor electrics fitted to the logs' joint voltages (UR5e eq 19,
    :func:`kinergy.identify.electrics.fit_electrics`) and the standby power to their supply
    power (:func:`kinergy.identify.electrics.fit_standby`), when every log has them; the fit's
    warnings say what was written into the model. Unchanged for logs without them. ``datas``
    are prepared logs or logs read in chunks (:class:`ElectricsLogs`)."""
    logs = _InMemory(datas) if isinstance(datas, Sequence) else datas
    robot, notes = result.robot, list[str]()
    sources = dict(robot.sources)
    if logs.has_voltage:
        fits = _electrics_fits(robot, logs, notes)
        robot = with_electrics(robot, fits)
        ref = "kinergy identify: R and k_b from actual_joint_voltage (UR5e eq 19)"
        sources["motor_constant"] = Source("identified", ref)
        for j, motor in enumerate(fits):
            if motor is not None:
                notes.append(
                    f"joint {j + 1} ({robot.joints[j].name}): R = {motor.resistance:.4g} ohm, "
                    f"k_b = {motor.back_emf:.4g} V s/rad from the logged joint voltages (voltage "
                    f"RMS error {motor.rms:.3g} V), written into the model"
                )
    if logs.has_supply:
        standby = max(logs.standby(robot), 0.0)
        robot = dataclasses.replace(robot, standby_power=standby)
        sources["supply"] = Source(
            "identified", "kinergy identify: standby power from actual_robot_current"
        )
        notes.append(
            f"standby power {standby:.3g} W from the logged supply power (actual_robot_voltage "
            "x actual_robot_current, less the motors' predicted draw), written into the model"
        )
    if not notes:
        return result
    robot = dataclasses.replace(robot, sources=sources)
    fit = dataclasses.replace(result.fit, notes=(*result.fit.notes, *notes))
    return dataclasses.replace(result, robot=robot, fit=fit)


def identify_payload_model(
    robot: Robot,
    logs: Sequence[str | os.PathLike[str] | Log],
    out: str | os.PathLike[str],
    reading: LogReading | None = None,
) -> tuple[Payload, PayloadEstimate, InputLogs]:
    """Identify the payload of ``robot`` (the model without it) from ``logs`` taken with it
    (read through the checks) and write the model with it."""
    datas, inputs = prepared_logs(logs, robot, reading or LogReading())
    check_signals(datas)
    payload, report = identify_payload(robot, list(datas))
    what = f"{robot.name} with the payload identified"
    save_robot(robot.with_payload(payload), out, header=_header(what, [d.path for d in datas]))
    return payload, report, inputs
