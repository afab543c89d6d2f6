"""The geometry of a robot program as the UR controller resolves it: joints at every target.

:func:`program_path` walks a :class:`~kinergy.trajectory.robot_program.RobotProgram` as the
controller does, from a start pose:

- a ``movej`` to a joint target goes there in joint space; to a pose target, to the inverse-
  kinematics solution closest to the joints it starts from (or to ``qnear``), over the eight
  branches and the ``2 pi`` shifts within the joint limits
  (:func:`kinergy.dynamics.ik.nearest_solution`);
- a ``movel``/``movep`` moves the tool on a straight line (:mod:`kinergy.trajectory.movel`) in the
  branch it starts in; its end joints are where the line leads (followed at 64 points);
- ``set_tcp`` and ``set_payload`` change the tool and the load from there on; every other event
  is time at rest;
- a blend radius ``r`` (m, at the tool) joins two moves with no event between them (of any kind:
  :mod:`kinergy.trajectory.program_motion` adds their displacements); anywhere else the move
  stops at its target. A ``movej``'s radius
  becomes the leading joint's distance to go when the tool enters the sphere of radius ``r``
  around its target (the joint-space line is fixed, so this does not depend on the timing).

A program runs in cycles: unless a start is given, it starts where it ends (resolved twice, from
its first joint target, then from where that pass ended). Every target outside the joint limits
or out of reach is one line naming the program line.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy.arrays import Array
from kinergy.dynamics.ik import (
    URGeometry,
    branch_of,
    ik_branches,
    joint_limits,
    nearest_solution,
    ur_geometry,
)
from kinergy.dynamics.kinematics import flange_pose
from kinergy.dynamics.poses import pose_matrix
from kinergy.errors import KinergyError
from kinergy.model.robot import Payload, Robot
from kinergy.trajectory.movej import trapezoid_timing
from kinergy.trajectory.movel import ToolSegment, tool_motion, tool_segment
from kinergy.trajectory.programs import UR_HOME
from kinergy.trajectory.robot_program import Event, Move, RobotProgram

__all__ = [
    "ProgramPath",
    "follow_line",
    "line_joints",
    "move_settings",
    "program_path",
    "tool_blend_radius",
]


#: points a straight tool line is followed at to find its end joints
_LINE_POINTS = 64
#: the longest a move may take, s (longer is a slip in the units, and overflows the plan)
_LONGEST_MOVE = 3600.0


@dataclass(frozen=True, eq=False)
class ProgramPath:
    """Where a program's moves go and what runs between them (no timing).

    Attributes
    ----------
    program : RobotProgram
    q0 : ndarray, shape (n,)
        Joints at the start, rad.
    q_end : ndarray, shape (K, n)
        Joints at each move's target, rad.
    tool : tuple of ToolSegment or None, length K
        The straight line of each tool move (None for a movej).
    branch : ndarray of int, shape (K,)
        Inverse-kinematics branch at each target (-1 where the arm has no UR geometry).
    tcp : ndarray, shape (K, 4, 4)
        The TCP (flange frame) during each move.
    travel : ndarray, shape (K,)
        What each move's profile runs over: the leading joint's travel (rad) for a movej, the
        path length (m, or rad for a turn) for a tool move.
    blend : ndarray, shape (K,)
        Blend radius at each move's end in the same unit (0: it stops).
    linked : ndarray of bool, shape (K,)
        Whether move k blends into move k + 1.
    speed, accel : ndarray, shape (K,)
        Each move's ``v`` and ``a`` (a given ``t`` converted, :func:`move_settings`).
    event_time : ndarray, shape (E,)
        Each event's duration, s.
    event_after : ndarray of int, shape (E,)
        The move each event follows (-1: before the first move).
    payloads : tuple of Payload or None
        Every load the program sets, each once; index 0 is the robot's own.
    robots : tuple of Robot
        The robot carrying each of ``payloads`` (built once: the drive model of every sample
        uses the one of its load).
    move_payload, event_payload : ndarray of int, shapes (K,), (E,)
        The load during each move and event.
    geometry : URGeometry or None
        For inverse kinematics along tool moves.
    """

    program: RobotProgram
    q0: Array
    q_end: Array
    tool: tuple[ToolSegment | None, ...]
    branch: NDArray[np.intp]
    tcp: Array
    travel: Array
    blend: Array
    linked: NDArray[np.bool_]
    speed: Array
    accel: Array
    event_time: Array
    event_after: NDArray[np.intp]
    payloads: tuple[Payload | None, ...]
    robots: tuple[Robot, ...]
    move_payload: NDArray[np.intp]
    event_payload: NDArray[np.intp]
    geometry: URGeometry | None

    @property
    def moves(self) -> int:
        return int(self.travel.size)

    @property
    def q_start(self) -> Array:
        """Joints where each move starts, shape (K, n)."""
        return np.vstack([self.q0, self.q_end[:-1]])

    @property
    def gaps(self) -> Array:
        """Time at rest before each move (its events), s, shape (K,)."""
        gap = np.zeros(self.moves)
        for after, time in zip(self.event_after, self.event_time, strict=True):
            if after + 1 < self.moves:
                gap[after + 1] += time
        return gap

    @property
    def tail(self) -> float:
        """Time at rest after the last move, s."""
        return float(self.event_time[self.event_after == self.moves - 1].sum())

    def with_timing(self, speed: ArrayLike, accel: ArrayLike) -> ProgramPath:
        """The same path at other per-move ``v`` and ``a``."""
        v = np.broadcast_to(np.asarray(speed, dtype=float), (self.moves,)).copy()
        a = np.broadcast_to(np.asarray(accel, dtype=float), (self.moves,)).copy()
        return dataclasses.replace(self, speed=v, accel=a)


def move_settings(travel: float, a: float, v: float, t: float) -> tuple[float, float]:
    """A move's ``(v, a)``: as given, or for a time ``t`` > 0 the speed that makes the move last
    ``t`` at acceleration ``a`` (the smaller root of ``t = D / v + v / a``; a triangle at
    ``4 D / t^2`` where ``a`` is too small for ``t``)."""
    if t <= 0.0 or travel <= 0.0:
        return v, a
    disc = (a * t) ** 2 - 4.0 * a * travel
    if disc < 0.0:
        return 2.0 * travel / t, 4.0 * travel / t**2
    return 0.5 * (a * t - np.sqrt(disc)), a


def tool_blend_radius(robot: Robot, tcp: Array, q_a: Array, q_b: Array, r: float) -> float:
    """A ``movej``'s blend radius ``r`` (m, at the tool) as the leading joint's distance to go
    (rad) when the tool enters the sphere of radius ``r`` around the target, on the joint-space
    line from ``q_a`` to ``q_b``."""
    travel = float(np.max(np.abs(q_b - q_a)))
    if r <= 0.0 or travel <= 0.0:
        return 0.0
    s = np.linspace(0.0, 1.0, 201)
    tips = (flange_pose(robot, q_a + s[:, None] * (q_b - q_a)) @ tcp)[:, :3, 3]
    dist = np.linalg.norm(tips - tips[-1], axis=1)
    outside = np.flatnonzero(dist > r)
    if outside.size == 0:
        return travel
    i = int(outside[-1])  # the last point outside; the sphere is entered between i and i + 1
    f = (dist[i] - r) / max(dist[i] - dist[i + 1], 1e-300)
    return float(travel * (1.0 - (s[i] + f * (s[i + 1] - s[i]))))


def follow_line(
    robot: Robot, g: URGeometry, tcp: Array, q_a: Array, segment: ToolSegment, branch: int
) -> Array:
    """Joints along a straight tool line from ``q_a`` (the branch it starts in), unwrapped
    continuously, shape (_LINE_POINTS, n)."""
    s = np.linspace(0.0, segment.length, _LINE_POINTS)[:, None]
    zero = np.zeros_like(s)
    pose, _, _ = tool_motion(
        segment.start,
        segment.shift[None],
        segment.turn[None],
        np.array([segment.length]),
        s,
        zero,
        zero,
    )
    flange = pose @ np.linalg.inv(tcp)
    q = ik_branches(g, flange, hint6=np.full(_LINE_POINTS, q_a[5]), branches=[branch])[:, 0]
    if np.any(np.isnan(q)):
        raise KinergyError("the straight line leaves the arm's reach")
    q = np.unwrap(q, axis=0)
    q = q + 2.0 * np.pi * np.round((q_a - q[0]) / (2.0 * np.pi))
    jumps = np.max(np.abs(np.diff(q, axis=0)), axis=1)
    if np.any(jumps > 0.5):
        raise KinergyError("the straight line passes a singularity of the arm (a wrist flip)")
    return np.asarray(q)


def line_joints(robot: Robot, path: ProgramPath, k: int) -> Array:
    """Joints along tool move ``k``'s straight line (without blends), shape (64, n), rad."""
    segment = path.tool[k]
    if segment is None or path.geometry is None:
        raise KinergyError(f"move {k + 1} is not a tool move")
    return follow_line(
        robot, path.geometry, path.tcp[k], path.q_start[k], segment, int(path.branch[k])
    )


