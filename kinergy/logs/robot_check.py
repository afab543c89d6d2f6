"""The ``robot`` check: does the robot's nominal model explain a log's torques and currents?

The nominal model's torques and currents (:func:`kinergy.predict.drive_state`: the rigid body
with the log's payload, the reflected rotor inertia and, for currents, the drive's friction and
torque constant) are set against the logged ``target_moment``, measured torques or currents on
an evenly thinned sample of rows: per joint a ratio (least-squares slope) and a correlation
(:func:`robot_match`). A joint whose sign is flipped, two joints swapped, or a log another
built-in robot explains far better fail, with the ratios seen and, where one fits, the robot
that would (:func:`explain_mismatch`). A joint whose modelled signal does not stand out of the
log's noise is not judged; a load the model lacks is named with the payload that would explain
it (:func:`payload_explains`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from kinergy.arrays import Array
from kinergy.drives.transmission import joint_torque, transmission_matrix
from kinergy.dynamics.regressor import regressor
from kinergy.errors import Code
from kinergy.logs.payload import describe, from_columns
from kinergy.logs.signal_checks import CURRENTS, MOVE_SPAN, MOVE_SPEED, TORQUES, rated_current
from kinergy.logs.sums import Moments
from kinergy.logs.verdicts import Check, Findings, first, joint_label
from kinergy.messages import Message
from kinergy.model.library import library_names, load_robot
from kinergy.model.robot import Payload, Robot
from kinergy.predict import (
    DriveState,
    drive_by_payload,
    drive_state,
    payload_robots,
    sensor_torque,
)

__all__ = [
    "LOADS",
    "Explained",
    "RobotMatch",
    "better_robot",
    "explain_mismatch",
    "judge_robot",
    "noise_name",
    "payload_explains",
    "robot_match",
    "without_effort",
]

#: a joint is informative for the robot check when the model's signal varies by this fraction
#: of its rating (standard deviation)
INFORMATIVE = 0.02
#: ... and by this many times the logged signal's noise (standard deviations): below it a right
#: log's correlation is 0.9 or less, and a short window or a joint that barely moves shows
#: nothing the check could judge
SIGNAL_TO_NOISE = 2.0
#: a joint's current is mostly friction where the model's load torque varies by less than this
#: share of its friction's variation: a nominal robot file's friction, its jumps with the
#: direction of power flow too, does not predict it, so such a current that does not follow the
#: model tells nothing about the robot (only a reversed sign does)
RIGID_SHARE = 1.0
#: why a joint is not judged (:attr:`RobotMatch.unjudged`)
NOISY = "its modelled signal does not stand out of the log's noise: a short window, a joint that barely moves"
FRICTION = "its current is mostly friction, which the model's nominal values do not predict, and does not follow it"
#: the rows' key of the logged payload (:func:`kinergy.logs.payload.payload_columns`, (k, 10))
LOADS = "payload"
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
    unjudged : dict of str to list of str
        Joints that move but are not judged, by why (:data:`NOISY`, :data:`FRICTION`): per
        reason ``"actual_current of joints 1, 3"`` texts, one per signal.
    scale : str
        The signal that set :attr:`score` ("" when none did).
    """

    ratios: dict[str, Array]
    correlations: dict[str, Array]
    failures: list[str] = field(default_factory=list)
    off: str = ""
    warnings: list[str] = field(default_factory=list)
    score: float = math.inf
    skipped: str = ""
    unjudged: dict[str, list[str]] = field(default_factory=dict)
    scale: str = ""

    @property
    def fits(self) -> bool:
        """Nothing failed and every signal's scale is in its band."""
        return not (self.failures or self.off or self.skipped)


def noise_name(name: str) -> str:
    """The rows' key of the second differences of the logged signal ``name`` (its noise)."""
    return f"{name}:noise"


def _noise(rows: dict[str, Array], name: str) -> Array:
    """The logged signal's noise per joint (standard deviation, its unit): the median absolute
    second difference of consecutive samples, which a smooth signal keeps near 0 and white noise
    of deviation s brings to 0.6745 sqrt(6) s; 0 where not kept."""
    d2 = rows.get(noise_name(name))
    if d2 is None or not len(d2):
        return np.zeros(rows[name].shape[1])
    return np.asarray(np.median(np.abs(d2), axis=0) / (0.6745 * math.sqrt(6.0)), dtype=float)


