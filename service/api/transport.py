"""Errors of the HTTP transport: raised by the API's middleware, uploads and compute pool, never by the library.

Each is a :class:`~inertia.errors.ServiceError` with its API code, so the one
handler of ``api.errors`` sends it in the contract's envelope.
"""

from __future__ import annotations

from ..errors import InputTooLargeError, ServiceError

__all__ = ["PayloadTooLargeError", "ComputeTimeoutError", "ServerBusyError", "UnauthorizedError"]


class PayloadTooLargeError(InputTooLargeError):
    """The request (its body, an uploaded file) is larger than the server accepts."""

    code = "payload_too_large"


class ComputeTimeoutError(ServiceError):
    """The computation did not finish within the server's time limit."""

    code = "timeout"


class ServerBusyError(ServiceError):
    """Every compute process is busy and the queue of waiting jobs is full; retry later."""

    code = "server_busy"


class UnauthorizedError(ServiceError):
    """The server requires an API key and the request has none, or the wrong one."""

    code = "unauthorized"
