"""``validate``: how well a model predicts logs, per log and pooled, moving and holding apart.

The pooled figures are the UR5e doc's Tables V and VII (``torque`` against ``target_moment``,
``current`` against ``actual_current``, ``joint_torque`` against measured joint torques), with two
additions per joint: the RMS error normalised by the RMS of the measured signal (``nrms``), and a
``note`` where R^2 means nothing: a joint that hardly moved over the samples (``not excited``: its
position spans less than :data:`EXCITED_RANGE`) or a signal that does not vary. Controller logs of
point-to-point programs are mostly static holds, where the current is the holding torque plus a
wandering standstill friction no motion model predicts; so every figure is given again for the
``moving`` and the ``holding`` samples apart (holding: every joint slower than
:data:`HOLD_SPEED` for at least :data:`HOLD_SECONDS`), and for each log on its own.

Where the logs measure the arm's supply (``actual_robot_voltage`` x ``actual_robot_current``),
``supply`` compares the power the model says the arm draws (the bus model with the standing
draw) with it: RMS error and R^2 of the power, and the energy of each with the prediction's
error (:class:`SupplyValidation`).

Every figure is accumulated over each log's chunks in one pass (:func:`validation_report`), so a
log of any length is validated in bounded memory.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.identification.chunks import Segment, WholeSegment, data_history
from kinergy.identification.metrics import (
    EXCITED_RANGE,
    ExcitedSums,
    MetricSums,
    SignalMetrics,
)
from kinergy.identification.prediction_band import (
    NO_BAND,
    BandTally,
    PredictionBand,
    band_method,
    half_widths,
)
from kinergy.identification.result import Prediction, Validation, predict
from kinergy.identification.sanity import check_signals
from kinergy.identification.uncertainty import current_shifts, torque_shifts
from kinergy.io.formats import CHUNK_ROWS
from kinergy.jsonable import to_jsonable
from kinergy.logs.prepare import IdentData
from kinergy.logs.reading import InputLogs
from kinergy.model.robot import Robot, transmission_matrix
from kinergy.predict import drive_state

__all__ = [
    "EXCITED_RANGE",
    "HOLD_SECONDS",
    "HOLD_SPEED",
    "PLOT_SAMPLES",
    "LogValidation",
    "SegmentedValidation",
    "Series",
    "SignalMetrics",
    "SupplyValidation",
    "ValidationReport",
    "holding_mask",
    "validation_report",
]


#: rad/s: a sample where every joint is slower than this belongs to a static hold
HOLD_SPEED = 0.02
#: s: shortest static hold (shorter pauses count as motion)
HOLD_SECONDS = 0.5
#: most samples of one log kept for plots (:attr:`LogValidation.series`); a longer log's plots
#: show every k-th sample
PLOT_SAMPLES = 200_000
#: the signals compared, as (name, measured attribute of IdentData)
SIGNALS = (("torque", "tau_ref"), ("current", "current"), ("joint_torque", "torque"))


@dataclass(frozen=True)
class SupplyValidation:
    """The arm's supply power, predicted (the bus model plus the standing draw) against
    measured (``actual_robot_voltage x actual_robot_current``) over ``samples`` samples: mean,
    largest ``|.|`` and RMS of the error (measured - predicted), W, and R^2 of the power; the
    energy of each (trapezoid over each log, J) and the prediction's error against the
    measured, %."""

    mean: float
    max: float
    rms: float
    r2: float
    predicted: float
    measured: float
    error: float
    samples: int
    includes: str = (
        "predicted: the motors' powers summed on the DC bus (braking surplus to the shunt) plus "
        "the model's standing draw; measured: actual_robot_voltage x actual_robot_current"
    )


@dataclass(frozen=True)
class SegmentedValidation(Validation):
    """A :class:`Validation` (of :class:`SignalMetrics`) over ``samples`` samples, with the same
    figures over the ``moving`` and the ``holding`` samples (None when there are none), the
    share of samples in static holds, where the logs measure it, the supply's power
    (:class:`SupplyValidation`; None otherwise) and, where the model carries its parameters'
    errors, the 95 % prediction band of the current and reference torque
    (:class:`~kinergy.identification.prediction_band.PredictionBand`; for a model without
    them, the pooled report's says so)."""

    samples: int = 0
    holding_fraction: float = 0.0
    moving: Validation | None = None
    holding: Validation | None = None
    supply: SupplyValidation | None = None
    band: PredictionBand | None = None


@dataclass(frozen=True, eq=False)
class Series:
    """One signal of one log for plots: time from the log's start (N,) s, the measured and the
    predicted values (N, n), every ``step``-th sample of the log, and the 95 % prediction
    band's half-width (N, n; None: the model carries no errors)."""

    t: Array
    measured: Array
    predicted: Array
    step: int = 1
    band: Array | None = None


@dataclass(frozen=True)
class LogValidation(SegmentedValidation):
    """One log's :class:`SegmentedValidation`, and its signals for plots (:class:`Series`, by
    signal name; not in JSON)."""

    log: str = ""
    series: Mapping[str, Series] = field(default_factory=dict, metadata={"json": False})


@dataclass(frozen=True)
class ValidationReport(SegmentedValidation):
    """``validate``'s result: the pooled :class:`SegmentedValidation` (its ``torque``,
    ``current``, ``joint_torque`` keep the ``validate --json`` keys), each log's, and what the
    logs were (by content) with their checks."""

    logs: tuple[LogValidation, ...] = ()
    inputs: InputLogs = field(default_factory=InputLogs, metadata={"json": lambda i: i.records()})
    notes: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """``kinergy validate --json`` (without where the command came from)."""
        out: dict[str, Any] = to_jsonable(self)
        return out


def holding_mask(t: Array, qd: Array) -> NDArray[np.bool_]:
    """Samples of static holds: every joint slower than :data:`HOLD_SPEED` for at least
    :data:`HOLD_SECONDS`; ``t`` (N,) in s, ``qd`` (N, n) in rad/s -> (N,) bool."""
    return _Holds().mask(t, qd, closed=True)[0]


def _signal_metrics(measured: Array, predicted: Array, q: Array) -> tuple[SignalMetrics, ...]:
    """Per joint metrics of (N, n) signals, with the joint positions ``q`` (N, n) deciding which
    joints were excited."""
    part = ExcitedSums(q.shape[1])
    part.add(measured, predicted, q)
    metrics = part.metrics()
    assert metrics is not None, "no samples"
    return metrics


@dataclass(frozen=True, eq=False)
class _Rows:
    """Consecutive samples of one log: time (N,) s, the real joint positions and speeds (N, n)
    and, per signal name, the measured and predicted values (N, n)."""

    t: Array
    q: Array
    qd: Array
    signals: dict[str, tuple[Array, Array]]
    bands: dict[str, Array] = field(default_factory=dict)

    def take(self, rows: slice) -> _Rows:
        return _Rows(
            self.t[rows],
            self.q[rows],
            self.qd[rows],
            {k: (m[rows], p[rows]) for k, (m, p) in self.signals.items()},
            {k: b[rows] for k, b in self.bands.items()},
        )

    def then(self, later: _Rows) -> _Rows:
        """These samples, then ``later``'s."""

        def cat(a: Array, b: Array) -> Array:
            return np.concatenate([a, b])

        return _Rows(
            cat(self.t, later.t),
            cat(self.q, later.q),
            cat(self.qd, later.qd),
            {
                k: (cat(m, later.signals[k][0]), cat(p, later.signals[k][1]))
                for k, (m, p) in self.signals.items()
            },
            {k: cat(b, later.bands[k]) for k, b in self.bands.items() if k in later.bands},
        )


class _Holds:
    """:func:`holding_mask` of one log over its chunks, in time order (the same mask as of the
    whole log). A sample is decided once the still run it belongs to has lasted
    :data:`HOLD_SECONDS` (a hold, whatever follows) or has ended; the samples of a still run
    still shorter than that at the end of a chunk wait for the next (at most
    :data:`HOLD_SECONDS` of samples)."""

    def __init__(self) -> None:
        self.waiting: _Rows | None = None
        self.in_hold = False  # the decided samples end in a hold that may go on

    def mask(self, t: Array, qd: Array, closed: bool) -> tuple[NDArray[np.bool_], int]:
        """The holding mask of samples ``t`` (N,), ``qd`` (N, n) following the decided ones,
        and how many of them are decided (all when the log ends with them, ``closed``)."""
        still = np.all(np.abs(qd) < HOLD_SPEED, axis=1)
        mask = np.zeros_like(still)
        decided = len(still)
        edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(np.int8), [0]])))
        for start, stop in zip(edges[::2], edges[1::2], strict=True):
            if t[stop - 1] - t[start] >= HOLD_SECONDS or (start == 0 and self.in_hold):
                mask[start:stop] = True
            elif stop == len(still) and not closed:
                decided = int(start)
        self.in_hold = bool(decided == len(still) and len(still) and mask[-1])
        return mask[:decided], decided

    def feed(self, rows: _Rows, closed: bool = False) -> tuple[_Rows, NDArray[np.bool_]]:
        """The samples now decided (those waiting, then ``rows``'s) and their holding mask."""
        if self.waiting is not None:
            rows = self.waiting.then(rows)
        mask, decided = self.mask(rows.t, rows.qd, closed)
        self.waiting = rows.take(slice(decided, None)) if decided < len(rows.t) else None
        return rows.take(slice(0, decided)), mask


