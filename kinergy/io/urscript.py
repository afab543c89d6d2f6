"""URScript programs a UR controller can run, written from kinergy's programs and motions.

:func:`program_script` writes a :class:`~kinergy.trajectory.robot_program.RobotProgram` read from
a file back with changed moves, every other line kept as it was, or a program built in code (a
task's movej program) as one statement per line: ``movej(q, a=..., v=..., r=...)``, joint angles
in rad, URScript's ``a`` (rad/s^2) and ``v`` (rad/s) of the leading joint, as kinergy's
:mod:`kinergy.trajectory.movej` plans them. :func:`servoj_program` streams a sampled trajectory.
:func:`write_script` puts any script on disk atomically.

Blending: URScript's ``r`` is a blend radius in metres around the target's tool position, while
a task may blend by a joint-space radius (rad, on the leading joint: :attr:`Move.joint_blend`).
The two do not convert without the tool, so only ``r`` is written.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.checks import number
from kinergy.errors import KinergyError
from kinergy.files import atomic_write
from kinergy.io.urscript_reader import (
    assigned_name,
    identifiers,
    parse_program,
    split_comment,
    target_name,
)
from kinergy.trajectory.motion import CONTROLLER_DT
from kinergy.trajectory.robot_program import Move, RobotProgram

__all__ = [
    "SERVO_PERIOD",
    "move_statement",
    "program_script",
    "servoj_program",
    "target_literal",
    "write_script",
]


def _num(x: float) -> str:
    """A number URScript parses, exactly enough for 500 Hz (9 significant digits)."""
    return f"{float(x):.9g}"


def _decimal(x: float) -> str:
    """A number in plain decimal notation (no exponent, which URScript may not read), to 1e-9:
    joint angles in rad, and ``a`` and ``v`` of a movej."""
    text = f"{float(x):.9f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def _name(name: str) -> str:
    if (
        not name
        or not (name[0].isalpha() or name[0] == "_")
        or not all(c.isalnum() or c == "_" for c in name)
    ):
        raise KinergyError(
            f"program name {name!r}: must be letters, digits and underscores, not starting "
            "with a digit"
        )
    return name


def _vector(q: ArrayLike) -> str:
    """A joint vector, rad, in plain decimals: ``[q0, q1, ...]``."""
    return "[" + ", ".join(_decimal(x) for x in np.asarray(q, dtype=float)) + "]"


def _comments(header: Sequence[str], indent: str) -> list[str]:
    """The header as comment lines after ``indent``: one per line of each entry."""
    return [f"{indent}# {line}" for text in header for line in str(text).splitlines()]


def _program(name: str, header: Sequence[str], body: Sequence[str]) -> str:
    """``def name():``, the header as comments (:func:`_comments`), the body lines (indented),
    ``end``; newline-terminated."""
    lines = [f"def {_name(name)}():", *_comments(header, "  ")]
    lines.extend(f"  {line}" for line in body)
    lines.append("end")
    return "\n".join(lines) + "\n"


def target_literal(move: Move) -> str:
    """A move's target as a URScript value: joints ``[...]`` (rad) or a pose ``p[...]``."""
    return ("p" if move.pose else "") + _vector(move.target)


def move_statement(move: Move, target: str | None = None) -> str:
    """One move as URScript: ``movej([...], a=..., v=..., r=...)``, a pose ``p[...]`` (m, rad),
    ``get_inverse_kin(p[...], qnear=[...])`` for a movej's pose target with ``qnear``;
    ``target``: the target's text instead of its literal value (a variable's name)."""
    text = target_literal(move) if target is None else target
    if move.pose and move.qnear is not None and not move.tool_space:
        text = f"get_inverse_kin({text}, qnear={_vector(move.qnear)})"
    args = [text, f"a={_decimal(move.a)}", f"v={_decimal(move.v)}"]
    if move.t > 0.0 and move.kind != "movep":
        args.append(f"t={_decimal(move.t)}")
    if move.r > 0.0:
        args.append(f"r={_decimal(move.r)}")
    return f"{move.kind}({', '.join(args)})"


