"""``kinergy place``: a program re-expressed for a moved base, the grid, the search, bad input."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from clicase import run_case
from hypothesis import given, settings
from hypothesis import strategies as st

from kinergy.dynamics.poses import tcp_pose
from kinergy.errors import KinergyError
from kinergy.io.urscript_reader import parse_program, read_program
from kinergy.model.library import load_robot
from kinergy.optimize.placement import MAX_CANDIDATES, PlacementGrid, Range
from kinergy.trajectory.program_path import program_path
from kinergy.trajectory.program_placement import BasePlacement, moved_program

PROGRAMS = Path(__file__).resolve().parents[1] / "benchmarks" / "programs"
SMALL = (Path(__file__).parent / "programs" / "small.script").read_text()


@pytest.mark.parametrize("name", ["ur5e_machine_tending", "ur10e_palletising"])
def test_a_moved_base_reaches_the_same_tool_poses_in_the_cell(name: str) -> None:
    """Every target (joint targets and poses) is the same TCP pose in the cell: today's pose
    equals the moved base's frame times the moved program's pose, to 1e-12; the joint targets
    keep their configuration."""
    robot = load_robot(name.split("_")[0])
    program = read_program(PROGRAMS / f"{name}.script")
    today = program_path(robot, program)
    placement = BasePlacement(0.1, -0.15, 0.05, math.radians(20.0))
    moved = program_path(robot, moved_program(robot, program, placement))
    base = placement.transform
    for k in range(today.moves):
        want = tcp_pose(robot, today.q_end[k], today.tcp[k])
        got = base @ tcp_pose(robot, moved.q_end[k], moved.tcp[k])
        np.testing.assert_allclose(got, want, atol=1e-12)
    joints = [k for k, m in enumerate(program.moves) if not m.pose]
    assert joints and all(moved.branch[k] == today.branch[k] for k in joints)


def test_todays_placement_is_the_program_itself() -> None:
    robot = load_robot("ur5e")
    program = parse_program(SMALL)
    assert moved_program(robot, program, BasePlacement()) is program


def test_the_grid_counts_and_lists_every_candidate() -> None:
    grid = PlacementGrid(
        Range(-0.2, 0.2), Range(0.0, 0.1), Range(0.0, 0.0), Range(0.0, math.radians(30.0)),
        step=0.1, yaw_step=math.radians(15.0),
    )  # fmt: skip
    places = grid.placements()
    assert grid.count == len(places) == 5 * 2 * 1 * 3
    assert places[0] == BasePlacement(-0.2, 0.0, 0.0, 0.0)
    assert places[-1].yaw == pytest.approx(math.radians(30.0))
    assert sum(p.today for p in places) == 1


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"step": 0.0}, "--step: must be a finite number > 0"),
        ({"step": float("nan")}, "--step"),
        ({"x": Range(0.3, -0.3)}, "--x: the range 0.3:-0.3 runs backwards"),
        ({"y": Range(0.0, 9.0)}, "--y: 0:9 reaches beyond 5 m"),
        ({"step": 1e-3}, f"at most {MAX_CANDIDATES} are searched"),
        ({"step": 5e-324}, f"at most {MAX_CANDIDATES} are searched"),
    ],
)
def test_bad_grids_are_one_line(kwargs: dict, match: str) -> None:
    args = {"x": Range(-0.2, 0.2), "y": Range(-0.2, 0.2), **kwargs}
    with pytest.raises(KinergyError, match=match) as info:
        PlacementGrid(**args)
    assert "\n" not in str(info.value)


@pytest.fixture(scope="module")
def placed(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """small.script over three placements, the farthest out of reach."""
    folder = tmp_path_factory.mktemp("place")
    (folder / "small.script").write_text(SMALL)
    args = [
        "place", "ur5e", "small.script", "--x", "-0.1:0.1", "--y", "0.0:0.9", "--step", "0.45",
        "--tool-symmetry", "z", "--json", "--urscript", "placed.script", "--plot", "map.png",
    ]  # fmt: skip
    import clicase

    limit = clicase.LIMIT
    clicase.LIMIT = 120.0
    try:
        out = run_case(args, folder, outputs=["placed.script", "map.png"], refuse=False)
    finally:
        clicase.LIMIT = limit
    return folder, json.loads(out.out)


def test_place_reports_every_candidate_and_the_best(placed: tuple[Path, dict]) -> None:
    folder, data = placed
    cells = data["candidates"]
    assert len(cells) == 3  # x = -0.1 (-0.1 + 0.45 lies beyond 0.1), y = 0, 0.45, 0.9
    for cell in cells:
        assert {"x", "y", "yaw", "reachable", "e_supply", "cycle_time"} <= set(cell)
    assert any(c["reachable"] for c in cells)
    out = [c for c in cells if not c["reachable"]]
    assert [c["y"] for c in out] == [0.9]
    assert out[0]["e_supply"] is None and out[0]["reason"] == "out of reach" and out[0]["why"]
    best, today = data["best"], data["today"]
    reachable = [c["e_supply"] for c in cells if c["reachable"]] + [today["e_supply"]]
    assert best["e_supply"] == pytest.approx(min(reachable))
    cycle = today["cycle_time"]
    assert all(c["cycle_time"] == pytest.approx(cycle, abs=2e-3) for c in cells if c["reachable"])
    assert data["best_readback_e_supply"] == pytest.approx(best["e_supply"], rel=0.01)
    assert data["saving_beyond_levers"] == pytest.approx(
        1 - data["best_readback_e_supply"] / data["today_readback_e_supply"]
    )
    assert (folder / "map.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = (folder / "placed.script").read_text()
    assert "kinergy place: the robot's base moved by" in text
    assert "set_standard_digital_out(0, True)" in text and "# down" in text


def test_the_text_report_keeps_every_reason_within_the_width(tmp_path: Path) -> None:
    """The printed report: no line over the tables' 120 characters, and the reason a placement is
    out of reach printed whole (wrapped, not cut), naming the placement."""
    import clicase

    from kinergy.cli.common import TABLE_WIDTH

    (tmp_path / "small.script").write_text(SMALL)
    args = ["place", "ur5e", "small.script", "--x", "0:0", "--y", "0:0.9", "--step", "0.9"]
    limit = clicase.LIMIT
    clicase.LIMIT = 120.0
    try:
        out = run_case(args, tmp_path, refuse=False).out
    finally:
        clicase.LIMIT = limit
    assert max(len(line) for line in out.splitlines()) <= TABLE_WIDTH
    assert "out of reach: small.script:" in out
    words = " ".join(out.split())
    assert "best placement: x=+0.000 m, y=+0.000 m" in words


@pytest.mark.parametrize(
    ("label", "extra", "match"),
    [
        ("step-zero", ["--step", "0"], "--step: must be a finite number > 0"),
        ("range-backwards", ["--x", "0.2:-0.2"], "--x: the range 0.2:-0.2 runs backwards"),
        ("range-text", ["--y", "left:right"], "--y: expected MIN:MAX in m"),
        ("range-one", ["--y", "0.2"], "--y: expected MIN:MAX in m"),
        ("range-nan", ["--x", "nan:0.1"], "--x: expected MIN:MAX in m"),
        ("yaw-step-negative", ["--yaw", "0:30", "--yaw-step", "-5"], "--yaw-step"),
        ("too-many", ["--step", "0.001"], "at most 400 are searched"),
        (
            "unreachable",
            ["--x", "3:3.5", "--y", "0:0"],
            "no candidate placement reaches every pose",
        ),
        ("over-input", ["--urscript", "small.script"], "is also an input"),
    ],
)
def test_bad_input_is_one_line_and_writes_nothing(
    tmp_path: Path, label: str, extra: list[str], match: str
) -> None:
    (tmp_path / "small.script").write_text(SMALL)
    args = [
        "place",
        "ur5e",
        "small.script",
        "--x",
        "-0.1:0.1",
        "--y",
        "-0.1:0.1",
        "--plot",
        "m.png",
    ]
    for i in range(0, len(extra), 2):
        if extra[i] in args:
            args[args.index(extra[i]) + 1] = extra[i + 1]
        else:
            args += extra[i : i + 2]
    out = run_case(args, tmp_path, refuse=True)
    assert match in out.err, out.err
    assert not (tmp_path / "m.png").exists()


def test_a_moved_program_is_written_with_its_new_values_under_its_names() -> None:
    """The moved program written back (no lever changed anything) reads back to the moved
    targets: every named waypoint's line carries the moved value, the moves still name it."""
    from kinergy.io.urscript import program_script

    robot = load_robot("ur5e")
    program = read_program(PROGRAMS / "ur5e_machine_tending.script")
    moved = moved_program(robot, program, BasePlacement(0.0, 0.2))
    text = program_script(moved)
    assert "movej(place1_above, a=1.2, v=1)" in text
    assert "place1_above = [-0.60000" not in text  # today's value is gone
    back = parse_program(text, path="moved.script")
    for a, b in zip(back.moves, moved.moves, strict=True):
        np.testing.assert_allclose(a.target, b.target, atol=1e-8)
    np.testing.assert_allclose(
        program_path(robot, back).q_end, program_path(robot, moved).q_end, atol=1e-8
    )


