"""The fleet manifest: which robots there are, their models, and where their logs are.

A TOML file with one table per robot; paths are relative to the manifest's folder::

    [[robot]]
    name = "cell-3"
    model = "ur5e"             # a built-in name or a robot file
    logs = "cell-3/*.csv"      # a glob (or a list of globs)
    topic = "/joint_states"    # optional, for ROS 2 bags: the JointState topic
    effort = "current"         # optional, for ROS 2 bags: what effort holds (current|torque)

:func:`fleet_logs` puts the manifest's globs and the logs named on the command line together,
each log once, each with its robot and its date: the ISO date (``YYYY-MM-DD``) in its file name,
else the day of its modification time. A log may be a ROS 2 bag (a rosbag2 folder or its storage
file, :mod:`kinergy.io.rosbag`), read with its robot's ``topic`` and ``effort``.
"""

from __future__ import annotations

import datetime as dt
import fnmatch
import glob
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from kinergy.errors import KinergyError
from kinergy.files import read_toml
from kinergy.io.rosbag import BagOptions, Effort, bag_options, is_bag
from kinergy.logs.checks import Check
from kinergy.logs.window import TimeWindow
from kinergy.model.robot import Payload

__all__ = ["FleetLog", "Manifest", "RobotEntry", "fleet_logs", "log_date", "read_manifest"]

_DATE = re.compile(r"(?<!\d)(\d{4})-(\d{2})-(\d{2})(?!\d)")


@dataclass(frozen=True)
class RobotEntry:
    """One ``[[robot]]`` table.

    Attributes
    ----------
    name : str
    model : str
        A built-in robot name or a robot file's path (made absolute against the manifest).
    globs : tuple of str
        Absolute glob patterns of its logs.
    topic : str or None
        Its ROS 2 bags' ``JointState`` topic; None: ``--topic``, else ``/joint_states``.
    effort : Effort or None
        What its bags' ``effort`` holds; None: ``--effort``, else the robot's default.
    """

    name: str
    model: str
    globs: tuple[str, ...]
    topic: str | None = None
    effort: Effort | None = None


@dataclass(frozen=True)
class Manifest:
    path: Path
    robots: tuple[RobotEntry, ...]


@dataclass(frozen=True)
class FleetLog:
    """A log to analyse: its robot, the robot's model, the log's date and, for a ROS 2 bag, how
    to read it; the checks accepted, the payload given (``--payload``: else the one the log's
    controller logged, else the model's) and the time window (``--from``/``--to``)."""

    robot: str
    model: str
    path: str
    date: dt.date
    bag: BagOptions | None = None
    accept: frozenset[Check] = frozenset()
    payload: Payload | None = None
    window: TimeWindow | None = None


def _text(table: dict[str, object], key: str, where: str) -> str:
    value = table.get(key)
    if not isinstance(value, str) or not value.strip():
        raise KinergyError(f"{where}: '{key}' must be a non-empty string")
    return value.strip()


def _entry(table: object, k: int, folder: Path, path: Path) -> RobotEntry:
    where = f"{path}: robot[{k}]"
    if not isinstance(table, dict):
        raise KinergyError(f"{where}: expected a [[robot]] table")
    unknown = sorted(set(table) - {"name", "model", "logs", "topic", "effort"})
    if unknown:
        raise KinergyError(
            f"{where}: unknown key(s) {', '.join(unknown)} (name, model, logs, topic, effort)"
        )
    name = _text(table, "name", where)
    where = f"{path}: robot {name!r}"
    model = _text(table, "model", where)
    if model.endswith((".toml", ".urdf")) or "/" in model or os.sep in model:
        model = str(folder / model)
    logs = table.get("logs")
    patterns = [logs] if isinstance(logs, str) else logs
    if (
        not isinstance(patterns, list)
        or not patterns
        or not all(isinstance(p, str) and p.strip() for p in patterns)
    ):
        raise KinergyError(f"{where}: 'logs' must be a glob or a list of globs")
    topic = None if table.get("topic") is None else _text(table, "topic", where)
    effort = None if table.get("effort") is None else _text(table, "effort", where)
    try:
        bag = bag_options(topic, effort)  # checked here, merged with the flags in fleet_logs
    except KinergyError as exc:
        raise KinergyError(f"{where}: {str(exc).removeprefix('--')}") from None
    return RobotEntry(
        name,
        model,
        tuple(str(folder / p.strip()) for p in patterns),
        None if topic is None or bag is None else bag.topic,
        None if bag is None else bag.effort,
    )


