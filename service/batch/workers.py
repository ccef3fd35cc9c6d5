"""Local worker processes fork from a ``forkserver`` that has imported the pipeline once.

With ``spawn`` every worker imports numpy and the pipeline again (and Dask,
for a Dask ``LocalCluster``), which on a small machine is most of a local
run's start-up.  The forkserver is
started as early as possible (``inertia batch`` starts it before it imports
numpy or Dask itself), so its imports run beside the command's own.  This
module imports neither.
"""

from __future__ import annotations

import multiprocessing
import os

__all__ = ["DASK_WORKER_PRELOAD", "WORKER_PRELOAD", "WORKER_THREAD_LIMITS", "start_forkserver"]

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
    added = [k for k in WORKER_THREAD_LIMITS if k not in os.environ]
    os.environ.update(dict.fromkeys(added, "1"))  # the forkserver inherits this environment
    try:
        forkserver.ensure_running()
    finally:
        for k in added:
            del os.environ[k]
    return True
