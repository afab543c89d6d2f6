"""A payload's mass, centre of mass and (where the motion excites it) inertia, from a log taken
with it and a model identified without it.

The payload adds, at every joint, torques linear in its 10 inertial parameters expressed in the
last link's frame (the last link's columns of the regressor, nursing eq 15). With the joint torque
the motors deliver measured through the currents (``N^T k_t I``, UR5e eqs 10, 17), or taken from
measured joint torques, the part the unloaded model does not explain is regressed on those
columns by least squares in N m, all joints stacked:

    N^T (k_t I) - tau_model(q, qd, qdd) = Y_n(q, qd, qdd) [m, m c, I_o]

Mass and first moment are always estimated; the six inertia terms only when the log excites them
well enough (relative standard deviation below :data:`MAX_INERTIA_SPREAD`); otherwise the payload
is a point mass, as UR's own ``set_payload`` takes it.

The residuals of a real log are far from white (the model's errors follow the motion for seconds),
so the white-noise formula understates the standard errors tenfold or more. They come instead
from a delete-one-block jackknife over :data:`BLOCKS` contiguous time blocks (the larger of the
two is stated): a motion whose parts disagree about the payload gets the wide error bars it
deserves, and a centre of mass whose error exceeds :data:`MAX_COM_STD` is reported as not
identifiable from this motion, with the motion that would fix it.

Every pass over the logs folds their rows into triangles (:class:`kinergy.linalg.Reduced`), one
per *cell*: the samples that share a time block of all the logs stacked, a log, and a time
block of that log. The whole fit, each jackknife fit without one block and each log's own fit
(and its jackknife) are those cells' triangles joined, so nothing is held but them.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from kinergy.arrays import Array
from kinergy.drives.electrics import torque_constants
from kinergy.drives.transmission import joint_torque
from kinergy.dynamics.regressor import regressor
from kinergy.errors import KinergyError
from kinergy.identification.chunks import LogChunks, data_history, one_blas_thread
from kinergy.identification.columns import ROWS
from kinergy.identification.drive_steps import joined
from kinergy.identification.options import Target
from kinergy.identification.physical import inertia_vector, link_from_standard
from kinergy.linalg import Reduced, scaled_solution
from kinergy.logs.prepare import IdentData
from kinergy.model.robot import Payload, Robot
from kinergy.predict import drive_state, sensor_torque

__all__ = [
    "BLOCKS",
    "MAX_COM_STD",
    "PayloadEstimate",
    "block_std",
    "identify_payload",
    "jackknife_std",
    "payload",
]


#: inertia terms are reported only when their relative standard deviation is below this
MAX_INERTIA_SPREAD = 0.2
#: contiguous time blocks of the jackknife standard errors
BLOCKS = 10
#: m: a centre-of-mass coordinate with a larger standard error is not identifiable
MAX_COM_STD = 0.02
#: the motion that shows each centre-of-mass coordinate (flange frame)
_COM_MOTION = {
    "x": "wrist 3 turned through half a turn or more with the flange axis near horizontal",
    "y": "wrist 3 turned through half a turn or more with the flange axis near horizontal",
    "z": "the flange axis tilted from vertical to horizontal (wrists 1 and 2)",
}
#: the check that tells how a payload sits on the flange in a log
_MOUNT_CHECK = (
    "start each loaded log with the flange axis horizontal and wrist 3 held a few seconds at "
    "0, 90, 180 and 270 deg: the wrist-3 current then gives the centre of mass's angle about "
    "the flange axis directly"
)


@dataclass(frozen=True)
class PayloadEstimate:
    """An identified payload and its uncertainty.

    Attributes
    ----------
    signal : str
        What it was fitted to (``current`` or ``target_moment``).
    mass, mass_std : float
        kg, and its standard error.
    com, com_std : tuple of float
        Centre of mass in the flange frame, m, and standard errors.
    inertia : tuple of float or None
        ``[Ixx, Iyy, Izz, Ixy, Iyz, Ixz]`` about the centre of mass, flange axes, kg m^2; None
        when the motion does not excite it (a point mass is written).
    condition : float
        Condition number of the column-scaled regression.
    samples : int
    notes : tuple of str
    """

    signal: str
    mass: float
    mass_std: float
    com: tuple[float, ...]
    com_std: tuple[float, ...]
    inertia: tuple[float, ...] | None
    condition: float
    samples: int
    notes: tuple[str, ...]


def identify_payload(
    robot: Robot, datas: Sequence[IdentData], *, signal: Target | str = Target.AUTO
) -> tuple[Payload, PayloadEstimate]:
    """:func:`payload` from prepared logs held in memory (each one chunk)."""
    try:
        parsed = Target(signal)
    except ValueError:
        raise KinergyError(
            f"unknown signal {signal!r} (known: auto, current, torque, moment)"
        ) from None
    return payload(robot, LogChunks.of(datas), signal=parsed)


@one_blas_thread
def payload(
    robot: Robot, logs: LogChunks, *, signal: Target = Target.AUTO
) -> tuple[Payload, PayloadEstimate]:
    """Identify the payload at the flange from logs taken with it.

    Parameters
    ----------
    robot : Robot
        The model identified without the payload (its own payload, if any, is ignored).
    logs : LogChunks
        Logs taken with the payload.
    signal : Target
        What measures the joint torques: motor currents (``AUTO``: them when present), measured
        joint torques, or ``target_moment`` (only if the controller was told about the payload).

    Returns
    -------
    payload : Payload
        Mass (kg), centre of mass in the flange frame (m) and inertia about it (kg m^2, zeros
        when not excited).
    report : PayloadEstimate
        Values with standard deviations, the condition number, and notes.

    Raises
    ------
    KinergyError
        No usable signal, a negative mass, or a motion that does not excite the payload.
    """
    bare = robot.with_payload(None)
    signal = _pick_signal(logs) if signal == Target.AUTO else signal
    cells, x, std, cond = _point_mass(robot, bare, logs, signal)
    every = [c.problem for c in cells]
    full, full_std, cond_full = scaled_solution(joined(every))
    blocks = _parts(cells, lambda c: c.block)
    full_std = np.maximum(full_std, jackknife_std(blocks))
    inertia_ok = bool(
        np.all(full_std[4:] < MAX_INERTIA_SPREAD * np.maximum(np.abs(full[4:]), 1e-3))
    )
    white = std[0]
    if inertia_ok:
        x, std, cond = full, full_std, cond_full
    else:
        std = np.maximum(std, jackknife_std([_four(b) for b in blocks]))
        x = np.concatenate([x, np.zeros(6)])
        std = np.concatenate([std, np.zeros(6)])
    samples = sum(s.samples for s in logs.summaries)
    found, report = _finish(robot, x, std, cond, inertia_ok, signal, samples)
    disagree, disputed = _disagreement(_log_fits(robot, cells, len(logs.segments)))
    notes = _uncertainty_notes(report, float(white), disputed) + disagree
    return found, dataclasses.replace(report, notes=report.notes + notes)


@dataclass(frozen=True, eq=False)
class _Cell:
    """The rows of the samples in time block ``block`` of all the logs stacked, log ``log`` and
    time block ``log_block`` of that log, folded into a triangle (``[regressor | torque]``,
    10 unknowns, unit column scale)."""

    block: int
    log: int
    log_block: int
    problem: Reduced


def _four(problem: Reduced) -> Reduced:
    """The point-mass problem ``[m, m c]`` (the first 4 unknowns) of a 10-unknown one."""
    pick = np.zeros((11, 5))
    pick[[0, 1, 2, 3, 10], [0, 1, 2, 3, 4]] = 1.0
    return problem.combine(pick)


def _parts(cells: Sequence[_Cell], key: object) -> list[Reduced]:
    """The cells' triangles joined by ``key(cell)`` (in order of the key)."""
    by: dict[int, list[Reduced]] = {}
    for c in cells:
        by.setdefault(key(c), []).append(c.problem)  # type: ignore[operator]
    return [joined(by[k]) for k in sorted(by)]


