"""How many threads the compiled dynamics kernels use, for the length of a ``with`` block.

The kernels (:mod:`kinergy.dynamics._kernels`) split samples over as many threads as numba's
thread count of the calling thread (:mod:`kinergy.dynamics.launch`). Callers that
evaluate small batches many times (the optimiser: a few thousand samples, thousands of times)
run faster on one thread, because a parallel launch costs more than the work and, on a busy
machine, far more (measured: 1.3 ms serial against 33 ms on two busy threads for one drive-model
call of 500 samples). numba's thread count belongs to the calling thread, so a setting here never
leaks to other threads, and it is restored when the block ends, even on an error.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import numba

__all__ = ["kernel_threads"]


@contextlib.contextmanager
def kernel_threads(count: int | None) -> Iterator[int]:
    """Run the dynamics kernels on ``count`` threads inside the block (None: leave as is).

    ``count`` is clipped to 1 .. the threads numba started with. Yields the count in force.
    """
    before = numba.get_num_threads()
    if count is None:
        yield before
        return
    most = int(getattr(numba.config, "NUMBA_NUM_THREADS", before))
    numba.set_num_threads(max(1, min(int(count), most)))
    try:
        yield numba.get_num_threads()
    finally:
        numba.set_num_threads(before)
