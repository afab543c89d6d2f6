"""What every command shares: the text table, number formats, the common options, progress."""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import click
import numpy as np

from kinergy.model import Robot, load_robot, parse_payload

__all__ = [
    "columns_option",
    "fmt",
    "fmt_vector",
    "load",
    "payload_option",
    "print_tables",
    "progress",
    "repair_option",
    "table",
]


def table(headers: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    """Left-aligned text columns, two spaces apart (the one table printer of the CLI)."""
    widths = [max(len(str(x)) for x in col) for col in zip(headers, *rows, strict=False)]
    lines = ["  ".join(str(h).ljust(w) for h, w in zip(headers, widths, strict=True)).rstrip()]
    for row in rows:
        lines.append("  ".join(str(x).ljust(w) for x, w in zip(row, widths, strict=True)).rstrip())
    return "\n".join(lines)


def fmt(x: float) -> str:
    """A number to 6 significant digits."""
    return f"{x:.6g}"


def fmt_vector(v: Any) -> str:
    """``[a, b, c]`` with :func:`fmt` numbers."""
    return "[" + ", ".join(fmt(float(x)) for x in np.asarray(v)) + "]"


def load(robot_name: str, payload: str | None) -> Robot:
    """The robot called ``robot_name`` (built-in or file), with ``--payload`` if given."""
    return load_robot(robot_name, payload=None if payload is None else parse_payload(payload))


payload_option = click.option(
    "--payload",
    metavar="MASS[,CX,CY,CZ[,IXX,IYY,IZZ,IXY,IYZ,IXZ]]",
    help="Payload at the flange (replaces the model's): kg, m (flange frame), kg m^2.",
)
columns_option = click.option(
    "--columns",
    metavar="SPEC",
    help='Layout of a headerless log, e.g. "timestamp,actual_q:6,actual_qd:6,actual_current:6".',
)
repair_option = click.option(
    "--repair",
    is_flag=True,
    help="Drop malformed rows (cut short, non-numeric, time out of order) instead of rejecting.",
)


def progress() -> Callable[[str], None]:
    """A progress callback: each message on stderr with the seconds since it was made."""
    start = time.perf_counter()

    def say(message: str) -> None:
        click.echo(f"[{time.perf_counter() - start:5.1f} s] {message}", err=True)

    return say


def note(message: str) -> None:
    """A note for the user on stderr (what reading a file changed)."""
    click.echo(f"kinergy: note: {message}", err=True)


def print_tables(tables: Mapping[str, Sequence[Any]], keys: Sequence[str]) -> None:
    """Print the report tables under ``keys`` (:class:`kinergy.report.html.Table`) as text."""
    for key in keys:
        for t in tables.get(key, []):
            click.echo(f"\n{t.caption}")
            click.echo(table(t.headers, t.rows))
            if t.note:
                click.echo(t.note)
