"""``inertia batch``: many files, folders and zip archives on Dask, into JSONL, CSV or Parquet.

    sources.py  PATH... -> Source (name, location, zip member)   [no Dask; the HTTP layer may use it]
    tasks.py    Source + AnalysisOptions -> JSON line           [runs on a worker]
    rows.py     JSON line -> flat CSV/Parquet row
    sinks.py    rows -> .jsonl / .csv / .parquet; --resume reads the names back
    runner.py   the Dask client: groups, bounded window, progress bar, head start
    workers.py  the forkserver local workers fork from (imports neither numpy nor Dask)

Every row is what ``pipeline.analyze`` gives for that file with the run's
options, so numbers equal those of ``inertia analyze``.  Dask, tqdm and pyarrow
are optional extras, imported only when a batch runs.  The command line
(``inertia batch``) lives in ``cli``: this package takes plain arguments.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .runner import BatchSummary

__all__ = ["BatchSummary", "run_batch"]


def run_batch(*args: Any, **kwargs: Any) -> BatchSummary:
    """See :func:`service.batch.runner.run_batch`."""
    from .runner import run_batch as _run_batch

    return _run_batch(*args, **kwargs)


def __getattr__(name: str) -> Any:
    if name == "BatchSummary":
        from .runner import BatchSummary

        return BatchSummary
    raise AttributeError(name)