def _log_fits(robot: Robot, cells: Sequence[_Cell], logs: int) -> list[tuple[Array, Array]]:
    """Each log's own point-mass fit: centre of mass (flange frame, m) and its standard errors
    (jackknife over its own time blocks); empty for one log."""
    if logs < 2:
        return []
    fits = []
    for k in range(logs):
        mine = [c for c in cells if c.log == k]
        x, std, _ = scaled_solution(_four(joined([c.problem for c in mine])))
        blocks = _parts(mine, lambda c: c.log_block)
        std = np.maximum(std, jackknife_std([_four(b) for b in blocks]))
        fits.append((_com(robot, x), std[1:4] / max(float(x[0]), 1e-12)))
    return fits


def _disagreement(fits: list[tuple[Array, Array]]) -> tuple[tuple[str, ...], set[str]]:
    """A note per pair of logs whose own centres of mass (:func:`_log_fits`) differ by more than
    twice their combined standard error on some axis, and the axes where some pair does.

    Across the flange axis the note says how far from it each log puts the centre of mass and
    by what angle about it they differ: equal distances at different angles, each well
    determined, is a payload that sat differently on the flange, not a poor motion.
    """
    notes: list[str] = []
    axes: set[str] = set()
    for (i, (c1, s1)), (j, (c2, s2)) in itertools.combinations(enumerate(fits), 2):
        bad = [k for k in range(3) if abs(c1[k] - c2[k]) > 2.0 * np.hypot(s1[k], s2[k])]
        if not bad:
            continue
        axes.update("xyz"[k] for k in bad)
        said = ", ".join(
            f"{'xyz'[k]} {c1[k]:.3f} ± {s1[k]:.3f} against {c2[k]:.3f} ± {s2[k]:.3f} m" for k in bad
        )
        note = f"logs {i + 1} and {j + 1} disagree on the centre of mass beyond 2 sigma: {said}"
        if {0, 1} & set(bad):
            r1, r2 = float(np.hypot(c1[0], c1[1])), float(np.hypot(c2[0], c2[1]))
            turn = np.degrees(np.arctan2(c2[1], c2[0]) - np.arctan2(c1[1], c1[0])) % 360.0
            note += (
                f"; {r1:.3f} and {r2:.3f} m from the flange axis, {turn:.0f} deg apart about "
                "it. Each log fixes its own centre of mass, so the payload sat differently on "
                "the flange in the two (mounted turned, or moved), and the pooled centre of "
                f"mass describes neither. To tell how it sat in a log, {_MOUNT_CHECK}"
            )
        notes.append(note)
    return tuple(notes), axes


