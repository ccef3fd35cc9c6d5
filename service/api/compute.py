"""A small pool of compute processes with a hard per-job deadline.

Why processes, and why not ``concurrent.futures.ProcessPoolExecutor``: the
analyses are CPU-bound numpy, so a thread would keep the GIL busy between
numpy calls and, worse, cannot be stopped; a job past its deadline would go on
eating a core. ``ProcessPoolExecutor`` cannot stop one running job either
(killing a worker breaks the whole pool and every other request in it). So
each job runs in a process of our own; at the deadline that one process is
killed (the job really stops), the client gets 503 ``timeout``, and a fresh
process replaces it on the next request. Healthy processes are reused, so the
usual cost is one pickle of the upload each way, not a process start.

Processes come from the ``forkserver`` start method where it exists (a clean
single-threaded parent, safe in a threaded server) with the pipeline modules
preloaded, so a replacement starts in milliseconds.

Deadlines: waiting for a free process is bounded by ``timeout_s``, and the job
itself by ``timeout_s`` from the moment it is handed over; starting a process
is not counted. At most ``max_waiting`` jobs wait for a process; one more is
refused at once (503 ``server_busy`` with ``Retry-After``), so a burst of
heavy uploads cannot pile up without bound.

Memory: each job carries a limit (see :func:`memory_limit`); the compute
process sets it as its address-space limit (``RLIMIT_AS``, above what the
process already maps) for the job's duration and restores it after, so an
input that needs more fails with ``MemoryError`` (413) in that process only.
"""

from __future__ import annotations

import asyncio
import importlib
import logging
import math
import multiprocessing
import os
import sys
import threading
import time
import traceback
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from multiprocessing.connection import Connection
from typing import Any

from ..blocks import set_block_threads
from ..errors import ServiceError, UnreadableFileError
from .jobs import Job, MeshJob, run_job
from .transport import ComputeTimeoutError, ServerBusyError

__all__ = ["ComputePool", "WorkerCrashError", "memory_limit", "MEMORY_FLOOR_BYTES", "MEMORY_FACTOR", "COMPRESSED_MEMORY_FACTOR"]

MIB = 1024 * 1024
# A job may map this much more than its process did before it, plus a multiple of its upload's size.
# Measured peaks (docs/security.md): 3x the file for binary STL, 9-20x for OBJ/PLY/OFF/GLB text and
# buffers, plus ~60 MiB of readers imported on first use; formats whose content is compressed (3MF,
# VTK XML) may inflate up to 100x before parsing (load/guard.py), hence their larger factor.
MEMORY_FLOOR_BYTES = 768 * MIB
MEMORY_FACTOR = 32
COMPRESSED_MEMORY_FACTOR = 256
_COMPRESSED = (".3mf", ".vtu", ".vtp", ".vts", ".vtr", ".vti", ".zip")


def memory_limit(size: int, filename: str | None, cap: int) -> int:
    """Bytes a job on an upload of ``size`` bytes may add to its process's address space."""
    factor = COMPRESSED_MEMORY_FACTOR if (filename or "").lower().endswith(_COMPRESSED) else MEMORY_FACTOR
    return min(cap, MEMORY_FLOOR_BYTES + factor * size)


_ROOT = __name__.split(".")[0]  # "inertia" when installed; the folder's name when run from a checkout
log = logging.getLogger("inertia.api")

PRELOAD = [f"{_ROOT}.api.jobs", f"{_ROOT}.report", f"{_ROOT}.load.stl", f"{_ROOT}.load.meshes", f"{_ROOT}.motion"]
KILL_GRACE_S = 5.0  # how long to wait for a killed process to be reaped
START_TIMEOUT_S = 60.0  # how long a new compute process may take to import what jobs need


class WorkerCrashError(RuntimeError):
    """A compute process died or failed outside the pipeline's own errors."""


def _context() -> multiprocessing.context.BaseContext:
    if "forkserver" in multiprocessing.get_all_start_methods():
        ctx = multiprocessing.get_context("forkserver")
        ctx.set_forkserver_preload(PRELOAD)
        return ctx
    return multiprocessing.get_context("spawn")


def _address_space() -> int | None:
    """This process's mapped address space [bytes], where /proc tells it."""
    try:
        with open("/proc/self/statm") as fh:
            return int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return None


