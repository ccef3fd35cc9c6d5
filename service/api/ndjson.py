"""POST /v1/batch as a stream: one NDJSON line per file, in upload order, as results are ready.

Up to ``window`` files are in the compute pool at once; lines still leave in
upload order. A file that fails is an error line; nothing a file does can end
the batch: an archive that fails while it is being unpacked gives an error
line, and the stream always ends after a complete line. Each file gets the
per-request time limit.
"""

from __future__ import annotations

import asyncio
import json
import logging
import shutil
from collections import deque
from collections.abc import AsyncIterator, Iterator
from typing import Any

from starlette.concurrency import run_in_threadpool

from ..errors import ServiceError, UnreadableFileError, envelope
from ..pipeline import AnalysisOptions
from .compute import ComputePool, memory_limit
from .jobs import MeshJob
from .uploads import Item

__all__ = ["batch_lines"]

log = logging.getLogger("inertia.api")


def _line(doc: dict[str, Any]) -> bytes:
    return json.dumps(doc, allow_nan=False, separators=(",", ":")).encode() + b"\n"


def _error_line(filename: str | None, error: dict[str, Any]) -> bytes:
    """The line of a file that failed: its name and the envelope (as batch rows write it)."""
    return _line({"source": {"filename": filename}, **error})


async def _one(pool: ComputePool, item: Item, options: AnalysisOptions, folder: str, memory_cap: int) -> bytes:
    if item.error is not None:
        return _error_line(item.filename, item.error.as_dict())
    assert item.path is not None
    job = MeshJob(item.path, item.filename, options, folder, memory_limit(item.size, item.filename, memory_cap))
    try:
        return _line(await pool.run(job))
    except ServiceError as exc:
        return _error_line(item.filename, exc.as_dict())
    except Exception as exc:
        log.error("unexpected error on batch file %r", item.filename, exc_info=exc)
        return _error_line(item.filename, envelope("internal_error", "the server failed on this file; the error was logged"))


def _next(items: Iterator[Item]) -> tuple[Item | None, bool]:
    """The next item (None at the end) and whether it is the last; a failure of the iteration itself
    (an archive that cannot be unpacked further) is a last error item."""
    try:
        item = next(items, None)
    except Exception as exc:
        log.error("unpacking the batch failed", exc_info=exc)
        return Item(
            None,
            error=UnreadableFileError(
                f"the upload could not be unpacked further ({type(exc).__name__}); the files before this line were analysed"
            ),
        ), True
    return item, item is None


async def batch_lines(
    items: Iterator[Item], options: AnalysisOptions, pool: ComputePool, window: int, folder: str, memory_cap: int
) -> AsyncIterator[bytes]:
    """NDJSON lines of ``items`` (a blocking iterator: read off the event loop); removes ``folder`` at the end."""
    pending: deque[asyncio.Task[bytes]] = deque()
    try:
        while True:
            item, last = await run_in_threadpool(_next, items)
            if item is not None:
                pending.append(asyncio.ensure_future(_one(pool, item, options, folder, memory_cap)))
            if last:
                break
            while len(pending) >= window or (pending and pending[0].done()):
                yield await pending.popleft()
        while pending:
            yield await pending.popleft()
    finally:
        for task in pending:  # the client went away: stop the work still queued
            task.cancel()
        if pending:
            await asyncio.gather(*pending, return_exceptions=True)  # killed processes are reaped first
        shutil.rmtree(folder, ignore_errors=True)
