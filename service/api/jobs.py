"""What a compute process runs: one pipeline call in, the API's JSON dict out.

This module imports no web framework: it is loaded in the worker processes.
Errors cross the process boundary pickled; a :class:`ServiceError` keeps its
class, message and details.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any

from ..errors import InvalidParameterError
from ..pipeline import AnalysisOptions, analyze, analyze_points, precession

log = logging.getLogger("inertia.api")

_OUT_OF_RANGE = ("the input's numbers are too large or too small to compute with in float64 "
                 "(the result would overflow or divide by zero); rescale the input, e.g. other units")

__all__ = ["MeshJob", "PointsJob", "PrecessionJob", "Job", "run_job"]


@dataclass(frozen=True, slots=True)
class MeshJob:
    data: bytes
    filename: str | None
    options: AnalysisOptions

    def __call__(self) -> dict[str, Any]:
        return analyze(self.data, filename=self.filename, options=self.options).as_dict()


@dataclass(frozen=True, slots=True)
class PointsJob:
    records: list[dict[str, Any]]
    options: AnalysisOptions

    def __call__(self) -> dict[str, Any]:
        return analyze_points(self.records, self.options).as_dict()


@dataclass(frozen=True, slots=True)
class PrecessionJob:
    arguments: dict[str, Any]

    def __call__(self) -> dict[str, Any]:
        return precession(**self.arguments).as_dict()


Job = MeshJob | PointsJob | PrecessionJob


def run_job(job: Job) -> dict[str, Any]:
    """Run one job in the current process; never return a non-finite number.

    Inputs of extreme magnitude can overflow inside the pipeline; that is a
    property of the input (``invalid_parameter``), not a server failure. It is
    logged with its traceback so that the stage which let it through can be
    made to say so itself.
    """
    try:
        doc = job()
    except ArithmeticError as exc:
        log.warning("arithmetic failure in %s, reported as invalid_parameter", type(job).__name__, exc_info=exc)
        raise InvalidParameterError(_OUT_OF_RANGE, reason=type(exc).__name__) from exc
    if not _finite(doc):
        log.warning("non-finite number in the result of %s, reported as invalid_parameter", type(job).__name__)
        raise InvalidParameterError(_OUT_OF_RANGE, reason="non-finite result")
    return doc


def _finite(value: Any) -> bool:
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    if isinstance(value, (list, tuple)):
        return all(_finite(v) for v in value)
    return True
