"""``inertia batch``: many files, folders and zip archives on Dask, into JSONL, CSV or Parquet.

    sources.py  PATH... -> Source (name, location, zip member)   [no Dask; the HTTP layer may use it]
    tasks.py    Source + AnalysisOptions -> JSON line           [runs on a worker]
    rows.py     JSON line -> flat CSV/Parquet row
    sinks.py    rows -> .jsonl / .csv / .parquet; --resume reads the names back
    runner.py   the Dask client: groups, bounded window, progress bar, head start
    workers.py  the forkserver local workers fork from (imports neither numpy nor Dask)

Every row is what ``pipeline.analyze`` gives for that file with the run's
options, so numbers equal those of ``inertia analyze``.  Dask, tqdm and pyarrow
are optional extras, imported only when a batch runs.
"""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .runner import BatchSummary

__all__ = ["BatchSummary", "run_batch", "run_batch_cli"]


def run_batch(*args: Any, **kwargs: Any) -> BatchSummary:
    """See :func:`service.batch.runner.run_batch`."""
    from .runner import run_batch as _run_batch

    return _run_batch(*args, **kwargs)


def run_batch_cli(args: argparse.Namespace) -> int:
    """``inertia batch``: run, print a one-line summary to stderr, exit 0.

    Files that fail are rows of the output, not a failure of the run; a bad
    option or a missing extra raises ``InvalidParameterError`` (exit 2).
    """
    if args.scheduler is None:  # a local cluster: its workers' imports start now, beside this process's
        from .workers import start_forkserver

        start_forkserver()
    from ..cli import options_from_args
    from .runner import run_batch as _run_batch

    summary = _run_batch(
        args.paths,
        args.out,
        options_from_args(args),
        resume=args.resume,
        workers=args.workers,
        scheduler=args.scheduler,
        progress=not args.no_progress,
    )
    print(summary.as_text(), file=sys.stderr)
    return 0


def __getattr__(name: str) -> Any:
    if name == "BatchSummary":
        from .runner import BatchSummary

        return BatchSummary
    raise AttributeError(name)
