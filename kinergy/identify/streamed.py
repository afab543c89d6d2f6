"""The sequential identification and the motor electrics from logs read in chunks: memory
bounded by a chunk, whatever the logs' length.

:class:`LogsInChunks` gives :func:`kinergy.identify.sequential.sequential_from` what it needs of
the logs (:class:`~kinergy.identify.sequential.SequentialLogs`) by passes over their chunks, each
folding the chunk into a small accumulator and dropping it:

1. on construction: the signals' sanity (:func:`~kinergy.identify.sanity.check_signals` per
   chunk), the joints' position spans and speed summary, and step 2's least squares (UR5e eqs
   7-9) folded into its QR triangle (:func:`~kinergy.identify.drive_steps.rotor_problem`: a
   streaming QR, numerically as good as one factorisation of all rows); the prepared chunks are
   written to an unnamed temporary file (:class:`_Store`), which the later passes read instead of
   preparing them again;
2. :meth:`LogsInChunks.fitter`: eq 18's triangle per motor and standstill hold (UR5e eqs 17-18);
3. :meth:`LogsInChunks.validation`: the fit statistics (:class:`~kinergy.identify.metrics.MetricSums`)
   and, in the same pass when the model holds no friction through standstill, eq 19 per motor
   (:class:`~kinergy.identify.electrics.ElectricsSums`, :meth:`LogsInChunks.electrics`) with the
   predicted currents kept for the standby power;
4. :meth:`LogsInChunks.standby`: the mean standby power (from the kept currents through UR5e eq
   23 when the model's mechanics are unchanged, else by another pass); :meth:`LogsInChunks.electrics`
   makes its own pass only when step 3 could not.

Memory holds one chunk and these accumulators, whatever the logs' length; the temporary files
(the log's spill, :mod:`kinergy.logs.prepare`, and the prepared chunks) hold the samples
on disk and are removed when closed.

Friction held through standstill (:mod:`kinergy.friction.standstill`) is the one thing that
reaches back in time without bound: a stopped joint keeps the friction of the last sample it
moved in. Each pass carries, per motor, that sample into the next chunk and puts it in front of
the chunk (then drops its result), so the hold sees what it would see in the whole log; it
restarts at each log where the in-memory code restarts it (the fit statistics are per log, the
current fit and the electrics run over all logs stacked).

Which fits stream: the sequential method with a fixed friction model whose shape needs no search
(``friction="auto"``'s cross-validation and ``power_law``'s exponent search refit many times:
:func:`streams` says no, and they run in memory).
"""

from __future__ import annotations

import dataclasses
import itertools
import os
import tempfile
from collections.abc import Iterator, Sequence
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.drives.bus import supply_power
from kinergy.drives.electrics import electrical_power, equivalent_voltage, torque_constants
from kinergy.drives.transmission import transmission_matrix
from kinergy.errors import KinergyError
from kinergy.friction.registry import get_model
from kinergy.friction.standstill import MIN_RUN, sustained
from kinergy.identify.drive_steps import (
    STILL_SPEED,
    FrictionChoice,
    JointFitter,
    _columns,
    _CurrentFit,
    _Signals,
    best_hold,
    holdings_of,
    motor_signals,
    rotor_problem,
    solve_current,
    start_params,
)
from kinergy.identify.electrics import ElectricsFit, ElectricsSums
from kinergy.identify.metrics import MetricSums
from kinergy.identify.result import Validation, predict
from kinergy.identify.sanity import STILL_SPAN, check_signals
from kinergy.identify.sequential import MotionSummary
from kinergy.io.formats import CHUNK_ROWS
from kinergy.linalg import Reduced
from kinergy.logs.prepare import SAMPLE_FIELDS, IdentData
from kinergy.model.robot import Joint, Robot
from kinergy.predict import drive_state

__all__ = ["LogsInChunks", "Segment", "WholeSegment", "streams"]