def _drive(robot: Robot, rows: dict[str, Array], q: Array, qd: Array, qdd: Array) -> DriveState:
    """The drive model on the rows' motion, each row with the payload the log says it carried
    (:data:`LOADS`), else with ``robot``'s own."""
    loads = rows.get(LOADS)
    if loads is None:
        return drive_state(robot, q, qd, qdd)
    unique, index = np.unique(loads, axis=0, return_inverse=True)
    payloads = tuple(from_columns(row) if row.any() else None for row in unique)
    robots = payload_robots(robot, payloads)
    return drive_by_payload(robots, np.asarray(index).reshape(-1), q, qd, qdd)


def _model_signal(
    robot: Robot, rows: dict[str, Array], name: str
) -> tuple[Array, Array, Array, Array] | None:
    """The model's prediction of the logged signal ``name`` on the logged motion (the commanded
    one where logged: noise-free, and the real motion trails it by a few milliseconds only,
    where the measured speeds' noise, differentiated, would swamp a wrist's inertial and
    friction terms; else the measured one), its rating per joint and which joints move (a joint
    at rest holds whatever its position loop needs: nothing to compare); None without a
    motion; and per joint whether the model's signal there is more than friction (a current whose
    variation friction dominates, a nominal robot file's friction does not predict: the joint
    tells nothing about the robot)."""
    prefix = "target" if "target_q" in rows else "actual" if "actual_q" in rows else ""
    if not prefix:
        return None
    q, qd, qdd = (rows[f"{prefix}_{k}"] for k in ("q", "qd", "qdd"))
    state = _drive(robot, rows, q, qd, qdd)
    torque = np.array([j.limits.torque for j in robot.joints])
    moving = (np.ptp(q, axis=0) >= MOVE_SPAN) & (np.sqrt(np.mean(qd**2, axis=0)) >= MOVE_SPEED)
    every = np.ones(robot.n, dtype=bool)
    if name == "target_moment":
        return state.tau_sim, torque, moving, every
    if name == "actual_joint_torque":
        return sensor_torque(robot, state), torque, moving, every
    if name == "actual_current_as_torque":
        return joint_torque(robot, state.tau_m), torque, moving, every
    rigid = state.tau_load.std(axis=0) >= RIGID_SHARE * state.tau_friction.std(axis=0)
    return state.current, rated_current(robot), moving, rigid


@dataclass(frozen=True)
class _Signal:
    """One logged signal set against the model: per joint the ratio and correlation, the joints
    judged, the failures and the joints that follow the model."""

    ratio: Array
    corr: Array
    judged: Array
    failures: list[str]
    good: list[int]
    unjudged: dict[str, list[int]]
    rigid: Array


def _signal_match(robot: Robot, rows: dict[str, Array], name: str) -> _Signal | None:
    """The logged signal ``name`` of ``rows`` against ``robot``'s model of it (None without a
    motion): flipped signs, swapped joints and joints that do not follow the model, judged on
    the joints that move and whose modelled signal varies by :data:`INFORMATIVE` of the rating
    and stands out of the logged signal's noise (:data:`SIGNAL_TO_NOISE`). A current that
    friction dominates (:data:`RIGID_SHARE`) and does not follow the model is not judged (the
    nominal friction does not predict it) unless its sign is reversed."""
    model = _model_signal(robot, rows, name)
    if model is None:
        return None
    x, rating, moving, rigid = model
    y, n = rows[name], robot.n
    sums = Moments(n)
    sums.add(x, y)
    ratio, corr = sums.slope(), sums.correlation()
    spread, noise = x.std(axis=0), _noise(rows, name)
    varies = moving & (spread >= INFORMATIVE * rating)
    clear = spread >= SIGNAL_TO_NOISE * noise
    judged = varies & clear
    loose = judged & np.logical_not(rigid) & ~(corr >= NEGATIVE) & ~(corr < -NEGATIVE)
    judged &= ~loose
    unjudged = {
        NOISY: [int(j) for j in np.flatnonzero(varies & ~clear)],
        FRICTION: [int(j) for j in np.flatnonzero(loose)],
    }
    failures: list[str] = []
    swapped = _swaps(x, y, judged, corr)
    in_swap = {j for pair in swapped for j in pair}
    for j, k in swapped:
        failures.append(
            f"{name} of {joint_label(robot, j)} and {joint_label(robot, k)} look swapped: each "
            f"follows the other's model (correlations {_cross(x, y, j, k)}; with their own "
            f"{corr[j]:.2f}, {corr[k]:.2f})"
        )
    good = []
    for j in range(n):
        if not judged[j] or j in in_swap:
            continue
        if corr[j] < -NEGATIVE:
            failures.append(
                f"{name} of {joint_label(robot, j)} has the opposite sign of the model's "
                f"(ratio {ratio[j]:.2f}, correlation {corr[j]:.2f}): sign flipped?"
            )
        elif not corr[j] >= NEGATIVE:
            failures.append(
                f"{name} of {joint_label(robot, j)} does not follow {robot.name}'s model "
                f"(correlation {corr[j]:.2f}, ratio {ratio[j]:.2f})"
            )
        else:
            good.append(j)
    return _Signal(ratio, corr, judged, failures, good, unjudged, rigid)


