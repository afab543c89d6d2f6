"""Excitation design (nursing eqs 22-23): optimised Fourier trajectories for identification.

Relations checked:
- the parametrisation meets the boundary conditions (start pose, zero speed and acceleration at
  both ends) for any unknowns, and agrees with :func:`fourier_series` (nursing eq 22);
- the criterion's and the constraints' derivatives agree with central differences;
- the optimised trajectory's condition number is at least 5x below the median of 50 random
  feasible trajectories of the same size (test size: 3 harmonics, 100 grid points, one start of
  60 iterations; the full size, 5 harmonics and 200 points, is measured in the report);
- every 2 ms sample meets every limit, checked here from the robot's data and kinematics, not
  from the problem's own margins;
- the full identification from the twin's log of the excitation recovers the true base
  parameters within 2 % (target_moment, exact and default noisy twin), and with noisy currents
  the optimised excitation identifies them better than a random one of median condition;
- the URScript program has the structure of a movement program and reproduces the samples;
- the ``excite`` command writes a motion file the twin runs, prints the JSON keys, and reports
  bad input in one line.
"""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import kinergy
from kinergy.cli import main as cli_main
from kinergy.cli.excite import excite
from kinergy.experiments.excitation_design import (
    Excitation,
    design_excitation,
    random_feasible,
)
from kinergy.experiments.excitation_limits import excitation_limits
from kinergy.experiments.excitation_problem import ExcitationProblem, excitation_problem
from kinergy.identification.full import identify_full
from kinergy.identification.physical import parameter_scale
from kinergy.io.rtde import read_log
from kinergy.io.urscript import servoj_program
from kinergy.logs.prepare import prepare
from kinergy.trajectory.fourier import fourier_series
from kinergy.trajectory.motion import Motion
from kinergy.twin import TwinSettings, simulate

HOME = np.array([0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0])


# ------------------------------------------------------------------------------------ fixtures


@pytest.fixture(scope="module")
def problem(ur5e: kinergy.Robot) -> ExcitationProblem:
    """Test size: 3 harmonics, period 10 s, 100 grid points per period."""
    return excitation_problem(ur5e, harmonics=3, period=10.0, samples=100)


@pytest.fixture(scope="module")
def designed(problem: ExcitationProblem) -> Excitation:
    return design_excitation(problem, starts=1, maxiter=60, seed=0)


@pytest.fixture(scope="module")
def randoms(problem: ExcitationProblem) -> list[Excitation]:
    return random_feasible(problem, np.random.default_rng(123), 50)


def base_truth(robot: kinergy.Robot) -> np.ndarray:
    return kinergy.base_parameters(robot).project(kinergy.inertial_parameters(robot))


def typical_base(robot: kinergy.Robot) -> np.ndarray:
    """Typical size of each base parameter: its combination applied to the standard parameters'
    typical sizes (kg, kg m, kg m^2 from each link's mass and 0.1 m)."""
    base = kinergy.base_parameters(robot)
    p_mat = np.zeros((base.size, 10 * robot.n))
    p_mat[:, base.independent] = np.eye(base.size)
    p_mat[:, base.dependent] = base.beta
    return np.abs(p_mat) @ parameter_scale(robot)


def base_errors(values: np.ndarray, robot: kinergy.Robot) -> np.ndarray:
    """``|value - truth| / |truth|``; for base parameters that are zero in the truth (symmetric
    links, centres of mass on an axis) ``|value| / typical size``."""
    truth = base_truth(robot)
    typical = typical_base(robot)
    zero = np.abs(truth) < 1e-9 * typical
    return np.abs(values - truth) / np.where(zero, typical, np.abs(truth))


def links_perturbed(robot: kinergy.Robot, seed: int, spread: float = 0.2) -> kinergy.Robot:
    """Masses, centres of mass and inertias each scaled by a seeded factor in 1 +- spread (the
    drives stay the truth's: the rotor inertias that merge into link parameters on a UR arm then
    carry no offset, and the base parameters compare with the truth's directly)."""
    rng = np.random.default_rng(seed)
    joints = []
    for j in robot.joints:
        f = 1.0 + rng.uniform(-spread, spread, 3)
        link = dataclasses.replace(
            j.link, mass=j.link.mass * f[0], com=j.link.com * f[1], inertia=j.link.inertia * f[2]
        )
        joints.append(dataclasses.replace(j, link=link))
    return robot.with_joints(joints)


