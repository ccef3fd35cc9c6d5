"""The blocks of a large mesh's element-wise passes, on several threads.

The passes over a large mesh (the signed volumes, each integration pass,
the double-double rotation, the areas) already run in blocks of a few
thousand elements, so that their temporaries stay in the cache; each block
writes its own slice of a preallocated result and the slices are combined
afterwards in a fixed order (the integration sums add the per-block sums
pairwise, in block order).  The blocks are independent, so running them
on several threads gives results bit-identical to one thread: no sum is
taken in a different order.  numpy releases the GIL in its element-wise
loops, gathers and reductions, where nearly all of a block's time goes.

How many threads: ``INERTIA_THREADS`` when set, else ``OMP_NUM_THREADS``
when set (the variable Dask's nanny and our own batch workers set to 1:
a worker that is one of many on a machine computes on one thread), else
the CPUs this process may use (``cpus.available_cpus``), at most
``MAX_THREADS``.  Small meshes, too few blocks to share, run on the
calling thread alone.
"""

from __future__ import annotations

import ctypes
import functools
import os
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor, wait

from .cpus import available_cpus

__all__ = ["block_threads", "for_each_block", "set_block_threads", "single_heap", "MAX_THREADS", "THREADS_VARIABLE"]

THREADS_VARIABLE = "INERTIA_THREADS"
# beyond this the passes are bound by memory bandwidth, not by cores
MAX_THREADS = 8
# a pass is shared only when each thread gets at least this many blocks ...
MIN_BLOCKS_PER_THREAD = 2
# ... and beyond two threads it takes one more per this many blocks, so that the temporaries of the
# blocks in flight stay a small part of the pass's own data: the peak memory of a 1e6-triangle STL is
# 2.9x the file on two threads, and was 3.1x with eight (5e6 triangles: 2.2x with eight)
BLOCKS_PER_EXTRA_THREAD = 12

_lock = threading.Lock()
_pool: ThreadPoolExecutor | None = None
_pool_threads = 0
_fixed: int | None = None  # set_block_threads
_in_block = threading.local()  # .active: this thread is running a block


def block_threads() -> int:
    """Threads for the blocks of one pass: ``INERTIA_THREADS``, else ``OMP_NUM_THREADS``, else the usable CPUs."""
    if _fixed is not None:
        return _fixed
    for name in (THREADS_VARIABLE, "OMP_NUM_THREADS"):
        value = os.environ.get(name, "").strip()
        if value:
            try:
                return max(1, min(int(value), MAX_THREADS))
            except ValueError:
                continue  # not a number: as if unset (numpy's own libraries ignore such a value too)
    return min(_usable_cpus(), MAX_THREADS)


@functools.cache
def _usable_cpus() -> int:
    return available_cpus()


def set_block_threads(threads: int | None) -> None:
    """Fix this process's thread count for block passes (None: back to the environment's).

    A compute process of the HTTP server sets 1: several of them share the
    machine, and each job runs under an address-space limit that every
    extra thread (its stack, its malloc arena) would eat into.
    """
    global _fixed
    _fixed = None if threads is None else max(1, min(int(threads), MAX_THREADS))


def for_each_block(work: Callable[[int], None], starts: Sequence[int]) -> None:
    """``work(start)`` for every block start, on up to ``block_threads()`` threads; returns when all are done.

    Two threads take part from four blocks on, and one more for every
    ``BLOCKS_PER_EXTRA_THREAD`` blocks.  The calling thread takes blocks
    too, beside threads of a pool kept for the process; blocks are handed
    out one at a time, in order.  Each call must write only its own
    block's slice of the results.  After an exception no further block
    starts, and the first exception is raised here once the blocks running
    have ended.  A block that itself calls ``for_each_block`` runs that
    pass on its own thread.
    """
    few = len(starts) < 2 * MIN_BLOCKS_PER_THREAD  # decided first: most meshes are one block
    threads = 1 if few or getattr(_in_block, "active", False) else block_threads()
    threads = min(threads, max(2, len(starts) // BLOCKS_PER_EXTRA_THREAD))
    if threads <= 1 or len(starts) < MIN_BLOCKS_PER_THREAD * threads:
        for start in starts:
            work(start)
        return
    pending = iter(starts)
    take = threading.Lock()
    errors: list[BaseException] = []

    def drain() -> None:
        _in_block.active = True
        try:
            while not errors:
                with take:
                    start = next(pending, None)
                if start is None:
                    return
                try:
                    work(start)
                except BaseException as exc:
                    errors.append(exc)
        finally:
            _in_block.active = False

    pool = _executor(block_threads() - 1)  # one pool for every pass, however many of its threads a pass takes
    helpers = [pool.submit(drain) for _ in range(threads - 1)]
    drain()
    wait(helpers)
    if errors:
        raise errors[0]


def _executor(threads: int) -> ThreadPoolExecutor:
    global _pool, _pool_threads
    with _lock:
        if _pool is None or _pool_threads != threads:
            if _pool is not None:
                _pool.shutdown(wait=False)
            _pool = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="inertia-blocks")
            _pool_threads = threads
        return _pool


_M_ARENA_MAX = -8  # mallopt's parameter number (malloc.h)


def single_heap() -> bool:
    """Every thread allocates from the main heap (glibc's ``M_ARENA_MAX`` = 1); False where that is not glibc.

    For a process of ours that runs block passes on several threads, the
    ``inertia analyze`` command: glibc gives each thread a heap (an arena)
    of its own, which keeps that thread's freed temporaries.  At 1e6
    triangles that added 12 MB to the peak (3.2x the STL file's size
    against 2.9x on one thread); with one heap the peak is that of one
    thread, at the same speed.
    """
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    return bool(mallopt(_M_ARENA_MAX, 1))


def _forget_pool_in_child() -> None:
    """A forked child has none of the parent's threads: it starts its own pool when it needs one."""
    global _lock, _pool, _pool_threads
    _lock, _pool, _pool_threads = threading.Lock(), None, 0


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pool_in_child)
