"""The panda-gaz layout: a time file beside files of one number per line, n per sample.

Gaz et al.'s Franka Emika Panda excitation run ("Dynamic Identification of the Franka Emika
Panda Robot With Retrieval of Feasible Parameters Using Penalty-Based Optimization", IEEE RA-L
2019) is published as four text files that share a stem::

    exciting_traj_time.txt        one time stamp per line (s), N lines
    exciting_traj_positions.txt   joint positions (rad), n per sample, sample after sample
    exciting_traj_velocity.txt    joint speeds (rad/s), likewise
    exciting_traj_torques.txt     measured joint torques (N m), likewise

so line ``k * n + j`` (from 0) of a value file is joint ``j`` of sample ``k``. A log in this
layout is the folder that holds one such set, or its ``STEM_time.txt`` file; the positions are
``actual_q``, the speeds ``actual_qd`` and the torques ``actual_joint_torque`` (speeds and torques
may be left out; ``position``, ``velocities``, ``torque`` spell them too). Blank lines are
skipped.

Before anything is read, every value file must hold the same whole number of values per time
stamp (the robot's joint count where it is known): one line names a file that does not. Values
must be finite numbers and time stamps increasing (``repair`` drops samples whose stamp is not
after the one before, noted); each problem is one line naming the file and line. The files are
read in step, ``rows`` samples at a time: memory does not grow with the log.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.io.formats import LogFormat, register
from kinergy.io.log import TIME_UNITS, Log, time_unit

__all__ = ["PANDA", "SIGNALS", "is_panda_layout", "panda_files"]

#: the time file's suffix
TIME = "_time.txt"
#: log signal -> the suffixes its file may have (the first is the dataset's)
SIGNALS = {
    "actual_q": ("_positions.txt", "_position.txt"),
    "actual_qd": ("_velocity.txt", "_velocities.txt"),
    "actual_joint_torque": ("_torques.txt", "_torque.txt"),
}


@dataclass(frozen=True)
class PandaFiles:
    """One set of files in the layout: the time file and each signal's file."""

    time: Path
    signals: dict[str, Path]


def _set(time: Path) -> PandaFiles | None:
    """The set whose time file is ``time``; None without a positions file beside it."""
    stem = time.name[: -len(TIME)]
    found = {}
    for signal, suffixes in SIGNALS.items():
        for suffix in suffixes:
            candidate = time.with_name(stem + suffix)
            if candidate.is_file():
                found[signal] = candidate
                break
    return PandaFiles(time, found) if "actual_q" in found else None


def panda_files(path: Path) -> PandaFiles:
    """The files of the log at ``path``: a folder holding one set, or a set's time file.

    Raises
    ------
    KinergyError
        No set, or a folder with several (naming their time files).
    """
    if path.is_dir():
        sets = [s for t in sorted(path.glob("*" + TIME)) if (s := _set(t)) is not None]
        if len(sets) > 1:
            raise KinergyError(
                f"{path}: {len(sets)} logs in the panda-gaz layout here; name one by its time "
                f"file: {', '.join(s.time.name for s in sets)}"
            )
    else:
        sets = [s] if path.name.endswith(TIME) and (s := _set(path)) is not None else []
    if not sets:
        raise KinergyError(
            f"{path}: no STEM{TIME} with a STEM{SIGNALS['actual_q'][0]} beside it (panda-gaz "
            "layout)"
        )
    return sets[0]


def is_panda_layout(path: Path, head: str = "") -> bool:
    """Whether ``path`` is a folder with a time file and a positions file of one stem, or such a
    time file."""
    if path.is_dir():
        return any(_set(t) is not None for t in path.glob("*" + TIME))
    return path.name.endswith(TIME) and _set(path) is not None


def _count(path: Path) -> int:
    """The non-blank lines of a file."""
    try:
        with path.open("rb") as fh:
            return sum(1 for line in fh if line.strip())
    except OSError as exc:
        raise KinergyError(f"{path}: cannot read log ({exc.strerror})") from None


def _numbers(path: Path) -> Iterator[tuple[int, str]]:
    """The non-blank lines of a file with their line numbers (from 1)."""
    try:
        with path.open("r", encoding="utf-8-sig", errors="replace") as fh:
            for number, line in enumerate(fh, start=1):
                if line.strip():
                    yield number, line
    except OSError as exc:
        raise KinergyError(f"{path}: cannot read log ({exc.strerror})") from None