def robot_match(robot: Robot, rows: dict[str, Array]) -> RobotMatch:
    """Judge whether the logged torques and currents ``rows`` (name -> (k, n), with the logged
    motion ``actual_q/qd/qdd`` or ``target_q/qd/qdd``, the logged payload under :data:`LOADS`)
    belong to ``robot`` (module docstring).

    Every signal is checked for flipped signs, swapped joints and joints that do not follow the
    model (:func:`_signal_match`); the scale (the ratios against the band of
    :data:`RATIO_BAND`, and the score) is judged on the first signal of ``target_moment``,
    measured torques, ``actual_current_as_torque``, currents that the motion informs: a torque
    does not depend on the drives' torque constants, which a robot file may have off by a factor
    of 2.
    """
    ratios: dict[str, Array] = {}
    correlations: dict[str, Array] = {}
    failures: list[str] = []
    warnings: list[str] = []
    unjudged: dict[str, list[str]] = {}
    off, score, scale = "", math.nan, ""
    for name in (*TORQUES, *CURRENTS):
        if name not in rows or rows[name].shape[1:] != (robot.n,):
            continue
        found = _signal_match(robot, rows, name)
        if found is None:
            continue
        # the scale: on joints the rigid body drives (a friction-made current's scale is the
        # robot file's nominal friction's)
        ratio, good = found.ratio, [j for j in found.good if found.rigid[j]]
        ratios[name] = np.where(found.judged, ratio, np.nan)
        correlations[name] = np.where(found.judged, found.corr, np.nan)
        failures += found.failures
        for why, joints in found.unjudged.items():
            if joints:
                which = ", ".join(str(j + 1) for j in joints)
                unjudged.setdefault(why, []).append(
                    f"{name} of joint{'s' if len(joints) > 1 else ''} {which}"
                )
        if not good:
            continue
        band = RATIO_BAND["torque" if name in TORQUES else "current"]
        out = [j for j in good if not band[0] <= ratio[j] <= band[1]]
        wild = [j for j in good if not WIDE_BAND[0] <= ratio[j] <= WIDE_BAND[1]]
        seen = ", ".join(f"{joint_label(robot, j)} {ratio[j]:.2f}" for j in (out or good))
        text = (
            f"{name} is {seen} times {robot.name}'s model (a matching robot gives "
            f"{band[0]:.2g} to {band[1]:.2g})"
        )
        if wild:  # beyond what a model a little off explains: a unit, a kind, a robot
            failures.append(text + _kind_hint(robot, name, ratio, wild))
        if math.isnan(score):  # the first informed signal sets the scale
            score = float(np.median(np.abs(np.log(np.clip(ratio[good], 1e-12, None)))))
            scale = name
            if not wild and out and len(out) * 2 >= len(good):
                off = text
            elif not wild and out:
                warnings.append(f"{text}: the model's drives or masses may be off there")
    if not ratios:
        return RobotMatch({}, {}, skipped="no motion beside the torques or currents")
    if not any(np.any(np.isfinite(r)) for r in ratios.values()):
        why = "no joint moves enough to compare"
        if unjudged:
            why = "no joint's modelled signal stands out of the log's noise"
        return RobotMatch(ratios, correlations, skipped=why, unjudged=unjudged)
    final = math.inf if math.isnan(score) else score
    return RobotMatch(
        ratios, correlations, failures, off, warnings, final, unjudged=unjudged, scale=scale
    )


def without_effort(text: str) -> str:
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
        [ratio[j] * (1 / per_amp[j] if name in CURRENTS else per_amp[j]) for j in joints]
    )
    if not 1 / 3 <= factor <= 3:
        return ""
    if name in CURRENTS:
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
        if name != LOADS:  # the payload is the flange's, not a joint's
            y[:, [j, k]] = x[:, [k, j]]
        out[name] = y
    return out


