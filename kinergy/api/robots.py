"""The ``kinergy robot`` commands, as functions: ``robot_list``, ``robot_show``,
``import_calibration``, ``export_robot``, ``import_urdf``."""

from __future__ import annotations

import os

from kinergy.api.common import PathLike, RobotLike, robot_of
from kinergy.checks import choice
from kinergy.errors import KinergyError
from kinergy.files import check_outputs, check_replaceable
from kinergy.friction.model import FrictionModel
from kinergy.identification.options import FrictionSearch, friction_option
from kinergy.model.export import Export
from kinergy.model.library import load_robot
from kinergy.model.urdf import UrdfImport
from kinergy.workflows.calibration import CalibrationImport
from kinergy.workflows.calibration import import_calibration as run_import
from kinergy.workflows.robots import (
    ExportFormat,
    LibraryRobot,
    RobotFile,
    library,
    read_urdf,
)
from kinergy.workflows.robots import (
    export_robot as write_export,
)

__all__ = ["export_robot", "import_calibration", "import_urdf", "robot_list", "robot_show"]


def robot_list() -> list[LibraryRobot]:
    """``kinergy robot list``: the built-in robots and where each model's parameters come from
    (each entry's ``to_dict()`` is one of the command's ``--json``)."""
    return library()


def robot_show(robot: RobotLike) -> RobotFile:
    """``kinergy robot show``: ``robot`` as its file holds it (``to_dict()``: the command's
    ``--json``)."""
    return RobotFile(robot_of(robot))


def import_calibration(
    robot: PathLike,
    calibration: PathLike,
    *,
    out: PathLike,
    friction: FrictionModel | FrictionSearch | str = "auto",
) -> CalibrationImport:
    """``kinergy robot import-calibration``: the drives of ``robot`` (a built-in name or a robot
    file) from a UR joint calibration summary (torque constants, friction as ``friction``: a
    model, or ``auto`` the one that cross-validates best, and the motor electrics), written to
    ``out`` as a robot file.

    Raises
    ------
    KinergyError
        ``out`` naming an input; a bad calibration file; a joint count that differs.
    """
    inputs = [os.fspath(calibration)] + ([os.fspath(robot)] if os.path.exists(robot) else [])
    check_outputs([("--out", out)], inputs)
    family = friction_option(friction)  # the family resolved, once, at the edge
    if family is None:
        raise KinergyError("--friction: a calibration import needs a family or auto")
    return run_import(load_robot(robot), calibration, friction=family, out=out)


def export_robot(
    model: RobotLike, format: ExportFormat | str, out: PathLike, *, source: str = ""
) -> Export:
    """``kinergy robot export``: ``model`` written to ``out`` as URDF or MuJoCo MJCF
    (``format``); the result's notes say what the format cannot hold exactly. ``source``: what
    the file's comments say it was made from (a robot file's name)."""
    fmt = choice(format, ExportFormat, "--format")
    check_replaceable(out)
    return write_export(robot_of(model), fmt, out, source=source)


def import_urdf(
    urdf: PathLike,
    out: PathLike,
    *,
    root: str | None = None,
    tip: str | None = None,
    name: str | None = None,
) -> UrdfImport:
    """``kinergy robot import-urdf``: a URDF's serial chain from ``root`` to ``tip`` as a robot
    file (TOML) at ``out``; a URDF written by :func:`export_robot` gives back its model."""
    check_replaceable(out)
    return read_urdf(urdf, out, root=root, tip=tip, name=name)
