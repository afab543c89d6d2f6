"""``kinergy simulate``: run the digital twin on a built-in program or a motion file, write its log."""

from __future__ import annotations

import os
from typing import TypeGuard

import numpy as np

from kinergy import checks
from kinergy.errors import KinergyError
from kinergy.io.log import Log
from kinergy.io.rtde import write_log
from kinergy.io.segments import segment_bounds
from kinergy.io.urscript_reader import read_program
from kinergy.logs.reading import LogReading
from kinergy.messages import Messages
from kinergy.model.robot import Robot
from kinergy.model.toml import save_robot
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.programs import TEST_TRAJECTORIES, paper_trajectory
from kinergy.twin import Mismatch, TwinSettings, realistic_truth, simulate
from kinergy.workflows.logs import read_motion

__all__ = ["builtin_log", "check_source", "is_builtin", "simulate_to_file", "twin_truth"]


def twin_truth(robot: Robot, mismatch: Mismatch | str, seed: int) -> Robot:
    """The twin's true robot for ``--mismatch``: the model itself (``none``) or
    :func:`kinergy.twin.realistic_truth` of it, seeded (``realistic``)."""
    mismatch = checks.choice(mismatch, Mismatch, "mismatch")
    return realistic_truth(robot, seed) if mismatch == Mismatch.REALISTIC else robot


def is_builtin(name: object) -> TypeGuard[str]:
    """Whether ``name`` names a built-in motion (``test-a``, ``test-b``) rather than a file."""
    return isinstance(name, str) and name in TEST_TRAJECTORIES and not os.path.exists(name)


def check_source(name: str | os.PathLike[str] | Log) -> None:
    """Refuse a log or motion named ``name`` that is neither a file or folder nor a built-in
    motion, listing the built-in motions (``test-c`` is a slip for ``test-a`` or ``test-b``).

    Raises
    ------
    KinergyError
        ``test-c: no such file or folder, nor a built-in motion (test-a, test-b)``.
    """
    if isinstance(name, Log) or is_builtin(name) or os.path.lexists(name):
        return
    raise KinergyError(
        f"{os.fspath(name)}: no such file or folder, nor a built-in motion "
        f"({', '.join(TEST_TRAJECTORIES)})"
    )


def builtin_log(robot: Robot, name: str, seed: int = 0) -> Log:
    """The log the realistic twin of ``robot`` (:func:`twin_truth`, seeded) writes running the
    built-in motion ``name`` planned on ``robot``: what a real arm's log of it looks like."""
    truth = twin_truth(robot, "realistic", seed)
    motion = paper_trajectory(robot, name)
    return simulate(truth, motion, TwinSettings.realistic(seed), name=name)


def _unbroken(trajectory: str, motion: Motion) -> None:
    """Refuse a motion whose sampling breaks (a gap, :func:`kinergy.io.segments.segment_bounds`):
    the twin runs one unbroken motion, and would run the gap as motion (an hour's gap: an hour
    of a log interpolated across it).

    Raises
    ------
    KinergyError
        Naming the file, the longest gap and where it is.
    """
    bounds = segment_bounds(motion.t)
    if len(bounds) < 2:
        return
    starts = [a for a, _ in bounds[1:]]
    gaps = [float(motion.t[a] - motion.t[a - 1]) for a in starts]
    k = int(np.argmax(gaps))
    at = starts[k]
    raise KinergyError(
        f"{trajectory}: the motion breaks off {len(starts)} time(s), the longest for "
        f"{gaps[k]:.4g} s (from t = {motion.t[at - 1]:.6g} s to {motion.t[at]:.6g} s, sample "
        f"{at + 1}): the twin runs one unbroken motion; simulate each part as its own file"
    )


def _target(robot: Robot, trajectory: str, reading: LogReading) -> tuple[Motion, Messages]:
    """The target motion of ``trajectory`` and what reading it said: the notes and warnings of
    a log's checks, and a warning for each load a URScript program sets (the twin carries the
    robot's own payload throughout)."""
    said = Messages()
    if trajectory in TEST_TRAJECTORIES:
        return paper_trajectory(robot, trajectory), said
    motion, inputs = read_motion(trajectory, robot, reading, source="target")
    _unbroken(trajectory, motion)
    said.notes += inputs.notes
    said.warnings += inputs.warnings
    if trajectory.endswith(".script"):
        said.warnings += [
            f"{trajectory}:{step.line}: {step.text.strip()} is not simulated: the twin carries "
            f"{robot.name}'s own payload throughout (--payload sets it; kinergy energy and "
            "optimize run the program with the loads it sets)"
            for step in read_program(trajectory).steps
            if getattr(step, "kind", "") == "payload"
        ]
    return motion, said


def simulate_to_file(
    robot: Robot,
    trajectory: str,
    out: str | os.PathLike[str],
    settings: TwinSettings,
    *,
    reading: LogReading | None = None,
    mismatch: str = "none",
    truth_out: str | os.PathLike[str] | None = None,
) -> tuple[Log, Messages]:
    """Simulate ``trajectory`` (``test-a``, ``test-b`` or a motion file's target motion) on the
    twin of ``robot`` and write the log to ``out`` (record.py layout, atomically).

    ``mismatch``: ``none`` runs the model itself, ``realistic`` a true robot that differs from
    it (:func:`twin_truth`, seeded with ``settings.seed``), whose robot file goes to
    ``truth_out`` when given. The program is planned on the model, as a user would. Returns the
    log and what reading ``trajectory`` said (its checks' notes and warnings).
    """
    truth = twin_truth(robot, mismatch, settings.seed)
    motion, said = _target(robot, trajectory, reading or LogReading())
    twin = simulate(truth, motion, settings, name=os.fspath(out))
    write_log(out, twin.t, twin.signals)
    if truth_out is not None:
        save_robot(truth, truth_out, header=truth.description)
    return twin, said
