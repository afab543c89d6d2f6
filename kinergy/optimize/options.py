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
from dataclasses import dataclass

import numpy as np

from kinergy.arrays import Array
from kinergy.checks import choice, flag, number

__all__ = [
    "MAX_ACCELERATION_CAP",
    "MAX_CYCLE_TIME",
    "MAX_SPEED_CAP",
    "MIN_CAP",
    "Configurations",
    "ProgramOptions",
    "ToolSymmetry",
    "ViaPoints",
]


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


class Configurations(enum.Enum):
    """Whether a movej's pose target keeps the program's inverse-kinematics branch (``KEEP``: a
    new branch can collide with the cell) or may take any of the eight (``FREE``)."""

    KEEP = "keep"
    FREE = "free"


class ViaPoints(enum.Enum):
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


#: s: the longest cycle time optimised (each is re-simulated at 500 Hz, Pareto points and all)
MAX_CYCLE_TIME = 600.0
#: the smallest speed (rad/s) and acceleration (rad/s^2) caps taken (below 1e-3, 0.06 deg/s, a
#: move takes longer than any cycle-time budget and its profile underflows), and the largest
MIN_CAP = 1e-3
MAX_SPEED_CAP = 100.0
MAX_ACCELERATION_CAP = 1e4


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
    standby : float or None
        Standby power, W (>= 0), counted over the cycle time; None: the robot file's.
    cycle_time : float or None
        The cycle time, s (> 0, <= :data:`MAX_CYCLE_TIME`); None: the program's own.
    v_max, a_max : float or None
        Caps on every joint's speed (rad/s) and acceleration (rad/s^2), from :data:`MIN_CAP`
        to :data:`MAX_SPEED_CAP` and :data:`MAX_ACCELERATION_CAP`; None: the program's own
        peaks (a task: the robot's limits).

    A name given for an enum (``tool_symmetry="z"``) is parsed into it.

    Raises
    ------
    KinergyError
        A value not one of an option's or out of range, in one line naming it by its flag
        (``--cycle-time: must be a finite number > 0 and <= 600, got 700``).
    """

    configurations: Configurations = Configurations.KEEP
    tool_symmetry: ToolSymmetry = ToolSymmetry.NONE
    via: ViaPoints = ViaPoints.KEEP
    blends: bool = True
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
            object.__setattr__(self, name, choice(getattr(self, name), kind, flag(name)))
        bounds: tuple[tuple[str, dict[str, float]], ...] = (
            ("standby", {"ge": 0.0}),
            ("cycle_time", {"gt": 0.0, "le": MAX_CYCLE_TIME}),
            ("v_max", {"ge": MIN_CAP, "le": MAX_SPEED_CAP}),
            ("a_max", {"ge": MIN_CAP, "le": MAX_ACCELERATION_CAP}),
        )
        for name, bound in bounds:
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, number(value, flag(name), **bound))
        object.__setattr__(self, "blends", bool(self.blends))

    def levers(self) -> list[str]:
        """The flags of the levers these options ask for (a value other than the default): those
        only a URScript program takes."""
        default = ProgramOptions()
        return [
            "--no-blends" if name == "blends" else flag(name)
            for name in ("configurations", "tool_symmetry", "via", "blends", "standby")
            if getattr(self, name) != getattr(default, name)
        ]
