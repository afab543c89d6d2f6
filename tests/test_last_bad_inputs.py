"""The last classes of bad input that ended badly, each now one clear line or the result a user
expects: a task so slow its plan would need billions of samples, ``report --out`` over a folder
holding a folder of the user's named ``report.html``, a motion file with an hour-long gap, control
characters in a robot's name, and a huge blend radius (a numpy ``RuntimeWarning`` leaked)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from kinergy.cli import main
from kinergy.io.rtde import read_log, write_log
from kinergy.trajectory.motion import MAX_SAMPLES
from kinergy.trajectory.movej import movej


def _task(path: Path, speed: float, blend: float = 0.0) -> Path:
    path.write_text(
        f"""robot = "ur5e"
speed = {speed!r}
acceleration = 2.0
start = [0, -1.5, 0, -1.5, 0, 0]
[[move]]
q = [1, -1.5, 0, -1.5, 0, 0]
r = {blend!r}
[[move]]
q = [0, -1.2, 0.5, -1.5, 0, 0]
r = {blend!r}
[[move]]
q = [0, -1.5, 0, -1.5, 0, 0]
""",
        encoding="utf-8",
    )
    return path


@pytest.mark.parametrize("speed", [1e-7, 1e-13, 1e-300])
def test_a_task_too_slow_to_plan_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], speed: float
) -> None:
    """v = 1e-7 rad/s asked for 5e9 samples (a 37 GiB array), 1e-13 'Maximum allowed size
    exceeded': both a traceback."""
    task = _task(tmp_path / "slow.toml", speed)
    assert main(["optimize", "ur5e", str(task)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    # the file, line and move, the speed, the time it would take
    assert "slow.toml:8: move[2]: " in err and f"at v={speed:.4g} and a=2 the move takes" in err
    assert "more than an hour" in err


def test_a_script_too_slow_to_plan_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    script = tmp_path / "slow.script"
    script.write_text(
        "def p():\n  movej([0, -1.5, 0, -1.5, 0, 0], a=2.0, v=1.0)\n"
        "  movej([1, -1.5, 0, -1.5, 0, 0], a=2.0, v=1e-9)\nend\n"
    )
    assert main(["energy", "ur5e", str(script)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "slow.script:3: movej(" in err
    assert "at v=1e-09 and a=2 the move takes 1e+09 s, more than an hour" in err


def test_a_plan_at_the_limit_is_still_planned() -> None:
    """Just under :data:`MAX_SAMPLES` the planner plans (the limit refuses nothing a real
    program needs: 1000 s at 500 Hz)."""
    dt = 0.5  # a coarse grid keeps the test quick; the limit counts samples
    m = movej([[0.0], [1.0]], speed=1.0 / (0.99 * MAX_SAMPLES * dt), acceleration=10.0, dt=dt)
    assert MAX_SAMPLES * 0.98 < m.t.size < MAX_SAMPLES


def test_report_never_replaces_a_folder_of_the_users(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--out rep`` where ``rep/report.html`` is a folder of the user's (empty, so no file in
    ``rep`` said it was theirs): it was deleted and replaced by kinergy's report."""
    log = tmp_path / "a.csv"
    assert main(["-q", "simulate", "ur5e", "--trajectory", "test-b", "--out", str(log)]) == 0
    out = tmp_path / "rep"
    (out / "report.html").mkdir(parents=True)
    capsys.readouterr()
    assert main(["report", "ur5e", "--energy", str(log), "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "holds report.html (a folder)" in err
    assert (out / "report.html").is_dir()
    # a folder kinergy wrote is still replaced, figures/ and all
    again = tmp_path / "mine"
    for _ in range(2):
        assert main(["-q", "report", "ur5e", "--energy", str(log), "--out", str(again)]) == 0
    assert (again / "report.html").is_file() and (again / "figures").is_dir()


def test_a_motion_with_an_hour_long_gap_is_refused_before_an_hours_log(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """It used to be simulated across the gap: an hour-long log of a motion interpolated
    through it, without a word. The twin runs one unbroken motion: one line naming the gap."""
    source = tmp_path / "b.csv"
    assert main(["-q", "simulate", "ur5e", "--trajectory", "test-b", "--out", str(source)]) == 0
    log = read_log(source)
    t = log.t.copy()
    t[t.size // 2 :] += 3600.0
    motion = tmp_path / "gap.csv"
    write_log(motion, t, {"target_q": log["target_q"]})
    out = tmp_path / "sim.csv"
    capsys.readouterr()
    assert main(["simulate", "ur5e", "--trajectory", str(motion), "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "the motion breaks off 1 time(s), the longest for 3600 s" in err
    assert not out.exists()
    # the same motion without the gap is simulated
    write_log(motion, log.t, {"target_q": log["target_q"]})
    assert main(["-q", "simulate", "ur5e", "--trajectory", str(motion), "--out", str(out)]) == 0


@pytest.mark.parametrize("name", ["ur5e\x1b[31mRED", "bell\x07", "two\nlines"])
def test_control_characters_in_a_robots_name_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    from importlib.resources import files

    text = (files("kinergy.model") / "library" / "ur5e.toml").read_text(encoding="utf-8")
    escaped = name.encode("unicode_escape").decode("ascii").replace("\\x", "\\u00")
    model = tmp_path / "robot.toml"
    model.write_text(text.replace('name = "ur5e"', f'name = "{escaped}"', 1), encoding="utf-8")
    for argv in (["energy", str(model), "test-a"], ["robot", "show", str(model)]):
        assert main(argv) == 1
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "robot name" in err and "control characters" in err
        assert not any(c in err[:-1] for c in "\x1b\x07")
    # a joint's name too
    joint = text.replace('name = "shoulder_pan"', 'name = "pan\\u001b"', 1)
    model.write_text(joint, encoding="utf-8")
    assert main(["robot", "show", str(model)]) == 1
    err = capsys.readouterr().err
    assert "joint name: must be plain text (no control characters: \\x1b" in err
    assert err.rstrip().endswith("got 'pan\\x1b'")


def test_a_huge_blend_gives_the_largest_blend_without_a_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """r = 1e308 overflowed ``2 r`` (numpy: 'overflow encountered in scalar multiply'); a radius
    beyond the move's travel blends as much as the travel itself, so the plan is that one."""
    huge = movej(
        [[0.0, 0.0], [1.0, 0.5], [0.0, 1.0]], speed=1.0, acceleration=2.0, blend=1e308, dt=0.01
    )
    travel = movej(
        [[0.0, 0.0], [1.0, 0.5], [0.0, 1.0]], speed=1.0, acceleration=2.0, blend=1.0, dt=0.01
    )
    np.testing.assert_array_equal(huge.q, travel.q)
    task = _task(tmp_path / "blend.toml", 1.0, blend=1e308)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        assert main(["-q", "optimize", "ur5e", str(task), "--pareto-points", "2"]) == 0
    assert "Warning" not in capsys.readouterr().err