def _same_target(a: Move, b: Move) -> bool:
    return a.pose == b.pose and bool(np.array_equal(a.target, b.target))


@dataclass
class _Variable:
    """A named target of the program and the moves that use it."""

    name: str
    line: int  # 0-based index of its assignment
    moves: list[int] = field(default_factory=list)  # indices into program.moves
    read_elsewhere: bool = False


def _variables(program: RobotProgram) -> dict[str, _Variable]:
    """The variables the program's moves take as targets, with the lines assigning them."""
    lines = program.lines
    assigned = {}
    for i, raw in enumerate(lines):
        name = assigned_name(split_comment(raw)[0])
        if name is not None and name not in assigned:
            assigned[name] = i
    found: dict[str, _Variable] = {}
    move_lines = set()
    for k, move in enumerate(program.moves):
        name, _ = target_name(move.text)
        if name is None or name not in assigned:
            continue
        found.setdefault(name, _Variable(name, assigned[name])).moves.append(k)
        move_lines.add(move.line - 1)
    for var in found.values():
        for i, raw in enumerate(lines):
            if i == var.line or (i in move_lines and _uses_as_target(program, i, var.name)):
                continue
            if var.name in identifiers(split_comment(raw)[0]):
                var.read_elsewhere = True
    return found


def _uses_as_target(program: RobotProgram, index: int, name: str) -> bool:
    """Whether the move on line ``index`` (0-based) uses ``name`` as its target and nowhere
    else in the statement."""
    for move in program.moves:
        if move.line - 1 == index:
            target, _ = target_name(move.text)
            rest = identifiers(move.text) - {target}
            return target == name and name not in rest
    return False


def _fresh(name: str, taken: set[str]) -> str:
    """``name_2``, ``name_3``, ...: the first not in ``taken`` (which it joins)."""
    i = 2
    while f"{name}_{i}" in taken:
        i += 1
    taken.add(f"{name}_{i}")
    return f"{name}_{i}"


def _assignment(raw: str, name: str, value: str) -> str:
    """The assignment line ``raw`` of ``name`` with another value (its indentation, ``global``
    or ``local`` and comment kept)."""
    code, comment = split_comment(raw)
    indent = raw[: len(raw) - len(raw.lstrip())]
    prefix = code.split(name, 1)[0]  # '', 'global ' or 'local '
    return f"{indent}{prefix}{name} = {value}" + (f"  {comment}" if comment else "")


def _named_targets(
    program: RobotProgram,
) -> tuple[dict[int, str], dict[int, str], dict[int, list[str]]]:
    """How the moves' variables are written: per move the target's text (a name), the
    assignment lines rewritten (0-based index -> line) and lines added after an assignment (new
    names for a value the variable cannot hold as well). A move goes where its lines say
    unless its target differs from what they say (the lines read again)."""
    lines = program.lines
    moves = program.moves
    as_read = parse_program("\n".join(lines), path=program.path, name=program.name).moves
    taken = set().union(*(identifiers(split_comment(raw)[0]) for raw in lines))
    targets: dict[int, str] = {}
    rewritten: dict[int, str] = {}
    added: dict[int, list[str]] = {}
    for var in _variables(program).values():
        changed = [not _same_target(moves[k], as_read[k]) for k in var.moves]
        if not any(changed):
            targets.update({k: var.name for k in var.moves})
            continue
        values: dict[str, str] = {}  # new value -> its name
        # the name keeps its value where a move still goes there or it is read elsewhere
        name_used = var.read_elsewhere or not all(changed)
        for k, change in zip(var.moves, changed, strict=True):
            if not change:
                targets[k] = var.name
                continue
            value = target_literal(moves[k])
            if value not in values:
                if not name_used:
                    values[value] = var.name
                    rewritten[var.line] = _assignment(lines[var.line], var.name, value)
                    name_used = True
                else:
                    new = _fresh(var.name, taken)
                    values[value] = new
                    indent = lines[var.line][: len(lines[var.line]) - len(lines[var.line].lstrip())]
                    added.setdefault(var.line, []).append(
                        f"{indent}{new} = {value}  # kinergy: {var.name} for line {moves[k].line}"
                    )
            targets[k] = values[value]
    return targets, rewritten, added