def _check_limits(robot: Robot, q: Array) -> None:
    lo, hi = joint_limits(robot)
    bad = np.flatnonzero((q < lo - 1e-9) | (q > hi + 1e-9))
    if bad.size:
        j = int(bad[0])
        at = f"{np.degrees(q[j]):.2f} deg" if abs(q[j]) < 1e300 else f"{q[j]:g} rad"
        raise KinergyError(
            f"the target puts {robot.joints[j].name} at {at}, outside its "
            f"limits [{np.degrees(lo[j]):.1f}, {np.degrees(hi[j]):.1f}] deg"
        )


class _Walk:
    """The controller's state while walking the program: joints, TCP, load, and the path."""

    def __init__(self, robot: Robot, program: RobotProgram, q0: Array) -> None:
        self.robot = robot
        self.program = program
        needs_ik = any(m.pose or m.tool_space for m in program.moves)
        self.g = ur_geometry(robot) if needs_ik else _optional_geometry(robot)
        self.q = q0.copy()
        self.tcp = np.eye(4)
        self.payloads: list[Payload | None] = [robot.payload]
        self.load = 0  # index into payloads of the load set from here on
        self.rows: list[tuple[Array, ToolSegment | None, int, Array, float, float, float]] = []
        self.events: list[tuple[float, int, int]] = []
        self.move_payload: list[int] = []

    def event(self, event: Event) -> None:
        if event.tcp is not None:
            self.tcp = pose_matrix(event.tcp)
        if event.kind == "payload":
            same = [i for i, p in enumerate(self.payloads) if _same_payload(p, event.payload)]
            self.load = same[0] if same else len(self.payloads)
            if not same:
                self.payloads.append(event.payload)
        self.events.append((event.duration, len(self.rows) - 1, self.load))

    def move(self, move: Move) -> None:
        q_a = self.q
        if move.tool_space:
            assert self.g is not None
            start = flange_pose(self.robot, q_a) @ self.tcp
            end = self._target_pose(move)
            segment = tool_segment(start, end)
            branch = branch_of(self.g, q_a, start @ np.linalg.inv(self.tcp))
            q_b = follow_line(self.robot, self.g, self.tcp, q_a, segment, branch)[-1]
            travel = segment.length
        else:
            segment = None
            q_b, branch = self._joint_target(move, q_a)
            travel = float(np.max(np.abs(q_b - q_a)))
        _check_limits(self.robot, q_b)
        v, a = move_settings(travel, move.a, move.v, move.t)
        duration = float(trapezoid_timing(travel, v, a)[0])
        if duration > _LONGEST_MOVE:
            raise KinergyError(
                f"at v={v:g} and a={a:g} the move takes {duration:.3g} s, more than an hour "
                "(a speed or acceleration in the wrong unit?)"
            )
        self.rows.append((q_b, segment, branch, self.tcp.copy(), travel, v, a))
        self.move_payload.append(self.load)
        self.q = q_b

    def _target_pose(self, move: Move) -> Array:
        if move.pose:
            return np.asarray(pose_matrix(move.target))
        _check_limits(self.robot, move.target)
        return np.asarray(flange_pose(self.robot, move.target) @ self.tcp)

    def _joint_target(self, move: Move, q_a: Array) -> tuple[Array, int]:
        if not move.pose:
            _check_limits(self.robot, move.target)
            if self.g is None:
                return move.target.copy(), -1
            return move.target.copy(), branch_of(
                self.g, move.target, flange_pose(self.robot, move.target)
            )
        assert self.g is not None
        flange = pose_matrix(move.target) @ np.linalg.inv(self.tcp)
        near = q_a if move.qnear is None else move.qnear
        return nearest_solution(self.robot, self.g, flange, near)


