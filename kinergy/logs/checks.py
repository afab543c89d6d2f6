"""Plausibility checks of a log, before it shapes any result: does it look like what a robot
controller writes, for this robot, in the units kinergy reads?

Each check is named (:class:`Check`) so that a user who knows better can accept it (``--accept
CHECK``; the result then records it). They run as a fold over the chunks the reader yields
(:class:`LogCheck`: ``add(chunk)`` per chunk, ``finish()`` at the end), in memory that does not
grow with the log: running sums per joint, and for the robot check a fixed-size, evenly thinned
sample of rows.

- ``time``: a plausible sample period (0.5 ms to 0.1 s: UR's controllers log at 2 or 8 ms,
  record.py and other recorders slower). Time stamps that repeat or go back are refused by the
  reader itself, naming the line.
- ``units``: joint positions within the robot's limits and speeds within a plausible multiple of
  them (positions in degrees fail here); temperatures in deg C, not kelvin.
- ``speeds``: each joint's logged speed against the derivative of its logged position, as a slope
  and a correlation over the samples where it moves: 1 and 1 for a true speed column; a swapped or
  shifted column layout fails here.
- ``ratings``: currents, torques and voltages within a plausible multiple of the robot's ratings
  (currents in mA or torques in N mm fail here).
- ``constant``: a measured signal that holds one value on every sample while its joint moves (the
  sensor was not logged; all zeros).
- ``robot``: the nominal model's torques and currents (:func:`kinergy.predict.drive_state`: the
  rigid body, the reflected rotor inertia and, for currents, the drive's friction and torque
  constant) against the logged ``target_moment``, measured torques or currents: per joint a ratio
  (least-squares slope) and a correlation. A joint whose sign is flipped, two joints swapped, or a
  log another built-in robot explains far better fail, with the ratios seen and, where one fits,
  the robot that would. A scale that is off while no built-in robot fits better is a warning only
  (a robot file whose masses are off, a controller logging a scaled signal).

``fit`` is not a check of the log: ``identify`` uses the name for a model its fit does not
support (:mod:`kinergy.identification`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.io.fields import check_widths
from kinergy.io.log import Log
from kinergy.logs.payload import from_columns, payload_columns, payload_problem
from kinergy.logs.robot_check import LOADS, judge_robot, noise_name, without_effort
from kinergy.logs.signal_checks import (
    CURRENTS,
    PAIRS,
    TORQUES,
    Seen,
    check_constant,
    check_magnitudes,
    check_ratings,
    check_speeds,
    check_time,
    check_units,
    moving,
)
from kinergy.logs.sums import Moments, Noise, Thinned
from kinergy.logs.verdicts import CHECKS, Check, Findings, LogChecks, first, parse_accept
from kinergy.messages import Message
from kinergy.model.robot import Robot

__all__ = ["CHECKS", "Check", "LogCheck", "LogChecks", "check_log", "parse_accept"]

#: rows the robot check keeps (evenly thinned over the whole log)
ROBOT_ROWS = 4096
#: the most distinct payloads the checks keep of a log (a payload ramped by
#: ``set_target_payload``'s transition time takes a few hundred)
MAX_LOADS = 256
#: s: the robot check's acceleration is the speed's central difference over this span
DIFF_SPAN = 0.02


class LogCheck:
    """The checks of one log as a fold over its chunks (module docstring).

    Parameters
    ----------
    robot : Robot
        The robot the log is read for.
    path : str
        The log's name, for messages.
    accept : collection of Check
        Checks whose failure the user accepts: recorded, not raised.
    """

    def __init__(
        self,
        robot: Robot,
        path: str,
        accept: Iterable[Check] = (),
    ):
        self.robot, self.path = robot, path
        self.accept = frozenset(accept)
        self.samples = 0
        self.last: Log | None = None
        n = robot.n
        self.seen = Seen(
            robot,
            path,
            speeds={pair: Moments(n) for pair in PAIRS},
            noise={pair: (Noise(n), Noise(n)) for pair in PAIRS},
        )
        self.thinned: Thinned | None = None
        #: the distinct payloads the log carries (:func:`kinergy.logs.payload.payload_columns`)
        self.loads: dict[bytes, Array] = {}

    @property
    def period(self) -> float:
        return self.seen.period

    # -- the fold ------------------------------------------------------------------------------

    def add(self, chunk: Log) -> None:
        """Fold one chunk (consecutive with the one before) into the checks.

        Raises
        ------
        KinergyError
            A signal of one value per joint whose width is not the robot's joint count.
        """
        if not len(chunk):
            return
        if self.last is None:
            check_widths(chunk.signals, self.robot.n, self.path)
        if math.isnan(self.period):
            steps = np.diff(chunk.t)
            if steps.size:
                self.seen.period = float(np.median(steps))
                stride = max(1, round(DIFF_SPAN / 2 / self.period)) if self.period > 0 else 1
                self.thinned = Thinned(ROBOT_ROWS, stride)
        self._extremes(chunk)
        self._speeds(chunk)
        self._robot_rows(chunk)
        self._loads(chunk)
        self.samples += len(chunk)
        last = slice(len(chunk) - 1, len(chunk))
        self.last = Log(self.path, chunk.t[last], {k: x[last] for k, x in chunk.signals.items()})

    def _extremes(self, chunk: Log) -> None:
        for name, x in chunk.signals.items():
            if x.ndim != 2 and name not in (
                "actual_robot_voltage",
                "actual_robot_current",
                "payload",
            ):
                continue
            lo, hi = np.nanmin(x, axis=0), np.nanmax(x, axis=0)
            seen = self.seen
            seen.lo[name] = lo if name not in seen.lo else np.minimum(seen.lo[name], lo)
            seen.hi[name] = hi if name not in seen.hi else np.maximum(seen.hi[name], hi)

    def _steps(self, t: Array) -> NDArray[np.bool_]:
        """Which steps ``t[i] -> t[i+1]`` are within a segment (no gap)."""
        step = np.diff(t)
        return (step > 0) & (step <= 5.0 * self.period)

    def _speeds(self, chunk: Log) -> None:
        """Fold the chunk's steps, and the one from the previous chunk's last sample."""
        t = chunk.t if self.last is None else np.concatenate([self.last.t, chunk.t])
        if t.size < 2:
            return
        ok = self._steps(t)
        every = bool(ok.all())
        dt = np.diff(t) if every else np.diff(t)[ok]
        for (q_name, qd_name), moments in self.seen.speeds.items():
            if q_name not in chunk or qd_name not in chunk or chunk[q_name].ndim != 2:
                continue
            q, qd = chunk[q_name], chunk[qd_name]
            if self.last is not None:
                q = np.concatenate([self.last[q_name], q])
                qd = np.concatenate([self.last[qd_name], qd])
            step, mean = np.diff(q, axis=0), 0.5 * (qd[1:] + qd[:-1])
            if every:  # the noise of consecutive samples (a chunk with a gap leaves it out)
                speed, quotient = self.seen.noise[(q_name, qd_name)]
                speed.add(qd)
                quotient.add(step / dt[:, None])
            else:
                step, mean = step[ok], mean[ok]
            moments.add(mean, step / dt[:, None])

    def _robot_rows(self, chunk: Log) -> None:
        """Keep evenly thinned rows of the motion and the logged torques and currents, with an
        acceleration from the speed's central difference (a chunk's first and last few rows,
        which lack neighbours, are not kept)."""
        thinned = self.thinned
        h = max(1, round(DIFF_SPAN / 2 / self.period)) if self.period > 0 else 1
        if thinned is None or len(chunk) <= 2 * h:
            return
        k = thinned.candidates(self.samples, h, len(chunk) - h)
        if not k.size:
            return
        t = chunk.t
        rows: dict[str, Array] = {}
        valid = np.ones(k.size, dtype=bool)
        for prefix in ("target", "actual"):
            q_name, qd_name = f"{prefix}_q", f"{prefix}_qd"
            if q_name not in chunk or qd_name not in chunk or chunk[q_name].ndim != 2:
                continue
            qd = chunk[qd_name]
            if f"{prefix}_qdd" in chunk:
                qdd = chunk[f"{prefix}_qdd"][k]
            else:
                span = t[k + h] - t[k - h]
                qdd = (qd[k + h] - qd[k - h]) / span[:, None]
                # a difference across a gap is no acceleration
                valid &= (span > 0) & (span <= 5.0 * 2 * h * self.period)
            rows[q_name], rows[qd_name], rows[f"{prefix}_qdd"] = chunk[q_name][k], qd[k], qdd
        for name in (*TORQUES, *CURRENTS):
            if name in chunk and chunk[name].ndim == 2:
                y = chunk[name]
                rows[name] = y[k]
                # the second difference of consecutive samples: the signal's noise
                rows[noise_name(name)] = y[k + 1] - 2.0 * y[k] + y[k - 1]
        loads = payload_columns(chunk)
        if loads is not None:
            rows[LOADS] = loads[k]
        if rows:
            thinned.add(self.samples + k[valid], {n: x[valid] for n, x in rows.items()})

    def _loads(self, chunk: Log) -> None:
        """Keep the distinct payloads the chunk logs (at most :data:`MAX_LOADS` in all)."""
        cols = payload_columns(chunk)
        if cols is None or len(self.loads) >= MAX_LOADS:
            return
        for row in np.unique(cols, axis=0)[: MAX_LOADS - len(self.loads)]:
            self.loads.setdefault(row.tobytes(), row)

    # -- the verdict ---------------------------------------------------------------------------

    def finish(self) -> LogChecks:
        """The checks' verdict on the whole log.

        Raises
        ------
        KinergyError
            The first failed check the user did not accept: one line naming the log, the check,
            the joint and what was seen, and how to accept it.
        """
        with np.errstate(all="ignore"):  # absurd values are judged, not warned about
            return self._finish()

    def _check_loads(self, found: Findings) -> None:
        """The ``ratings`` check of the payloads the controller logged (:func:`payload_problem`);
        columns that hold no load at all are refused outright."""
        if not self.loads:
            return
        try:
            loads = [from_columns(row) for row in self.loads.values() if row.any()]
        except KinergyError as exc:
            raise KinergyError(
                f"{self.path}: the controller's payload columns hold no load: {exc}"
            ) from None
        problem = payload_problem(self.robot, loads)
        if problem:
            found.fail(Check.RATINGS, problem)

    def _is_bag(self) -> bool:
        """Whether the log is a ROS 2 bag (its hints name --effort)."""
        p = Path(self.path)
        if p.suffix in (".mcap", ".db3") or p.name == "metadata.yaml":
            return True
        return p.is_dir() and (p / "metadata.yaml").is_file()

    def _finish(self) -> LogChecks:
        seen = self.seen
        check_magnitudes(seen)
        found = Findings()
        joints_moving = moving(seen)
        check_time(seen, found)
        check_units(seen, found)
        check_speeds(seen, found, joints_moving)
        check_ratings(seen, found)
        self._check_loads(found)
        check_constant(seen, found, joints_moving)
        thinned = self.thinned
        rows = {} if thinned is None else {name: thinned.get(name) for name in thinned.rows}
        judge_robot(self.robot, rows, found)
        if not self._is_bag():  # the --effort hints are for bags only
            for texts in found.failed.values():
                texts[:] = [without_effort(t) for t in texts]
        accepted: list[str] = []
        for check, texts in found.failed.items():
            text = first(texts)
            if check in self.accept:
                accepted.append(f"{check.value}: {text}")
                continue
            raise KinergyError(
                f"{self.path}: {check.value} check failed: {text} "
                f"(if the log is right, --accept {check.value})"
            )
        return LogChecks(
            log=self.path,
            passed=tuple(c.value for c in found.passed),
            accepted=tuple(accepted),
            not_checked=tuple(f"{c.value}: {why}" for c, why in found.skipped.items()),
            warnings=tuple(Message(w).prefixed(self.path) for w in found.warnings),
            notes=tuple(f"{self.path}: {n}" for n in found.notes),
        )


def check_log(robot: Robot, log: Log, accept: Iterable[Check] = ()) -> LogChecks:
    """The checks of a log held whole (one chunk of :class:`LogCheck`)."""
    check = LogCheck(robot, log.path, accept)
    check.add(log)
    return check.finish()
