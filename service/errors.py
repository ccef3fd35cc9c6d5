"""One hierarchy of errors, each carrying its API error code.

Every failure the service can explain is a :class:`ServiceError`.  The HTTP
layer (``service.api.errors``) maps classes to status codes and the CLI maps
them to exit codes; nothing else needs to know about transports.  Errors that
only a transport raises (authentication, request size, the compute pool's time
limit and queue) live with it, in ``service.api.transport``.

:func:`envelope` is the one spelling of the contract's error envelope: the API's
error responses, the NDJSON and batch rows of a failed file and the command
line's ``--json`` errors are all made by it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

# the error classes (``envelope`` is imported by name)
__all__ = [
    "ServiceError",
    "LoadError",
    "UnsupportedFormatError",
    "UnreadableFileError",
    "ExternalReferenceError",
    "EmptyGeometryError",
    "InvalidMeshError",
    "NotWatertightError",
    "DegenerateBodyError",
    "ZeroVolumeError",
    "InsufficientPrecisionError",
    "InvalidParameterError",
    "MotionError",
    "InputTooLargeError",
    "InvalidInertiaError",
]


def envelope(code: str, message: str, details: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The error envelope of the API contract: ``{"error": {"code", "message", "details"}}``."""
    return {"error": {"code": code, "message": message, "details": {} if details is None else details}}


class ServiceError(Exception):
    """Base of every error the service reports to a client.

    ``code`` is the snake_case API error code; ``message`` is one sentence a
    person can act on; ``details`` are machine-readable extras.
    """

    code: str = "internal_error"

    def __init__(self, message: str, **details: Any) -> None:
        super().__init__(message)
        self.message = message
        self.details = details

    def as_dict(self) -> dict[str, Any]:
        """The error envelope of the API contract."""
        return envelope(self.code, self.message, self.details)


class LoadError(ServiceError):
    """The input could not be turned into a body."""

    code = "unreadable_file"


class UnsupportedFormatError(LoadError):
    code = "unsupported_format"


class UnreadableFileError(LoadError):
    code = "unreadable_file"


class ExternalReferenceError(UnreadableFileError):
    """The file names another file (an include, an external buffer) that did not come with it."""

    code = "external_reference"


class EmptyGeometryError(LoadError):
    code = "empty_geometry"


class InvalidMeshError(ServiceError):
    """The mesh was read but does not bound a solid."""

    code = "not_watertight"


class NotWatertightError(InvalidMeshError):
    code = "not_watertight"


class DegenerateBodyError(ServiceError):
    code = "zero_volume"


class ZeroVolumeError(DegenerateBodyError):
    code = "zero_volume"


class InsufficientPrecisionError(DegenerateBodyError):
    """The stored coordinates cannot represent the body: its volume or a moment is within the
    change their resolution allows (float32 far from the origin, degenerate shells), or the
    polyhedron they make has a zero or negative principal moment."""

    code = "insufficient_precision"


class InvalidParameterError(ServiceError):
    code = "invalid_parameter"


class MotionError(InvalidParameterError):
    """The motion cannot be predicted for these inputs."""

    code = "invalid_parameter"


class InputTooLargeError(ServiceError):
    """The input passes a bound set on what is read: files in an archive, bytes it inflates to,
    memory a reader may take.  (The HTTP layer's own size limit is its subclass
    ``api.transport.PayloadTooLargeError``.)"""

    code = "payload_too_large"


class InvalidInertiaError(ServiceError):
    """The body's inertia is one a simulator would refuse to load (robotics export)."""

    code = "invalid_inertia"
