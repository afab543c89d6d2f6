"""The coupled-drive nursing arm's identification (nursing doc sections 3-4): the particle swarm,
eq 21 and the coupling's sign convention, the odd/even friction split, Makkar fits on the twin's
constant-speed runs, cycle averaging, ridge regression of the minimal set and ``kinergy nursing``.
Every random draw is seeded."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from click.testing import CliRunner

import kinergy
import kinergy.api
from kinergy.cli import nursing as nursing_cmd
from kinergy.drives.coupled import (
    coupled_torques,
    joint_friction,
    joint_kind,
    joint_torques_from_current,
    makkar_joint_side,
    makkar_motor_side,
    torque_from_current,
)
from kinergy.drives.transmission import joint_torque, motor_speed, transmission_matrix
from kinergy.dynamics.regressor import base_parameters, inertial_parameters, regressor
from kinergy.errors import KinergyError
from kinergy.experiments.friction_runs import back_and_forth_motion
from kinergy.experiments.nursing_doc import BASE_FREQUENCY, DOC_EQ21
from kinergy.experiments.nursing_excitation import table6_motion
from kinergy.friction.makkar import makkar
from kinergy.identification import nursing as nu
from kinergy.identification.cycles import cycle_average, find_period
from kinergy.identification.friction_points import (
    constant_speed_runs,
    friction_points,
    odd_even_friction,
)
from kinergy.identification.makkar_fit import fit_makkar_lsq, fit_makkar_pso
from kinergy.identification.pso import constriction, particle_swarm
from kinergy.identification.ridge import ridge_minimal
from kinergy.io.log import Log
from kinergy.logs.prepare import prepare
from kinergy.model import load_robot, save_robot
from kinergy.model.robot import Limits
from kinergy.trajectory.fourier import fourier_motion
from kinergy.twin import TwinSettings, simulate

#: the nursing arm's joint-side Makkar curve (its file's header): the mean of Table 4's two
TWIN_GAMMA = np.array([30.137, 9.295, 5.895, 20.884, 12.998, 1.812])


@pytest.fixture(scope="module")
def arm() -> kinergy.Robot:
    return load_robot("nursing-arm")


def _twin_data(robot: kinergy.Robot, motion, settings: TwinSettings, name: str):
    return prepare(simulate(robot, motion, settings, name=name), robot.n)


# ---------------------------------------------------------------------------------------------
# particle swarm


def test_constriction_factor_is_clercs() -> None:
    # Clerc & Kennedy 2002: phi = 4.1 gives chi = 0.729843788
    assert constriction(2.05, 2.05) == pytest.approx(0.7298437881, abs=1e-9)
    with pytest.raises(KinergyError, match="c1 \\+ c2 > 4"):
        constriction(2.0, 2.0)


def test_swarm_finds_the_sphere_minimum_and_is_reproducible() -> None:
    def sphere(x: np.ndarray) -> np.ndarray:
        return np.sum((x - 0.5) ** 2, axis=1)

    a = particle_swarm(sphere, -5 * np.ones(6), 5 * np.ones(6), rng=3)
    b = particle_swarm(sphere, -5 * np.ones(6), 5 * np.ones(6), rng=3)
    assert a.fun < 1e-10
    np.testing.assert_allclose(a.x, 0.5, atol=1e-5)
    np.testing.assert_array_equal(a.x, b.x)
    assert a.history.shape == (201,)
    assert np.all(np.diff(a.history) <= 0.0)  # the best never gets worse
    assert a.nfev == 40 * 201


@pytest.mark.parametrize("dim", [4, 6])
def test_swarm_finds_the_rosenbrock_minimum(dim: int) -> None:
    def rosenbrock(x: np.ndarray) -> np.ndarray:
        return np.sum(100.0 * (x[:, 1:] - x[:, :-1] ** 2) ** 2 + (1.0 - x[:, :-1]) ** 2, axis=1)

    res = particle_swarm(
        rosenbrock, -5 * np.ones(dim), 5 * np.ones(dim), particles=60, iterations=5000, rng=1
    )
    assert res.fun < 1e-3
    np.testing.assert_allclose(res.x, 1.0, atol=0.05)


def test_swarm_stays_in_its_box() -> None:
    # the unconstrained minimum (3, 3) lies outside: the best point is the box's corner
    res = particle_swarm(lambda x: np.sum((x - 3.0) ** 2, axis=1), [-1, -1], [1, 1], rng=0)
    np.testing.assert_allclose(res.x, [1.0, 1.0])
    with pytest.raises(KinergyError, match="bounds"):
        particle_swarm(lambda x: x[:, 0], [1.0], [0.0])


# ---------------------------------------------------------------------------------------------
# eq 21 and the coupling


def test_eq21_with_the_docs_constants() -> None:
    assert torque_from_current(2.0, **DOC_EQ21) == pytest.approx(2 * 3060 * 0.82 * 0.0293)


def test_currents_to_joint_torques_follow_the_coupling_by_power_balance(arm) -> None:
    rng = np.random.default_rng(7)
    current = rng.normal(size=(5, 6))
    kt = np.array([j.drive.torque_constant for j in arm.joints])
    ratios = np.array([j.drive.gear_ratio for j in arm.joints])
    tau = joint_torques_from_current(arm, current)
    # eta = 1: the drives' own joint_torque of k_t I
    np.testing.assert_allclose(tau, joint_torque(arm, kt * current), rtol=1e-12)
    np.testing.assert_allclose(joint_torques_from_current(arm, current, eta=0.82), 0.82 * tau)
    # per pair (pitch, rotation) = (T1 + T2, T1 - T2) with T = n K_m I (eq 21)
    t_in = torque_from_current(current, n=ratios, eta=1.0, km=kt)
    for p in (0, 2, 4):
        pitch, rot = coupled_torques(t_in[:, p], t_in[:, p + 1])
        np.testing.assert_allclose(tau[:, p], pitch)
        np.testing.assert_allclose(tau[:, p + 1], rot)
        assert joint_kind(arm, p) == "pitch" and joint_kind(arm, p + 1) == "rotation"
    # power: joint torques times joint speeds == motor torques times motor speeds
    qd = rng.normal(size=(5, 6))
    wm = motor_speed(arm, qd)
    np.testing.assert_allclose(np.sum(tau * qd, axis=1), np.sum(kt * current * wm, axis=1))
    # the doc's eqs 17-18 print the mirrored pairing: pitch T1 - T2, rotation T1 + T2
    pitch_m, rot_m = coupled_torques(3.0, 1.0, mirrored=True)
    assert (float(pitch_m), float(rot_m)) == (2.0, 4.0)


def test_makkar_side_conversion_matches_the_robot_file(arm) -> None:
    motor = np.array([arm.joints[0].drive.friction.params[f"gamma{k}"] for k in range(1, 7)])
    joint = makkar_joint_side(motor, 3060.0, 2)
    np.testing.assert_allclose(joint, TWIN_GAMMA, rtol=2e-4)  # the header's rounded values
    np.testing.assert_allclose(makkar_motor_side(joint, 3060.0, 2), motor, rtol=1e-12)
    # moving one joint of a pair: N^T f(N qd) is the joint-side Makkar curve
    v = np.geomspace(0.005, 0.5, 9)
    for j in range(6):
        qd = np.zeros((v.size, 6))
        qd[:, j] = v
        np.testing.assert_allclose(joint_friction(arm, qd)[:, j], makkar(joint, v), rtol=1e-10)


# ---------------------------------------------------------------------------------------------
# friction runs, odd/even split, Makkar fits


def test_odd_even_split_recovers_a_hand_built_friction_and_error() -> None:
    v = np.linspace(0.01, 0.5, 12)
    friction = 3.0 * np.tanh(40 * v) + 0.8 * v  # odd
    error = 0.4 + 0.2 * v**2  # even: depends on |v| only
    gravity = -1.7  # same both ways
    f, e = odd_even_friction(v, friction + error + gravity, -friction + error + gravity)
    np.testing.assert_allclose(f, friction, rtol=1e-14)
    np.testing.assert_allclose(e, error + gravity, rtol=1e-14)
    with pytest.raises(KinergyError, match="> 0"):
        odd_even_friction(-v, f, f)


def test_friction_points_cancel_a_position_dependent_torque(arm) -> None:
    run = back_and_forth_motion(arm, 2, [0.05, 0.2], pose=np.zeros(6))
    q = run.motion.q[:, 2]
    qd = run.motion.qd[:, 2]
    tau = 5.0 * np.sin(q) + makkar(TWIN_GAMMA, qd)  # gravity-like plus friction
    pts = friction_points(q, tau, run.speeds, run.forward, run.backward)
    np.testing.assert_allclose(pts.friction, makkar(TWIN_GAMMA, run.speeds), rtol=1e-9)
    np.testing.assert_allclose(pts.sample_friction, makkar(TWIN_GAMMA, pts.sample_speeds))


@pytest.fixture(scope="module")
def elbow_runs(arm):
    """The doc's forearm (elbow) pair, pitch and rotation runs on the exact twin."""
    out = {}
    for j in (2, 3):
        run = back_and_forth_motion(arm, j)
        data = _twin_data(arm, run.motion, TwinSettings.exact(), f"elbow-{j}")
        tau = joint_torques_from_current(arm, data.current)
        out[j] = (
            run,
            data,
            friction_points(data.q[:, j], tau[:, j], run.speeds, run.forward, run.backward),
        )
    return out