class Segment(Protocol):
    """One log (segment) that yields its prepared samples in chunks, in time order."""

    @property
    def path(self) -> str: ...

    @property
    def lag(self) -> float: ...

    def __len__(self) -> int: ...

    def chunks(self, rows: int = CHUNK_ROWS) -> Iterator[IdentData]: ...


class WholeSegment:
    """A prepared log held whole, cut into chunks (:class:`Segment`)."""

    def __init__(self, data: IdentData):
        self.data = data
        self.path = data.path
        self.lag = data.lag

    def __len__(self) -> int:
        return len(self.data)

    def chunks(self, rows: int = CHUNK_ROWS) -> Iterator[IdentData]:
        for start in range(0, len(self.data), rows):
            yield self.data.sliced(start, min(start + rows, len(self.data)))


def streams(robot: Robot, method: str, friction: str | None) -> bool:
    """Whether :class:`LogsInChunks` runs this identification (module docstring)."""
    if method != "sequential" or friction == "auto":
        return False
    models = {friction or j.drive.friction.model for j in robot.joints}
    return not any(get_model(m).search for m in models)


class _History:
    """What friction held through standstill (:func:`kinergy.friction.standstill.hold`) needs
    of the samples before a chunk, whatever their number: per motor the run of the last
    sustained motion (its last :data:`~kinergy.friction.standstill.MIN_RUN` samples: the held
    friction is that run's last sample's) and the last ``MIN_RUN - 1`` samples (a run that goes
    on into the chunk). :meth:`ahead` puts them in front of a chunk in time order, a sample at
    rest for every motor (speeds and accelerations zero) between stretches that are not
    contiguous, so no run joins across a left-out stretch. A run seen in part is never longer
    than it is, and each remembered run is seen whole enough to count as sustained, so every
    sample of the chunk is held as in the whole log (``tests/test_identify_stream.py``).

    ``rows`` of any sample container with ``take(x, index)`` (those rows, in order),
    ``join(parts)``, ``at_rest(x)`` (one row, speeds zeroed) and ``speeds(x)`` ((N, m) motor
    speeds, rad/s); ``still`` (m,) the speeds below which each motor is at rest.
    """

    def __init__(self, still: Sequence[float], take: Any, join: Any, at_rest: Any, speeds: Any):
        self.still = np.asarray(still, dtype=float)
        self.take, self.join, self.at_rest, self.speeds = take, join, at_rest, speeds
        self.reset()

    def reset(self) -> None:
        """A new log: nothing is held (the hold restarts in each log)."""
        self.rows: Any = None  # the remembered samples, in time order
        self.index = np.empty(0, dtype=np.int64)  # their sample numbers in the log
        self.seen = 0

    @property
    def active(self) -> bool:
        return bool(np.any(self.still > 0.0))

    def ahead(self, chunk: Any) -> tuple[Any, int]:
        """``chunk`` with the remembered samples in front, and how many rows were put there."""
        if not self.active or self.rows is None:
            return chunk, 0
        parts: list[Any] = []
        cuts = np.flatnonzero(np.diff(self.index) > 1) + 1
        for k, (lo, hi) in enumerate(itertools.pairwise([0, *cuts.tolist(), self.index.size])):
            if k > 0:
                parts.append(self.at_rest(self.take(self.rows, np.array([lo]))))
            parts.append(self.take(self.rows, np.arange(lo, hi)))
        joined = self.join([*parts, chunk])
        return joined, self._length(joined) - self._length(chunk)

    def update(self, joined: Any, skip: int) -> None:
        """Remember what the samples so far leave for the next chunk (``joined`` as
        :meth:`ahead` gave it, ``skip`` rows in front)."""
        if not self.active:
            return
        rows = self._length(joined) - skip
        numbers = np.full(self._length(joined), -1, dtype=np.int64)
        numbers[skip:] = self.seen + np.arange(rows)
        if skip:  # the remembered samples' numbers; rest rows between stretches stay -1
            cuts = np.flatnonzero(np.diff(self.index) > 1)
            real = np.ones(skip, dtype=bool)
            real[cuts + 1 + np.arange(cuts.size)] = False
            numbers[:skip][real] = self.index
        wm = self.speeds(joined)
        keep = set(range(max(0, self.seen + rows - (MIN_RUN - 1)), self.seen + rows))
        for m, still in enumerate(self.still):
            if still <= 0.0:
                continue
            moving = sustained(np.abs(wm[:, m]) >= still, wm[:, m])
            if moving.any():
                last = int(numbers[np.flatnonzero(moving)[-1]])
                keep.update(range(last - MIN_RUN + 1, last + 1))
        wanted = np.array(sorted(keep), dtype=np.int64)
        where = {int(n): k for k, n in enumerate(numbers) if n >= 0}
        self.rows = self.take(joined, np.array([where[int(n)] for n in wanted], dtype=np.int64))
        self.index = wanted
        self.seen += rows

    def _length(self, x: Any) -> int:
        return int(self.speeds(x).shape[0])


