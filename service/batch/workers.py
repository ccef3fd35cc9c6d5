"""Local worker processes fork from a ``forkserver`` that has imported the pipeline once.

With ``spawn`` every worker imports numpy and the pipeline again (and Dask,
for a Dask ``LocalCluster``), which on a small machine is most of a local
run's start-up.  The forkserver is
started as early as possible (``inertia batch`` starts it before it imports
numpy or Dask itself), so its imports run beside the command's own.  This
module imports neither.

A task on a Dask worker also undoes what Dask's environment does to glibc's
heap (``relax_frozen_heap_thresholds``, below).
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import sys

__all__ = [
    "DASK_WORKER_PRELOAD",
    "WORKER_PRELOAD",
    "WORKER_THREAD_LIMITS",
    "limit_numeric_threads",
    "relax_frozen_heap_thresholds",
    "start_forkserver",
]

# What local workers fork from: a forkserver that has imported these once.
_ROOT = __name__.split(".")[0]  # "inertia" when installed; the folder's name when run from a checkout
WORKER_PRELOAD = ["concurrent.futures.process", f"{_ROOT}.batch.tasks", f"{_ROOT}.batch._frozen"]
# ... and for the workers of a Dask LocalCluster (``run_batch(engine="dask")``), Dask as well.
DASK_WORKER_PRELOAD = ["distributed", *WORKER_PRELOAD]
# One thread per worker for the numeric libraries, as Dask's default pre-spawn
# environment sets (``distributed.nanny.pre-spawn-environ``); a value already
# in the environment wins, as in Dask.  The forkserver must start with them,
# since numpy reads them when the forkserver imports it: with OpenBLAS's own
# threads, two workers on two cores ran at about half speed.
WORKER_THREAD_LIMITS = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS")


def limit_numeric_threads() -> list[str]:
    """One thread per numeric library in this process and what it starts; returns the variables it set.

    For a process that computes nothing itself, such as the ``inertia batch``
    command, which lists inputs, hands out tasks and writes rows.  OpenBLAS
    starts a thread per core when numpy is imported, and each spins about
    0.1 s before it sleeps: on 16 cores that was 1.7 s of the command's CPU
    (2.06 s in all, against 0.40 s on 2 cores), taken from the workers
    while they start.  A value already in the environment wins, as for the
    workers; call it before numpy is imported.
    """
    added = [k for k in WORKER_THREAD_LIMITS if k not in os.environ]
    os.environ.update(dict.fromkeys(added, "1"))
    return added


def start_forkserver(preload: list[str] | None = None) -> bool:
    """Start the forkserver (if not running yet) with ``preload`` (default ``WORKER_PRELOAD``); False where there is none.

    The forkserver is one per process: if one is already running (an HTTP
    server's compute pool, an earlier cluster), workers fork from it and
    import what it lacks.  It does not block: the imports run in the server.
    """
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return False
    from multiprocessing import forkserver

    multiprocessing.get_context("forkserver").set_forkserver_preload(WORKER_PRELOAD if preload is None else preload)
    added = limit_numeric_threads()  # the forkserver inherits this environment
    try:
        forkserver.ensure_running()
    finally:
        for k in added:
            del os.environ[k]
    return True


# Dask's nanny starts every worker with MALLOC_TRIM_THRESHOLD_=65536 (``distributed.nanny.pre-spawn-environ``)
# so that freed memory goes back to the OS at once.  Setting it also freezes glibc's mmap threshold at 128 KiB:
# every numpy temporary above that is a fresh mmap whose pages fault in and are zeroed, and the heap above
# 64 KiB is trimmed at each free.  On a 327,680-triangle STL that made one analysis take 0.82 s of CPU and
# 256,000 page faults instead of 0.29 s and 4,500.  A task on such a worker therefore sets the two thresholds
# where glibc's own dynamic rule takes them at most (mallopt(3): the mmap threshold rises to
# DEFAULT_MMAP_THRESHOLD_MAX, 32 MiB on 64-bit systems, and the trim threshold is twice it): freed memory up
# to 64 MiB stays with the worker for the next file, as it would under glibc's defaults.
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3  # mallopt's parameter numbers (malloc.h)
_MMAP_THRESHOLD_MAX = 32 << 20
_relaxed: bool | None = None


def relax_frozen_heap_thresholds() -> bool:
    """In a Dask worker whose environment froze glibc's heap thresholds, raise them to glibc's dynamic maxima.

    Acts once per process, only where the ``distributed`` package is loaded and ``MALLOC_TRIM_THRESHOLD_``
    is set (a user's own setting in a local run is left alone), and only with glibc's ``mallopt``;
    returns whether the thresholds are now raised.
    """
    global _relaxed
    if _relaxed is None:
        _relaxed = False
        if "MALLOC_TRIM_THRESHOLD_" in os.environ and "distributed" in sys.modules:
            try:
                mallopt = ctypes.CDLL(None).mallopt
            except (OSError, AttributeError):  # not glibc (or no C library to load): nothing was frozen there
                return False
            _relaxed = bool(mallopt(_M_MMAP_THRESHOLD, _MMAP_THRESHOLD_MAX)) and bool(
                mallopt(_M_TRIM_THRESHOLD, 2 * _MMAP_THRESHOLD_MAX)
            )
    return _relaxed
