"""What a compute process runs: one pipeline call in, the API's JSON dict out.

This module imports no web framework: it is loaded in the worker processes.
Errors cross the process boundary pickled; a :class:`ServiceError` keeps its
class, message and details.

A mesh job names a file that the parent process wrote into a private folder
(``workdir``) and removes after the job, whatever happened to it; the worker
also puts its own temporary files there (``tempfile.tempdir``), so a killed
worker leaves nothing behind that the parent does not remove.

What the readers still let through is classified by ``load.load_body``: any
failure while a client's file is being read (a library's ``SystemExit``, an
``IndexError`` in a parser, a too-deep ``RecursionError``) is that file's
``unreadable_file`` (422). Running out of the job's memory allowance is
``payload_too_large`` (413). A failure after loading is a bug and stays one.
"""

from __future__ import annotations

import logging
import math
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from ..errors import InvalidParameterError, ServiceError
from ..few_points import few_points_document
from ..pipeline import AnalysisOptions, analyze_loaded, analyze_points, precession
from .transport import PayloadTooLargeError

log = logging.getLogger("inertia.api")

_OUT_OF_RANGE = (
    "the input's numbers are too large or too small to compute with in float64 "
    "(the result would overflow or divide by zero); rescale the input, e.g. other units"
)

__all__ = ["MeshJob", "PointsJob", "PrecessionJob", "Job", "run_job", "run_job_json", "is_small"]

# point-mass jobs up to this size, without a trajectory, run in the server process itself: they take
# well under a millisecond, less than the round trip to a compute process (they cannot hang: no file)
INLINE_MAX_POINTS = 1000


@dataclass(frozen=True, slots=True)
class MeshJob:
    """One mesh file: its bytes (library and tests) or the path of the parent's private copy (the API);
    or several files of one upload (a model and its companions) as ``((client name, path), ...)``."""

    source: bytes | str | tuple[tuple[str, str], ...]
    filename: str | None
    options: AnalysisOptions
    workdir: str | None = None
    memory_limit_bytes: int | None = None

    def __call__(self) -> dict[str, Any]:
        start = time.perf_counter()
        try:
            with _temporary_files_in(self.workdir):
                loaded = _load(self.source, self.filename, self.options)
                return analyze_loaded(loaded, self.options, start).as_dict()
        except ServiceError as exc:
            raise _without_paths(exc, self) from None


def _without_paths(exc: ServiceError, job: MeshJob) -> ServiceError:
    """The error with the server's own file and folder names replaced by the client's file name."""
    label = job.filename or "the upload"
    files = job.source if isinstance(job.source, tuple) else ((label, job.source),) if isinstance(job.source, str) else ()
    ours = [(path, name) for name, path in files] + [(p, "<temp>") for p in (job.workdir, tempfile.gettempdir()) if p]

    def scrub(value: Any) -> Any:
        if isinstance(value, str):
            for path, name in ours:
                value = value.replace(path, name)
        return value

    exc.message = scrub(exc.message)
    exc.args = (exc.message,)
    exc.details = {k: scrub(v) for k, v in exc.details.items()}
    return exc


@dataclass(frozen=True, slots=True)
class PointsJob:
    records: list[dict[str, Any]]
    options: AnalysisOptions
    memory_limit_bytes: int | None = None

    def __call__(self) -> dict[str, Any]:
        # a few plain point masses: the same document without the general pipeline's objects
        doc = few_points_document(self.records, self.options)
        return analyze_points(self.records, self.options).as_dict() if doc is None else doc


@dataclass(frozen=True, slots=True)
class PrecessionJob:
    arguments: dict[str, Any]
    memory_limit_bytes: int | None = None

    def __call__(self) -> dict[str, Any]:
        return precession(**self.arguments).as_dict()


Job = MeshJob | PointsJob | PrecessionJob


def is_small(job: Job) -> bool:
    """Whether the job is cheap and bounded enough to run without a compute process."""
    if isinstance(job, PointsJob):
        return len(job.records) <= INLINE_MAX_POINTS and job.options.samples is None
    if isinstance(job, PrecessionJob):
        return job.arguments.get("samples") is None
    return False


@contextmanager
def _temporary_files_in(workdir: str | None) -> Iterator[None]:
    """Make the readers' temporary files land in the job's folder, which the parent removes."""
    if workdir is None:
        yield
        return
    previous = tempfile.tempdir
    tempfile.tempdir = workdir
    try:
        yield
    finally:
        tempfile.tempdir = previous


def _read_files(files: tuple[tuple[str, str], ...]) -> list[tuple[str, bytes]]:
    out = []
    for name, path in files:
        with open(path, "rb") as fh:
            out.append((name, fh.read()))
    return out


def _load(source: bytes | str | tuple[tuple[str, str], ...], filename: str | None, options: AnalysisOptions) -> Any:
    from ..load import load_body

    if isinstance(source, tuple):
        return load_body(_read_files(source), format=options.format, units=options.units, isotopes=options.isotopes)
    return load_body(source, filename=filename, format=options.format, units=options.units, isotopes=options.isotopes)


def run_job(job: Job) -> dict[str, Any]:
    """Run one job in the current process; never return a non-finite number or a zero mass.

    Inputs of extreme magnitude can overflow inside the pipeline; that is a
    property of the input (``invalid_parameter``), not a server failure. It is
    logged with its traceback so that the stage which let it through can be
    made to say so itself.
    """
    doc = _outcome(job)
    _check_result(job, doc, _finite(doc))
    return doc


def run_job_json(job: Job, dumps: Callable[[Any], bytes]) -> bytes:
    """``run_job``'s document as the JSON ``dumps`` writes, with the same checks.

    ``dumps`` must write a non-finite float as ``NaN``, ``Infinity`` or
    ``-Infinity`` (pydantic_core's ``to_json`` does). Then text without those
    words holds only finite numbers, and the document is not walked a second
    time to check them; where the words occur (a number, or a string naming
    one) the walk decides as in ``run_job``.
    """
    doc = _outcome(job)
    text = dumps(doc)
    _check_result(job, doc, (b"NaN" not in text and b"Infinity" not in text) or _finite(doc))
    return text


def _outcome(job: Job) -> dict[str, Any]:
    try:
        return job()
    except ArithmeticError as exc:
        log.warning("arithmetic failure in %s, reported as invalid_parameter", type(job).__name__, exc_info=exc)
        raise InvalidParameterError(_OUT_OF_RANGE, reason=type(exc).__name__) from exc
    except MemoryError:
        limit = job.memory_limit_bytes
        raise PayloadTooLargeError(
            "the analysis needed more memory than this server allows for an input of this size"
            + (f" ({limit} bytes)" if limit else "")
            + "; send a smaller or simpler file",
            limit_bytes=limit,
        ) from None


def _check_result(job: Job, doc: dict[str, Any], finite: bool) -> None:
    if not finite:
        log.warning("non-finite number in the result of %s, reported as invalid_parameter", type(job).__name__)
        raise InvalidParameterError(_OUT_OF_RANGE, reason="non-finite result")
    mass = doc.get("mass")
    if isinstance(mass, float) and not mass >= sys.float_info.min:  # zero or subnormal: underflowed
        raise InvalidParameterError(
            f"the mass comes out as {mass!r}: the density or masses are too small to compute with in float64 "
            "(the product underflowed); use larger units of mass or density",
            parameter="density",
            mass=mass,
        )


def _finite(value: Any) -> bool:
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    if isinstance(value, (list, tuple)):
        return all(_finite(v) for v in value)
    return True