_PARTS = ("whole", "moving", "holding")


class _Tally:
    """The figures of one log (or of all): per signal over all, the moving and the holding
    samples (:class:`ExcitedSums`), and how many samples and holding samples there were."""

    def __init__(self, n: int):
        self.n = n
        self.parts: dict[str, dict[str, ExcitedSums]] = {}
        self.samples = 0
        self.held = 0

    def add(self, rows: _Rows, holding: NDArray[np.bool_]) -> None:
        self.samples += len(holding)
        self.held += int(holding.sum())
        for name, (measured, predicted) in rows.signals.items():
            parts = self.parts.setdefault(name, {key: ExcitedSums(self.n) for key in _PARTS})
            parts["whole"].add(measured, predicted, rows.q)
            for key, sel in (("moving", ~holding), ("holding", holding)):
                parts[key].add(measured[sel], predicted[sel], rows.q[sel])

    def fields(self) -> dict[str, object]:
        """The fields of a :class:`SegmentedValidation`."""
        found = {}
        for key in _PARTS:
            metrics = {name: parts[key].metrics() for name, parts in self.parts.items()}
            found[key] = None if all(m is None for m in metrics.values()) else metrics
        return {
            **(found["whole"] or {}),
            "samples": self.samples,
            "holding_fraction": self.held / self.samples if self.samples else 0.0,
            "moving": None if found["moving"] is None else Validation(**found["moving"]),
            "holding": None if found["holding"] is None else Validation(**found["holding"]),
        }