def program_script(program: RobotProgram, header: Sequence[str] = ()) -> str:
    """A program read from a file written back with its (changed) moves.

    Every move's line is replaced by :func:`move_statement` (its indentation and comment kept).
    A move whose target was a variable keeps the variable: the variable is assigned the new
    value on its own line (its comment kept) and the move names it; where the moves sharing a
    variable now go to different places, or the variable is read elsewhere, the new values get
    new names (``home_2 = ...``) on lines after it. Every other line (events, I/O, comments)
    stays as it was, and so does a variable whose moves all still go where its line says (the
    lines are read again to tell). ``header`` lines go in as comments after the
    ``def`` line (or at the top). A program built in code (no ``lines``: a task) is written as
    ``def name():`` (its name made a URScript name) with one move per line and its events'
    statements.

    Returns
    -------
    str
        Newline-terminated.
    """
    if not program.lines:
        body = [move_statement(s) if isinstance(s, Move) else s.text for s in program.steps]
        name = "".join(c if c.isalnum() or c == "_" else "_" for c in program.name)
        if not name or not (name[0].isalpha() or name[0] == "_"):
            name = "kinergy_" + name
        return _program(name, header, body)
    targets, rewritten, added = _named_targets(program)
    lines = list(program.lines)
    for index, line in rewritten.items():
        lines[index] = line
    for k, move in enumerate(program.moves):
        old = lines[move.line - 1]
        indent = old[: len(old) - len(old.lstrip())]
        _, comment = split_comment(old)
        statement = move_statement(move, targets.get(k))
        lines[move.line - 1] = indent + statement + (f"  {comment}" if comment else "")
    out: list[str] = []
    for i, line in enumerate(lines):
        out.append(line)
        out.extend(added.get(i, []))
    at = next((i + 1 for i, line in enumerate(out) if line.lstrip().startswith("def ")), 0)
    out[at:at] = _comments(header, "  " if at else "")
    return "\n".join(out) + "\n"


def write_script(path: str | os.PathLike[str], text: str) -> Path:
    """Write a URScript program to ``path`` atomically (no half-written file on failure).

    Raises
    ------
    KinergyError
        ``PATH: cannot write (reason)``.
    """

    def write(fh: IO[Any]) -> None:
        fh.write(text)

    return atomic_write(path, write)


# ---------------------------------------------------------------------------------------------
# servoj: a sampled trajectory streamed at the controller's rate

#: the controller's cycle, s (e-Series: 500 Hz)
SERVO_PERIOD = CONTROLLER_DT


def _servo_steps(t: ArrayLike, q: ArrayLike) -> tuple[Array, Array, float]:
    """The sample times (N,), joint angles (N, 6) and their uniform step, s (at least the
    controller's cycle)."""
    times = np.asarray(t, dtype=float)
    angles = np.asarray(q, dtype=float)
    if times.ndim != 1 or times.size < 2:
        raise KinergyError(f"t: expected shape (N,) with N >= 2, got {times.shape}")
    if angles.shape != (times.size, 6):
        raise KinergyError(
            f"q: expected shape ({times.size}, 6) (URScript joint vectors have 6 entries), "
            f"got {angles.shape}"
        )
    if not (np.all(np.isfinite(times)) and np.all(np.isfinite(angles))):
        raise KinergyError("t and q must be finite")
    steps = np.diff(times)
    dt = float(np.mean(steps))
    if np.any(np.abs(steps - dt) > 1e-6):
        k = int(np.argmax(np.abs(steps - dt)))
        raise KinergyError(
            f"t: servoj needs uniform steps; step {k + 1} is {steps[k]:.6g} s, the mean {dt:.6g} s"
        )
    if dt < SERVO_PERIOD - 1e-9:
        raise KinergyError(
            f"t: steps of {dt:.6g} s are shorter than the controller's cycle ({SERVO_PERIOD} s)"
        )
    return times, angles, dt


