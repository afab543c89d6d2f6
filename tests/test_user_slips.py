"""Slips a person makes at the command line, each refused in one line before anything is
written: a number that is not one, a payload's centre of mass in mm, the same log twice."""

from __future__ import annotations

from pathlib import Path

import pytest

from kinergy.cli import main


@pytest.fixture(scope="module")
def log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("slips") / "a.csv"
    assert main(["-q", "simulate", "ur5e", "--trajectory", "test-a", "--out", str(path)]) == 0
    return path


@pytest.mark.parametrize(
    ("argv", "flag"),
    [
        (["simulate", "ur5e", "--trajectory", "test-a", "--ambient", "nan"], "--ambient"),
        (["simulate", "ur5e", "--trajectory", "test-a", "--initial-temperature", "inf"], None),
        (["optimize", "ur5e", "test-a", "--v-max", "nan"], "--v-max"),
        (["excite", "ur5e", "--period", "nan"], "--period"),
    ],
)
def test_a_number_that_is_not_finite_is_refused_naming_the_flag(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], flag: str | None
) -> None:
    out = tmp_path / "out.csv"
    assert main([*argv, "--out", str(out)] if argv[0] != "optimize" else argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "must be a finite number" in err
    assert flag is None or f"error: {flag}: must be" in err
    assert not out.exists()


def test_a_payload_centre_of_mass_in_mm_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    # the value refused where --payload is parsed (LogReading): a usage error, as --columns's
    assert main(["energy", "ur5e", "test-a", "--payload", "1.5,0,0,60"]) == 2
    err = capsys.readouterr().err
    assert "--payload: payload com is 60 m from the flange" in err and "mm instead of m?" in err


def test_the_same_log_twice_is_refused(
    log: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    copy = tmp_path / "copy.csv"
    copy.write_bytes(log.read_bytes())
    out = tmp_path / "m.toml"
    for logs in ([log, log], [log, copy]):
        assert main(["identify", "--robot", "ur5e", "--out", str(out), *map(str, logs)]) == 1
        err = capsys.readouterr().err
        assert f"{logs[1]}: the same log as {log} (same SHA-256): given twice" in err
        assert err.count("\n") == 1 and not out.exists()


def test_a_supply_signal_that_cannot_be_is_refused(
    log: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The supply's voltage stuck at 0 V and its current with the sign flipped (the arm would
    feed the supply) fail the ratings check; the current stuck at one value fails constant."""
    header, *rows = log.read_text().splitlines()
    names = header.split(" ")
    v, i = names.index("actual_robot_voltage"), names.index("actual_robot_current")

    def edited(name: str, change: object) -> Path:
        out = tmp_path / name
        lines = []
        for row in rows:
            cells = row.split(" ")
            change(cells)  # type: ignore[operator]
            lines.append(" ".join(cells))
        out.write_text("\n".join([header, *lines]) + "\n")
        return out

    cases = {
        "volt0.csv": (lambda c: c.__setitem__(v, "0"), "ratings check failed: actual_robot_voltage never exceeds 0 V"),
        "flipped.csv": (lambda c: c.__setitem__(i, str(-abs(float(c[i])))), "actual_robot_current is never positive"),
        "stuck.csv": (lambda c: c.__setitem__(i, "1.5"), "constant check failed: actual_robot_current holds 1.5"),
    }  # fmt: skip
    for name, (change, words) in cases.items():
        assert main(["energy", "ur5e", str(edited(name, change))]) == 1
        err = capsys.readouterr().err
        assert words in err and err.count("\n") == 1, err
    assert main(["-q", "energy", "ur5e", str(log)]) == 0


def test_validate_with_nothing_to_compare_is_refused(
    log: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    header, *rows = log.read_text().splitlines()
    names = header.split(" ")
    keep = [
        k
        for k, n in enumerate(names)
        if not n.startswith(("target_moment", "actual_current", "target_current"))
    ]
    bare = tmp_path / "bare.csv"
    bare.write_text(
        "\n".join(" ".join(line.split(" ")[k] for k in keep) for line in [header, *rows]) + "\n"
    )
    assert main(["validate", "ur5e", str(bare)]) == 1
    err = capsys.readouterr().err
    assert "nothing to compare the model with" in err and err.count("\n") == 1


@pytest.mark.parametrize(
    ("argv", "words", "status"),
    [  # the options refuse them (a usage error: 2), or the run does (1)
        (["simulate", "ur5e", "--trajectory", "test-a", "--exact", "--lag", "0.1"], "--exact and --lag together", 2),
        (["simulate", "ur5e", "--trajectory", "test-a", "--truth", "t.toml"], "--truth: only with --mismatch realistic", 1),
        (["excite", "ur5e", "--no-floor", "--floor", "0.2"], "--no-floor and --floor together", 2),
    ],
)  # fmt: skip
def test_flags_that_contradict_each_other_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], words: str, status: int
) -> None:
    out = tmp_path / "out.csv"
    assert main([*argv, "--out", str(out)]) == status
    err = capsys.readouterr().err
    assert words in err and err.count("\n") == 1 and not out.exists()


def test_a_motion_the_arm_cannot_run_is_a_warning(capsys: pytest.CaptureFixture[str]) -> None:
    """50 kg on a UR5e (rated 5 kg): the energy is given, with a warning naming the joint and
    how far past its torque limit the motion goes; the rated payload gives none."""
    assert main(["-q", "energy", "ur5e", "test-a", "--payload", "50"]) == 0
    err = capsys.readouterr().err
    assert "warning: the motion needs" in err and "with a 50 kg payload" in err
    assert "times its 150 N m limit: the arm cannot run it" in err
    assert main(["-q", "energy", "ur5e", "test-a", "--payload", "5"]) == 0
    assert capsys.readouterr().err == ""


def test_a_task_in_radians_that_says_degrees_is_refused(tmp_path: Path) -> None:
    from kinergy.errors import KinergyError
    from kinergy.io.task import load_task

    task = tmp_path / "t.toml"
    task.write_text(
        'unit = "deg"\n[[move]]\nq = [0.1, -1.57, 1.2, -1.2, -1.57, 0.0]\n'
        "[[move]]\nq = [0.6, -1.2, 1.0, -1.4, -1.57, 0.3]\n"
    )
    with pytest.raises(KinergyError, match=r'unit = "deg", but every joint angle is within 1.57'):
        load_task(task)
    task.write_text(task.read_text().replace('"deg"', '"rad"'))
    assert load_task(task).waypoints.shape == (3, 6)


def test_validating_on_a_few_samples_is_a_warning(
    log: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    short = tmp_path / "short.csv"
    short.write_text("\n".join(log.read_text().splitlines()[:4]) + "\n")
    assert main(["-q", "validate", "ur5e", str(short)]) == 0
    err = capsys.readouterr().err
    assert "3 samples over 0.004 s: too short for these figures" in err


def test_a_file_that_is_not_a_log_is_named_for_what_it_is(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    task = tmp_path / "task.toml"
    task.write_text('robot = "ur5e"\n')
    assert main(["validate", "ur5e", str(task)]) == 1
    err = capsys.readouterr().err
    assert f"{task}: a TOML file (a robot or task file), not a log" in err


def test_a_yaw_range_is_shown_in_the_degrees_it_was_given(
    capsys: pytest.CaptureFixture[str],
) -> None:
    program = str(Path(__file__).parent / "programs" / "small.script")
    argv = ["place", "ur5e", program, "--x", "0:0", "--y", "0:0", "--yaw", "0:720"]
    assert main(argv) == 2  # the grid refuses it: a usage error
    assert "--yaw: 0:720 reaches beyond 360 deg" in capsys.readouterr().err