@contextmanager
def _memory_bounded(limit: int | None) -> Iterator[None]:
    """``RLIMIT_AS`` = what the process maps now + ``limit``, for the block only."""
    try:
        import resource
    except ImportError:  # not on this platform: the deadline still bounds the job
        yield
        return
    current = _address_space()
    if limit is None or current is None:
        yield
        return
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    wanted = current + limit
    if hard != resource.RLIM_INFINITY:
        wanted = min(wanted, hard)
    resource.setrlimit(resource.RLIMIT_AS, (wanted, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def _serve_jobs(conn: Connection) -> None:
    """Main loop of a compute process: say it is ready, then receive a job, send back its outcome."""
    # What a job needs is imported before the process counts as started, so a job's deadline never pays for
    # it: the forkserver is one per parent process and may have been started by someone else (the batch
    # engine) without these modules preloaded, which made a replacement's first job seconds long.
    for name in PRELOAD:
        importlib.import_module(name)
    # several compute processes share the machine, and a job's address-space limit leaves no room for the
    # stacks and heaps of more threads: a large mesh's block passes run on this process's one thread
    set_block_threads(1)
    conn.send(("ready", os.getpid()))
    while True:
        try:
            job = conn.recv()
        except (EOFError, OSError):
            return
        try:
            with _memory_bounded(job.memory_limit_bytes):
                outcome: tuple[str, Any] = ("ok", run_job(job))
        except ServiceError as exc:
            outcome = ("error", exc)
        except BaseException:
            outcome = ("crash", traceback.format_exc())
        try:
            conn.send(outcome)
        except Exception:
            conn.send(("crash", traceback.format_exc()))


@contextmanager
def _main_not_rerun() -> Iterator[None]:
    """Start a child without re-running the parent's ``__main__`` script.

    spawn and forkserver children import the parent's main script unless it
    was run with ``-m``; the job loop lives in this module and needs none of
    it, and a script without a ``__main__`` guard (or stdin) would break or
    start a second server in every worker.
    """
    main = sys.modules.get("__main__")
    hidden = main is not None and getattr(main, "__spec__", None) is None and hasattr(main, "__file__")
    if hidden:
        path = main.__file__  # type: ignore[union-attr]
        del main.__file__  # type: ignore[union-attr]
    try:
        yield
    finally:
        if hidden:
            main.__file__ = path  # type: ignore[union-attr]


_START_LOCK = threading.Lock()


class _Worker:
    def __init__(self, ctx: Any) -> None:  # a multiprocessing context (forkserver or spawn)
        parent, child = ctx.Pipe()
        self.process = ctx.Process(target=_serve_jobs, args=(child,), daemon=True, name="inertia-compute")
        with _START_LOCK, _main_not_rerun():
            self.process.start()
        child.close()
        self.conn = parent
        # start() returns once the process exists; wait until it has imported what jobs need and said so,
        # so that starting it (not counted against a job's deadline) really is over before a job is sent
        try:
            ready = parent.poll(START_TIMEOUT_S) and parent.recv()[0] == "ready"
        except (EOFError, OSError):
            ready = False
        if not ready:
            self.kill()
            parent.close()
            raise WorkerCrashError(
                f"compute process did not start within {START_TIMEOUT_S:g} s (exit code {self.process.exitcode})"
            )

    def call(self, job: Job) -> tuple[str, Any]:
        try:
            self.conn.send(job)
            return self.conn.recv()  # type: ignore[no-any-return]
        except (EOFError, OSError) as exc:
            self.conn.close()
            raise WorkerCrashError(f"compute process exited with code {self.process.exitcode}") from exc

    def kill(self) -> None:
        if self.process.is_alive():
            self.process.kill()
        self.process.join(KILL_GRACE_S)


def _died_on(job: MeshJob, worker: _Worker) -> UnreadableFileError:
    """A compute process that died while reading a client's file: a reader crashed on it (or ran out of memory
    where a library aborts instead of raising); the file is the cause the client can act on."""
    code = worker.process.exitcode
    log.error("compute process died (exit code %s) on file %r", code, job.filename)
    return UnreadableFileError(
        f"the reader stopped abnormally on this file (exit code {code}); the file may be corrupt or need more "
        f"than the {job.memory_limit_bytes or 0} bytes of memory allowed for it; check it or send a simpler one",
        exit_code=code,
        limit_bytes=job.memory_limit_bytes,
    )


class ComputePool:
    """At most ``size`` jobs at once, each in its own reusable process."""

    def __init__(self, size: int, timeout_s: float, max_waiting: int | None = None) -> None:
        self.size = size
        self.timeout_s = timeout_s
        self.max_waiting = 4 * size if max_waiting is None else max_waiting
        self._waiting = 0
        self._job_s = 1.0  # running mean of job durations, for Retry-After
        self._ctx = _context()
        self._idle: list[_Worker] = []
        self._lock = threading.Lock()
        self._slots: tuple[asyncio.AbstractEventLoop, asyncio.Semaphore] | None = None
        self._executor: ThreadPoolExecutor | None = None

    @property
    def _threads(self) -> ThreadPoolExecutor:
        # one thread per job in flight blocks on its pipe; extra room for spawns and killed jobs' threads.
        # Made on first use, so a pool that was closed (end of a lifespan) can serve again.
        with self._lock:
            if self._executor is None:
                self._executor = ThreadPoolExecutor(max_workers=2 * self.size + 2, thread_name_prefix="inertia-pipe")
            return self._executor

    async def warm_up(self) -> None:
        """Start the fork server and one process, so the first request does not wait for imports."""
        loop = asyncio.get_running_loop()
        worker = await loop.run_in_executor(self._threads, _Worker, self._ctx)
        self._release(worker)

    async def run(self, job: Job) -> dict[str, Any]:
        """The job's result; its ``ServiceError``, ``ComputeTimeoutError`` or ``WorkerCrashError``."""
        slots = self._slots_of(asyncio.get_running_loop())
        if slots.locked() and self._waiting >= self.max_waiting:
            raise self._busy()
        self._waiting += 1
        try:
            await asyncio.wait_for(slots.acquire(), self.timeout_s)
        except TimeoutError:
            raise self._timeout("the server is busy; no compute process became free", retry_after_s=self._retry_after()) from None
        finally:
            self._waiting -= 1
        start = time.monotonic()
        try:
            return await self._run_in_worker(job)
        finally:
            slots.release()
            self._job_s = 0.8 * self._job_s + 0.2 * (time.monotonic() - start)

    def _retry_after(self) -> int:
        return max(1, math.ceil(self._job_s * (self._waiting + 1) / self.size))

    def _busy(self) -> ServerBusyError:
        return ServerBusyError(
            f"the server is busy: {self.size} analyses are running and {self._waiting} are "
            "waiting; retry after the time in the Retry-After header",
            retry_after_s=self._retry_after(),
            waiting=self._waiting,
        )

    def _slots_of(self, loop: asyncio.AbstractEventLoop) -> asyncio.Semaphore:
        # a semaphore belongs to one event loop; a server has one, test clients may make several
        if self._slots is None or self._slots[0] is not loop:
            self._slots = (loop, asyncio.Semaphore(self.size))
        return self._slots[1]

    async def _run_in_worker(self, job: Job) -> dict[str, Any]:
        loop = asyncio.get_running_loop()
        worker = await loop.run_in_executor(self._threads, self._acquire)
        try:
            status, payload = await asyncio.wait_for(loop.run_in_executor(self._threads, worker.call, job), self.timeout_s)
        except TimeoutError:
            await loop.run_in_executor(self._threads, worker.kill)
            raise self._timeout("the computation took too long and was stopped") from None
        except WorkerCrashError as exc:
            await loop.run_in_executor(self._threads, worker.kill)
            if isinstance(job, MeshJob):
                raise _died_on(job, worker) from exc
            raise
        except BaseException:
            await asyncio.shield(loop.run_in_executor(self._threads, worker.kill))
            raise
        self._release(worker)
        if status == "ok":
            return payload  # type: ignore[no-any-return]
        if status == "error":
            raise payload
        raise WorkerCrashError(f"compute process failed:\n{payload}")

    def _timeout(self, what: str, **details: Any) -> ComputeTimeoutError:
        return ComputeTimeoutError(
            f"{what} (limit {self.timeout_s:g} s); send a smaller input or raise INERTIA_TIMEOUT_S",
            timeout_s=self.timeout_s,
            **details,
        )

    def _acquire(self) -> _Worker:
        with self._lock:
            while self._idle:
                worker = self._idle.pop()
                if worker.process.is_alive():
                    return worker
                worker.kill()
        return _Worker(self._ctx)

    def _release(self, worker: _Worker) -> None:
        with self._lock:
            self._idle.append(worker)

    def close(self) -> None:
        """Stop the idle processes; jobs still running end with their requests."""
        with self._lock:
            idle, self._idle = self._idle, []
            executor, self._executor = self._executor, None
        for worker in idle:
            worker.conn.close()
            worker.kill()
        if executor is not None:
            executor.shutdown(wait=False)
