"""Calling the compiled dynamics kernels: serially for small batches or one thread, else split
over a pool of Python threads (the kernels release the GIL). Each kernel is compiled at its
first use (only the ones a command calls), with a one-line notice on stderr when that takes a
while (a fresh install, no on-disk cache yet).

How many threads a call uses is numba's thread count of the calling thread
(:func:`kinergy.dynamics.threads.kernel_threads`, or the ``threads`` argument). Each of those
threads takes blocks of :data:`CHUNK` samples from a shared counter until none are left, so a
thread that the machine slows down takes fewer. Batches up to :data:`SERIAL_ROWS` samples run on
the calling thread: handing work to the pool costs tens of microseconds.
"""

from __future__ import annotations

import enum
import sys
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np

from kinergy.arrays import Array
from kinergy.dynamics import _kernels
from kinergy.dynamics.chain import KernelData
from kinergy.dynamics.threads import kernel_threads

__all__ = [
    "CHUNK",
    "SERIAL_ROWS",
    "Kernel",
    "compile_kernel",
    "regressor_gradient_into",
    "regressor_into",
    "rnea_into",
]


#: batches up to this many samples run serially
SERIAL_ROWS = 256
#: samples a thread takes at a time (a whole number of the kernels' lanes)
CHUNK = 8 * _kernels.LANES
#: the notice is printed when preparing a kernel takes longer than this, s (loading it from the
#: cache takes well under a second, even on a loaded machine, most of the time)
_NOTICE_AFTER = 2.0


class Kernel(enum.Enum):
    """A compiled dynamics kernel; the value names it in the compile notice."""

    RNEA = "RNEA"
    REGRESSOR = "regressor"
    GRADIENT = "regressor gradient"


#: what compiling each kernel takes on this project's two-core machine, processor time, s: quiet
#: (the RNEA in a first `kinergy demo`, 2026-11-27) and busy (load average 11, 2026-11-28, a
#: fresh NUMBA_CACHE_DIR: wall 82, 223 and 335 s)
_COMPILE_SECONDS = {
    Kernel.RNEA: (10, 21),
    Kernel.REGRESSOR: (15, 33),
    Kernel.GRADIENT: (30, 59),
}

_compiled: set[tuple[Kernel, bool]] = set()
_lock = threading.Lock()
_pool: ThreadPoolExecutor | None = None
#: set once the compile notice was printed: one notice per process, whatever the kernels
_noticed = threading.Event()


def _notice() -> str:
    """The one compile notice: what the kernels take, all of them, from measurements."""
    low = _COMPILE_SECONDS[Kernel.RNEA][0]
    high = sum(busy for _, busy in _COMPILE_SECONDS.values())
    return (
        "kinergy: preparing the dynamics kernels (numba compiles each one a command uses, once "
        f"per install: {low}-{high} s of processor time on a two-core machine, the RNEA alone "
        "the least; minutes of wall time when the machine is busy; later runs load them from "
        "the cache)"
    )


def _with_notice(compile_one: Callable[[], None], kernel: Kernel) -> None:
    """Run ``compile_one``, printing :func:`_notice` on stderr if it takes over
    :data:`_NOTICE_AFTER` (a compile, or a slow load from the cache), at most once per
    process."""

    def say() -> None:
        if not _noticed.is_set():
            _noticed.set()
            print(_notice(), file=sys.stderr, flush=True)

    timer = threading.Timer(_NOTICE_AFTER, say)
    timer.daemon = True
    timer.start()
    try:
        compile_one()
    finally:
        timer.cancel()


def compile_kernel(data: KernelData, kernel: Kernel) -> None:
    """Compile (or load from numba's cache) one kernel for ``data``'s chain type once per
    process, with a notice if that takes a while. Only the kernel a call needs is compiled:
    the RNEA (what simulation, prediction and energy use) takes about 10 s on a fresh install,
    the regressor (identification) 15 s more."""
    key = (kernel, data.z_first)
    if key in _compiled:
        return
    n = data.geo[0].shape[0]
    z = np.zeros((1, n))
    state = (z, z, z)
    g0 = data.ends[2]
    calls: dict[Kernel, Callable[[], None]] = {
        Kernel.RNEA: lambda: _rnea(data)(0, 1, data.geo, g0, data.body, state, np.empty((1, n))),
        Kernel.REGRESSOR: lambda: _regressor(data)(
            0, 1, data.geo, g0, state, np.empty((1, n, 10 * n)), True
        ),
        Kernel.GRADIENT: lambda: _kernels.regressor_gradient_rows(
            0, 1, data.geo, g0, state, np.zeros((1, n, 10 * n)), 1e-5, np.empty((3, 1, n))
        ),
    }
    with _lock:
        if key not in _compiled:
            _with_notice(calls[kernel], kernel)
            _compiled.add(key)


