"""Task files: a movej program as TOML, for ``kinergy optimize``, read into the same program
type as a URScript program (:class:`~kinergy.trajectory.robot_program.RobotProgram`: one
``movej`` to a joint target per move).

A task is what a program must do (its joint targets) and, optionally, how fast the program as
written does it. Every problem is reported as one line naming the file and the field::

    # a kinergy task: a movej program
    robot = "ur5e"                      # optional: the model it was written for
    unit = "deg"                        # joint angles in degrees; default "rad"
    speed = 3.0                         # default v of every move, rad/s (URScript's movej v)
    acceleration = 6.0                  # default a of every move, rad/s^2
    start = [0, -90, 0, -90, 0, 0]      # optional; default the last target (a cycle)

    [[move]]
    q = [10, -80, 30, -90, 0, 0]        # joint targets, in `unit`
    v = 2.0                             # optional, rad/s: this move's speed
    a = 4.0                             # optional, rad/s^2
    r = 0.05                            # optional: joint-space blend radius, rad (kinergy's)
    ur_r = 0.02                         # optional: UR's blend radius in the URScript, m (TCP)

``unit`` applies to the joint angles (``start``, ``q``) only: speeds, accelerations and blend
radii are always in rad/s, rad/s^2 and rad, as URScript's ``movej`` and kinergy's planner take
them. A move without ``v`` or ``a`` (and no default) takes URScript's (1.05 rad/s, 1.4 rad/s^2),
as a ``movej`` without them does. ``r`` is the joint-space blend kinergy plans with
(:mod:`kinergy.trajectory.movej`, :attr:`Move.joint_blend`); UR's own ``r`` is a tool-centre-point
radius in metres that depends on the tool, so it is separate (``ur_r``): the blend the program
runs with where ``r`` is not given, and the one written into a URScript. Without ``start`` the
program runs in cycles (it starts where its last move ends).

The built-in tasks ``test-a`` and ``test-b`` are the UR5e doc's test programs
(:func:`kinergy.trajectory.programs.paper_waypoints`, 3 rad/s and 6 rad/s^2, capped by the robot's limits).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from kinergy.arrays import Array
from kinergy.checks import number
from kinergy.errors import KinergyError
from kinergy.files import read_text, read_toml
from kinergy.model.library import library_names, load_robot
from kinergy.model.robot import Robot
from kinergy.trajectory.programs import paper_speed, paper_waypoints
from kinergy.trajectory.robot_program import MOVE_DEFAULTS, Move, RobotProgram

__all__ = ["BUILTIN_TASKS", "load_task", "task_from_dict"]


#: built-in task name -> seed of :func:`kinergy.trajectory.programs.paper_waypoints`
BUILTIN_TASKS = {"test-a": 1, "test-b": 2}

_TOP_KEYS = {"robot", "unit", "speed", "acceleration", "start", "move", "name", "description"}
_MOVE_KEYS = {"q", "v", "a", "r", "ur_r"}


def _angles(value: Any, what: str, scale: float, n: int | None) -> Array:
    if not isinstance(value, list) or not value:
        raise KinergyError(f"{what}: expected a list of joint angles, got {value!r}")
    out = []
    for i, x in enumerate(value):
        if isinstance(x, bool) or not isinstance(x, int | float) or not math.isfinite(x):
            raise KinergyError(f"{what}[{i}]: expected a finite number, got {x!r}")
        out.append(float(x) * scale)
    if n is not None and len(out) != n:
        raise KinergyError(f"{what}: expected {n} joint angles, got {len(out)}")
    return np.array(out)


def _move(
    move: dict[str, Any],
    where: str,
    scale: float,
    n: int | None,
    defaults: tuple[float, float],
) -> tuple[Array, float, float, float, float]:
    """One ``[[move]]`` table: its target (rad) and ``v``, ``a``, ``r``, ``ur_r``; ``defaults``
    are the task's ``speed`` and ``acceleration``."""
    extra = sorted(set(move) - _MOVE_KEYS)
    if extra:
        raise KinergyError(
            f"{where}: unknown field {extra[0]!r} (known: {', '.join(sorted(_MOVE_KEYS))})"
        )
    if "q" not in move:
        raise KinergyError(f"{where}.q: missing (the move's joint targets)")
    q = _angles(move["q"], f"{where}.q", scale, n)
    return (
        q,
        number(move["v"], f"{where}.v", gt=0.0) if "v" in move else defaults[0],
        number(move["a"], f"{where}.a", gt=0.0) if "a" in move else defaults[1],
        number(move.get("r", 0.0), f"{where}.r", ge=0.0),
        number(move.get("ur_r", 0.0), f"{where}.ur_r", ge=0.0),
    )


def _program(
    name: str,
    path: str,
    rows: list[tuple[Array, float, float, float, float]],
    start: Array | None,
    lines: list[int],
) -> RobotProgram:
    """The movej program of a task's moves (``lines``: each ``[[move]]``'s line, 0: unknown)."""
    moves = [
        Move(
            "movej",
            q,
            pose=False,
            a=a,
            v=v,
            r=ur_r,
            joint_blend=r,
            line=lines[k] if k < len(lines) else 0,
            text=f"move[{k + 1}]",
        )
        for k, (q, v, a, r, ur_r) in enumerate(rows)
    ]
    return RobotProgram(name=name, steps=tuple(moves), path=path, start=start)


