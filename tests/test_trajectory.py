"""Motions: movej against the real UR controller's planner output, its own properties, and the
Fourier series against finite differences."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kinergy.errors import KinergyError
from kinergy.io.rtde import read_log
from kinergy.trajectory.fourier import fourier_motion, fourier_series
from kinergy.trajectory.movej import (
    blend_starts,
    movej,
    plan_movej,
    sample_moves,
    trapezoid_timing,
)

DATASETS = Path(__file__).resolve().parents[2] / "shared" / "datasets"
MOVEJ_LOG = DATASETS / "ur3e-aurt" / "AllJoints_MoveJ_Target.csv"


@pytest.mark.skipif(not MOVEJ_LOG.exists(), reason="shared datasets not available")
def test_movej_reproduces_the_ur_controller_profile() -> None:
    # AllJoints_MoveJ_Target.README: q from [-360,-185,0,-90,-90,0] to [360,15,-135,90,90,360] deg,
    # speed 40 deg/s, acceleration 60 deg/s^2; the controller's target q, qd, qdd at 125 Hz
    log = read_log(MOVEJ_LOG)
    way = np.radians([[-360, -185, 0, -90, -90, 0], [360, 15, -135, 90, 90, 360]])
    v, a = np.radians(40.0), np.radians(60.0)
    plan = plan_movej(way, speed=v, acceleration=a)
    t, q, qd = log.t, log["target_q"], log["target_qd"]
    moving = np.flatnonzero(np.any(qd != 0.0, axis=1))
    first, last = moving[0], moving[-1]
    lead = int(np.argmax(np.abs(way[1] - way[0])))
    # the log samples the 500 Hz controller at 125 Hz: the move began between two log samples
    start = t[first] - abs(qd[first, lead]) / a
    mq, mqd, _ = plan.sample(t - start)
    rms = np.sqrt(np.mean((mq - q) ** 2))
    assert rms < 1e-3
    assert np.max(np.abs(mqd - qd)) < 1e-3
    # same duration within 3 samples (8 ms each): the log's move ends at the first still sample
    logged = t[last + 1] - start
    assert abs(plan.total_time - logged) < 3 * 0.008
    motion = movej(way, speed=v, acceleration=a, dt=0.008)
    assert abs(motion.duration - logged) < 3 * 0.008


def test_movej_synchronises_joints_on_one_trapezoid() -> None:
    way = np.array([[0.0, 0.0, 0.0], [2.0, -1.0, 0.5], [2.0, 1.0, 0.4]])
    m = movej(way, speed=1.5, acceleration=3.0, dt=0.001)
    np.testing.assert_allclose(m.q[0], way[0])
    np.testing.assert_allclose(m.q[-1], way[-1], atol=1e-12)
    assert np.max(np.abs(m.qd)) <= 1.5 + 1e-12
    assert np.max(np.abs(m.qdd)) <= 3.0 + 1e-12
    # every joint's speed is the leading joint's scaled by its share of the travel
    first = m.t <= plan_movej(way, speed=1.5, acceleration=3.0).duration[0]
    np.testing.assert_allclose(m.qd[first, 1], -0.5 * m.qd[first, 0], atol=1e-12)
    np.testing.assert_allclose(m.qd[first, 2], 0.25 * m.qd[first, 0], atol=1e-12)
    # move 1: 2 rad at 1.5 rad/s, 3 rad/s^2 -> 2/1.5 + 0.5 s; move 2 (2 rad): the same
    plan = plan_movej(way, speed=1.5, acceleration=3.0)
    np.testing.assert_allclose(plan.duration, [2 / 1.5 + 0.5] * 2)
    # position is the integral of speed, speed of acceleration
    np.testing.assert_allclose(np.gradient(m.q, m.t, axis=0)[5:-5], m.qd[5:-5], atol=2e-3)


def test_movej_short_moves_are_triangles() -> None:
    plan = plan_movej([[0.0], [0.1]], speed=3.0, acceleration=6.0)
    # 0.1 rad < v^2/a = 1.5: peak sqrt(a d), duration 2 sqrt(d/a)
    assert plan.peak[0] == pytest.approx(np.sqrt(0.6))
    assert plan.duration[0] == pytest.approx(2 * np.sqrt(0.1 / 6.0))


def test_movej_blend_overlaps_moves_continuously() -> None:
    way = np.array([[0.0, 0.0], [1.0, 0.5], [2.0, 0.0]])
    plain = movej(way, speed=1.0, acceleration=2.0, dt=0.001)
    blended = movej(way, speed=1.0, acceleration=2.0, dt=0.001, blend=0.2)
    assert blended.duration < plain.duration
    np.testing.assert_allclose(blended.q[-1], way[-1], atol=1e-12)
    # continuous speed: no jumps bigger than a * dt
    assert np.max(np.abs(np.diff(blended.qd, axis=0))) <= 2 * 2.0 * 0.001 + 1e-12
    assert np.max(np.abs(blended.qd[:, 0])) <= 1.0 + 1e-12
    # the blended path passes near, not through, the middle waypoint
    dist = np.min(np.max(np.abs(blended.q - way[1]), axis=1))
    assert 0.0 < dist < 0.2


def test_movej_per_move_speeds() -> None:
    way = np.array([[0.0], [1.0], [0.0]])
    plan = plan_movej(way, speed=[1.0, 0.5], acceleration=[2.0, 1.0])
    np.testing.assert_allclose(plan.duration, [1.0 + 0.5, 2.0 + 0.5])


def test_movej_batched_over_programs_is_each_plan_on_its_own() -> None:
    # the optimiser plans and samples many candidate programs in one call: row b of the batch
    # must be exactly plan_movej/sample of row b's settings
    rng = np.random.default_rng(7)
    way = rng.uniform(-2.0, 2.0, (5, 3))
    way[2] = way[1]  # a move that does not move
    travel = np.max(np.abs(np.diff(way, axis=0)), axis=1)
    blend = np.array([0.1, 0.0, 0.2, 0.0])
    v = rng.uniform(0.3, 3.0, (6, 4))
    a = rng.uniform(0.5, 10.0, (6, 4))
    duration, ramp, peak = trapezoid_timing(travel, v, a)
    start = blend_starts(travel, blend, duration, a, ramp)
    t = np.sort(rng.uniform(0.0, 12.0, (6, 50)), axis=1)
    q, qd, qdd = sample_moves(way, t, start, duration, ramp, peak, a)
    for b in range(6):
        plan = plan_movej(way, speed=v[b], acceleration=a[b], blend=blend)
        assert np.array_equal(plan.start, start[b]) and np.array_equal(plan.duration, duration[b])
        one = plan.sample(t[b])
        for got, want in zip((q[b], qd[b], qdd[b]), one, strict=True):
            assert np.array_equal(got, want)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"waypoints": [[0.0, 1.0]], "speed": 1.0, "acceleration": 1.0}, "waypoints"),
        ({"waypoints": [[0.0], [1.0]], "speed": 0.0, "acceleration": 1.0}, "speed"),
        ({"waypoints": [[0.0], [1.0]], "speed": 1.0, "acceleration": [1.0, 2.0]}, "acceleration"),
        ({"waypoints": [[0.0], [np.nan]], "speed": 1.0, "acceleration": 1.0}, "waypoints"),
        ({"waypoints": [[0.0], [1.0]], "speed": 1.0, "acceleration": 1.0, "blend": -1.0}, "blend"),
    ],
)
def test_movej_bad_input(kwargs: dict, message: str) -> None:
    with pytest.raises(KinergyError, match=message):
        movej(**kwargs)


def test_fourier_series_derivatives_and_period() -> None:
    # nursing Table 6 coefficients, w_f = 0.2 pi
    a = np.array([[0.204, -0.004, -0.201], [0.163, -0.106, -0.056]])
    b = np.array([[0.139, -0.440, 0.247], [0.208, 0.074, -0.119]])
    q0 = np.array([0.002, 0.328])
    wf = 0.2 * np.pi
    t = np.linspace(0.0, 10.0, 20001)
    q, qd, qdd = fourier_series(t, q0, a, b, wf)
    np.testing.assert_allclose(np.gradient(q, t, axis=0)[2:-2], qd[2:-2], atol=1e-6)
    np.testing.assert_allclose(np.gradient(qd, t, axis=0)[2:-2], qdd[2:-2], atol=1e-5)
    np.testing.assert_allclose(q[0], q[-1], atol=1e-12)  # one period is 10 s
    m = fourier_motion(q0, a, b, base_frequency=wf, periods=2, dt=0.002)
    assert m.duration == pytest.approx(20.0)
    with pytest.raises(KinergyError, match="coefficients"):
        fourier_series(t, q0, a, b[:, :2], wf)


def test_top_level_movej_api() -> None:
    # movej(waypoints, *, speed, acceleration, dt) returning a motion with .t .q .qd .qdd
    import kinergy

    m = kinergy.movej([[0.0, 0.0], [0.5, -0.2]], speed=1.0, acceleration=2.0, dt=0.01)
    assert isinstance(m, kinergy.Motion)
    assert m.q.shape == m.qd.shape == m.qdd.shape == (len(m.t), 2)
    for name in ("load_robot", "rnea", "regressor", "inertial_parameters", "movej", "energy"):
        assert callable(getattr(kinergy, name))
