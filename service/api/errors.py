"""One table from error class to HTTP status, and one handler for every failure.

Everything a client can get wrong, and everything that goes wrong inside,
leaves as the contract's envelope
``{"error": {"code": ..., "message": ..., "details": {...}}}``.
"""

from __future__ import annotations

import logging
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from starlette.exceptions import HTTPException
from starlette.responses import JSONResponse

from ..errors import (
    DegenerateBodyError,
    InputTooLargeError,
    InvalidInertiaError,
    InvalidMeshError,
    InvalidParameterError,
    LoadError,
    ServiceError,
    UnsupportedFormatError,
    envelope,
)
from .transport import ComputeTimeoutError, PayloadTooLargeError, ServerBusyError, UnauthorizedError

__all__ = ["STATUS", "error_response", "install_error_handlers", "status_of", "internal_error_response"]

log = logging.getLogger("inertia.api")

# most specific class first is not needed: the lookup walks the class's MRO
STATUS: dict[type[ServiceError], int] = {
    UnsupportedFormatError: 415,
    LoadError: 422,
    InvalidMeshError: 422,
    DegenerateBodyError: 422,  # zero_volume, insufficient_precision
    InvalidParameterError: 422,
    InvalidInertiaError: 422,
    InputTooLargeError: 413,
    PayloadTooLargeError: 413,
    UnauthorizedError: 401,
    ComputeTimeoutError: 503,
    ServerBusyError: 503,
    ServiceError: 500,
}

# the challenge of a 401: the API key goes in the X-API-Key header (INERTIA_API_KEY)
WWW_AUTHENTICATE = 'API-Key header="X-API-Key"'

# framework errors that are not ServiceErrors: status -> code
_HTTP_CODES = {401: "unauthorized", 404: "not_found", 405: "method_not_allowed", 413: "payload_too_large"}


def status_of(exc: ServiceError) -> int:
    return next(STATUS[cls] for cls in type(exc).__mro__ if cls in STATUS)


def error_response(exc: ServiceError) -> JSONResponse:
    status = status_of(exc)
    headers = {}
    retry = exc.details.get("retry_after_s")
    if isinstance(retry, int):  # 503: when to come back
        headers["Retry-After"] = str(retry)
    if status >= 500 and status != 503:
        headers["Connection"] = "close"  # a bug: start the client's next request on a fresh connection
    if status == 401:  # RFC 9110 §15.5.2: a 401 names the challenge; here, the header that carries the key
        headers["WWW-Authenticate"] = WWW_AUTHENTICATE
    return JSONResponse(exc.as_dict(), status_code=status, headers=headers)


def internal_error_response() -> JSONResponse:
    """The envelope of an unexpected failure; the connection is closed cleanly after it (``Connection: close``),
    so a keep-alive client's next request goes on a new connection instead of into a reset one."""
    message = "the server failed unexpectedly; the error was logged, please report it with the input that caused it"
    return JSONResponse(envelope("internal_error", message), status_code=500, headers={"Connection": "close"})


def _where(loc: tuple[Any, ...]) -> str:
    if not loc:
        return "request"
    if loc[0] == "body" and len(loc) == 1:
        return "request body"
    path = ".".join(str(part) for part in loc[1:]) or str(loc[0])
    return f"{loc[0]} field {path!r}" if loc[0] in ("body", "query") else path