def test_friction_runs_are_constant_speed_in_a_gravity_free_pose(arm, elbow_runs) -> None:
    for j, (run, data, pts) in elbow_runs.items():
        assert run.tilt < 1e-6  # the moving joint's axis is vertical
        assert run.speeds[-1] == pytest.approx(arm.joints[j].limits.speed)
        still = np.delete(np.arange(6), j)
        assert np.all(run.motion.qd[:, still] == 0.0)
        for a, b in run.forward:
            np.testing.assert_allclose(run.motion.qd[a:b, j], run.motion.qd[a, j])
            np.testing.assert_allclose(run.motion.qdd[a + 1 : b - 1, j], 0.0)
        q = run.motion.q[:, j]
        lo, hi = arm.joints[j].limits.position
        assert lo <= q.min() and q.max() <= hi
        # the even part (gravity and modelling error) is zero on the exact twin
        np.testing.assert_allclose(pts.error, 0.0, atol=1e-9)
        # the runs are found again in the log alone
        speeds, fwd, _ = constant_speed_runs(data.qd_cmd[:, j], data.qdd_cmd[:, j])
        np.testing.assert_allclose(speeds, run.speeds)
        assert np.all(fwd[:, 0] >= run.forward[:, 0]) and np.all(fwd[:, 1] <= run.forward[:, 1])


