"""The one optimiser on movej programs: task files read into the program type, the timing against
brute force on a toy arm, the UR5e test A result against an independent re-simulation and its
limits, the Pareto front, URScript output and the ``optimize`` command."""

from __future__ import annotations

import json
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import kinergy
from kinergy.accounting.energy import energy
from kinergy.cli import main
from kinergy.cli.optimize import optimize
from kinergy.drives.transmission import joint_torque
from kinergy.errors import KinergyError
from kinergy.io.task import load_task
from kinergy.io.urscript import program_script, write_script
from kinergy.io.urscript_reader import parse_program
from kinergy.model import Drive, Friction, Joint, Limits, Link, Robot
from kinergy.optimize import (
    ProgramOptions,
    ProgramSamples,
    SupplyEnergy,
    limit_violations,
    optimize_program,
    pareto_front,
    simulate_path,
)
from kinergy.optimize.problem import uniform_scaling
from kinergy.optimize.programs import MAX_MOVES
from kinergy.optimize.samples import durations, sample_path_programs
from kinergy.predict import drive_state
from kinergy.trajectory.movej import movej, plan_movej
from kinergy.trajectory.program_motion import line_tables
from kinergy.trajectory.program_path import program_path
from kinergy.trajectory.programs import paper_waypoints
from kinergy.trajectory.robot_program import Move, RobotProgram

# -- a toy arm ------------------------------------------------------------------------------------


def _toy_robot() -> Robot:
    """Two links in a vertical plane (gravity along -y of the base), 100:1 drives with viscous and
    Coulomb friction: a small arm whose optimum a brute-force search can find."""
    drive = Drive(
        gear_ratio=100.0,
        motor_inertia=5e-5,
        reducer_inertia=5e-5,
        torque_constant=0.1,
        motor_constant=0.15,
        kt_over_kb=0.9,
        friction=Friction("viscous_coulomb", {"viscous": 4e-4, "coulomb": 0.03, "smoothing": 1e-3}),
    )
    limits = Limits(position=np.array([-np.pi, np.pi]), speed=3.0, torque=80.0)
    joints = tuple(
        Joint(
            name=f"j{i + 1}",
            d=0.0,
            a=length,
            alpha=0.0,
            offset=0.0,
            link=Link(
                mass=mass,
                com=np.array([-length / 2, 0.0, 0.0]),
                inertia=np.array([0.002, 0.02, 0.02, 0.0, 0.0, 0.0]),
            ),
            drive=drive,
            limits=limits,
        )
        for i, (length, mass) in enumerate(((0.4, 3.0), (0.3, 1.5)))
    )
    return Robot(name="toy", convention="dh", joints=joints, gravity=np.array([0.0, -9.81, 0.0]))


TOY = _toy_robot()


def movej_program(
    waypoints: np.ndarray,
    v: float | np.ndarray,
    a: float | np.ndarray,
    blends: float | np.ndarray = 0.0,
    *,
    start: bool = True,
) -> RobotProgram:
    """A program of movej moves through ``waypoints`` (K + 1, n) from the first (``start``: an
    explicit start; else the program runs in cycles), joint-space blends in rad."""
    k = waypoints.shape[0] - 1
    v, a, r = (np.broadcast_to(np.asarray(x, dtype=float), (k,)) for x in (v, a, blends))
    moves = [
        Move("movej", waypoints[i + 1], pose=False, a=a[i], v=v[i], joint_blend=r[i], line=i + 1)
        for i in range(k)
    ]
    return RobotProgram("p", tuple(moves), start=waypoints[0] if start else None)


def _supply(robot: Robot, w: np.ndarray, v: object, a: object, blend: object = 0.0) -> float:
    """The supply energy of a movej program, independently of the optimiser: kinergy's movej
    planner at 500 Hz and the energy accounting (motors on the bus, braking lost), J."""
    motion = movej(w, speed=v, acceleration=a, blend=blend, dt=0.002)  # type: ignore[arg-type]
    return energy(robot, motion, recovery=False).total_e_elec


def _timing_only(**changes: object) -> ProgramOptions:
    """The timing lever alone on a toy's task: no blends, the toy's speed limit as the cap."""
    return ProgramOptions(blends=False, v_max=3.0, **changes)  # type: ignore[arg-type]