def _body_message(error: dict[str, Any], content_type: str | None) -> str | None:
    """What to send instead, when FastAPI could not take the body as JSON: malformed JSON, or a body sent
    without ``Content-Type: application/json`` (FastAPI then hands the raw bytes on) or not an object."""
    loc = error["loc"]
    if len(loc) == 2 and loc[0] == "body" and isinstance(loc[1], int) and error.get("type") == "json_invalid":
        return f"the request body is not valid JSON (at character {loc[1]}); send the JSON document of API.md"
    if loc == ["body"] and error.get("type") == "model_attributes_type":
        if content_type is None or "json" not in content_type.lower():
            sent = f"was sent as {content_type}" if content_type else "came without a Content-Type header"
            return f"the request body {sent}; send the JSON document of API.md with the header Content-Type: application/json"
        return "the request body must be a JSON object (the document of API.md), not an array or a single value"
    if len(loc) >= 2 and loc[0] == "body" and "Expected UploadFile" in str(error.get("msg", "")):
        # a multipart part without a file name is a form field, not a file (curl -F 'file=<x.stl')
        return (
            f"the multipart part '{loc[1]}' came without a file name, so it is a form field rather than a file; "
            f"send it as a file part with its name, e.g. curl -F {loc[1]}=@part.stl"
        )
    return None


_BOUNDS = {
    "less_than_equal": ("le", "at most"),
    "less_than": ("lt", "less than"),
    "greater_than_equal": ("ge", "at least"),
    "greater_than": ("gt", "greater than"),
}


def _bound_message(error: Any) -> str:
    """pydantic's message, with a numeric bound written as a number (1e+100, not 101 digits)."""
    kind = _BOUNDS.get(str(error.get("type", "")))
    bound = (error.get("ctx") or {}).get(kind[0]) if kind else None
    if kind is None or not isinstance(bound, float):
        return str(error.get("msg", ""))
    return f"Input should be {kind[1]} {bound:.17g}"


def invalid_request(exc: RequestValidationError, content_type: str | None = None) -> InvalidParameterError:
    """A schema failure as ``invalid_parameter``, naming the first bad field."""
    errors = [
        {
            "loc": [str(p) if not isinstance(p, int) else p for p in e.get("loc", ())],
            "msg": _bound_message(e),
            "type": str(e.get("type", "")),
        }
        for e in exc.errors()
    ]
    first = errors[0] if errors else {"loc": [], "msg": "invalid request"}
    message = f"{_where(tuple(first['loc']))}: {first['msg']}; fix it and send the request again"
    # the field's name, not a list index: 'omega' for body.omega.0, 'position' for body.points.2.position.1
    names = [p for p in first["loc"] if isinstance(p, str)]
    parameter = names[-1] if names else None
    message = _body_message(first, content_type) or message
    return InvalidParameterError(message, parameter=parameter, errors=errors)


async def _service_error(request: Request, exc: Exception) -> JSONResponse:
    assert isinstance(exc, ServiceError)
    if status_of(exc) >= 500 and status_of(exc) != 503:
        log.error("internal error on %s %s: %s", request.method, request.url.path, exc.message)
    return error_response(exc)


async def _validation_error(request: Request, exc: Exception) -> JSONResponse:
    assert isinstance(exc, RequestValidationError)
    return error_response(invalid_request(exc, request.headers.get("content-type")))


async def _http_error(request: Request, exc: Exception) -> JSONResponse:
    assert isinstance(exc, HTTPException)
    detail = str(exc.detail).rstrip(".")
    if exc.status_code == 400:  # FastAPI could not parse the body (bad JSON or multipart)
        return JSONResponse(envelope("invalid_parameter", f"{detail}; send well-formed JSON or multipart data"), status_code=422)
    code = _HTTP_CODES.get(exc.status_code, "http_error")
    message = f"{detail}: {request.method} {request.url.path}; see /docs for the endpoints"
    return JSONResponse(envelope(code, message), status_code=exc.status_code, headers=exc.headers)


async def _unexpected_error(request: Request, exc: Exception) -> JSONResponse:
    log.error("unexpected error on %s %s", request.method, request.url.path, exc_info=exc)
    return internal_error_response()


def install_error_handlers(app: FastAPI) -> None:
    app.add_exception_handler(ServiceError, _service_error)
    app.add_exception_handler(RequestValidationError, _validation_error)
    app.add_exception_handler(HTTPException, _http_error)
    app.add_exception_handler(Exception, _unexpected_error)