def test_makkar_fits_recover_the_twin_noise_free(elbow_runs) -> None:
    for _, _, pts in elbow_runs.values():
        # the odd part is the twin's joint-side curve, exactly
        np.testing.assert_allclose(pts.friction, makkar(TWIN_GAMMA, pts.speeds), rtol=2e-4)
        lsq = fit_makkar_lsq(pts.speeds, pts.friction)
        assert lsq.r2 >= 0.99
        np.testing.assert_allclose(lsq.gamma, TWIN_GAMMA, rtol=2e-4)  # the parameters
        pso = fit_makkar_pso(pts.speeds, pts.friction, rng=0)
        assert pso.r2 >= 0.99
        # the swarm finds the curve (within 1 % of its peak), not each parameter: Makkar's
        # model has flat valleys; the polish pins the parameters down
        v = np.linspace(0.0, pts.speeds.max(), 200)
        peak = np.max(np.abs(makkar(TWIN_GAMMA, v)))
        assert np.max(np.abs(makkar(pso.gamma, v) - makkar(TWIN_GAMMA, v))) < 0.01 * peak
        assert np.all(np.diff(pso.history) <= 0)
        polished = fit_makkar_pso(pts.speeds, pts.friction, rng=0, polish=True)
        np.testing.assert_allclose(polished.gamma, TWIN_GAMMA, rtol=2e-4)


def test_six_dimensional_swarm_as_the_doc_fits_the_curve(elbow_runs) -> None:
    _, _, pts = elbow_runs[2]
    fit = fit_makkar_pso(pts.speeds, pts.friction, variable_projection=False, particles=60, rng=2)
    assert fit.r2 >= 0.99
    assert np.all(fit.gamma >= 0.0) and fit.gamma[1] >= fit.gamma[2]


def test_makkar_fit_rejects_too_few_points() -> None:
    with pytest.raises(KinergyError, match="at least 6"):
        fit_makkar_lsq([0.1, 0.2], [1.0, 2.0])


# ---------------------------------------------------------------------------------------------
# cycle averaging, period, excitation, ridge


def test_cycle_averaging_cuts_noise_by_the_root_of_the_cycles() -> None:
    rng = np.random.default_rng(11)
    dt, period, cycles = 0.01, 2.0, 16
    t = dt * np.arange(round(cycles * period / dt) + 1)
    clean = np.column_stack([np.sin(2 * np.pi * t / period), np.cos(6 * np.pi * t / period)])
    sigma = 0.3
    noisy = clean + sigma * rng.standard_normal(clean.shape)
    t1, avg = cycle_average(t, noisy, period)
    assert t1.shape == (200,) and avg.shape == (200, 2)
    residual = np.std(avg - clean[:200], axis=0)
    np.testing.assert_allclose(residual, sigma / np.sqrt(cycles), rtol=0.15)
    # 16 whole periods of samples without the closing sample: the same 16 cycles
    np.testing.assert_array_equal(cycle_average(t[:-1], noisy[:-1], period)[1], avg)
    _, as_dict = cycle_average(t, {"x": noisy}, period)
    np.testing.assert_array_equal(as_dict["x"], avg)
    # a period that is not a whole number of samples: interpolated onto a grid that is
    odd_period = 2.005
    wave = np.sin(2 * np.pi * t / odd_period)
    t2, avg2 = cycle_average(t, wave, odd_period)
    assert t2[-1] < odd_period
    np.testing.assert_allclose(avg2, np.sin(2 * np.pi * t2 / odd_period), atol=2e-3)


