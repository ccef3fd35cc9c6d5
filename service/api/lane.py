"""A short way through the server for small point-mass requests.

A 3-point ``POST /v1/analyze/points`` is a few hundred microseconds of
analysis; FastAPI's routing, dependency resolution and request object cost
about as much again. This ASGI layer sits inside the access log, the API-key
and size guard and the last-resort handler, in front of FastAPI's router. For
that one path it reads the JSON body, validates it with the route's own model
(``PointsRequest``, from the JSON text with pydantic's parser: the same model
FastAPI builds from ``json.loads``' values, in one pass) and, when the job is
small (``is_small``), answers with ``run_job_json``'s bytes: the route's own
response, byte for byte. What that parser refuses and ``json.loads`` reads
(``NaN``, UTF-16 text) goes on to FastAPI, which decides as it always has.

Everything else goes on to FastAPI unchanged, with the body replayed: another
path or method, a body that is not ``application/json``, a body that does not
parse or validate (FastAPI then answers with its 422, as without this layer),
a job for the compute pool, and a failure other than the input's own error
(a 4xx ``ServiceError``, answered here with the envelope the error handler
writes). The route stays FastAPI's for the OpenAPI document and for all those
cases; ``tests/api/test_lane.py`` checks that the answers agree.
"""

from __future__ import annotations

from pydantic_core import to_json
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from ..errors import ServiceError
from .errors import error_response, status_of
from .jobs import PointsJob, is_small, run_job_json
from .schemas import PointsRequest

__all__ = ["POINTS_PATH", "SmallPointsLane"]

POINTS_PATH = "/v1/analyze/points"
_HEADERS = [(b"content-type", b"application/json")]
MAX_LANE_BYTES = 1 << 20
"""A body larger than this is no small job (1,000 points take ~100 kB): it goes on to FastAPI unparsed here."""


def _route_path(scope: Scope) -> str:
    """The path as the router matches it: without the application's mount point (``root_path``)."""
    path: str = scope["path"]
    root: str = scope.get("root_path", "")
    return path[len(root) :] if root and path.startswith(root) else path


def _is_json(scope: Scope) -> bool:
    """A ``Content-Type`` of ``application/json`` (parameters such as charset aside)."""
    for name, value in scope["headers"]:
        if name == b"content-type":
            media: bytes = value.split(b";", 1)[0].strip().lower()
            return media == b"application/json"
    return False


class SmallPointsLane:
    """``POST /v1/analyze/points`` for small jobs without FastAPI's routing; see the module's text."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http" or scope["method"] != "POST" or _route_path(scope) != POINTS_PATH or not _is_json(scope):
            await self.app(scope, receive, send)
            return
        messages: list[Message] = []
        chunks: list[bytes] = []
        size = 0
        while True:
            message = await receive()
            messages.append(message)
            if message["type"] != "http.request":
                break  # a disconnect: FastAPI sees it, as it would have
            chunks.append(message.get("body", b""))
            size += len(chunks[-1])
            if size > MAX_LANE_BYTES:
                break  # a large request: the route and the compute pool take it, parsed once
            if not message.get("more_body", False):
                job = _small_job(b"".join(chunks))
                if job is not None and await _answered(job, send):
                    return
                break
        await self.app(scope, _replay(messages, receive), send)


def _small_job(body: bytes) -> PointsJob | None:
    """The route's job for this body, if it validates and is small; else None (FastAPI decides)."""
    try:
        request = PointsRequest.model_validate_json(body)
        job = PointsJob(request.records(), request.as_options())
    except Exception:  # malformed JSON, a validation error, an option the route refuses: FastAPI's answer
        return None
    return job if is_small(job) else None


async def _answered(job: PointsJob, send: Send) -> bool:
    """Run the job and send its response; False (nothing sent) where the route's handlers must answer."""
    try:
        text = run_job_json(job, to_json)
    except ServiceError as exc:
        if status_of(exc) >= 500:
            return False  # logged and answered by the error handler
        response = error_response(exc)
        await send({"type": "http.response.start", "status": response.status_code, "headers": response.raw_headers})
        await send({"type": "http.response.body", "body": response.body})
        return True
    except Exception:  # a bug: the route raises it again, and the handlers log it and answer 500
        return False
    headers = [(b"content-length", b"%d" % len(text)), *_HEADERS]
    await send({"type": "http.response.start", "status": 200, "headers": headers})
    await send({"type": "http.response.body", "body": text})
    return True


def _replay(messages: list[Message], receive: Receive) -> Receive:
    """A ``receive`` that gives the messages already read, then the client's own."""
    pending = list(messages)

    async def replayed() -> Message:
        return pending.pop(0) if pending else await receive()

    return replayed
