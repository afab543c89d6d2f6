"""What an identification returns, and the model's predictions on a log.

Results are frozen dataclasses, written as JSON by :mod:`kinergy.jsonable`:

- :class:`Validation`: per-joint :class:`~kinergy.identification.metrics.JointMetrics` of the reference
  torque, the current and the measured joint torque (``validate --json``);
- :class:`Fit`: a validation on the identification logs plus what every method reports (samples,
  logs, lag, warnings); each method extends it with its own diagnostics;
- :class:`DriveEstimate`: one joint's identified drive (each method extends it with standard
  errors and flags);
- :class:`IdentificationResult`: the identified robot, the method, the joints and the fit
  (``identify --json``).
"""

from __future__ import annotations

import enum
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, TypedDict

from kinergy.arrays import Array
from kinergy.drives.bus import supply_power
from kinergy.identification.chunks import LogChunks, data_history
from kinergy.identification.electrics import StandingDraw
from kinergy.identification.metrics import ExcitedSums, JointMetrics
from kinergy.jsonable import to_jsonable
from kinergy.logs.prepare import IdentData
from kinergy.logs.reading import InputLogs
from kinergy.messages import Messages
from kinergy.model.robot import Friction, Joint, Robot
from kinergy.predict import drive_state, sensor_torque

__all__ = [
    "AT_BOUND",
    "FLAGS",
    "IDENTIFIED",
    "KEPT",
    "DriveEstimate",
    "DriveFields",
    "Fit",
    "Flag",
    "IdentificationResult",
    "Prediction",
    "Validation",
    "drive_fields",
    "fit_fields",
    "predict",
    "predictions",
    "validation_metrics",
]


#: a per-joint metrics field: one entry per joint, or None when no log has the signal
Metrics = tuple[JointMetrics, ...] | None


class Flag(enum.StrEnum):
    """What the data did with a parameter: fitted, left at the starting model's value, or held at
    a physical bound by the constrained fit (``--json`` writes the value)."""

    IDENTIFIED = "identified"
    KEPT = "kept from prior"
    AT_BOUND = "at bound"


IDENTIFIED, KEPT, AT_BOUND = Flag.IDENTIFIED, Flag.KEPT, Flag.AT_BOUND
#: every flag, in the order tables count them
FLAGS = tuple(Flag)


@dataclass(frozen=True)
class Validation:
    """UR5e Tables V and VII: per joint, how well the model predicts ``target_moment``
    (``torque``), ``actual_current`` (``current``) and measured joint torques
    (``joint_torque``); None where no log has the signal."""

    torque: Metrics = None
    current: Metrics = None
    joint_torque: Metrics = None


@dataclass(frozen=True)
class Fit(Validation):
    """The fit on the identification logs (the identified model's :class:`Validation`) and what
    every method reports: samples used, the logs, each log's lag (s), the warnings (what may make
    the model wrong) and the notes (what is routine: values written, defaults kept)."""

    samples: int = 0
    logs: tuple[str, ...] = ()
    lag: tuple[float, ...] = ()
    warnings: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()


class DriveFields(TypedDict):
    """The fields every method's per-joint result starts from (:func:`drive_fields`)."""

    name: str
    rotor_inertia: float
    motor_inertia: float
    torque_constant: float
    friction: Friction


def drive_fields(joint: Joint, rotor_inertia: float | None = None) -> DriveFields:
    """A joint's drive as the model holds it, as :class:`DriveEstimate` fields (``name``,
    ``rotor_inertia``, ``motor_inertia``, ``torque_constant``, ``friction``): keyword arguments
    of a method's per-joint result. ``rotor_inertia`` (kg m^2, motor side) replaces the drive's
    J_m + J_r where a method estimates it on its own."""
    drive = joint.drive
    return DriveFields(
        name=joint.name,
        rotor_inertia=drive.rotor_inertia if rotor_inertia is None else rotor_inertia,
        motor_inertia=drive.motor_inertia,
        torque_constant=drive.torque_constant,
        friction=drive.friction,
    )


@dataclass(frozen=True)
class DriveEstimate:
    """One joint's identified drive, motor side: ``rotor_inertia`` = J_m + J_r and
    ``motor_inertia`` J_m (kg m^2), ``torque_constant`` k_t (N m/A), ``friction``
    (its model and parameters; ``--json`` writes ``{"model": name, **parameters}``); per parameter (``rotor_inertia``, ``torque_constant`` and the
    friction's linear parameters by name) its flag (:data:`FLAGS`) and its standard error from the
    residuals (None where not estimated: a parameter kept from the prior)."""

    name: str
    rotor_inertia: float
    motor_inertia: float
    torque_constant: float
    friction: Friction = field(metadata={"json": Friction.as_dict})
    flags: Mapping[str, Flag] = field(default_factory=dict)
    std: Mapping[str, float | None] = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class IdentificationResult:
    """An identified model with what the fit says about it.

    Attributes
    ----------
    robot : Robot
        The identified model (the input model with the identified parameters replaced); JSON
        gives its name.
    method : str
    joints : tuple of DriveEstimate
        Per joint, the identified drive (a method's subclass adds its standard errors and flags).
    fit : Fit
        Fit statistics on the identification logs (a method's subclass adds its diagnostics).
    inputs : InputLogs
        The logs it was identified from (by content) and what their checks found.
    accepted : tuple of str
        Checks that failed and the user accepted (``--accept``), with what they saw.
    standing_draw : StandingDraw or None
        The arm's standing draw found from the logs' measured supply (None where they do not
        measure it).
    """

    robot: Robot = field(metadata={"json": lambda r: r.name})
    method: str
    joints: tuple[DriveEstimate, ...]
    fit: Fit
    inputs: InputLogs = field(default_factory=InputLogs, metadata={"json": lambda i: i.records()})
    accepted: tuple[str, ...] = ()
    standing_draw: StandingDraw | None = None

    @property
    def warnings(self) -> list[str]:
        """What may make the model wrong: the logs' checks' and the fit's."""
        return [*self.inputs.warnings, *self.fit.warnings]

    @property
    def notes(self) -> list[str]:
        """What is routine: how the logs were read, values written, defaults kept."""
        return [*self.inputs.notes, *self.fit.notes]

    def to_dict(self) -> dict[str, Any]:
        """The ``identify --json`` shape: ``robot``, ``method``, ``joints``, ``fit``, ``inputs``,
        ``accepted``, ``notes`` and ``warnings``."""
        out = to_jsonable(self)
        assert isinstance(out, dict)
        out["notes"], out["warnings"] = self.notes, self.warnings
        return out