def _rnea(data: KernelData) -> Callable[..., None]:
    """The RNEA kernel for ``data``'s chain."""
    return _kernels.rnea_rows_dh if data.z_first else _kernels.rnea_rows


def _regressor(data: KernelData) -> Callable[..., None]:
    """The regressor kernel for ``data``'s chain."""
    return _kernels.regressor_rows_dh if data.z_first else _kernels.regressor_rows


def _shared_pool() -> ThreadPoolExecutor:
    """The process's worker threads, started at first use (as many as numba may use)."""
    global _pool
    with _lock:
        if _pool is None:
            most = int(getattr(numba.config, "NUMBA_NUM_THREADS", 1))
            _pool = ThreadPoolExecutor(max_workers=most, thread_name_prefix="kinergy-dynamics")
        return _pool


def _launch(
    kernel: Callable[..., None],
    rows: int,
    args: tuple[object, ...],
    threads: int | None,
    chunk: int = CHUNK,
) -> None:
    """``kernel(lo, hi, *args)`` over rows 0:rows: on the calling thread for batches up to
    :data:`SERIAL_ROWS` (or one ``chunk``, if smaller) or one thread, else in blocks of ``chunk``
    rows on as many threads as numba's thread count (or ``threads``) says, the calling thread and
    pool threads. If the calling thread is interrupted, the pool threads stop after the block
    they are on."""
    if threads is not None:
        with kernel_threads(threads):
            _launch(kernel, rows, args, None, chunk)
        return
    workers = min(numba.get_num_threads(), -(-rows // chunk))
    if rows <= min(SERIAL_ROWS, chunk) or workers <= 1:
        kernel(0, rows, *args)
        return
    starts = iter(range(0, rows, chunk))
    taken, stop = threading.Lock(), threading.Event()

    def work() -> None:
        while not stop.is_set():
            with taken:
                lo = next(starts, None)
            if lo is None:
                return
            kernel(lo, min(rows, lo + chunk), *args)

    # the calling thread works too: the blocks start at once on the core it already has, and the
    # pool's threads join as the system wakes them
    futures = [_shared_pool().submit(work) for _ in range(workers - 1)]
    try:
        work()
        for future in futures:
            future.result()
    finally:
        stop.set()


def rnea_into(
    data: KernelData,
    state: tuple[Array, Array, Array],
    tau: Array,
    g0: Array,
    threads: int | None = None,
) -> None:
    """Fill ``tau`` (N, n) with the RNEA torques of ``state`` (contiguous (N, n) each) under
    gravity ``g0`` (3,) in frame 0, on ``threads`` threads (None: as set)."""
    compile_kernel(data, Kernel.RNEA)
    args = (data.geo, g0, data.body, state, tau)
    _launch(_rnea(data), tau.shape[0], args, threads)


def regressor_into(
    data: KernelData,
    state: tuple[Array, Array, Array],
    y: Array,
    g0: Array | None = None,
    threads: int | None = None,
    *,
    clear: bool = True,
) -> None:
    """Fill ``y`` (N, n, 10 n) with the regressor of ``state`` on ``threads`` threads (None: as
    set); ``g0`` overrides the gravity in frame 0. ``clear=False`` leaves the structurally zero
    entries alone: for a ``y`` that holds zeros there (fresh ``np.zeros``, or a regressor)."""
    compile_kernel(data, Kernel.REGRESSOR)
    args = (data.geo, data.ends[2] if g0 is None else g0, state, y, clear)
    _launch(_regressor(data), y.shape[0], args, threads)


def regressor_gradient_into(
    data: KernelData,
    state: tuple[Array, Array, Array],
    weights: Array,
    sens: Array,
    step_q: float,
    threads: int | None = None,
) -> None:
    """Fill ``sens`` (3, N, n) with the derivatives of ``sum(weights * Y)`` in each sample's
    ``q``, ``qd``, ``qdd`` (:func:`kinergy.dynamics._kernels.regressor_gradient_rows`)."""
    compile_kernel(data, Kernel.GRADIENT)
    args = (data.geo, data.ends[2], state, weights, step_q, sens)
    # a sample costs 5 n + 1 regressors: the threads take one block of lanes at a time
    _launch(_kernels.regressor_gradient_rows, weights.shape[0], args, threads, _kernels.LANES)
