"""A twin fleet: N robots x D days of controller logs, some robots wearing or changing payload.

Every robot is the UR5e twin (:func:`kinergy.twin.simulate`) repeating one program, logged
at 500 Hz in record.py layout, one file per log named ``NAME_YYYY-MM-DD_HHMM.csv`` in a folder
per robot, with a manifest ``fleet.toml`` beside them. From log to log the joints' friction
varies by ``jitter`` (0.5 %, seeded: temperature, lubrication); a robot in ``wear`` has its
friction rise by the given share linearly from the first day to the last; a robot in
``payload`` carries ``(day, kg)`` from that day on (at 5 cm along the flange's z axis).

:func:`plan` lists the logs (cheap, picklable :class:`TwinLog` values) and :func:`write_twin_log`
writes one, so a caller can spread the writing over processes; :func:`twin_fleet` does both.
"""

from __future__ import annotations

import dataclasses
import datetime as dt
import functools
import os
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kinergy.io.rtde import write_log
from kinergy.model.library import load_robot
from kinergy.model.robot import Payload, Robot
from kinergy.trajectory.motion import CONTROLLER_DT, Motion
from kinergy.trajectory.movej import movej
from kinergy.trajectory.programs import UR_HOME, pad_rest, paper_trajectory
from kinergy.twin import TwinSettings, simulate

__all__ = ["PROGRAMS", "TwinLog", "plan", "twin_fleet", "with_friction_scaled", "write_twin_log"]

#: the programs a twin robot can run: the UR5e doc's tests (13.5 s, 10.9 s) and a 2.7 s cycle
PROGRAMS = ("test-a", "test-b", "short")
START = dt.date(2024, 5, 6)


@dataclass(frozen=True)
class TwinLog:
    """One log to write: which robot, where, and the robot's state that day."""

    robot: str
    path: str
    day: int
    program: str
    seconds: float
    friction_scale: float
    payload: float
    seed: int
    clock: float


def with_friction_scaled(robot: Robot, scale: float) -> Robot:
    """``robot`` with every joint's friction torque times ``scale`` (the model's linear friction
    parameters scaled; shape parameters such as the smoothing speed kept)."""
    joints = []
    for joint in robot.joints:
        f = joint.drive.friction
        drive = dataclasses.replace(joint.drive, friction=f.with_values(f.values * scale))
        joints.append(dataclasses.replace(joint, drive=drive))
    return robot.with_joints(joints)


@functools.cache
def _program(name: str) -> Motion:
    """One cycle of a program on the UR5e at 500 Hz (its last sample equals its first)."""
    robot = load_robot("ur5e")
    if name != "short":
        return paper_trajectory(robot, name)
    moves = np.array([[0.8, 0.3, -0.5, 0.2, 0.6, 0.0], [-0.5, 0.2, 0.4, 0.0, 0.0, 1.0]])
    way = np.vstack([UR_HOME, UR_HOME + moves[0], UR_HOME + moves[1], UR_HOME])
    return pad_rest(movej(way, speed=2.0, acceleration=5.0, dt=CONTROLLER_DT), 0.1, CONTROLLER_DT)


def plan(
    folder: str | os.PathLike[str],
    *,
    robots: int = 10,
    days: int = 7,
    logs: int = 7,
    seconds: float = 60.0,
    programs: Iterable[str] = ("test-a", "test-b"),
    wear: Mapping[str, float] | None = None,
    payload: Mapping[str, tuple[int, float]] | None = None,
    jitter: float = 0.005,
    seed: int = 0,
) -> list[TwinLog]:
    """The logs of a twin fleet: ``robots`` robots (``robot-01``...), ``logs`` per robot spread
    evenly over ``days`` days, each ``seconds`` long; the programs are dealt out in turn."""
    wear, payload = dict(wear or {}), dict(payload or {})
    cycle = list(programs)
    rng = np.random.default_rng(seed)
    out = []
    for r in range(robots):
        name = f"robot-{r + 1:02d}"
        day_of = [k * days // logs for k in range(logs)]
        for k, day in enumerate(day_of):
            slot = day_of[:k].count(day)
            date = START + dt.timedelta(days=day)
            rise = wear.get(name, 0.0) * (day / max(days - 1, 1))
            when, kg = payload.get(name, (days + 1, 0.0))
            out.append(
                TwinLog(
                    robot=name,
                    path=str(Path(folder) / name / f"{name}_{date}_{8 + slot:02d}00.csv"),
                    day=day,
                    program=cycle[r % len(cycle)],
                    seconds=seconds,
                    friction_scale=(1.0 + rise) * (1.0 + jitter * rng.standard_normal()),
                    payload=kg if day >= when else 0.0,
                    seed=int(rng.integers(2**31)),
                    clock=float(3600.0 * (24 * day + 8 + slot)),
                )
            )
    return out


def write_twin_log(item: TwinLog) -> str:
    """Simulate and write one log of the plan; return its path."""
    robot = with_friction_scaled(load_robot("ur5e"), item.friction_scale)
    if item.payload:
        robot = robot.with_payload(Payload(mass=item.payload, com=np.array([0.0, 0.0, 0.05])))
    cycle = _program(item.program)
    period = len(cycle.t) - 1
    samples = round(item.seconds * 500)
    rng = np.random.default_rng(item.seed)
    index = (np.arange(samples) + int(rng.integers(period))) % period
    t = item.clock + CONTROLLER_DT * np.arange(samples, dtype=float)
    motion = Motion(t, cycle.q[index], cycle.qd[index], cycle.qdd[index])
    log = simulate(robot, motion, TwinSettings(seed=item.seed), name=item.path)
    Path(item.path).parent.mkdir(parents=True, exist_ok=True)
    write_log(item.path, log.t, log.signals)
    return item.path


def write_manifest(folder: str | os.PathLike[str], names: Iterable[str]) -> Path:
    """``fleet.toml`` in ``folder``: every robot a UR5e with its logs in its own folder."""
    path = Path(folder) / "fleet.toml"
    text = "".join(
        f'[[robot]]\nname = "{n}"\nmodel = "ur5e"\nlogs = "{n}/*.csv"\n\n' for n in sorted(names)
    )
    path.write_text(text, encoding="utf-8")
    return path


def twin_fleet(
    folder: str | os.PathLike[str],
    *,
    map_: Callable[[Callable[[TwinLog], str], list[TwinLog]], Iterable[str]] = map,
    **settings: object,
) -> Path:
    """Write a twin fleet (:func:`plan`'s settings) and its manifest; return the manifest.

    ``map_`` writes the logs (the built-in ``map``, or a process pool's ``map``).
    """
    logs = plan(folder, **settings)  # type: ignore[arg-type]
    list(map_(write_twin_log, logs))
    return write_manifest(folder, {item.robot for item in logs})
