"""Reading URScript programs: the subset pick-and-place and palletising programs use.

:func:`read_program` reads a ``.script`` file into a
:class:`kinergy.trajectory.robot_program.RobotProgram`:

- ``def name():`` ... ``end`` around the program (or statements at the top level);
- ``movej``, ``movel``, ``movep`` to a joint target ``[q1, ..., q6]`` (rad), a pose
  ``p[x, y, z, rx, ry, rz]`` (m, rotation vector in rad) or ``get_inverse_kin(p[...], qnear=[...])``,
  with ``a``, ``v``, ``t``, ``r`` by keyword or position (URScript's defaults where not given);
- ``set_tcp(p[...])``, ``set_payload(m[, cog])``, ``set_target_payload(m, cog[, inertia])``,
  ``sleep(t)``, ``sync()``, and the I/O calls (``set_digital_out``,
  ``set_standard_digital_out``, ``set_tool_digital_out``, ``set_configurable_digital_out``,
  analog outputs ...): events at rest, their time fixed;
- variables assigned once from literals (numbers, joint vectors, poses; ``pi``, ``d2r()``,
  ``r2d()`` and the four operations are allowed), with ``global``/``local`` or without;
- any other call (``textmsg``, ``popup``, a gripper's function ...) is kept verbatim as an event of
  0 s, and the program's ``notes`` say so.

Anything else (control flow, functions of poses, a variable assigned twice) is refused with one
line naming the file, the line and what cannot be handled.
"""

from __future__ import annotations

import ast
import math
import os
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from kinergy.errors import KinergyError
from kinergy.files import read_text
from kinergy.model.robot import Payload
from kinergy.trajectory.motion import CONTROLLER_DT
from kinergy.trajectory.robot_program import MOVE_DEFAULTS, Event, Move, RobotProgram, Step

__all__ = [
    "IO_CALLS",
    "assigned_name",
    "identifiers",
    "parse_program",
    "read_program",
    "split_comment",
    "target_name",
]

#: calls that set an output: events at rest, 0 s
IO_CALLS = frozenset(
    {
        "set_digital_out",
        "set_standard_digital_out",
        "set_tool_digital_out",
        "set_configurable_digital_out",
        "set_analog_out",
        "set_standard_analog_out",
        "set_tool_voltage",
        "set_flag",
    }
)

#: the controller's cycle, s: what ``sync()`` waits
_SYNC = CONTROLLER_DT

_CONTROL = re.compile(
    r"^(if|elif|else|while|for|thread|return|halt|break|continue|run|join|kill)\b"
)
_DEF = re.compile(r"^def\s+([A-Za-z_]\w*)\s*\(\s*\)\s*:$")
_ASSIGN = re.compile(r"^(?:(?:global|local)\s+)?([A-Za-z_]\w*)\s*=(?!=)\s*(.+)$")
_CALL = re.compile(r"^([A-Za-z_]\w*)\s*\(.*\)$")

#: positional parameters of each move after the target
_MOVE_ARGS = {
    "movej": ("a", "v", "t", "r"),
    "movel": ("a", "v", "t", "r"),
    "movep": ("a", "v", "r"),
}


@dataclass(frozen=True)
class _Pose:
    """A pose value ``p[...]`` (6 numbers)."""

    values: tuple[float, ...]


@dataclass(frozen=True)
class _Inverse:
    """``get_inverse_kin(pose, qnear)``."""

    pose: _Pose
    qnear: tuple[float, ...] | None


_FUNCTIONS: dict[str, Callable[[float], float]] = {"d2r": math.radians, "r2d": math.degrees}
_OPERATORS: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: lambda x, y: x + y,
    ast.Sub: lambda x, y: x - y,
    ast.Mult: lambda x, y: x * y,
    ast.Div: lambda x, y: x / y,
}