def read_manifest(path: str | os.PathLike[str]) -> Manifest:
    """Read and check a manifest (see the module docstring).

    Raises
    ------
    KinergyError
        Not TOML, no ``[[robot]]`` table, a missing or unknown key, a repeated robot name.
    """
    path = Path(path)
    data = read_toml(path, "fleet manifest")
    tables = data.get("robot")
    if not isinstance(tables, list) or not tables:
        raise KinergyError(f"{path}: no [[robot]] table (name, model, logs)")
    extra = sorted(set(data) - {"robot"})
    if extra:
        raise KinergyError(f"{path}: unknown table(s) {', '.join(extra)}; expected [[robot]]")
    folder = path.resolve().parent
    robots = tuple(_entry(t, k, folder, path) for k, t in enumerate(tables))
    names = [r.name for r in robots]
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise KinergyError(f"{path}: robot name(s) {', '.join(repeated)} given twice")
    return Manifest(path, robots)


def log_date(path: str | os.PathLike[str]) -> dt.date:
    """The ISO date in the file's name (the last one), else its modification day."""
    found = _DATE.findall(Path(path).name)
    for year, month, day in reversed(found):
        try:
            return dt.date(int(year), int(month), int(day))
        except ValueError:
            continue
    return dt.date.fromtimestamp(os.path.getmtime(path))


def _is_log(path: Path) -> bool:
    """A file, or a ROS 2 bag folder."""
    return path.is_file() or (path.is_dir() and is_bag(path))


def _robot_of(log: Path, manifest: Manifest) -> RobotEntry:
    """The robot a command-line log belongs to: the one whose glob names it, else the one whose
    name is a folder on its path or starts its file name."""
    for robot in manifest.robots:
        if any(fnmatch.fnmatch(str(log), str(Path(g).resolve())) for g in robot.globs):
            return robot
    for robot in manifest.robots:
        if robot.name in log.parts[:-1] or log.name.startswith(robot.name):
            return robot
    raise KinergyError(f"{log}: belongs to no robot of the manifest (no glob names it)")


def _bag(robot: RobotEntry, given: BagOptions | None) -> BagOptions | None:
    """How ``robot``'s bags are read: its entry's topic and effort, else the ``given`` ones."""
    topic = robot.topic or (None if given is None else given.topic)
    return bag_options(topic, robot.effort or (None if given is None else given.effort))


def fleet_logs(
    manifest: Manifest,
    extra: Sequence[str | os.PathLike[str]] = (),
    bag: BagOptions | None = None,
) -> list[FleetLog]:
    """Every log the manifest's globs and ``extra`` name, each once, with robot and date, and
    how to read it if it is a ROS 2 bag (the robot entry's ``topic`` and ``effort``, else
    ``bag``'s: ``--topic``, ``--effort``).

    Raises
    ------
    KinergyError
        A glob that matches nothing, a log two robots' globs name, a missing command-line log,
        or one that belongs to no robot.
    """
    owner: dict[Path, RobotEntry] = {}
    for robot in manifest.robots:
        for pattern in robot.globs:
            found = sorted(Path(p).resolve() for p in glob.glob(pattern) if _is_log(Path(p)))
            if not found:
                raise KinergyError(
                    f"{manifest.path}: robot {robot.name!r}: {pattern} matches no file"
                )
            for log in found:
                other = owner.setdefault(log, robot)
                if other.name != robot.name:
                    raise KinergyError(
                        f"{log}: named by the logs of both {other.name!r} and {robot.name!r}"
                    )
    for given in extra:
        log = Path(given).resolve()
        if not _is_log(log):
            raise KinergyError(f"{given}: no such log file")
        owner.setdefault(log, _robot_of(log, manifest))
    return [
        FleetLog(robot.name, robot.model, str(log), log_date(log), _bag(robot, bag))
        for log, robot in sorted(owner.items(), key=lambda item: (item[1].name, str(item[0])))
    ]
