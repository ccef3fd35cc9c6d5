"""POST /v1/batch as a stream: one NDJSON line per file, in upload order, as results are ready.

Up to ``window`` files are in the compute pool at once; lines still leave in
upload order. A file that fails is an error line; nothing a file does can end
the batch. Each file gets the per-request time limit.
"""

from __future__ import annotations

import asyncio
import json
import logging
from collections import deque
from collections.abc import AsyncIterator, Iterator
from typing import Any

from starlette.concurrency import run_in_threadpool

from ..errors import ServiceError
from ..pipeline import AnalysisOptions
from .compute import ComputePool
from .jobs import MeshJob
from .uploads import Item

__all__ = ["batch_lines"]

log = logging.getLogger("inertia.api")


def _line(doc: dict[str, Any]) -> bytes:
    return json.dumps(doc, allow_nan=False, separators=(",", ":")).encode() + b"\n"


def _error_line(filename: str | None, exc: ServiceError) -> bytes:
    return _line({"source": {"filename": filename}, **exc.as_dict()})


async def _one(pool: ComputePool, item: Item, options: AnalysisOptions) -> bytes:
    if item.error is not None:
        return _error_line(item.filename, item.error)
    assert item.data is not None
    try:
        return _line(await pool.run(MeshJob(item.data, item.filename, options)))
    except ServiceError as exc:
        return _error_line(item.filename, exc)
    except Exception as exc:
        log.error("unexpected error on batch file %r", item.filename, exc_info=exc)
        return _line({"source": {"filename": item.filename}, "error": {
            "code": "internal_error", "message": "the server failed on this file; the error was logged",
            "details": {}}})


_DONE = object()


async def batch_lines(items: Iterator[Item], options: AnalysisOptions, pool: ComputePool,
                      window: int) -> AsyncIterator[bytes]:
    """NDJSON lines of ``items`` (a blocking iterator: read off the event loop)."""
    pending: deque[asyncio.Task[bytes]] = deque()
    try:
        while True:
            item = await run_in_threadpool(next, items, _DONE)
            if item is _DONE:
                break
            pending.append(asyncio.ensure_future(_one(pool, item, options)))  # type: ignore[arg-type]
            while len(pending) >= window or (pending and pending[0].done()):
                yield await pending.popleft()
        while pending:
            yield await pending.popleft()
    finally:
        for task in pending:  # the client went away: stop the work still queued
            task.cancel()
