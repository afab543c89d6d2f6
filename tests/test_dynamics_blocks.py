"""Large results from recycled memory (kinergy.dynamics.blocks): a result is always the caller's
own, the memory of a dropped one is reused, and the regressor is right in reused memory."""

from __future__ import annotations

import gc

import numpy as np
import pytest

import kinergy
from kinergy.dynamics import blocks

SHAPE = (15_000, 6, 60)  # 43 MB: a UR5e regressor of 30 s at 500 Hz


@pytest.fixture(autouse=True)
def empty_free_list():
    gc.collect()
    blocks._free.clear()
    yield
    gc.collect()
    blocks._free.clear()


def test_a_result_is_a_plain_writeable_float_array() -> None:
    y = blocks.result_array(SHAPE)
    assert y.shape == SHAPE and y.dtype == np.float64
    assert y.flags.c_contiguous and y.flags.writeable and not y.flags.owndata
    y[-1, -1, -1] = 1.5
    assert y.reshape(-1)[-1] == 1.5
    small = blocks.result_array((10, 6, 60))
    assert small.flags.owndata  # below MIN_BYTES: plain np.empty


def test_the_memory_of_a_dropped_result_is_reused() -> None:
    first = blocks.result_array(SHAPE)
    address = first.ctypes.data
    del first
    gc.collect()
    again = blocks.result_array(SHAPE)
    assert again.ctypes.data == address
    smaller = (10_000, 6, 60)  # 29 MB < MIN_BYTES: not from the free list
    del again
    assert blocks.result_array(smaller).flags.owndata


def test_memory_a_view_still_uses_is_never_handed_out() -> None:
    first = blocks.result_array(SHAPE)
    address = first.ctypes.data
    view = first[100:200].T  # only a view of the first result is left
    del first
    gc.collect()
    second = blocks.result_array(SHAPE)
    assert second.ctypes.data != address
    second.fill(7.0)
    view.fill(-1.0)
    assert np.all(second == 7.0)
    del view
    gc.collect()
    assert blocks.result_array(SHAPE).ctypes.data == address  # now free


def test_free_blocks_are_bounded() -> None:
    results = [blocks.result_array(SHAPE) for _ in range(8)]  # 8 x 43 MB
    del results
    gc.collect()
    assert sum(b.nbytes for b in blocks._free) <= blocks.KEEP_BYTES
    assert len(blocks._free) == blocks.KEEP_BYTES // (8 * int(np.prod(SHAPE)))


def test_regressor_is_right_in_reused_memory(ur5e: kinergy.Robot) -> None:
    """A result written into the memory of one full of NaN (the structural zeros written too)
    equals the result written into fresh zeros, and reproduces the RNEA (nursing eq 15)."""
    rng = np.random.default_rng(3)
    q, qd, qdd = (rng.normal(0.0, 1.0, SHAPE[:2]) for _ in range(3))
    first = kinergy.regressor(ur5e, q, qd, qdd)
    address = first.ctypes.data
    first.fill(np.nan)
    del first
    gc.collect()
    y = kinergy.regressor(ur5e, q, qd, qdd)
    assert y.ctypes.data == address
    fresh = np.zeros(SHAPE)
    kinergy.regressor(ur5e, q, qd, qdd, out=fresh)
    assert np.array_equal(y, fresh)
    tau = kinergy.rnea(ur5e, q, qd, qdd)
    assert np.allclose(y @ kinergy.inertial_parameters(ur5e), tau, rtol=0, atol=1e-9)
