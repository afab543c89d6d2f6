"""A log converted to another format: a ROS 2 bag from a log (``kinergy convert LOG --to bag``)
and a log in UR's record.py layout from a bag or any log (``--to csv``).

The log is read chunk by chunk (:func:`kinergy.io.formats.iter_log`) and written as it is read,
never whole. A bag holds the motion and one effort (:mod:`kinergy.io.bag_write`); the log's other
signals are left out and named. From a bag, the CSV's ``timestamp`` is the bag's header stamp in
s (``stamp_ns / 1e9``: a log converted to a bag and back has its time stamps again, bit for bit)
where the stamps are under 10^6 s (a controller's clock, as RTDE's ``timestamp``); stamps since
1970, as ROS drivers write them, would lose a quarter of a microsecond as seconds in a float, so
there the time is written from the first stamp, as kinergy reads a bag (a note says so).
"""

from __future__ import annotations

import enum
import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kinergy.errors import KinergyError
from kinergy.io.bag_write import bag_joint_names, write_bag
from kinergy.io.columns import Columns
from kinergy.io.formats import iter_log
from kinergy.io.log import Log
from kinergy.io.rosbag import BagOptions, first_stamp, is_bag
from kinergy.io.rtde import write_log_chunks

__all__ = ["ABSOLUTE_STAMPS", "Converted", "LogKind", "convert_log"]

#: bag stamps below this (ns, 10^6 s) are written as they are; above it, from the first stamp
ABSOLUTE_STAMPS = 10**15


class LogKind(enum.Enum):
    """What ``convert`` writes."""

    #: a rosbag2 folder, MCAP storage (:mod:`kinergy.io.bag_write`)
    BAG = "bag"
    #: UR's record.py layout (:func:`kinergy.io.rtde.write_log_chunks`)
    CSV = "csv"


@dataclass(frozen=True)
class Converted:
    """What :func:`convert_log` wrote.

    Attributes
    ----------
    path : Path
    kind : LogKind
    rows : int
        Samples written.
    signals : tuple of str
        The signals written (RTDE names; a bag's effort as the signal it came from).
    left_out : tuple of str
        The log's signals the output has no place for.
    notes : tuple of str
        What reading and writing assumed or changed.
    """

    path: Path
    kind: LogKind
    rows: int
    signals: tuple[str, ...]
    left_out: tuple[str, ...]
    notes: tuple[str, ...]


def convert_log(
    source: str | os.PathLike[str],
    out: str | os.PathLike[str],
    to: LogKind,
    joints: tuple[str, ...],
    *,
    columns: Columns | None = None,
    repair: bool = False,
    bag: BagOptions | None = None,
) -> Converted:
    """Convert the log at ``source`` (any log kinergy reads) to a ``to`` log at ``out``.

    Parameters
    ----------
    source, out : path
        ``out`` must not exist (kinergy never replaces a log).
    to : LogKind
    joints : tuple of str
        The robot's joint names, in its order: a bag's joints are matched to them, a bag is
        written with them (:func:`~kinergy.io.bag_write.bag_joint_names`).
    columns : Columns, optional
        The layout of a headerless text log.
    repair : bool
        Drop malformed rows or messages instead of refusing the log.
    bag : BagOptions, optional
        A bag's topic and effort: the bag read (``--to csv``) or written (``--to bag``: its
        ``effort`` says which of the log's signals becomes ``effort``).

    Raises
    ------
    KinergyError
        ``out`` exists, a bad log, a signal asked for that the log lacks.
    """
    target = Path(out)
    if target.exists() or target.is_symlink():
        raise KinergyError(f"{target}: exists; kinergy never replaces it: give a new name")
    notes: list[str] = []
    from_bag = is_bag(Path(source))
    chunks = _noted(
        iter_log(
            source,
            columns=columns,
            repair=repair,
            joints=joints,
            bag=bag if from_bag else None,
        ),
        notes,
    )
    if to is LogKind.BAG:
        topic = bag.topic if bag is not None else BagOptions().topic
        effort = bag.effort if bag is not None else None
        written = write_bag(target, chunks, joints, effort=effort, topic=topic)
        signals = ("actual_q", "actual_qd", *([written.effort] if written.effort else []))
        notes.append(
            f"{target}: {written.messages} JointState messages on {topic}, joints "
            f"{', '.join(bag_joint_names(joints))}; effort: {written.effort or 'none'}"
        )
        return Converted(target, to, written.messages, signals, written.left_out, tuple(notes))
    if from_bag:
        origin = first_stamp(source, bag)
        if origin < ABSOLUTE_STAMPS:
            chunks = (_shifted(c, origin) for c in chunks)
            notes.append(
                f"{target}: timestamp is the bag's header stamps in s, the first at "
                f"{origin / 1e9:.9f} s (a controller's clock, kept as it is)"
            )
        else:
            notes.append(
                f"{target}: timestamp from the bag's first header stamp ({origin} ns): stamps "
                "since 1970 lose a quarter of a microsecond as seconds"
            )
    seen: list[Log] = []
    rows = write_log_chunks(target, _first_kept(chunks, seen))
    signals = tuple(seen[0].signals) if seen else ()
    return Converted(target, to, rows, signals, (), tuple(notes))


def _noted(chunks: Iterator[Log], notes: list[str]) -> Iterator[Log]:
    """``chunks``, their notes added to ``notes``."""
    for chunk in chunks:
        notes.extend(chunk.notes)
        yield chunk


def _first_kept(chunks: Iterator[Log], seen: list[Log]) -> Iterator[Log]:
    """``chunks``, the first one kept in ``seen``."""
    for chunk in chunks:
        if not seen:
            seen.append(chunk)
        yield chunk


def _shifted(chunk: Log, origin: int) -> Log:
    """``chunk`` (time from the first stamp, s) with its time the bag's stamps in s, each
    ``stamp_ns / 1e9`` rounded once (the stamps recovered exactly from ``t * 1e9``)."""
    ns = origin + np.round(chunk.t * 1e9).astype(np.int64)
    return Log(chunk.path, ns / 1e9, chunk.signals, chunk.notes, chunk.ignored)
