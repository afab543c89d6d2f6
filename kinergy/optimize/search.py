"""The path search of a robot program: one configuration per target, by dynamic programming.

Every move's target has a few candidate states (:func:`kinergy.optimize.path_costs.
target_states`: the inverse-kinematics branch, the turn about a symmetric tool's axis) and every
move an estimated energy from each state of its start to each state of its end
(:func:`kinergy.optimize.path_costs.move_costs`). The program runs in cycles, so its cheapest
choice is a shortest closed walk through K layers: :func:`cheapest_cycle` solves it exactly in
``O(S^3 K)`` (min-plus products, for every state of the last target at once), never ``S^K``.

:func:`lever_mask` restricts the states to one set of levers (the program's own branch, no
turn, ...), so one cost table serves every lever's figure. :func:`chosen_moves` turns the chosen
states into the program's moves: each joint takes the ``2 pi`` choice nearest the joints it comes
from (within its limits), a movej's pose target gets ``qnear`` (the controller then picks exactly
that configuration), a turned target its turned pose.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.dynamics.ik import joint_limits, wrap_near
from kinergy.dynamics.poses import pose_vector
from kinergy.model.robot import Robot
from kinergy.optimize.path_costs import TargetStates
from kinergy.trajectory.program_path import ProgramPath
from kinergy.trajectory.robot_program import Move

__all__ = ["cheapest_cycle", "chosen_moves", "lever_mask", "masked", "wrapped_moves"]


def cheapest_cycle(costs: list[Array]) -> tuple[NDArray[np.intp], float]:
    """The cheapest closed walk through the layers of a cyclic program.

    Parameters
    ----------
    costs : list of ndarray, length K
        Entry k has shape (S_{k-1}, S_k): the cost of move k from each state of the previous
        target to each state of its own (``S_{-1} = S_{K-1}``: the program ends where it starts);
        ``inf`` where impossible.

    Returns
    -------
    states : ndarray of int, shape (K,)
        The chosen state of every target.
    cost : float
        Its total (``inf`` if no closed walk exists).
    """
    last = costs[0].shape[0]
    value = costs[0]  # (S_last, S_0): from each closing state
    back = []
    for k in range(1, len(costs)):
        total = value[:, :, None] + costs[k][None, :, :]  # (S_last, S_{k-1}, S_k)
        arg = np.argmin(total, axis=1)
        value = np.take_along_axis(total, arg[:, None, :], axis=1)[:, 0, :]
        back.append(arg)
    closing = value[np.arange(last), np.arange(last)]
    s = int(np.argmin(closing))
    states = [s]
    j = s
    for arg in reversed(back):
        j = int(arg[s, j])
        states.append(j)
    return np.array(states[::-1], dtype=np.intp), float(closing[s])


def lever_mask(
    path: ProgramPath,
    states: list[TargetStates],
    *,
    branch: bool,
    turn: bool,
    via: bool = False,
) -> list[NDArray[np.bool_]]:
    """Which states each target may take with a set of levers: another branch (a movej's pose
    target; tool moves follow their line), a turn about the tool axis, the joints of the target
    before a via point (``via``: the route leaves the via point out)."""
    out = []
    for k, st in enumerate(states):
        move = path.program.moves[k]
        ok = ~st.moved
        if not turn:
            ok &= st.turn == 0.0
        if not branch and not move.tool_space:
            ok &= st.branch == st.branch[st.own]
        if via:
            ok |= st.moved
        out.append(ok)
    return out


def masked(costs: list[Array], mask: list[NDArray[np.bool_]]) -> list[Array]:
    """The costs with the states a mask excludes made impossible."""
    out = []
    for k, c in enumerate(costs):
        allowed = mask[k - 1][:, None] & mask[k][None, :]
        out.append(np.where(allowed, c, np.inf))
    return out


def _closed_joints(path: ProgramPath, q: Array, lo: Array, hi: Array) -> Array:
    """Joints of every target, each move taking the smaller turn of every joint, with the cycle
    closed: where the turns of a joint add up to whole turns, the joint-space move whose turn of
    that joint is closest to it goes the other way round. Shape (K, n), rad."""
    start = wrap_near(q[-1], path.q_end[-1], lo, hi)
    delta = _wrap(np.diff(np.vstack([q[-1:], q]), axis=0))  # (K, n): the smaller turns
    turns = np.round(delta.sum(axis=0) / (2.0 * np.pi))
    joint_moves = np.array([not m.tool_space for m in path.program.moves])
    for j in np.flatnonzero(turns):
        if not np.any(joint_moves):
            break
        full = 2.0 * np.pi * turns[j]
        cost = np.where(joint_moves, np.abs(delta[:, j] - full), np.inf)
        delta[int(np.argmin(cost)), j] -= full
    return np.asarray(start + np.cumsum(delta, axis=0))


def _wrap(q: Array) -> Array:
    return np.asarray(np.pi - np.mod(np.pi - q, 2.0 * np.pi))


def _moves_at(path: ProgramPath, q_all: Array, poses: Array, same: list[bool]) -> list[Move]:
    """The program's moves to joints ``q_all`` (K, n) and TCP poses ``poses`` (K, 4, 4); a move
    marked ``same`` is kept as written."""
    out = []
    for k, move in enumerate(path.program.moves):
        q = q_all[k]
        if same[k] and np.allclose(q, path.q_end[k], atol=1e-9):
            out.append(move)
        elif not move.pose:  # a joint target (of a tool move: the pose of those joints)
            out.append(move.replaced(target=q, qnear=None))
        elif move.tool_space:
            out.append(move.replaced(target=pose_vector(poses[k]), pose=True, qnear=None))
        else:
            out.append(move.replaced(target=pose_vector(poses[k]), pose=True, qnear=q))
    return out


def chosen_moves(
    path: ProgramPath, states: list[TargetStates], choice: NDArray[np.intp]
) -> list[Move]:
    """The program's moves with the chosen states as their targets (module docstring; a via
    point left out takes the joints of the target before it)."""
    q_all = np.array([st.q[c] for st, c in zip(states, choice, strict=True)])
    poses = np.array([st.pose[c] for st, c in zip(states, choice, strict=True)])
    same = [int(c) == st.own for st, c in zip(states, choice, strict=True)]
    return _moves_at(path, q_all, poses, same)


def wrapped_moves(robot: Robot, path: ProgramPath, states: list[TargetStates]) -> list[Move]:
    """The ``2 pi`` lever: the program's own targets, each joint taking the smaller turn from the
    joints before it (within its limits), the cycle closed (:func:`_closed_joints`)."""
    lo, hi = joint_limits(robot)
    q_all = _closed_joints(path, _wrap(path.q_end), lo, hi)
    poses = np.array([st.pose[st.own] for st in states])
    return _moves_at(path, q_all, poses, [True] * path.moves)