def _data_history(robot: Robot) -> _History:
    """A :class:`_History` of prepared samples (:class:`IdentData`) for ``robot``'s friction."""
    n_mat = transmission_matrix(robot)
    still = [float(j.drive.friction.params.get("standstill", 0.0)) for j in robot.joints]

    def take(x: IdentData, index: NDArray[np.int64]) -> IdentData:
        return (
            IdentData.joined([x.sliced(int(k), int(k) + 1) for k in index])
            if index.size
            else x.sliced(0, 0)
        )

    def at_rest(x: IdentData) -> IdentData:
        zero = np.zeros_like(x.qd)
        return dataclasses.replace(x, qd=zero, qdd=zero, qd_cmd=zero, qdd_cmd=zero)

    return _History(still, take, IdentData.joined, at_rest, lambda x: x.qd @ n_mat.T)


def _signal_history(still: float) -> _History:
    """A :class:`_History` of one motor's eq 18 signals (:class:`_Signals`)."""

    def take(x: _Signals, index: NDArray[np.int64]) -> _Signals:
        t = None if x.temperature is None else x.temperature[index]
        return _Signals(x.tau_load[index], x.wm[index], x.dwm[index], x.current[index], t)

    def join(parts: Sequence[_Signals]) -> _Signals:
        out = parts[0]
        for part in parts[1:]:
            out = _cat(out, part)
        return out

    def at_rest(x: _Signals) -> _Signals:
        return dataclasses.replace(x, wm=np.zeros_like(x.wm), dwm=np.zeros_like(x.dwm), piece=None)

    return _History([still], take, join, at_rest, lambda x: x.wm[:, None])


def _state(robot: Robot, held: _History, chunk: IdentData, temperature: bool) -> Array:
    """The chunk's motor currents and electrical powers under ``robot`` (:func:`drive_state`,
    friction held as in its whole log), each (N, n)."""
    data, k = held.ahead(chunk)
    temp = data.temperature if temperature else None
    state = drive_state(robot, data.q, data.qd, data.qdd, temperature=temp)
    held.update(data, k)
    return np.stack([state.current[k:], state.power[k:]])


class _Spool:
    """Blocks of float arrays written once to an unnamed temporary file (removed when closed)
    and read back in order."""

    def __init__(self) -> None:
        self.file = tempfile.TemporaryFile()
        self.index: list[tuple[int, list[tuple[int, ...]]]] = []
        self.end = 0

    def put(self, arrays: Sequence[Array]) -> None:
        """Append one block."""
        data = b"".join(np.ascontiguousarray(a, dtype=float).tobytes() for a in arrays)
        self.file.write(data)
        self.index.append((self.end, [np.shape(a) for a in arrays]))
        self.end += len(data)

    def __iter__(self) -> Iterator[list[Array]]:
        self.file.flush()
        for k, (offset, shapes) in enumerate(self.index):
            stop = self.index[k + 1][0] if k + 1 < len(self.index) else self.end
            raw = np.frombuffer(os.pread(self.file.fileno(), stop - offset, offset), dtype=float)
            out, at = [], 0
            for shape in shapes:
                size = int(np.prod(shape))
                out.append(raw[at : at + size].reshape(shape))
                at += size
            yield out

    def close(self) -> None:
        self.file.close()


