"""A robot program as the controller runs it: moves and fixed-time events, in order.

This is what :mod:`kinergy.io.urscript_reader` reads from a URScript file and what
:mod:`kinergy.trajectory.controller` simulates: a sequence of :class:`Move` (``movej``,
``movel``, ``movep`` to a joint or a pose target with URScript's ``a``, ``v``, ``t``, ``r``) and
:class:`Event` (``sleep``, I/O calls, ``set_tcp``, ``set_payload`` and any other line kept
verbatim), each remembering its line in the file so that every message can name it.

Units are URScript's: joint targets in rad, ``a`` and ``v`` in rad/s^2 and rad/s for ``movej``
and in m/s^2 and m/s for ``movel``/``movep``, ``t`` in s, the blend radius ``r`` in m (at the
tool centre point), poses ``[x, y, z, rx, ry, rz]`` in m and rad (rotation vector).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.model.robot import Payload

__all__ = [
    "MOVE_DEFAULTS",
    "Event",
    "Move",
    "RobotProgram",
    "Step",
]


#: URScript's default ``(a, v)`` of each move (rad/s^2, rad/s for movej; m/s^2, m/s otherwise)
MOVE_DEFAULTS = {"movej": (1.4, 1.05), "movel": (1.2, 0.25), "movep": (1.2, 0.25)}

#: event kinds: what the controller does there (the robot is at rest during each)
EVENT_KINDS = ("sleep", "io", "tcp", "payload", "sync", "other")


@dataclass(frozen=True, eq=False)
class Move:
    """One ``movej``, ``movel`` or ``movep``.

    Attributes
    ----------
    kind : {'movej', 'movel', 'movep'}
    target : ndarray, shape (n,) or (6,)
        Joint angles (rad; URScript's have 6, a task's as many as its robot's joints) or, when
        ``pose``, ``[x, y, z, rx, ry, rz]`` (m, rad).
    pose : bool
        Whether ``target`` is a pose (``p[...]``).
    a, v : float
        Acceleration and speed, > 0 (URScript's units, see the module docstring).
    t : float
        Duration, s (0: from ``a`` and ``v``).
    r : float
        Blend radius at the tool, m (0: the move stops at its target).
    joint_blend : float
        A movej's blend radius on the leading joint, rad (a task's ``r``: kinergy's own); when
        > 0 the move blends by it instead of by ``r`` (which is then only written out).
    qnear : ndarray, shape (6,), optional
        For a pose target: the joints the solution should be near (``get_inverse_kin(x,
        qnear)``); default the joints where the move starts (the controller's choice).
    line : int
        Line in the program file (1-based; 0: not from a file).
    text : str
        The statement as written.
    """

    kind: str
    target: Array
    pose: bool
    a: float
    v: float
    t: float = 0.0
    r: float = 0.0
    joint_blend: float = 0.0
    qnear: Array | None = None
    line: int = 0
    text: str = ""

    def __post_init__(self) -> None:
        if self.kind not in MOVE_DEFAULTS:
            raise KinergyError(f"unknown move {self.kind!r}")
        target = np.asarray(self.target, dtype=float)
        if (
            target.ndim != 1
            or (self.pose and target.size != 6)
            or target.size == 0
            or not np.all(np.isfinite(target))
        ):
            what = "a pose of 6" if self.pose else "joint angles as"
            raise KinergyError(f"{self.kind}: the target must be {what} finite numbers")
        object.__setattr__(self, "target", target)
        for name, low, strict in (("a", 0.0, True), ("v", 0.0, True), ("t", 0.0, False)):
            x = float(getattr(self, name))
            if not np.isfinite(x) or x < low or (strict and x == low):
                raise KinergyError(
                    f"{self.kind}: {name} must be {'>' if strict else '>='} 0, got {x:g}"
                )
            object.__setattr__(self, name, x)
        for name in ("r", "joint_blend"):
            x = float(getattr(self, name))
            if not (np.isfinite(x) and x >= 0.0):
                raise KinergyError(f"{self.kind}: {name} must be >= 0, got {x:g}")
            object.__setattr__(self, name, x)
        if self.joint_blend > 0.0 and self.kind != "movej":
            raise KinergyError(f"{self.kind}: a joint-space blend is for a movej only")
        if self.qnear is not None:
            qn = np.asarray(self.qnear, dtype=float)
            if qn.shape != (6,) or not np.all(np.isfinite(qn)):
                raise KinergyError(f"{self.kind}: qnear must be 6 finite joint angles")
            object.__setattr__(self, "qnear", qn)

    @property
    def tool_space(self) -> bool:
        """Whether the tool moves on a straight line (``movel``, ``movep``)."""
        return self.kind != "movej"

    @property
    def blends(self) -> bool:
        """Whether the move has a blend radius (it blends into the next move, if one follows
        with no event between)."""
        return self.r > 0.0 or self.joint_blend > 0.0

    def replaced(self, **changes: object) -> Move:
        """A copy with some fields changed."""
        return dataclasses.replace(self, **changes)  # type: ignore[arg-type]


@dataclass(frozen=True, eq=False)
class Event:
    """A statement that is not a move: the robot is at rest for ``duration`` seconds.

    Attributes
    ----------
    kind : {'sleep', 'io', 'tcp', 'payload', 'sync', 'other'}
    duration : float
        s, >= 0 (fixed: the optimiser never changes it).
    line : int
    text : str
        The statement as written (kept verbatim in a rewritten program).
    tcp : ndarray, shape (6,), optional
        ``set_tcp``'s pose of the tool centre point in the flange frame.
    payload : Payload, optional
        ``set_payload``'s load.
    """

    kind: str
    duration: float
    line: int = 0
    text: str = ""
    tcp: Array | None = None
    payload: Payload | None = None

    def __post_init__(self) -> None:
        if self.kind not in EVENT_KINDS:
            raise KinergyError(f"unknown event kind {self.kind!r}")
        if not (np.isfinite(self.duration) and self.duration >= 0.0):
            raise KinergyError(f"{self.kind}: a duration must be >= 0 s, got {self.duration}")
        if self.tcp is not None:
            tcp = np.asarray(self.tcp, dtype=float)
            if tcp.shape != (6,) or not np.all(np.isfinite(tcp)):
                raise KinergyError("set_tcp needs a pose of 6 numbers")
            object.__setattr__(self, "tcp", tcp)


Step = Move | Event


@dataclass(frozen=True, eq=False)
class RobotProgram:
    """A program: its steps in order and the file it came from.

    Attributes
    ----------
    name : str
        ``def name():`` (or the file's stem).
    steps : tuple of Move and Event
    path : str
        The file (for messages; empty when built in code).
    lines : tuple of str
        The file's lines, to write the program back with changed moves.
    notes : tuple of str
        What reading assumed (statements kept verbatim as events of fixed time).
    start : ndarray, shape (n,), optional
        Joints the program starts from, rad; None: where it ends (it runs in cycles).
    """

    name: str
    steps: tuple[Step, ...]
    path: str = ""
    lines: tuple[str, ...] = ()
    notes: tuple[str, ...] = field(default=())
    start: Array | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "steps", tuple(self.steps))
        if self.start is not None:
            start = np.asarray(self.start, dtype=float)
            if start.ndim != 1 or not np.all(np.isfinite(start)):
                raise KinergyError(f"{self.path or self.name}: the start must be finite joints")
            object.__setattr__(self, "start", start)
        if not self.moves:
            raise KinergyError(f"{self.path or self.name}: the program has no move")

    @property
    def moves(self) -> list[Move]:
        """The moves, in order."""
        return [s for s in self.steps if isinstance(s, Move)]

    @property
    def move_index(self) -> list[int]:
        """Index in :attr:`steps` of each move."""
        return [i for i, s in enumerate(self.steps) if isinstance(s, Move)]

    def where(self, line: int) -> str:
        """``FILE:LINE`` (or ``line LINE``) for a message."""
        return f"{self.path}:{line}" if self.path else f"line {line}"

    def with_moves(self, moves: list[Move]) -> RobotProgram:
        """The same program with its moves replaced, in order (events kept)."""
        if len(moves) != len(self.moves):
            raise KinergyError(f"expected {len(self.moves)} moves, got {len(moves)}")
        it = iter(moves)
        steps = tuple(next(it) if isinstance(s, Move) else s for s in self.steps)
        return dataclasses.replace(self, steps=steps)