class _SupplyTally:
    """:class:`SupplyValidation` accumulated chunk by chunk: the power's error statistics and
    the two energies by the trapezoid rule, the last sample of a chunk carried into the next
    one (one tally per log; :meth:`merge` pools them)."""

    def __init__(self) -> None:
        self.sums = MetricSums(1)
        self.energy = np.zeros(2)  # predicted, measured
        self.last: tuple[float, Array] | None = None

    def add(self, t: Array, predicted: Array, measured: Array) -> None:
        if not len(t):
            return
        self.sums.add(measured[:, None], predicted[:, None])
        y = np.column_stack([predicted, measured])
        if self.last is not None:
            t0, y0 = self.last
            self.energy += 0.5 * (t[0] - t0) * (y0 + y[0])
        if len(t) > 1:
            self.energy += np.sum(0.5 * np.diff(t)[:, None] * (y[1:] + y[:-1]), axis=0)
        self.last = (float(t[-1]), y[-1].copy())

    def merge(self, other: _SupplyTally) -> None:
        """Add ``other``'s samples and energies (another log's)."""
        if other.sums.count == 0:
            return
        self.energy += other.energy
        self.sums.merge(other.sums)

    def result(self) -> SupplyValidation | None:
        if self.sums.count == 0:
            return None
        (m,) = self.sums.metrics()
        predicted, measured = (float(x) for x in self.energy)
        error = 100.0 * (predicted / measured - 1.0) if measured else float("nan")
        return SupplyValidation(
            m.mean, m.max, m.rms, m.r2, predicted, measured, error, self.sums.count
        )


class _Sampled:
    """Every ``step``-th sample of a log's signals, chunk by chunk (:class:`Series`)."""

    def __init__(self, step: int):
        self.step, self.seen, self.t0 = step, 0, 0.0
        self.parts: dict[str, list[tuple[Array, Array, Array]]] = {}
        self.bands: dict[str, list[Array]] = {}

    def add(self, rows: _Rows) -> None:
        if self.seen == 0 and len(rows.t):
            self.t0 = float(rows.t[0])
        at = slice((-self.seen) % self.step, None, self.step)
        self.seen += len(rows.t)
        for name, (measured, predicted) in rows.signals.items():
            self.parts.setdefault(name, []).append((rows.t[at], measured[at], predicted[at]))
        for name, band in rows.bands.items():
            self.bands.setdefault(name, []).append(band[at])

    def series(self) -> dict[str, Series]:
        out = {}
        for name, parts in self.parts.items():
            t, measured, predicted = (np.concatenate(x) for x in zip(*parts, strict=True))
            band = np.concatenate(self.bands[name]) if name in self.bands else None
            out[name] = Series(t - self.t0, measured, predicted, self.step, band)
        return out


def _rows(robot: Robot, data: IdentData, pred: Prediction) -> _Rows:
    """``data``'s samples with the signals it logged and ``robot`` predicts."""
    signals = {}
    for name, attr in SIGNALS:
        measured, predicted = getattr(data, attr), getattr(pred, name)
        if measured is not None and predicted is not None:
            signals[name] = (np.asarray(measured), np.asarray(predicted))
    return _Rows(data.t, data.q, data.qd, signals)


#: the signals the prediction band covers
_BANDED = ("current", "torque")