def test_find_period_of_a_fourier_excitation() -> None:
    m = fourier_motion(
        [0.1, -0.2],
        [[0.2, 0.1, 0.0], [0.0, 0.3, 0.1]],
        [[0.1, 0.0, 0.2], [0.2, 0.0, 0.0]],
        base_frequency=BASE_FREQUENCY,
        periods=3,
        dt=0.01,
    )
    assert find_period(m.t, m.q) == pytest.approx(10.0, abs=0.011)
    assert find_period(m.t[:700], m.q[:700]) is None  # fewer than two periods


def test_table6_fits_the_nursing_arm_and_is_scaled_for_tighter_limits(arm) -> None:
    motion, scale, notes = table6_motion(arm, periods=1, dt=0.01)
    np.testing.assert_array_equal(scale, 1.0)
    assert notes == []
    assert motion.duration == pytest.approx(10.0)
    np.testing.assert_allclose(motion.q[0], 0.0, atol=2e-3)  # eq 23: starts near zero
    slow = arm.with_joints(
        [
            dataclasses.replace(j, limits=Limits(j.limits.position, 0.25, j.limits.torque))
            for j in arm.joints
        ]
    )
    motion, scale, notes = table6_motion(slow, periods=1, dt=0.01)
    assert scale[0] < 1.0 and len(notes) >= 1 and "scaled" in notes[0]
    assert np.max(np.abs(motion.qd)) <= 0.25


def test_ridge_tends_to_least_squares_as_alpha_vanishes(arm) -> None:
    rng = np.random.default_rng(5)
    n = 300
    q = rng.uniform(-1.0, 1.0, (n, 6))
    qd, qdd = rng.normal(size=(n, 6)), rng.normal(size=(n, 6))
    base = base_parameters(arm)
    true = base.project(inertial_parameters(arm))
    y_b = base.regressor(regressor(arm, q, qd, qdd))
    tau = y_b @ true + 0.01 * rng.standard_normal((n, 6))
    fit = ridge_minimal(arm, q, qd, qdd, tau, alphas=[0.0], base=base)
    # the same regression by ordinary least squares with an intercept, on the training part
    x = y_b[: fit.split].reshape(-1, base.size)
    ols = np.linalg.lstsq(
        np.column_stack([x, np.ones(len(x))]), tau[: fit.split].reshape(-1), rcond=None
    )[0]
    np.testing.assert_allclose(fit.coef, ols[:-1], rtol=1e-6, atol=1e-9)
    assert fit.intercept == pytest.approx(ols[-1], abs=1e-9)
    # exact data, no intercept: the model's base parameters
    exact = ridge_minimal(arm, q, qd, qdd, y_b @ true, alphas=[0.0], base=base, center=False)
    np.testing.assert_allclose(exact.coef, true, rtol=1e-6, atol=1e-9)
    # a strong ridge shrinks the standardised coefficients
    strong = ridge_minimal(arm, q, qd, qdd, tau, alphas=[10.0], base=base)
    assert np.linalg.norm(strong.coef * x.std(axis=0)) < np.linalg.norm(fit.coef * x.std(axis=0))


def test_identify_nursing_on_a_noise_free_excitation(arm, tmp_path) -> None:
    motion, _, _ = table6_motion(arm, periods=2, dt=0.004)
    data = _twin_data(arm, motion, TwinSettings.exact(), "excitation")
    result = nu.identify_nursing(arm, [data])
    ridge = result.fit.ridge
    assert result.method == "nursing"
    assert len(result.fit.base_parameters) == 36  # the doc's Table 3
    assert ridge.logs[0].period == pytest.approx(10.0, abs=0.005)
    assert np.all(np.isfinite(ridge.rmse_test))
    assert max(ridge.rmse_test) < 5e-3  # N m, on torques of 0.1-0.5 N m spread
    assert max(m.rms for m in result.fit.current) < 1e-3  # A
    # no friction runs: the motors keep the model's friction, and say so
    assert any("no friction run" in n for n in result.notes)
    save_robot(result.robot, tmp_path / "identified.toml")
    assert load_robot(str(tmp_path / "identified.toml")).n == 6
    json.dumps(result.to_dict(), default=float)


