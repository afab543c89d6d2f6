"""``kinergy demo``: the UR5e study on the built-in digital twin, from logs to report.

1. The twin (the UR5e doc's own model: Tables I-IV and VI) runs the doc's test programs A and B
   and writes their RTDE logs, with a realistic 4 ms lag and speed and current noise.
2. Identification on test A by the sequential method (UR5e doc sections 3-4), starting from a
   model whose drives are nominal guesses, so every drive parameter has to come from the log.
3. Validation on test A and the unseen test B (Tables V and VII), energy of both (Table VIII),
   each next to the twin's truth or the doc's values; figures and ``report.html``.
4. The energy-optimal timing of test A at its own cycle time, with the Pareto front.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from pathlib import Path

from kinergy.files import output_folder
from kinergy.identify.preprocess import prepare
from kinergy.identify.sequential import identify_sequential
from kinergy.io.motion import motion_from_log
from kinergy.io.rtde import read_log, write_log
from kinergy.io.task import load_task
from kinergy.model.library import load_robot
from kinergy.model.robot import Friction, Robot
from kinergy.report.html import Table
from kinergy.simulate import TwinSettings, simulate
from kinergy.trajectory.programs import paper_trajectory
from kinergy.workflows.study import run_study, write_study

__all__ = ["nominal_drives", "run_demo"]


def nominal_drives(robot: Robot) -> Robot:
    """The robot with guessed drive data: no motor inertia, no friction, k_t 0.1 N m/A (the
    reducer inertia, a catalogue value, is kept)."""
    joints = []
    for joint in robot.joints:
        params = {name: 0.0 for name in joint.drive.friction.params}
        params["smoothing"] = joint.drive.friction.params.get("smoothing", 1e-3)
        drive = dataclasses.replace(
            joint.drive,
            motor_inertia=0.0,
            torque_constant=0.1,
            friction=Friction(joint.drive.friction.model, params),
        )
        joints.append(dataclasses.replace(joint, drive=drive))
    return robot.with_joints(joints)


def run_demo(
    out: Path | None = None, progress: Callable[[str], None] | None = None
) -> tuple[dict[str, list[Table]], Path, float]:
    """Run the demo into folder ``out``, built beside it and renamed into place at the end
    (:func:`kinergy.files.atomic_folder`: a failure or an interruption leaves no half-written
    folder). ``out`` None: a new folder ``kinergy-demo-*`` in the system's temporary folder
    (nothing is written to the current folder unless asked).

    Returns
    -------
    tables
        The report's tables (keyed ``"IV"``, ``"V"``, ``"VI"``, ``"VII"``, ``"VIII"``,
        ``"breakdown"``, ``"timing"``).
    report : Path
        ``out / "report.html"``.
    seconds : float
        Wall time.
    """
    start = time.perf_counter()
    with output_folder(out, prefix="kinergy-demo") as (folder, target):
        tables = _demo(folder, progress or (lambda _msg: None))
    return tables, target / "report.html", time.perf_counter() - start


def _demo(out: Path, say: Callable[[str], None]) -> dict[str, list[Table]]:
    """The demo's steps, writing into folder ``out``; returns the report's tables."""
    truth = load_robot("ur5e")
    logs = out / "logs"
    logs.mkdir(parents=True, exist_ok=True)
    datas, motions = {}, {}
    for k, name in enumerate(("test-a", "test-b")):
        label = "test " + name[-1].upper()
        say(f"simulating {label} on the UR5e twin (500 Hz, 4 ms lag, speed and current noise)")
        twin = simulate(truth, paper_trajectory(truth, name), TwinSettings(seed=k + 1))
        path = logs / f"{name}.csv"
        write_log(path, twin.t, twin.signals)
        log = read_log(path)
        datas[label] = prepare(log, truth.n)
        motions[label] = motion_from_log(log, n_joints=truth.n, source="target")
    say("identifying on test A (sequential method, UR5e doc sections 3-4)")
    result = identify_sequential(nominal_drives(truth), [datas["test A"]])
    study = run_study(
        result.robot,
        validation=datas,
        motions=motions,
        result=result,
        truth=truth,
        paper=True,
        task=load_task("test-a", robot=result.robot),
        progress=say,
    )
    say("writing the report")
    _, tables = write_study(
        study,
        out,
        title="kinergy demo: the UR5e study on the digital twin",
        subtitle=(
            "Tests A and B simulated on the twin, drives identified on test A, validated on A and "
            "the unseen B, energy of both (UR5e doc Tables IV-VIII)"
        ),
        meta={
            "robot": truth.name,
            "logs": ", ".join(str(p.relative_to(out)) for p in sorted(logs.glob("*.csv"))),
        },
    )
    return tables