def task_from_dict(
    data: dict[str, Any],
    *,
    name: str = "task",
    n_joints: int | None = None,
    path: str = "",
    lines: list[int] | None = None,
) -> RobotProgram:
    """The movej program of a parsed task file (see the module docstring).

    Parameters
    ----------
    data : dict
        The TOML document.
    name : str
        The program's name unless the file gives one (messages are prefixed by the caller).
    n_joints : int, optional
        The robot's joint count, to check every pose against.
    path : str
        The file, for messages naming a move's line.
    lines : list of int, optional
        Each ``[[move]]`` table's line in the file.

    Raises
    ------
    KinergyError
        One line naming the field at fault.
    """
    unknown = sorted(set(data) - _TOP_KEYS)
    if unknown:
        raise KinergyError(f"unknown field {unknown[0]!r} (known: {', '.join(sorted(_TOP_KEYS))})")
    robot = data.get("robot")
    if robot is not None and (not isinstance(robot, str) or not robot):
        raise KinergyError(f"robot: expected a robot name or file, got {robot!r}")
    unit = data.get("unit", "rad")
    if unit not in ("rad", "deg"):
        raise KinergyError(f'unit: expected "rad" or "deg", got {unit!r}')
    scale = math.pi / 180.0 if unit == "deg" else 1.0
    acc_default, speed_default = MOVE_DEFAULTS["movej"]
    speed = data.get("speed")
    speed = speed_default if speed is None else number(speed, "speed", gt=0.0)
    acc = data.get("acceleration")
    acc = acc_default if acc is None else number(acc, "acceleration", gt=0.0)
    moves = data.get("move")
    if moves is None:
        raise KinergyError("no [[move]] entries: a task needs at least one move")
    if not isinstance(moves, list) or not all(isinstance(m, dict) for m in moves):
        raise KinergyError("move: expected [[move]] tables")
    if not moves:
        raise KinergyError("no [[move]] entries: a task needs at least one move")
    rows = []
    n = n_joints
    for k, move in enumerate(moves):
        rows.append(_move(move, f"move[{k + 1}]", scale, n, (speed, acc)))
        n = rows[-1][0].size
    targets = [row[0] for row in rows]
    start = _angles(data["start"], "start", scale, n) if "start" in data else None
    every = np.vstack([targets[-1] if start is None else start, *targets])
    largest = float(np.max(np.abs(every))) / scale
    if unit == "deg" and largest <= 2.0 * math.pi:
        raise KinergyError(
            f'unit = "deg", but every joint angle is within {largest:.3g}, as angles in rad '
            'are: radians in a file that says degrees? (unit = "rad")'
        )
    if start is not None and np.array_equal(start, targets[-1]):
        start = None  # a cycle: the program starts where it ends
    return _program(str(data.get("name", name)), path, rows, start, lines or [])


def _builtin(name: str, robot: Robot | None) -> RobotProgram:
    if robot is None:
        raise KinergyError(f"task {name!r}: a built-in task needs the robot it runs on")
    waypoints = paper_waypoints(robot, BUILTIN_TASKS[name])
    speed, acc = paper_speed(robot)
    rows = [(q, speed, acc, 0.0, 0.0) for q in waypoints[1:]]
    start = None if np.array_equal(waypoints[0], waypoints[-1]) else waypoints[0]
    return _program(name, name, rows, start, list(range(1, len(rows) + 1)))


def _move_lines(text: str) -> list[int]:
    """The line (1-based) of every ``[[move]]`` table header, in order."""
    return [
        i + 1
        for i, line in enumerate(text.splitlines())
        if line.split("#", 1)[0].strip().replace(" ", "") == "[[move]]"
    ]


def load_task(name_or_path: str | os.PathLike[str], *, robot: Robot | None = None) -> RobotProgram:
    """Read a task file (TOML, see the module docstring) or build a built-in task, as the movej
    program it describes.

    Parameters
    ----------
    name_or_path : str or path
        ``test-a``, ``test-b`` (:data:`BUILTIN_TASKS`) or a task file.
    robot : Robot, optional
        The robot the task runs on: needed for a built-in task; for a file, every pose is
        checked to have its joint count, and the robot the file names must be this one.

    Returns
    -------
    RobotProgram
        One ``movej`` to a joint target (rad) per move, with its ``v``, ``a``, ``r`` (UR's, m,
        from ``ur_r``) and kinergy's joint-space blend (``r``, rad); the start where the file
        gives one (else the program runs in cycles). A move's line is its ``[[move]]`` table's.

    Raises
    ------
    KinergyError
        ``FILE: FIELD: problem``, one line.
    """
    key = os.fspath(name_or_path)
    if key in BUILTIN_TASKS:
        return _builtin(key, robot)
    path = Path(key)
    if not path.exists():
        raise KinergyError(
            f"{path}: no such task file (built-in tasks: {', '.join(BUILTIN_TASKS)})"
        )
    data = read_toml(path, "task file")
    lines = _move_lines(read_text(path, "task file"))
    try:
        program = task_from_dict(
            data,
            name=path.stem,
            n_joints=None if robot is None else robot.n,
            path=str(path),
            lines=lines,
        )
    except KinergyError as exc:
        raise exc.prefixed(str(path)) from None
    named = data.get("robot")
    if robot is not None and isinstance(named, str):
        _check_robot(path, named, robot)
    return program


def _check_robot(path: Path, named: str, robot: Robot) -> None:
    """Refuse a task file whose ``robot`` names another robot than the one it is run on: its
    poses and speeds were chosen for that arm. A robot file it names is read (relative to the
    task file) for its name; an identified model keeps its robot's name."""
    if named in library_names():
        want = named
    else:
        where = path.parent / named
        try:
            want = load_robot(where).name
        except KinergyError as exc:
            raise exc.prefixed(f"{path}: robot") from None
    if want != robot.name:
        raise KinergyError(
            f"{path}: robot: the task was written for {want}, the model is {robot.name}; "
            f"give a {want} model, or remove the task's robot line to run it on {robot.name}"
        )
