"""What every command shares: the text table, number formats, the common options, the files a
command writes (:func:`writes`), progress."""

from __future__ import annotations

import contextlib
import enum
import functools
import hashlib
import textwrap
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any, TypeVar

import click
import numpy as np
from rich.console import Console
from rich.progress import (
    BarColumn,
    Progress,
    ProgressColumn,
    SpinnerColumn,
    Task,
    TaskID,
    TextColumn,
    TimeElapsedColumn,
)
from rich.text import Text

from kinergy._version import __version__
from kinergy.checks import choice
from kinergy.cli.app import NOTES, QUIET
from kinergy.errors import KinergyError
from kinergy.files import check_folder, check_outputs, check_parent, check_replaceable
from kinergy.io.formats import NOT_LOGS
from kinergy.io.rosbag import Effort
from kinergy.jsonable import dumps, to_jsonable
from kinergy.logs.checks import Check
from kinergy.logs.reading import MAX_CUTOFF, InputLogs, LogReading
from kinergy.messages import Say, silent
from kinergy.model import Robot, load_robot, parse_payload

__all__ = [
    "TABLE_WIDTH",
    "as_usage",
    "choice_of",
    "flag_of",
    "fmt",
    "fmt_vector",
    "json_result",
    "load",
    "log_output",
    "note",
    "output_file_option",
    "payload_option",
    "print_tables",
    "progress",
    "reading_options",
    "refuse_together",
    "report_folder_option",
    "seed_option",
    "swapped",
    "table",
    "tell",
    "warn",
    "writes",
]

F = TypeVar("F", bound=Callable[..., Any])


#: the widest line :func:`table` prints, characters
TABLE_WIDTH = 120


def prose(text: str, width: int = TABLE_WIDTH) -> str:
    """Each line of ``text`` wrapped to ``width`` characters, its continuation lines indented
    two more than its own (the tables' width, so a report reads in one column)."""
    out = []
    for line in text.split("\n"):
        if len(line) <= width:
            out.append(line)
            continue
        lead = " " * (len(line) - len(line.lstrip(" ")))
        out.append(
            textwrap.fill(line.strip(), width, initial_indent=lead, subsequent_indent=lead + "  ")
        )
    return "\n".join(out)


