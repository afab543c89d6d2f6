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
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.identification.metrics import JointMetrics, fit_metrics
from kinergy.identification.result import Validation, predict
from kinergy.logs.prepare import IdentData
from kinergy.logs.reading import InputLogs
from kinergy.model.robot import Robot

__all__ = [
    "EXCITED_RANGE",
    "HOLD_SECONDS",
    "HOLD_SPEED",
    "LogValidation",
    "SegmentedValidation",
    "SignalMetrics",
    "ValidationReport",
    "holding_mask",
    "validation_report",
]


#: rad/s: a sample where every joint is slower than this belongs to a static hold
HOLD_SPEED = 0.02
#: s: shortest static hold (shorter pauses count as motion)
HOLD_SECONDS = 0.5
#: rad: a joint whose position spans less than this over the samples is not excited
EXCITED_RANGE = 0.02
#: the signals compared, as (name, measured attribute of IdentData)
SIGNALS = (("torque", "tau_ref"), ("current", "current"), ("joint_torque", "torque"))
_FIELDS = ("measured", "predicted", "q", "holding")


@dataclass(frozen=True)
class SignalMetrics(JointMetrics):
    """:class:`JointMetrics` with the RMS error over the RMS of the measured signal (``nrms``)
    and a ``note`` where R^2 means nothing (``not excited``, ``signal constant``; None
    otherwise, R^2 then NaN, JSON null)."""

    nrms: float = float("nan")
    note: str | None = None


@dataclass(frozen=True)
class SegmentedValidation(Validation):
    """A :class:`Validation` (of :class:`SignalMetrics`) over ``samples`` samples, with the same
    figures over the ``moving`` and the ``holding`` samples (None when there are none) and the
    share of samples in static holds."""

    samples: int = 0
    holding_fraction: float = 0.0
    moving: Validation | None = None
    holding: Validation | None = None


@dataclass(frozen=True)
class LogValidation(SegmentedValidation):
    """One log's :class:`SegmentedValidation`."""

    log: str = ""


@dataclass(frozen=True)
class ValidationReport(SegmentedValidation):
    """``validate``'s result: the pooled :class:`SegmentedValidation` (its ``torque``,
    ``current``, ``joint_torque`` keep the ``validate --json`` keys), each log's, and what the
    logs were (by content) with their checks."""

    logs: tuple[LogValidation, ...] = ()
    inputs: InputLogs = field(default_factory=InputLogs, metadata={"json": lambda i: i.records()})
    notes: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()


def holding_mask(t: Array, qd: Array) -> NDArray[np.bool_]:
    """Samples of static holds: every joint slower than :data:`HOLD_SPEED` for at least
    :data:`HOLD_SECONDS`; ``t`` (N,) in s, ``qd`` (N, n) in rad/s -> (N,) bool."""
    still = np.all(np.abs(qd) < HOLD_SPEED, axis=1)
    mask = np.zeros_like(still)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(np.int8), [0]])))
    for start, stop in zip(edges[::2], edges[1::2], strict=True):
        if t[stop - 1] - t[start] >= HOLD_SECONDS:
            mask[start:stop] = True
    return mask


def _signal_metrics(measured: Array, predicted: Array, q: Array) -> tuple[SignalMetrics, ...]:
    """Per joint metrics of (N, n) signals, with the joint positions ``q`` (N, n) deciding which
    joints were excited."""
    out = []
    for j, m in enumerate(fit_metrics(measured, predicted)):
        spread = float(np.ptp(q[:, j])) if len(q) else 0.0
        level = float(np.sqrt(np.mean(measured[:, j] ** 2))) if len(q) else 0.0
        note = None
        if spread < EXCITED_RANGE:
            note = "not excited"
        elif not np.isfinite(m.r2):
            note = "signal constant"
        r2 = m.r2 if note is None else float("nan")
        nrms = m.rms / level if level > 0 else float("nan")
        out.append(SignalMetrics(m.mean, m.max, m.rms, r2, nrms, note))
    return tuple(out)


@dataclass(frozen=True, eq=False)
class _Signal:
    """One signal over some samples: measured and predicted (N, n), the joint positions (N, n)
    and which samples are static holds (N,)."""

    measured: Array
    predicted: Array
    q: Array
    holding: NDArray[np.bool_]

    def metrics(self, rows: NDArray[np.bool_]) -> tuple[SignalMetrics, ...] | None:
        if not rows.any():
            return None
        return _signal_metrics(self.measured[rows], self.predicted[rows], self.q[rows])


def _signals(robot: Robot, data: IdentData) -> dict[str, _Signal]:
    """The signals ``data`` logged, with ``robot``'s predictions."""
    pred = predict(robot, data)
    holding = holding_mask(data.t, data.qd)
    out = {}
    for name, attr in SIGNALS:
        measured, predicted = getattr(data, attr), getattr(pred, name)
        if measured is not None and predicted is not None:
            out[name] = _Signal(np.asarray(measured), np.asarray(predicted), data.q, holding)
    return out


def _segmented(signals: dict[str, _Signal], t_holding: NDArray[np.bool_]) -> dict[str, object]:
    """The fields of a :class:`SegmentedValidation` of ``signals``; ``t_holding`` (N,) marks the
    static holds among all the samples."""
    parts = {}
    for key, select in (("whole", None), ("moving", False), ("holding", True)):
        metrics = {
            k: s.metrics(np.ones(len(s.q), bool) if select is None else s.holding == select)
            for k, s in signals.items()
        }
        parts[key] = None if all(m is None for m in metrics.values()) else metrics
    return {
        **(parts["whole"] or {}),
        "samples": len(t_holding),
        "holding_fraction": float(np.mean(t_holding)) if len(t_holding) else 0.0,
        "moving": None if parts["moving"] is None else Validation(**parts["moving"]),
        "holding": None if parts["holding"] is None else Validation(**parts["holding"]),
    }


def validation_report(robot: Robot, datas: Sequence[IdentData]) -> ValidationReport:
    """How well ``robot`` predicts ``datas``: pooled and per log, moving and holding apart
    (module docstring)."""
    per_log = [_signals(robot, d) for d in datas]
    holds = [holding_mask(d.t, d.qd) for d in datas]
    logs = tuple(
        LogValidation(**_segmented(sig, hold), log=str(d.path))  # type: ignore[arg-type]
        for sig, hold, d in zip(per_log, holds, datas, strict=True)
    )
    pooled = {}
    for name, _ in SIGNALS:
        found = [sig[name] for sig in per_log if name in sig]
        if found:
            pooled[name] = _Signal(
                *(np.concatenate([getattr(f, a) for f in found]) for a in _FIELDS)
            )
    every = np.concatenate(holds) if holds else np.zeros(0, dtype=bool)
    return ValidationReport(**_segmented(pooled, every), logs=logs)  # type: ignore[arg-type]