class _Store:
    """Prepared chunks kept in a :class:`_Spool`: later passes do not prepare them again
    (splines, resampling)."""

    def __init__(self) -> None:
        self.spool = _Spool()
        self.shells: list[tuple[int, list[str], IdentData]] = []

    def put(self, segment: int, chunk: IdentData) -> None:
        """Append ``chunk`` of segment number ``segment``."""
        present = [(n, getattr(chunk, n)) for n in SAMPLE_FIELDS if getattr(chunk, n) is not None]
        self.spool.put([a for _, a in present])
        # no sample, and no view of the chunk's arrays (which would keep them alive)
        empty: dict[str, Any] = {n: np.empty((0, *a.shape[1:])) for n, a in present}
        shell = dataclasses.replace(chunk.sliced(0, 0), **empty)
        self.shells.append((segment, [n for n, _ in present], shell))

    def chunks(self) -> Iterator[tuple[int, IdentData]]:
        """(segment number, chunk) in the order they were put."""
        for (segment, names, shell), arrays in zip(self.shells, self.spool, strict=True):
            fields: dict[str, Any] = dict(zip(names, arrays, strict=True))
            yield segment, dataclasses.replace(shell, **fields)

    def close(self) -> None:
        self.spool.close()


class LogsInChunks:
    """Prepared logs read in chunks of ``rows`` samples (:class:`~kinergy.identify.sequential.SequentialLogs`
    for :func:`~kinergy.identify.sequential.sequential_from`); step 2's rows for ``robot``.

    Raises
    ------
    KinergyError
        As :func:`~kinergy.identify.sanity.check_signals` and
        :func:`~kinergy.identify.sanity.check_motion`.
    """

    def __init__(self, robot: Robot, segments: Sequence[Segment], rows: int = CHUNK_ROWS):
        self.segments, self.rows, self.robot = list(segments), rows, robot
        self.paths = tuple(s.path for s in self.segments)
        self.lags = tuple(s.lag for s in self.segments)
        self.samples = int(sum(len(s) for s in self.segments))
        self.has: list[dict[str, bool]] = []
        self.seconds = 0.0
        self._summary: MotionSummary | None = None
        self._electrics: tuple[Robot, list[ElectricsSums]] | None = None
        self._drawn: tuple[Robot, _Spool] | None = None
        problem, span = Reduced.empty(robot.n), 0.0
        self.store = _Store()
        for k, segment in enumerate(self.segments):
            low = high = None
            first = True
            for chunk in segment.chunks(rows):
                check_signals([chunk])
                self.store.put(k, chunk)
                if first:
                    self.has.append({f: getattr(chunk, f) is not None for f in SAMPLE_FIELDS})
                    t0, first = float(chunk.t[0]), False
                low = chunk.q.min(axis=0) if low is None else np.minimum(low, chunk.q.min(axis=0))
                high = (
                    chunk.q.max(axis=0) if high is None else np.maximum(high, chunk.q.max(axis=0))
                )
                summary = MotionSummary.of(chunk.qd)
                self._summary = summary if self._summary is None else self._summary.merged(summary)
                if chunk.tau_ref is not None:
                    problem = rotor_problem(robot, [chunk], into=problem)
                t1 = float(chunk.t[-1])
            assert low is not None and high is not None
            span = max(span, float(np.max(high - low)))
            self.seconds += t1 - t0
        if span < STILL_SPAN:
            raise KinergyError(
                f"no joint moves in these logs (largest position span {span:.2g} rad, below "
                f"{STILL_SPAN} rad): nothing to identify from"
            )
        self.has_ref = any(h["tau_ref"] for h in self.has)
        self.has_current = any(h["current"] for h in self.has)
        self._rotor = problem if self.has_ref else None

    def _every(self, *fields: str) -> bool:
        return bool(self.segments) and all(all(h[f] for f in fields) for h in self.has)

    def _chunks(self, field: str | None = None) -> Iterator[tuple[int, IdentData]]:
        """(segment index, chunk) of every segment (that has ``field``), in order."""
        for k, chunk in self.store.chunks():
            if field is None or self.has[k][field]:
                yield k, chunk

    def summary(self) -> MotionSummary:
        assert self._summary is not None
        return self._summary

    def rotor_problem(self, robot: Robot) -> Reduced | None:
        if robot is not self.robot:
            raise ValueError("step 2 was folded in for another robot")
        return self._rotor

    def fitter(
        self, staged: Robot, rotor: Array, options: tuple[str | None, str | bool]
    ) -> JointFitter:
        """Eq 18's triangles of every motor and standstill hold, in one pass (module docstring)."""
        friction, hold = options
        if not streams(staged, "sequential", friction):
            raise KinergyError(f"friction {friction!r} is not fitted in chunks")
        holdings = holdings_of(hold)
        models = [friction or j.drive.friction.model for j in staged.joints]
        stills = [STILL_SPEED * abs(j.drive.gear_ratio) for j in staged.joints]
        params = [
            [start_params(j, models[m], stills[m], h) for h in holdings]
            for m, j in enumerate(staged.joints)
        ]
        problems = [
            [Reduced.empty(1 + len(get_model(models[m]).linear)) for _ in holdings]
            for m in range(staged.n)
        ]
        history = [_signal_history(stills[m]) for m in range(staged.n)]
        # as motor_signals: temperatures only when every log with currents has them
        warm = all(h["temperature"] for h in self.has if h["current"])
        last = -1
        for k, chunk in self._chunks("current"):
            if k != last:  # the hold restarts in each log
                for past in history:
                    past.reset()
                last = k
            for m, s in enumerate(motor_signals(staged, rotor, [chunk])):
                if not warm:
                    s = _Signals(s.tau_load, s.wm, s.dwm, s.current, None)
                s = dataclasses.replace(s, piece=None)
                joined, skip = history[m].ahead(s)
                for h, p in enumerate(params[m]):
                    cols = _columns(models[m], p, joined)[skip:]
                    problems[m][h] = problems[m][h].stack(cols, s.current)
                history[m].update(joined, skip)

        index = {h: k for k, h in enumerate(holdings)}

        def fit_joint(m: int, joint: Joint, _: float) -> tuple[_CurrentFit, FrictionChoice | None]:
            def fit(h: float) -> _CurrentFit:
                k = index[h]
                return solve_current(
                    models[m], params[m][k], problems[m][k], joint.drive.torque_constant
                )

            return best_hold(holdings, fit), None

        return fit_joint

    def validation(self, robot: Robot) -> Validation:
        """The fit statistics of ``robot`` on the logs, pooled (friction held per log, as
        :func:`~kinergy.identify.result.validation_metrics`). When the model holds no friction
        through standstill and the logs' temperatures are all there or all missing, its
        predicted currents are the instrument of :meth:`electrics` too: the same pass
        accumulates that fit."""
        sums: dict[str, MetricSums | None] = dict.fromkeys(("torque", "current", "joint_torque"))
        held = _data_history(robot)
        warm = {h["temperature"] for h in self.has}
        fused = self.has_voltage and not held.active and len(warm) == 1
        motors = [ElectricsSums() for _ in range(robot.n)] if fused else None
        if fused and self.has_supply:  # the predicted currents, for standby
            self._drawn = (robot, _Spool())
        last = -1
        for k, chunk in self._chunks():
            if k != last:
                held.reset()
                last = k
            data, skip = held.ahead(chunk)
            pred = predict(robot, data)
            held.update(data, skip)
            for key, measured, predicted in (
                ("torque", chunk.tau_ref, pred.torque),
                ("current", chunk.current, pred.current),
                ("joint_torque", chunk.torque, pred.joint_torque),
            ):
                if measured is not None and predicted is not None:
                    sums[key] = sums[key] or MetricSums(robot.n)
                    sums[key].add(measured, predicted[skip:])  # type: ignore[union-attr]
            if motors is not None:
                assert pred.current is not None
                _add_electrics(motors, transmission_matrix(robot), chunk, pred.current)
            if self._drawn is not None and pred.current is not None:
                self._drawn[1].put([pred.current])
        if motors is not None:
            self._electrics = (robot, motors)
        return Validation(**{k: None if s is None else s.metrics() for k, s in sums.items()})

    @property
    def has_voltage(self) -> bool:
        return self._every("voltage", "current")

    @property
    def has_supply(self) -> bool:
        return self._every("supply_voltage", "supply_current")

    def electrics(self, robot: Robot) -> list[ElectricsFit | KinergyError]:
        """Per motor, eq 19's fit (:func:`~kinergy.identify.electrics.fit_electrics` with the
        current ``robot`` predicts as the instrument) or why it cannot be made."""
        if self._electrics is not None and self._electrics[0] is robot:
            motors = self._electrics[1]
        else:
            motors = [ElectricsSums() for _ in range(robot.n)]
            held = _data_history(robot)
            warm = self._every("temperature")
            for _, chunk in self._chunks():  # over the logs stacked, as the in-memory fit
                predicted = _state(robot, held, chunk, warm)[0]
                _add_electrics(motors, transmission_matrix(robot), chunk, predicted)
        out: list[ElectricsFit | KinergyError] = []
        for motor in motors:
            try:
                out.append(motor.fit())
            except KinergyError as exc:
                out.append(exc)
        return out

    def standby(self, robot: Robot) -> float:
        """The mean of the supply power less the motors' predicted draw, W
        (:func:`~kinergy.identify.electrics.fit_standby`'s ``standby``). The currents
        :meth:`validation` predicted serve when ``robot`` differs from its model in the
        electrics alone (its currents on the first chunk are the same to the bit): the power
        is then ``tau_m = k_t I`` through UR5e eq 23 (:func:`electrical_power`)."""
        held, total, count = _data_history(robot), 0.0, 0
        warm = self._every("temperature")
        drawn = iter(self._drawn[1]) if self._drawn is not None else None
        n_mat, kt = transmission_matrix(robot), torque_constants(robot)
        for _, chunk in self._chunks():  # over the logs stacked, as the in-memory fit
            assert chunk.supply_voltage is not None and chunk.supply_current is not None
            if drawn is not None and count > 0:
                power = electrical_power(robot, next(drawn)[0] * kt, chunk.qd @ n_mat.T)
            else:
                current, power = _state(robot, held, chunk, warm)
                if drawn is not None and not np.array_equal(current, next(drawn)[0]):
                    drawn = None
            supply = np.asarray(chunk.supply_voltage * chunk.supply_current, dtype=float)
            total += float(np.sum(supply - supply_power(power).motors))
            count += len(chunk)
        return total / count

    def close(self) -> None:
        """Remove the prepared chunks' files."""
        self.store.close()
        if self._drawn is not None:
            self._drawn[1].close()


def _add_electrics(
    motors: list[ElectricsSums], n_mat: Array, chunk: IdentData, predicted: Array
) -> None:
    """Fold ``chunk``'s currents, voltages and motor speeds into each motor's eq 19, with the
    ``predicted`` currents (N, n) as the instrument."""
    assert chunk.current is not None and chunk.voltage is not None
    voltage, wm = equivalent_voltage(chunk.voltage), chunk.qd @ n_mat.T
    for m, motor in enumerate(motors):
        motor.add(chunk.current[:, m], voltage[:, m], wm[:, m], predicted[:, m])


def _cat(a: _Signals, b: _Signals) -> _Signals:
    """Motor signals ``a`` then ``b``."""
    temp = (
        None
        if a.temperature is None or b.temperature is None
        else np.concatenate([a.temperature, b.temperature])
    )
    return _Signals(
        np.concatenate([a.tau_load, b.tau_load]),
        np.concatenate([a.wm, b.wm]),
        np.concatenate([a.dwm, b.dwm]),
        np.concatenate([a.current, b.current]),
        temp,
    )