def test_only_todays_and_the_best_optimisation_are_kept() -> None:
    """Each optimisation holds its 500 Hz motions: a search keeps today's and the best one's,
    and only the figures of the others (400 candidates would otherwise hold gigabytes)."""
    from kinergy.optimize.options import ProgramOptions
    from kinergy.optimize.placement import place_program

    robot = load_robot("ur5e")
    grid = PlacementGrid(Range(-0.1, 0.1), Range(0.0, 0.0), step=0.1)
    search = place_program(robot, parse_program(SMALL, path="small.script"), grid, ProgramOptions())
    kept = [c for c in search.candidates if c.result is not None]
    assert search.today.result is not None and search.best.result is not None
    assert all(c is search.best or c is search.today for c in kept)
    assert all(c.e_supply is not None and c.cycle_time is not None for c in search.candidates)
    energies = [c.e_supply for c in search.candidates]
    assert search.best.e_supply == min([*energies, search.today.e_supply])


def test_a_placement_scores_the_same_in_any_grid_and_on_any_number_of_processes() -> None:
    """A placement's result does not depend on its neighbours, the grid it is part of, the order
    and processes it runs in or what ran before it in the process: x = +0.2 m alone, in a grid
    from -0.4 m (where it is -0.4 + 3 * 0.2 = 0.20000000000000007 in floating point) and on two
    processes gives the same energy to the last bit. That shift in the 17th digit gave another
    optimum, 2 % of the energy apart, before the grid's values were rounded to a nanometre; and
    the BLAS thread count left in force by an earlier caller (two threads split some sums) moved
    it by 8e-5 (196.0703 against 196.0856 J) before the optimiser ran its algebra on one."""
    from threadpoolctl import threadpool_limits

    from kinergy.optimize.options import ProgramOptions
    from kinergy.optimize.placement import place_program

    assert -0.4 + 3 * 0.2 != 0.2  # the arithmetic the grid's rounding takes out
    robot = load_robot("ur5e")
    program = parse_program(SMALL, path="small.script")
    options = ProgramOptions(blends=False)

    def energy(grid: PlacementGrid, workers: int, blas: int) -> float | None:
        with threadpool_limits(limits=blas, user_api="blas"):  # as an earlier caller left it
            search = place_program(robot, program, grid, options, workers=workers)
        (found,) = [c for c in search.candidates if abs(c.placement.x - 0.2) < 1e-9]
        assert found.placement.x == 0.2
        return found.e_supply

    alone = energy(PlacementGrid(Range(0.2, 0.2), Range(0.0, 0.0), step=0.1), 1, 2)
    grid = PlacementGrid(Range(-0.4, 0.2), Range(0.0, 0.0), step=0.2)
    assert alone is not None
    assert energy(grid, 1, 1) == alone
    assert energy(grid, 2, 2) == alone


