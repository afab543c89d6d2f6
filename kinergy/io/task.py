"""Task files: the waypoints of a movej program, as TOML, for ``kinergy optimize``.

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
them. A move without ``v`` or ``a`` (and no default) runs at the fastest the robot allows.
``r`` is the joint-space blend kinergy plans with (:mod:`kinergy.trajectory.movej`); UR's own
``r`` is a tool-centre-point radius in metres that depends on the tool, so it is separate
(``ur_r``) and only written into a URScript.

The built-in tasks ``test-a`` and ``test-b`` are the UR5e doc's test programs
(:func:`kinergy.trajectory.programs.paper_waypoints`, 3 rad/s and 6 rad/s^2, capped by the robot's limits).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.files import read_toml
from kinergy.model.library import library_names, load_robot
from kinergy.model.robot import Robot
from kinergy.trajectory.programs import paper_speed, paper_waypoints

__all__ = ["BUILTIN_TASKS", "Task", "load_task", "task_from_dict"]


#: built-in task name -> seed of :func:`kinergy.trajectory.programs.paper_waypoints`
BUILTIN_TASKS = {"test-a": 1, "test-b": 2}

_TOP_KEYS = {"robot", "unit", "speed", "acceleration", "start", "move", "name", "description"}
_MOVE_KEYS = {"q", "v", "a", "r", "ur_r"}


@dataclass(frozen=True, eq=False)
class Task:
    """A movej program's waypoints and settings.

    Attributes
    ----------
    name : str
        The file name or the built-in name.
    robot : str or None
        The robot the file names (a built-in name or a path), if any.
    waypoints : ndarray, shape (K + 1, n)
        The start pose and the K targets, rad.
    speeds, accels : ndarray, shape (K,)
        Each move's ``v`` (rad/s) and ``a`` (rad/s^2) as written; NaN where the task gives none
        (the program then runs that move at the fastest the robot allows).
    blends : ndarray, shape (K,)
        Joint-space blend radii, rad (0: the move stops at its target).
    ur_blends : ndarray, shape (K,)
        UR blend radii for the URScript, m (tool centre point).
    """

    name: str
    robot: str | None
    waypoints: Array
    speeds: Array
    accels: Array
    blends: Array
    ur_blends: Array

    @property
    def moves(self) -> int:
        return int(self.waypoints.shape[0] - 1)


def _number(value: Any, what: str, *, low: float, strict: bool) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise KinergyError(f"{what}: expected a number, got {value!r}")
    x = float(value)
    if not math.isfinite(x) or x < low or (strict and x == low):
        raise KinergyError(f"{what}: must be {'>' if strict else '>='} {low:g}, got {value!r}")
    return x


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
    defaults: tuple[float | None, float | None],
) -> tuple[Array, float, float, float, float]:
    """One ``[[move]]`` table: its target (rad) and ``v``, ``a`` (NaN: not given), ``r``,
    ``ur_r``; ``defaults`` are the task's ``speed`` and ``acceleration``."""
    extra = sorted(set(move) - _MOVE_KEYS)
    if extra:
        raise KinergyError(
            f"{where}: unknown field {extra[0]!r} (known: {', '.join(sorted(_MOVE_KEYS))})"
        )
    if "q" not in move:
        raise KinergyError(f"{where}.q: missing (the move's joint targets)")
    q = _angles(move["q"], f"{where}.q", scale, n)
    v = move.get("v", defaults[0])
    a = move.get("a", defaults[1])
    return (
        q,
        math.nan if v is None else _number(v, f"{where}.v", low=0.0, strict=True),
        math.nan if a is None else _number(a, f"{where}.a", low=0.0, strict=True),
        _number(move.get("r", 0.0), f"{where}.r", low=0.0, strict=False),
        _number(move.get("ur_r", 0.0), f"{where}.ur_r", low=0.0, strict=False),
    )


def task_from_dict(
    data: dict[str, Any], *, name: str = "task", n_joints: int | None = None
) -> Task:
    """A :class:`Task` from a parsed task file (see the module docstring).

    Parameters
    ----------
    data : dict
        The TOML document.
    name : str
        For the task's name (messages are prefixed by the caller).
    n_joints : int, optional
        The robot's joint count, to check every pose against.

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
    speed = data.get("speed")
    speed = None if speed is None else _number(speed, "speed", low=0.0, strict=True)
    acc = data.get("acceleration")
    acc = None if acc is None else _number(acc, "acceleration", low=0.0, strict=True)
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
    settings = np.array([row[1:] for row in rows])  # (K, 4): v, a, r, ur_r
    start = _angles(data["start"], "start", scale, n) if "start" in data else targets[-1].copy()
    largest = float(np.max(np.abs(np.vstack([start, *targets])))) / scale
    if unit == "deg" and largest <= 2.0 * math.pi:
        raise KinergyError(
            f'unit = "deg", but every joint angle is within {largest:.3g}, as angles in rad '
            'are: radians in a file that says degrees? (unit = "rad")'
        )
    return Task(
        name=str(data.get("name", name)),
        robot=robot,
        waypoints=np.vstack([start, *targets]),
        speeds=settings[:, 0].copy(),
        accels=settings[:, 1].copy(),
        blends=settings[:, 2].copy(),
        ur_blends=settings[:, 3].copy(),
    )


def _builtin(name: str, robot: Robot | None) -> Task:
    if robot is None:
        raise KinergyError(f"task {name!r}: a built-in task needs the robot it runs on")
    waypoints = paper_waypoints(robot, BUILTIN_TASKS[name])
    speed, acc = paper_speed(robot)
    moves = waypoints.shape[0] - 1
    return Task(
        name=name,
        robot=robot.name,
        waypoints=waypoints,
        speeds=np.full(moves, speed),
        accels=np.full(moves, acc),
        blends=np.zeros(moves),
        ur_blends=np.zeros(moves),
    )


def load_task(name_or_path: str | os.PathLike[str], *, robot: Robot | None = None) -> Task:
    """Read a task file (TOML, see the module docstring) or build a built-in task.

    Parameters
    ----------
    name_or_path : str or path
        ``test-a``, ``test-b`` (:data:`BUILTIN_TASKS`) or a task file.
    robot : Robot, optional
        The robot the task runs on: needed for a built-in task; for a file, every pose is
        checked to have its joint count.

    Returns
    -------
    Task
        ``waypoints`` (K + 1, n) in rad; per-move ``speeds``, ``accels`` (NaN: not given),
        ``blends`` and ``ur_blends``.

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
    try:
        task = task_from_dict(data, name=path.stem, n_joints=None if robot is None else robot.n)
    except KinergyError as exc:
        raise exc.prefixed(str(path)) from None
    if robot is not None and task.robot is not None:
        _check_robot(path, task.robot, robot)
    return task


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
