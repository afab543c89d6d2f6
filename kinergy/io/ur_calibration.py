"""Reader of a UR controller's joint calibration summary (``robot_calibration_summary.txt``).

UR robots measure each joint at the factory: its torque constant and, at constant joint speeds in
both directions, the motor's voltage and current, the joint temperature, the friction torque and
the back-EMF constant. The summary lists them joint by joint::

    **** Joint 0 :
      Calibration revision : v12.0.1498805116
      K_tau    tau_avg  Stiction-  Stiction+  TauMax-  TauMax+  Avg. temp.
      +0.1005   0.1037  -0.05894    +0.05545  -0.1814   0.1741     +40.03

      Ang. vel.    U        I      Temp     Tau       Km
        -3.20   +23.862   -1.805  +45.74   -0.181   +0.072
        ...
    ------------------------------------------------------------------

Units and sides, as kinergy reads them (``datasets/ur5e-calibration``'s README and
docs/FRICTION.md): ``K_tau`` N m/A, motor side (``Tau = K_tau I``); ``Ang. vel.`` rad/s, JOINT
side; ``U`` V, the magnitude of the controller's dq voltage (the file writes it positive in both
directions); ``I`` A (signed); ``Temp`` deg C; ``Tau`` N m, motor side, the friction torque at
that speed; ``Km`` V s/rad, motor side. The row at speed 0 (``Km`` = nan) carries nothing and is
dropped.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.files import read_text

__all__ = ["Calibration", "JointCalibration", "read_ur_calibration"]


_SUMMARY = ("K_tau", "tau_avg", "Stiction-", "Stiction+", "TauMax-", "TauMax+", "Avg. temp.")
_POINTS = ("Ang. vel.", "U", "I", "Temp", "Tau", "Km")


@dataclass(frozen=True, eq=False)
class JointCalibration:
    """One joint's calibration (module docstring for units and sides).

    Attributes
    ----------
    joint : int
        0-based joint number, as the file writes it.
    revision : str
    torque_constant : float
        ``K_tau``, N m/A, motor side.
    stiction : tuple of float
        ``(Stiction-, Stiction+)``, N m, motor side.
    temperature : float
        ``Avg. temp.``, deg C.
    speed, voltage, current, point_temperature, friction, back_emf : ndarray, shape (k,)
        Per speed point: joint speed (rad/s), |U| (V), I (A), temperature (deg C), Tau (N m,
        motor side) and Km (V s/rad).
    """

    joint: int
    revision: str
    torque_constant: float
    stiction: tuple[float, float]
    temperature: float
    speed: Array
    voltage: Array
    current: Array
    point_temperature: Array
    friction: Array
    back_emf: Array


@dataclass(frozen=True, eq=False)
class Calibration:
    """A calibration summary: the file and its joints, in file order."""

    path: str
    joints: tuple[JointCalibration, ...]


def _numbers(line: str, count: int, where: str, what: tuple[str, ...]) -> list[float]:
    fields = line.split()
    try:
        values = [float(f) for f in fields]
    except ValueError:
        values = []
    if len(values) != count:
        raise KinergyError(f"{where}: expected {count} numbers ({', '.join(what)}), got {line!r}")
    return values


class _Reader:
    """The file's lines with their numbers, skipping blank ones; errors name ``path:line``."""

    def __init__(self, path: Path, lines: list[str]) -> None:
        self.path = path
        self.rows = [(k + 1, text.strip()) for k, text in enumerate(lines) if text.strip()]
        self.at = 0

    def where(self) -> str:
        line = self.rows[self.at][0] if self.at < len(self.rows) else len(self.rows) + 1
        return f"{self.path}:{line}"

    def peek(self) -> str:
        return self.rows[self.at][1] if self.at < len(self.rows) else ""

    def take(self, expected: str) -> str:
        if self.at >= len(self.rows):
            raise KinergyError(f"{self.path}: ends early; expected {expected}")
        self.at += 1
        return self.rows[self.at - 1][1]


def _header(reader: _Reader) -> int:
    where = reader.where()
    text = reader.take("'**** Joint N :'")
    parts = text.replace(":", " ").split()
    if len(parts) < 3 or parts[:2] != ["****", "Joint"] or not parts[2].isdigit():
        raise KinergyError(f"{where}: expected '**** Joint N :', got {text!r}")
    return int(parts[2])


def _joint(reader: _Reader) -> JointCalibration:
    number = _header(reader)
    where = reader.where()
    text = reader.take("'Calibration revision : ...'")
    if not text.startswith("Calibration revision"):
        raise KinergyError(f"{where}: expected 'Calibration revision : ...', got {text!r}")
    revision = text.split(":", 1)[-1].strip()
    where = reader.where()
    if not reader.take("the K_tau header").startswith("K_tau"):
        raise KinergyError(f"{where}: expected the header {' '.join(_SUMMARY)}")
    where = reader.where()
    summary = _numbers(reader.take("the K_tau line"), len(_SUMMARY), where, _SUMMARY)
    where = reader.where()
    if not reader.take("the speed table header").startswith("Ang. vel."):
        raise KinergyError(f"{where}: expected the header {' '.join(_POINTS)}")
    points = []
    while reader.peek() and not reader.peek().startswith(("---", "****")):
        where = reader.where()
        points.append(_numbers(reader.take("a speed point"), len(_POINTS), where, _POINTS))
    if reader.peek().startswith("---"):
        reader.take("a separator")
    table = np.array([p for p in points if p[0] != 0.0], dtype=float).reshape(-1, len(_POINTS))
    if len(table) < 2:
        raise KinergyError(f"{where}: joint {number} has fewer than 2 speed points")
    if summary[0] <= 0.0:
        raise KinergyError(f"{where}: joint {number}: K_tau must be > 0, got {summary[0]}")
    speed, voltage, current, temp, tau, km = table.T
    return JointCalibration(
        joint=number,
        revision=revision,
        torque_constant=summary[0],
        stiction=(summary[2], summary[3]),
        temperature=summary[6],
        speed=speed,
        voltage=np.abs(voltage),
        current=current,
        point_temperature=temp,
        friction=tau,
        back_emf=km,
    )


def read_ur_calibration(path: str | os.PathLike[str]) -> Calibration:
    """Read a UR joint calibration summary (module docstring).

    Raises
    ------
    KinergyError
        An unreadable file, or one line naming the line and what was expected there (a joint
        header, the ``K_tau`` line, a speed point of six numbers); joints not numbered 0, 1, ...
    """
    path = Path(path)
    text = read_text(path, "calibration file")
    reader = _Reader(path, text.splitlines())
    joints = []
    while reader.peek():
        joints.append(_joint(reader))
    if not joints:
        raise KinergyError(f"{path}: no joint ('**** Joint 0 :') in this calibration file")
    numbers = [j.joint for j in joints]
    if numbers != list(range(len(joints))):
        raise KinergyError(f"{path}: joints must be numbered 0, 1, ... in order, got {numbers}")
    return Calibration(str(path), tuple(joints))
