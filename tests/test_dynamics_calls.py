"""How the dynamics are called (issue 16): geometry cached per robot, ``out=`` arrays, blocks of
the regressor in one reused buffer, the thread count per call, serial and parallel paths giving
the same bits."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

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


def test_the_kernels_sines_and_cosines_match_the_c_library() -> None:
    """The kernels compute sin and cos themselves (so a block's loops vectorise): within 2 units
    in the last place of numpy's (measured: 1 up to 1000 rad, 2 at 1e5), exactly the C library's
    past the reduction's range, and NaN for a NaN or infinite angle."""
    from kinergy.dynamics._kernels import _REDUCE_MAX, LANES, _sincos

    rng = np.random.default_rng(11)
    spans = [np.pi / 4, 2 * np.pi, 50.0, _REDUCE_MAX]
    for span in spans:
        x = rng.uniform(-span, span, (400, LANES))
        x[0, :8] = [0.0, -0.0, np.pi / 4, np.pi / 2, np.pi, -np.pi / 2, 1e-300, 3 * np.pi / 4]
        cs = np.empty((2, LANES))
        for row in x:
            _sincos(row, cs)
            for got, want in ((cs[0], np.cos(row)), (cs[1], np.sin(row))):
                ulp = np.spacing(np.maximum(np.abs(want), 1e-300))
                assert np.all(np.abs(got - want) <= 2 * ulp), span
    beyond = np.full(LANES, 0.5)
    beyond[3] = 10 * _REDUCE_MAX
    cs = np.empty((2, LANES))
    _sincos(beyond, cs)
    np.testing.assert_array_equal(cs, [np.cos(beyond), np.sin(beyond)])
    for bad in (np.nan, np.inf):
        beyond[3] = bad
        _sincos(beyond, cs)
        assert np.isnan(cs[:, 3]).all() and np.isfinite(np.delete(cs, 3, axis=1)).all()


def test_read_only_and_writable_inputs_mix(ur5e: kinergy.Robot) -> None:
    """A read-only joint array beside writable ones (a memory-mapped log) is a different numba
    type: the kernels take the state apart instead of indexing it."""
    q, qd, qdd = _states(70)
    frozen = q.copy()
    frozen.setflags(write=False)
    np.testing.assert_array_equal(
        kinergy.rnea(ur5e, frozen, qd, qdd), kinergy.rnea(ur5e, q, qd, qdd)
    )
    np.testing.assert_array_equal(
        kinergy.regressor(ur5e, frozen, qd, qdd), kinergy.regressor(ur5e, q, qd, qdd)
    )


def test_a_call_compiles_only_its_own_kernel() -> None:
    """A fresh process that only simulates (the RNEA) compiles or loads no other kernel: the
    regressor and the gradient stay uncompiled (issue 29: a quick first run)."""
    code = (
        "import numpy as np, kinergy\n"
        "from kinergy.dynamics import _kernels, launch\n"
        "kinergy.rnea(kinergy.load_robot('ur5e'), np.zeros((300, 6)))\n"
        "print(sorted((k.value, z) for k, z in launch._compiled))\n"
        "print([len(f.signatures) for f in (_kernels.rnea_rows_dh, _kernels.rnea_rows,\n"
        "       _kernels.regressor_rows_dh, _kernels.regressor_rows,\n"
        "       _kernels.regressor_gradient_rows)])\n"
    )
    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": str(root)}
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
    )
    assert proc.stdout.splitlines() == ["[('RNEA', True)]", "[1, 0, 0, 0, 0]"]
