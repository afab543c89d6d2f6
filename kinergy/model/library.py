"""The built-in robot library (the robot files shipped in ``kinergy/model/library/``, by name),
and any robot file by path: TOML, or URDF by its ``.urdf`` suffix."""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path
from typing import Any

from kinergy.errors import KinergyError
from kinergy.model.robot import Payload, Robot
from kinergy.model.toml import read_robot_toml
from kinergy.model.urdf import robot_from_urdf

__all__ = ["library_names", "load_robot", "read_robot_file"]


def _library_dir() -> Any:
    return resources.files("kinergy.model") / "library"


def library_names() -> list[str]:
    """Names of the built-in robot files, sorted."""
    return sorted(
        p.name.removesuffix(".toml") for p in _library_dir().iterdir() if p.name.endswith(".toml")
    )


def read_robot_file(path: str | os.PathLike[str]) -> Robot:
    """Read a robot file: TOML (:func:`kinergy.model.toml.read_robot_toml`), or URDF by its
    ``.urdf`` suffix (:func:`kinergy.model.urdf.robot_from_urdf`).

    Raises
    ------
    KinergyError
        ``FILE: problem`` for unreadable files, syntax errors (with line and column) and any
        invalid field.
    """
    if Path(path).suffix.lower() == ".urdf":
        return robot_from_urdf(path)
    return read_robot_toml(path)


def load_robot(name_or_path: str | os.PathLike[str], *, payload: Payload | None = None) -> Robot:
    """Load a built-in robot by name (``"ur5e"``) or a robot file by path (TOML or URDF).

    Parameters
    ----------
    name_or_path : str or path
        A name from :func:`library_names` or a path to a ``.toml`` / ``.urdf`` file.
    payload : Payload, optional
        Replaces the file's payload.

    Raises
    ------
    KinergyError
        Unknown name (listing the built-in ones), unreadable or invalid file.
    """
    key = os.fspath(name_or_path)
    if key in library_names():
        ref = _library_dir() / f"{key}.toml"
        with resources.as_file(ref) as path:
            robot = read_robot_file(path)
    elif Path(key).exists():
        robot = read_robot_file(key)
    else:
        raise KinergyError(
            f"unknown robot {key!r}: not a built-in robot ({', '.join(library_names())}) "
            "and no such file"
        )
    return robot if payload is None else robot.with_payload(payload)
