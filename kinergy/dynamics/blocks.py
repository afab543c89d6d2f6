"""Large result arrays from recycled memory: the cure for the page faults of a fresh result.

A fresh (N, n, 10 n) regressor of N = 15,000 UR5e samples is 43 MB. An array that large is
mapped fresh from the operating system by every ``np.empty`` or ``np.zeros`` (glibc maps
anything over 32 MB on its own and unmaps it when freed), so every call pays a page fault per
page it writes: measured 4.5 ms of processor time for 43 MB on this kind of virtual machine,
where the kernel itself takes 11 ms on one core, and the faults of two threads writing into the
same fresh mapping wait for each other, which is why two threads gained little
(``benchmarks/README.md``).

:func:`result_array` keeps the memory of a result that nothing refers to any more and hands it
to the next result of about the same size, whose pages are then already mapped. It never hands
out memory that an array still uses: each result's base is a small holder object, every view
of the result keeps the holder alive, and only when the last of them is gone does a finaliser
return the block to the free list. So a caller always gets an array of its own; only the bytes
of one it has dropped come back. At most :data:`KEEP_BYTES` of free blocks are kept; a block
that would exceed it is freed, and a block is only reused for a request of at least half its
size.
"""

from __future__ import annotations

import threading
import weakref

import numpy as np

from kinergy.arrays import Array

__all__ = ["KEEP_BYTES", "MIN_BYTES", "result_array"]

#: results smaller than this come from ``np.empty`` (glibc reuses freed memory below 32 MB)
MIN_BYTES = 32 * 2**20
#: free blocks kept for later results at most, bytes
KEEP_BYTES = 256 * 2**20

_free: list[Array] = []
#: re-entrant: a garbage collection inside :func:`_take` may run a finaliser, :func:`_release`
_lock = threading.RLock()


class _Holder:
    """The base of one result: exposes ``block``'s first bytes as the result's array and keeps
    ``block`` alive as long as any view of the result exists."""

    def __init__(self, block: Array, shape: tuple[int, ...]) -> None:
        self.block = block
        self.__array_interface__ = {
            "data": (block.ctypes.data, False),
            "shape": shape,
            "typestr": "<f8",
            "version": 3,
        }


def _release(block: Array) -> None:
    """Put ``block`` on the free list, unless that would keep more than :data:`KEEP_BYTES`."""
    with _lock:
        if sum(b.nbytes for b in _free) + block.nbytes <= KEEP_BYTES:
            _free.append(block)


def _take(nbytes: int) -> Array:
    """A free block of ``nbytes`` to twice that (the smallest), or a new one."""
    with _lock:
        fits = [b for b in _free if nbytes <= b.nbytes <= 2 * nbytes]
        if fits:
            block = min(fits, key=lambda b: b.nbytes)
            _free.remove(block)
            return block
    return np.empty(nbytes, dtype=np.uint8)


def result_array(shape: tuple[int, ...]) -> Array:
    """An uninitialised C-contiguous float64 array of ``shape`` that is the caller's own (no
    other live array shares its memory); above :data:`MIN_BYTES` its memory may be that of a
    result nothing refers to any more (module docstring), so its contents are arbitrary."""
    nbytes = 8 * int(np.prod(shape))
    if nbytes < MIN_BYTES:
        return np.empty(shape)
    holder = _Holder(_take(nbytes), shape)
    weakref.finalize(holder, _release, holder.block)
    return np.asarray(holder)