def test_one_move_matches_a_brute_force_search() -> None:
    # one move in a fixed time: the only freedom is the ramp (v and a tied by the duration);
    # a fine grid over it, every point re-simulated at 500 Hz, is the oracle
    w = np.array([[0.0, 0.0], [1.2, -0.6]])
    budget, a_max = 2.0, 20.0
    grid = np.linspace(0.02, 1.0, 150)
    ramp = 0.5 * grid * budget
    v = 1.2 / (budget - ramp)
    a = v / ramp
    ok = (v <= 3.0) & (a <= a_max)
    best = min(_supply(TOY, w, vk, ak) for vk, ak in zip(v[ok], a[ok], strict=True))
    options = _timing_only(cycle_time=budget, a_max=a_max)
    result = optimize_program(TOY, movej_program(w, 1.0, a_max), options)
    opt = result.optimized.result
    assert opt.ok
    assert opt.cycle_time == pytest.approx(budget, abs=2e-3)
    assert opt.e_supply == pytest.approx(best, rel=0.01)
    assert opt.e_supply <= best * 1.002  # a grid cannot beat the optimiser by much


def test_two_moves_match_a_brute_force_search_over_the_budget_share() -> None:
    # unblended moves are independent: E = E1(t1) + E2(T - t1), each minimised over its ramp
    w = np.array([[0.0, 0.0], [1.0, -0.5], [0.2, 0.4]])
    budget, a_max = 3.0, 15.0
    travel = np.max(np.abs(np.diff(w, axis=0)), axis=1)
    ramps = np.linspace(0.03, 1.0, 24)

    def best_move(k: int, t: float) -> float:
        out = np.inf
        for f in ramps:
            ramp = 0.5 * f * t
            v = travel[k] / (t - ramp)
            if v <= 3.0 and v / ramp <= a_max:
                out = min(out, _supply(TOY, w[k : k + 2], v, v / ramp))
        return out

    shares = np.linspace(0.3, 0.7, 21) * budget
    brute = min(best_move(0, t1) + best_move(1, budget - t1) for t1 in shares)
    options = _timing_only(cycle_time=budget, a_max=a_max)
    result = optimize_program(TOY, movej_program(w, 1.0, a_max), options)
    opt = result.optimized.result
    assert np.isfinite(brute)
    assert opt.ok
    assert opt.e_supply == pytest.approx(brute, rel=0.01)
    assert opt.e_supply <= brute * 1.002  # a grid cannot beat the optimiser by much


def squared_current(samples: ProgramSamples) -> tuple[np.ndarray, np.ndarray]:
    """A second objective, written as a user would: ``int sum_j I_j^2 dt`` (A^2 s), the
    windings' heating load."""
    return samples.integrate(np.sum(samples.drive.current**2, axis=1))


def test_a_plugged_in_objective_matches_a_brute_force_search_of_its_own() -> None:
    # the oracle of test_one_move_matches_a_brute_force_search, scored with the new objective
    # at 500 Hz: the solver minimises whatever objective it is given
    w = np.array([[0.0, 0.0], [1.2, -0.6]])
    budget, a_max = 2.0, 20.0
    grid = np.linspace(0.02, 1.0, 150)
    ramp = 0.5 * grid * budget
    v = 1.2 / (budget - ramp)
    a = v / ramp
    ok = (v <= 3.0) & (a <= a_max)
    path = program_path(TOY, movej_program(w, 1.0, a_max))
    best = min(
        simulate_path(TOY, path.with_timing(vk, ak), objective=squared_current).result.score
        for vk, ak in zip(v[ok], a[ok], strict=True)
    )
    options = _timing_only(cycle_time=budget, a_max=a_max)
    program = movej_program(w, 1.0, a_max)
    result = optimize_program(TOY, program, options, objective=squared_current)
    opt = result.optimized.result
    assert opt.ok and opt.cycle_time == pytest.approx(budget, abs=2e-3)
    assert opt.score == pytest.approx(best, rel=0.01)
    assert opt.score <= best * 1.002
    # the energy optimum is another timing, worse by this measure
    energy_opt = optimize_program(TOY, program, options).optimized
    other = simulate_path(TOY, energy_opt.path, objective=squared_current).result
    assert other.score is not None and other.score > opt.score * 1.01


