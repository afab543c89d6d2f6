"""The full method (base-parameter regression of links, rotor inertias and friction).

Relations checked: on noise-free twin logs the regression returns the true model's base
parameters (nursing eq 16) and rotor inertias exactly, and the returned robot reproduces the
logged signals; with realistic noise the estimates agree with the truth within their own standard
deviations; base parameters without a physical realisation are flagged and the robot written back
stays valid; logs that cannot identify a joint are refused; on the Panda's real excitation run
the identified model predicts a held-out 30 % of the measured joint torques.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

import kinergy
import kinergy.identification.writeback as writeback
from kinergy.errors import Code
from kinergy.identification.full import identify_full
from kinergy.identification.options import IdentifyOptions, Method
from kinergy.identification.physical import (
    inertia_vector,
    link_consistency,
    parameter_scale,
    pseudo_inertia,
    standard_from_base,
)
from kinergy.identification.result import KEPT, IdentificationResult, validation_metrics
from kinergy.io.log import Log
from kinergy.logs.filtering import lowpass
from kinergy.logs.prepare import IdentData, prepare
from kinergy.model.robot import Friction, inertia_matrix
from kinergy.trajectory.fourier import fourier_motion
from kinergy.trajectory.motion import Motion
from kinergy.twin import TwinSettings, simulate

PANDA_GAZ = Path(__file__).resolve().parents[2] / "shared" / "datasets" / "panda-gaz"


# ------------------------------------------------------------------------------------ helpers


def excitation(
    robot: kinergy.Robot,
    seed: int,
    *,
    harmonics: int = 4,
    period: float = 10.0,
    periods: int = 2,
    dt: float = 0.004,
    still: tuple[int, ...] = (),
) -> Motion:
    """A seeded Fourier excitation (nursing eq 22) about the middle of each joint's range, at most
    1 rad (and 80 % of the half range) from it, speeds up to about 1 rad/s; joints in ``still``
    (0-based) do not move."""
    rng = np.random.default_rng(seed)
    n = robot.n
    wf = 2.0 * np.pi / period
    lim = np.array([j.limits.position for j in robot.joints])
    mid, half = lim.mean(axis=1), 0.5 * (lim[:, 1] - lim[:, 0])
    a, b = rng.normal(size=(n, harmonics)), rng.normal(size=(n, harmonics))
    harm = wf * np.arange(1, harmonics + 1)
    amplitude = np.sum((np.abs(a) + np.abs(b)) / harm, axis=1)  # bound on |q - q0|
    speed = np.sum(np.abs(a) + np.abs(b), axis=1)  # bound on |qd|
    k = np.minimum(0.8 * np.minimum(half, 1.0) / amplitude, 1.5 / speed)
    a, b = a * k[:, None], b * k[:, None]
    for j in still:
        a[j] = b[j] = 0.0
    return fourier_motion(mid, a, b, base_frequency=wf, periods=periods, dt=dt)


def twin_data(robot: kinergy.Robot, motion: Motion, settings: TwinSettings) -> IdentData:
    """The twin's log of ``motion`` on ``robot``, prepared for identification."""
    return prepare(simulate(robot, motion, settings), robot.n)


def perturbed(robot: kinergy.Robot, seed: int, spread: float = 0.2) -> kinergy.Robot:
    """Link masses, inertias and motor inertias each scaled by a seeded factor in 1 +- spread."""
    rng = np.random.default_rng(seed)
    joints = []
    for j in robot.joints:
        f = 1.0 + rng.uniform(-spread, spread, 3)
        link = dataclasses.replace(j.link, mass=j.link.mass * f[0], inertia=j.link.inertia * f[1])
        drive = dataclasses.replace(j.drive, motor_inertia=j.drive.motor_inertia * f[2])
        joints.append(dataclasses.replace(j, link=link, drive=drive))
    return robot.with_joints(joints)


