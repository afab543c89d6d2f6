"""``kinergy identify``: a model (or a payload) from logs, written as a robot file.

Every identification reads its logs in chunks (:func:`~kinergy.workflows.logs.chunked_logs`)
and runs as folds over them (:class:`~kinergy.identification.chunks.LogChunks`), whatever the method;
logs already prepared in memory (:func:`identify_model`) are one chunk each of the same folds.
"""

from __future__ import annotations

import dataclasses
import datetime
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinergy._version import __version__
from kinergy.accounting.uncertainty import Sensitivity
from kinergy.drives.bus import supply_power
from kinergy.drives.electrics import electrical_power, torque_constants
from kinergy.drives.transmission import transmission_matrix
from kinergy.errors import Code, KinergyError
from kinergy.identification.chunks import LogChunks, Summary, data_history
from kinergy.identification.electrics import BLOCK_SECONDS, StandingDraw, StandingDrawSums
from kinergy.identification.full import full
from kinergy.identification.nursing import nursing
from kinergy.identification.options import CurrentOptions, IdentifyOptions, Method, Target
from kinergy.identification.payload import PayloadEstimate, payload
from kinergy.identification.result import IDENTIFIED, IdentificationResult, validation_metrics
from kinergy.identification.sanity import check_motion
from kinergy.identification.sequential import sequential
from kinergy.identification.uncertainty import (
    fit_residual,
    fold_gradients,
    supply_calibration,
    with_standing_draw,
)
from kinergy.io.columns import compact_columns
from kinergy.io.formats import CHUNK_ROWS
from kinergy.io.log import Log
from kinergy.jsonable import to_jsonable
from kinergy.logs.checks import Check
from kinergy.logs.prepare import IdentData
from kinergy.logs.reading import InputLogs, LogReading
from kinergy.messages import Say, coded, silent
from kinergy.model import Robot, save_robot
from kinergy.model.robot import Identified, InputRecord, Source
from kinergy.predict import drive_state
from kinergy.workflows.logs import chunked_logs, one_payload

__all__ = [
    "MIN_MOTION_SHARE",
    "MIN_SECONDS",
    "PayloadRun",
    "identify_chunks",
    "identify_logs",
    "identify_model",
    "identify_payload_model",
    "measured_electrics",
    "motion_share",
    "unsupported_fit",
]

#: s: the shortest logs (all together) an identification accepts
MIN_SECONDS = 1.0


def _header(what: str, logs: Sequence[str | os.PathLike[str]]) -> str:
    stamp = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    return f"kinergy {__version__}: {what} from {', '.join(os.fspath(p) for p in logs)} on {stamp}"


def _checks(summaries: list[Summary]) -> None:
    """What every identification asks of its logs, checked at the end of their first pass:
    some joint moves, and the logs span :data:`MIN_SECONDS` together.

    Raises
    ------
    KinergyError
        Logs without motion (:func:`kinergy.identification.sanity.check_motion`) or too short.
    """
    check_motion(max(float(np.max(s.span)) for s in summaries))
    seconds = sum(s.seconds for s in summaries)
    if seconds < MIN_SECONDS:
        raise KinergyError(
            f"the logs span {seconds:.2f} s: identification needs at least {MIN_SECONDS:g} s of "
            "motion (a few periods of every joint's excitation)"
        )


def identify_chunks(
    robot: Robot, logs: LogChunks, options: IdentifyOptions | None = None
) -> IdentificationResult:
    """Identify ``robot`` from ``logs`` as ``options`` say, then the bus voltage and the
    standing draw where the logs measure them (:func:`measured_electrics`)."""
    options = options or IdentifyOptions()
    if options.method == Method.SEQUENTIAL:
        result = sequential(robot, logs, CurrentOptions(options.friction, errors=options.errors))
    elif options.method == Method.NURSING:
        result = nursing(robot, logs)
    else:
        result = full(robot, logs, options)
    errors = result.robot.uncertainty
    if errors is not None:  # the prediction band's noise: what the fit missed
        errors = dataclasses.replace(errors, residual=fit_residual(result.fit))
        result = dataclasses.replace(
            result, robot=dataclasses.replace(result.robot, uncertainty=errors)
        )
    return measured_electrics(result, logs)


def identify_model(
    robot: Robot,
    datas: Sequence[IdentData],
    options: IdentifyOptions | None = None,
) -> IdentificationResult:
    """:func:`identify_chunks` of prepared logs held in memory (each one chunk).

    Raises
    ------
    KinergyError
        Logs spanning less than :data:`MIN_SECONDS` together, with signals no robot logs or
        without motion (:mod:`kinergy.identification.sanity`).
    """
    return identify_chunks(robot, LogChunks.of(datas, check=_checks), options)