def _check_servo(
    start_speed: float, start_acceleration: float, lookahead_time: float, gain: float
) -> None:
    number(start_speed, "start_speed", gt=0.0)
    number(start_acceleration, "start_acceleration", gt=0.0)
    number(lookahead_time, "lookahead_time", ge=0.03, le=0.2)
    number(gain, "gain", ge=100.0, le=2000.0)


def servoj_program(
    t: ArrayLike,
    q: ArrayLike,
    *,
    name: str = "kinergy_excitation",
    start_speed: float = 0.5,
    start_acceleration: float = 1.0,
    lookahead_time: float = 0.1,
    gain: float = 300.0,
    comments: Sequence[str] = (),
) -> str:
    """A URScript program that runs a sampled joint trajectory with ``servoj``.

    The program first moves to ``q[0]`` with ``movej`` at ``start_speed`` and
    ``start_acceleration`` (not part of the timed motion), then commands every sample in turn with
    ``servoj(q_k, 0, 0, dt, lookahead_time, gain)``, which blocks for ``dt`` (the samples' step,
    normally the controller's 2 ms), so sample ``k`` is the target at time ``k * dt`` and the
    motion runs at the controller's rate, and finally brakes with ``stopj``.

    Structure: one ``servoj`` line per sample inside ``def name(): ... end``. This is valid on
    every URScript version (CB3 3.x and e-Series 5.x) because it needs no nested lists (list
    literals of lists and their size limits differ between versions) and does no interpreter work
    between two samples, so no cycle is missed. The cost is size, about 115 bytes per sample
    (10 s at 500 Hz are 5000 lines, some 0.6 MB), which UR controllers load and run.

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times, s: uniform steps of at least :data:`SERVO_PERIOD` (the controller's cycle).
    q : array_like, shape (N, 6)
        Joint angles, rad (URScript's joint vectors have 6 entries).
    name : str
        The program's name (``def name():``).
    start_speed, start_acceleration : float
        ``movej``'s ``v`` (rad/s) and ``a`` (rad/s^2) to the first sample, > 0; ``a`` is also
        the ``stopj`` deceleration at the end.
    lookahead_time : float
        ``servoj``'s look-ahead, s, in [0.03, 0.2] (UR's range).
    gain : float
        ``servoj``'s proportional gain, in [100, 2000] (UR's range).
    comments : sequence of str
        More comment lines for the header.

    Returns
    -------
    str
        ``def name():`` ... ``end``, newline-terminated.

    Raises
    ------
    KinergyError
        Shapes, non-uniform or too short steps, settings out of range.

    Examples
    --------
    >>> text = servoj_program([0.0, 0.002], [[0, 0, 0, 0, 0, 0], [0.001, 0, 0, 0, 0, 0]])
    >>> text.splitlines()[-3].strip()
    'servoj([0.001, 0, 0, 0, 0, 0], 0, 0, 0.002, 0.1, 300)'
    """
    times, angles, dt = _servo_steps(t, q)
    _check_servo(start_speed, start_acceleration, lookahead_time, gain)
    tail = f", 0, 0, {_num(dt)}, {_num(lookahead_time)}, {_num(gain)})"
    header = [
        "written by kinergy: a servoj program, joint angles in rad",
        f"{times.size} samples every {_num(dt)} s ({times[-1] - times[0]:.3f} s), one servoj each",
        "servoj(q, a, v, t, lookahead_time, gain): a and v are unused by the controller",
        *(str(c) for c in comments),
    ]
    body = [
        "# the start pose (not part of the timed motion)",
        f"movej({_vector(angles[0])}, a={_num(start_acceleration)}, v={_num(start_speed)})",
        "# the motion: sample k at time k * t",
        *(f"servoj({_vector(row)}{tail}" for row in angles),
        f"stopj({_num(start_acceleration)})",
    ]
    return _program(name, header, body)