class _Evaluator:
    """Literal values of URScript expressions: numbers, lists, poses, variables."""

    def __init__(self) -> None:
        self.names: dict[str, Any] = {"pi": math.pi}

    def number(self, node: ast.expr) -> float:
        value = self.value(node)
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise KinergyError(f"expected a number, got {ast.unparse(node)!r}")
        return float(value)

    def vector(self, node: ast.expr, what: str) -> tuple[float, ...]:
        value = self.value(node)
        if isinstance(value, _Pose):
            return value.values
        if not isinstance(value, list) or len(value) != 6:
            raise KinergyError(f"{what}: expected 6 numbers, got {ast.unparse(node)!r}")
        return tuple(value)

    def value(self, node: ast.expr) -> Any:
        if isinstance(node, ast.Constant) and isinstance(node.value, int | float | bool | str):
            return node.value
        if isinstance(node, ast.Name):
            if node.id in self.names:
                return self.names[node.id]
            if node.id in ("True", "False"):
                return node.id == "True"
            raise KinergyError(f"unknown variable {node.id!r} (assign it from a literal first)")
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            x = self.number(node.operand)
            return -x if isinstance(node.op, ast.USub) else x
        if isinstance(node, ast.BinOp) and type(node.op) in _OPERATORS:
            return float(_OPERATORS[type(node.op)](self.number(node.left), self.number(node.right)))
        if isinstance(node, ast.List):
            return [self.number(e) for e in node.elts]
        if isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name):
            return self._pose(node)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            return self._call(node)
        raise KinergyError(
            f"cannot evaluate {ast.unparse(node)!r}: only literals, variables assigned once "
            "from literals, pi, d2r(), r2d() and + - * / are read"
        )

    def _pose(self, node: ast.Subscript) -> _Pose:
        if not (isinstance(node.value, ast.Name) and node.value.id == "p"):
            raise KinergyError(f"cannot evaluate {ast.unparse(node)!r}")
        items = node.slice.elts if isinstance(node.slice, ast.Tuple) else [node.slice]
        values = tuple(self.number(e) for e in items)
        if len(values) != 6:
            raise KinergyError(f"a pose needs 6 numbers, got {len(values)}")
        return _Pose(values)

    def _call(self, node: ast.Call) -> Any:
        assert isinstance(node.func, ast.Name)
        name = node.func.id
        if name in _FUNCTIONS and len(node.args) == 1 and not node.keywords:
            return _FUNCTIONS[name](self.number(node.args[0]))
        if name == "get_inverse_kin":
            args = _arguments(node, ("x", "qnear", "maxPositionError", "maxOrientationError"))
            pose = self.value(args["x"]) if "x" in args else None
            if not isinstance(pose, _Pose):
                raise KinergyError("get_inverse_kin: the first argument must be a pose p[...]")
            qnear = self.vector(args["qnear"], "qnear") if "qnear" in args else None
            return _Inverse(pose, qnear)
        raise KinergyError(
            f"{name}() cannot be evaluated: only pi, d2r(), r2d() and get_inverse_kin(p[...], "
            "qnear) are read in values"
        )


def _arguments(node: ast.Call, names: tuple[str, ...]) -> dict[str, ast.expr]:
    """A call's arguments by parameter name (positional in the order of ``names``)."""
    if len(node.args) > len(names):
        raise KinergyError(f"too many arguments: at most {len(names)} ({', '.join(names)})")
    out = dict(zip(names, node.args, strict=False))
    for kw in node.keywords:
        if kw.arg is None or kw.arg not in names:
            raise KinergyError(f"unknown argument {kw.arg!r} (known: {', '.join(names)})")
        if kw.arg in out:
            raise KinergyError(f"argument {kw.arg!r} given twice")
        out[kw.arg] = kw.value
    return out


def split_comment(line: str) -> tuple[str, str]:
    """A line's statement (stripped) and its ``#`` comment (from the ``#``, ``''`` if none),
    ``#`` inside strings not counting."""
    quote = ""
    for i, c in enumerate(line):
        if quote:
            if c == quote:
                quote = ""
        elif c in "\"'":
            quote = c
        elif c == "#":
            return line[:i].strip(), line[i:].rstrip()
    return line.strip(), ""


