"""Intervals from a model's parameter errors: the storage, the propagation against Monte Carlo,
and the coverage on the realistic twin (issue 36)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import kinergy
from kinergy.accounting.energy import energy
from kinergy.errors import KinergyError
from kinergy.model.toml import robot_from_dict, robot_to_dict
from kinergy.model.uncertainty import Uncertainty, parameter_value, perturbed, t_quantile
from kinergy.trajectory.programs import paper_trajectory


def _with_errors(robot: kinergy.Robot, seed: int, rel: float = 0.03) -> kinergy.Robot:
    """``robot`` with made-up correlated errors (10 jackknife-like modes) on every joint's rotor
    inertia, torque constant and friction levels, and its standing draw."""
    names = []
    for j, joint in enumerate(robot.joints):
        names += [f"joints[{j}].rotor_inertia", f"joints[{j}].torque_constant"]
        names += [f"joints[{j}].friction.{p}" for p in joint.drive.friction.model.linear]
    names.append("standby_power")
    robot = dataclasses.replace(robot, standby_power=30.0)
    values = np.array([parameter_value(robot, n) for n in names])
    rng = np.random.default_rng(seed)
    modes = rng.normal(size=(10, len(names))) * rel * np.abs(values) / np.sqrt(10)
    u = Uncertainty(tuple(names), modes, 9, "test modes")
    return dataclasses.replace(robot, uncertainty=u)


def _short_motion(robot: kinergy.Robot) -> kinergy.Motion:
    m = paper_trajectory(robot, "test-a", dt=0.01)
    keep = slice(0, 400)
    return kinergy.Motion(t=m.t[keep], q=m.q[keep], qd=m.qd[keep], qdd=m.qdd[keep])


def test_uncertainty_round_trips_through_the_robot_file(ur5e):
    robot = _with_errors(ur5e, 0)
    back = robot_from_dict(robot_to_dict(robot))
    assert back.uncertainty is not None
    assert back.uncertainty.parameters == robot.uncertainty.parameters
    np.testing.assert_array_equal(back.uncertainty.modes, robot.uncertainty.modes)
    assert back.uncertainty.dof == 9
    bad = robot_to_dict(robot)
    bad["uncertainty"]["parameters"][0] = "joints[9].rotor_inertia"
    with pytest.raises(KinergyError, match="uncertainty.parameters"):
        robot_from_dict(bad)


def test_energy_interval_matches_monte_carlo(ur5e):
    """The delta method's standard deviation of the supply energy and of each joint's electrical
    energy against brute-force Monte Carlo (the whole energy recomputed for each parameter
    draw): the same draws' linear prediction to 1 %, the stated spread to the sampling error."""
    robot = _with_errors(ur5e, 1)
    motion = _short_motion(robot)
    report = energy(robot, motion)
    iv = report.intervals
    assert iv is not None
    u = robot.uncertainty
    rng = np.random.default_rng(7)
    draws = 600
    z = rng.normal(size=(draws, u.modes.shape[0]))
    exact, linear = [], []
    g = iv.gradients["drawn"]
    for k in range(draws):
        delta = z[k] @ u.modes
        moved = perturbed(robot, dict(zip(u.parameters, delta, strict=True)))
        exact.append(energy(moved, motion).supply.drawn)
        linear.append(g @ delta)
    exact_dev = np.array(exact) - report.supply.drawn
    linear_dev = np.array(linear)
    assert np.std(exact_dev) == pytest.approx(np.std(linear_dev), rel=0.01)
    # the stated spread is the draws' to within their sampling error (1/sqrt(2 x 600) = 3 %)
    assert iv.drawn.std == pytest.approx(np.std(exact_dev), rel=0.1)
    half = iv.drawn.high - report.supply.drawn
    assert half == pytest.approx(t_quantile(9) * iv.drawn.std)


def test_joint_interval_matches_monte_carlo(ur5e):
    robot = _with_errors(ur5e, 2)
    motion = _short_motion(robot)
    report = energy(robot, motion)
    u = robot.uncertainty
    rng = np.random.default_rng(8)
    devs = []
    for _ in range(300):
        delta = rng.normal(size=u.modes.shape[0]) @ u.modes
        moved = perturbed(robot, dict(zip(u.parameters, delta, strict=True)))
        devs.append(energy(moved, motion).e_elec - report.e_elec)
    spread = np.std(np.array(devs), axis=0)
    stated = np.array([i.std for i in report.intervals.e_elec])
    np.testing.assert_allclose(stated, spread, rtol=0.15)


def test_a_model_without_errors_says_so(ur5e):
    report = energy(ur5e, _short_motion(ur5e))
    assert report.intervals is None
    assert "no parameter errors" in report.to_dict()["intervals"]["note"]


