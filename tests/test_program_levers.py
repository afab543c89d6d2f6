"""The program optimiser's levers: typed options and outcomes, the same program on a slow host,
a lever repaired before it is judged, via points left out, programs written back with the
user's names."""

from __future__ import annotations

import ast
import time
from pathlib import Path

import numpy as np
import pytest

import kinergy.optimize.program_samples as program_samples
from kinergy.errors import KinergyError
from kinergy.io.urscript import program_script
from kinergy.io.urscript_reader import parse_program
from kinergy.model.library import load_robot
from kinergy.optimize.objectives import SupplyEnergy
from kinergy.optimize.options import Configurations, ProgramOptions, ToolSymmetry, ViaPoints
from kinergy.optimize.program_repair import Caps, at_cycle, repair
from kinergy.optimize.program_verify import simulate_path
from kinergy.optimize.programs import optimize_program
from kinergy.optimize.solve import Outcome
from kinergy.trajectory.program_path import program_path

ROOT = Path(__file__).resolve().parents[1]
SMALL = (Path(__file__).parent / "programs" / "small.script").read_text()


def _small(**changes: object) -> str:
    """small.script with the optimiser's output written back (the written text and energies)."""
    robot = load_robot("ur5e")
    program = parse_program(SMALL, path="small.script")
    options = ProgramOptions(tool_symmetry=ToolSymmetry.Z, **changes)  # type: ignore[arg-type]
    result = optimize_program(robot, program, options)
    energies = [lv.result.score for lv in result.levers]
    return program_script(result.written) + repr(energies)