def _band_shifts(model: Robot, data: IdentData, skip: int, rows: _Rows) -> dict[str, Array]:
    """The error modes' shifts (K, N, n) of ``model``'s predictions of ``rows``'s current and
    reference torque (``data``: the chunk with the ``skip`` rows ahead of it), and the band's
    half-widths into ``rows.bands``."""
    u = model.uncertainty
    assert u is not None
    shifts: dict[str, Array] = {}
    if "current" in rows.signals:
        state = drive_state(model, data.q, data.qd, data.qdd, temperature=data.temperature)
        shifts["current"] = current_shifts(model, state, data.temperature)[:, skip:]
    if "torque" in rows.signals:
        dwm = np.asarray(data.qdd_cmd) @ transmission_matrix(model).T
        shifts["torque"] = torque_shifts(model, dwm)[:, skip:]
    for name, moved in shifts.items():
        rows.bands[name] = half_widths(u, moved, name)
    return shifts


def _band(tallies: dict[str, BandTally] | None, model: Robot) -> PredictionBand | None:
    if tallies is None:
        return None
    assert model.uncertainty is not None
    return PredictionBand(
        method=band_method(model.uncertainty),
        current=tallies["current"].result(),
        torque=tallies["torque"].result(),
    )


def validation_report(
    robot: Robot,
    logs: Sequence[Segment | IdentData],
    *,
    rows: int = CHUNK_ROWS,
    plot_samples: int = 0,
    robots: Sequence[Robot] | None = None,
) -> ValidationReport:
    """How well ``robot`` predicts ``logs`` (prepared segments, or prepared logs in memory):
    pooled and per log, moving and holding apart (module docstring), in one pass over each
    log's chunks of ``rows`` samples (the same figures to round-off, whatever the chunks).

    Friction held through standstill is predicted as in the whole log
    (:func:`~kinergy.identification.chunks.data_history`). With ``plot_samples`` > 0, each
    log's :attr:`LogValidation.series` keeps its signals for plots: every sample of a log up to
    that many samples, every ``k``-th of a longer one (the figures use every sample).
    ``robots``: each log's model where they differ (the payload each log's controller logged:
    :meth:`kinergy.logs.prepare.PreparedSegment.robot`); default ``robot`` for every log.

    Raises
    ------
    KinergyError
        A chunk's signal not finite or beyond what a robot logs
        (:func:`~kinergy.identification.sanity.check_signals`).
    """
    segments = [WholeSegment(x) if isinstance(x, IdentData) else x for x in logs]
    pooled = _Tally(robot.n)
    held = data_history(robot)
    out = []
    pooled_supply = _SupplyTally()
    errors = robot.uncertainty
    modes = 0 if errors is None else errors.modes.shape[0]
    pooled_band = None if errors is None else {s: BandTally(modes, robot.n) for s in _BANDED}
    for k, segment in enumerate(segments):
        tally, holds, supply = _Tally(robot.n), _Holds(), _SupplyTally()
        bands = None if errors is None else {s: BandTally(modes, robot.n) for s in _BANDED}
        sampled = _Sampled(-(-len(segment) // plot_samples)) if plot_samples > 0 else None
        model = robot if robots is None else robots[k]
        for chunk in segment.chunks(rows):
            check_signals([chunk])
            data, skip = held.ahead(k, chunk)
            pred = predict(model, data).after(skip)
            if pred.supply is not None:
                assert chunk.supply_voltage is not None and chunk.supply_current is not None
                supply.add(chunk.t, pred.supply, chunk.supply_voltage * chunk.supply_current)
            found = _rows(robot, chunk, pred)
            if bands is not None and model.uncertainty is not None:
                for name, moved in _band_shifts(model, data, skip, found).items():
                    bands[name].add(*found.signals[name], moved, found.bands[name])
            held.update(data, skip)
            if sampled is not None:
                sampled.add(found)
            decided, holding = holds.feed(found)
            tally.add(decided, holding)
            pooled.add(decided, holding)
        if holds.waiting is not None:  # a still run shorter than a hold ends the log
            last = holds.waiting
            tally.add(last, np.zeros(len(last.t), dtype=bool))
            pooled.add(last, np.zeros(len(last.t), dtype=bool))
        series = {} if sampled is None else sampled.series()
        pooled_supply.merge(supply)
        if bands is not None and pooled_band is not None:
            for name, part in bands.items():
                pooled_band[name].merge(part)
        fields = {**tally.fields(), "supply": supply.result(), "band": _band(bands, model)}
        out.append(LogValidation(**fields, log=str(segment.path), series=series))  # type: ignore[arg-type]
    band = _band(pooled_band, robot) if errors is not None else PredictionBand(note=NO_BAND)
    fields = {**pooled.fields(), "supply": pooled_supply.result(), "band": band}
    return ValidationReport(**fields, logs=tuple(out))  # type: ignore[arg-type]