def jackknife_std(blocks: Sequence[Reduced]) -> Array:
    """Standard errors of a least-squares solution from a delete-one-block jackknife:
    ``sqrt((K - 1) / K * sum_k (x_k - mean x_k)^2)``, ``x_k`` the solution without block ``k``
    of the ``K`` blocks' triangles (:meth:`kinergy.linalg.Reduced.stack`, unit column scale),
    shape (p,). Zeros when there are fewer than :data:`BLOCKS` blocks (too few samples)."""
    p = blocks[0].r.shape[1] - 1 if blocks else 0
    if len(blocks) < BLOCKS:
        return np.zeros(p)
    fits = [
        scaled_solution(joined([b for i, b in enumerate(blocks) if i != k]))[0]
        for k in range(len(blocks))
    ]
    x = np.array(fits)
    k = len(blocks)
    return np.sqrt((k - 1) / k * np.sum((x - x.mean(axis=0)) ** 2, axis=0))


def _block_edges(samples: int, blocks: int = BLOCKS) -> Array:
    """Where :data:`BLOCKS` contiguous time blocks of ``samples`` samples begin and end (none when
    there are fewer samples than ``2 blocks``: no jackknife)."""
    if samples < 2 * blocks:
        return np.array([0, samples])
    return np.linspace(0, samples, blocks + 1).astype(int)