def identified_base(
    robot: kinergy.Robot, motion: Motion, settings: TwinSettings, target: str
) -> tuple[np.ndarray, np.ndarray]:
    """Base parameters identified by the full method from the twin's log of ``motion``, starting
    from perturbed links, and their standard deviations."""
    data = prepare(simulate(robot, motion, settings), robot.n)
    result = identify_full(links_perturbed(robot, seed=2), [data], target=target)
    values = np.array([p.value for p in result.fit.base_parameters])
    std = np.array([p.std for p in result.fit.base_parameters])
    return values, std


# ------------------------------------------------------------------------ the parametrisation


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_any_unknowns_meet_the_boundary_conditions(problem: ExcitationProblem, seed: int) -> None:
    z = np.random.default_rng(seed).normal(0.0, 0.3, problem.size)
    q0, a, b = problem.coefficients(z)
    ends = np.array([0.0, problem.period, 3.0 * problem.period])
    q, qd, qdd = fourier_series(ends, q0, a, b, problem.base_frequency)
    np.testing.assert_allclose(q, np.tile(HOME, (3, 1)), atol=1e-12)
    np.testing.assert_allclose(qd, 0.0, atol=1e-12)
    np.testing.assert_allclose(qdd, 0.0, atol=1e-12)
    # the problem's own states are nursing eq 22 with these coefficients
    q, qd, qdd = fourier_series(problem.grid.t, q0, a, b, problem.base_frequency)
    for mine, eq22 in zip(problem.states(z), (q, qd, qdd), strict=True):
        np.testing.assert_allclose(mine, eq22, atol=1e-12)


@pytest.mark.parametrize("criterion", ["cond", "dopt"])
def test_criterion_gradient_matches_central_differences(
    ur5e: kinergy.Robot, problem: ExcitationProblem, criterion: str
) -> None:
    p = problem if criterion == "cond" else dataclasses.replace(problem, criterion="dopt")
    z = p.random_start(np.random.default_rng(4))
    _, grad = p.objective(z)
    rng = np.random.default_rng(5)
    for _ in range(3):
        d = rng.standard_normal(z.size)
        h = 1e-5
        numeric = (p.objective(z + h * d)[0] - p.objective(z - h * d)[0]) / (2 * h)
        assert grad @ d == pytest.approx(numeric, rel=1e-4, abs=1e-7)
    # the optimised value is the condition number's logarithm
    if criterion == "cond":
        assert np.exp(p.objective(z)[0]) == pytest.approx(p.condition(z), rel=1e-6)


def test_constraint_jacobian_matches_central_differences(problem: ExcitationProblem) -> None:
    z = problem.random_start(np.random.default_rng(6))
    jac = problem.constraints_jacobian(z)
    h = 1e-6
    numeric = np.column_stack(
        [
            (problem.constraints(z + h * e) - problem.constraints(z - h * e)) / (2 * h)
            for e in np.eye(z.size)
        ]
    )
    np.testing.assert_allclose(jac, numeric, atol=1e-6)


# ---------------------------------------------------------------------------- the optimisation


def test_optimised_condition_is_five_times_below_the_random_median(
    designed: Excitation, randoms: list[Excitation]
) -> None:
    median = float(np.median([r.condition for r in randoms]))
    assert designed.condition <= median / 5.0, (designed.condition, median)
    assert designed.criterion == "cond" and len(designed.history) == designed.iterations + 1
    assert designed.history[-1] < designed.history[0]