def test_saving_interval_from_the_same_parameter_draws(ur5e):
    """The saving's gradient (program and optimised one on the same parameters) against the
    saving recomputed with the model moved along each error mode (both programs re-simulated
    at 500 Hz): the first-order change to 2 %; and the interval holds the saving."""
    from pathlib import Path

    from kinergy.io.urscript_reader import read_program
    from kinergy.optimize.programs import optimize_program
    from kinergy.optimize.verify import simulate_path

    robot = _with_errors(ur5e, 3)
    program = read_program(Path(__file__).parent / "programs" / "small.script")
    found = optimize_program(robot, program)
    iv = found.saving_interval
    assert iv is not None and iv.low < found.saving < iv.high
    u = robot.uncertainty
    objective = found.program.result  # the runs' scoring objective is the optimiser's

    def saving(moved: kinergy.Robot) -> float:
        import dataclasses

        def carried(path):  # the path's drive model is built once, for the robot it was made for
            robots = tuple(
                moved if p is robot.payload else moved.with_payload(p) for p in path.payloads
            )
            return dataclasses.replace(path, robots=robots)

        runs = [
            simulate_path(moved, carried(r.path), standby=moved.standby_power)
            for r in (found.program, found.optimized)
        ]
        return 1.0 - runs[1].result.e_supply / runs[0].result.e_supply

    assert objective.score is not None
    g = found.saving_gradient
    for k in range(2):
        delta = u.modes[k]
        moved = perturbed(robot, dict(zip(u.parameters, delta, strict=True)))
        change = saving(moved) - found.saving
        assert change == pytest.approx(g @ delta, rel=0.02, abs=1e-7)


def test_uncertainty_survives_the_urdf_export(ur5e, tmp_path):
    from kinergy.model.library import read_robot_file
    from kinergy.model.urdf_export import robot_to_urdf

    robot = _with_errors(ur5e, 4)
    path = tmp_path / "robot.urdf"
    path.write_text(robot_to_urdf(robot).text, encoding="utf-8")
    back = read_robot_file(path)
    assert back.uncertainty is not None
    np.testing.assert_allclose(back.uncertainty.modes, robot.uncertainty.modes)


def test_energy_intervals_cover_the_realistic_twin(ur5e, tmp_path):
    """Coverage on a fast seeded case (issue 36; ``benchmarks/bench_uncertainty.py twin`` is
    the full one): two realistic true arms, each identified (``--friction auto``) on its logs of
    test A and of a seeded 20 s Fourier excitation, predict the supply energy of test B and of
    two UR5e programs they never saw. The 95 % intervals hold at least 5 of the 6 logged
    supplies, are under 5 % of the energy wide, and their standard deviation is the errors'
    own size (RMS of error / std between 0.4 and 2: neither a zero-width nor a blanket
    interval); the calibrated t quantile takes the calibration blocks' degrees of freedom."""
    from kinergy.experiments.excitation_design import random_feasible
    from kinergy.experiments.excitation_problem import excitation_problem
    from kinergy.io.rtde import write_log
    from kinergy.io.urscript_reader import read_program
    from kinergy.trajectory.program_motion import program_motion
    from kinergy.trajectory.program_path import program_path
    from kinergy.twin import TwinSettings, realistic_truth, simulate

    programs = Path(__file__).resolve().parents[1] / "benchmarks" / "programs"
    unseen = [paper_trajectory(ur5e, "test-b")]
    for name in ("ur5e_conveyor_to_tray", "ur5e_sorting"):
        path = program_path(ur5e, read_program(programs / f"{name}.script"))
        unseen.append(program_motion(ur5e, path)[0])
    problem = excitation_problem(ur5e, harmonics=5, period=20.0)
    held, z, widths = 0, [], []
    for seed in (0, 1):
        truth = realistic_truth(ur5e, seed)
        excitation = random_feasible(problem, np.random.default_rng(seed))[0].motion
        logs = [
            simulate(truth, m, TwinSettings.realistic(1000 * seed + k))
            for k, m in enumerate((paper_trajectory(ur5e, "test-a"), excitation))
        ]
        model = kinergy.identify(logs, ur5e, kinergy.IdentifyOptions(friction="auto")).robot
        u = model.uncertainty
        assert u is not None and u.calibration >= 1.0
        if u.calibration > 1.0:
            assert u.dof > 9 and f"{u.dof} degrees of freedom" in u.method
        for k, motion in enumerate(unseen):
            log = simulate(truth, motion, TwinSettings.realistic(1000 * seed + 10 + k))
            path = tmp_path / f"{seed}-{k}.csv"
            write_log(path, log.t, log.signals)
            figures = kinergy.energy(model, path)
            measured, iv = figures.measured.drawn, figures.intervals.drawn
            held += iv.holds(measured)
            z.append((figures.supply.drawn - measured) / iv.std)
            widths.append(iv.half_width / measured)
    assert held >= 5
    assert max(widths) < 0.05
    assert 0.4 < np.sqrt(np.mean(np.square(z))) < 2.0
