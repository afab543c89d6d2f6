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

import enum
import math
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.drives.transmission import joint_torque, transmission_matrix
from kinergy.dynamics.regressor import regressor
from kinergy.errors import Code, KinergyError
from kinergy.io.fields import FIELDS, JOINTS
from kinergy.io.log import Log
from kinergy.messages import Message
from kinergy.model.library import library_names, load_robot
from kinergy.model.robot import Payload, Robot
from kinergy.predict import drive_state

__all__ = [
    "CHECKS",
    "Check",
    "LogCheck",
    "LogChecks",
    "better_robot",
    "check_log",
    "explain_mismatch",
    "parse_accept",
    "payload_explains",
    "robot_match",
]


class Check(enum.StrEnum):
    """The named checks ``--accept`` takes."""

    TIME = "time"
    UNITS = "units"
    SPEEDS = "speeds"
    RATINGS = "ratings"
    CONSTANT = "constant"
    ROBOT = "robot"
    FIT = "fit"


#: what each check verifies, for help texts and the documentation
CHECKS: dict[Check, str] = {
    Check.TIME: "a plausible sample period (0.5 ms to 0.1 s)",
    Check.UNITS: "positions within the joint limits (rad, not degrees), speeds and temperatures "
    "plausible",
    Check.SPEEDS: "each joint's logged speed equals the derivative of its logged position",
    Check.RATINGS: "currents, torques and voltages within 5 times the robot's ratings",
    Check.CONSTANT: "no measured signal stuck at one value while its joint moves",
    Check.ROBOT: "the robot model's torques and currents match the logged ones (ratio and sign "
    "per joint)",
    Check.FIT: "identify: the fit explains the identification logs (R^2 >= 0 for every joint that "
    "moved)",
}


def parse_accept(values: Iterable[str]) -> frozenset[Check]:
    """``--accept`` values (names or comma-separated lists) as checks.

    Raises
    ------
    KinergyError
        A name that is not a check, with the known ones.
    """
    out: set[Check] = set()
    for value in values:
        for name in value.split(","):
            name = name.strip().lower()
            if name == "all":
                out.update(Check)
                continue
            try:
                out.add(Check(name))
            except ValueError:
                known = ", ".join(c.value for c in Check)
                raise KinergyError(
                    f"--accept: unknown check {name!r}; the checks are {known} (or all)"
                ) from None
    return frozenset(out)


@dataclass(frozen=True)
class LogChecks:
    """What the checks found in one log.

    Attributes
    ----------
    log : str
    passed : tuple of str
        Checks that ran and passed.
    accepted : tuple of str
        Checks that failed and were accepted by the user (``--accept``), with what they saw.
    not_checked : tuple of str
        Checks the log gave nothing to run on, with why.
    warnings : tuple of str
        What passed but may still make a result wrong.
    """

    log: str
    passed: tuple[str, ...] = ()
    accepted: tuple[str, ...] = ()
    not_checked: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()


# --------------------------------------------------------------------------------------------
# thresholds

#: a magnitude no signal of a robot's log reaches in any unit (kinergy refuses it outright)
ABSURD = 1e9
#: s: the plausible sample periods of a controller log
PERIOD_RANGE = (5e-4, 0.1)
#: rad: a joint whose position spans less than this does not move (nothing to compare)
MOVE_SPAN = 0.05
#: rad/s: ... or whose RMS speed is below this
MOVE_SPEED = 0.01
#: the slope and correlation of logged speed against the position's derivative that pass
SPEED_SLOPE = (0.8, 1.25)
SPEED_CORRELATION = 0.9
#: positions may exceed the joint limits by this much (rad) before they are not radians
POSITION_MARGIN = 0.1
#: speeds may exceed the speed limit by this factor
SPEED_FACTOR = 2.0
#: currents, torques and voltages may exceed their rating by this factor
RATING_FACTOR = 5.0
#: deg C: plausible joint temperatures
TEMPERATURE_RANGE = (-40.0, 150.0)
#: rows the robot check keeps (evenly thinned over the whole log)
ROBOT_ROWS = 4096
#: s: the robot check's acceleration is the speed's central difference over this span
DIFF_SPAN = 0.02
#: a joint is informative for the robot check when the model's signal varies by this fraction
#: of its rating (standard deviation)
INFORMATIVE = 0.02
#: the ratio band of a matching robot, per kind of signal (nominal torque constants of a robot
#: file can be off by 2 while its masses are within 20 %)
RATIO_BAND = {"torque": (0.5, 2.0), "current": (1 / 3, 3.0)}
#: a ratio outside this band on any joint is not a model that is a little off
WIDE_BAND = (0.2, 5.0)
#: another built-in robot "fits far better" when its score is within this (ratios within about
#: 10 %) while the given robot's is beyond :data:`POOR_SCORE` (about 25 %)
CLOSE_SCORE = 0.1
POOR_SCORE = 0.25
#: correlations: a flipped sign below -NEGATIVE, a match above MATCH
NEGATIVE = 0.5
MATCH = 0.8
#: two joints look swapped when each follows the other's model with a correlation above this
SWAP_MATCH = 0.9