def _strip_comment(line: str) -> str:
    """The statement of a line without its ``#`` comment (outside strings)."""
    return split_comment(line)[0]


def assigned_name(statement: str) -> str | None:
    """The variable a statement assigns (``[global|local] name = ...``), or None."""
    m = _ASSIGN.match(statement)
    return None if m is None else m.group(1)


def identifiers(statement: str) -> set[str]:
    """The names a statement uses (outside strings), e.g. to tell whether a variable is read."""
    code = re.sub(r"(\"[^\"]*\"|'[^']*')", "", statement)
    return set(re.findall(r"[A-Za-z_]\w*", code))


def target_name(statement: str) -> tuple[str | None, bool]:
    """The variable a move statement's target is (``movej(home, ...)``, or the pose of
    ``get_inverse_kin(pose_name, ...)``), or None for a literal; and whether it is the pose of
    ``get_inverse_kin``."""
    try:
        node = ast.parse(statement, mode="eval").body
    except SyntaxError:
        return None, False
    if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)):
        return None, False
    kind = node.func.id
    if kind not in _MOVE_ARGS:
        return None, False
    try:
        target = _arguments(node, ("pose_or_q", *_MOVE_ARGS[kind])).get("pose_or_q")
    except KinergyError:
        return None, False
    if isinstance(target, ast.Name):
        return target.id, False
    if (
        isinstance(target, ast.Call)
        and isinstance(target.func, ast.Name)
        and target.func.id == "get_inverse_kin"
        and target.args
        and isinstance(target.args[0], ast.Name)
    ):
        return target.args[0].id, True
    return None, False