def _same_payload(a: Payload | None, b: Payload | None) -> bool:
    """Whether two loads are the same (``set_payload`` of the same values: one drive model)."""
    if a is None or b is None:
        return a is b
    return (
        a.mass == b.mass and np.array_equal(a.com, b.com) and np.array_equal(a.inertia, b.inertia)
    )


def _optional_geometry(robot: Robot) -> URGeometry | None:
    try:
        return ur_geometry(robot)
    except KinergyError:
        return None


def _links(program: RobotProgram) -> NDArray[np.bool_]:
    """Whether each move blends into the next: ``r`` > 0, the next step is a move (no event
    between), and it is not the last move."""
    steps = program.steps
    index = program.move_index
    out = np.zeros(len(index), dtype=bool)
    for k, i in enumerate(index[:-1]):
        move = steps[i]
        assert isinstance(move, Move)
        out[k] = move.blends and isinstance(steps[i + 1], Move)
    return out


def _walk(robot: Robot, program: RobotProgram, q0: Array) -> _Walk:
    walk = _Walk(robot, program, q0)
    for step in program.steps:
        try:
            if isinstance(step, Move):
                walk.move(step)
            else:
                walk.event(step)
        except KinergyError as exc:
            raise exc.prefixed(f"{program.where(step.line)}: {step.text or 'move'}") from None
    return walk