def test_supply_energy_parts_add_up_and_agree_with_the_resimulation() -> None:
    w = np.array([[0.0, 0.0], [1.0, -0.5], [0.2, 0.4], [0.0, 0.0]])
    v, a = np.array([1.0, 2.0, 1.5]), np.array([3.0, 5.0, 4.0])
    blends = np.array([0.05, 0.1, 0.0])
    path = program_path(TOY, movej_program(w, v, a, blends))
    t, f = durations(path.travel, v, a)
    samples = sample_path_programs(TOY, path, t[None, :], f[None, :], tables=line_tables(TOY, path))
    for standby in (0.0, 40.0):
        total, parts = SupplyEnergy(standby)(samples)
        assert parts.sum(axis=1) == pytest.approx(total, rel=1e-12)
        run = simulate_path(TOY, path, standby=standby)
        again = run.result
        # the 500 Hz trapezoid sum is the energy accounting's (over the samples, to the first at
        # or after the end); the quadrature agrees closely
        assert again.score == pytest.approx(again.e_elec + standby * run.motion.t[-1], rel=1e-9)
        assert again.e_supply == pytest.approx(
            _supply(TOY, w, v, a, blends) + standby * again.cycle_time, rel=1e-9
        )
        assert total[0] == pytest.approx(again.e_supply, rel=2e-3)


def test_fixed_shares_keep_each_moves_share_of_the_time() -> None:
    w = np.array([[0.0, 0.0], [1.0, -0.5], [0.2, 0.4]])
    options = _timing_only(cycle_time=3.0, fixed_shares=True, a_max=10.0)
    result = optimize_program(TOY, movej_program(w, 1.0, 4.0), options)
    uniform = next(lv for lv in result.levers if lv.name == "uniform scaling").result
    share = uniform.durations / uniform.durations.sum()
    opt = result.optimized.result
    assert opt.durations / opt.durations.sum() == pytest.approx(share, rel=1e-3)
    assert opt.e_supply <= uniform.e_supply * (1 + 1e-9)


# -- the UR5e twin, test A --------------------------------------------------------------------------


@pytest.fixture(scope="module")
def test_a(ur5e: Robot) -> tuple[np.ndarray, object]:
    w = paper_waypoints(ur5e, 1)
    return w, optimize_program(ur5e, load_task("test-a", robot=ur5e))


def test_test_a_at_its_own_cycle_time_saves_energy(ur5e: Robot, test_a: tuple) -> None:
    w, result = test_a
    own = plan_movej(w, speed=3.0, acceleration=6.0).total_time
    assert result.program.result.cycle_time == pytest.approx(own)
    assert result.optimized.result.cycle_time == pytest.approx(own, abs=2e-3)
    assert result.optimized.result.e_supply <= result.program.result.e_supply
    # the 2 pi wraps, the blends and the timing; the timing alone (the Coulomb part of the
    # friction cannot be timed away) saves a few %
    assert result.saving > 0.05
    names = [lv.name for lv in result.levers if lv.kept]
    assert names[0] == "program" and "timing" in names


def _independent(result: object) -> tuple[np.ndarray, object]:
    """The optimised movej program re-planned by :func:`kinergy.trajectory.movej.movej` (not the
    optimiser's program sampler) at 500 Hz: its waypoints and motion."""
    opt = result.optimized  # type: ignore[attr-defined]
    w = np.vstack([opt.path.q0, opt.path.q_end])
    r = opt.result
    return w, movej(w, speed=r.speeds, acceleration=r.accels, blend=r.blends, dt=0.002)