def expected_unknowns(result: IdentificationResult, truth: kinergy.Robot) -> np.ndarray:
    """The true value of every regression unknown (``fit.parameters``: base parameters, rotor
    inertias, friction levels), plus what merged rotor inertias put into the others: a dropped
    column keeps the model's value, so the unknowns it merges into carry ``coefficient *
    (true - model)`` (``fit.merged``)."""
    base = kinergy.base_parameters(truth)
    x = np.concatenate(
        [
            base.project(kinergy.inertial_parameters(truth)),
            [j.drive.rotor_inertia for j in truth.joints],
            np.full(len(result.fit.parameters) - base.size - truth.n, np.nan),
        ]
    )
    names = [p.name for p in result.fit.parameters]
    for entry in result.fit.merged:
        k = names.index(entry.parameter)
        for into in entry.into:
            x[into.index] += into.coefficient * (x[k] - entry.value)
    return x


def expected_base(result: IdentificationResult, truth: kinergy.Robot) -> np.ndarray:
    """The base-parameter part of :func:`expected_unknowns`."""
    return expected_unknowns(result, truth)[: len(result.fit.base_parameters)]


def identified_base(result: IdentificationResult) -> tuple[np.ndarray, np.ndarray]:
    values = np.array([p.value for p in result.fit.base_parameters])
    std = np.array([p.std for p in result.fit.base_parameters])
    return values, std


# ------------------------------------------------------------------------------------ fixtures


@pytest.fixture(scope="module")
def ur5e_motion(ur5e: kinergy.Robot) -> Motion:
    return excitation(ur5e, seed=11)


@pytest.fixture(scope="module")
def exact_log(ur5e: kinergy.Robot, ur5e_motion: Motion) -> IdentData:
    return twin_data(ur5e, ur5e_motion, TwinSettings.exact())


@pytest.fixture(scope="module")
def noisy_log(ur5e: kinergy.Robot, ur5e_motion: Motion) -> IdentData:
    return twin_data(ur5e, ur5e_motion, TwinSettings(seed=5))


@pytest.fixture(scope="module")
def ur5e_vc(ur5e: kinergy.Robot) -> kinergy.Robot:
    """The UR5e with direction-independent friction (viscous_coulomb, the mean Coulomb level)."""
    joints = []
    for j in ur5e.joints:
        p = j.drive.friction.params
        coulomb = 0.5 * (p["coulomb_direct"] + p["coulomb_reverse"])
        fr = Friction(
            "viscous_coulomb",
            {"viscous": p["viscous"], "coulomb": coulomb, "smoothing": p["smoothing"]},
        )
        joints.append(dataclasses.replace(j, drive=dataclasses.replace(j.drive, friction=fr)))
    return ur5e.with_joints(joints)


@pytest.fixture(scope="module")
def noisy_vc_log(ur5e_vc: kinergy.Robot, ur5e_motion: Motion) -> IdentData:
    return twin_data(ur5e_vc, ur5e_motion, TwinSettings(seed=5))


# ------------------------------------------------------------------------ noise-free twin logs


def test_moment_recovers_the_true_base_parameters_and_rotor_inertias(
    ur5e: kinergy.Robot, exact_log: IdentData
) -> None:
    start = perturbed(ur5e, seed=2)
    result = identify_full(start, [exact_log], target="moment", currents=False)
    assert result.method == "full" and result.fit.target == "moment"
    values, std = identified_base(result)
    np.testing.assert_allclose(values, expected_base(result, ur5e), rtol=1e-6, atol=1e-9)
    assert np.all(np.isfinite(std))
    # on a UR arm J1 and J2 multiply the same signals as the Iyy1 and Izz2 groups
    merged = [e.parameter for e in result.fit.merged]
    assert merged == [
        "rotor inertia of joint 1 (shoulder_pan)",
        "rotor inertia of joint 2 (shoulder_lift)",
    ]
    assert sum("cannot be told apart" in n for n in result.notes) == 2
    for m, (entry, joint) in enumerate(zip(result.joints, ur5e.joints, strict=True)):
        assert entry.rotor_inertia_merged == (m < 2)
        if m >= 2:  # the separable rotor inertias are exact
            assert entry.rotor_inertia == pytest.approx(joint.drive.rotor_inertia, rel=1e-6)
            assert entry.rotor_inertia_std > 0
    # the returned robot reproduces target_moment; the moment carries no friction, kept
    torque = result.fit.torque
    assert min(t.r2 for t in torque) > 1.0 - 1e-9
    for joint, old in zip(result.robot.joints, start.joints, strict=True):
        assert joint.drive.friction.params == old.drive.friction.params
    assert result.robot.sources["inertia"].status == "identified"
    assert result.robot.sources["drive_inertia"].status == "identified"
    assert result.robot.sources["friction"].status != "identified"
    assert result.fit.condition < 1e3
    names = [b.name for b in result.fit.base_parameters]
    assert names == kinergy.base_parameters(ur5e).expressions()
    json.dumps(result.to_dict())  # the identify --json shape