@settings(max_examples=300, deadline=None)
@given(st.text(max_size=30), st.floats(allow_nan=True, allow_infinity=True))
def test_any_range_text_and_step_is_parsed_or_refused_in_one_line(text: str, step: float) -> None:
    """Whatever the user types for a range and a step: a checked grid, or a KinergyError of one
    line (never another exception, never a grid with NaN or more than the cap)."""
    from kinergy.cli.place import parse_range

    try:
        r = parse_range(text, "--x", "m")
        grid = PlacementGrid(r, Range(0.0, 0.0), step=step)
    except KinergyError as exc:
        assert "\n" not in str(exc) and str(exc).startswith(("--x", "--step"))
        return
    assert math.isfinite(r.low) and math.isfinite(r.high) and r.low <= r.high
    assert 1 <= grid.count <= MAX_CANDIDATES == 400
    assert all(math.isfinite(p.x) for p in grid.placements())


def test_the_api_places_as_the_command(
    placed: tuple[Path, dict], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``kinergy.api.place`` with the grid and options the command parsed: its ``to_dict()`` is
    the command's ``--json`` (the files it writes are its own)."""
    import kinergy.api as api

    _folder, data = placed
    monkeypatch.chdir(tmp_path)  # the program named as the command named it
    program = Path("small.script")
    program.write_text(SMALL)
    grid = PlacementGrid(x=Range(-0.1, 0.1), y=Range(0.0, 0.9), step=0.45)
    options = api.ProgramOptions(tool_symmetry=api.ToolSymmetry.Z)
    run = api.place("ur5e", program, grid, options, urscript="placed.script")
    got = json.loads(json.dumps(run.to_dict(), default=str).replace("NaN", "null"))
    cli = {k: v for k, v in data.items() if k not in ("kinergy", "inputs")}
    got.pop("written"), cli.pop("written")
    assert _close(got, cli)


def _close(a: object, b: object) -> bool:
    """``a == b`` with floats equal to 1e-12 relative."""
    if isinstance(a, dict) and isinstance(b, dict):
        assert set(a) == set(b), set(a) ^ set(b)
        return all(_close(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        assert len(a) == len(b)
        return all(_close(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and isinstance(b, float):
        assert a == pytest.approx(b, rel=1e-12, abs=1e-15)
        return True
    assert a == b
    return True
