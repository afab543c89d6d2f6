"""Calling the compiled dynamics kernels: serially for small batches or one thread, split over
numba's threads otherwise; compiled at first use, with a one-line notice on stderr when that
takes a while (a fresh install, no on-disk cache yet).

A parallel launch costs tens of microseconds (far more on a busy machine) and one sample costs
about one, so batches up to :data:`SERIAL_ROWS` samples, and any batch inside
``kernel_threads(1)``, run on the calling thread.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable

import numba
import numpy as np

from kinergy.arrays import Array
from kinergy.dynamics import _kernels
from kinergy.dynamics.chain import KernelData
from kinergy.dynamics.threads import kernel_threads

__all__ = [
    "SERIAL_ROWS",
    "compile_kernels",
    "regressor_gradient_into",
    "regressor_into",
    "rnea_into",
]


#: batches up to this many samples run serially
SERIAL_ROWS = 256
#: the notice is printed when compiling takes longer than this, s
_NOTICE_AFTER = 1.0
_NOTICE = "kinergy: compiling the dynamics kernels (once, about 20 s)"

_compiled: set[str] = set()
_lock = threading.Lock()


def _with_notice(compile_all: Callable[[], None]) -> None:
    """Run ``compile_all``, printing :data:`_NOTICE` on stderr if it takes over a second."""
    timer = threading.Timer(_NOTICE_AFTER, lambda: print(_NOTICE, file=sys.stderr, flush=True))
    timer.daemon = True
    timer.start()
    try:
        compile_all()
    finally:
        timer.cancel()


def compile_kernels(data: KernelData, *, gradient: bool = False) -> None:
    """Compile (or load from numba's cache) the dynamics kernels once per process (with
    ``gradient``, the regressor gradient's too), with a notice if that takes a while."""
    zf = data.z_first
    if f"dynamics{zf}" in _compiled and (not gradient or f"gradient{zf}" in _compiled):
        return
    n = data.geo[0].shape[0]
    z = np.zeros((1, n))
    state = (z, z, z)

    def dynamics() -> None:
        args = (data.geo, data.ends, data.body, state, np.empty((0, 6)), np.empty((1, n)))
        serial, parallel = _rnea(data)
        parallel(*args)
        serial(0, 1, *args)
        y = np.empty((1, n, 10 * n))
        serial, parallel = _regressor(data)
        parallel(data.geo, data.ends[2], state, y, True)
        serial(0, 1, data.geo, data.ends[2], state, y, True)

    def gradients() -> None:
        w = np.zeros((1, n, 10 * n))
        args = (data.geo, data.ends[2], state, w, 1e-5, np.empty((3, 1, n)))
        _kernels.regressor_gradient_kernel(*args)
        _kernels.regressor_gradient_rows(0, 1, *args)

    with _lock:
        for key, fn in (("dynamics", dynamics), ("gradient", gradients if gradient else None)):
            if fn is not None and f"{key}{zf}" not in _compiled:
                _with_notice(fn)
                _compiled.add(f"{key}{zf}")


def _rnea(data: KernelData) -> tuple[Callable[..., None], Callable[..., None]]:
    """The serial and the parallel RNEA kernel for ``data``'s chain."""
    if data.z_first:
        return _kernels.rnea_rows_dh, _kernels.rnea_kernel_dh
    return _kernels.rnea_rows, _kernels.rnea_kernel


def _regressor(data: KernelData) -> tuple[Callable[..., None], Callable[..., None]]:
    """The serial and the parallel regressor kernel for ``data``'s chain."""
    if data.z_first:
        return _kernels.regressor_rows_dh, _kernels.regressor_kernel_dh
    return _kernels.regressor_rows, _kernels.regressor_kernel


def _launch(
    serial: Callable[..., None],
    parallel: Callable[..., None],
    rows: int,
    args: tuple[object, ...],
    threads: int | None,
    serial_rows: int = SERIAL_ROWS,
) -> None:
    """``serial(0, rows, *args)`` for batches up to ``serial_rows`` or one thread, else
    ``parallel(*args)``."""
    if threads is not None:
        with kernel_threads(threads):
            _launch(serial, parallel, rows, args, None, serial_rows)
    elif rows <= serial_rows or numba.get_num_threads() == 1:
        serial(0, rows, *args)
    else:
        parallel(*args)


def rnea_into(
    data: KernelData,
    state: tuple[Array, Array, Array],
    wrench: Array,
    tau: Array,
    g0: Array | None = None,
    threads: int | None = None,
) -> None:
    """Fill ``tau`` (N, n) with the RNEA torques of ``state`` (contiguous (N, n) each) on
    ``threads`` threads (None: as set); ``wrench`` (N, 6) or (0, 6); ``g0`` overrides the
    gravity in frame 0."""
    compile_kernels(data)
    ends = data.ends if g0 is None else (data.ends[0], data.ends[1], g0)
    args = (data.geo, ends, data.body, state, wrench, tau)
    _launch(*_rnea(data), tau.shape[0], args, threads)


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
    compile_kernels(data)
    args = (data.geo, data.ends[2] if g0 is None else g0, state, y, clear)
    _launch(*_regressor(data), y.shape[0], args, threads)


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
    compile_kernels(data, gradient=True)
    args = (data.geo, data.ends[2], state, weights, step_q, sens)
    _launch(
        _kernels.regressor_gradient_rows,
        _kernels.regressor_gradient_kernel,
        weights.shape[0],
        args,
        threads,
        _kernels.GRADIENT_CHUNK,
    )