def table(headers: Sequence[str], rows: Sequence[Sequence[Any]], width: int = TABLE_WIDTH) -> str:
    """Left-aligned text columns, two spaces apart (the one table printer of the CLI), no line
    longer than ``width`` characters.

    A table wider than that is printed as blocks of its columns, one under the other (a blank
    line between), each led by the first column, the row's name; a cell that would not fit even
    so is wrapped onto more lines of its row.
    """
    cells = [[str(x) for x in row] for row in [headers, *rows]]
    widths = [max(len(row[k]) for row in cells) for k in range(len(headers))]
    key = min(widths[0], width // 3)
    most = max(1, width - key - 2)  # the widest any other column may be
    widths = [key] + [min(w, most) for w in widths[1:]]
    blocks: list[list[int]] = []
    for k in range(1, len(widths)):
        if blocks and sum(widths[i] + 2 for i in blocks[-1]) + widths[k] <= width:
            blocks[-1].append(k)
        else:
            blocks.append([0, k])
    return "\n\n".join(_table_block(cells, widths, block) for block in blocks or [[0]])


def _table_block(cells: list[list[str]], widths: list[int], columns: list[int]) -> str:
    """The ``columns`` of ``cells`` as text lines, each cell wrapped to its column's width."""
    lines = []
    for row in cells:
        wrapped = [_wrap(row[k], widths[k]) for k in columns]
        for i in range(max(len(w) for w in wrapped)):
            parts = [
                (w[i] if i < len(w) else "").ljust(widths[k])
                for w, k in zip(wrapped, columns, strict=True)
            ]
            lines.append("  ".join(parts).rstrip())
    return "\n".join(lines)


def _wrap(text: str, width: int) -> list[str]:
    """``text`` as lines of at most ``width`` characters (whole words where they fit)."""
    if len(text) <= width:
        return [text]
    return textwrap.wrap(text, width, break_on_hyphens=False) or [""]


def fmt(x: float) -> str:
    """A number to 6 significant digits."""
    return f"{x:.6g}"


def fmt_vector(v: Any) -> str:
    """``[a, b, c]`` with :func:`fmt` numbers."""
    return "[" + ", ".join(fmt(float(x)) for x in np.asarray(v)) + "]"


#: suffixes of logs (a model file is never one of them)
_LOG_SUFFIXES = (".csv", ".txt", ".mcap", ".db3", ".log")
#: suffixes of robot files (a log is never one of them)
_MODEL_SUFFIXES = (".toml", ".urdf", ".json")


def swapped(model: str, logs: Sequence[str]) -> None:
    """Refuse, in one line, MODEL and LOG given in each other's place (``validate LOG.csv
    model.toml``): the model names a log (by its suffix, or a folder: a bag) and a log names a
    robot file."""
    is_log = Path(model).suffix.lower() in _LOG_SUFFIXES or Path(model).is_dir()
    robot_file = next((x for x in logs if Path(x).suffix.lower() in _MODEL_SUFFIXES), None)
    if is_log and robot_file is not None:
        command = click.get_current_context().command_path
        raise KinergyError(
            f"MODEL {model} looks like a log and LOG {robot_file} like a robot file: the "
            f"arguments are swapped; the model comes first: {command} {robot_file} {model}"
        )


def load(robot_name: str, payload: str | None) -> Robot:
    """The robot called ``robot_name`` (built-in or file), with ``--payload`` if given."""
    return load_robot(robot_name, payload=None if payload is None else parse_payload(payload))


#: ``--payload``'s value, as :func:`kinergy.model.toml.parse_payload` reads it
PAYLOAD_METAVAR = "MASS[,CX,CY,CZ[,IXX,IYY,IZZ,IXY,IYZ,IXZ]]"

payload_option = click.option(
    "--payload",
    metavar=PAYLOAD_METAVAR,
    help="Payload at the flange (replaces the model's): kg, m (flange frame), kg m² about its "
    "centre of mass.",
)


def output_file_option(
    flag: str,
    help: str,
    *,
    dest: str | None = None,
    metavar: str | None = None,
    required: bool = False,
) -> Callable[[F], F]:
    """An option naming a file the command writes (``--out``, ``--urscript``): a path that is
    not a folder, None when not given, passed as ``dest`` (default: the flag's name); list it in
    :func:`writes` ``files`` too."""
    names = (flag,) if dest is None else (flag, dest)
    return click.option(
        *names, type=click.Path(dir_okay=False), metavar=metavar, required=required, help=help
    )


def report_folder_option(contents: str = "the figures") -> Callable[[F], F]:
    """``--out FOLDER`` of a command that writes ``contents`` and a report.html there
    (:func:`kinergy.files.output_folder`: a new temporary folder when not given)."""
    return click.option(
        "--out",
        "out",
        type=click.Path(file_okay=False),
        default=None,
        help=f"Folder for {contents} and report.html [a new folder in the system's temporary "
        "folder; its path is printed].",
    )


class EnumChoice(click.Choice):
    """A click choice of the members of an enum, by their values (``--method full``), given to
    the command as the member (``Method.FULL``)."""

    def __init__(self, kind: type[enum.Enum]) -> None:
        super().__init__([str(member.value) for member in kind])
        self.kind = kind

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        if isinstance(value, self.kind):
            return value
        name = super().convert(value, param, ctx)  # a name not of the enum: a usage error
        return choice(name, self.kind, param.get_error_hint(ctx) if param and ctx else "value")


def choice_of(kind: type[enum.Enum]) -> EnumChoice:
    """The click type of an option whose values are those of enum ``kind``."""
    return EnumChoice(kind)


@contextlib.contextmanager
def as_usage() -> Iterator[None]:
    """Options built from a command's flags: a value the option's type refuses on construction
    (one line naming the flag, as the Python API gives it) is a usage error, exit status 2."""
    try:
        yield
    except KinergyError as exc:
        raise click.UsageError(str(exc)) from None


#: the flag of each parameter of :meth:`LogReading.parse`: how every command reads its logs
_READING_FLAGS: dict[str, Callable[[Any], Any]] = {
    "columns": click.option(
        "--columns",
        metavar="SPEC",
        help="Layout of a headerless log: UR's RTDE field names, NAME:N for an N-vector, _ (or "
        '_:N) for columns to skip, e.g. "timestamp,actual_q:6,actual_qd:6,actual_current:6"; or '
        "a header log's own names mapped to RTDE fields, FIELD=COLUMN with * for a vector's "
        'index, e.g. "timestamp=time,actual_q=positions_*" (_=COLUMN leaves a column unread). A '
        "header's columns that are no RTDE field are ignored (a note names them).",
    ),
    "repair": click.option(
        "--repair",
        is_flag=True,
        help="Drop malformed rows (cut short, non-numeric, time out of order) instead of "
        "rejecting.",
    ),
    "cutoff": click.option(
        "--cutoff",
        type=float,
        default=None,
        help=f"Low-pass cutoff for measured speeds, Hz (> 0, <= {MAX_CUTOFF:g}) [min(10, fs/5)].",
    ),
    "accept": click.option(
        "--accept",
        "accept",
        multiple=True,
        metavar="CHECK",
        help="Go on although this check fails (repeatable; recorded in the result): "
        + ", ".join(c.value for c in Check)
        + ", or all.",
    ),
    "topic": click.option(
        "--topic",
        metavar="TOPIC",
        default=None,
        help="ROS 2 bags: the sensor_msgs/JointState topic [/joint_states].",
    ),
    "effort": click.option(
        "--effort",
        type=choice_of(Effort),
        default=None,
        help="ROS 2 bags: what JointState effort holds, motor currents (A) or joint torques "
        "(N m) [current for UR arms, as UR's driver publishes by default; torque for others].",
    ),
    "payload": click.option(
        "--payload",
        metavar=PAYLOAD_METAVAR,
        help="Payload at the flange: kg, m (flange frame), kg m² about its centre of mass. It "
        "replaces the model's and the one a log's controller logged (payload, payload_cog, "
        "payload_inertia), which is used otherwise.",
    ),
    "start": click.option(
        "--from",
        "start",
        type=float,
        default=None,
        metavar="S",
        help="Read each log from this time (s, on the log's own time axis) [its start].",
    ),
    "stop": click.option(
        "--to",
        "stop",
        type=float,
        default=None,
        metavar="S",
        help="Read each log up to this time (s, on the log's own time axis: its timestamp "
        "column; a ROS 2 bag's from its first message) [its end].",
    ),
}


def reading_options(*names: str) -> Callable[[F], F]:
    """The log-reading flags, one per parameter of :meth:`LogReading.parse` (``names``: those
    the command takes; default all), parsed there into one :class:`LogReading` that the command
    receives as ``reading``."""
    wanted = names or tuple(_READING_FLAGS)

    def decorate(command: F) -> F:
        @functools.wraps(command)
        def parsed(**kwargs: Any) -> Any:
            flags = {name: kwargs.pop(name) for name in wanted}
            with as_usage():
                reading = LogReading.parse(**flags)
            return command(reading=reading, **kwargs)

        for name in reversed(wanted):
            parsed = _READING_FLAGS[name](parsed)
        return parsed  # type: ignore[return-value]

    return decorate


seed_option = click.option(
    "--seed",
    type=int,
    default=0,
    show_default=True,
    help="Seed of the random generator (0 to 2^32-1).",
)


def flag_of(command: click.Command, name: str) -> str:
    """The flag (``--out``) or metavar (``LOG...``) of the parameter called ``name``."""
    for param in command.params:
        if param.name == name:
            if isinstance(param, click.Option):
                return max(param.opts, key=len)
            return param.human_readable_name
    raise KeyError(name)  # a command declared a parameter it does not have: a programming error


def _given(value: Any) -> list[str]:
    """A parameter's value as a list of the paths it names (None: none; a tuple: several)."""
    if value is None:
        return []
    return [str(v) for v in value] if isinstance(value, tuple | list) else [str(value)]


def log_output(flag: str, path: str) -> None:
    """Refuse a log (CSV) to be written under a name that says it is something else (a robot or
    task file, a URDF, a program, an image): ``--out model.toml`` would replace a model with a
    log."""
    what = NOT_LOGS.get(Path(path).suffix.lower())
    if what is not None:
        raise KinergyError(f"{flag} {path}: a log is written there, but the name says {what}")


def refuse_together(*pairs: tuple[str, str, str]) -> None:
    """Refuse, in one line naming both flags, two options given together on the command line
    that contradict each other (a usage error): each pair is (parameter, parameter, why)."""
    ctx = click.get_current_context()

    def given(name: str) -> bool:
        return ctx.get_parameter_source(name) is click.core.ParameterSource.COMMANDLINE

    for a, b, why in pairs:
        if given(a) and given(b):
            raise click.UsageError(
                f"{flag_of(ctx.command, a)} and {flag_of(ctx.command, b)} together: {why}"
            )


def _within(path: Path, folder: Path) -> bool:
    """Whether ``path`` is ``folder`` or lies below it (links resolved)."""
    return path.resolve().is_relative_to(folder.resolve())


def writes(
    *,
    files: Sequence[str] = (),
    folders: Sequence[str] = (),
    into: Sequence[str] = (),
    inputs: Sequence[str] = (),
) -> Callable[[F], F]:
    """Declare what a command writes and reads, by parameter name; before the command does any
    work, refuse (one line naming the flag) an output that is an input or another output, an
    existing output that is not a regular file or that kinergy did not write
    (:func:`kinergy.files.check_replaceable`), and a folder
    of outputs holding files kinergy did not write (:func:`kinergy.files.check_folder`) or an
    input (it is replaced whole).
    ``into``: folders the command adds files to (only checked against the inputs and outputs).

    Inputs that are not existing files (built-in names such as ``ur5e``, ``test-a``) are skipped.
    Put it right above the function, below the click options.
    """

    def decorate(command: F) -> F:
        @functools.wraps(command)
        def checked(**kwargs: Any) -> Any:
            cmd = click.get_current_context().command
            outputs = [
                (flag_of(cmd, name), path)
                for name in (*files, *folders, *into)
                for path in _given(kwargs[name])
            ]
            for flag, path in outputs:
                if not path.strip():
                    raise KinergyError(f"{flag}: an empty path names no file or folder")
            sources = [p for name in inputs for p in _given(kwargs[name]) if Path(p).exists()]
            check_outputs(outputs, [p for p in sources if Path(p).is_file()])
            for name in folders:  # a folder of outputs is replaced whole: no input inside it
                for folder in _given(kwargs[name]):
                    inside = [p for p in sources if _within(Path(p), Path(folder))]
                    if inside:
                        raise KinergyError(
                            f"{flag_of(cmd, name)} {folder}: holds an input ({inside[0]}), which "
                            "replacing the folder would delete; choose another folder"
                        )
            for name, check in (
                [(n, check_replaceable) for n in files]
                + [(n, check_folder) for n in folders]
                + [(n, check_parent) for n in into]
            ):
                for path in _given(kwargs[name]):
                    try:
                        check(path)
                    except KinergyError as exc:
                        raise exc.prefixed(flag_of(cmd, name)) from None
            return command(**kwargs)

        checked.kinergy_inputs = tuple(inputs)  # type: ignore[attr-defined]
        return checked  # type: ignore[return-value]

    return decorate


class _Parts(ProgressColumn):
    """``k/n`` and the time left (rich's estimate) of a step of parts; nothing for a plain
    step."""

    def render(self, task: Task) -> Text:
        if not task.fields.get("parts") or task.total is None:
            return Text("")
        left = task.time_remaining
        clock = "" if left is None else f", {int(left) // 60}:{int(left) % 60:02d} left"
        return Text(f"{task.completed:.0f}/{task.total:.0f}{clock}")


@contextlib.contextmanager
def progress(*, quiet: bool = False) -> Iterator[Say]:
    """A progress display on stderr for the steps of a long command
    (:class:`kinergy.messages.Say`): ``say(message)`` starts a step (a spinner and its running
    time) and ends the one before; ``say(message, done=k, total=n)`` shows a step of ``n``
    parts as a bar with ``k/n`` and the time left (rich's estimate from the parts done so far),
    the same step advanced while ``n`` stays.

    Silent when stderr is not a terminal, with ``quiet``, or with the global ``--quiet``.
    """
    ctx = click.get_current_context(silent=True)
    console = Console(stderr=True)
    if quiet or (ctx is not None and ctx.meta.get(QUIET)) or not console.is_terminal:
        yield silent
        return
    columns = (
        SpinnerColumn(),
        TextColumn("{task.description}"),
        BarColumn(bar_width=24),
        TimeElapsedColumn(),
        _Parts(),
    )
    with Progress(*columns, console=console) as bar:
        current: list[tuple[TaskID, int | None]] = []

        def end() -> None:
            if current:
                task, total = current[-1]
                bar.update(task, total=total or 1, completed=total or 1)

        def say(message: str, *, done: int | None = None, total: int | None = None) -> None:
            if total is not None and current and current[-1][1] == total:
                bar.update(current[-1][0], description=message, completed=done or 0)
                return
            end()
            task = bar.add_task(message, total=total, completed=done or 0, parts=total is not None)
            current.append((task, total))

        try:
            yield say
        finally:
            end()


def _say(level: str, message: str) -> None:
    ctx = click.get_current_context(silent=True)
    held = ctx.find_object(dict) if ctx is not None else None
    if held is not None and NOTES in held:
        held[NOTES].append((level, message))
    elif level != "note" or ctx is None or not ctx.meta.get(QUIET):
        click.echo(f"kinergy: {level}: {message}", err=True)


def note(message: str) -> None:
    """A note for the user on stderr: something routine (what reading a file changed, a value
    written, a default used); ``--quiet`` drops it. Under :func:`kinergy.cli.main` notes and
    warnings are held back and shown when the command succeeds: a refusal stays one line."""
    _say("note", message)


def warn(message: str) -> None:
    """A warning for the user on stderr: something that may make the result wrong (held back as
    :func:`note` is, never dropped)."""
    _say("warning", message)


def tell(notes: Sequence[str], warnings: Sequence[str]) -> None:
    """:func:`note` each of ``notes`` and :func:`warn` each of ``warnings``."""
    for text in notes:
        note(text)
    for text in warnings:
        warn(text)


def _file_record(path: str) -> dict[str, Any]:
    """``path``, ``sha256``, ``size`` (bytes) of an input file."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        while block := fh.read(1 << 23):
            digest.update(block)
    return {"path": path, "sha256": digest.hexdigest(), "size": Path(path).stat().st_size}


def _plain(value: Any) -> Any:
    """An option's value as JSON holds it (enums as their names' values, tuples as lists)."""
    if isinstance(value, enum.Enum):
        return value.value
    if isinstance(value, tuple | list):
        return [_plain(v) for v in value]
    return value


def json_result(result: Any) -> str:
    """``--json`` of a command: ``result.to_dict()`` (a result of :mod:`kinergy.api`; plain data
    as it is) with where it came from: ``kinergy`` (``version``, ``command``, the command's
    ``options`` as given) and ``inputs`` (every input file by content: ``path``, ``sha256``,
    ``size``; a log also ``rows`` and its ``checks``, from the result's ``inputs``). A result
    that is a list is printed as it is."""
    inputs = getattr(result, "inputs", None)
    inputs = inputs if isinstance(inputs, InputLogs) else None
    result = result.to_dict() if hasattr(result, "to_dict") else result
    out = to_jsonable(result)
    if not isinstance(out, dict):  # a list (robot list): nothing to record beside it
        return dumps(out)
    ctx = click.get_current_context()
    logs = {r["path"]: r for r in (inputs.records() if inputs is not None else [])}
    files: list[dict[str, Any]] = []
    declared = getattr(ctx.command.callback, "kinergy_inputs", ())
    for name in declared:
        for path in _given(ctx.params.get(name)):
            if path in logs:
                files.append(logs.pop(path))
            elif Path(path).is_file():
                files.append(_file_record(path))
    files += logs.values()
    types = {p.name: p.type for p in ctx.command.params}
    options = {
        k: _plain(getattr(types.get(k), "shown", lambda v: v)(v))  # a type's word for a value
        for k, v in ctx.params.items()
        if k != "as_json"
    }
    out["kinergy"] = {"version": __version__, "command": ctx.command_path, "options": options}
    out["inputs"] = files
    return dumps(out)


def print_tables(tables: Mapping[str, Sequence[Any]], keys: Sequence[str]) -> None:
    """Print the report tables under ``keys`` (:class:`kinergy.report.html.Table`) as text."""
    for key in keys:
        for t in tables.get(key, []):
            click.echo(f"\n{textwrap.fill(t.caption, TABLE_WIDTH)}")
            click.echo(table(t.headers, t.rows))
            if t.note:
                click.echo(textwrap.fill(t.note, TABLE_WIDTH))
