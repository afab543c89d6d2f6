"""Shared fixtures: seeded random states for any robot."""

from __future__ import annotations

import numpy as np
import pytest

import kinergy


def random_state(robot: kinergy.Robot, samples: int, seed: int) -> tuple[np.ndarray, ...]:
    """Angles uniform over the joint ranges (clipped to +-pi), speeds and accelerations normal."""
    rng = np.random.default_rng(seed)
    lo = np.array([max(j.limits.position[0], -np.pi) for j in robot.joints])
    hi = np.array([min(j.limits.position[1], np.pi) for j in robot.joints])
    q = rng.uniform(lo, hi, (samples, robot.n))
    qd = rng.normal(0.0, 1.5, (samples, robot.n))
    qdd = rng.normal(0.0, 3.0, (samples, robot.n))
    return q, qd, qdd


@pytest.fixture(scope="session")
def ur5e() -> kinergy.Robot:
    return kinergy.load_robot("ur5e")
