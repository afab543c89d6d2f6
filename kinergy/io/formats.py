"""The registry of log formats: each a name, a sniff (is this file mine?) and a chunked reader.

Adding a format is one module under ``kinergy/io`` that calls :func:`register` at import and is
named in ``_MODULES``; :func:`iter_log` and :func:`read_log` ask each format in turn, UR's
``record.py`` layout (:mod:`kinergy.io.rtde`) last, as it takes any delimited text.

A log can be a folder too (a rosbag2 folder, the panda-gaz layout): only the formats that read
folders (``LogFormat.folders``) are asked about one. A format whose reader needs the robot's joint
names (a ROS 2 bag names its joints; :mod:`kinergy.io.rosbag`) takes them as ``joints=``, with
the bag's options (:class:`kinergy.io.rosbag.BagOptions`) as ``bag=``.

Examples
--------
>>> [f.name for f in formats()]
['rosbag', 'panda', 'rtde']
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from kinergy.errors import KinergyError
from kinergy.io.columns import Columns, parse_column_spec
from kinergy.io.log import Log

if TYPE_CHECKING:  # the bag options live with the bag reader, which registers itself here
    from kinergy.io.rosbag import BagOptions

__all__ = ["CHUNK_ROWS", "NOT_LOGS", "LogFormat", "formats", "iter_log", "read_log", "register"]

#: rows per chunk of :func:`iter_log`: 100 s of a 500 Hz log, about 30 MB of 40 columns
CHUNK_ROWS = 50_000

#: the modules that register a format, asked in this order
_MODULES = ("kinergy.io.rosbag", "kinergy.io.panda_layout", "kinergy.io.rtde")


@dataclass(frozen=True)
class LogFormat:
    """A log format.

    Attributes
    ----------
    name : str
    sniff : callable (Path, str) -> bool
        Whether a file, given its path and first line, is in this format (a folder: given its
        path and ``""``).
    chunks : callable
        ``chunks(path, columns=, repair=, select=, rows=)`` -> iterator of :class:`Log` of at
        most ``rows`` samples each, time stamps in s.
    folders : bool
        Whether a log in this format can be a folder (then ``sniff`` is asked about folders).
    joints : bool
        Whether ``chunks`` also takes ``joints=`` (the robot's joint names, in the robot's
        order, or None) and ``bag=`` (:class:`kinergy.io.rosbag.BagOptions` or None).
    """

    name: str
    sniff: Callable[[Path, str], bool]
    chunks: Callable[..., Iterator[Log]]
    folders: bool = False
    joints: bool = False


_REGISTRY: dict[str, LogFormat] = {}


def register(fmt: LogFormat) -> LogFormat:
    """Add ``fmt`` to the registry (a format of the same name is replaced); return it."""
    _REGISTRY[fmt.name] = fmt
    return fmt


def formats() -> list[LogFormat]:
    """Every registered format, in the order they are asked: formats registered by other code
    first (in the order registered), then those of ``_MODULES`` in its order, whichever module
    was imported first (UR's record.py layout, which takes any text, stays last)."""
    for module in _MODULES:
        importlib.import_module(module)

    def rank(fmt: LogFormat) -> int:
        module = getattr(fmt.chunks, "__module__", "")
        return _MODULES.index(module) if module in _MODULES else -1

    return sorted(_REGISTRY.values(), key=rank)


def _format_of(path: Path, name: str | None) -> LogFormat:
    known = formats()
    if name is not None:
        for fmt in known:
            if fmt.name == name:
                return fmt
        raise KinergyError(
            f"unknown log format {name!r}; known: {', '.join(f.name for f in known)}"
        )
    if path.is_dir():
        folders = [fmt for fmt in known if fmt.folders]
        for fmt in folders:
            if fmt.sniff(path, ""):
                return fmt
        raise KinergyError(
            f"{path}: a folder that is not a log (folders are read as "
            f"{' or '.join(f.name for f in folders)} logs)"
        )
    try:
        with path.open("r", encoding="utf-8-sig", errors="replace") as fh:
            head = fh.readline(1 << 16)
    except OSError as exc:
        raise KinergyError(f"{path}: cannot read log ({exc.strerror})") from None
    for fmt in known:
        if fmt.sniff(path, head):
            return fmt
    raise KinergyError(
        f"{path}: not a log in any known format ({', '.join(f.name for f in known)})"
    )


#: files a log is not, by suffix: what they are
NOT_LOGS = {
    ".toml": "a TOML file (a robot or task file)",
    ".urdf": "a URDF model",
    ".script": "a URScript program",
    ".png": "an image",
}


def iter_log(
    path: str | os.PathLike[str],
    *,
    columns: str | Columns | Sequence[str] | None = None,
    repair: bool = False,
    select: Sequence[str] | None = None,
    rows: int = CHUNK_ROWS,
    format: str | None = None,
    joints: Sequence[str] | None = None,
    bag: BagOptions | None = None,
) -> Iterator[Log]:
    """A log in chunks of at most ``rows`` samples (the whole file is never held, except to
    ``repair`` it or to say what is wrong with it).

    Parameters
    ----------
    path : path
    columns : str, ColumnMap or sequence of str, optional
        The layout of a headerless file: its column spec (``"timestamp,actual_q:6,..."``, parsed
        by :func:`kinergy.io.columns.parse_column_spec`) or the column names it expands to; or
        a header log's names mapped to RTDE's (``"timestamp=time,actual_q=pos_*"``,
        :class:`kinergy.io.columns.ColumnMap`).
    repair : bool
        Drop malformed rows instead of rejecting the file; the first chunk's ``notes`` say
        which.
    select : sequence of str, optional
        The signals to read (default all); the others are never converted.
    rows : int
        The most samples per chunk.
    format : str, optional
        A registered format's name; default the first whose sniff accepts the file.
    joints : sequence of str, optional
        The robot's joint names, in its order: a ROS 2 bag is read with them (its joints are
        matched by name, :mod:`kinergy.io.rosbag`); other formats check their joint count
        against them where they can.
    bag : BagOptions, optional
        A ROS 2 bag's topic and what its ``effort`` holds (default: ``/joint_states``, the
        robot's usual effort); refused for a log that is not a bag.

    Yields
    ------
    Log
        Consecutive chunks; time stamps in s, strictly increasing across chunks.
    """
    if rows < 2:
        raise KinergyError(f"chunks of {rows} rows: need at least 2")
    path = Path(path)
    if path.suffix.lower() in NOT_LOGS and format is None:
        raise KinergyError(
            f"{path}: {NOT_LOGS[path.suffix.lower()]}, not a log; give a log (record.py layout, "
            "a headerless file with --columns, a ROS 2 bag, the panda-gaz layout)"
        )
    if isinstance(columns, str):
        columns = parse_column_spec(columns)
    fmt = _format_of(path, format)
    if not fmt.joints:
        if bag is not None:
            raise KinergyError(
                f"{path}: a {fmt.name} log, not a ROS 2 bag: the bag options (topic, effort) "
                "apply to bags only"
            )
        yield from fmt.chunks(path, columns=columns, repair=repair, select=select, rows=rows)
        return
    yield from fmt.chunks(
        path,
        columns=columns,
        repair=repair,
        select=select,
        rows=rows,
        joints=None if joints is None else tuple(joints),
        bag=bag,
    )


def read_log(
    path: str | os.PathLike[str],
    *,
    columns: str | Columns | Sequence[str] | None = None,
    repair: bool = False,
    select: Sequence[str] | None = None,
    format: str | None = None,
    joints: Sequence[str] | None = None,
    bag: BagOptions | None = None,
) -> Log:
    """A whole log (:func:`iter_log`'s chunks joined; the same keywords)."""
    parts = list(
        iter_log(
            path,
            columns=columns,
            repair=repair,
            select=select,
            format=format,
            joints=joints,
            bag=bag,
        )
    )
    return Log.concatenate(parts)