def _first_joints(robot: Robot, program: RobotProgram) -> Array:
    """Where a first pass starts: the first joint target, else UR's home pose."""
    for move in program.moves:
        if not move.pose:
            return move.target.copy()
    if robot.n != 6:
        raise KinergyError(f"{robot.name}: the program needs joint targets")
    return UR_HOME.copy()


def program_path(
    robot: Robot, program: RobotProgram, *, start: ArrayLike | None = None
) -> ProgramPath:
    """Resolve a program's targets to joints, as the UR controller runs it (module docstring).

    Parameters
    ----------
    robot : Robot
    program : RobotProgram
    start : array_like, shape (n,), optional
        Joints at the start, rad; default the program's own (:attr:`RobotProgram.start`), else
        where it ends (it runs in cycles).

    Returns
    -------
    ProgramPath

    Raises
    ------
    KinergyError
        ``FILE:LINE: statement: what`` for a target out of reach or outside the joint limits.
    """
    for move in program.moves:
        if not move.pose and move.target.size != robot.n:
            raise KinergyError(
                f"{program.where(move.line)}: the joint target has {move.target.size} joints, "
                f"{robot.name} has {robot.n}"
            )
    if start is None and program.start is not None:
        start = program.start
        if start.size != robot.n:
            raise KinergyError(
                f"{program.path or program.name}: the start has {start.size} joints, "
                f"{robot.name} has {robot.n}"
            )
    if start is None:
        first = _walk(robot, program, _first_joints(robot, program))
        q0 = first.q
    else:
        q0 = np.asarray(start, dtype=float)
    walk = _walk(robot, program, q0)
    return _path(robot, program, walk, q0)


def _path(robot: Robot, program: RobotProgram, walk: _Walk, q0: Array) -> ProgramPath:
    rows = walk.rows
    linked = _links(program)
    q_end = np.array([row[0] for row in rows])
    q_start = np.vstack([q0, q_end[:-1]])
    blend = np.zeros(len(rows))
    moves = program.moves
    for k, row in enumerate(rows):
        if not linked[k]:
            continue
        if row[1] is not None:
            blend[k] = moves[k].r
        elif moves[k].joint_blend > 0.0:
            blend[k] = moves[k].joint_blend
        else:
            blend[k] = tool_blend_radius(robot, row[3], q_start[k], q_end[k], moves[k].r)
    events = walk.events
    return ProgramPath(
        program=program,
        q0=q0,
        q_end=q_end,
        tool=tuple(row[1] for row in rows),
        branch=np.array([row[2] for row in rows], dtype=np.intp),
        tcp=np.array([row[3] for row in rows]),
        travel=np.array([row[4] for row in rows]),
        blend=blend,
        linked=linked,
        speed=np.array([row[5] for row in rows]),
        accel=np.array([row[6] for row in rows]),
        event_time=np.array([e[0] for e in events], dtype=float),
        event_after=np.array([e[1] for e in events], dtype=np.intp),
        payloads=tuple(walk.payloads),
        robots=tuple(robot if p is robot.payload else robot.with_payload(p) for p in walk.payloads),
        move_payload=np.array(walk.move_payload, dtype=np.intp),
        event_payload=np.array([e[2] for e in events], dtype=np.intp),
        geometry=walk.g,
    )