class _Reader:
    """State while reading one program: variables, TCP, steps, notes."""

    def __init__(self) -> None:
        self.values = _Evaluator()
        self.assigned: dict[str, int] = {}
        self.steps: list[Step] = []
        self.notes: list[str] = []
        self.name = ""
        self.depth = 0

    def statement(self, text: str, line: int) -> None:
        """Read one statement (comment removed, not empty)."""
        if (m := _DEF.match(text)) is not None:
            if self.depth:
                raise KinergyError("a function inside the program cannot be read")
            self.depth, self.name = 1, self.name or m.group(1)
            return
        if text == "end":
            if not self.depth:
                raise KinergyError("'end' without 'def'")
            self.depth = 0
            return
        if (m := _CONTROL.match(text)) is not None:
            raise KinergyError(f"control flow ({m.group(1)}) cannot be simulated")
        if (m := _ASSIGN.match(text)) is not None:
            self._assign(m.group(1), m.group(2), line)
            return
        if _CALL.match(text) is not None:
            self._call(text, line)
            return
        raise KinergyError(f"cannot read {text!r}")

    def _assign(self, name: str, expr: str, line: int) -> None:
        if name in self.assigned:
            raise KinergyError(
                f"{name} is assigned again (first on line {self.assigned[name]}): only variables "
                "assigned once are read"
            )
        self.values.names[name] = self.values.value(_parse(expr))
        self.assigned[name] = line

    def _call(self, text: str, line: int) -> None:
        node = _parse(text)
        assert isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
        name = node.func.id
        if name in MOVE_DEFAULTS:
            self.steps.append(self._move(name, node, text, line))
        elif name == "sleep":
            args = _arguments(node, ("t",))
            if "t" not in args:
                raise KinergyError("sleep: the time is missing")
            duration = self.values.number(args["t"])
            if not 0.0 <= duration <= 3600.0:  # an hour: longer is a typo, and overflows the plan
                raise KinergyError(f"sleep: the time must be from 0 to 3600 s, got {duration:g}")
            self.steps.append(Event("sleep", duration, line, text))
        elif name == "sync":
            self.steps.append(Event("sync", _SYNC, line, text))
        elif name == "set_tcp":
            args = _arguments(node, ("pose", "tcp_name"))
            tcp = self.values.vector(args["pose"], "set_tcp") if "pose" in args else None
            if tcp is None:
                raise KinergyError("set_tcp: the pose is missing")
            self.steps.append(Event("tcp", 0.0, line, text, tcp=np.array(tcp)))
        elif name in ("set_payload", "set_target_payload", "set_payload_mass"):
            self.steps.append(Event("payload", 0.0, line, text, payload=self._payload(node)))
        elif name in IO_CALLS:
            self.steps.append(Event("io", 0.0, line, text))
        else:
            self.steps.append(Event("other", 0.0, line, text))
            self.notes.append(f"line {line}: {name}() kept verbatim as an event of 0 s at rest")

    def _payload(self, node: ast.Call) -> Payload:
        args = _arguments(node, ("m", "cog", "inertia", "transition_time"))
        if "m" not in args:
            raise KinergyError("the payload mass is missing")
        mass = self.values.number(args["m"])
        cog = np.zeros(3)
        if "cog" in args:
            value = self.values.value(args["cog"])
            if not isinstance(value, list) or len(value) != 3:
                raise KinergyError("the payload's centre of gravity must be 3 numbers [x, y, z]")
            cog = np.array(value)
        return Payload(mass=mass, com=cog)

    def _move(self, kind: str, node: ast.Call, text: str, line: int) -> Move:
        args = _arguments(node, ("pose_or_q", *_MOVE_ARGS[kind]))
        if "pose_or_q" not in args:
            raise KinergyError(f"{kind}: the target is missing")
        target = self.values.value(args["pose_or_q"])
        a, v = MOVE_DEFAULTS[kind]
        settings = {"a": a, "v": v, "t": 0.0, "r": 0.0}
        for key in _MOVE_ARGS[kind]:
            if key in args:
                settings[key] = self.values.number(args[key])
        qnear = None
        if isinstance(target, _Inverse):
            qnear = None if target.qnear is None else np.array(target.qnear)
            target = target.pose
        if isinstance(target, _Pose):
            values, pose = np.array(target.values), True
        elif isinstance(target, list) and len(target) == 6:
            values, pose = np.array(target, dtype=float), False
        else:
            raise KinergyError(
                f"{kind}: the target must be 6 joint angles [...] or a pose p[...], got "
                f"{ast.unparse(args['pose_or_q'])!r}"
            )
        return Move(kind, values, pose, qnear=qnear, line=line, text=text, **settings)


def _parse(text: str) -> ast.expr:
    try:
        return ast.parse(text, mode="eval").body
    except SyntaxError:
        raise KinergyError(f"cannot read {text!r}") from None


def parse_program(text: str, *, path: str = "", name: str = "program") -> RobotProgram:
    """Read URScript source (see the module docstring).

    Parameters
    ----------
    text : str
        The program.
    path : str
        The file it came from, for messages.
    name : str
        The program's name when it has no ``def``.

    Raises
    ------
    KinergyError
        ``FILE:LINE: what cannot be handled``, one line.
    """
    reader = _Reader()
    lines = text.splitlines()
    for number, raw in enumerate(lines, start=1):
        statement = _strip_comment(raw)
        if not statement:
            continue
        try:
            reader.statement(statement, number)
        except KinergyError as exc:
            where = f"{path}:{number}" if path else f"line {number}"
            raise exc.prefixed(where) from None
    if reader.depth:
        raise KinergyError(f"{path or name}: 'def' without 'end'")
    return RobotProgram(  # names its path itself when it refuses (no move)
        name=reader.name or name,
        steps=tuple(reader.steps),
        path=path,
        lines=tuple(lines),
        notes=tuple(reader.notes),
    )


def read_program(path: str | os.PathLike[str]) -> RobotProgram:
    """Read a URScript program file (see the module docstring).

    Raises
    ------
    KinergyError
        The file cannot be read, or ``FILE:LINE: what cannot be handled``.
    """
    p = Path(path)
    text = read_text(p, "the program")
    return parse_program(text, path=str(p), name=p.stem)
