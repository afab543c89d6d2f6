"""How the dynamics are called (issue 16): geometry cached per robot, ``out=`` arrays, blocks of
the regressor in one reused buffer, the thread count per call, serial and parallel paths giving
the same bits."""

from __future__ import annotations

import numpy as np
import pytest

import kinergy
from kinergy.dynamics.chain import kernel_data
from kinergy.dynamics.launch import SERIAL_ROWS
from kinergy.dynamics.regressor import regressor_chunks
from kinergy.errors import KinergyError


@pytest.fixture(scope="module")
def ur5e() -> kinergy.Robot:
    return kinergy.load_robot("ur5e")


def _states(n: int, seed: int = 3) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.uniform(-3, 3, (n, 6)), rng.normal(size=(n, 6)), rng.normal(size=(n, 6))


def test_the_geometry_is_built_once_per_robot(ur5e: kinergy.Robot) -> None:
    assert kernel_data(ur5e) is kernel_data(ur5e)
    other = kinergy.load_robot("ur5e")
    assert kernel_data(other) is not kernel_data(ur5e)


def test_out_arrays_are_filled_and_returned(ur5e: kinergy.Robot) -> None:
    q, qd, qdd = _states(700)
    tau = np.full((700, 6), np.nan)
    assert kinergy.rnea(ur5e, q, qd, qdd, out=tau) is tau
    np.testing.assert_array_equal(tau, kinergy.rnea(ur5e, q, qd, qdd))
    y = np.full((700, 6, 60), np.nan)  # any contents on entry
    assert kinergy.regressor(ur5e, q, qd, qdd, out=y) is y
    np.testing.assert_array_equal(y, kinergy.regressor(ur5e, q, qd, qdd))
    one = np.empty(6)
    kinergy.rnea(ur5e, q[0], qd[0], qdd[0], out=one)
    np.testing.assert_array_equal(one, tau[0])


@pytest.mark.parametrize(
    "bad", [np.empty((5, 6)), np.empty((700, 6), dtype=np.float32), np.empty((6, 700)).T]
)
def test_a_wrong_out_array_is_refused(ur5e: kinergy.Robot, bad: np.ndarray) -> None:
    q, qd, qdd = _states(700)
    with pytest.raises(KinergyError, match="out: expected a writeable C-contiguous float64"):
        kinergy.rnea(ur5e, q, qd, qdd, out=bad)


def test_regressor_blocks_equal_the_whole(ur5e: kinergy.Robot) -> None:
    q, qd, qdd = _states(1000)
    whole = kinergy.regressor(ur5e, q, qd, qdd)
    seen = 0
    for part, block in regressor_chunks(ur5e, q, qd, qdd, rows=300):
        np.testing.assert_array_equal(block, whole[part])
        seen += block.shape[0]
    assert seen == 1000


@pytest.mark.parametrize("threads", [1, 2])
def test_serial_and_parallel_paths_give_the_same_bits(ur5e: kinergy.Robot, threads: int) -> None:
    q, qd, qdd = _states(4 * SERIAL_ROWS + 7)
    tau = kinergy.rnea(ur5e, q, qd, qdd, threads=threads)
    y = kinergy.regressor(ur5e, q, qd, qdd, threads=threads)
    for k in (0, SERIAL_ROWS, len(q) - 1):  # one sample at a time: the serial path
        np.testing.assert_array_equal(kinergy.rnea(ur5e, q[k], qd[k], qdd[k]), tau[k])
        np.testing.assert_array_equal(kinergy.regressor(ur5e, q[k], qd[k], qdd[k]), y[k])


def test_regressor_gradient_matches_central_differences(ur5e: kinergy.Robot) -> None:
    from kinergy.dynamics.regressor import regressor_gradient

    q, qd, qdd = _states(40)
    weights = np.random.default_rng(9).normal(size=(40, 6, 60))
    sens = regressor_gradient(ur5e, q, qd, qdd, weights)

    def f(*x: np.ndarray) -> np.ndarray:
        return np.einsum("sic,sic->s", weights, kinergy.regressor(ur5e, *x))

    h = 1e-6
    for kind in range(3):
        for j in range(6):
            up, down = [q.copy(), qd.copy(), qdd.copy()], [q.copy(), qd.copy(), qdd.copy()]
            up[kind][:, j] += h
            down[kind][:, j] -= h
            numeric = (f(*up) - f(*down)) / (2 * h)
            np.testing.assert_allclose(sens[kind, :, j], numeric, rtol=1e-6, atol=1e-6)