#: a swap of two joints explains a log when, exchanged, both are informative and the median
#: |log ratio| is within this (ratios within about 25 %)
SWAP_SCORE = 0.25

#: the position and speed signals checked against each other
_PAIRS = (("actual_q", "actual_qd"), ("target_q", "target_qd"))
#: torque-like signals, N m, against the limits' torque
_TORQUES = ("target_moment", "actual_joint_torque", "actual_current_as_torque")
#: current signals, A, against the drive's rated current
_CURRENTS = ("actual_current", "target_current")
#: measured signals that may not hold one value while their joint moves
_MEASURED = (*_TORQUES, *_CURRENTS, "actual_joint_voltage")


def _joint(robot: Robot, j: int) -> str:
    return f"joint {j + 1} ({robot.joints[j].name})"


def _rated_current(robot: Robot) -> Array:
    """Per motor, the current that makes the joint's rated torque (A): ``N^-T tau_lim / k_t``,
    largest over the joints a coupled motor drives."""
    n_mat = transmission_matrix(robot)
    limits = np.array([j.limits.torque for j in robot.joints])
    motor = np.abs(np.linalg.solve(n_mat.T, np.diag(limits))).max(axis=1)
    kt = np.array([j.drive.torque_constant for j in robot.joints])
    return np.asarray(motor / kt, dtype=float)