def test_current_with_friction_reproduces_the_currents(
    ur5e: kinergy.Robot, exact_log: IdentData
) -> None:
    start = perturbed(ur5e, seed=3)
    result = identify_full(start, [exact_log], target="current", currents=False)
    values, _ = identified_base(result)
    np.testing.assert_allclose(values, expected_base(result, ur5e), rtol=1e-6, atol=1e-9)
    current = result.fit.current
    assert min(c.r2 for c in current) > 0.9999
    for entry, joint in zip(result.joints, ur5e.joints, strict=True):  # power-flow friction
        assert entry.friction.name == "power_flow"
        for name in ("viscous", "coulomb_direct", "coulomb_reverse"):
            assert entry.friction.params[name] == pytest.approx(
                joint.drive.friction.params[name], rel=1e-6
            )
        assert entry.friction.params["smoothing"] == joint.drive.friction.params["smoothing"]
        assert entry.torque_constant == joint.drive.torque_constant
    assert result.fit.power_flow_mismatch == 0
    assert result.robot.sources["friction"].status == "identified"


def test_load_proportional_friction_is_fitted_on_the_load_it_sees(
    ur5e: kinergy.Robot, ur5e_motion: Motion
) -> None:
    # a truth whose Coulomb friction grows with the joint load (load_coulomb); the fit starts
    # from perturbed links, so its first load torque is wrong: the fixed point on the fitted
    # model's own load must still land on the truth (a zero load column did not: issue 13)
    joints = []
    for j in ur5e.joints:
        p = j.drive.friction.params
        fr = Friction(
            "load_coulomb",
            {
                "coulomb": 0.5 * (p["coulomb_direct"] + p["coulomb_reverse"]),
                "load": 0.03,
                "viscous": p["viscous"],
                "smoothing": p["smoothing"],
            },
        )
        joints.append(dataclasses.replace(j, drive=dataclasses.replace(j.drive, friction=fr)))
    truth = ur5e.with_joints(joints)
    log = twin_data(truth, ur5e_motion, TwinSettings.exact())
    result = identify_full(perturbed(truth, seed=4), [log], target="current", currents=False)
    values, _ = identified_base(result)
    np.testing.assert_allclose(values, expected_base(result, truth), rtol=1e-6, atol=1e-9)
    for entry, joint in zip(result.joints, truth.joints, strict=True):
        assert entry.friction.name == "load_coulomb"
        for name in ("coulomb", "load", "viscous"):
            assert entry.friction.params[name] == pytest.approx(
                joint.drive.friction.params[name], rel=1e-6
            )


def test_coupled_joints_are_identified_through_the_transmission() -> None:
    # the nursing arm's differential joints: motor speeds N qd with N = gear ratio x coupling,
    # reflected inertia N^T diag(J) N (nursing eqs 3-4)
    robot = kinergy.load_robot("nursing-arm")
    data = twin_data(robot, excitation(robot, seed=3), TwinSettings.exact())
    result = identify_full(perturbed(robot, seed=1), [data], target="moment")
    expected = expected_unknowns(result, robot)
    values = np.array([p.value for p in result.fit.parameters])
    b = len(result.fit.base_parameters)
    np.testing.assert_allclose(values[:b], expected[:b], rtol=1e-6, atol=1e-9)
    separable = ~np.array([j.rotor_inertia_merged for j in result.joints])
    np.testing.assert_allclose(
        values[b : b + 6][separable], expected[b : b + 6][separable], rtol=1e-6
    )
    # joint 2's rotor column is a combination of joint 1's and two link base columns
    (merged,) = result.fit.merged
    assert merged.parameter == "rotor inertia of joint 2 (shoulder_rotation)"
    assert {e.parameter for e in merged.into} >= {"rotor inertia of joint 1 (shoulder_pitch)"}
    assert min(t.r2 for t in result.fit.torque) > 1.0 - 1e-9
    assert all(result.fit.links_physical)


