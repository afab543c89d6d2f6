"""The program optimiser: the path search, and ``kinergy optimize`` on a URScript program."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from kinergy.cli.optimize import optimize
from kinergy.io.rtde import read_log
from kinergy.model.library import load_robot
from kinergy.optimize.search import cheapest_cycle
from kinergy.workflows.logs import read_motion

SMALL = (Path(__file__).parent / "programs" / "small.script").read_text()


def test_cheapest_cycle_is_the_brute_force_optimum() -> None:
    rng = np.random.default_rng(5)
    sizes = [3, 2, 4, 3]
    costs = [rng.uniform(1, 10, (sizes[k - 1], sizes[k])) for k in range(len(sizes))]
    costs[2][1, 2] = np.inf
    best = min(
        (
            sum(costs[k][states[k - 1], states[k]] for k in range(len(sizes))),
            states,
        )
        for states in itertools.product(*(range(s) for s in sizes))
    )
    states, total = cheapest_cycle(costs)
    assert total == pytest.approx(best[0])
    assert tuple(states) == best[1]


@pytest.fixture(scope="module")
def optimized(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    folder = tmp_path_factory.mktemp("program")
    source = folder / "small.script"
    source.write_text(SMALL)
    out = folder / "small_opt.script"
    result = CliRunner().invoke(
        optimize,
        [
            "ur5e", str(source), "--tool-symmetry", "z", "--json",
            "--urscript", str(out), "--motions", str(folder / "motions"),
        ],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    return folder, json.loads(result.stdout)


def test_optimize_program_saves_and_keeps_the_job(optimized: tuple[Path, dict]) -> None:
    _, data = optimized
    for key in ("program", "optimized"):
        assert {"cycle_time", "e_elec", "within_limits"} <= set(data[key])
    assert data["optimized"]["cycle_time"] == pytest.approx(data["program"]["cycle_time"], rel=1e-3)
    assert data["optimized"]["within_limits"]
    assert data["targets_met"]
    assert data["saving"] > 0.02
    names = [lv["name"] for lv in data["levers"]]
    assert names[:2] == ["program", "2pi"] and "tool symmetry" in names and "timing" in names
    readback = data["readback_e_supply"] / data["optimized"]["e_supply"] - 1.0
    assert abs(readback) < 0.01


def test_written_program_reproduces_optimized_csv(optimized: tuple[Path, dict]) -> None:
    folder, _ = optimized
    text = (folder / "small_opt.script").read_text()
    assert "set_standard_digital_out(0, True)" in text and "sleep(0.25)" in text
    log = read_log(folder / "motions" / "optimized.csv")
    assert {"target_q", "target_qd", "target_qdd"} <= set(log.signals)
    assert (folder / "motions" / "optimized.csv").read_text().startswith("timestamp target_q_0")
    again, _ = read_motion(folder / "small_opt.script", load_robot("ur5e"))
    q = log["target_q"]
    n = min(q.shape[0], again.q.shape[0])
    assert abs(q.shape[0] - again.q.shape[0]) <= 1
    np.testing.assert_allclose(again.q[:n], q[:n], atol=1e-5)


def test_never_writes_over_the_program(tmp_path: Path) -> None:
    source = tmp_path / "small.script"
    source.write_text(SMALL)
    result = CliRunner().invoke(
        optimize, ["ur5e", str(source), "--urscript", str(source), "--no-blends"]
    )
    assert result.exit_code != 0
    assert "is also an input" in str(result.exception)
    assert source.read_text() == SMALL


def test_cycle_time_too_short_names_a_line(tmp_path: Path) -> None:
    source = tmp_path / "small.script"
    source.write_text(SMALL)
    result = CliRunner().invoke(optimize, ["ur5e", str(source), "--cycle-time", "0.5"])
    assert result.exit_code != 0
    message = str(result.exception)
    assert "\n" not in message
    assert "small.script" in message and "shorter than the fastest possible" in message


def test_refined_turns_keep_the_own_state_and_wrap() -> None:
    from kinergy.optimize.path_costs import refined_turns

    turns = refined_turns(np.array([0.0, 6.2]), np.deg2rad(15.0))
    assert turns[0].size == 5 and turns[0][0] == 0.0
    assert turns[1].size == 6 and np.all((turns[1] >= 0.0) & (turns[1] < 2.0 * np.pi))
    assert np.allclose(np.sort(np.mod(turns[1][1:] - 6.2 + np.pi, 2 * np.pi) - np.pi)[2], 0.0)


def test_energy_floor_is_below_the_friction_of_the_program() -> None:
    from kinergy.io.urscript_reader import parse_program
    from kinergy.optimize.floor import energy_floor
    from kinergy.optimize.verify import simulate_path
    from kinergy.trajectory.program_path import program_path

    robot = load_robot("ur5e")
    run = simulate_path(robot, program_path(robot, parse_program(SMALL, path="small.script")))
    floor = energy_floor(robot, run)
    friction = floor.parts["friction"]
    moving = floor.path_length > 0.0
    assert np.all(floor.friction_floor[moving] > 0.0)
    assert np.all(floor.friction_floor <= friction + 1e-9)
    for key, part in floor.parts.items():  # the same parts as the re-simulation's breakdown
        assert part.sum() == pytest.approx(run.result.breakdown[key], rel=1e-3, abs=1e-3)
    assert 0.0 < floor.untouched < run.result.e_elec


def test_the_energy_of_a_program_carries_the_load_it_sets(tmp_path: Path) -> None:
    """``kinergy energy`` of a URScript program runs it with its ``set_payload`` (as
    ``optimize`` accounts it): the same as the program without it on the robot carrying that
    load, and more than on the bare robot."""
    from kinergy.io.urscript_reader import read_program
    from kinergy.workflows.energy import energy_of_log

    robot = load_robot("ur5e")
    program = Path(__file__).parent / "programs" / "small.script"
    (load,) = [
        s.payload for s in read_program(program).steps if getattr(s, "kind", "") == "payload"
    ]
    bare = tmp_path / "bare.script"
    bare.write_text(program.read_text().replace("  set_payload(0.5)\n", ""))
    got = energy_of_log(robot, program)
    loaded = energy_of_log(robot.with_payload(load), bare)
    unloaded = energy_of_log(robot, bare)
    assert load is not None and load.mass == 0.5
    np.testing.assert_allclose(got.e_elec, loaded.e_elec, rtol=1e-12)
    np.testing.assert_allclose(got.breakdown["copper"], loaded.breakdown["copper"], rtol=1e-12)
    assert got.total_e_elec > unloaded.total_e_elec * 1.01


def test_a_payload_the_program_overrides_before_it_moves_is_a_warning(tmp_path: Path) -> None:
    """``--payload`` (the robot's own payload) on a program that sets its own before its first
    move is carried by no sample: the energy says so (it was silently the same figure)."""
    from kinergy.model import Payload
    from kinergy.workflows.energy import energy_of_log

    program = Path(__file__).parent / "programs" / "small.script"
    robot = load_robot("ur5e")
    bare = energy_of_log(robot, program)
    heavy = energy_of_log(robot.with_payload(Payload(mass=8.0)), program)
    np.testing.assert_allclose(heavy.e_elec, bare.e_elec, rtol=1e-12)
    assert bare.warnings == []
    assert any("sets its payload before its first move" in w for w in heavy.warnings)
