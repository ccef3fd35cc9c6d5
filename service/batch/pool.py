"""The local engine: a plain pool of worker processes forked from a preloaded forkserver.

One process per core (``--workers N``), each running one task at a time.  A
task is a group of inputs (see ``runner._groups``); the worker reads its
files itself and sends back its rows rendered for the output, which the
client appends as each task finishes.  At most ``window`` tasks are in
flight, so memory stays bounded on the client (rows of the tasks in flight)
and on each worker (one task's files).

A worker that dies (killed for memory, a crash in a native library) breaks
the whole pool (``BrokenProcessPool``): every task in flight then fails,
though only one of them caused it.  The pool is started again, and the files
of those tasks are analysed one at a time, each alone on the pool, so the
file that kills its worker again is known for sure and becomes an
``unreadable_file`` row (as the HTTP service answers it); the others get
their rows as usual.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import signal
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from ..errors import UnreadableFileError
from ..pipeline import AnalysisOptions
from .rows import error_row
from .sinks import render
from .sources import Source
from .tasks import InternalError, render_sources
from .workers import start_forkserver

__all__ = ["died_on", "run_pool"]

Rendered = list[tuple[Any, bool]]


def _ignore_interrupts() -> None:
    """Workers leave Ctrl-C to the command, which stops them (no traceback from each worker)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _new_pool(workers: int) -> ProcessPoolExecutor:
    method = "forkserver" if start_forkserver() else "spawn"
    return ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context(method), initializer=_ignore_interrupts)


def _stop(pool: ProcessPoolExecutor) -> None:
    """Stop a pool now: pending tasks cancelled, running ones killed with their workers."""
    processes = list(getattr(pool, "_processes", {}).values())  # not public API: tolerate its absence
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in processes:
        with contextlib.suppress(Exception):
            proc.terminate()


Task = Callable[[list[Source], AnalysisOptions, str], Rendered]


def run_pool(
    groups: Iterator[list[Source]],
    workers: int,
    window: int,
    options: AnalysisOptions,
    fmt: str,
    write: Callable[[Rendered], None],
    task: Task = render_sources,
) -> None:
    """Analyse every group on ``workers`` local processes, ``window`` tasks in flight; ``write`` each task's rows.

    ``task`` (a module-level function the workers can import) is what runs on a group.
    """
    pool = _new_pool(workers)
    in_flight: dict[Future[Rendered], list[Source]] = {}
    suspects: list[Source] = []
    try:
        while True:
            while len(in_flight) < window:
                group = next(groups, None)
                if group is None:
                    break
                in_flight[pool.submit(task, group, options, fmt)] = group
            if not in_flight:
                break
            done, _ = wait(in_flight, return_when=FIRST_COMPLETED)
            broken = False
            for future in done:
                group = in_flight.pop(future)
                try:
                    rows = future.result()
                except BrokenProcessPool:
                    broken = True
                    suspects.extend(group)
                    continue
                except Exception as exc:  # the task itself failed (e.g. a row that cannot be pickled)
                    rows = [_failed(src, exc, fmt) for src in group]
                write(rows)
            if broken:
                for group in in_flight.values():
                    suspects.extend(group)
                in_flight.clear()
                _stop(pool)
                pool = _new_pool(workers)
                pool = _isolate(pool, suspects, workers, options, fmt, write, task)
                suspects = []
    except BaseException:  # Ctrl-C or an error writing rows: stop the workers rather than wait for them
        _stop(pool)
        raise
    pool.shutdown(wait=True)


def _isolate(
    pool: ProcessPoolExecutor,
    suspects: list[Source],
    workers: int,
    options: AnalysisOptions,
    fmt: str,
    write: Callable[[Rendered], None],
    task: Task,
) -> ProcessPoolExecutor:
    """Analyse the files that were in flight when a worker died, one at a time; returns the (new) pool."""
    for src in suspects:
        try:
            rows = pool.submit(task, [src], options, fmt).result()
        except BrokenProcessPool:
            rows = [died_on(src, fmt)]
            _stop(pool)
            pool = _new_pool(workers)
        except Exception as exc:
            rows = [_failed(src, exc, fmt)]
        write(rows)
    return pool


def died_on(src: Source, fmt: str) -> tuple[Any, bool]:
    """The row of a file whose worker died while it alone was analysed: a native reader crashed on it, or it
    needed more memory than there was (the file is what the user can act on, as the HTTP service says)."""
    err = UnreadableFileError(
        "the reader stopped abnormally on this file (its worker process died); the file may be corrupt or need "
        "more memory than a worker has: check it, or send a simpler one",
        filename=src.name,
    )
    return render(error_row(src.name, err), fmt), True


def _failed(src: Source, exc: BaseException, fmt: str) -> tuple[Any, bool]:
    err = InternalError(
        f"the analysis of this file failed on the worker ({type(exc).__name__}: {exc}); it may need more memory than a worker has"
    )
    return render(error_row(src.name, err), fmt), True