def test_auto_target_prefers_torque_then_moment(ur5e: kinergy.Robot, exact_log: IdentData) -> None:
    assert identify_full(ur5e, [exact_log]).fit.target == "moment"
    torque = dataclasses.replace(exact_log, torque=exact_log.tau_ref)
    assert identify_full(ur5e, [torque]).fit.target == "torque"


# ------------------------------------------------------------------------------- noisy twin logs


@pytest.mark.parametrize(("solver", "ridge"), [("ols", 0.0), ("wls", 0.0), ("ridge", 1e-6)])
def test_noisy_currents_give_honest_estimates(
    ur5e_vc: kinergy.Robot, noisy_vc_log: IdentData, solver: str, ridge: float
) -> None:
    # default twin noise: 0.04 A on the currents, 0.01 rad/s on the speeds, a 4 ms lag
    start = perturbed(ur5e_vc, seed=4)
    result = identify_full(
        start, [noisy_vc_log], target="current", solver=solver, ridge=ridge, currents=False
    )
    values, std = identified_base(result)
    truth = expected_base(result, ur5e_vc)
    assert np.all(np.isfinite(std)) and np.all(std > 0)
    # every estimate within 5 of its own standard deviations of the truth: the current noise is
    # white and the friction model the twin's, so the standard deviations must be honest ...
    z = (values - truth) / std
    assert np.max(np.abs(z)) < 5.0, np.round(z, 2)
    # ... and the well-determined ones (relative std below 1 %) within 3 %
    rel = np.array([b.rel_std for b in result.fit.base_parameters])
    good = rel < 0.01
    assert good.sum() >= 2
    np.testing.assert_allclose(values[good], truth[good], rtol=0.03)
    # the residual is the current noise: 0.04 A times k_t times the gear ratio at each joint
    noise = np.array([0.04 * j.drive.torque_constant * j.drive.gear_ratio for j in ur5e_vc.joints])
    assert np.all(np.abs(np.array(result.fit.residual_std) / noise - 1.0) < 0.1)
    rotor_std = [j.rotor_inertia_std for j in result.joints]
    assert all(s is None or (np.isfinite(s) and s > 0) for s in rotor_std)
    for j in result.joints:
        assert all(np.isfinite(s) for s in j.friction_std.values())
    assert all(result.fit.links_physical)
    if solver == "wls":  # Gautier's weights are the inverse noise variances
        weights = np.array(result.fit.weights)
        np.testing.assert_allclose(weights / weights[0], (noise[0] / noise) ** 2, rtol=0.2)


def test_noisy_currents_with_power_flow_friction(ur5e: kinergy.Robot, noisy_log: IdentData) -> None:
    # the power-flow direction is decided from the noisy measurement where the load is within
    # the noise of zero: a small bias (the wrist gravity group mz6 + mz5 + 0.0996 m6 comes out
    # about 6 standard deviations, 24 %, high); the well-determined parameters are unaffected
    result = identify_full(
        perturbed(ur5e, seed=4), [noisy_log], target="current", solver="wls", currents=False
    )
    values, std = identified_base(result)
    truth = expected_base(result, ur5e)
    rel = np.array([b.rel_std for b in result.fit.base_parameters])
    good = rel < 0.01
    np.testing.assert_allclose(values[good], truth[good], rtol=0.03)
    assert np.max(np.abs((values - truth) / std)) < 10.0
    # the regression explains the currents down to the noise; the returned robot decides the
    # direction from its own load torque, and joint 5's Coulomb levels (0.0201 direct, 0.001
    # reverse) make that sensitive near zero load: its R^2 drops (0.84 here, 0.96 for the true
    # model) while the other joints keep theirs
    regression = [c.r2 for c in result.fit.regression]
    assert min(regression) > 0.95
    current = [c.r2 for c in result.fit.current]
    assert min(current[:4]) > 0.98 and min(current) > 0.8
    assert all(result.fit.links_physical)