def test_identify_nursing_rejects_logs_without_current(arm) -> None:
    motion, _, _ = table6_motion(arm, periods=1, dt=0.01)
    twin = simulate(arm, motion, TwinSettings.exact())
    t, sig = twin.t, dict(twin.signals)
    sig.pop("actual_current")
    with pytest.raises(KinergyError, match="actual_current"):
        nu.identify_nursing(arm, [prepare(Log("no-current", t, sig), 6)])


# ---------------------------------------------------------------------------------------------
# the command


def test_nursing_command_prints_both_tables() -> None:
    result = CliRunner().invoke(nursing_cmd.nursing, ["--exact"])
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "Table 4" in out and "0.927" in out and "0.931" in out
    assert "Table 8" in out and "14.372" in out and "3.152" in out
    assert out.count("LSQ") == 6 and out.count("PSO") >= 6
    # noise-free: every LSQ fit reproduces the twin's curve
    for line in out.splitlines():
        if " LSQ " in line:
            assert float(line.split()[-3]) >= 0.99


def test_nursing_command_json(monkeypatch) -> None:
    from types import SimpleNamespace

    canned = {"robot": "nursing-arm", "friction": [], "ridge": {"rmse_test": [0.1] * 6}}
    study = SimpleNamespace(excitation_notes=(), warnings=(), **canned)
    monkeypatch.setattr(kinergy.api, "nursing_study", lambda robot, options, **kw: study)
    monkeypatch.setattr(nursing_cmd, "json_result", lambda s, *a: json.dumps(vars(s)))
    result = CliRunner().invoke(nursing_cmd.nursing, ["--json", "--seed", "3"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert {k: v for k, v in out.items() if k in canned} == canned


def test_transmission_of_the_nursing_arm_is_diag_n_times_coupling(arm) -> None:
    np.testing.assert_allclose(transmission_matrix(arm), 3060.0 * arm.coupling)


def test_the_nursing_method_does_not_depend_on_the_chunks(arm) -> None:
    """Logs cut into chunks of 997 rows (filtered on windows, cycle-averaged by sums per phase)
    give the whole logs' identification: the averaged torques to round-off of the filter's
    window (its reach: 1e-25 of the impulse response), the ridge's base parameters with them."""
    from kinergy.identification.chunks import LogChunks, WholeSegment
    from kinergy.identification.options import NursingOptions

    run = back_and_forth_motion(arm, 1)
    motion, _, _ = table6_motion(arm, periods=3, dt=0.004)
    datas = [
        _twin_data(arm, run.motion, TwinSettings(seed=1), "run"),
        _twin_data(arm, motion, TwinSettings(seed=2), "excitation"),
    ]
    whole = nu.identify_nursing(arm, datas)
    logs = LogChunks([WholeSegment(d) for d in datas], rows=997, spool=True)
    chunked = nu.nursing(arm, logs, NursingOptions())
    logs.close()
    assert [r.gamma for r in chunked.fit.friction_runs] == [
        r.gamma for r in whole.fit.friction_runs
    ]
    assert chunked.fit.friction_runs and chunked.fit.ridge.logs[0].cycles == 3
    got = np.array([b.value for b in chunked.fit.base_parameters])
    want = np.array([b.value for b in whole.fit.base_parameters])
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12 * np.abs(want).max())
    np.testing.assert_allclose(chunked.fit.ridge.rmse_test, whole.fit.ridge.rmse_test, rtol=1e-9)


def test_the_api_runs_the_study_as_the_command(tmp_path) -> None:
    """``kinergy.api.nursing_study``'s ``to_dict()`` is ``kinergy nursing --json`` (but the
    timings), and what it writes to ``out``."""
    from kinergy.cli import main

    options = kinergy.api.NursingStudyOptions(noise=False)
    study = kinergy.api.nursing_study("nursing-arm", options, out=tmp_path / "api.json")
    result = CliRunner().invoke(nursing_cmd.nursing, ["--exact", "--json"])
    assert result.exit_code == 0, result.output
    cli = json.loads(result.stdout)
    cli.pop("kinergy"), cli.pop("inputs")
    got = json.loads(json.dumps(study.to_dict()))
    assert json.loads((tmp_path / "api.json").read_text()) == got
    for out in (got, cli):
        out.pop("timings")
    assert got == cli
    assert main(["nursing", "--exact", "--seed", "-1"]) == 2