def _values(path: Path, lines: Sequence[tuple[int, str]]) -> Array:
    """The lines' numbers, or one line naming the file and line of the first that is not a
    finite number."""
    try:
        values = np.array([text for _, text in lines], dtype=float)
    except ValueError:
        values = np.full(len(lines), np.nan)
    if not np.all(np.isfinite(values)):
        for number, text in lines:
            try:
                ok = np.isfinite(float(text))
            except ValueError:
                ok = False
            if not ok:
                shown = text.strip()
                shown = shown if len(shown) <= 60 else shown[:60] + "..."
                raise KinergyError(f"{path}, line {number}: not a finite number: {shown!r}")
    return values


def _per_sample(files: PandaFiles, joints: tuple[str, ...] | None) -> tuple[int, int]:
    """The number of samples and of values per sample, checked across the files."""
    samples = _count(files.time)
    if samples < 2:
        raise KinergyError(f"{files.time}: {samples} time stamp(s); need 2 or more")
    counts = {signal: _count(path) for signal, path in files.signals.items()}
    first = files.signals["actual_q"]
    n = len(joints) if joints else counts["actual_q"] // samples
    for signal, path in files.signals.items():
        if n < 1 or counts[signal] != n * samples:
            per = counts[signal] / samples
            expect = f"{n} x {samples} = {n * samples}" if n >= 1 else f"{samples} or more"
            whose = f"the robot's {n} joints" if joints else f"{first.name}'s {n} per sample"
            raise KinergyError(
                f"{path}: {counts[signal]} values for {samples} time stamps in {files.time.name} "
                f"({per:.4g} per sample); expected {expect} ({whose})"
            )
    return samples, n


def _panda_chunks(
    path: Path,
    *,
    columns: str | None,
    repair: bool,
    select: Sequence[str] | None,
    rows: int,
    joints: tuple[str, ...] | None,
    bag: object | None,
) -> Iterator[Log]:
    """The :class:`~kinergy.io.formats.LogFormat` reader of the layout (module docstring)."""
    if columns is not None:
        raise KinergyError(f"{path}: a panda-gaz log's files name their signals; no --columns")
    files = panda_files(path)
    _, n = _per_sample(files, joints)
    wanted = dict(files.signals)
    if select is not None:
        missing = [s for s in select if s not in wanted]
        if missing:
            raise KinergyError(
                f"{path}: no file for {', '.join(missing)}; the log has: {', '.join(wanted)}"
            )
        wanted = {s: wanted[s] for s in select}
    streams = {s: _numbers(p) for s, p in wanted.items()}
    times = _numbers(files.time)
    scale, previous, notes = 0.0, -np.inf, []
    while True:
        stamps = list(itertools.islice(times, rows))
        if not stamps:
            break
        t = _values(files.time, stamps)
        block = {
            s: _values(wanted[s], list(itertools.islice(it, len(t) * n))).reshape(len(t), n)
            for s, it in streams.items()
        }
        if scale == 0.0:
            unit = time_unit(t, str(files.time))
            scale = TIME_UNITS[unit]
            if unit != "s":
                notes.append(f"{files.time}: timestamps are in {unit}; converted to s")
        t = t * scale
        late = np.diff(np.concatenate([[previous], t])) <= 0
        if np.any(late):
            k = int(np.argmax(late))
            if not repair:
                raise KinergyError(
                    f"{files.time}, line {stamps[k][0]}: time {t[k]:.6g} s is not after the "
                    "one before; --repair drops such samples"
                )
            keep = t > np.maximum.accumulate(np.concatenate([[previous], t]))[:-1]
            notes.append(
                f"{files.time}: {int(np.sum(~keep))} sample(s) from line {stamps[k][0]} on whose "
                "time was not after the one before dropped (--repair)"
            )
            t, block = t[keep], {s: v[keep] for s, v in block.items()}
        if len(t):
            previous = float(t[-1])
            yield Log(str(path), t, block, notes)
            notes = []


#: the panda-gaz layout: a time file and one-number-per-line files of n values per sample
PANDA = register(LogFormat("panda", is_panda_layout, _panda_chunks, folders=True, joints=True))