def test_ridge_moves_from_least_squares_to_the_prior(
    ur5e_vc: kinergy.Robot, noisy_vc_log: IdentData
) -> None:
    start = perturbed(ur5e_vc, seed=4)
    noisy_log = noisy_vc_log

    def fit(**options: object) -> np.ndarray:
        return identified_base(
            identify_full(start, [noisy_log], target="current", currents=False, **options)  # type: ignore[arg-type]
        )[0]

    ols, tiny, huge = fit(), fit(solver="ridge", ridge=1e-12), fit(solver="ridge", ridge=1e8)
    prior = kinergy.base_parameters(start).project(kinergy.inertial_parameters(start))
    scale = np.abs(prior).max()
    assert np.max(np.abs(tiny - ols)) < 1e-6 * scale
    assert np.max(np.abs(huge - prior)) < 1e-3 * scale
    assert np.max(np.abs(ols - prior)) > 1e-2 * scale


# ------------------------------------------------------------------------- physical consistency


def _moment_log(robot: kinergy.Robot, motion: Motion, pi_b: np.ndarray) -> IdentData:
    """target_moment made from chosen base parameters ``pi_b`` and the robot's rotor inertias."""
    base = kinergy.base_parameters(robot)
    y = base.regressor(kinergy.regressor(robot, motion.q, motion.qd, motion.qdd))
    rotor = np.array([j.drive.rotor_inertia * j.drive.gear_ratio**2 for j in robot.joints])
    tau = y @ pi_b + motion.qdd * rotor
    signals = {"target_q": motion.q, "target_qd": motion.qd, "target_qdd": motion.qdd}
    return prepare(Log("chosen", motion.t, {**signals, "target_moment": tau}), robot.n)


def test_unphysical_base_parameters_are_flagged(ur5e: kinergy.Robot, ur5e_motion: Motion) -> None:
    base = kinergy.base_parameters(ur5e)
    pi_b = base.project(kinergy.inertial_parameters(ur5e))
    izz6 = base.expressions().index("Izz6")  # inertia about link 6's own axis: never negative
    pi_b[izz6] = -0.05
    result = identify_full(ur5e, [_moment_log(ur5e, ur5e_motion, pi_b)], target="moment")
    values, _ = identified_base(result)
    assert values[izz6] == pytest.approx(-0.05, rel=1e-6)  # what the data say ...
    flagged = [w for w in result.notes if w.startswith("link 6 (wrist_3)")]
    assert len(flagged) == 1 and "not positive definite" in flagged[0]
    # what the constrained fit is (the ~150-character aside) is said once, not per finding
    aside = [w for w in result.notes if "fit['physical_fit']" in w]
    assert (
        len(aside) == 1 and "finding(s) above, the returned robot is the least-squares" in aside[0]
    )
    assert "fit['physical_fit']" not in flagged[0]
    # ... and a valid robot anyway: the fit constrained to physical links
    assert result.fit.write_back == "physically consistent least squares"
    assert all(result.fit.links_physical)
    assert result.fit.physical_fit is not None
    assert result.fit.physical_fit.chi2_increase > 1.0
    pi = kinergy.inertial_parameters(result.robot)
    assert all(p is None for p in link_consistency(pi))
    assert np.all(np.linalg.eigvalsh(pseudo_inertia(pi))[:, 0] > 0)


def test_a_link_that_cannot_be_made_physical_keeps_the_model(
    ur5e: kinergy.Robot, ur5e_motion: Motion, monkeypatch: pytest.MonkeyPatch
) -> None:
    base = kinergy.base_parameters(ur5e)
    pi_b = base.project(kinergy.inertial_parameters(ur5e))
    pi_b[base.expressions().index("Izz6")] = -0.05
    monkeypatch.setattr(writeback, "physical_fit", lambda *args, **kwargs: None)
    result = identify_full(ur5e, [_moment_log(ur5e, ur5e_motion, pi_b)], target="moment")
    assert len([w for w in result.warnings if w.startswith("link 6 (wrist_3)")]) == 1
    kept = [w for w in result.warnings if "kept the model's mass, centre of mass" in w]
    assert len(kept) == 1 and "for link(s) 6, so the returned robot's torques differ" in kept[0]
    assert result.fit.links_physical[5] is False
    link6, model6 = result.robot.joints[5].link, ur5e.joints[5].link
    assert link6.mass == model6.mass
    np.testing.assert_array_equal(link6.inertia, model6.inertia)
    assert "link(s) 6 kept from the model" in result.robot.sources["inertia"].ref


