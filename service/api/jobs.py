"""What a compute process runs: one pipeline call in, the API's JSON dict out.

This module imports no web framework: it is loaded in the worker processes.
Errors cross the process boundary pickled; a :class:`ServiceError` keeps its
class, message and details.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..pipeline import AnalysisOptions, analyze, analyze_points, precession

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
    """Run one job in the current process."""
    return job()
