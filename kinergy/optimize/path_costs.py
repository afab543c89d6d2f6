"""The path search's states and its cheap energy estimate of every move between them.

Each move's target can be reached in several joint configurations: the inverse-kinematics branch
(:mod:`kinergy.dynamics.ik`: eight for a pose target of a movej with ``--configurations free``;
the program's own otherwise) and, for a tool symmetric about its z axis, any turn of the target
about that axis (:class:`kinergy.optimize.options.ToolSymmetry`: 180 or 90 degree steps, or
every 45 degrees for ``z``, then finer around the best: :func:`refined_turns`).
:func:`target_states` lists them per move, each joint at the ``2 pi``
choice nearest the program's own joints there (so a cycle of states is a cycle of joints: the
program ends where it starts), and for 180 and 90 degree turns also with the last joint the
other way round. With free via points (:class:`kinergy.optimize.options.ViaPoints`), a
joint-space via point (:func:`via_points`) may also take the joints of any state of the target
before it: the move to it then goes nowhere and the route leaves the via point out.

:func:`move_costs` estimates the energy of every move from each state of its start target to
each state of its end target: the move alone, from rest to rest, at the program's own ``v`` and
``a`` (a movej along the joint-space line between the two states; a tool move on its straight
line, in the branch it starts in, and only to the state where the line leads), its
drive model at Gauss-Legendre nodes of its three phases with the load the program sets there, the
bus power clipped at 0 plus standby; and the energy of holding the arm still at the end target
during the events that follow it. Moves are evaluated in chunks, all states at once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.dynamics.ik import branch_of, ik_branches, joint_limits, wrap_choices, wrap_near
from kinergy.dynamics.poses import rotation_about_z, tcp_pose
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.optimize.options import ToolSymmetry
from kinergy.optimize.samples import piece_nodes
from kinergy.predict import drive_by_payload
from kinergy.trajectory.movej import trapezoid, trapezoid_timing
from kinergy.trajectory.movel import joints_on_path, segment_arrays, tool_motion
from kinergy.trajectory.program_path import ProgramPath
from kinergy.trajectory.robot_program import Event, Move

__all__ = ["TargetStates", "move_costs", "refined_turns", "target_states", "via_points"]


#: Gauss-Legendre nodes per phase (ramp up, cruise, braking) of the estimate
_NODES = 4
#: samples evaluated at once (memory: about 1 kB each)
_CHUNK = 60_000
#: events that do not make a target a stop of the job (they set the tool or the load)
_SETUP = ("tcp", "payload")


@dataclass(frozen=True, eq=False)
class TargetStates:
    """The configurations one move's target can be reached in.

    Attributes
    ----------
    q : ndarray, shape (S, n)
        Joints of each state, rad (the ``2 pi`` choice nearest the program's own).
    branch : ndarray of int, shape (S,)
    turn : ndarray, shape (S,)
        The target's turn about the tool z axis, rad.
    pose : ndarray, shape (S, 4, 4)
        The TCP pose of each state.
    own : int
        The state of the program as written (its branch, no turn).
    moved : ndarray of bool, shape (S,)
        States of a via point that leave it out of the route (the joints of a state of the
        target before it); all False elsewhere.
    """

    q: Array
    branch: NDArray[np.intp]
    turn: Array
    pose: Array
    own: int
    moved: NDArray[np.bool_]


def refined_turns(chosen: Array, step: float) -> list[Array]:
    """Turns about a fully symmetric tool's axis around each target's chosen one: ``chosen_k +
    i step`` for ``i`` in -2..2, and no turn (the program's own state), rad, one array per
    target."""
    out = []
    for c in chosen:
        turns = np.mod(c + step * np.arange(-2, 3), 2.0 * np.pi)
        out.append(np.unique(np.concatenate([[0.0], turns])))
    return out


def _wrap(q: Array) -> Array:
    return np.asarray(np.pi - np.mod(np.pi - q, 2.0 * np.pi))


def _fits(q: Array, lo: Array, hi: Array) -> bool:
    """Whether every joint has a ``2 pi`` shift within its limits."""
    return bool(np.all(np.any(~np.isnan(wrap_choices(q, lo, hi, most=1)), axis=-1)))


def _turn_choices(q: Array, own: Array, lo: Array, hi: Array, *, both: bool) -> list[Array]:
    """A state's joints at the ``2 pi`` choice nearest the program's own, and with ``both`` the
    other way round for the last joint (a turned tool can get there either way), if within its
    limits."""
    near = wrap_near(q, own, lo, hi)
    if not both:
        return [near]
    other = near.copy()
    other[-1] -= 2.0 * np.pi * np.sign(near[-1] - own[-1])
    return [near, other] if lo[-1] <= other[-1] <= hi[-1] else [near]


def via_points(program_path: ProgramPath) -> NDArray[np.bool_]:
    """Which moves' targets are joint-space via points, shape (K,): a movej's target followed
    (cyclically: the program runs in cycles) by another movej with nothing at rest between them
    but ``set_tcp`` or ``set_payload`` (:class:`kinergy.optimize.options.ViaPoints`)."""
    program = program_path.program
    steps, index = program.steps, program.move_index
    out = np.zeros(len(index), dtype=bool)
    for k, i in enumerate(index):
        move = steps[i]
        assert isinstance(move, Move)
        following = steps[i + 1 :] if k + 1 < len(index) else (*steps[i + 1 :], *steps)
        between = []
        for step in following:
            if isinstance(step, Move):
                nxt = step
                break
            between.append(step)
        out[k] = (
            not move.tool_space
            and not nxt.tool_space
            and all(isinstance(e, Event) and e.kind in _SETUP for e in between)
        )
    return out


def _own_states(
    robot: Robot, path: ProgramPath, k: int, free: bool, symmetry: ToolSymmetry, angles: Array
) -> TargetStates:
    """Move k's target in every branch and turn the levers allow (module docstring)."""
    geometry = path.geometry
    move = path.program.moves[k]
    own_q = path.q_end[k]
    if geometry is None:
        pose = tcp_pose(robot, own_q, path.tcp[k])[None]
        return TargetStates(own_q[None], np.array([-1]), np.zeros(1), pose, 0, np.zeros(1, bool))
    lo, hi = joint_limits(robot)
    base = tcp_pose(robot, own_q, path.tcp[k])
    poses = rotation_about_z(base, angles)  # (A, 4, 4)
    sols = ik_branches(geometry, poses @ np.linalg.inv(path.tcp[k]), hint6=own_q[5])
    any_branch = move.tool_space or (free and move.pose)
    rows = []
    for a in range(angles.size):
        for b in range(8) if any_branch else [int(path.branch[k])]:
            q = sols[a, b]
            if not np.any(np.isnan(q)) and _fits(q, lo, hi):
                for q_s in _turn_choices(
                    q, own_q, lo, hi, both=symmetry.steps and angles[a] != 0.0
                ):
                    rows.append((q_s, b, angles[a], poses[a]))
    own = next(
        i
        for i, row in enumerate(rows)
        if row[1] == path.branch[k] and row[2] == 0.0 and np.allclose(row[0], own_q, atol=1e-6)
    )
    return TargetStates(
        q=np.array([r[0] for r in rows]),
        branch=np.array([r[1] for r in rows], dtype=np.intp),
        turn=np.array([r[2] for r in rows]),
        pose=np.array([r[3] for r in rows]),
        own=own,
        moved=np.zeros(len(rows), dtype=bool),
    )


def _with_moved(
    robot: Robot, path: ProgramPath, k: int, states: TargetStates, before: TargetStates
) -> TargetStates:
    """A via point's states and, after them, the joints of every state of the target before it
    (the route then leaves the via point out)."""
    geometry = path.geometry
    q = before.q
    pose = tcp_pose(robot, q, path.tcp[k])
    branch = np.array(
        [-1 if geometry is None else branch_of(geometry, qi, tcp_pose(robot, qi)) for qi in q],
        dtype=np.intp,
    )
    return TargetStates(
        q=np.vstack([states.q, q]),
        branch=np.concatenate([states.branch, branch]),
        turn=np.concatenate([states.turn, np.zeros(q.shape[0])]),
        pose=np.concatenate([states.pose, pose]),
        own=states.own,
        moved=np.concatenate([states.moved, np.ones(q.shape[0], dtype=bool)]),
    )


def target_states(
    robot: Robot,
    path: ProgramPath,
    *,
    free: bool,
    symmetry: ToolSymmetry,
    via: bool = False,
    turns: list[Array] | None = None,
) -> list[TargetStates]:
    """Every move's candidate states (module docstring): ``free`` lets a movej's pose target
    take any branch; ``symmetry`` its turns about the tool axis (``turns``: each target's own,
    rad, each including 0); ``via`` lets a joint-space via point take the joints of the target
    before it (a run of via points in order, each from the states of the one before)."""
    out = [
        _own_states(
            robot, path, k, free, symmetry, symmetry.angles() if turns is None else turns[k]
        )
        for k in range(path.moves)
    ]
    if not via:
        return out
    vias = via_points(path)
    if np.all(vias):
        return out  # a program of via points alone: nothing to leave out
    first = int(np.flatnonzero(~vias)[-1]) + 1  # after a target that is not a via point
    for j in range(path.moves):
        k = (first + j) % path.moves
        if vias[k]:
            out[k] = _with_moved(robot, path, k, out[k], out[k - 1])
    return out


def _phase_nodes(duration: Array, ramp: Array) -> tuple[Array, Array]:
    """Gauss-Legendre nodes (P, 3 _NODES) and weights of trapezoids' three phases."""
    breaks = np.stack([np.zeros_like(duration), ramp, duration - ramp, duration], axis=1)
    times, weights, _ = piece_nodes(breaks[:, :-1], breaks[:, 1:], sub=1, order=_NODES)
    return times[:, : 3 * _NODES], weights[:, : 3 * _NODES]


def _joint_moves(
    q_a: Array, q_b: Array, v: float, a: float
) -> tuple[Array, Array, Array, Array, Array]:
    """Samples of movej moves from ``q_a`` to ``q_b`` (P, n) at ``v``, ``a``: q, qd, qdd of
    shape (P, M, n), weights (P, M) and durations (P,)."""
    delta = q_b - q_a
    travel = np.max(np.abs(delta), axis=1)
    duration, ramp, peak = trapezoid_timing(travel, v, a)
    ramp = np.where(travel > 0.0, ramp, 0.0)
    times, weights = _phase_nodes(duration, ramp)
    s, sd, sdd = trapezoid(times, duration[:, None], ramp[:, None], peak[:, None], a)
    unit = np.where(travel[:, None] > 0.0, delta / np.maximum(travel, 1e-300)[:, None], 0.0)
    u = unit[:, None, :]
    return q_a[:, None] + s[..., None] * u, sd[..., None] * u, sdd[..., None] * u, weights, duration


def _tool_moves(
    robot: Robot, path: ProgramPath, k: int, q_a: Array, pose_b: Array, branch: int, q_want: Array
) -> tuple[Array, Array, Array, Array, Array]:
    """Samples of tool moves (straight lines) from joints ``q_a`` (P, n) to TCP poses ``pose_b``
    (P, 4, 4) in ``branch``: as :func:`_joint_moves`; NaN joints where a line fails or does not
    end at the joints ``q_want`` (P, n) of the target's state."""
    assert path.geometry is not None
    tcp = path.tcp[k]
    pose_a = tcp_pose(robot, q_a, tcp)
    shift, turn, length = segment_arrays(pose_a, pose_b)
    duration, ramp, peak = trapezoid_timing(length, path.speed[k], path.accel[k])
    ramp = np.where(length > 0.0, ramp, 0.0)
    times, weights = _phase_nodes(duration, ramp)
    s, sd, sdd = trapezoid(times, duration[:, None], ramp[:, None], peak[:, None], path.accel[k])
    m = times.shape[1]
    rep = np.repeat(np.arange(length.size), m)
    shape = (length.size, m, q_a.shape[1])
    pose, twist, acc = tool_motion(
        pose_a[rep],
        shift[rep, None],
        turn[rep, None],
        length[rep, None],
        s.reshape(-1, 1),
        sd.reshape(-1, 1),
        sdd.reshape(-1, 1),
    )
    q_b = ik_branches(
        path.geometry, pose_b @ np.linalg.inv(tcp), hint6=q_a[:, 5], branches=[branch]
    )[:, 0]
    q_b = q_a + _wrap(q_b - q_a)
    frac = (s / np.maximum(length, 1e-300)[:, None]).reshape(-1, 1)
    ref = q_a[rep] + frac * (q_b - q_a)[rep]
    try:
        q, qd, qdd = joints_on_path(robot, path.geometry, tcp, branch, pose, twist, acc, ref)
    except KinergyError:
        return (np.full(shape, np.nan),) * 3 + (weights, duration)
    q = q.reshape(shape)
    q[np.any(np.abs(q_b - q_want) > 1e-6, axis=1)] = np.nan
    return q, qd.reshape(shape), qdd.reshape(shape), weights, duration


def _energy(
    robot: Robot, path: ProgramPath, k: int, samples: tuple[Array, ...], standby: float
) -> Array:
    """Clipped bus energy plus standby of P sampled moves (P,), J; inf where a sample is NaN."""
    q, qd, qdd, weights, duration = samples
    p, m, n = q.shape
    bad = np.any(np.isnan(q.reshape(p, -1)), axis=1)
    q, qd, qdd = (np.nan_to_num(x).reshape(-1, n) for x in (q, qd, qdd))
    load = np.full(p * m, path.move_payload[k], dtype=np.intp)
    drive = drive_by_payload(path.robots, load, q, qd, qdd)
    bus = np.maximum(drive.power.sum(axis=1), 0.0).reshape(p, m)
    e = np.sum(bus * weights, axis=1) + standby * duration
    return np.where(bad, np.inf, e)


def _hold_power(robot: Robot, path: ProgramPath, k: int, q: Array) -> Array:
    """Bus power (W) holding the arm still at joints ``q`` (S, n) during the events after move k,
    times their durations: J per state."""
    events = np.flatnonzero(path.event_after == k)
    total = np.zeros(q.shape[0])
    zero = np.zeros_like(q)
    for e in events:
        if path.event_time[e] <= 0.0:
            continue
        load = np.full(q.shape[0], path.event_payload[e], dtype=np.intp)
        drive = drive_by_payload(path.robots, load, q, zero, zero)
        total += np.maximum(drive.power.sum(axis=1), 0.0) * path.event_time[e]
    return total


def move_costs(
    robot: Robot, path: ProgramPath, states: list[TargetStates], *, standby: float = 0.0
) -> list[Array]:
    """The estimated energy of every move between the states of its two targets (J).

    Returns
    -------
    list of ndarray, length K
        Entry k has shape (S_prev, S_k), S_prev the states of the target move k starts from
        (the last move's for k = 0: the program runs in cycles), including the holding energy
        at move k's target; ``inf`` where the move cannot run (a tool move changing branch, a
        line out of reach or through a singularity).
    """
    out = []
    for k in range(path.moves):
        prev, here = states[k - 1], states[k]
        grid = np.meshgrid(np.arange(prev.q.shape[0]), np.arange(here.q.shape[0]), indexing="ij")
        ia, ib = grid[0].ravel(), grid[1].ravel()
        cost = np.full(ia.size, np.inf)
        if path.tool[k] is None:
            q_a = prev.q[ia]
            q_b = here.q[ib]
            per = max(1, _CHUNK // (3 * _NODES))
            for lo in range(0, ia.size, per):
                sl = slice(lo, lo + per)
                samples = _joint_moves(q_a[sl], q_b[sl], path.speed[k], path.accel[k])
                cost[sl] = _energy(robot, path, k, samples, standby)
        else:
            for b in np.unique(here.branch):
                pick = np.flatnonzero((prev.branch[ia] == b) & (here.branch[ib] == b))
                per = max(1, _CHUNK // (3 * _NODES))
                for lo in range(0, pick.size, per):
                    sel = pick[lo : lo + per]
                    samples = _tool_moves(
                        robot, path, k, prev.q[ia[sel]], here.pose[ib[sel]], int(b), here.q[ib[sel]]
                    )
                    cost[sel] = _energy(robot, path, k, samples, standby)
        cost += _hold_power(robot, path, k, here.q)[ib]
        out.append(cost.reshape(prev.q.shape[0], here.q.shape[0]))
    return out