def test_test_a_optimum_keeps_every_limit_at_every_sample(ur5e: Robot, test_a: tuple) -> None:
    _, result = test_a
    _, motion = _independent(result)
    state = drive_state(ur5e, motion.q, motion.qd, motion.qdd)
    # independently of LimitCheck: the robot's limits straight from the model
    speed = np.array([j.limits.speed for j in ur5e.joints])
    torque = np.array([j.limits.torque for j in ur5e.joints])
    lo = np.array([j.limits.position[0] for j in ur5e.joints])
    hi = np.array([j.limits.position[1] for j in ur5e.joints])
    assert np.all(np.abs(motion.qd) <= speed * (1 + 1e-9))
    assert np.all(np.abs(joint_torque(ur5e, state.tau_m)) <= torque)
    assert np.all((motion.q >= lo) & (motion.q <= hi))
    caps = result.settings.caps
    assert np.all(np.abs(motion.qd) <= caps.speed * (1 + 1e-6))
    assert np.all(np.abs(motion.qdd) <= caps.acceleration * (1 + 1e-6))
    assert limit_violations(ur5e, motion, state).ok
    opt = result.optimized.result
    assert opt.ok and not opt.check.violations()


def test_test_a_reported_energy_is_the_resimulated_energy(ur5e: Robot, test_a: tuple) -> None:
    _, result = test_a
    _, motion = _independent(result)
    opt = result.optimized.result
    assert energy(ur5e, motion, recovery=False).total_e_elec == pytest.approx(opt.e_elec, rel=1e-6)
    # the optimiser's own quadrature agrees with the 500 Hz re-simulation
    assert opt.predicted is None or opt.predicted == pytest.approx(opt.score, rel=0.005)
    assert opt.e_moves.sum() == pytest.approx(opt.score, rel=1e-9)
    # the parts are signed (braking returned); the motors' energy loses the surplus in the shunt
    signed = energy(ur5e, motion).total_e_elec
    assert sum(opt.breakdown.values()) == pytest.approx(signed, rel=1e-9)
    assert signed <= opt.e_elec


def test_another_cycle_time_starts_from_uniform_scaling(ur5e: Robot) -> None:
    w = paper_waypoints(ur5e, 1)[:4]
    program = movej_program(w, 2.0, 4.0)
    own = plan_movej(w, speed=2.0, acceleration=4.0).total_time
    result = optimize_program(ur5e, program, ProgramOptions(cycle_time=1.25 * own, blends=False))
    lever = next(lv for lv in result.levers if lv.name == "uniform scaling").result
    v, a = uniform_scaling(np.full(3, 2.0), np.full(3, 4.0), 1.0 / 1.25)
    assert lever.speeds == pytest.approx(v) and lever.accels == pytest.approx(a)
    assert lever.cycle_time == pytest.approx(1.25 * own)
    assert lever.e_elec == pytest.approx(_supply(ur5e, w, v, a), rel=1e-9)
    assert result.optimized.result.cycle_time == pytest.approx(1.25 * own, abs=2e-3)


def test_uniform_scaling_stretches_every_time_by_the_factor() -> None:
    w = np.array([[0.0, 0.0], [1.0, -0.5], [0.2, 0.4]])
    v, a = np.array([1.0, 2.0]), np.array([3.0, 5.0])
    plan = plan_movej(w, speed=v, acceleration=a, blend=[0.05, 0.0])
    sv, sa = uniform_scaling(v, a, 0.5)
    slow = plan_movej(w, speed=sv, acceleration=sa, blend=[0.05, 0.0])
    assert slow.total_time == pytest.approx(2.0 * plan.total_time)
    assert slow.start == pytest.approx(2.0 * plan.start)


def test_pareto_front_falls_with_cycle_time_and_beats_uniform_scaling(
    ur5e: Robot, test_a: tuple
) -> None:
    w, result = test_a
    own = result.program.result.cycle_time
    points = pareto_front(ur5e, result, cycle_times=[own, 1.3 * own, 1.8 * own])
    energies = np.array([p.optimized for p in points])
    times = np.array([p.cycle_time for p in points])
    # the supply's figure holds the standing draw over the cycle (~T); what the motors draw falls:
    # on the UR5e viscous friction (~1/T) outweighs the gravity copper loss (~T) over this range
    assert result.settings.standby > 0.0
    assert np.all(np.diff(energies - result.settings.standby * times) < 0.0)
    for p in points:
        assert p.optimized_ok and p.uniform_ok
        assert p.optimized <= p.uniform
    standing = result.settings.standby * points[0].cycle_time  # the standing draw over it
    assert points[0].uniform == pytest.approx(_supply(ur5e, w, 3.0, 6.0) + standing, rel=1e-9)


