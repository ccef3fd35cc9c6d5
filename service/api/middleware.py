"""ASGI middleware: access log, API key and body-size limit, before any body is read."""

from __future__ import annotations

import hmac
import json
import logging
import time
from typing import Any

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from ..errors import ServiceError
from .errors import error_response, internal_error_response
from .settings import Settings
from .transport import PayloadTooLargeError, UnauthorizedError

__all__ = ["AccessLog", "Guard", "LastResort"]

access_log = logging.getLogger("inertia.api.access")
log = logging.getLogger("inertia.api")

PROTECTED_PREFIX = "/v1/"


class AccessLog:
    """One JSON line per request at INFO: method, path, status, elapsed_ms."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        start = time.perf_counter()
        status = 500  # what the client sees if the app raises before answering

        async def send_logged(message: Message) -> None:
            nonlocal status
            if message["type"] == "http.response.start":
                status = message["status"]
            await send(message)

        try:
            await self.app(scope, receive, send_logged)
        finally:
            client = scope.get("client")
            access_log.info(
                json.dumps(
                    {
                        "event": "access",
                        "method": scope["method"],
                        "path": scope["path"],
                        "status": status,
                        "elapsed_ms": round((time.perf_counter() - start) * 1e3, 3),
                        "client": client[0] if client else None,
                    }
                )
            )


class LastResort:
    """An exception that escapes the app (a bug) becomes the 500 envelope with ``Connection: close``.

    Starlette's outermost handler answers too, but then re-raises, and the
    server drops the connection without saying so: a keep-alive client sends
    its next request into a closed socket. Here the exception stops, logged;
    the response tells the client to reconnect, and the server closes the
    connection after it. A response already under way cannot be replaced; it
    is ended (the client sees a truncated body, never a hang).
    """

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        started = False

        async def tracked_send(message: Message) -> None:
            nonlocal started
            if message["type"] == "http.response.start":
                started = True
            await send(message)

        try:
            await self.app(scope, receive, tracked_send)
        except Exception as exc:
            log.error("unexpected error on %s %s", scope.get("method"), scope.get("path"), exc_info=exc)
            if started:
                raise
            await internal_error_response()(scope, receive, send)


class Guard:
    """Refuse a request before its body is read: a missing API key (401) or a body too large (413).

    A declared ``Content-Length`` over the limit is refused at once. A body
    without one (chunked) is counted as it streams in; at the limit the client
    gets 413 and the application sees a disconnect, so at most the limit (plus
    one chunk) is ever read.
    """

    def __init__(self, app: ASGIApp, settings: Settings) -> None:
        self.app = app
        self.limit = settings.max_upload_bytes
        self.api_key = settings.api_key.encode() if settings.api_key else None

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        headers = dict(scope["headers"])
        refusal = self._refusal(scope["path"], headers)
        if refusal is not None:
            await error_response(refusal)(scope, receive, send)
            return
        await self._counted(scope, receive, send)

    def _refusal(self, path: str, headers: dict[bytes, bytes]) -> ServiceError | None:
        if self.api_key is not None and path.startswith(PROTECTED_PREFIX):
            given = headers.get(b"x-api-key", b"")
            if not hmac.compare_digest(given, self.api_key):
                return UnauthorizedError("missing or wrong API key; send it in the X-API-Key header")
        declared = headers.get(b"content-length")
        if declared is not None and declared.isdigit() and int(declared) > self.limit:
            return self._too_large(int(declared))
        return None

    def _too_large(self, size: int | None) -> PayloadTooLargeError:
        details: dict[str, Any] = {"limit_bytes": self.limit}
        if size is not None:
            details["content_length"] = size
        return PayloadTooLargeError(
            f"the request body is larger than the limit of {self.limit} bytes; send a smaller file "
            "or raise INERTIA_MAX_UPLOAD_BYTES",
            **details,
        )

    async def _counted(self, scope: Scope, receive: Receive, send: Send) -> None:
        received = 0
        refused = False
        started = False

        async def counting_receive() -> Message:
            nonlocal received, refused
            if refused:
                return {"type": "http.disconnect"}
            message = await receive()
            if message["type"] == "http.request":
                received += len(message.get("body", b""))
                if received > self.limit:
                    refused = True
                    if not started:
                        await error_response(self._too_large(None))(scope, receive, send)
                    return {"type": "http.disconnect"}
            return message

        async def guarded_send(message: Message) -> None:
            nonlocal started
            if refused:
                return  # the 413 has been sent; drop whatever the app answers to the disconnect
            if message["type"] == "http.response.start":
                started = True
            await send(message)

        try:
            await self.app(scope, counting_receive, guarded_send)
        except Exception:
            if not refused:
                raise
