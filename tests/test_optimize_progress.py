"""``kinergy optimize`` says how far it is: a fraction of its planned steps and the time left on a
terminal, nothing on a pipe (issue 37)."""

from __future__ import annotations

import contextlib
import io
import os
import re
from pathlib import Path

import pytest

from kinergy.cli import main
from kinergy.io.urscript_reader import parse_program
from kinergy.model.library import load_robot
from kinergy.optimize.options import ProgramOptions
from kinergy.optimize.programs import optimize_program

SMALL = (Path(__file__).parent / "programs" / "small.script").read_text()


def test_the_optimiser_counts_its_steps_against_a_planned_total() -> None:
    """Every step says the steps done of one planned total (the same at every call, so one bar),
    never going back, the last step with all but itself done; a plain hook (``print``-like) gets
    the fraction in its line."""
    said: list[tuple[str, int | None, int | None]] = []

    def record(message: str, *, done: int | None = None, total: int | None = None) -> None:
        said.append((message, done, total))

    lines: list[str] = []
    robot = load_robot("ur5e")
    program = parse_program(SMALL, path="small.script")
    own = optimize_program(robot, program, ProgramOptions(blends=False), progress=lines.append)
    slower = ProgramOptions(blends=False, cycle_time=1.1 * own.settings.cycle_time)
    optimize_program(robot, program, slower, progress=record)
    totals = {total for _, _, total in said}
    assert len(totals) == 1
    (total,) = totals
    assert total is not None and len(said) <= total
    done = [d for _, d, _ in said]
    assert done[0] == 0 and done[-1] == total - 1 and done == sorted(done)
    assert said[1][0] == "uniform scaling to the cycle time"  # a cycle time given: planned
    assert said[-1][0] == "checking the targets"
    assert lines[0].endswith(f"(0/{total - 1})")  # its own cycle time: no uniform scaling
    assert lines[-1] == f"checking the targets ({total - 2}/{total - 1})"


def _optimize(folder: Path) -> str:
    """``kinergy optimize ur5e small.script`` in ``folder``: what it wrote on stderr, without
    the terminal's control sequences."""
    err = io.StringIO()
    cwd = os.getcwd()
    try:
        os.chdir(folder)
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            status = main(["optimize", "ur5e", "small.script", "--no-blends"])
    finally:
        os.chdir(cwd)
    assert status == 0, err.getvalue()
    return re.sub(r"\x1b\[[0-9;?]*[a-zA-Z]", "", err.getvalue())


def test_optimize_shows_a_fraction_and_the_time_left_on_a_terminal_and_nothing_on_a_pipe(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "small.script").write_text(SMALL)
    monkeypatch.delenv("FORCE_COLOR", raising=False)
    monkeypatch.delenv("TTY_COMPATIBLE", raising=False)
    assert _optimize(tmp_path) == ""  # stderr is a pipe (a StringIO)
    monkeypatch.setenv("FORCE_COLOR", "1")  # rich takes stderr for a terminal
    monkeypatch.setenv("COLUMNS", "120")
    err = _optimize(tmp_path)
    fractions = {(int(k), int(n)) for k, n in re.findall(r"\b(\d+)/(\d+), \d+:\d\d left", err)}
    assert fractions, err
    (total,) = {n for _, n in fractions}
    assert (total, total) in fractions  # the bar ends full
    assert "timing: solving every move's v and a" in err and "checking the targets" in err