def test_blended_program_keeps_its_budget_and_limits(ur5e: Robot) -> None:
    # blends overlap the moves (not separable): the cycle time is kinergy's overlap rule
    w = paper_waypoints(ur5e, 1)[:5]
    blends = np.full(4, 0.1)
    blends[-1] = 0.0
    program = movej_program(w, 3.0, 6.0, blends)
    result = optimize_program(ur5e, program, ProgramOptions(cycle_time=10.0, blends=False))
    opt = result.optimized.result
    assert opt.blends.tolist() == blends.tolist()
    assert opt.cycle_time == pytest.approx(10.0, abs=2e-3)
    assert opt.ok
    uniform = next(lv for lv in result.levers if lv.name == "uniform scaling").result
    assert opt.e_supply <= uniform.e_supply
    _, motion = _independent(result)
    assert opt.e_elec == pytest.approx(energy(ur5e, motion, recovery=False).total_e_elec, rel=1e-6)


def test_a_repeated_waypoint_is_a_move_that_does_not_move(ur5e: Robot) -> None:
    w = paper_waypoints(ur5e, 1)
    w = np.vstack([w[:3], w[2:4]])  # move 3 stays where move 2 ended
    result = optimize_program(ur5e, movej_program(w, 3.0, 6.0))
    assert result.optimized.result.durations[2] == 0.0
    opt = result.optimized.result
    assert opt.ok and opt.e_supply <= result.program.result.e_supply


def test_a_cycle_time_below_the_fastest_feasible_is_refused(ur5e: Robot) -> None:
    w = paper_waypoints(ur5e, 1)[:3]
    program = movej_program(w, 3.0, 6.0)
    with pytest.raises(KinergyError, match="shorter than the fastest possible") as info:
        optimize_program(ur5e, program, ProgramOptions(cycle_time=0.5))
    assert "the longest move: line" in str(info.value)


def test_an_acceleration_cap_is_kept_and_reported(ur5e: Robot) -> None:
    w = paper_waypoints(ur5e, 1)[:4]
    result = optimize_program(
        ur5e, movej_program(w, 3.0, 6.0), ProgramOptions(a_max=6.0, blends=False)
    )
    _, motion = _independent(result)
    assert np.all(np.abs(motion.qdd) <= 6.0 * (1 + 1e-6))
    assert result.optimized.result.ok
    assert result.settings.caps.acceleration == 6.0
    assert result.optimized.result.e_supply <= result.program.result.e_supply


def test_limit_violations_finds_an_overspeed_and_an_overload(ur5e: Robot) -> None:
    w = paper_waypoints(ur5e, 1)[:2]
    motion = movej(w, speed=4.0, acceleration=6.0, dt=0.002)  # 4 rad/s > 180 deg/s
    check = limit_violations(ur5e, motion, drive_state(ur5e, motion.q, motion.qd, motion.qdd))
    assert not check.ok
    assert any(line.startswith("speed of") for line in check.violations())
    heavy = ur5e.with_payload(kinergy.Payload(mass=40.0))
    check = limit_violations(heavy, motion, drive_state(heavy, motion.q, motion.qd, motion.qdd))
    assert any(line.startswith("torque of") for line in check.violations())
    capped = limit_violations(
        ur5e, motion, drive_state(ur5e, motion.q, motion.qd, motion.qdd), acceleration_cap=5.0
    )
    assert any(line.startswith("acceleration of") for line in capped.violations())


# -- a task is a movej program -------------------------------------------------------------------

TASK = """
robot = "ur5e"
unit = "deg"
speed = 2.0
acceleration = 4.0
start = [0, -90, 0, -90, 0, 0]

[[move]]
q = [30, -80, 20, -90, 10, 0]

[[move]]
q = [-20, -100, 40, -70, 0, 30]
v = 1.5
a = 3.0
r = 0.05
ur_r = 0.02
"""


