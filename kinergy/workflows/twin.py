"""``kinergy simulate``: run the digital twin on a built-in program, a motion or a motion file,
write its log (:func:`run_twin`, with :class:`SimulateOptions`)."""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass
from typing import TypeGuard

import numpy as np

from kinergy.checks import choice, integer, number
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

__all__ = [
    "MAX_SEED",
    "SimulateOptions",
    "Simulation",
    "builtin_log",
    "check_source",
    "is_builtin",
    "run_twin",
    "twin_truth",
]


def twin_truth(robot: Robot, mismatch: Mismatch, seed: int) -> Robot:
    """The twin's true robot for ``--mismatch``: the model itself (``none``) or
    :func:`kinergy.twin.realistic_truth` of it, seeded (``realistic``)."""
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
    truth = twin_truth(robot, Mismatch.REALISTIC, seed)
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


#: the most the seed of ``--seed`` may be
MAX_SEED = 2**32 - 1
#: the lag and noises :class:`SimulateOptions` may set: name, flag, most (s, rad/s, A)
_IMPERFECTIONS = (
    ("lag", "--lag", 1.0),
    ("speed_noise", "--speed-noise", 10.0),
    ("current_noise", "--current-noise", 100.0),
)


@dataclass(frozen=True)
class SimulateOptions:
    """How ``kinergy simulate`` runs the twin, checked on construction (one line naming the
    option): the truth it runs and the imperfections of its controller and measurements.

    Attributes
    ----------
    mismatch : Mismatch
        ``none``: the model itself is the truth; ``realistic``: a true robot that differs from
        it as a real arm does (:func:`kinergy.twin.realistic_truth`, seeded), with a real
        controller's current steps, voltage noise and supply ripple.
    seed : int
        Of the random generator (0 to :data:`MAX_SEED`).
    exact : bool
        No lag and no noise: the model's equations exactly (not with ``lag`` or a noise).
    lag : float or None
        Real motion behind the target, s, 0 to 1 (None: 0.004).
    speed_noise : float or None
        Measured speed noise std, rad/s, 0 to 10 (None: 0.01).
    current_noise : float or None
        Measured current noise std, A, 0 to 100 (None: 0.04).
    ambient : float
        Air, deg C, -50 to 100.
    initial_temperature : float or None
        The joints' temperature at the start, deg C, -50 to 200 (None: the ambient).
    """

    mismatch: Mismatch = Mismatch.NONE
    seed: int = 0
    exact: bool = False
    lag: float | None = None
    speed_noise: float | None = None
    current_noise: float | None = None
    ambient: float = 25.0
    initial_temperature: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "mismatch", choice(self.mismatch, Mismatch, "--mismatch"))
        object.__setattr__(self, "seed", integer(self.seed, "--seed", ge=0, le=MAX_SEED))
        for name, what, most in _IMPERFECTIONS:
            value = getattr(self, name)
            if value is not None:
                if self.exact:
                    raise KinergyError(
                        f"--exact and {what} together: --exact means no lag and no noise"
                    )
                object.__setattr__(self, name, number(value, what, ge=0.0, le=most))
        object.__setattr__(self, "ambient", number(self.ambient, "--ambient", ge=-50.0, le=100.0))
        if self.initial_temperature is not None:
            start = number(self.initial_temperature, "--initial-temperature", ge=-50.0, le=200.0)
            object.__setattr__(self, "initial_temperature", start)

    def settings(self) -> TwinSettings:
        """The twin's :class:`~kinergy.twin.TwinSettings`: those of the mismatch (or exact),
        with the lag and noises given."""
        if self.exact:
            base = TwinSettings.exact()
        elif self.mismatch == Mismatch.REALISTIC:
            base = TwinSettings.realistic(self.seed)
        else:
            base = TwinSettings()
        return dataclasses.replace(
            base,
            lag=base.lag if self.lag is None else self.lag,
            speed_noise=base.speed_noise if self.speed_noise is None else self.speed_noise,
            current_noise=base.current_noise if self.current_noise is None else self.current_noise,
            seed=self.seed,
            ambient=self.ambient,
            initial_temperature=self.initial_temperature,
        )


@dataclass(frozen=True, eq=False)
class Simulation:
    """What the twin wrote: its log, its true robot, and what reading the trajectory said.

    Attributes
    ----------
    log : Log
        The controller's log (record.py signals, 500 Hz unless the motion says otherwise).
    truth : Robot
        The robot the twin ran (the model, or the realistic truth).
    settings : TwinSettings
    notes, warnings : tuple of str
    """

    log: Log
    truth: Robot
    settings: TwinSettings
    notes: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()


def run_twin(
    robot: Robot,
    trajectory: str | os.PathLike[str] | Motion,
    options: SimulateOptions,
    *,
    reading: LogReading | None = None,
    out: str | os.PathLike[str] | None = None,
    truth_out: str | os.PathLike[str] | None = None,
) -> Simulation:
    """Simulate ``trajectory`` (``test-a``, ``test-b``, a :class:`Motion`, or a motion file's
    or URScript program's target motion) on the twin of ``robot`` and write the log to ``out``
    (record.py layout, atomically) when given.

    The twin's truth is ``robot`` or a robot that differs from it (``options.mismatch``, seeded
    with ``options.seed``), whose robot file goes to ``truth_out`` when given. The program is
    planned on the model, as a user would.

    Raises
    ------
    KinergyError
        ``truth_out`` without the realistic mismatch; an unknown trajectory; a motion file that
        fails its checks.
    """
    if truth_out is not None and options.mismatch != Mismatch.REALISTIC:
        raise KinergyError(
            "--truth: only with --mismatch realistic (with none the twin's truth is ROBOT itself)"
        )
    settings = options.settings()
    truth = twin_truth(robot, options.mismatch, settings.seed)
    if isinstance(trajectory, Motion):
        motion, said = trajectory, Messages()
    else:
        motion, said = _target(robot, os.fspath(trajectory), reading or LogReading())
    name = os.fspath(out) if out is not None else os.fspath(getattr(trajectory, "name", "twin"))
    log = simulate(truth, motion, settings, name=name)
    if out is not None:
        write_log(out, log.t, log.signals)
    if truth_out is not None:
        save_robot(truth, truth_out, header=truth.description)
    return Simulation(log, truth, settings, tuple(said.notes), tuple(said.warnings))