def _flipped(rows: dict[str, Array], j: int) -> dict[str, Array]:
    """``rows`` with joint ``j``'s sign reversed in every signal."""
    out = {}
    for name, x in rows.items():
        y = x.copy()
        if name != LOADS:
            y[:, j] = -x[:, j]
        out[name] = y
    return out


def _informed(match: RobotMatch, joints: Sequence[int]) -> bool:
    """Whether some signal informs ``match`` about all of ``joints`` (a current that friction
    dominates may not: the torque does)."""
    return any(all(np.isfinite(r[j]) for j in joints) for r in match.ratios.values())


@dataclass(frozen=True)
class Explained:
    """A payload that explains a log the model alone does not (:func:`payload_explains`).

    Attributes
    ----------
    text : str
        The warning naming it, with the ``--payload`` that would give it.
    score : float
        The loaded model's :attr:`RobotMatch.score` on the log.
    """

    text: str
    score: float


def _logged(rows: dict[str, Array]) -> Payload | bool | None:
    """The one payload the rows log (None: none or a mass of 0), or False when they log
    several."""
    loads = rows.get(LOADS)
    if loads is None:
        return None
    unique = np.unique(loads, axis=0)
    if len(unique) > 1:
        return False
    return from_columns(unique[0]) if unique[0].any() else None


def payload_explains(robot: Robot, rows: dict[str, Array]) -> Explained | None:
    """A point mass at the flange, missing from ``robot`` and from the payload the log says it
    carried, that explains the logged torques where the model alone does not (a payload the user
    did not give, or not all of it); None otherwise.

    The mass ``m`` and its first moment ``m c`` are least squares of the torques the model
    misses on the last link's columns of the regressor (``Y @ pi == rnea``, nursing eq 15; a
    point mass's inertia is left out: second order at a robot's speeds), from the reference
    torque (``target_moment`` or measured torques), else from the currents through the torque
    constants and gear ratios. The model with that payload (joined to the logged one) must then
    fit the log.
    """
    name = next((n for n in (*TORQUES, *CURRENTS) if n in rows), None)
    logged = _logged(rows)
    if name is None or logged is False:
        return None
    prefix = "target" if "target_q" in rows else "actual"  # as _model_signal's
    if f"{prefix}_q" not in rows:
        return None
    q, qd, qdd = (rows[f"{prefix}_{k}"] for k in ("q", "qd", "qdd"))
    model = _model_signal(robot, rows, name)
    if model is None:
        return None
    missed = rows[name] - model[0]
    if name in CURRENTS:  # motor current -> joint torque, through k_t and the gear
        gear = np.abs(np.diag(transmission_matrix(robot)))
        missed = missed * gear * np.array([j.drive.torque_constant for j in robot.joints])
    last = slice(10 * (robot.n - 1), 10 * (robot.n - 1) + 4)
    columns = regressor(robot, q, qd, qdd)[:, :, last].reshape(-1, 4)
    theta = np.linalg.lstsq(columns, missed.reshape(-1), rcond=None)[0]
    mass = float(theta[0])
    if not 0.05 <= mass <= 100.0:
        return None
    com = (np.linalg.inv(robot.flange) @ np.append(theta[1:] / mass, 1.0))[:3]
    total = Payload(mass=mass, com=com)
    if isinstance(logged, Payload):  # the two bodies as one, about their joint centre of mass
        both = logged.mass + mass
        total = Payload(both, (logged.mass * logged.com + mass * com) / both, logged.inertia)
    bare = {k: v for k, v in rows.items() if k != LOADS}
    match = robot_match(robot.with_payload(total), bare)
    if not match.fits:
        return None
    where = ",".join(f"{c:.3g}" for c in total.com)
    extra = f"{mass:.3g} kg at [{','.join(f'{c:.3g}' for c in com)}] m (flange frame)"
    beside = ""
    if isinstance(logged, Payload):
        beside = f" beside the controller's logged {describe(logged)}"
    return Explained(
        f"the logged {name} fits {robot.name} carrying about {extra}{beside} that the model "
        f"lacks: give the whole payload (--payload {total.mass:.3g},{where}) or identify it "
        "(identify --payload-only)",
        match.score,
    )


def better_robot(robot: Robot, rows: dict[str, Array], score: float) -> str:
    """The built-in robot (of the same joint count) whose model fits the logged ``rows`` with
    the lowest score below ``score``; "" when none does."""
    return _best_robot(robot, rows, score)[0]