def test_link_consistency_names_what_is_wrong() -> None:
    pi = np.array([-0.2, 0, 0, 0, 1e-3, 0, 1e-3, 0, 0, 1e-3])
    assert link_consistency(pi) == ["identified mass -0.2 kg is not physical"]
    flat = np.array([1.0, 0, 0, 0, 1e-3, 0, 1e-3, 0, 0, 3e-3])  # Izz > Ixx + Iyy
    assert "triangle inequality" in str(link_consistency(flat)[0])
    offset = np.array([1.0, 0.1, 0, 0, 1e-3, 0, 1e-3, 0, 0, 1e-3])  # I_o < m c^2 about y, z
    assert "not positive definite" in str(link_consistency(offset)[0])


def test_pseudo_inertia_is_positive_definite_exactly_for_physical_links() -> None:
    rng = np.random.default_rng(7)
    counts = [0, 0]
    for _ in range(400):
        # a physical link: mass, centre of mass, principal second moments >= 0 in random axes
        m = rng.uniform(0.5, 5.0)
        c = rng.normal(0.0, 0.1, 3)
        second = rng.uniform(0.0, 0.01, 3) * m  # int x^2 dm etc.
        rot = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        i_c = rot @ np.diag(second.sum() - second) @ rot.T
        i_o = i_c + m * (c @ c * np.eye(3) - np.outer(c, c))
        pi = np.array(
            [m, *(m * c), i_o[0, 0], i_o[0, 1], i_o[1, 1], i_o[0, 2], i_o[1, 2], i_o[2, 2]]
        )
        if rng.random() < 0.5:  # and half of them spoiled
            pi[4:] += rng.normal(0.0, 0.01, 6) * m
            pi[0] *= 1.0 if rng.random() < 0.8 else -1.0
        physical = link_consistency(pi)[0] is None
        definite = bool(np.linalg.eigvalsh(pseudo_inertia(pi))[0, 0] > 0)
        assert physical == definite
        counts[physical] += 1
    assert min(counts) > 50  # both kinds were drawn


def test_inertia_vector_inverts_inertia_matrix() -> None:
    six = np.random.default_rng(3).normal(size=6)
    np.testing.assert_array_equal(inertia_vector(inertia_matrix(six)), six)


@pytest.mark.parametrize("name", ["ur5e", "panda"])
def test_standard_from_base_reaches_the_base_parameters(name: str) -> None:
    robot = kinergy.load_robot(name)
    base = kinergy.base_parameters(robot)
    pi0 = kinergy.inertial_parameters(robot)
    rng = np.random.default_rng(1)
    target = base.project(pi0) + 0.01 * rng.normal(size=base.size)
    for scale in (None, parameter_scale(robot)):
        pi = standard_from_base(base, target, pi0, scale=scale)
        np.testing.assert_allclose(base.project(pi), target, atol=1e-12)
    # unscaled, it is the brief's pi0 + P^T (P P^T)^-1 (pi_b - P pi0): the change lies in P's rows
    p_mat = np.zeros((base.size, pi0.size))
    p_mat[:, base.independent] = np.eye(base.size)
    p_mat[:, base.dependent] = base.beta
    change = standard_from_base(base, target, pi0) - pi0
    rows, *_ = np.linalg.lstsq(p_mat.T, change, rcond=None)
    np.testing.assert_allclose(p_mat.T @ rows, change, atol=1e-12)


# ------------------------------------------------------------------------------- diagnostics


def test_a_joint_that_never_moves_is_named(ur5e: kinergy.Robot) -> None:
    data = twin_data(ur5e, excitation(ur5e, seed=3, periods=1, still=(2,)), TwinSettings.exact())
    with pytest.raises(kinergy.KinergyError, match=r"joint 3 \(elbow\) never moves") as err:
        identify_full(ur5e, [data], target="moment")
    assert "joint 1" not in str(err.value) and "\n" not in str(err.value)


