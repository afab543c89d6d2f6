"""``kinergy identify``: a model (or a payload) from logs, written as a robot file."""

from __future__ import annotations

import contextlib
import dataclasses
import datetime
import os
from collections.abc import Sequence
from typing import Any, Protocol

import numpy as np

from kinergy.drives.electrics import equivalent_voltage
from kinergy.drives.transmission import transmission_matrix
from kinergy.errors import KinergyError
from kinergy.identify.electrics import ElectricsFit, fit_electrics, fit_standby, with_electrics
from kinergy.identify.full import identify_full
from kinergy.identify.nursing import identify_nursing
from kinergy.identify.payload import PayloadEstimate, identify_payload
from kinergy.identify.preprocess import IdentData
from kinergy.identify.result import IdentificationResult
from kinergy.identify.sanity import check_motion, check_signals
from kinergy.identify.sequential import identify_sequential, sequential_from
from kinergy.identify.streamed import LogsInChunks, streams
from kinergy.io.formats import CHUNK_ROWS
from kinergy.model import Payload, Robot, save_robot
from kinergy.model.robot import Source
from kinergy.predict import drive_state
from kinergy.workflows.logs import LogReading, chunked_logs, prepared_logs

__all__ = [
    "METHODS",
    "MIN_SECONDS",
    "ElectricsLogs",
    "identify_logs",
    "identify_model",
    "identify_payload_model",
    "measured_electrics",
]

#: identification methods by the name ``--method`` takes
METHODS = ("sequential", "full", "nursing")
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
    out: str | os.PathLike[str] | None = None,
    *,
    method: str = "sequential",
    friction: str | None = None,
    target: str = "auto",
    solver: str = "ols",
    ridge: float = 0.0,
) -> IdentificationResult:
    """Identify ``robot`` from prepared logs by ``method``, then the motor electrics and the
    standby power where the logs have voltages and the supply (:func:`measured_electrics`);
    write the identified model to ``out`` when given.

    Raises
    ------
    KinergyError
        Logs spanning less than :data:`MIN_SECONDS` together, with signals no robot logs or
        without motion (:mod:`kinergy.identify.sanity`); nothing is written.
    """
    check_signals(datas)
    check_motion(datas)
    _check_seconds(sum(float(d.t[-1] - d.t[0]) for d in datas))
    if method == "sequential":
        result = identify_sequential(robot, list(datas), friction=friction)
    elif method == "nursing":
        result = identify_nursing(robot, list(datas))
    else:
        result = identify_full(
            robot, list(datas), target=target, solver=solver, ridge=ridge, friction=friction
        )
    result = measured_electrics(result, datas)
    if out is not None:
        what = f"{robot.name} identified ({result.method} method)"
        save_robot(result.robot, out, header=_header(what, [d.path for d in datas]))
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
    fit = dataclasses.replace(result.fit, warnings=(*result.fit.warnings, *notes))
    return dataclasses.replace(result, robot=robot, fit=fit)


def identify_logs(
    robot: Robot,
    paths: Sequence[str | os.PathLike[str]],
    out: str | os.PathLike[str],
    *,
    reading: LogReading | None = None,
    rows: int = CHUNK_ROWS,
    **options: Any,
) -> IdentificationResult:
    """Read, prepare and identify the logs at ``paths`` and write the model to ``out``.

    ``reading`` says how to read the logs (:class:`~kinergy.workflows.logs.LogReading`),
    ``options`` are :func:`identify_model`'s. When the method
    streams (:func:`kinergy.identify.streamed.streams`: the sequential method with a fixed
    friction model) the logs are read in chunks of ``rows`` samples and never held whole
    (:func:`~kinergy.workflows.logs.chunked_logs`); other methods prepare them in memory.
    """
    reading = LogReading(**(reading or {}))
    reading.setdefault("joints", robot.joint_names)
    method, friction = options.get("method", "sequential"), options.get("friction")
    if not streams(robot, method, friction):
        datas = prepared_logs(paths, n_joints=robot.n, **reading)
        return identify_model(robot, datas, out, **options)
    with chunked_logs(paths, n_joints=robot.n, rows=rows, **reading) as segments:
        with contextlib.closing(LogsInChunks(robot, segments, rows)) as logs:
            _check_seconds(logs.seconds)
            result = sequential_from(robot, logs, friction=friction)
            result = measured_electrics(result, logs)
    what = f"{robot.name} identified ({result.method} method)"
    save_robot(result.robot, out, header=_header(what, [s.path for s in segments]))
    return result


def identify_payload_model(
    robot: Robot, datas: Sequence[IdentData], out: str | os.PathLike[str]
) -> tuple[Payload, PayloadEstimate]:
    """Identify the payload of ``robot`` (the model without it) and write the model with it."""
    check_signals(datas)
    payload, report = identify_payload(robot, list(datas))
    what = f"{robot.name} with the payload identified"
    save_robot(robot.with_payload(payload), out, header=_header(what, [d.path for d in datas]))
    return payload, report
