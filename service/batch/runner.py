"""Run a batch on Dask: local worker processes by default, or an existing cluster.

The client lists the inputs (metadata only), drops those already in the output
(``--resume``), groups small files into tasks and keeps a bounded window of
tasks in flight (``as_completed`` as a sliding window): memory on the client
and on every worker stays bounded whatever the number of files.  Workers read
their inputs themselves (paths or fsspec URLs they can reach); only rows come
back, and each is written and flushed as soon as its task completes.

A local cluster is started in a background thread while this process
analyses the first small files itself, with the same task function the
workers run: the half second a cluster takes to start is not lost.  Its
workers fork from a ``forkserver`` that is started first, with Dask and the
pipeline already imported, so they do not import them again.

Scheduling, retries of tasks on workers that died, and the transport are
Dask's.  A task whose worker keeps dying (``KilledWorker``, e.g. out of
memory) is split into single files; a single file that still fails gets an
``internal_error`` row.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import sys
import time
import uuid
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

from ..errors import InvalidParameterError
from ..pipeline import AnalysisOptions
from .extras import ensure_installed, require
from .rows import error_row
from .sinks import Sink, done_names, open_sink, output_format
from .sources import Source, list_sources
from .tasks import InternalError, analyze_sources
from .workers import start_forkserver

_ROOT = __name__.split(".")[0]  # "inertia" when installed; the folder's name when run from a checkout

__all__ = ["BatchSummary", "connect", "local_cluster", "run_batch"]

# A task groups files until it holds this much input: ~0.1 s of analysis at
# the pipeline's ~40 MB/s, far above Dask's ~1 ms of overhead per task.
TASK_BYTES = 4 << 20
# ... or this many files, so progress and load balance stay fine-grained.
TASK_FILES = 32
# At least this many tasks per worker thread when there are enough files, so
# the last tasks do not leave workers idle.
TASKS_PER_THREAD = 8
# Tasks in flight per worker thread: enough to hide the round trip, few enough
# to bound memory (each holds at most TASK_BYTES of input plus its rows).
WINDOW_PER_THREAD = 4
# While the local cluster starts, this process analyses files up to this size
# itself (~20,000 triangles of binary STL, ~10 ms each): it stays responsive
# to the cluster being ready, and large files wait for the workers, whose
# memory the nanny watches.
HEAD_START_BYTES = 1 << 20
# Python's switch interval while the cluster starts beside the head start (the default is 5 ms).
HEAD_START_SWITCH_S = 0.0005


# Dask starts workers with MALLOC_TRIM_THRESHOLD_=65536 so that freed memory
# goes back to the OS at once.  Setting it also freezes glibc's mmap threshold
# at 128 KiB, so every large numpy temporary is a fresh mmap whose pages fault
# in and get zeroed: the pipeline then needed ~3x the CPU on meshes of 1e5
# triangles and ~1.5x on 1e6 (even with a 32 MiB mmap threshold added).  Our
# tasks hold one file at a time, so glibc's own dynamic thresholds (which
# trim freed heap beyond twice the largest recent mmap, at most 64 MiB) keep
# worker memory flat; the local workers run without the variable.
DROPPED_ENV = ("MALLOC_TRIM_THRESHOLD_",)


@dataclass(frozen=True, slots=True)
class BatchSummary:
    """What a run did: files analysed, of which failed, and skipped by ``--resume``."""

    analysed: int
    errors: int
    skipped: int
    elapsed_s: float
    out: str

    def as_text(self) -> str:
        rate = self.analysed / self.elapsed_s if self.elapsed_s > 0 else 0.0
        return (f"{self.analysed} files analysed ({self.errors} errors), {self.skipped} skipped as already in "
                f"{self.out}; {self.elapsed_s:.1f} s, {rate:.1f} files/s")


_DASK = {"purpose": "a batch run", "extra": "batch", "parameter": "workers"}


def _distributed() -> Any:
    return require("distributed", **_DASK)


def local_cluster(workers: int | None = None) -> Any:
    """The default engine: one single-threaded worker process per core (or ``workers``)."""
    distributed = _distributed()
    n = _worker_count(workers)
    import dask

    method = "forkserver" if start_forkserver() else "spawn"
    environ = {k: v for k, v in dask.config.get("distributed.nanny.pre-spawn-environ", {}).items()
               if k not in DROPPED_ENV}
    settings = {"distributed.worker.multiprocessing-method": method, "distributed.nanny.pre-spawn-environ": environ,
                "distributed.worker.profile.enabled": False}
    with dask.config.set(settings):
        return distributed.LocalCluster(
            n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=logging.ERROR,
            preload=[f"{_ROOT}.batch.tasks"],  # a no-op after a forkserver; spawned workers import it at start-up
        )


def _worker_count(workers: int | None) -> int:
    n = workers if workers is not None else (os.cpu_count() or 1)
    if n < 1:
        raise InvalidParameterError(f"--workers must be at least 1, got {n}", parameter="workers")
    return n


def connect(scheduler: str | None, workers: int | None) -> tuple[Any, Any]:
    """(client, cluster it owns or None): ``scheduler`` is an address, else a local cluster."""
    distributed = _distributed()
    if scheduler is not None:
        try:
            return distributed.Client(scheduler, timeout="30s"), None
        except OSError as exc:
            raise InvalidParameterError(
                f"cannot reach the Dask scheduler at {scheduler!r}: {exc}", parameter="scheduler"
            ) from exc
    cluster = local_cluster(workers)
    return distributed.Client(cluster), cluster


def run_batch(
    paths: Sequence[str],
    out: str,
    options: AnalysisOptions = AnalysisOptions(),
    *,
    resume: bool = False,
    workers: int | None = None,
    scheduler: str | None = None,
    client: Any = None,
    progress: bool = True,
) -> BatchSummary:
    """Analyse every input under ``paths`` into ``out`` (.jsonl, .csv or .parquet).

    Runs on ``client`` when given, else on the cluster at ``scheduler``, else
    on a local cluster of ``workers`` processes started for this run (this
    process analyses the first small files while it starts).
    """
    start = time.perf_counter()
    if scheduler is not None and workers is not None:
        raise InvalidParameterError("give --workers (a local cluster) or --scheduler (an existing one), not both",
                                    parameter="workers")
    output_format(out)  # fail on a bad --out before any work
    local = client is None and scheduler is None
    if local:  # a bad --workers or a missing extra fails before any work too
        ensure_installed("distributed", **_DASK)
        _worker_count(workers)
        start_forkserver()  # its imports run while this process lists the inputs
    sources = list_sources([_absolute(p) for p in paths])
    done = done_names(out) if resume else set()
    pending = [s for s in sources if s.name not in done]
    skipped = len(sources) - len(pending)
    output = _Output(open_sink(out, resume), _progress_bar(len(pending), progress and bool(pending)))
    try:
        if not pending:  # nothing to do: no cluster, but the output exists as for any run
            pass
        elif client is not None:
            _distribute(client, pending, options, output)
        elif scheduler is not None:
            client, _ = connect(scheduler, None)
            try:
                _distribute(client, pending, options, output)
            finally:
                client.close()
        else:
            _run_local(pending, workers, options, output)
    finally:
        output.close()
    return BatchSummary(len(pending), output.errors, skipped, time.perf_counter() - start, out)


def _absolute(path: str) -> str:
    return path if "://" in path else os.path.abspath(path)


class _Output:
    """The sink, the progress bar and the error count of one run."""

    def __init__(self, sink: Sink, bar: Any) -> None:
        self.sink, self.bar, self.errors = sink, bar, 0

    def write(self, rows: list[dict[str, Any]]) -> None:
        for row in rows:
            self.sink.write(row)
            self.errors += "error" in row
        self.sink.flush()
        self.bar.update(len(rows))

    def close(self) -> None:
        try:
            self.bar.close()
        finally:
            self.sink.close()


def _run_local(pending: list[Source], workers: int | None, options: AnalysisOptions, output: _Output) -> None:
    """Start a local cluster in the background, analyse small files here meanwhile, then hand over the rest.

    Dask is imported first (the forkserver imports it at the same time, on the
    other core).  While the cluster thread starts the scheduler and the
    workers, Python's switch interval is cut to ``HEAD_START_SWITCH_S``: a
    thread waiting for the GIL otherwise gets it only every 5 ms, and the
    cluster's many short steps would each wait behind an analysis.
    """
    distributed = _distributed()
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="inertia-local-cluster") as pool:
        starting = pool.submit(local_cluster, workers)
        try:
            with _switch_interval(HEAD_START_SWITCH_S):
                rest = _head_start(pending, starting.done, options, output)
        except BaseException:
            _close_when_started(starting)
            raise
        cluster = starting.result()
    try:
        if rest:
            client = distributed.Client(cluster)
            try:
                _distribute(client, rest, options, output)
            finally:
                client.close()
    finally:
        cluster.close()


@contextlib.contextmanager
def _switch_interval(seconds: float) -> Iterator[None]:
    previous = sys.getswitchinterval()
    sys.setswitchinterval(seconds)
    try:
        yield
    finally:
        sys.setswitchinterval(previous)


def _head_start(pending: list[Source], ready: Callable[[], bool], options: AnalysisOptions,
                output: _Output) -> list[Source]:
    """Analyse small files here, one at a time, until ``ready()``; returns the files left for the workers."""
    deferred: list[Source] = []
    for i, src in enumerate(pending):
        if ready():
            return deferred + pending[i:]
        if src.size is None or src.size > HEAD_START_BYTES:
            deferred.append(src)
            continue
        output.write(analyze_sources([src], options))
    return deferred


def _close_when_started(starting: Future[Any]) -> None:
    with contextlib.suppress(Exception):  # the error being raised matters more than a failed start
        starting.result().close()


def _distribute(client: Any, pending: list[Source], options: AnalysisOptions, output: _Output) -> None:
    """Run ``pending`` on the cluster behind ``client``, a bounded window of tasks at a time."""
    distributed = _distributed()
    threads = max(1, sum(client.nthreads().values()))
    tasks = _groups(pending, threads)
    run_id = uuid.uuid4().hex[:8]
    counter = iter(range(sys.maxsize))
    in_flight: dict[str, list[Source]] = {}

    def submit(group: list[Source], ac: Any) -> None:
        key = f"inertia-batch-{run_id}-{next(counter)}"
        in_flight[key] = group
        ac.add(client.submit(analyze_sources, group, options, key=key, pure=False, retries=0))

    ac = distributed.as_completed()
    for group in _take(tasks, WINDOW_PER_THREAD * threads):
        submit(group, ac)
    for future in ac:
        group = in_flight.pop(future.key)
        output.write(_rows(future, group, lambda g: submit(g, ac)))
        future.release()
        for group in _take(tasks, 1):
            submit(group, ac)


def _rows(future: Any, group: list[Source], resubmit: Callable[[list[Source]], None]) -> list[dict[str, Any]]:
    """The rows of a finished task; a task that failed as a whole is split or reported."""
    try:
        rows: list[dict[str, Any]] = future.result()
        return rows
    except Exception as exc:
        if len(group) > 1:
            for src in group:
                resubmit([src])
            return []
        err = InternalError(f"the analysis of this file failed on the worker ({type(exc).__name__}: {exc}); "
                            "it may need more memory than a worker has")
        return [error_row(group[0].name, err)]


def _take(it: Iterator[list[Source]], n: int) -> Iterator[list[Source]]:
    for _ in range(n):
        item = next(it, None)
        if item is None:
            return
        yield item


def _groups(sources: list[Source], threads: int) -> Iterator[list[Source]]:
    """Consecutive groups of sources: one large file, or several small ones."""
    per_task = max(1, min(TASK_FILES, math.ceil(len(sources) / (threads * TASKS_PER_THREAD))))
    group: list[Source] = []
    size = 0
    for src in sources:
        group.append(src)
        size += src.size or 0
        if len(group) >= per_task or size >= TASK_BYTES:
            yield group
            group, size = [], 0
    if group:
        yield group


def _progress_bar(total: int, enabled: bool) -> Any:
    try:
        from tqdm import tqdm  # type: ignore[import-untyped,unused-ignore]
    except ImportError as exc:
        if enabled:
            raise InvalidParameterError(
                "the progress bar needs tqdm: pip install 'inertia-service[batch]' (or pass --no-progress)",
                parameter="no_progress",
            ) from exc
        return _NoBar()
    # tqdm shows the count, the rate (files/s) and the ETA
    return tqdm(total=total, unit="file", file=sys.stderr, disable=not enabled, dynamic_ncols=True,
                smoothing=0.1)


class _NoBar:
    def update(self, n: int) -> None:
        pass

    def close(self) -> None:
        pass