#: the least share of their samples the logs must move on (any joint faster than
#: :data:`~kinergy.identification.chunks.STILL_SPEED`) before a fit they do not support is
#: blamed on their layout rather than on too little motion
MIN_MOTION_SHARE = 0.25


def motion_share(summary: Summary) -> float:
    """The share of a log's samples some joint moves on (its most moving joint's)."""
    moving = np.asarray(summary.forward + summary.backward, dtype=float)
    return float(np.max(moving) / max(summary.samples, 1))


def unsupported_fit(result: IdentificationResult, share: float = 1.0) -> str:
    """Why the identified model is not supported by its own logs, or "": no drive parameter
    identified, or an R^2 below 0 on the identification logs for a joint that moved, of the
    reference torque, the current or (identified from them) the measured joint torque (module
    docstring of :mod:`kinergy.logs.checks`, check ``fit``); logs that move on less than
    :data:`MIN_MOTION_SHARE` of their samples (``share``) are told they hold too little motion,
    not that their layout is wrong."""
    flags = [f for j in result.joints for k, f in j.flags.items()]
    if flags and all(f != IDENTIFIED for f in flags):
        return (
            "no drive parameter could be identified from these logs (every one kept from the "
            "model): nothing in them excites the drives, or their layout is wrong"
        )
    moved = [getattr(j, "identified", True) for j in result.joints]
    worst = []
    signals = [("torque", "target_moment"), ("current", "actual_current")]
    fit = result.fit  # the full method against measured torques, its friction from them
    if (
        getattr(fit, "target", "") == Target.TORQUE.value
        and getattr(fit, "drives", "") != "currents"
    ):
        signals.append(("joint_torque", "measured joint torque"))
    for key, unit in signals:
        metrics = getattr(result.fit, key)
        if metrics is None:
            continue
        for k, m in enumerate(metrics):
            if moved[k] and m.r2 < 0:
                worst.append(f"{result.robot.joints[k].name} {unit} R² {m.r2:.2f}")
    if worst and share < MIN_MOTION_SHARE:
        return (
            f"too little motion to identify from: the joints move on {100 * share:.0f} % of the "
            f"logs' samples and the model fitted to them does not explain them "
            f"({', '.join(worst)}); log more motion (kinergy excite designs it), or cut the logs "
            "to where the arm moves (--from/--to)"
        )
    if worst:
        return (
            f"the identified model does not explain its own logs ({', '.join(worst)}): the "
            "logs' layout, units or robot are likely wrong (check --columns and --robot)"
        )
    return ""


def _record(
    robot: Robot,
    inputs: InputLogs,
    options: IdentifyOptions,
    columns: str | None,
    accepted: Sequence[str],
) -> Robot:
    """``robot`` with where it was identified from (:class:`~kinergy.model.robot.Identified`)."""
    settings: dict[str, str | float] = options.record()
    if columns:
        settings["columns"] = columns
    records = tuple(InputRecord(p.path, p.sha256, p.size, p.rows) for p in inputs.provenance)
    ident = Identified(__version__, "identify", settings, records, tuple(accepted))
    return dataclasses.replace(robot, identified=ident)


