"""``kinergy robot``: the built-in library, a robot as its file holds it, and robot files
written as URDF or MJCF or read from a URDF."""

from __future__ import annotations

import enum
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from kinergy.errors import KinergyError
from kinergy.files import atomic_write
from kinergy.model import SOURCE_CATEGORIES, Robot, library_names, load_robot
from kinergy.model.export import Export
from kinergy.model.mjcf import robot_to_mjcf
from kinergy.model.toml import robot_to_dict, save_robot
from kinergy.model.urdf import UrdfImport, import_urdf
from kinergy.model.urdf_export import robot_to_urdf

__all__ = [
    "ExportFormat",
    "LibraryRobot",
    "RobotFile",
    "export_robot",
    "library",
    "read_urdf",
]


@dataclass(frozen=True, eq=False)
class LibraryRobot:
    """A built-in robot, as ``robot list`` shows it: its name, joints, convention and where each
    group of its parameters comes from."""

    robot: Robot

    def status(self, categories: Sequence[str]) -> str:
        """The status shared by the parameter ``categories`` (``mixed`` when they differ)."""
        statuses = {self.robot.sources[c].status for c in categories}
        return statuses.pop() if len(statuses) == 1 else "mixed"

    def to_dict(self) -> dict[str, Any]:
        """One entry of ``kinergy robot list --json``."""
        r = self.robot
        return {
            "name": r.name,
            "description": r.description,
            "joints": r.n,
            "convention": r.convention,
            "sources": {
                c: {"status": r.sources[c].status, "ref": r.sources[c].ref}
                for c in SOURCE_CATEGORIES
            },
        }


def library() -> list[LibraryRobot]:
    """Every built-in robot, in the library's order."""
    return [LibraryRobot(load_robot(name)) for name in library_names()]


@dataclass(frozen=True, eq=False)
class RobotFile:
    """A robot as ``robot show`` gives it; :meth:`to_dict` is ``robot show --json``, the
    dictionary its TOML file holds."""

    robot: Robot

    def to_dict(self) -> dict[str, Any]:
        return robot_to_dict(self.robot)


class ExportFormat(enum.Enum):
    """``robot export --format``: URDF (kinematics, inertials, limits, joint-side friction, the
    drives in a ``<kinergy:model>`` element) or a MuJoCo MJCF model."""

    URDF = "urdf"
    MJCF = "mjcf"


def export_robot(
    robot: Robot, format: ExportFormat, out: str | os.PathLike[str], *, source: str = ""
) -> Export:
    """Write ``robot`` to ``out`` as ``format`` (whole or not at all); ``source``: what the
    file's comments say it was made from. Returns the text and the notes (what the format
    could not hold)."""
    writer = robot_to_urdf if format is ExportFormat.URDF else robot_to_mjcf
    export = writer(robot, source=source)
    atomic_write(out, lambda fh: fh.write(export.text))
    return export


def read_urdf(
    urdf: str | os.PathLike[str],
    out: str | os.PathLike[str],
    *,
    root: str | None = None,
    tip: str | None = None,
    name: str | None = None,
) -> UrdfImport:
    """Read the serial chain of ``urdf`` (:func:`kinergy.model.urdf.import_urdf`) and write it
    to ``out`` as a robot file (TOML).

    Raises
    ------
    KinergyError
        ``out`` named ``.urdf`` (it is written as TOML); a URDF that is no serial chain.
    """
    if Path(out).suffix.lower() == ".urdf":
        raise KinergyError(
            f"--out: {os.fspath(out)} would be written as TOML but read back as URDF; name it .toml"
        )
    result = import_urdf(urdf, root=root, tip=tip, name=name)
    r = result.robot
    header = f"{r.name}: imported from {Path(urdf).name} by kinergy robot import-urdf"
    save_robot(r, out, header=header)
    return result