def test_too_few_samples_and_bad_options_are_refused(
    ur5e: kinergy.Robot, exact_log: IdentData
) -> None:
    with pytest.raises(kinergy.KinergyError, match=r"only 40 samples for \d+ parameters"):
        identify_full(ur5e, [exact_log.sliced(0, 40)], target="moment")
    with pytest.raises(kinergy.KinergyError, match="needs measured joint torques, missing in twin"):
        identify_full(ur5e, [exact_log], target="torque")
    with pytest.raises(
        kinergy.KinergyError,
        match="target: must be one of auto, moment, current, torque, got 'power'",
    ):
        identify_full(ur5e, [exact_log], target="power")
    with pytest.raises(kinergy.KinergyError, match="solver: must be one of"):
        identify_full(ur5e, [exact_log], solver="lasso")
    with pytest.raises(kinergy.KinergyError, match="needs ridge > 0"):
        identify_full(ur5e, [exact_log], solver="ridge")
    with pytest.raises(kinergy.KinergyError, match="only used by solver 'ridge'"):
        identify_full(ur5e, [exact_log], ridge=0.1)
    with pytest.raises(kinergy.KinergyError, match="friction: must be one of .*, got 'dahl'"):
        identify_full(ur5e, [exact_log], target="current", friction="dahl")
    with pytest.raises(kinergy.KinergyError, match="no log"):
        identify_full(ur5e, [])


def test_friction_auto_works_with_the_full_method_or_says_what_it_needs(
    ur5e_vc: kinergy.Robot, noisy_vc_log: IdentData
) -> None:
    # with currents in the logs the regression takes each joint's own family and the currents
    # choose each joint's, as the sequential method does
    result = identify_full(ur5e_vc, [noisy_vc_log], target="moment", friction="auto")
    choices = result.fit.friction_choice
    assert choices is not None and len(choices) == ur5e_vc.n
    assert all(c is not None and c.model.name in c.cv_rms for c in choices)
    # each joint has the family chosen for it (or keeps its own where that fit is not physical)
    for joint, start, c in zip(result.joints, ur5e_vc.joints, choices, strict=True):
        assert c is not None and joint.friction.model in (c.model, start.drive.friction.model)
    # without currents nothing can choose: refused, saying what it needs, with its code
    no_current = dataclasses.replace(noisy_vc_log, current=None)
    with pytest.raises(kinergy.KinergyError, match="--friction auto .* actual_current") as err:
        identify_full(ur5e_vc, [no_current], target="moment", friction="auto")
    assert err.value.code == Code.UNSUPPORTED
    # the nursing method fits its own friction: any --friction is refused, naming the methods
    with pytest.raises(kinergy.KinergyError, match="sequential and full methods") as err:
        IdentifyOptions(method=Method.NURSING, friction="auto")
    assert err.value.code == Code.UNSUPPORTED


def test_an_unexcited_regression_is_refused(ur5e: kinergy.Robot) -> None:
    # every joint turns at a constant 0.2 rad/s: nothing multiplies an acceleration alone, so
    # the base parameters of joint 1's inertia group (the Iyy1 group, only ever times qdd1) are
    # not excited
    t = np.arange(0.0, 10.0, 0.004)
    q0 = np.array([0.0, -1.5, 1.0, -1.5, 0.5, 0.0])
    qd = np.full((t.size, 6), 0.2)
    motion = Motion(t, q0 + qd * t[:, None], qd, np.zeros_like(qd))
    data = twin_data(ur5e, motion, TwinSettings.exact())
    with pytest.raises(
        kinergy.KinergyError, match=r"the logs do not excite \d+ link base parameter\(s\) \(Iyy1"
    ):
        identify_full(ur5e, [data], target="moment")


# --------------------------------------------------------------------------- Panda, real data


