"""The checks of a log's signals against themselves and the robot's ratings: ``time``, ``units``,
``speeds``, ``ratings`` and ``constant`` (the module docstring of :mod:`kinergy.logs.checks`
says what each looks for), judged on what the fold kept (:class:`Seen`), and the refusal of
values no robot logs in any unit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from kinergy.arrays import Array
from kinergy.drives.transmission import transmission_matrix
from kinergy.errors import KinergyError
from kinergy.logs.sums import Moments, Noise
from kinergy.logs.verdicts import Check, Findings, joint_label
from kinergy.model.robot import Robot

__all__ = [
    "ABSURD",
    "CURRENTS",
    "MEASURED",
    "MOVE_SPAN",
    "MOVE_SPEED",
    "PAIRS",
    "PERIOD_RANGE",
    "TORQUES",
    "Seen",
    "check_constant",
    "check_magnitudes",
    "check_ratings",
    "check_speeds",
    "check_time",
    "check_units",
    "moving",
    "rated_current",
]

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
#: a joint's speeds are judged when their spread is this many times the larger noise of the
#: logged speed and of the position's difference quotient (a right log then correlates at 0.97 or
#: more; a joint that barely moves, or moves within a short window, shows no more than noise)
SPEED_TO_NOISE = 4.0
#: positions may exceed the joint limits by this much (rad) before they are not radians
POSITION_MARGIN = 0.1
#: speeds may exceed the speed limit by this factor
SPEED_FACTOR = 2.0
#: currents, torques and voltages may exceed their rating by this factor
RATING_FACTOR = 5.0
#: deg C: plausible joint temperatures
TEMPERATURE_RANGE = (-40.0, 150.0)

#: the position and speed signals checked against each other
PAIRS = (("actual_q", "actual_qd"), ("target_q", "target_qd"))
#: torque-like signals, N m, against the limits' torque
TORQUES = ("target_moment", "actual_joint_torque", "actual_current_as_torque")
#: current signals, A, against the drive's rated current
CURRENTS = ("actual_current", "target_current")
#: measured signals that may not hold one value while their joint moves
MEASURED = (*TORQUES, *CURRENTS, "actual_joint_voltage")


@dataclass
class Seen:
    """What the fold kept of a log for these checks.

    Attributes
    ----------
    robot : Robot
    path : str
    lo, hi : dict of str to ndarray
        Per signal, the lowest and highest value of each column ((n,) for a joint signal, () for
        a scalar).
    period : float
        The median sample period of the first chunk, s (nan: fewer than two samples).
    speeds : dict of (str, str) to Moments
        Per (position, speed) pair of :data:`PAIRS`: the logged speed against the position's
        difference quotient, over steps within a segment.
    noise : dict of (str, str) to (Noise, Noise)
        Per pair, the noise of the logged speed and of the difference quotient.
    """

    robot: Robot
    path: str
    lo: dict[str, Array] = field(default_factory=dict)
    hi: dict[str, Array] = field(default_factory=dict)
    period: float = math.nan
    speeds: dict[tuple[str, str], Moments] = field(default_factory=dict)
    noise: dict[tuple[str, str], tuple[Noise, Noise]] = field(default_factory=dict)


def rated_current(robot: Robot) -> Array:
    """Per motor, the current that makes the joint's rated torque (A): ``N^-T tau_lim / k_t``,
    largest over the joints a coupled motor drives."""
    n_mat = transmission_matrix(robot)
    limits = np.array([j.limits.torque for j in robot.joints])
    motor = np.abs(np.linalg.solve(n_mat.T, np.diag(limits))).max(axis=1)
    kt = np.array([j.drive.torque_constant for j in robot.joints])
    return np.asarray(motor / kt, dtype=float)


def values_text(x: Array) -> str:
    """The first few distinct values of ``x``, for a message."""
    vals = sorted({float(v) for v in np.ravel(x)})
    return ", ".join(f"{v:.4g}" for v in vals[:3]) + (", ..." if len(vals) > 3 else "")


def check_magnitudes(seen: Seen) -> None:
    """Refuse values no robot logs in any unit (beyond :data:`ABSURD`): a corrupted log,
    whatever is accepted (computing on them would only overflow)."""
    for name in sorted(seen.lo):
        peak = float(np.max(np.maximum(np.abs(seen.lo[name]), np.abs(seen.hi[name]))))
        if not peak <= ABSURD:
            raise KinergyError(
                f"{seen.path}: {name} holds {peak:.3g}: not a value a robot logs in any unit "
                "(a corrupted log; no --accept lets it through)"
            )


def moving(seen: Seen) -> Array:
    """Per joint, whether it moves in the log (its position spans :data:`MOVE_SPAN`)."""
    n = seen.robot.n
    for name in ("actual_q", "target_q"):
        if name in seen.lo and seen.lo[name].shape == (n,):
            return np.asarray(seen.hi[name] - seen.lo[name] >= MOVE_SPAN)
    return np.zeros(n, dtype=bool)


def check_time(seen: Seen, found: Findings) -> None:
    lo, hi = PERIOD_RANGE
    if math.isnan(seen.period):
        found.verdict(Check.TIME, False, "fewer than two samples")
        return
    if not lo <= seen.period <= hi:
        found.fail(
            Check.TIME,
            f"the sample period is {seen.period:.4g} s, not a controller's "
            f"({lo * 1e3:g} ms to {hi:g} s): are the time stamps in another unit, or is the "
            "first column not the time?",
        )
    found.verdict(Check.TIME, True)


def check_units(seen: Seen, found: Findings) -> None:
    robot, ran = seen.robot, False
    for name in ("actual_q", "target_q"):
        if name not in seen.lo or seen.lo[name].shape != (robot.n,):
            continue
        ran = True
        for j, joint in enumerate(robot.joints):
            if joint.limits.continuous:  # no end stop: any angle is one (speeds check units)
                continue
            low, high = joint.limits.position
            x_lo, x_hi = seen.lo[name][j], seen.hi[name][j]
            if x_lo < low - POSITION_MARGIN or x_hi > high + POSITION_MARGIN:
                degrees = (
                    np.radians(x_lo) >= low - POSITION_MARGIN
                    and np.radians(x_hi) <= high + POSITION_MARGIN
                )
                hint = " (degrees? kinergy reads radians)" if degrees else ""
                found.fail(
                    Check.UNITS,
                    f"{name} of {joint_label(robot, j)} spans {x_lo:.4g} to {x_hi:.4g}, beyond its "
                    f"limits {low:.4g} to {high:.4g} rad{hint}",
                )
    for name in ("actual_qd", "target_qd"):
        if name not in seen.lo or seen.lo[name].shape != (robot.n,):
            continue
        ran = True
        peak = np.maximum(np.abs(seen.lo[name]), np.abs(seen.hi[name]))
        for j, joint in enumerate(robot.joints):
            if peak[j] > SPEED_FACTOR * joint.limits.speed:
                degrees = np.radians(peak[j]) <= SPEED_FACTOR * joint.limits.speed
                hint = " (degrees per second? kinergy reads rad/s)" if degrees else ""
                found.fail(
                    Check.UNITS,
                    f"{name} of {joint_label(robot, j)} reaches {peak[j]:.4g}, more than "
                    f"{SPEED_FACTOR:g} times its limit of {joint.limits.speed:.4g} rad/s{hint}",
                )
    if "joint_temperatures" in seen.lo:
        ran = True
        t_lo, t_hi = TEMPERATURE_RANGE
        lo, hi = (
            float(np.min(seen.lo["joint_temperatures"])),
            float(np.max(seen.hi["joint_temperatures"])),
        )
        if lo < t_lo or hi > t_hi:
            hint = " (kelvin? kinergy reads deg C)" if 230 < lo and hi < 430 else ""
            found.fail(
                Check.UNITS,
                f"joint_temperatures span {lo:.4g} to {hi:.4g}, not deg C of a working robot{hint}",
            )
    found.verdict(Check.UNITS, ran, "no positions, speeds or temperatures")


def check_speeds(seen: Seen, found: Findings, moving: Array) -> None:
    robot, ran = seen.robot, False
    for (q_name, qd_name), m in seen.speeds.items():
        if not np.any(m.n > 0):
            continue
        slope, corr, rms = m.slope(), m.correlation(), m.rms_x()
        noise = np.zeros(robot.n)
        if (q_name, qd_name) in seen.noise:
            speed, quotient = seen.noise[(q_name, qd_name)]
            noise = np.maximum(speed.sigma(), quotient.sigma())
        with np.errstate(invalid="ignore", divide="ignore"):
            spread = np.sqrt(np.maximum(m.sxx / m.n - (m.sx / m.n) ** 2, 0.0))
        bad: list[tuple[int, float, float]] = []
        for j in range(robot.n):
            derivative_rms = math.sqrt(m.syy[j] / m.n[j]) if m.n[j] else 0.0
            if not moving[j] or max(rms[j], derivative_rms) < MOVE_SPEED:
                continue
            if not max(rms[j], derivative_rms) >= SPEED_TO_NOISE * noise[j]:
                continue  # nothing but noise to compare
            ran = True
            # s: slope of the derivative on the logged speed; the correlation only where the
            # speed varies beyond its noise (a constant speed correlates with nothing)
            s, r = float(slope[j]), float(corr[j])
            varies = spread[j] >= max(MOVE_SPEED, SPEED_TO_NOISE * noise[j])
            if not (
                SPEED_SLOPE[0] <= s <= SPEED_SLOPE[1] and (r >= SPEED_CORRELATION or not varies)
            ):
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
        shown = ", ".join(
            f"{joint_label(robot, j)} {x:.3g} (correlation {r:.2f})"
            for (j, _, r), x in zip(bad, ratios, strict=True)
        )
        found.fail(
            Check.SPEEDS,
            f"{qd_name} is not the derivative of {q_name} (a speed column gives 1 and "
            f"correlation 1): {shown}: {hint}",
        )
    found.verdict(Check.SPEEDS, ran, "no joint moves with both positions and speeds logged")


def check_ratings(seen: Seen, found: Findings) -> None:
    robot, ran = seen.robot, False
    torque = np.array([j.limits.torque for j in robot.joints])
    current = rated_current(robot)
    for names, rating, unit, small in (
        (TORQUES, torque, "N m", "N mm"),
        (CURRENTS, current, "A", "mA"),
        (("actual_joint_voltage",), np.full(robot.n, robot.bus_voltage), "V", "mV"),
    ):
        for name in names:
            if name not in seen.lo or seen.lo[name].shape != (robot.n,):
                continue
            ran = True
            peak = np.maximum(np.abs(seen.lo[name]), np.abs(seen.hi[name]))
            over = np.flatnonzero(~(peak <= RATING_FACTOR * rating))
            if over.size:
                j = int(over[np.argmax(peak[over] / rating[over])])
                # a thousand times too large: the next smaller unit
                thousand = 50 * rating[j] < peak[j] <= 1000 * RATING_FACTOR * rating[j]
                hint = f" ({small}? kinergy reads {unit})" if thousand else ""
                if not thousand and name in CURRENTS:
                    hint = (
                        " (joint torques in N m logged as currents? a ROS 2 bag: --effort torque)"
                    )
                found.fail(
                    Check.RATINGS,
                    f"{name} of {joint_label(robot, j)} reaches {peak[j]:.4g} {unit}, more than "
                    f"{RATING_FACTOR:g} times its rating of {rating[j]:.3g} {unit}{hint}",
                )
    bus = float(seen.hi.get("actual_robot_voltage", np.nan))
    if bus < 0.5 * robot.bus_voltage:
        found.fail(
            Check.RATINGS,
            f"actual_robot_voltage never exceeds {bus:.4g} V, under half the {robot.bus_voltage:g} V "
            "bus it measures: another signal, or another unit?",
        )
    drawn = float(seen.hi.get("actual_robot_current", np.nan))
    if drawn <= 0.0 and moving(seen).any():
        found.fail(
            Check.RATINGS,
            f"actual_robot_current is never positive ({drawn + 0.0:.4g} A at most) while the arm "
            "moves, yet the arm draws from its supply: its sign flipped?",
        )
    for name, limit, unit in (
        ("actual_robot_voltage", 5.0 * robot.bus_voltage, "V"),
        ("actual_robot_current", RATING_FACTOR * float(np.sum(current)), "A"),
    ):
        if name in seen.lo:
            ran = True
            top = float(max(abs(seen.lo[name]), abs(seen.hi[name])))
            if not top <= limit:
                found.fail(
                    Check.RATINGS,
                    f"{name} reaches {top:.4g} {unit}, beyond a plausible {limit:.3g} {unit}",
                )
    found.verdict(Check.RATINGS, ran, "no currents, torques or voltages")


def check_constant(seen: Seen, found: Findings, moving: Array) -> None:
    robot, ran = seen.robot, False
    for name in ("actual_qd", "target_qd", *MEASURED):
        if name not in seen.lo or seen.lo[name].shape != (robot.n,):
            continue
        ran = True
        flat = seen.lo[name] == seen.hi[name]
        if name in ("actual_qd", "target_qd"):  # a joint cruises at one speed: not stuck unless 0
            flat &= seen.lo[name] == 0.0
        stuck = np.flatnonzero(flat & moving)
        if flat.all() and moving.any():
            found.fail(
                Check.CONSTANT,
                f"{name} holds one value on every joint and every sample "
                f"({values_text(seen.lo[name])}) while the arm moves: not logged?",
            )
        elif stuck.size:
            joints = ", ".join(joint_label(robot, int(j)) for j in stuck)
            found.fail(
                Check.CONSTANT,
                f"{name} of {joints} holds {values_text(seen.lo[name][stuck])} on every sample "
                "while the joint moves: not logged?",
            )
    for name in ("actual_robot_current",):  # the supply's (an ideal voltage may be constant)
        if name in seen.lo and moving.any():
            ran = True
            if float(seen.lo[name]) == float(seen.hi[name]):
                found.fail(
                    Check.CONSTANT,
                    f"{name} holds {float(seen.lo[name]):.4g} on every sample while the arm "
                    "moves: not logged?",
                )
    found.verdict(Check.CONSTANT, ran, "no measured signal")