def identify_logs(
    robot: Robot,
    logs: Sequence[str | os.PathLike[str] | Log],
    out: str | os.PathLike[str] | None,
    *,
    reading: LogReading | None = None,
    options: IdentifyOptions | None = None,
    rows: int = CHUNK_ROWS,
    progress: Say = silent,
) -> IdentificationResult:
    """Read (through the checks), prepare and identify ``logs`` (files or logs in memory) and
    write the model to ``out`` when given; ``progress`` is told each log read (of all) and
    when the identification starts.

    ``reading`` says how to read the logs (:class:`~kinergy.logs.reading.LogReading`),
    ``options`` what to identify. The logs are read in chunks of ``rows`` samples and never held
    whole (:func:`~kinergy.workflows.logs.chunked_logs`, :func:`identify_chunks`; the files
    themselves are read in chunks of at least 2 rows).

    Raises
    ------
    KinergyError
        A log that fails its checks, logs that cannot identify the model, and a model the logs
        do not support (:func:`unsupported_fit`) unless ``reading.accept`` holds ``fit``;
        nothing is written then.
    """
    reading = reading or LogReading()
    options = options or IdentifyOptions()
    with chunked_logs(logs, robot, reading, rows=max(rows, 2), progress=progress) as (
        segments,
        inputs,
    ):
        progress(f"identifying ({options.method.value} method)")
        start = one_payload(reading.loaded(robot), segments, inputs.notes)
        chunks = LogChunks(segments, rows, check=_checks)
        try:
            result = identify_chunks(start, chunks, options)
            share = motion_share(Summary.pooled(chunks.summaries))
        finally:
            chunks.close()
    # the payload was the run's, not the arm's: the model keeps its file's own
    result = dataclasses.replace(result, robot=result.robot.with_payload(robot.payload))
    accepted = [a for c in inputs.checks for a in c.accepted]
    problem = unsupported_fit(result, share)
    if problem:
        if Check.FIT not in reading.accept:
            raise KinergyError(
                f"fit check failed: {problem}; no model written (if the logs are right, "
                "--accept fit)"
            )
        accepted.append(f"fit: {problem}")
    result = dataclasses.replace(result, inputs=inputs, accepted=tuple(accepted))
    if out is not None:
        columns = None
        if isinstance(reading.columns, tuple):
            columns = compact_columns(reading.columns)
        elif reading.columns is not None:
            columns = str(reading.columns)
        model = _record(result.robot, inputs, options, columns, accepted)
        what = f"{robot.name} identified ({result.method} method)"
        save_robot(model, out, header=_header(what, [p.path for p in inputs.provenance]))
        result = dataclasses.replace(result, robot=model)
    return result


def _predicted_currents(robot: Robot, logs: LogChunks) -> list[np.ndarray]:
    """The currents ``robot`` predicts on every chunk, as its validation kept them
    (:attr:`~kinergy.identification.chunks.LogChunks.currents`; validated now when it did not)."""
    if logs.currents is None or logs.currents[0] is not robot:
        validation_metrics(robot, logs)
    assert logs.currents is not None
    return [current for (current,) in logs.currents[1]]  # type: ignore[misc]


def _standing_draw(
    robot: Robot, logs: LogChunks, currents: list[np.ndarray] | None
) -> tuple[StandingDraw, tuple[float, int] | None]:
    """The supply power less the motors' draw (UR5e eq 23 on the ``currents`` ``robot``
    predicts, else on its :func:`~kinergy.predict.drive_state`), folded into
    :class:`~kinergy.identification.electrics.StandingDrawSums`; and, when ``robot`` carries
    parameter errors, their calibration factor on the same blocks and the blocks' count
    (:func:`~kinergy.identification.uncertainty.supply_calibration`; else None)."""
    n_mat, kt = transmission_matrix(robot), torque_constants(robot)
    held = data_history(robot)
    sums = StandingDrawSums()
    sensitivity = None if robot.uncertainty is None else Sensitivity(robot)
    gradients: dict[tuple[int, int], np.ndarray] = {}
    for c, (k, chunk) in enumerate(logs.chunks()):
        assert chunk.supply_voltage is not None and chunk.supply_current is not None
        if currents is not None and sensitivity is None:
            power = electrical_power(robot, currents[c] * kt, chunk.qd @ n_mat.T)
        else:
            data, skip = held.ahead(k, chunk)
            state = drive_state(robot, data.q, data.qd, data.qdd, temperature=data.temperature)
            held.update(data, skip)
            power = state.power[skip:]
            if sensitivity is not None:
                cols = sensitivity.rows(state, data.temperature)[sensitivity.p :, skip:].T
                fold_gradients(gradients, sums, k, chunk.t, cols)
        supply = np.asarray(chunk.supply_voltage * chunk.supply_current, dtype=float)
        sums.add(k, chunk.t, supply - supply_power(power).motors)
    draw = sums.fit()
    if sensitivity is None:
        return draw, None
    return draw, supply_calibration(sensitivity.uncertainty, sums, gradients, draw.power)


def _bus_voltage(logs: LogChunks, name: str) -> float:
    """The mean of a logged voltage (``supply_voltage`` or the joints' ``voltage``), V."""
    total, count = 0.0, 0
    for _, chunk in logs.chunks(name):
        values = getattr(chunk, name)
        total += float(np.sum(values))
        count += values.size
    return total / count