class _Moments:
    """Running sums of pairs ``(x, y)`` per joint: counts, sums, squares and cross products."""

    def __init__(self, n: int):
        self.n = np.zeros(n)
        self.sx = np.zeros(n)
        self.sy = np.zeros(n)
        self.sxx = np.zeros(n)
        self.syy = np.zeros(n)
        self.sxy = np.zeros(n)

    def add(self, x: Array, y: Array) -> None:
        self.n += x.shape[0]
        self.sx += x.sum(axis=0)
        self.sy += y.sum(axis=0)
        self.sxx += np.einsum("ij,ij->j", x, x)
        self.syy += np.einsum("ij,ij->j", y, y)
        self.sxy += np.einsum("ij,ij->j", x, y)

    def slope(self) -> Array:
        """Least-squares slope of y on x through the origin."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.asarray(self.sxy / self.sxx, dtype=float)

    def correlation(self) -> Array:
        with np.errstate(invalid="ignore", divide="ignore"):
            cxx = self.sxx - self.sx**2 / self.n
            cyy = self.syy - self.sy**2 / self.n
            cxy = self.sxy - self.sx * self.sy / self.n
            return np.asarray(cxy / np.sqrt(cxx * cyy), dtype=float)

    def rms_x(self) -> Array:
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.asarray(np.sqrt(self.sxx / self.n), dtype=float)


class _Thinned:
    """Rows of a long log evenly thinned to at most ``size``: every ``stride``-th sample, the
    stride doubling (and every other kept row dropped) when the rows fill up."""

    def __init__(self, size: int, stride: int):
        self.size, self.stride = size, max(1, stride)
        self.rows: dict[str, list[Array]] = {}
        self.index: list[NDArray[np.intp]] = []
        self.count = 0

    def candidates(self, start: int, lo: int, hi: int) -> NDArray[np.intp]:
        """The rows ``lo <= k < hi`` of a chunk starting at sample ``start`` that fall on the
        stride."""
        first = lo + (-(start + lo)) % self.stride
        return np.arange(first, hi, self.stride)

    def add(self, numbers: NDArray[np.intp], rows: dict[str, Array]) -> None:
        """Rows of samples ``numbers`` (on the stride)."""
        if numbers.size:
            self.index.append(numbers)
            for name, x in rows.items():
                self.rows.setdefault(name, []).append(x)
            self.count += numbers.size
        while self.count > self.size:
            self._halve()

    def _halve(self) -> None:
        self.stride *= 2
        index = np.concatenate(self.index)
        keep = index % self.stride == 0
        self.index = [index[keep]]
        self.rows = {name: [np.concatenate(x)[keep]] for name, x in self.rows.items()}
        self.count = int(keep.sum())

    def get(self, name: str) -> Array:
        return np.concatenate(self.rows[name]) if name in self.rows else np.empty((0, 0))


@dataclass
class _Findings:
    """What the checks concluded, per check: failures (which stop), passes, warnings."""

    failed: dict[Check, list[str]] = field(default_factory=dict)
    passed: list[Check] = field(default_factory=list)
    skipped: dict[Check, str] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)

    def fail(self, check: Check, text: str) -> None:
        self.failed.setdefault(check, []).append(text)

    def verdict(self, check: Check, ran: bool, why_not: str = "") -> None:
        if check in self.failed:
            return
        if ran:
            self.passed.append(check)
        else:
            self.skipped[check] = why_not


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
        n = robot.n
        self.samples = 0
        self.period = math.nan
        self.last: Log | None = None
        self.lo: dict[str, Array] = {}
        self.hi: dict[str, Array] = {}
        self.peak: dict[str, Array] = {}
        self.speeds = {pair: _Moments(n) for pair in _PAIRS}
        self.thinned: _Thinned | None = None

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
            self._check_widths(chunk)
        if math.isnan(self.period):
            steps = np.diff(chunk.t)
            if steps.size:
                self.period = float(np.median(steps))
                stride = max(1, round(DIFF_SPAN / 2 / self.period)) if self.period > 0 else 1
                self.thinned = _Thinned(ROBOT_ROWS, stride)
        self._extremes(chunk)
        self._speeds(chunk)
        self._robot_rows(chunk)
        self.samples += len(chunk)
        last = slice(len(chunk) - 1, len(chunk))
        self.last = Log(self.path, chunk.t[last], {k: x[last] for k, x in chunk.signals.items()})

    def _check_widths(self, chunk: Log) -> None:
        n = self.robot.n
        for name, x in chunk.signals.items():
            if FIELDS.get(name) == JOINTS and (x.ndim != 2 or x.shape[1] != n):
                width = 1 if x.ndim == 1 else x.shape[1]
                raise KinergyError(f"{self.path}: {name} has {width} joints but the robot has {n}")

    def _extremes(self, chunk: Log) -> None:
        for name, x in chunk.signals.items():
            if x.ndim != 2 and name not in ("actual_robot_voltage", "actual_robot_current"):
                continue
            lo, hi = np.nanmin(x, axis=0), np.nanmax(x, axis=0)
            self.lo[name] = lo if name not in self.lo else np.minimum(self.lo[name], lo)
            self.hi[name] = hi if name not in self.hi else np.maximum(self.hi[name], hi)

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
        for (q_name, qd_name), moments in self.speeds.items():
            if q_name not in chunk or qd_name not in chunk or chunk[q_name].ndim != 2:
                continue
            q, qd = chunk[q_name], chunk[qd_name]
            if self.last is not None:
                q = np.concatenate([self.last[q_name], q])
                qd = np.concatenate([self.last[qd_name], qd])
            step, mean = np.diff(q, axis=0), 0.5 * (qd[1:] + qd[:-1])
            if not every:
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
        for name in (*_TORQUES, *_CURRENTS):
            if name in chunk and chunk[name].ndim == 2:
                rows[name] = chunk[name][k]
        if rows:
            thinned.add(self.samples + k[valid], {n: x[valid] for n, x in rows.items()})

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

    def _is_bag(self) -> bool:
        """Whether the log is a ROS 2 bag (its hints name --effort)."""
        p = Path(self.path)
        if p.suffix in (".mcap", ".db3") or p.name == "metadata.yaml":
            return True
        return p.is_dir() and (p / "metadata.yaml").is_file()

    def _finish(self) -> LogChecks:
        self._check_magnitudes()
        found = _Findings()
        moving = self._moving()
        self._check_time(found)
        self._check_units(found)
        self._check_speeds(found, moving)
        self._check_ratings(found)
        self._check_constant(found, moving)
        self._check_robot(found)
        if not self._is_bag():  # the --effort hints are for bags only
            for texts in found.failed.values():
                texts[:] = [_without_effort(t) for t in texts]
        accepted: list[str] = []
        for check, texts in found.failed.items():
            text = _first(texts)
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
        )

    def _check_magnitudes(self) -> None:
        """Refuse values no robot logs in any unit (beyond :data:`ABSURD`): a corrupted log,
        whatever is accepted (computing on them would only overflow)."""
        for name in sorted(self.lo):
            peak = float(np.max(np.maximum(np.abs(self.lo[name]), np.abs(self.hi[name]))))
            if not peak <= ABSURD:
                raise KinergyError(
                    f"{self.path}: {name} holds {peak:.3g}: not a value a robot logs in any unit "
                    "(a corrupted log; no --accept lets it through)"
                )

    def _moving(self) -> Array:
        """Per joint, whether it moves in the log (its position spans :data:`MOVE_SPAN`)."""
        n = self.robot.n
        for name in ("actual_q", "target_q"):
            if name in self.lo and self.lo[name].shape == (n,):
                return np.asarray(self.hi[name] - self.lo[name] >= MOVE_SPAN)
        return np.zeros(n, dtype=bool)

    def _check_time(self, found: _Findings) -> None:
        lo, hi = PERIOD_RANGE
        if math.isnan(self.period):
            found.verdict(Check.TIME, False, "fewer than two samples")
            return
        if not lo <= self.period <= hi:
            found.fail(
                Check.TIME,
                f"the sample period is {self.period:.4g} s, not a controller's "
                f"({lo * 1e3:g} ms to {hi:g} s): are the time stamps in another unit, or is the "
                "first column not the time?",
            )
        found.verdict(Check.TIME, True)

    def _check_units(self, found: _Findings) -> None:
        robot, ran = self.robot, False
        for name in ("actual_q", "target_q"):
            if name not in self.lo or self.lo[name].shape != (robot.n,):
                continue
            ran = True
            for j, joint in enumerate(robot.joints):
                low, high = joint.limits.position
                x_lo, x_hi = self.lo[name][j], self.hi[name][j]
                if x_lo < low - POSITION_MARGIN or x_hi > high + POSITION_MARGIN:
                    degrees = (
                        np.radians(x_lo) >= low - POSITION_MARGIN
                        and np.radians(x_hi) <= high + POSITION_MARGIN
                    )
                    hint = " (degrees? kinergy reads radians)" if degrees else ""
                    found.fail(
                        Check.UNITS,
                        f"{name} of {_joint(robot, j)} spans {x_lo:.4g} to {x_hi:.4g}, beyond its "
                        f"limits {low:.4g} to {high:.4g} rad{hint}",
                    )
        for name in ("actual_qd", "target_qd"):
            if name not in self.lo or self.lo[name].shape != (robot.n,):
                continue
            ran = True
            peak = np.maximum(np.abs(self.lo[name]), np.abs(self.hi[name]))
            for j, joint in enumerate(robot.joints):
                if peak[j] > SPEED_FACTOR * joint.limits.speed:
                    degrees = np.radians(peak[j]) <= SPEED_FACTOR * joint.limits.speed
                    hint = " (degrees per second? kinergy reads rad/s)" if degrees else ""
                    found.fail(
                        Check.UNITS,
                        f"{name} of {_joint(robot, j)} reaches {peak[j]:.4g}, more than "
                        f"{SPEED_FACTOR:g} times its limit of {joint.limits.speed:.4g} rad/s{hint}",
                    )
        if "joint_temperatures" in self.lo:
            ran = True
            t_lo, t_hi = TEMPERATURE_RANGE
            lo, hi = (
                float(np.min(self.lo["joint_temperatures"])),
                float(np.max(self.hi["joint_temperatures"])),
            )
            if lo < t_lo or hi > t_hi:
                hint = " (kelvin? kinergy reads deg C)" if 230 < lo and hi < 430 else ""
                found.fail(
                    Check.UNITS,
                    f"joint_temperatures span {lo:.4g} to {hi:.4g}, not deg C of a working "
                    f"robot{hint}",
                )
        found.verdict(Check.UNITS, ran, "no positions, speeds or temperatures")

    def _check_speeds(self, found: _Findings, moving: Array) -> None:
        robot, ran = self.robot, False
        for (q_name, qd_name), m in self.speeds.items():
            if not np.any(m.n > 0):
                continue
            slope, corr, rms = m.slope(), m.correlation(), m.rms_x()
            bad: list[tuple[int, float, float]] = []
            for j in range(robot.n):
                derivative_rms = math.sqrt(m.syy[j] / m.n[j]) if m.n[j] else 0.0
                if not moving[j] or max(rms[j], derivative_rms) < MOVE_SPEED:
                    continue
                ran = True
                # s: slope of the derivative on the logged speed
                s, r = float(slope[j]), float(corr[j])
                if not (SPEED_SLOPE[0] <= s <= SPEED_SLOPE[1] and r >= SPEED_CORRELATION):
                    bad.append((j, s, r))
            if not bad:
                continue
            ratios = [1 / s if s else math.inf for _, s, _ in bad]
            good_corr = all(r >= SPEED_CORRELATION for _, _, r in bad)
            if good_corr and all(40 < x < 80 for x in ratios):
                hint = "degrees per second? kinergy reads rad/s"
            elif good_corr and all(1 / 80 < x < 1 / 40 for x in ratios):
                hint = "positions in degrees? kinergy reads radians"
            else:
                hint = "columns swapped or shifted? check the layout (--columns)"
            seen = ", ".join(
                f"{_joint(robot, j)} {x:.3g} (correlation {r:.2f})"
                for (j, _, r), x in zip(bad, ratios, strict=True)
            )
            found.fail(
                Check.SPEEDS,
                f"{qd_name} is not the derivative of {q_name} (a speed column gives 1 and "
                f"correlation 1): {seen}: {hint}",
            )
        found.verdict(Check.SPEEDS, ran, "no joint moves with both positions and speeds logged")

    def _check_ratings(self, found: _Findings) -> None:
        robot, ran = self.robot, False
        torque = np.array([j.limits.torque for j in robot.joints])
        current = _rated_current(robot)
        for names, rating, unit, small in (
            (_TORQUES, torque, "N m", "N mm"),
            (_CURRENTS, current, "A", "mA"),
            (("actual_joint_voltage",), np.full(robot.n, robot.bus_voltage), "V", "mV"),
        ):
            for name in names:
                if name not in self.lo or self.lo[name].shape != (robot.n,):
                    continue
                ran = True
                peak = np.maximum(np.abs(self.lo[name]), np.abs(self.hi[name]))
                over = np.flatnonzero(~(peak <= RATING_FACTOR * rating))
                if over.size:
                    j = int(over[np.argmax(peak[over] / rating[over])])
                    # a thousand times too large: the next smaller unit
                    thousand = 50 * rating[j] < peak[j] <= 1000 * RATING_FACTOR * rating[j]
                    hint = f" ({small}? kinergy reads {unit})" if thousand else ""
                    if not thousand and name in _CURRENTS:
                        hint = " (joint torques in N m logged as currents? a ROS 2 bag: --effort torque)"
                    found.fail(
                        Check.RATINGS,
                        f"{name} of {_joint(robot, j)} reaches {peak[j]:.4g} {unit}, more than "
                        f"{RATING_FACTOR:g} times its rating of {rating[j]:.3g} {unit}{hint}",
                    )
        bus = float(self.hi.get("actual_robot_voltage", np.nan))
        if bus < 0.5 * robot.bus_voltage:
            found.fail(
                Check.RATINGS,
                f"actual_robot_voltage never exceeds {bus:.4g} V, under half the {robot.bus_voltage:g} V "
                "bus it measures: another signal, or another unit?",
            )
        drawn = float(self.hi.get("actual_robot_current", np.nan))
        if drawn <= 0.0 and self._moving().any():
            found.fail(
                Check.RATINGS,
                f"actual_robot_current is never positive ({drawn + 0.0:.4g} A at most) while the arm "
                "moves, yet the arm draws from its supply: its sign flipped?",
            )
        for name, limit, unit in (
            ("actual_robot_voltage", 5.0 * robot.bus_voltage, "V"),
            ("actual_robot_current", RATING_FACTOR * float(np.sum(current)), "A"),
        ):
            if name in self.lo:
                ran = True
                top = float(max(abs(self.lo[name]), abs(self.hi[name])))
                if not top <= limit:
                    found.fail(
                        Check.RATINGS,
                        f"{name} reaches {top:.4g} {unit}, beyond a plausible {limit:.3g} {unit}",
                    )
        found.verdict(Check.RATINGS, ran, "no currents, torques or voltages")

    def _check_constant(self, found: _Findings, moving: Array) -> None:
        robot, ran = self.robot, False
        for name in ("actual_qd", "target_qd", *_MEASURED):
            if name not in self.lo or self.lo[name].shape != (robot.n,):
                continue
            ran = True
            flat = self.lo[name] == self.hi[name]
            stuck = np.flatnonzero(flat & moving)
            if flat.all() and moving.any():
                found.fail(
                    Check.CONSTANT,
                    f"{name} holds one value on every joint and every sample "
                    f"({_values(self.lo[name])}) while the arm moves: not logged?",
                )
            elif stuck.size:
                joints = ", ".join(_joint(robot, int(j)) for j in stuck)
                found.fail(
                    Check.CONSTANT,
                    f"{name} of {joints} holds {_values(self.lo[name][stuck])} on every sample "
                    "while the joint moves: not logged?",
                )
        for name in ("actual_robot_current",):  # the supply's (an ideal voltage may be constant)
            if name in self.lo and moving.any():
                ran = True
                if float(self.lo[name]) == float(self.hi[name]):
                    found.fail(
                        Check.CONSTANT,
                        f"{name} holds {float(self.lo[name]):.4g} on every sample while the arm "
                        "moves: not logged?",
                    )
        found.verdict(Check.CONSTANT, ran, "no measured signal")

    def _check_robot(self, found: _Findings) -> None:
        thinned = self.thinned
        names = [] if thinned is None else [n for n in (*_TORQUES, *_CURRENTS) if n in thinned.rows]
        if thinned is None or not names:
            found.verdict(Check.ROBOT, False, "no torques or currents logged")
            return
        rows = {name: thinned.get(name) for name in thinned.rows}
        if next(iter(rows.values())).shape[0] < 20:
            found.verdict(Check.ROBOT, False, "too few samples")
            return
        with np.errstate(all="ignore"):
            match = robot_match(self.robot, rows)
        if match.skipped:
            found.verdict(Check.ROBOT, False, match.skipped)
            return
        if match.failures or match.off or match.warnings:
            payload = payload_explains(self.robot, rows)
            if payload:
                found.warnings.append(Message(payload, Code.PAYLOAD_MISSING))
                found.verdict(Check.ROBOT, True)
                return
        if match.failures or match.off:
            hint = explain_mismatch(self.robot, rows, match)
            seen = _first(match.failures) or match.off
            if match.failures or hint:
                found.fail(Check.ROBOT, f"{hint}: {seen}" if hint else seen)
            else:
                found.warnings.append(
                    f"{match.off}; no built-in robot fits better: the model's masses or torque "
                    "constants, a payload, or the logged signal's scale are off (what is fitted "
                    "to it will be too)"
                )
        elif match.warnings and (hint := explain_mismatch(self.robot, rows, match, library=False)):
            found.fail(Check.ROBOT, f"{hint}: {match.warnings[0].split(': the model')[0]}")
        elif match.score > POOR_SCORE:
            with np.errstate(all="ignore"):
                best = better_robot(self.robot, rows, CLOSE_SCORE)
            if best:
                found.fail(
                    Check.ROBOT,
                    f"{self.robot.name}'s model is {math.exp(match.score):.2f} times off the "
                    f"log's torques where {best}'s fits within {math.exp(CLOSE_SCORE):.2f}: "
                    f"looks like {best} (or a payload the model lacks: --payload)",
                )
        if Check.ROBOT not in found.failed:
            found.warnings.extend(match.warnings)
        found.verdict(Check.ROBOT, True)


def _first(texts: Sequence[str], count: int = 3) -> str:
    """The first ``count`` of ``texts`` joined, and how many more there are."""
    more = len(texts) - count
    return "; ".join(texts[:count]) + (f"; and {more} more" if more > 0 else "")


def _values(x: Array) -> str:
    vals = sorted({float(v) for v in np.ravel(x)})
    return ", ".join(f"{v:.4g}" for v in vals[:3]) + (", ..." if len(vals) > 3 else "")


@dataclass(frozen=True)
class RobotMatch:
    """How well a robot's nominal model explains a log's torques and currents
    (:func:`robot_match`).

    Attributes
    ----------
    ratios : dict of str to ndarray
        Per logged signal, the least-squares ratio logged / model per joint (nan where the joint
        tells nothing: the model's signal hardly varies).
    correlations : dict of str to ndarray
    failures : list of str
        A flipped sign, swapped joints, a joint that does not follow the model: one text each.
    off : str
        Most informative joints' ratios outside the band (the wrong robot, or a scaled signal);
        "" when not.
    warnings : list of str
        A few joints' ratios outside the band.
    score : float
        The largest over the signals of the median |log ratio| of the informative joints (0: a
        perfect scale).
    skipped : str
        Why nothing could be judged ("" when something was).
    """

    ratios: dict[str, Array]
    correlations: dict[str, Array]
    failures: list[str] = field(default_factory=list)
    off: str = ""
    warnings: list[str] = field(default_factory=list)
    score: float = math.inf
    skipped: str = ""

    @property
    def fits(self) -> bool:
        """Nothing failed and every signal's scale is in its band."""
        return not (self.failures or self.off or self.skipped)


def _model_signal(
    robot: Robot, rows: dict[str, Array], name: str
) -> tuple[Array, Array, Array] | None:
    """The model's prediction of the logged signal ``name`` on the logged motion (the commanded
    one for ``target_*`` signals where logged, else the measured one), its rating per joint and
    which joints move (a joint at rest holds whatever its position loop needs: nothing to
    compare); None without a motion."""
    prefix = "target" if name.startswith("target") and "target_q" in rows else "actual"
    if f"{prefix}_q" not in rows:
        prefix = "target" if "target_q" in rows else ""
    if not prefix:
        return None
    q, qd, qdd = (rows[f"{prefix}_{k}"] for k in ("q", "qd", "qdd"))
    state = drive_state(robot, q, qd, qdd)
    torque = np.array([j.limits.torque for j in robot.joints])
    moving = (np.ptp(q, axis=0) >= MOVE_SPAN) & (np.sqrt(np.mean(qd**2, axis=0)) >= MOVE_SPEED)
    if name == "target_moment":
        return state.tau_sim, torque, moving
    if name in ("actual_joint_torque", "actual_current_as_torque"):
        return joint_torque(robot, state.tau_m), torque, moving
    return state.current, _rated_current(robot), moving


def robot_match(robot: Robot, rows: dict[str, Array]) -> RobotMatch:
    """Judge whether the logged torques and currents ``rows`` (name -> (k, n), with the logged
    motion ``actual_q/qd/qdd`` or ``target_q/qd/qdd``) belong to ``robot`` (module docstring).

    Every signal is checked for flipped signs, swapped joints and joints that do not follow the
    model; the scale (the ratios against the band of :data:`RATIO_BAND`, and the score) is judged
    on the first signal of ``target_moment``, measured torques, ``actual_current_as_torque``,
    currents that the motion informs: a torque does not depend on the drives' torque constants,
    which a robot file may have off by a factor of 2.
    """
    ratios: dict[str, Array] = {}
    correlations: dict[str, Array] = {}
    failures: list[str] = []
    warnings: list[str] = []
    off, score = "", math.nan
    n = robot.n
    for name in (*_TORQUES, *_CURRENTS):
        if name not in rows or rows[name].shape[1:] != (n,):
            continue
        model = _model_signal(robot, rows, name)
        if model is None:
            continue
        x, rating, moving = model
        y = rows[name]
        sums = _Moments(n)
        sums.add(x, y)
        ratio, corr = sums.slope(), sums.correlation()
        informative = moving & (x.std(axis=0) >= INFORMATIVE * rating)
        ratios[name] = np.where(informative, ratio, np.nan)
        correlations[name] = np.where(informative, corr, np.nan)
        swapped = _swaps(x, y, informative, corr)
        in_swap = {j for pair in swapped for j in pair}
        for j, k in swapped:
            failures.append(
                f"{name} of {_joint(robot, j)} and {_joint(robot, k)} look swapped: each "
                f"follows the other's model (correlations {_cross(x, y, j, k)}; with their own "
                f"{corr[j]:.2f}, {corr[k]:.2f})"
            )
        good = []
        for j in range(n):
            if not informative[j] or j in in_swap:
                continue
            if corr[j] < -NEGATIVE:
                failures.append(
                    f"{name} of {_joint(robot, j)} has the opposite sign of the model's "
                    f"(ratio {ratio[j]:.2f}, correlation {corr[j]:.2f}): sign flipped?"
                )
            elif not corr[j] >= NEGATIVE:
                failures.append(
                    f"{name} of {_joint(robot, j)} does not follow {robot.name}'s model "
                    f"(correlation {corr[j]:.2f}, ratio {ratio[j]:.2f})"
                )
            else:
                good.append(j)
        if not good:
            continue
        band = RATIO_BAND["torque" if name in _TORQUES else "current"]
        out = [j for j in good if not band[0] <= ratio[j] <= band[1]]
        wild = [j for j in good if not WIDE_BAND[0] <= ratio[j] <= WIDE_BAND[1]]
        seen = ", ".join(f"{_joint(robot, j)} {ratio[j]:.2f}" for j in (out or good))
        text = (
            f"{name} is {seen} times {robot.name}'s model (a matching robot gives "
            f"{band[0]:.2g} to {band[1]:.2g})"
        )
        if wild:  # beyond what a model a little off explains: a unit, a kind, a robot
            failures.append(text + _kind_hint(robot, name, ratio, wild))
        if math.isnan(score):  # the first informed signal sets the scale
            score = float(np.median(np.abs(np.log(np.clip(ratio[good], 1e-12, None)))))
            if not wild and out and len(out) * 2 >= len(good):
                off = text
            elif not wild and out:
                warnings.append(f"{text}: the model's drives or masses may be off there")
    if not ratios:
        return RobotMatch({}, {}, skipped="no motion beside the torques or currents")
    if not any(np.any(np.isfinite(r)) for r in ratios.values()):
        return RobotMatch(ratios, correlations, skipped="no joint moves enough to compare")
    return RobotMatch(
        ratios, correlations, failures, off, warnings, math.inf if math.isnan(score) else score
    )


def _without_effort(text: str) -> str:
    """``text`` without its hint for ROS 2 bags (``(a ROS 2 bag: --effort ...)``)."""
    text = re.sub(r" \(a ROS 2 bag: --effort \w+\)", "", text)
    return re.sub(r" a ROS 2 bag: --effort \w+\)", ")", text)


def _kind_hint(robot: Robot, name: str, ratio: Array, joints: Sequence[int]) -> str:
    """What a signal far off the model may be instead: joint torques logged as currents (a ratio
    near gear ratio x torque constant) or currents logged as torques (its inverse)."""
    per_amp = np.abs(np.diag(transmission_matrix(robot))) * np.array(
        [j.drive.torque_constant for j in robot.joints]
    )
    factor = np.median(
        [ratio[j] * (1 / per_amp[j] if name in _CURRENTS else per_amp[j]) for j in joints]
    )
    if not 1 / 3 <= factor <= 3:
        return ""
    if name in _CURRENTS:
        return ": joint torques in N m logged as currents? (a ROS 2 bag: --effort torque)"
    return ": motor currents in A logged as torques? (a ROS 2 bag: --effort current)"


def _swaps(x: Array, y: Array, informative: Array, corr: Array) -> list[tuple[int, int]]:
    """Pairs of informative joints whose logged columns follow each other's model far better
    than their own."""
    pairs = []
    n = x.shape[1]
    for j in range(n):
        for k in range(j + 1, n):
            if not (informative[j] and informative[k]):
                continue
            if corr[j] > MATCH and corr[k] > MATCH:
                continue
            jk = float(np.corrcoef(x[:, k], y[:, j])[0, 1])
            kj = float(np.corrcoef(x[:, j], y[:, k])[0, 1])
            # each follows the other's model clearly better than its own
            if jk > SWAP_MATCH and kj > SWAP_MATCH and jk > corr[j] + 0.1 and kj > corr[k] + 0.1:
                pairs.append((j, k))
    return pairs


def _cross(x: Array, y: Array, j: int, k: int) -> str:
    jk = float(np.corrcoef(x[:, k], y[:, j])[0, 1])
    kj = float(np.corrcoef(x[:, j], y[:, k])[0, 1])
    return f"{jk:.2f}, {kj:.2f}"


def _swapped(rows: dict[str, Array], j: int, k: int) -> dict[str, Array]:
    """``rows`` with joints ``j`` and ``k`` exchanged in every signal."""
    out = {}
    for name, x in rows.items():
        y = x.copy()
        y[:, [j, k]] = x[:, [k, j]]
        out[name] = y
    return out


def _flipped(rows: dict[str, Array], j: int) -> dict[str, Array]:
    """``rows`` with joint ``j``'s sign reversed in every signal."""
    out = {}
    for name, x in rows.items():
        y = x.copy()
        y[:, j] = -x[:, j]
        out[name] = y
    return out


def _informed(match: RobotMatch, joints: Sequence[int]) -> bool:
    """Whether every signal informs ``match`` about all of ``joints``."""
    return bool(match.ratios) and all(
        all(np.isfinite(r[j]) for j in joints) for r in match.ratios.values()
    )


def payload_explains(robot: Robot, rows: dict[str, Array]) -> str:
    """A warning when a point mass at the flange, missing from ``robot``, explains the logged
    torques where the model alone does not (a payload the user did not give); "" otherwise.

    The mass ``m`` and its first moment ``m c`` are least squares of the torques the model
    misses on the last link's columns of the regressor (``Y @ pi == rnea``, nursing eq 15; a
    point mass's inertia is left out: second order at a robot's speeds), from the reference
    torque (``target_moment`` or measured torques), else from the currents through the torque
    constants and gear ratios. The model with that payload must then fit the log.
    """
    name = next((n for n in (*_TORQUES, *_CURRENTS) if n in rows), None)
    if name is None:
        return ""
    prefix = "target" if name.startswith("target") and "target_q" in rows else "actual"
    if f"{prefix}_q" not in rows:
        return ""
    q, qd, qdd = (rows[f"{prefix}_{k}"] for k in ("q", "qd", "qdd"))
    model = _model_signal(robot, rows, name)
    if model is None:
        return ""
    missed = rows[name] - model[0]
    if name in _CURRENTS:  # motor current -> joint torque, through k_t and the gear
        gear = np.abs(np.diag(transmission_matrix(robot)))
        missed = missed * gear * np.array([j.drive.torque_constant for j in robot.joints])
    last = slice(10 * (robot.n - 1), 10 * (robot.n - 1) + 4)
    columns = regressor(robot, q, qd, qdd)[:, :, last].reshape(-1, 4)
    theta = np.linalg.lstsq(columns, missed.reshape(-1), rcond=None)[0]
    mass = float(theta[0])
    if not 0.05 <= mass <= 100.0:
        return ""
    com_link = theta[1:] / mass
    com = (np.linalg.inv(robot.flange) @ np.append(com_link, 1.0))[:3]
    loaded = robot.with_payload(Payload(mass=mass, com=com))
    if not robot_match(loaded, rows).fits:
        return ""
    where = ",".join(f"{c:.3g}" for c in com)
    return (
        f"the logged {name} fits {robot.name} carrying about {mass:.3g} kg at [{where}] m (flange "
        f"frame) that the model lacks: give the payload (--payload {mass:.3g},{where}) or identify "
        "it (identify --payload-only)"
    )


def better_robot(robot: Robot, rows: dict[str, Array], score: float) -> str:
    """The built-in robot (of the same joint count) whose model fits the logged ``rows`` with
    the lowest score below ``score``; "" when none does."""
    best, best_score = "", score
    for name in library_names():
        other = load_robot(name)
        if other.n != robot.n or other.name == robot.name:
            continue
        m = robot_match(other, rows)
        if m.fits and m.score < best_score:
            best, best_score = other.name, m.score
    return best


def explain_mismatch(
    robot: Robot, rows: dict[str, Array], match: RobotMatch, *, library: bool = True
) -> str:
    """What would explain a failed robot check: a built-in robot (of the same joint count)
    whose model fits the log better (unless not ``library``), two joints exchanged in every
    logged signal, or one joint's sign reversed in every signal; "" when none does."""
    with np.errstate(all="ignore"):
        best = better_robot(robot, rows, match.score) if library else ""
        if best:
            return f"looks like {best} (its model fits this log)"
        for j in range(robot.n):
            for k in range(j + 1, robot.n):
                m = robot_match(robot, _swapped(rows, j, k))
                if m.fits and _informed(m, (j, k)) and m.score <= SWAP_SCORE:
                    return (
                        f"with joints {j + 1} and {k + 1} exchanged in every signal the model "
                        "fits: their columns look swapped"
                    )
        for j in range(robot.n):
            m = robot_match(robot, _flipped(rows, j))
            if m.fits and _informed(m, (j,)) and m.score <= SWAP_SCORE:
                return (
                    f"with joint {j + 1}'s sign reversed in every signal the model fits: its "
                    "sign looks flipped"
                )
    return ""


def check_log(robot: Robot, log: Log, accept: Iterable[Check] = ()) -> LogChecks:
    """The checks of a log held whole (one chunk of :class:`LogCheck`)."""
    check = LogCheck(robot, log.path, accept)
    check.add(log)
    return check.finish()
