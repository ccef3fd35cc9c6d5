"""Run a batch: a pool of local worker processes by default, or an existing Dask cluster.

The client lists the inputs (metadata only), drops those already in the output
(``--resume``), groups small files into tasks sized by their bytes and keeps a
bounded window of tasks in flight (a sliding window): memory on the client and
on every worker stays bounded whatever the number of files.  Workers read
their inputs themselves (paths or fsspec URLs they can reach); only rendered
rows come back, and each task's rows are written and flushed as soon as it
completes.

Engines:

- ``pool`` (the local default): ``concurrent.futures.ProcessPoolExecutor``
  whose workers fork from a ``forkserver`` that has imported the pipeline
  once (``pool.py``).  Measured against a Dask ``LocalCluster`` on the same
  machine it starts in a fraction of the time and costs ~0.1 ms per task
  instead of ~1-2 ms, with no scheduler in the client (``docs/batch.md``).
- ``dask``: a ``dask.distributed`` cluster: ``--scheduler ADDRESS`` (or a
  ``client``), or, from Python, ``engine="dask"`` for a ``LocalCluster``
  started in a background thread while this process analyses the first small
  files itself (its head start).

Scheduling, retries of tasks on workers that died, and the transport are
Dask's.  A task whose worker keeps dying (``KilledWorker``, e.g. out of
memory) is split into single files; a single file that still fails gets an
``internal_error`` row.
"""

from __future__ import annotations

import contextlib
import logging
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
from .pool import died_on, run_pool
from .rows import error_row
from .sinks import Sink, done_names, open_sink, output_format, render
from .sources import Source, list_sources
from .tasks import InternalError, render_sources
from .workers import DASK_WORKER_PRELOAD, start_forkserver

_ROOT = __name__.split(".")[0]  # "inertia" when installed; the folder's name when run from a checkout

__all__ = ["BatchSummary", "connect", "local_cluster", "run_batch"]

# Tasks are sized by the work they hold, estimated from bytes: a file's size
# plus FILE_COST_BYTES for what every file costs whatever its size (opening,
# parsing the header, the fixed steps of the analysis: ~0.5 ms, what the
# pipeline spends on ~20-40 KB of binary STL).
FILE_COST_BYTES = 32 << 10
# A task holds about total / (threads * TASKS_PER_THREAD) of the work, so each
# worker gets several tasks and the last ones end close together ...
TASKS_PER_THREAD = 8
# ... but at least this much, so the per-task cost stays ~1% of the task:
# ~0.1 ms on the local pool against ~25 ms of analysis in 1 MiB; Dask's ~1-3 ms
# per task (scheduler, transport, worker) against ~100 ms in 4 MiB.
MIN_TASK_BYTES = {"pool": 1 << 20, "dask": 4 << 20}
# ... and at most this much, so progress and load balance stay fine-grained.
MAX_TASK_BYTES = 32 << 20
# Tasks in flight per worker thread: enough to hide the round trip, few enough
# to bound memory (a task in flight holds its list of sources, then its rows).
WINDOW_PER_THREAD = 4
ENGINES = ("pool", "dask")
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
# worker memory flat; the local workers run without the variable, and on a
# cluster started elsewhere each worker's first task raises the thresholds
# itself (``workers.relax_frozen_heap_thresholds``).
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
        return (
            f"{self.analysed} files analysed ({self.errors} errors), {self.skipped} skipped as already in "
            f"{self.out}; {self.elapsed_s:.1f} s, {rate:.1f} files/s"
        )


_DASK = {"purpose": "a batch run", "extra": "batch", "parameter": "workers"}


def _distributed() -> Any:
    return require("distributed", **_DASK)