def _best_robot(robot: Robot, rows: dict[str, Array], score: float) -> tuple[str, float]:
    """:func:`better_robot` and its score (``score`` when none fits better)."""
    best, best_score = "", score
    for name in library_names():
        other = load_robot(name)
        if other.n != robot.n or other.name == robot.name:
            continue
        m = robot_match(other, rows)
        if m.fits and m.score < best_score:
            best, best_score = other.name, m.score
    return best, best_score


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


def judge_robot(robot: Robot, rows: dict[str, Array], found: Findings) -> None:
    """The ``robot`` check on the thinned rows ``rows`` (name -> (k, ...)): its verdict into
    ``found`` (module docstring). A log the model does not fit passes with a warning when a
    payload it lacks explains it (:func:`payload_explains`) better than another built-in robot
    does; joints whose signal does not stand out of the noise are named in a note."""
    if not any(n in rows for n in (*TORQUES, *CURRENTS)):
        found.verdict(Check.ROBOT, False, "no torques or currents logged")
        return
    if next(iter(rows.values())).shape[0] < 20:
        found.verdict(Check.ROBOT, False, "too few samples")
        return
    with np.errstate(all="ignore"):
        match = robot_match(robot, rows)
    if match.unjudged:
        found.notes.append(
            "robot check: not judged: "
            + "; ".join(f"{' and '.join(what)} ({why})" for why, what in match.unjudged.items())
        )
    if match.skipped:
        found.verdict(Check.ROBOT, False, match.skipped)
        return
    if match.failures or match.off or match.warnings or match.score > POOR_SCORE:
        with np.errstate(all="ignore"):
            load = payload_explains(robot, rows)
            other = _best_robot(robot, rows, CLOSE_SCORE)[1] if load is not None else math.inf
        if load is not None and load.score <= other:
            found.warnings.append(Message(load.text, Code.PAYLOAD_MISSING))
            found.verdict(Check.ROBOT, True)
            return
    _judge_mismatch(robot, rows, match, found)


def _payload_misfit(robot: Robot, rows: dict[str, Array], match: RobotMatch) -> str:
    """The robot's payload named as what does not fit the log, when the robot without it
    (nor any logged one) fits better; "" otherwise (no payload, or it is not the cause)."""
    if robot.payload is None or robot.payload.mass <= 0:
        return ""
    bare = {k: v for k, v in rows.items() if k != LOADS}
    with np.errstate(all="ignore"):
        without = robot_match(robot.with_payload(None), bare)
    if not without.fits or not without.score < match.score:
        return ""
    return (
        f"the payload {describe(robot.payload)} does not fit this log: {robot.name}'s model "
        "fits it without that payload; check --payload (or the robot file's payload)"
    )


def _judge_mismatch(
    robot: Robot, rows: dict[str, Array], match: RobotMatch, found: Findings
) -> None:
    """The verdict on a log no payload explains: a failure where the model does not follow the
    log, another robot fits far better, or a swap or flip explains it; else warnings."""
    if match.failures or match.off:
        hint = _payload_misfit(robot, rows, match) or explain_mismatch(robot, rows, match)
        seen = first(match.failures) or match.off
        if match.failures or hint:
            found.fail(Check.ROBOT, f"{hint}: {seen}" if hint else seen)
        else:
            found.warnings.append(
                f"{match.off}; no built-in robot fits better: the model's masses or torque "
                "constants, a payload, or the logged signal's scale are off (what is fitted "
                "to it will be too)"
            )
    elif match.warnings and (hint := explain_mismatch(robot, rows, match, library=False)):
        found.fail(Check.ROBOT, f"{hint}: {match.warnings[0].split(': the model')[0]}")
    elif match.score > POOR_SCORE and match.scale in TORQUES:
        # a current's scale carries the robot file's nominal torque constants (off by up to 2):
        # only a torque's tells one robot from another this finely
        with np.errstate(all="ignore"):
            misfit = _payload_misfit(robot, rows, match)
            best = "" if misfit else better_robot(robot, rows, CLOSE_SCORE)
        if misfit:
            found.fail(Check.ROBOT, misfit)
        elif best:
            found.fail(
                Check.ROBOT,
                f"{robot.name}'s model is {math.exp(match.score):.2f} times off the "
                f"log's torques where {best}'s fits within {math.exp(CLOSE_SCORE):.2f}: "
                f"looks like {best} (or a payload the model lacks: --payload)",
            )
    if Check.ROBOT not in found.failed:
        found.warnings.extend(match.warnings)
    found.verdict(Check.ROBOT, True)