def check_every_sample(robot: kinergy.Robot, motion: Motion, period: float) -> None:
    """The issue's limits from the robot's data: +-90 deg about the UR home within the joint
    limits, the speed limits, 2/s times them for accelerations (the UR5e publishes none), every
    link frame from the elbow on and the flange 5 cm above the base plane; rest in the home pose
    at the start, at the end and at every period boundary."""
    q, qd, qdd, t = motion.q, motion.qd, motion.qdd, motion.t
    dt = np.diff(t)
    np.testing.assert_allclose(dt, 0.002, rtol=1e-9)
    limits = np.array([j.limits.position for j in robot.joints])
    lower = np.maximum(limits[:, 0], HOME - np.pi / 2)
    upper = np.minimum(limits[:, 1], HOME + np.pi / 2)
    speed = np.array([j.limits.speed for j in robot.joints])
    assert np.all(q >= lower) and np.all(q <= upper)
    assert np.all(np.abs(qd) <= speed)
    assert np.all(np.abs(qdd) <= 2.0 * speed)
    heights = kinergy.link_poses(robot, q)[:, 1:, 2, 3]
    assert np.all(heights >= 0.05)
    assert np.all(kinergy.flange_pose(robot, q)[:, 2, 3] >= 0.05)
    boundaries = np.flatnonzero(np.isclose(np.mod(t + 1e-9, period), 1e-9, atol=1e-6))
    assert boundaries.size == round(motion.duration / period) + 1
    for k in boundaries:
        np.testing.assert_allclose(q[k], HOME, atol=1e-12)
        np.testing.assert_allclose(qd[k], 0.0, atol=1e-12)
        np.testing.assert_allclose(qdd[k], 0.0, atol=1e-12)


def test_every_sample_of_the_optimised_and_random_ones_meets_every_limit(
    ur5e: kinergy.Robot, designed: Excitation, randoms: list[Excitation]
) -> None:
    check_every_sample(ur5e, designed.repeated(2), designed.period)
    assert len(designed.motion) == 5001
    assert min(v for k, v in designed.margins.items() if k != "boundary") >= 0.0
    assert designed.margins["boundary"] < 1e-12
    for r in randoms[:10]:
        check_every_sample(ur5e, r.motion, r.period)
    # the random draws use the room the limits give: some limit binds within 1 %
    speed = min(j.limits.speed for j in ur5e.joints)
    for r in randoms:
        m = r.margins
        binding = min(
            m["speed"] / speed,
            m["acceleration"] / (2 * speed),
            m["position"] / (np.pi / 2),
            m["floor"] / 1.0,
        )
        assert binding < 0.01, m


def test_d_optimality_and_bad_options(ur5e: kinergy.Robot) -> None:
    p = excitation_problem(ur5e, harmonics=2, samples=40, criterion="dopt")
    best = design_excitation(p, starts=1, maxiter=15)
    start = p.random_start(np.random.default_rng(0))
    assert best.d_criterion < p.d_criterion(start)
    assert best.criterion == "dopt"
    for kwargs, message in (
        ({"harmonics": 1}, "harmonics must be >= 2"),
        ({"harmonics": 0}, "harmonics must be >= 2"),
        ({"period": 0.0}, "period: must be a finite number > 0"),
        ({"criterion": "e-opt"}, "unknown criterion"),
        ({"samples": 5}, "samples must be"),
        ({"limits": excitation_limits(kinergy.load_robot("panda"))}, "limits for 7 joints"),
    ):
        with pytest.raises(kinergy.KinergyError, match=message):
            excitation_problem(ur5e, **kwargs)
    for kwargs, message in (
        ({"floor": 2.0}, "not above the floor"),
        ({"start": [0.0] * 5}, "start pose"),
        ({"speed": 0.0}, "speed limit of joint 1"),
        ({"position_range": -1.0}, "position range: must be finite numbers, each > 0"),
        ({"floor_frames": "tool"}, "unknown floor_frames"),
    ):
        with pytest.raises(kinergy.KinergyError, match=message):
            excitation_limits(ur5e, **kwargs)


# ----------------------------------------------------------------------------- identification


