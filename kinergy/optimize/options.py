"""The program optimiser's options as types, parsed once where they enter (the CLI, the Python API).

:class:`ToolSymmetry` is a tool's symmetry about its z axis with the turns it allows,
:class:`Configurations` whether a pose target may change its inverse-kinematics branch,
:class:`ViaPoints` whether the joint-space via points of a program may leave the route, and
:class:`ProgramOptions` all of a program optimisation's options in one frozen value, checked on
construction. Below this module nothing re-validates a string: the values are passed down as they
are.
"""

from __future__ import annotations

import enum
import math
import re
from dataclasses import dataclass
from typing import Self

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError

__all__ = ["Configurations", "ProgramOptions", "ToolSymmetry", "ViaPoints"]


#: a fully symmetric tool's first search steps about its axis, rad
_ANY_ANGLE_STEP = np.pi / 4


class ToolSymmetry(enum.Enum):
    """The turns about the tool's z axis that leave the tool's job unchanged.

    ``NONE``: none; ``Z2``: 180 degree steps (two fingers); ``Z4``: 90 degree steps (a square
    box); ``Z``: any angle (a vacuum cup on a round part).
    """

    NONE = "none"
    Z = "z"
    Z2 = "z2"
    Z4 = "z4"

    @classmethod
    def parse(cls, text: str) -> ToolSymmetry:
        """The symmetry named ``text`` (``none``, ``z``, ``z2``, ``z4``).

        Raises
        ------
        KinergyError
            Any other name, in one line.
        """
        try:
            return cls(text)
        except ValueError:
            names = ", ".join(s.value for s in cls)
            raise KinergyError(f"tool symmetry: expected one of {names}, got {text!r}") from None

    @property
    def turns(self) -> int:
        """How many equivalent turns a full turn holds (0: any angle)."""
        return {"none": 1, "z2": 2, "z4": 4, "z": 0}[self.value]

    @property
    def any_angle(self) -> bool:
        """Whether every angle about the axis is equivalent."""
        return self.turns == 0

    @property
    def steps(self) -> bool:
        """Whether the symmetry is a few discrete turns (180 or 90 degrees)."""
        return self.turns > 1

    def angles(self) -> Array:
        """The turns the path search tries first, rad: the equivalent turns, or every 45 degrees
        for any angle (refined around the best later)."""
        step = _ANY_ANGLE_STEP if self.any_angle else 2.0 * np.pi / self.turns
        return np.arange(0.0, 2.0 * np.pi - 1e-9, step)

    def equivalent(self) -> Array:
        """The turns that leave the tool's pose unchanged for its job (for checking a target),
        rad; empty for any angle (only the tool axis counts then)."""
        if self.any_angle:
            return np.zeros(0)
        return 2.0 * np.pi * np.arange(self.turns) / self.turns


class _KeepOrFree(enum.Enum):
    """An option that is ``keep`` or ``free``, named in its messages after its class
    (``ViaPoints``: "via points")."""

    @classmethod
    def parse(cls, text: str) -> Self:
        """``keep`` or ``free``.

        Raises
        ------
        KinergyError
            Any other name, in one line.
        """
        try:
            return cls(text)
        except ValueError:
            name = re.sub(r"(?<!^)(?=[A-Z])", " ", cls.__name__).lower()
            raise KinergyError(f"{name}: expected keep or free, got {text!r}") from None


class Configurations(_KeepOrFree):
    """Whether a movej's pose target keeps the program's inverse-kinematics branch (``KEEP``: a
    new branch can collide with the cell) or may take any of the eight (``FREE``)."""

    KEEP = "keep"
    FREE = "free"


class ViaPoints(_KeepOrFree):
    """Whether the program's joint-space via points stay where the programmer put them.

    A joint-space via point is the target of a ``movej`` that is followed by another ``movej``
    with no I/O, ``sleep`` or other call at rest between them (``set_tcp`` and ``set_payload``
    do not count): it only shapes the route, such as a home pose passed on every cycle. ``KEEP``
    (the default: the route may avoid something in the cell); ``FREE``: the route between the
    two targets around it may leave it out, the via point then taking the joints of the target
    before or after it (the move to it goes nowhere).
    """

    KEEP = "keep"
    FREE = "free"


def _positive(name: str, value: float | None) -> float | None:
    if value is None:
        return None
    x = float(value)
    if not (math.isfinite(x) and x > 0.0):
        raise KinergyError(f"{name}: must be a finite number > 0, got {value!r}")
    return x


@dataclass(frozen=True)
class ProgramOptions:
    """What :func:`kinergy.optimize.programs.optimize_program` may change, and its limits.

    Attributes
    ----------
    configurations : Configurations
    tool_symmetry : ToolSymmetry
    via : ViaPoints
    blends : bool
        Whether via points may get blend radii.
    fixed_shares : bool
        The timing keeps each move's share of the cycle time (chooses only how each runs).
    standby : float or None
        Standby power, W (>= 0), counted over the cycle time; None: the robot file's.
    cycle_time : float or None
        The cycle time, s (> 0); None: the program's own.
    v_max, a_max : float or None
        Caps on every joint's speed (rad/s) and acceleration (rad/s^2), > 0; None: the
        program's own peaks.

    Raises
    ------
    KinergyError
        A value of the wrong type or out of range, in one line naming it.
    """

    configurations: Configurations = Configurations.KEEP
    tool_symmetry: ToolSymmetry = ToolSymmetry.NONE
    via: ViaPoints = ViaPoints.KEEP
    blends: bool = True
    fixed_shares: bool = False
    standby: float | None = None
    cycle_time: float | None = None
    v_max: float | None = None
    a_max: float | None = None

    def __post_init__(self) -> None:
        for name, kind in (
            ("configurations", Configurations),
            ("tool_symmetry", ToolSymmetry),
            ("via", ViaPoints),
        ):
            if not isinstance(getattr(self, name), kind):
                raise KinergyError(
                    f"{name}: expected a {kind.__name__}, got {getattr(self, name)!r}"
                )
        if self.standby is not None:
            standby = float(self.standby)
            if not (math.isfinite(standby) and standby >= 0.0):
                raise KinergyError(f"standby: must be a finite power >= 0 W, got {self.standby!r}")
            object.__setattr__(self, "standby", standby)
        for name in ("cycle_time", "v_max", "a_max"):
            object.__setattr__(self, name, _positive(name, getattr(self, name)))
        object.__setattr__(self, "blends", bool(self.blends))
        object.__setattr__(self, "fixed_shares", bool(self.fixed_shares))