def local_cluster(workers: int | None = None) -> Any:
    """The default engine: one single-threaded worker process per core (or ``workers``)."""
    distributed = _distributed()
    n = _worker_count(workers)
    import dask

    method = "forkserver" if start_forkserver(DASK_WORKER_PRELOAD) else "spawn"
    environ = {k: v for k, v in dask.config.get("distributed.nanny.pre-spawn-environ", {}).items() if k not in DROPPED_ENV}
    settings = {
        "distributed.worker.multiprocessing-method": method,
        "distributed.nanny.pre-spawn-environ": environ,
        "distributed.worker.profile.enabled": False,
    }
    with dask.config.set(settings):
        return distributed.LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            silence_logs=logging.ERROR,
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
            raise InvalidParameterError(f"cannot reach the Dask scheduler at {scheduler!r}: {exc}", parameter="scheduler") from exc
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
    engine: str = "pool",
) -> BatchSummary:
    """Analyse every input under ``paths`` into ``out`` (.jsonl, .csv or .parquet).

    Runs on ``client`` when given, else on the Dask cluster at ``scheduler``,
    else on ``workers`` local processes started for this run: a process pool
    (``engine="pool"``, the default) or a Dask ``LocalCluster``
    (``engine="dask"``, with a head start in this process).
    """
    start = time.perf_counter()
    if scheduler is not None and workers is not None:
        raise InvalidParameterError(
            "give --workers (a local cluster) or --scheduler (an existing one), not both", parameter="workers"
        )
    if engine not in ENGINES:
        raise InvalidParameterError(f"unknown engine {engine!r}; use one of {', '.join(ENGINES)}", parameter="engine")
    fmt = output_format(out)  # fail on a bad --out before any work
    local = client is None and scheduler is None
    if local:  # a bad --workers or a missing extra fails before any work too
        if engine == "dask":
            ensure_installed("distributed", **_DASK)
        _worker_count(workers)
        # its imports run while this process lists the inputs
        start_forkserver(DASK_WORKER_PRELOAD if engine == "dask" else None)
    sources = list_sources([_absolute(p) for p in paths])
    done = done_names(out) if resume else set()
    pending = [s for s in sources if s.name not in done]
    skipped = len(sources) - len(pending)
    output = _Output(open_sink(out, resume), _progress_bar(len(pending), progress and bool(pending)), fmt)
    try:
        if not pending:  # nothing to do: no workers, but the output exists as for any run
            pass
        elif client is not None:
            _distribute(client, pending, options, output)
        elif scheduler is not None:
            client, _ = connect(scheduler, None)
            try:
                _distribute(client, pending, options, output)
            finally:
                client.close()
        elif engine == "pool":
            n = min(_worker_count(workers), len(pending))
            run_pool(_groups(pending, n, MIN_TASK_BYTES["pool"]), n, WINDOW_PER_THREAD * n, options, fmt, output.write)
        else:
            _run_local(pending, workers, options, output)
    finally:
        output.close()
    return BatchSummary(len(pending), output.errors, skipped, time.perf_counter() - start, out)


def _absolute(path: str) -> str:
    return path if "://" in path else os.path.abspath(path)


class _Output:
    """The sink, the progress bar and the error count of one run."""

    def __init__(self, sink: Sink, bar: Any, fmt: str) -> None:
        self.sink, self.bar, self.fmt, self.errors = sink, bar, fmt, 0

    def write(self, rendered: list[tuple[Any, bool]]) -> None:
        """Append one task's rows, rendered by ``tasks.render_sources`` for this output's format."""
        for row, is_error in rendered:
            self.sink.write_rendered(row)
            self.errors += is_error
        self.sink.flush()
        self.bar.update(len(rendered))

    def close(self) -> None:
        try:
            self.bar.close()
        finally:
            self.sink.close()