def test_the_same_program_on_a_host_a_thousand_times_slower(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Every clock runs 1000 times fast and every drive-model evaluation sleeps 2 ms: the
    optimiser, which stops on iterations and tolerances only, writes the same program to the
    last digit and scores every lever the same."""
    fast = _small()
    for name in ("process_time", "perf_counter", "monotonic", "time"):
        real = getattr(time, name)
        start = real()
        monkeypatch.setattr(time, name, lambda r=real, s=start: s + 1000.0 * (r() - s))
    drive = program_samples.drive_by_payload
    sleep = time.sleep
    calls = []

    def slow(*args: object, **kwargs: object) -> object:
        calls.append(1)
        sleep(0.002)
        return drive(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(program_samples, "drive_by_payload", slow)
    slowed = _small()
    assert len(calls) > 20  # the slowdown was in the path
    assert slowed == fast


def test_options_are_typed_once_and_refuse_strings_below_the_edge() -> None:
    options = ProgramOptions(tool_symmetry="z2", configurations="free", via="keep")  # type: ignore[arg-type]
    assert options.tool_symmetry is ToolSymmetry.Z2 and ToolSymmetry.Z2.turns == 2
    assert options.configurations is Configurations.FREE and options.via is ViaPoints.KEEP
    assert ToolSymmetry.Z.any_angle and ToolSymmetry.Z4.steps and not ToolSymmetry.NONE.steps
    np.testing.assert_allclose(ToolSymmetry.Z4.equivalent(), np.arange(4) * np.pi / 2)
    with pytest.raises(KinergyError, match="--tool-symmetry: must be one of none, z, z2, z4"):
        ProgramOptions(tool_symmetry="z3")  # type: ignore[arg-type]
    with pytest.raises(KinergyError, match="--v-max: must be a finite number"):
        ProgramOptions(v_max=float("nan"))
    with pytest.raises(KinergyError, match="--standby: must be a finite number >= 0"):
        ProgramOptions(standby=-1.0)
    with pytest.raises(KinergyError, match="--cycle-time: must be a finite number > 0 and <= 600"):
        ProgramOptions(cycle_time=600.5)


def test_solver_outcomes_are_typed_and_worded_without_jargon() -> None:
    assert Outcome.of_slsqp(0) is Outcome.CONVERGED
    assert Outcome.of_slsqp(9) is Outcome.ITERATION_LIMIT
    assert Outcome.of_slsqp(4) is Outcome.INFEASIBLE
    assert Outcome.of_slsqp(8) is Outcome.STALLED
    assert Outcome.CONVERGED.words == "optimal"
    assert Outcome.ITERATION_LIMIT.words == "improved, iteration limit"
    assert all("Iteration limit reached" not in o.words for o in Outcome)


@pytest.mark.parametrize(
    "module",
    [
        *sorted((ROOT / "kinergy" / "optimize").glob("*.py")),
        ROOT / "kinergy" / "workflows" / "optimize.py",
        ROOT / "kinergy" / "workflows" / "optimize_program.py",
        ROOT / "kinergy" / "workflows" / "place.py",
        ROOT / "kinergy" / "cli" / "optimize.py",
        ROOT / "kinergy" / "cli" / "place.py",
    ],
    ids=lambda p: f"{p.parent.name}/{p.name}",
)
def test_no_untyped_options(module: Path) -> None:
    """No function takes ``**options: Any`` or a ``dict[str, Any]`` of settings (the JSON
    writers return such dicts; none takes one)."""
    tree = ast.parse(module.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            args = node.args
            if args.kwarg is not None:
                assert args.kwarg.annotation is None or "Any" not in ast.unparse(
                    args.kwarg.annotation
                ), f"{module.name}:{node.lineno} {node.name} takes **{args.kwarg.arg}: Any"
            for arg in [*args.args, *args.kwonlyargs, *args.posonlyargs]:
                text = "" if arg.annotation is None else ast.unparse(arg.annotation)
                assert "dict[str, Any]" not in text, f"{module.name}:{node.lineno} {node.name}"


def test_a_run_over_the_caps_is_repaired_at_the_same_cycle_time() -> None:
    """The program held to caps 10 % below its own peak speed and acceleration breaks them at
    its own cycle time; the repair slows the moves over them and speeds up the others: within
    every cap, the same cycle time, and a program a 500 Hz re-simulation confirms."""
    robot = load_robot("ur5e")
    path = program_path(robot, parse_program(SMALL, path="small.script"))
    own = simulate_path(robot, path)
    caps = Caps(
        0.9 * float(np.max(np.abs(own.motion.qd))), 0.9 * float(np.max(np.abs(own.motion.qdd)))
    )
    budget = own.result.cycle_time
    objective = SupplyEnergy()
    first = at_cycle(robot, path, budget, objective, caps, "first")
    assert not first.result.ok
    fixed = repair(robot, first, budget, objective, caps)
    assert fixed is not None and fixed.how in ("per move", "re-timed")
    assert fixed.run.result.ok
    assert fixed.run.result.cycle_time == pytest.approx(budget, abs=2e-3)
    again = simulate_path(
        robot, fixed.run.path, objective=objective, speed_cap=caps.speed,
        acceleration_cap=caps.acceleration,
    )  # fmt: skip
    assert again.result.ok and again.result.score == pytest.approx(fixed.run.result.score)


def test_via_points_left_out_keep_every_job_target() -> None:
    """With free via points the home pose passed every cycle is left out (both movej(home)
    take the joints of the target before them); every other stop is met, at rest, and the
    written program still names home."""
    robot = load_robot("ur5e")
    program = parse_program(SMALL, path="small.script")
    kept = optimize_program(robot, program, ProgramOptions())
    free = optimize_program(robot, program, ProgramOptions(via=ViaPoints.FREE))
    assert free.optimized.result.score < kept.optimized.result.score
    assert free.targets_met and free.optimized.result.ok
    assert [c.line for c in free.targets if c.left_out] == [6, 12]
    names = [lv.name for lv in free.levers]
    assert "via points" in names
    via = free.levers[names.index("via points")]
    assert via.kept and via.saved > 0.0 and "2 via points left out" in via.note
    text = program_script(free.written)
    assert "  movej(home, a=" in text and "home = [0.0, -1.75" not in text
    back = parse_program(text)
    again = simulate_path(robot, program_path(robot, back))
    assert again.result.score == pytest.approx(free.optimized.result.score, rel=1e-3)


WRITER = """def w():
  set_tcp(p[0, 0, 0.12, 0, 0, 0])
  home = [0.0, -1.75, 1.6, -1.4208, -1.5708, 0.0]  # the safe pose
  above = p[-0.34228, -0.36621, 0.25191, 2.52847, 1.86453, 0.0]
  down = p[-0.34228, -0.36621, 0.15191, 2.52847, 1.86453, 0.0]
  spare = home
  movej(home, a=1.4, v=1.05)
  movej(above, a=1.4, v=1.05)  # over the part
  movel(down, a=1.2, v=0.25)
  set_standard_digital_out(0, True)
  movel(above, a=1.2, v=0.25)
  movej(home, a=1.4, v=1.05)
end
"""


def test_written_program_keeps_names_values_and_comments() -> None:
    program = parse_program(WRITER)
    moves = program.moves
    turned = moves[1].target.copy()
    turned[5] = 0.5
    changed = [
        moves[0],
        moves[1].replaced(target=turned, a=2.0),  # above: a new value for its first use only
        moves[2].replaced(v=0.2),  # down: the same target
        moves[3],
        moves[4].replaced(target=np.array([0.1, -1.75, 1.6, -1.4208, -1.5708, 0.0])),
    ]
    text = program_script(program.with_moves(changed), ["hello"])
    lines = text.splitlines()
    assert lines[1] == "  # hello"
    # home is read elsewhere (spare = home): it keeps its value; the changed move gets home_2
    assert "  home = [0.0, -1.75, 1.6, -1.4208, -1.5708, 0.0]  # the safe pose" in lines
    assert any(line.startswith("  home_2 = [0.1, -1.75,") for line in lines)
    assert lines[-2] == "  movej(home_2, a=1.4, v=1.05)"
    assert "  movej(home, a=1.4, v=1.05)" in lines
    # above: the name holds the value of its unchanged use, the changed movej gets above_2
    assert any(line.startswith("  above = p[-0.34228") for line in lines)
    assert any(
        line.startswith("  above_2 = p[-0.34228, -0.36621, 0.25191, 2.52847, 1.86453, 0.5]")
        for line in lines
    )
    assert "  movej(above_2, a=2, v=1.05)  # over the part" in lines
    assert "  movel(down, a=1.2, v=0.2)" in lines
    assert "  down = p[-0.34228, -0.36621, 0.15191, 2.52847, 1.86453, 0.0]" in lines
    back = parse_program(text)
    for a, b in zip(back.moves, changed, strict=True):
        np.testing.assert_allclose(a.target, b.target, atol=1e-9)
        assert (a.a, a.v) == (b.a, b.v)


def test_a_variable_all_of_whose_moves_change_alike_is_reassigned() -> None:
    text = WRITER.replace("  spare = home\n", "")
    program = parse_program(text)
    new = np.array([0.2, -1.7, 1.5, -1.4, -1.5708, 0.1])
    moves = [m.replaced(target=new) if m.line in (6, 11) else m for m in program.moves]
    assert sum(m.line in (6, 11) for m in program.moves) == 2
    out = program_script(program.with_moves(moves))
    assert "  home = [0.2, -1.7, 1.5, -1.4, -1.5708, 0.1]  # the safe pose" in out
    assert out.count("movej(home, a=1.4, v=1.05)") == 2 and "home_2" not in out


def test_the_budget_shared_per_move_is_the_brute_force_optimum() -> None:
    """The allocation's dynamic programme over the time used equals a brute-force search of
    every combination of grid durations: the most of the budget used (the whole of it, to its
    step, where a combination fits it), at the least energy."""
    import itertools

    from kinergy.optimize import program_timing

    rng = np.random.default_rng(7)
    total = 3.2
    unit = total / program_timing._UNITS
    whole = rng.integers(100, 700, (5, 4)) * unit  # sums that hit the budget exactly exist
    for durations in (rng.uniform(0.2, 1.5, (5, 4)), whole):  # 5 grid durations of 4 moves
        energy = rng.uniform(1.0, 9.0, (5, 4))
        energy[2, 1] = np.inf  # not feasible
        steps = np.ceil(durations / unit - 1e-9).astype(int)
        found: dict[int, float] = {}
        for combo in itertools.product(range(5), repeat=4):
            used = sum(steps[d, j] for j, d in enumerate(combo))
            value = sum(energy[d, j] for j, d in enumerate(combo))
            if used <= program_timing._UNITS and np.isfinite(value):
                found[used] = min(found.get(used, np.inf), value)
        best = found[max(found)]  # the most of the budget used, at the least energy
        chosen = program_timing._share(energy, durations, total)
        assert chosen is not None
        assert sum(energy[d, j] for j, d in enumerate(chosen)) == pytest.approx(best)


def test_straight_lines_from_tables_match_the_inverse_kinematics() -> None:
    """A lone tool line's joints from its quintic table against the exact inverse kinematics
    and Jacobians at 5000 random times of the palletising program."""
    from kinergy.io.urscript_reader import read_program
    from kinergy.trajectory.program_motion import line_tables, sample_path, schedule

    robot = load_robot("ur10e")
    path = program_path(robot, read_program(ROOT / "benchmarks/programs/ur10e_palletising.script"))
    sched = schedule(path, path.speed, path.accel)
    t = np.random.default_rng(3).uniform(0.0, float(sched.total[0]), (1, 5000))
    tables = line_tables(robot, path)
    assert len(tables) == sum(seg is not None for seg in path.tool)
    exact = sample_path(robot, path, sched, t)
    tabled = sample_path(robot, path, sched, t, tables=tables)
    for a, b, tol in zip(exact, tabled, (1e-12, 1e-9, 1e-6), strict=True):
        np.testing.assert_allclose(b, a, atol=tol)


def test_the_timing_solver_starts_from_the_better_start_and_keeps_the_cycle_time() -> None:
    from kinergy.optimize.program_repair import timing_checks
    from kinergy.optimize.program_timing import allocated, retime

    robot = load_robot("ur5e")
    path = program_path(robot, parse_program(SMALL, path="small.script"))
    own = simulate_path(robot, path)
    caps = Caps(float(np.max(np.abs(own.motion.qd))), float(np.max(np.abs(own.motion.qdd))))
    checks = timing_checks(robot, path, SupplyEnergy(), caps)
    budget = own.result.cycle_time
    shared = allocated(checks, budget)
    assert shared is not None
    start = checks.run(*shared, "allocated")
    assert start.cycle_time == pytest.approx(budget, abs=1e-6) and start.ok
    result, verified = retime(checks, budget)
    assert result.ok and result.cycle_time == pytest.approx(budget, abs=2e-3)
    assert result.score is not None and own.result.score is not None
    assert result.score <= min(start.score, own.result.score) + 1e-9  # type: ignore[type-var]
    assert verified.outcome is not None and "Iteration limit" not in verified.words


def test_another_cycle_time_is_kept_by_every_lever() -> None:
    """With a cycle time 25 % longer than the program's own, the search starts from the program
    uniformly slowed to it, and the optimum runs at it (never at the program's own)."""
    robot = load_robot("ur5e")
    program = parse_program(SMALL, path="small.script")
    own = simulate_path(robot, program_path(robot, program)).result.cycle_time
    result = optimize_program(
        robot, program, ProgramOptions(tool_symmetry=ToolSymmetry.Z, cycle_time=1.25 * own)
    )
    names = [lv.name for lv in result.levers]
    assert names[:2] == ["program", "uniform scaling"]
    assert result.levers[0].result.cycle_time == pytest.approx(own)
    for lever in result.levers[1:]:
        assert lever.result.cycle_time == pytest.approx(1.25 * own, abs=2e-3), lever.name
    assert result.optimized.result.cycle_time == pytest.approx(1.25 * own, abs=2e-3)
    assert result.optimized.result.ok and result.targets_met


def test_blends_go_only_between_joint_moves_so_straight_lines_stay_whole() -> None:
    """The blend lever rounds a movej into the next movej, never a corner into or out of a
    movel: the approach and the retreat of a pick stay straight in the 500 Hz simulation of the
    optimised program (the tool within 0.1 mm of each line)."""
    from kinergy.dynamics.poses import tcp_pose
    from kinergy.optimize.program_levers import via_blends
    from kinergy.trajectory.program_motion import program_motion
    from kinergy.trajectory.robot_program import Move

    robot = load_robot("ur5e")
    text = WRITER.replace(
        "  movej(above, a=1.4, v=1.05)  # over the part\n",
        "  movej([0.4, -1.5, 1.3, -1.4, -1.5708, 0.0], a=1.4, v=1.05)\n"
        "  movej(above, a=1.4, v=1.05)  # over the part\n",
    )
    program = parse_program(text, path="w.script")
    blended = via_blends(robot, program_path(robot, program))
    kinds = [m.kind for m in program.moves]
    assert kinds == ["movej", "movej", "movej", "movel", "movel", "movej"]
    # the first move starts where the program ends (home): it goes nowhere, nothing to round
    assert [m.r > 0 for m in blended] == [False, True, False, False, False, False]
    result = optimize_program(robot, program, ProgramOptions())
    written = result.written
    steps = written.steps
    for i in written.move_index:
        move = steps[i]
        if move.r > 0:
            after = steps[i + 1]
            assert isinstance(after, Move) and move.kind == after.kind == "movej", move.line
    path = program_path(robot, written)
    motion, _ = program_motion(robot, path)
    tool = np.array([tcp_pose(robot, q, path.tcp[0])[:3, 3] for q in motion.q])
    ends = [tcp_pose(robot, path.q0, path.tcp[0])[:3, 3]]
    ends += [tcp_pose(robot, path.q_end[k], path.tcp[k])[:3, 3] for k in range(path.moves)]
    lines = [k for k, m in enumerate(written.moves) if m.kind == "movel"]
    assert lines
    for k in lines:
        a, b = ends[k], ends[k + 1]
        u = (b - a) / np.linalg.norm(b - a)
        rel = tool - a
        along = rel @ u
        on = (along > 1e-4) & (along < np.linalg.norm(b - a) - 1e-4)
        off = np.linalg.norm(rel - np.outer(along, u), axis=1)
        near = on & (off < 0.02)  # the samples of this line (others are elsewhere in the cell)
        assert near.sum() > 20 and off[near].max() < 1e-4, k


def test_no_lever_buys_its_saving_with_a_longer_cycle() -> None:
    """A program at its own limits leaves no room: a lever whose program holds the limits only
    when it takes longer is not kept, and the timing reports itself not possible (it claimed
    17.8 % by taking 2.774 s for a 2.390 s cycle)."""
    from kinergy.optimize.program_levers import CYCLE_TOLERANCE, LeverStatus

    robot = load_robot("ur5e")
    text = "movej([0,-1.57,0,-1.57,0,0], a=1.4, v=1.05)\nmovej([0.5,-1.2,0.3,-1.57,0,0], a=1.4, v=1.05)\n"
    result = optimize_program(robot, parse_program(text, path="tight.script"))
    own = result.program.result.cycle_time
    assert result.optimized.result.cycle_time <= own + CYCLE_TOLERANCE
    for lever in result.levers:
        if lever.status is LeverStatus.KEPT:
            assert lever.result.cycle_time <= own + CYCLE_TOLERANCE, lever.name
    blends = next(lv for lv in result.levers if lv.name == "blends")
    assert blends.status is LeverStatus.OVER_LIMITS and "over the cycle time" in blends.note