def measured_electrics(result: IdentificationResult, logs: LogChunks) -> IdentificationResult:
    """``result`` with the bus voltage and the standing draw the logs measure, when every log
    has them: the bus voltage, the mean of ``actual_robot_voltage`` (else of
    ``actual_joint_voltage``, each joint's supply, never a motor's voltage: ``R`` and ``k_b`` stay
    the model's); the standing draw (:func:`_standing_draw`) from ``actual_robot_voltage`` x
    ``actual_robot_current``, with its standard error. The fit's notes say what was written into
    the model. Unchanged for logs without them."""
    robot, notes = result.robot, list[str]()
    sources = dict(robot.sources)
    has_supply = logs.every("supply_voltage", "supply_current")
    which = "supply_voltage" if has_supply else "voltage" if logs.every("voltage") else None
    if which is None:
        return result
    bus = _bus_voltage(logs, which)
    logged = "actual_robot_voltage" if has_supply else "actual_joint_voltage (each joint's supply)"
    robot = dataclasses.replace(robot, bus_voltage=bus)
    notes.append(
        f"bus voltage {bus:.4g} V, the mean of the logged {logged}, written into the model; the "
        "motors' R and k_b stay the model's (a log has no motor voltage: robot "
        "import-calibration takes them from a UR calibration's U and I)"
    )
    draw = None
    if has_supply:
        model = result.robot  # the currents its validation kept
        currents = _predicted_currents(model, logs) if logs.every("current") else None
        draw, factor = _standing_draw(model, logs, currents)
        robot = dataclasses.replace(robot, standby_power=max(draw.power, 0.0))
        if np.isfinite(draw.std) and robot.uncertainty is not None:
            errors = with_standing_draw(robot.uncertainty, draw.std, factor)
            robot = dataclasses.replace(robot, uncertainty=errors)
        sources["supply"] = Source(
            "identified",
            f"kinergy identify: standing draw {draw.power:.4g} ± {draw.std:.2g} W (standard "
            "error) from actual_robot_voltage x actual_robot_current less the motors' draw",
        )
        notes.append(
            f"standing draw {draw.power:.4g} W (standard error {draw.std:.2g} W, {draw.blocks} "
            f"blocks of {BLOCK_SECONDS:g} s) from the logged supply power (actual_robot_voltage "
            "x actual_robot_current, less the motors' predicted draw), written into the model"
            + (" as 0 W" if draw.power < 0 else "")
        )
    robot = dataclasses.replace(robot, sources=sources)
    fit = dataclasses.replace(result.fit, notes=(*result.fit.notes, *notes))
    return dataclasses.replace(result, robot=robot, fit=fit, standing_draw=draw)


@dataclass(frozen=True, eq=False)
class PayloadRun:
    """``identify --payload-only``: the payload found (:class:`PayloadEstimate`), the robot
    written with it, and what the logs were. :meth:`to_dict` is the command's ``--json``
    (without where the command came from)."""

    robot: Robot
    payload: PayloadEstimate
    inputs: InputLogs

    @property
    def lacks(self) -> list[str]:
        """The checks' "a payload the model lacks" (code ``PAYLOAD_MISSING``): what this
        identifies, so routine here."""
        return coded(self.inputs.warnings, Code.PAYLOAD_MISSING)

    @property
    def notes(self) -> list[str]:
        return [*self.inputs.notes, *self.lacks, *self.payload.notes]

    @property
    def warnings(self) -> list[str]:
        return [w for w in self.inputs.warnings if w not in self.lacks]

    def to_dict(self) -> dict[str, Any]:
        return {
            "robot": self.robot.name,
            "method": "payload",
            "payload": to_jsonable(self.payload),
            "inputs": self.inputs.records(),
            "notes": self.notes,
            "warnings": self.warnings,
        }


def identify_payload_model(
    robot: Robot,
    logs: Sequence[str | os.PathLike[str] | Log],
    out: str | os.PathLike[str],
    reading: LogReading | None = None,
    *,
    rows: int = CHUNK_ROWS,
) -> PayloadRun:
    """Identify the payload of ``robot`` (the model without it) from ``logs`` taken with it
    (read through the checks, in chunks of ``rows`` samples) and write the model with it."""
    reading = reading or LogReading()
    with chunked_logs(logs, robot, reading, rows=max(rows, 2)) as (segments, inputs):
        chunks = LogChunks(segments, rows)
        try:
            found, report = payload(robot, chunks)
        finally:
            chunks.close()
    what = f"{robot.name} with the payload identified"
    loaded = robot.with_payload(found)
    save_robot(loaded, out, header=_header(what, list(chunks.paths)))
    return PayloadRun(loaded, report, inputs)