def _run_local(pending: list[Source], workers: int | None, options: AnalysisOptions, output: _Output) -> None:
    """Start a Dask LocalCluster in the background, analyse small files here meanwhile, then hand over the rest.

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


def _head_start(pending: list[Source], ready: Callable[[], bool], options: AnalysisOptions, output: _Output) -> list[Source]:
    """Analyse small files here, one at a time, until ``ready()``; returns the files left for the workers."""
    deferred: list[Source] = []
    for i, src in enumerate(pending):
        if ready():
            return deferred + pending[i:]
        if src.size is None or src.size > HEAD_START_BYTES:
            deferred.append(src)
            continue
        output.write(render_sources([src], options, output.fmt))
    return deferred


def _close_when_started(starting: Future[Any]) -> None:
    with contextlib.suppress(Exception):  # the error being raised matters more than a failed start
        starting.result().close()


def _distribute(client: Any, pending: list[Source], options: AnalysisOptions, output: _Output) -> None:
    """Run ``pending`` on the Dask cluster behind ``client``, a bounded window of tasks at a time."""
    distributed = _distributed()
    threads = max(1, sum(client.nthreads().values()))
    tasks = _groups(pending, threads, MIN_TASK_BYTES["dask"])
    run_id = uuid.uuid4().hex[:8]
    counter = iter(range(sys.maxsize))
    in_flight: dict[str, list[Source]] = {}
    fmt = output.fmt

    def submit(group: list[Source], ac: Any) -> None:
        key = f"inertia-batch-{run_id}-{next(counter)}"
        in_flight[key] = group
        ac.add(client.submit(render_sources, group, options, fmt, key=key, pure=False, retries=0))

    ac = distributed.as_completed()
    for group in _take(tasks, WINDOW_PER_THREAD * threads):
        submit(group, ac)
    for future in ac:
        group = in_flight.pop(future.key)
        output.write(_rows(future, group, lambda g: submit(g, ac), fmt))
        future.release()
        for group in _take(tasks, 1):
            submit(group, ac)


def _rows(future: Any, group: list[Source], resubmit: Callable[[list[Source]], None], fmt: str = "jsonl") -> list[tuple[Any, bool]]:
    """The rendered rows of a finished task; a task that failed as a whole is split or reported."""
    try:
        rows: list[tuple[Any, bool]] = future.result()
        return rows
    except Exception as exc:
        if len(group) > 1:
            for src in group:
                resubmit([src])
            return []
        if type(exc).__name__ == "KilledWorker":  # the file alone kept killing its workers: as the local pool says it
            return [died_on(group[0], fmt)]
        err = InternalError(
            f"the analysis of this file failed on the worker ({type(exc).__name__}: {exc}); "
            "it may need more memory than a worker has"
        )
        return [(render(error_row(group[0].name, err), fmt), True)]


def _take(it: Iterator[list[Source]], n: int) -> Iterator[list[Source]]:
    for _ in range(n):
        item = next(it, None)
        if item is None:
            return
        yield item


def _cost(src: Source) -> int:
    return (src.size or 0) + FILE_COST_BYTES


def _groups(sources: list[Source], threads: int, min_bytes: int) -> Iterator[list[Source]]:
    """Groups of sources of about equal work, the largest files first.

    A group holds about total / (threads * TASKS_PER_THREAD) of the work
    (size + ``FILE_COST_BYTES`` per file), kept between ``min_bytes`` and
    ``MAX_TASK_BYTES``; a file larger than that is a group by itself.  The
    largest files go first (the longest tasks start first, and the small
    ones fill the end), which is the classic rule for an even finish.
    """
    total = sum(_cost(src) for src in sources)
    target = min(MAX_TASK_BYTES, max(min_bytes, total // max(1, threads * TASKS_PER_THREAD)))
    group: list[Source] = []
    work = 0
    for src in sorted(sources, key=_cost, reverse=True):  # stable: equal sizes keep their listing order
        group.append(src)
        work += _cost(src)
        if work >= target:
            yield group
            group, work = [], 0
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
    return tqdm(total=total, unit="file", file=sys.stderr, disable=not enabled, dynamic_ncols=True, smoothing=0.1)


class _NoBar:
    def update(self, n: int) -> None:
        pass

    def close(self) -> None:
        pass
