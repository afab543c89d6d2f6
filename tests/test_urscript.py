"""URScript programs: the reader of the pick-and-place subset, the writer, clear errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kinergy.dynamics.ik import branch_of, ur_geometry
from kinergy.dynamics.poses import tcp_pose
from kinergy.errors import KinergyError
from kinergy.io.urscript import program_script
from kinergy.io.urscript_reader import parse_program, read_program
from kinergy.model.library import load_robot
from kinergy.trajectory.movel import joints_on_path
from kinergy.trajectory.program_motion import program_motion, sample_path
from kinergy.trajectory.program_path import program_path
from kinergy.trajectory.robot_program import Event, Move

PROGRAMS = Path(__file__).parent.parent / "benchmarks" / "programs"

SMALL = (Path(__file__).parent / "programs" / "small.script").read_text()


def test_reads_moves_events_and_variables() -> None:
    program = parse_program(SMALL)
    assert program.name == "small"
    kinds = [s.kind for s in program.steps]
    assert kinds == [
        "tcp", "payload", "movej", "movej", "movel", "io", "sleep", "movel", "movej"
    ]  # fmt: skip
    moves = program.moves
    assert not moves[0].pose and moves[1].pose and moves[2].pose
    assert moves[3].r == pytest.approx(0.02)
    assert moves[2].line == 8
    sleep = program.steps[6]
    assert isinstance(sleep, Event) and sleep.duration == pytest.approx(0.25)


@pytest.mark.parametrize(
    ("line", "match"),
    [
        ("  if True:", "small.script:6"),
        ("  movej([1, 2, 3], a=1)", "small.script:6"),
        ("  movej(p[9, 0, 0.2, 0, 3.14, 0], a=1.4, v=1.05)", "small.script:6"),
    ],
)
def test_bad_lines_are_one_line_naming_the_line(line: str, match: str) -> None:
    lines = SMALL.splitlines()
    lines.insert(5, line)
    text = "\n".join(lines) + "\n"
    with pytest.raises(KinergyError, match=match) as info:
        program = parse_program(text, path="small.script")
        program_path(load_robot("ur5e"), program)
    assert "\n" not in str(info.value)


def test_target_outside_the_joint_limits_names_its_line() -> None:
    text = SMALL.replace("home = [0.0,", "home = [7.0,")
    with pytest.raises(KinergyError, match=r"small.script:\d+"):
        program_path(load_robot("ur5e"), parse_program(text, path="small.script"))


def test_written_program_reads_back_to_the_same_motion() -> None:
    robot = load_robot("ur5e")
    program = parse_program(SMALL, path="small.script")
    moves = [m.replaced(v=m.v * 0.8, a=m.a * 0.9) for m in program.moves]
    changed = program.with_moves(moves)
    text = program_script(changed, ["changed"])
    assert "set_standard_digital_out(0, True)" in text and "# changed" in text
    assert "# down" in text
    back = parse_program(text)
    a, _ = program_motion(robot, program_path(robot, changed))
    b, _ = program_motion(robot, program_path(robot, back))
    np.testing.assert_allclose(b.q, a.q, atol=1e-6)


def test_movej_profile_and_movel_straight_line() -> None:
    robot = load_robot("ur5e")
    path = program_path(robot, parse_program(SMALL))
    motion, sched = program_motion(robot, path)
    # the movel down keeps the tool on a straight vertical line
    k = 2
    t0, t1 = sched.start[0, k], sched.start[0, k] + sched.duration[0, k]
    inside = (motion.t > t0) & (motion.t < t1)
    tips = tcp_pose(robot, motion.q[inside], path.tcp[k])[:, :3, 3]
    assert np.ptp(tips[:, 0]) < 1e-6 and np.ptp(tips[:, 1]) < 1e-6
    # peak tool speed along the line is the programmed v
    speed = np.linalg.norm(np.diff(tips, axis=0), axis=1) / 0.002
    assert speed.max() == pytest.approx(0.25, rel=1e-2)
    # at rest during the I/O and the sleep
    rest = (motion.t > t1 + 0.01) & (motion.t < t1 + 0.24)
    assert np.abs(motion.qd[rest]).max() < 1e-9


@pytest.mark.parametrize("path", sorted(PROGRAMS.glob("*.script")), ids=lambda p: p.stem)
def test_benchmark_programs_resolve(path: Path) -> None:
    program = read_program(path)
    assert 4 <= len({tuple(m.target) for m in program.moves if m.pose or True}) <= 14
    assert any(isinstance(s, Event) and s.kind == "io" for s in program.steps)
    assert any(isinstance(s, Move) and s.pose for s in program.steps)
    program_path(load_robot(path.stem.split("_")[0]), program)


def test_movel_speeds_and_accelerations_are_the_derivatives_of_the_angles() -> None:
    """The joints' speeds (``J^-1 V``) and accelerations (``J^-1 (A - Jdot qd)``) on the movel
    down against central differences (step 10 us) of the angles and speeds sampled around
    every 500 Hz sample of the move."""
    robot = load_robot("ur5e")
    path = program_path(robot, parse_program(SMALL))
    motion, sched = program_motion(robot, path)
    k = 2
    t0, t1 = sched.start[0, k], sched.start[0, k] + sched.duration[0, k]
    t = motion.t[(motion.t > t0 + 1e-3) & (motion.t < t1 - 1e-3)]
    h = 1e-5
    q_, qd_, _ = sample_path(robot, path, sched, np.stack([t - h, t + h]))
    _, qd, qdd = sample_path(robot, path, sched, t[None])
    np.testing.assert_allclose(qd[0], (q_[1] - q_[0]) / (2 * h), atol=1e-7)
    np.testing.assert_allclose(qdd[0], (qd_[1] - qd_[0]) / (2 * h), atol=1e-5)


def test_a_line_through_the_wrist_singularity_is_refused() -> None:
    robot = load_robot("ur5e")
    g = ur_geometry(robot)
    s = np.linspace(-1.0, 1.0, 41)[:, None]
    q = np.array([0.3, -1.4, 1.5, -1.6, 0.0, 0.4]) + s * [0.1, 0.05, -0.05, 0.1, 0.3, 0.1]
    pose = tcp_pose(robot, q)  # wrist 2 passes 0 at the middle sample
    still = np.zeros((len(q), 6))
    branch = branch_of(g, q[0], pose[0])
    with pytest.raises(KinergyError, match="singularity"):
        joints_on_path(robot, g, np.eye(4), branch, pose, still, still, q)
    moved = q + np.array([0.0, 0.0, 0.0, 0.0, 1.0, 0.0])  # the same line, away from it
    pose = tcp_pose(robot, moved)
    branch = branch_of(g, moved[0], pose[0])
    q_back, _, _ = joints_on_path(robot, g, np.eye(4), branch, pose, still, still, moved)
    np.testing.assert_allclose(q_back, moved, atol=1e-9)


def test_a_program_without_moves_names_its_file_once(tmp_path: Path) -> None:
    script = tmp_path / "idle.script"
    script.write_text("def idle():\n  set_payload(1.0)\nend\n")
    with pytest.raises(KinergyError) as err:
        read_program(script)
    assert str(err.value) == f"{script}: the program has no move"