def block_std(a: Array, b: Array, n: int, blocks: int = BLOCKS) -> Array:
    """:func:`jackknife_std` of the least-squares ``x`` of ``a x = b`` over ``blocks``
    contiguous blocks of samples; rows are samples x ``n`` joints, (N n, p) and (N n,) -> (p,).
    Zeros when there are fewer samples than ``2 blocks``."""
    edges = n * _block_edges(len(b) // n, blocks)
    parts = [
        Reduced.empty(a.shape[1]).stack(a[lo:hi], b[lo:hi]) for lo, hi in itertools.pairwise(edges)
    ]
    return jackknife_std(parts) if len(parts) == blocks else np.zeros(a.shape[1])


def _uncertainty_notes(
    report: PayloadEstimate, white_mass_std: float, disputed: set[str]
) -> tuple[str, ...]:
    """How the standard errors were found and, per centre-of-mass coordinate whose error is too
    large, that it is not identifiable and what motion would fix it; on an axis in
    ``disputed`` (the logs disagree), that the error is their disagreement instead."""
    notes = [
        f"standard errors from a jackknife over {BLOCKS} time blocks (correlated residuals): "
        f"mass ± {report.mass_std:.2g} kg against {white_mass_std:.2g} kg by the white-noise formula"
    ]
    for axis, value, std in zip("xyz", report.com, report.com_std, strict=True):
        if std > MAX_COM_STD and axis in disputed:
            notes.append(
                f"pooled centre of mass {axis} = {value:.3f} ± {std:.3f} m: that error is the "
                "logs' disagreement (below), not a motion too poor to show it"
            )
        elif std > MAX_COM_STD:
            notes.append(
                f"centre of mass {axis} = {value:.3f} ± {std:.3f} m is not identifiable from "
                f"this motion; it needs {_COM_MOTION[axis]}"
            )
    return tuple(notes)


def _pick_signal(logs: LogChunks) -> Target:
    """The signal every log has: currents, else measured torques, else ``target_moment``."""
    for name, attr in (
        (Target.CURRENT, "current"),
        (Target.TORQUE, "torque"),
        (Target.MOMENT, "tau_ref"),
    ):
        if logs.every(attr):
            return name
    raise KinergyError(
        "payload identification needs actual_current, measured torques or target_moment"
    )


def _point_mass(
    robot: Robot, bare: Robot, logs: LogChunks, signal: Target
) -> tuple[list[_Cell], Array, Array, float]:
    """Mass and first moment ``[m, m c]`` (4,) by least squares, iterated to a fixed point because
    the payload moves the friction's power-flow direction (UR5e eqs 12-13), a pass over the logs
    each: the last pass's cells (:class:`_Cell`), the estimate, its standard errors and the
    condition number."""
    guess: Robot = bare
    x = np.zeros(4)
    for _ in range(30):
        cells = _cells(bare, guess, logs, signal)
        x_new, std, cond = scaled_solution(_four(joined([c.problem for c in cells])))
        change = float(np.max(np.abs(x_new - x)))
        x = x_new
        guess = bare.with_payload(Payload(mass=max(float(x[0]), 1e-6), com=_com(robot, x)))
        if change < 1e-9 * max(abs(float(x[0])), 1.0):
            break
    return cells, x, std, cond


def _com(robot: Robot, x: Array) -> Array:
    """Centre of mass in the flange frame from ``[m, m c]`` in the last link frame."""
    rot, pos = robot.flange[:3, :3], robot.flange[:3, 3]
    return np.asarray(rot.T @ (x[1:4] / max(float(x[0]), 1e-12) - pos), dtype=float)


def _residuals(
    bare: Robot, guess: Robot, data: IdentData, signal: Target, skip: int
) -> tuple[Array, Array]:
    """The payload regressor of ``data``'s samples after the first ``skip`` (rows: samples x
    joints, 10 columns) and the torque the bare model leaves unexplained, with friction
    evaluated on the loaded ``guess`` (held through standstill as the ``skip`` samples before
    say)."""
    n = bare.n
    if signal == Target.MOMENT:
        if data.tau_ref is None:
            raise KinergyError(f"{data.path}: no target_moment")
        q, qd, qdd = data.q_cmd[skip:], data.qd_cmd[skip:], data.qdd_cmd[skip:]
        predicted = drive_state(bare, q, qd, qdd).tau_sim
        measured = data.tau_ref[skip:]
    else:
        q, qd, qdd = data.q[skip:], data.qd[skip:], data.qdd[skip:]
        state = drive_state(bare, q, qd, qdd)
        loaded = drive_state(guess, data.q, data.qd, data.qdd).tau_friction[skip:]
        predicted = joint_torque(bare, state.tau_load + loaded)
        if signal == Target.CURRENT:
            if data.current is None:
                raise KinergyError(f"{data.path}: no actual_current")
            measured = joint_torque(bare, data.current[skip:] * torque_constants(bare))
        else:
            if data.torque is None:
                raise KinergyError(f"{data.path}: no measured joint torques")
            measured = data.torque[skip:]
            # what the sensors read: no rotor inertia on the link side, their offsets
            with_friction = dataclasses.replace(state, tau_m=state.tau_load + loaded)
            predicted = sensor_torque(bare, with_friction)
    y = regressor(bare, q, qd, qdd)
    return y[:, :, 10 * (n - 1) :].reshape(-1, 10), (measured - predicted).reshape(-1)


def _cells(bare: Robot, guess: Robot, logs: LogChunks, signal: Target) -> list[_Cell]:
    """One pass: every cell's triangle (:class:`_Cell`) of the payload's regression with
    friction evaluated on ``guess``."""
    n = bare.n
    sizes = [s.samples for s in logs.summaries]
    starts = np.cumsum([0, *sizes])
    edges = _block_edges(int(starts[-1]))
    cuts = sorted(
        {int(e) for e in edges}
        | {int(v) for v in starts}
        | {int(starts[k] + e) for k, size in enumerate(sizes) for e in _block_edges(size)}
    )
    problems = [Reduced.empty(10) for _ in cuts[:-1]]
    held = data_history(guess)
    at = 0
    for k, chunk in logs.chunks():
        for lo in range(0, len(chunk), ROWS):
            part = chunk.sliced(lo, min(lo + ROWS, len(chunk)))
            data, skip = held.ahead(k, part)
            a, b = _residuals(bare, guess, data, signal, skip)
            held.update(data, skip)
            size = len(part)
            for c, (lo, hi) in enumerate(itertools.pairwise(cuts)):
                lo, hi = max(lo, at), min(hi, at + size)
                if lo < hi:
                    rows = slice(n * (lo - at), n * (hi - at))
                    problems[c] = problems[c].stack(a[rows], b[rows])
            at += size
    out = []
    for c, (lo, _) in enumerate(itertools.pairwise(cuts)):
        log = int(np.searchsorted(starts, lo, side="right")) - 1
        block = int(np.searchsorted(edges, lo, side="right")) - 1
        own = _block_edges(sizes[log])
        log_block = int(np.searchsorted(own, lo - starts[log], side="right")) - 1
        out.append(
            _Cell(min(block, len(edges) - 2), log, min(log_block, len(own) - 2), problems[c])
        )
    return out


def _inertia(robot: Robot, x: Array) -> tuple[Array, str | None]:
    """The inertia 6-vector about the centre of mass in flange axes (kg m^2) of ``x`` (10,),
    whose ``x[4:]`` are ``[Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`` about the last link's origin; zeros
    and a note when it is not physical."""
    mass, _, i_c = link_from_standard(x)
    rot = robot.flange[:3, :3]
    inertia6 = inertia_vector(rot.T @ i_c @ rot)
    try:
        Payload(mass=mass, com=_com(robot, x), inertia=inertia6)
    except KinergyError as exc:
        note = f"identified inertia is not physical ({exc}); payload taken as a point mass"
        return np.zeros(6), note
    return inertia6, None


def _finish(
    robot: Robot,
    x: Array,
    std: Array,
    cond: float,
    inertia_ok: bool,
    signal: Target,
    samples: int,
) -> tuple[Payload, PayloadEstimate]:
    """The payload and its report from ``[m, m c, I_o]`` (10,) and standard errors."""
    mass = float(x[0])
    if mass <= 0 or std[0] > 0.5 * abs(mass):
        raise KinergyError(
            f"the logs do not show a payload: identified mass {mass:.3g} ± {std[0]:.2g} kg"
        )
    com = _com(robot, x)
    inertia6, note = _inertia(robot, x) if inertia_ok else (np.zeros(6), None)
    if not inertia_ok:
        note = "the motion does not excite the payload's inertia enough: point mass"
    inertia_ok = inertia_ok and note is None
    report = PayloadEstimate(
        signal=signal.value,
        mass=mass,
        mass_std=float(std[0]),
        com=tuple(com.tolist()),
        com_std=tuple((std[1:4] / mass).tolist()),
        inertia=tuple(inertia6.tolist()) if inertia_ok else None,
        condition=cond,
        samples=samples,
        notes=() if note is None else (note,),
    )
    return Payload(mass=mass, com=com, inertia=inertia6), report