def load_panda_gaz(folder: Path, *, cutoff: float = 10.0) -> IdentData:
    """The Gaz et al. Panda excitation run as :class:`IdentData` (measured joint torques).

    Time stamps are irregular (about 1 kHz): every signal is resampled to a uniform grid at the
    median period by linear interpolation; the speed is low-passed (zero phase, ``cutoff`` Hz) and
    differentiated for the acceleration (nursing eq 24's filtering); positions and torques are
    used as measured.
    """
    t = np.loadtxt(folder / "exciting_traj_time.txt")
    pos, vel, tau = (
        np.loadtxt(folder / f"exciting_traj_{name}.txt").reshape(t.size, 7)
        for name in ("positions", "velocity", "torques")
    )
    dt = float(np.median(np.diff(t)))
    grid = t[0] + dt * np.arange(int(np.floor((t[-1] - t[0]) / dt)) + 1)

    def resample(x: np.ndarray) -> np.ndarray:
        return np.column_stack([np.interp(grid, t, x[:, k]) for k in range(x.shape[1])])

    q = resample(pos)
    qd = lowpass(resample(vel), 1.0 / dt, cutoff)
    qdd = np.gradient(qd, grid, axis=0)
    return IdentData(
        str(folder), grid, q, qd, qdd, q, qd, qdd, None, None, resample(tau), 0.0, "filtered actual"
    )


@pytest.mark.skipif(not PANDA_GAZ.is_dir(), reason="shared dataset panda-gaz is absent")
def test_panda_predicts_held_out_measured_torques() -> None:
    robot = kinergy.load_robot("panda")
    data = load_panda_gaz(PANDA_GAZ)
    assert data.q.shape == (21000, 7)  # 21 s resampled at the median 1 ms
    split = int(0.7 * len(data))
    result = identify_full(robot, [data.sliced(0, split)], target="torque")
    held_out = validation_metrics(result.robot, [data.sliced(split, len(data))]).joint_torque
    r2 = np.array([m.r2 for m in held_out])
    rms = np.array([m.rms for m in held_out])
    # measured: R^2 0.983 0.9994 0.998 0.994 0.984 0.990 0.953, RMS 0.32 0.41 0.28 0.43 0.13 0.12
    # 0.061 N m (Gaz et al.'s own parameters: R^2 0.977 0.998 0.998 0.993 0.970 0.986 0.935);
    # without the sensor offsets 0.979 0.9994 0.998 0.994 0.983 0.986 0.957
    assert np.all(r2 > [0.95, 0.995, 0.99, 0.98, 0.95, 0.95, 0.90]), np.round(r2, 4)
    assert np.all(rms < [0.5, 0.6, 0.4, 0.6, 0.2, 0.2, 0.09]), np.round(rms, 3)
    # link-side torque sensors see no rotor inertia: kept from the model, not fitted
    for j, model in zip(result.joints, robot.joints, strict=True):
        assert j.rotor_inertia == pytest.approx(model.drive.rotor_inertia, rel=1e-12)
        assert j.flags["rotor_inertia"] == KEPT
    # the offsets of joints 1-4 and 6 are determined (-0.18 -0.15 0.05 -0.22 0.08 N m), those of
    # joints 5 and 7 are not (kept at 0)
    offsets = [j.torque_sensor_offset for j in result.joints]
    assert offsets[0] == pytest.approx(-0.18, abs=0.02) and offsets[6] == 0.0, offsets
    assert all(result.fit.links_physical)


def test_what_the_logs_do_not_determine_is_a_warning() -> None:
    """Base parameters whose standard error exceeds their value (above round-off) and drive
    parameters held at a bound are warnings; a parameter zero to round-off is not counted."""
    from kinergy.identification.full import Parameter, _undetermined

    base = [
        Parameter("m1", 2.0, 0.1, 0.05),
        Parameter("mx4", 1e-12, 6e-12, 6.0),  # zero to round-off: determined
        Parameter("Iyz7", -1e-4, 6e-4, 6.0),
        Parameter("mx5", 5e-5, 4e-4, 8.0),
    ]
    drives = [
        Parameter("rotor inertia of joint 1 (j1)", 0.0, 1e-5, None, "rotor", "at bound"),
        Parameter("rotor inertia of joint 3 (j3)", 0.0, 1e-5, None, "rotor", "at bound"),
        Parameter("viscous of joint 2 (j2)", 0.1, 0.01, 0.1, "friction", "identified"),
    ]
    loose, held = _undetermined(base, [*base, *drives])
    assert loose.startswith("2 of 4 base parameters have a standard error larger than their")
    assert "(largest: mx5, 8 times)" in loose
    assert "rotor inertia of joint(s) 1, 3;" in held and "viscous" not in held
    assert _undetermined(base[:2], base[:2]) == []