@pytest.mark.parametrize(
    "settings", [TwinSettings.exact(), TwinSettings(seed=5)], ids=["exact", "noisy"]
)
def test_full_identification_recovers_the_base_parameters_within_two_percent(
    ur5e: kinergy.Robot, designed: Excitation, settings: TwinSettings
) -> None:
    values, _ = identified_base(ur5e, designed.repeated(2), settings, "moment")
    errors = base_errors(values, ur5e)
    assert errors.max() < 0.02, errors.max()


def test_with_noisy_currents_the_optimised_excitation_identifies_more_precisely(
    ur5e: kinergy.Robot, designed: Excitation, randoms: list[Excitation]
) -> None:
    """target_moment is noise-free in the twin; the currents are not (0.04 A, 4 ms lag). The
    standard deviations of a current-based identification (the covariance of the fit, set by the
    excitation) are well below those of a random draw of median condition number."""
    order = np.argsort([r.condition for r in randoms])
    typical = randoms[order[len(order) // 2]]
    noisy = TwinSettings(seed=5)
    scale = typical_base(ur5e)
    _, std_opt = identified_base(ur5e, designed.repeated(2), noisy, "current")
    _, std_rnd = identified_base(ur5e, typical.repeated(2), noisy, "current")
    assert np.median(std_opt / scale) < 0.5 * np.median(std_rnd / scale)


# ---------------------------------------------------------------------------------- URScript

_NUMBER = r"-?\d+(?:\.\d+)?"
_VECTOR = rf"\[({_NUMBER}(?:, {_NUMBER}){{5}})\]"


def test_urscript_is_a_servoj_movement_program(designed: Excitation) -> None:
    motion = designed.motion
    text = servoj_program(motion.t, motion.q, name="kinergy_excitation")
    lines = text.splitlines()
    assert text.endswith("end\n")
    assert lines[0] == "def kinergy_excitation():" and lines[-1] == "end"
    body = lines[1:-1]
    assert all(line.startswith("  ") and not line.startswith("   ") for line in body)
    assert sum(line.strip().startswith("def ") for line in lines) == 1
    assert not any(re.search(r"\d[eE][-+]?\d", line) for line in lines)  # no exponents
    code = [line.strip() for line in body if not line.strip().startswith("#")]
    move = re.fullmatch(rf"movej\({_VECTOR}, a={_NUMBER}, v={_NUMBER}\)", code[0])
    assert move is not None
    np.testing.assert_allclose([float(x) for x in move.group(1).split(",")], motion.q[0], atol=1e-9)
    servo = [re.fullmatch(rf"servoj\({_VECTOR}, 0, 0, 0\.002, 0\.1, 300\)", c) for c in code[1:-1]]
    assert len(servo) == len(motion) and all(m is not None for m in servo)
    parsed = np.array([[float(x) for x in m.group(1).split(",")] for m in servo if m is not None])
    np.testing.assert_allclose(parsed, motion.q, atol=1e-9)
    assert re.fullmatch(rf"stopj\({_NUMBER}\)", code[-1])


def test_urscript_refuses_what_servoj_cannot_run() -> None:
    t = np.arange(5) * 0.002
    q = np.zeros((5, 6))
    for args, kwargs, message in (
        ((t, np.zeros((5, 7))), {}, "6 entries"),
        ((np.array([0, 0.002, 0.005, 0.006, 0.008]), q), {}, "uniform steps"),
        ((t / 2, q), {}, "controller's cycle"),
        ((t, q), {"gain": 50.0}, "gain"),
        ((t, q), {"lookahead_time": 0.5}, "lookahead_time"),
        ((t, q), {"name": "1bad"}, "program name"),
    ):
        with pytest.raises(kinergy.KinergyError, match=message):
            servoj_program(*args, **kwargs)


# ------------------------------------------------------------------------------- the command

_FAST = ["--harmonics", "2", "--samples", "40", "--starts", "1", "--maxiter", "8", "--quiet"]


def test_cli_writes_the_motion_and_script_and_the_twin_runs_it(tmp_path: Path) -> None:
    motion_path, script_path = tmp_path / "motion.csv", tmp_path / "excite.script"
    result = CliRunner().invoke(
        excite,
        [
            "ur5e",
            *_FAST,
            "--periods",
            "1",
            "--compare",
            "3",
            "--json",
            "--out",
            str(motion_path),
            "--urscript",
            str(script_path),
        ],
    )
    assert result.exit_code == 0, result.output
    report = json.loads(result.stdout)
    for key in (
        "robot",
        "condition",
        "harmonics",
        "period",
        "periods",
        "margins",
        "random",
        "ratio",
        "a",
        "b",
        "q0",
        "start",
        "seconds",
        "out",
        "urscript",
    ):
        assert key in report
    assert report["random"]["count"] == 3 and report["ratio"] == pytest.approx(
        report["random"]["median"] / report["condition"]
    )
    assert min(v for k, v in report["margins"].items() if k != "boundary") >= 0.0
    log = read_log(motion_path)
    assert {"target_q", "target_qd", "target_qdd"} <= set(log.signals)
    assert len(log) == 5001 and log.t[-1] == pytest.approx(10.0)
    np.testing.assert_allclose(log["target_q"][0], HOME, atol=1e-9)
    assert script_path.read_text().count("\n  servoj(") == 5001
    # the twin simulates the motion file
    out = tmp_path / "twin.csv"
    assert cli_main(["simulate", "ur5e", "--trajectory", str(motion_path), "--out", str(out)]) == 0
    twin = read_log(out)
    assert "target_moment" in twin and len(twin) == 5001
    np.testing.assert_allclose(twin["target_q"], log["target_q"], atol=1e-8)


def test_cli_text_output_reports_condition_and_margins(tmp_path: Path) -> None:
    result = CliRunner().invoke(excite, ["ur5e", *_FAST, "--out", str(tmp_path / "m.csv")])
    assert result.exit_code == 0, result.output
    assert "condition number" in result.stdout and "margins to the limits" in result.stdout


@pytest.mark.parametrize(
    ("args", "status"),
    [  # 2: a value the options refuse on construction (a usage error); 1: what the run refuses
        (["nosuchrobot"], 1),
        (["ur5e", "--harmonics", "0"], 2),
        (["ur5e", "--harmonics", "1"], 2),
        (["ur5e", "--period", "0"], 2),
        (["ur5e", "--period", "-3"], 2),
        (["ur5e", "--floor", "1.5"], 1),
        (["ur5e", "--start-deg", "0,0,0"], 1),
        (["ur5e", "--start-deg", "0,-90,zero,-90,0,0"], 2),
        (["ur5e", "--periods", "0"], 2),
        (["ur5e", "--compare", "-1"], 2),
        (["ur5e", "--range-deg", "0"], 2),
        (["ur5e", "--speed", "nan"], 2),
        (["panda", "--urscript", "never-written.script"], 1),
    ],
)
def test_cli_errors_are_one_line_and_leave_no_file(
    tmp_path: Path, args: list[str], status: int, capsys: pytest.CaptureFixture[str]
) -> None:
    """Through the entry point (:func:`kinergy.cli.main`), which turns a KinergyError into one
    line and exit status 1 (2 for a value the option's type refuses, a usage error)."""
    out = tmp_path / "m.csv"
    got = cli_main(["excite", *_FAST, *args, "--out", str(out)])
    captured = capsys.readouterr()
    assert got == status, captured.err
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("kinergy: error: "), captured.err
    assert captured.out == ""
    assert not out.exists() and not Path("never-written.script").exists()


def test_criterion_gradient_is_close_to_exact(problem: ExcitationProblem) -> None:
    """The regressor's derivative is exact in qd and qdd and a 1e-5 rad central step in q: the
    directional derivative agrees with a central difference of the criterion to 1e-6."""
    z = problem.random_start(np.random.default_rng(7))
    _, grad = problem.objective(z)
    d = np.random.default_rng(8).standard_normal(z.size)
    h = 1e-5
    numeric = (problem.objective(z + h * d)[0] - problem.objective(z - h * d)[0]) / (2 * h)
    assert grad @ d == pytest.approx(numeric, rel=1e-6)