def _write(tmp_path: Path, text: str, name: str = "task.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_task_file_is_read_in_si_units(tmp_path: Path) -> None:
    task = load_task(_write(tmp_path, TASK))
    assert task.name == "task" and len(task.moves) == 2
    assert task.start == pytest.approx(np.radians([0, -90, 0, -90, 0, 0]))
    assert task.moves[1].target == pytest.approx(np.radians([-20, -100, 40, -70, 0, 30]))
    assert [m.kind for m in task.moves] == ["movej", "movej"]
    assert [m.v for m in task.moves] == [2.0, 1.5]
    assert [m.a for m in task.moves] == [4.0, 3.0]
    assert [m.joint_blend for m in task.moves] == [0.0, 0.05]  # rad, not degrees
    assert [m.r for m in task.moves] == [0.0, 0.02]
    assert [m.line for m in task.moves] == [8, 11]  # each [[move]] table's line


def test_task_defaults_start_at_the_last_target_and_missing_speeds_are_urscripts(
    tmp_path: Path,
) -> None:
    task = load_task(_write(tmp_path, "[[move]]\nq = [0.1, 0.2]\n[[move]]\nq = [0.3, -0.1]\n"))
    assert task.start is None  # a cycle: it starts where it ends
    assert [m.target.tolist() for m in task.moves] == [[0.1, 0.2], [0.3, -0.1]]
    assert [(m.a, m.v) for m in task.moves] == [(1.4, 1.05)] * 2  # a movej without them


def test_a_task_and_the_same_urscript_program_give_the_same_result(tmp_path: Path) -> None:
    """A task file and the URScript program of the same movej moves are one program type: the
    optimiser gives the same result to the last digit."""
    task = _write(
        tmp_path,
        "speed = 1.2\nacceleration = 2.5\n[[move]]\nq = [0.5, -1.4, 0.4, -1.6, 0.2, 0.0]\n"
        "[[move]]\nq = [-0.35, -1.75, 0.7, -1.2, 0.0, 0.5]\nv = 1.5\na = 3.0\nur_r = 0.02\n",
    )
    program = load_task(task)
    assert program.start is None
    text = program_script(program)
    script = parse_program(text, path="task.script")
    robot = kinergy.load_robot("ur5e")
    options = ProgramOptions(tool_symmetry=kinergy.optimize.ToolSymmetry.Z)
    a = optimize_program(robot, program, options).to_dict()
    b = optimize_program(robot, script, options).to_dict()
    # every figure the same; only the lines a target is named by are each file's own
    assert [c.pop("line") for c in a["targets"]] == [3, 5]  # the [[move]] tables
    assert [c.pop("line") for c in b["targets"]] == [2, 3]  # def, then the moves
    assert a["saving"] > 0.0
    assert json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


def test_a_task_written_for_another_robot_is_refused(tmp_path: Path, ur5e: Robot) -> None:
    """The task names the robot its poses were chosen for: another model is refused in one line
    naming both; the same robot (or a file of it, relative to the task) is accepted."""
    path = _write(tmp_path, TASK)
    assert len(load_task(path, robot=ur5e).moves) == 2
    ur10e = kinergy.load_robot("ur10e")
    with pytest.raises(KinergyError, match=r"task.toml: robot: the task was written for ur5e, "
                       r"the model is ur10e; give a ur5e model"):  # fmt: skip
        load_task(path, robot=ur10e)
    kinergy.save_robot(ur5e, tmp_path / "arm.toml")
    path = _write(tmp_path, TASK.replace('robot = "ur5e"', 'robot = "arm.toml"'), "t2.toml")
    assert len(load_task(path, robot=ur5e).moves) == 2
    with pytest.raises(KinergyError, match="written for ur5e, the model is ur10e"):
        load_task(path, robot=ur10e)


def test_builtin_tasks_are_the_papers_test_programs(ur5e: Robot) -> None:
    task = load_task("test-a", robot=ur5e)
    w = paper_waypoints(ur5e, 1)
    assert np.array([m.target for m in task.moves]) == pytest.approx(w[1:])
    assert task.start is None and w[0] == pytest.approx(w[-1])  # home, six points, home
    assert [m.v for m in task.moves] == [3.0] * 7 and [m.a for m in task.moves] == [6.0] * 7
    with pytest.raises(KinergyError, match="needs the robot"):
        load_task("test-b")


@pytest.mark.parametrize(
    ("text", "field"),
    [
        ('unit = "grad"\n[[move]]\nq = [0, 0]\n', "unit"),
        ("speed = 1.0\n", r"no \[\[move\]\]"),
        ("[[move]]\nv = 1.0\n", r"move\[1\]\.q: missing"),
        ("[[move]]\nq = [0, 0]\n[[move]]\nq = [0, 0, 0]\n", r"move\[2\]\.q: expected 2"),
        ("[[move]]\nq = [0, 'a']\n", r"move\[1\]\.q\[1\]"),
        ("[[move]]\nq = [0, 0]\nv = -1\n", r"move\[1\]\.v: must be a finite number > 0"),
        ("[[move]]\nq = [0, 0]\nr = -0.1\n", r"move\[1\]\.r: must be a finite number >= 0"),
        ("[[move]]\nq = [0, 0]\nspeed = 1\n", r"move\[1\]: unknown field 'speed'"),
        ("velocity = 1\n[[move]]\nq = [0, 0]\n", "unknown field 'velocity'"),
        ("start = [0]\n[[move]]\nq = [0, 0]\n", "start: expected 2"),
        ("[[move]\nq = [0, 0]\n", "not valid TOML"),
    ],
)
def test_task_file_errors_are_one_line_naming_file_and_field(
    tmp_path: Path, text: str, field: str
) -> None:
    path = _write(tmp_path, text)
    with pytest.raises(KinergyError, match=field) as info:
        load_task(path)
    message = str(info.value)
    assert message.startswith(str(path)) and "\n" not in message


def test_task_poses_must_fit_the_robot(tmp_path: Path, ur5e: Robot) -> None:
    with pytest.raises(KinergyError, match=r"move\[1\]\.q: expected 6 joint angles, got 2"):
        load_task(_write(tmp_path, "[[move]]\nq = [0, 0]\n"), robot=ur5e)
    with pytest.raises(KinergyError, match="no such task file"):
        load_task(tmp_path / "missing.toml")


# -- URScript -----------------------------------------------------------------------------------------

_MOVEJ = re.compile(r"^\s*movej\(\[([^\]]*)\], a=([^,]+), v=([^,)]+)(?:, r=([^)]+))?\)$")


def test_a_task_written_as_urscript() -> None:
    rng = np.random.default_rng(3)
    w = rng.uniform(-2.0, 2.0, (5, 6))
    w[2, 3] = 1.5e-6  # plain decimals, never an exponent
    v, a = rng.uniform(0.5, 3.0, 4), rng.uniform(1.0, 20.0, 4)
    program = replace(movej_program(w, v, a, start=False), name="demo-task")
    text = program_script(program, ["a header"])
    lines = text.splitlines()
    assert lines[0] == "def demo_task():" and lines[-1] == "end"
    moves = [_MOVEJ.match(line) for line in lines if "movej(" in line]
    assert len(moves) == 4 and all(moves)
    for k, match in enumerate(moves):
        assert match is not None
        q = [float(x) for x in match.group(1).split(",")]
        assert q == pytest.approx(w[k + 1], abs=1e-8)
        assert float(match.group(2)) == pytest.approx(a[k], rel=1e-8)
        assert float(match.group(3)) == pytest.approx(v[k], rel=1e-8)
        assert match.group(4) is None
    assert "  # a header" in lines
    assert not any(re.search(r"\de", line) for line in lines if "movej(" in line)
    back = parse_program(text, path="demo.script")
    assert np.array([m.target for m in back.moves]) == pytest.approx(w[1:], abs=1e-8)
    assert replace(program, name="1bad").name == "1bad"
    assert program_script(replace(program, name="1bad")).startswith("def kinergy_1bad():")


def test_urscript_writes_atomically(tmp_path: Path) -> None:
    w = np.zeros((2, 6))
    w[1, 0] = 1.0
    with pytest.raises(KinergyError, match="a must be > 0"):
        movej_program(w, 1.0, 0.0)
    path = write_script(tmp_path / "out" / "p.script", program_script(movej_program(w, 1.0, 1.0)))
    assert path.read_text().startswith("def p():")
    assert [p.name for p in path.parent.iterdir()] == ["p.script"]


# -- the command ------------------------------------------------------------------------------------

SMALL = """
unit = "deg"
speed = 3.0
acceleration = 6.0
start = [0, -90, 0, -90, 0, 0]

[[move]]
q = [60, -60, 40, -100, 30, 20]

[[move]]
q = [-30, -110, 70, -80, -20, 90]

[[move]]
q = [0, -90, 0, -90, 0, 0]
"""


def test_command_json_urscript_and_plot(tmp_path: Path) -> None:
    task = _write(tmp_path, SMALL)
    script, plot = tmp_path / "prog.script", tmp_path / "pareto.png"
    args = ["ur5e", str(task), "--json", "--urscript", str(script), "--plot", str(plot)]
    result = CliRunner().invoke(optimize, [*args, "--pareto-points", "3"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.output, parse_constant=lambda c: pytest.fail(f"{c} in JSON"))
    for key in ("program", "optimized", "saving", "saving_supply", "saving_motors", "pareto"):
        assert key in out
    assert [set(m) >= {"v", "a", "duration"} for m in out["optimized"]["moves"]] == [True] * 3
    assert out["optimized"]["e_supply"] <= out["program"]["e_supply"]
    assert out["saving"] == pytest.approx(
        1 - out["optimized"]["e_supply"] / out["program"]["e_supply"]
    )
    assert out["saving_motors"] == pytest.approx(
        1 - out["optimized"]["e_elec"] / out["program"]["e_elec"]
    )
    assert out["optimized"]["within_limits"] is True
    assert len(out["pareto"]) >= 3
    assert script.read_text().count("movej(") == 3  # the three moves (the cycle closes)
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_command_text_report(tmp_path: Path) -> None:
    task = _write(tmp_path, SMALL)
    result = CliRunner().invoke(optimize, ["ur5e", str(task), "--cycle-time", "6"])
    assert result.exit_code == 0, result.output
    assert "Saving:" in result.output and "active limits:" in result.output
    assert "uniform scaling" in result.output and "of the motors' energy" in result.output


@pytest.mark.parametrize(
    ("args", "match", "status"),
    [  # 2: the options refuse the value (a usage error); 1: the run refuses it
        (["--cycle-time", "fast"], "--cycle-time", 2),
        (["--cycle-time", "0.5"], "shorter than the fastest possible", 1),
        (["--a-max", "-1"], "--a-max: must be a finite number >= 0.001", 2),
        (["--pareto-points", "0", "--plot", "x.png"], "--plot", 1),
    ],
)
def test_command_errors_are_one_line_and_leave_no_file(
    tmp_path: Path, args: list[str], match: str, status: int, capsys: pytest.CaptureFixture[str]
) -> None:
    task = _write(tmp_path, SMALL)
    script = tmp_path / "prog.script"
    assert main(["optimize", "ur5e", str(task), "--urscript", str(script), *args]) == status
    err = capsys.readouterr().err
    assert re.search(match, err) and err.count("\n") == 1 and err.startswith("kinergy: error: ")
    assert not script.exists()


def test_command_bad_task_file(tmp_path: Path) -> None:
    task = _write(tmp_path, "[[move]]\nq = [0, 0]\n", "bad.toml")
    script = tmp_path / "prog.script"
    result = CliRunner().invoke(optimize, ["ur5e", str(task), "--urscript", str(script)])
    assert result.exit_code == 1
    assert isinstance(result.exception, KinergyError)
    message = str(result.exception)
    assert "bad.toml" in message and "move[1].q" in message and "\n" not in message
    assert not script.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


def test_a_task_over_the_move_cap_is_refused_in_one_line_at_once(tmp_path: Path) -> None:
    rng = np.random.default_rng(7)
    moves = "".join(
        f"[[move]]\nq = {[round(float(x), 3) for x in rng.uniform(-1, 1, 6)]}\n"
        for _ in range(MAX_MOVES + 1)
    )
    task = tmp_path / "big.toml"
    task.write_text("speed = 1.0\nacceleration = 2.0\n" + moves)
    result = CliRunner().invoke(optimize, ["ur5e", str(task)])
    assert result.exit_code != 0
    assert f"{MAX_MOVES + 1} moves; the optimiser takes at most {MAX_MOVES}" in str(
        result.output + str(result.exception)
    )