@dataclass(frozen=True, eq=False)
class Prediction:
    """A model's predictions on one log, each (N, n) or None when the log cannot be compared.

    ``torque`` is the controller's reference torque (UR5e eq 7, against ``target_moment``),
    ``current`` the motor current (eq 17, against ``actual_current``), ``joint_torque`` the torque
    a torque sensor reads (:func:`~kinergy.predict.sensor_torque`, against measured joint torques), ``supply`` (N,) what the arm
    draws from its supply, W (the bus model with the standing draw, :mod:`kinergy.drives.bus`;
    against ``actual_robot_voltage x actual_robot_current``).
    """

    torque: Array | None
    current: Array | None
    joint_torque: Array | None
    supply: Array | None = None

    def after(self, skip: int) -> Prediction:
        """The predictions from row ``skip`` on."""
        return Prediction(*(None if x is None else x[skip:] for x in vars(self).values()))


def predict(robot: Robot, data: IdentData) -> Prediction:
    """Predict what ``data``'s log recorded: reference torques on the commanded motion, currents
    and joint torques on the real motion."""
    torque = None
    if data.tau_ref is not None:
        torque = drive_state(robot, data.q_cmd, data.qd_cmd, data.qdd_cmd).tau_sim
    current = joint = supply = None
    measures = data.supply_voltage is not None and data.supply_current is not None
    if data.current is not None or data.torque is not None or measures:
        state = drive_state(robot, data.q, data.qd, data.qdd, temperature=data.temperature)
        current = state.current if data.current is not None else None
        joint = sensor_torque(robot, state) if data.torque is not None else None
        supply = supply_power(state.power, robot.standby_power).supply if measures else None
    return Prediction(torque, current, joint, supply)


def predictions(
    robot: Robot, logs: LogChunks, *fields: str
) -> Iterator[tuple[int, IdentData, Prediction]]:
    """:func:`predict` over every chunk (of the logs that have ``fields``): (segment number,
    chunk, predictions), friction held through standstill as in each whole log."""
    held = data_history(robot)
    for k, chunk in logs.chunks(*fields):
        data, skip = held.ahead(k, chunk)
        pred = predict(robot, data)
        held.update(data, skip)
        yield k, chunk, pred.after(skip)


def fit_fields(
    robot: Robot,
    logs: LogChunks,
    said: Messages,
) -> Fit:
    """The :class:`Fit` every method reports (its own fit extends it, ``**vars(fit)``): the
    identified ``robot``'s :func:`validation_metrics` on ``logs``, the samples, the logs, their
    lags (s) and what the fit ``said``."""
    return Fit(
        **vars(validation_metrics(robot, logs)),
        samples=sum(s.samples for s in logs.summaries),
        logs=logs.paths,
        lag=logs.lags,
        warnings=tuple(said.warnings),
        notes=tuple(said.notes),
    )


def validation_metrics(robot: Robot, logs: LogChunks | Sequence[IdentData]) -> Validation:
    """UR5e Tables V and VII over several logs (pooled): per joint mean, max, RMS error and R²
    (:class:`~kinergy.identification.metrics.SignalMetrics`: none, with a note, for a joint
    that did not move, as validation says) of the torque (against ``target_moment``), the current (against ``actual_current``) and, for
    arms with torque sensors, the joint torque. Where every log measures the supply, the
    predicted currents are kept (:attr:`LogChunks.currents`) for the standing draw's fit."""
    logs = logs if isinstance(logs, LogChunks) else LogChunks.of(logs)
    sums: dict[str, ExcitedSums] = {}
    keep = logs.every("supply_voltage", "current")
    kept = logs.derived() if keep else None
    for _, chunk, pred in predictions(robot, logs):
        for key, measured, predicted in (
            ("torque", chunk.tau_ref, pred.torque),
            ("current", chunk.current, pred.current),
            ("joint_torque", chunk.torque, pred.joint_torque),
        ):
            if measured is not None and predicted is not None:
                sums.setdefault(key, ExcitedSums(robot.n)).add(measured, predicted, chunk.q)
        if kept is not None:
            kept.put([pred.current])
    if kept is not None:
        logs.currents = (robot, kept)
    names = ("torque", "current", "joint_torque")
    return Validation(**{k: sums[k].metrics() if k in sums else None for k in names})
