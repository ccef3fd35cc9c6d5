"""The small path's JSON doubles as its finiteness check (``run_job_json``); it must refuse what
``run_job`` refuses, and accept a finite document whose strings merely name a non-finite value."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, cast

import pytest
from pydantic_core import to_json

from inertia.api.jobs import Job, run_job, run_job_json
from inertia.errors import InvalidParameterError


@dataclass(frozen=True)
class _Fixed:
    """A job whose result is given (a stand-in for a pipeline that let a number through)."""

    doc: dict[str, Any]
    memory_limit_bytes: int | None = None

    def __call__(self) -> dict[str, Any]:
        return self.doc


def _job(doc: dict[str, Any]) -> Job:
    return cast(Job, _Fixed(doc))


@pytest.mark.parametrize("bad", [math.inf, -math.inf, math.nan])
def test_a_non_finite_number_anywhere_is_refused_by_both_paths(bad: float) -> None:
    doc = {"mass": 1.0, "principal": {"moments": [1.0, bad, 2.0]}}
    for run in (run_job, lambda job: run_job_json(job, to_json)):
        with pytest.raises(InvalidParameterError) as info:
            run(_job(doc))
        assert info.value.details["reason"] == "non-finite result"


def test_a_string_naming_infinity_is_not_a_number() -> None:
    doc = {"mass": 1.0, "warnings": ["NaN and Infinity are words here"], "moments": [1.0, 2.0]}
    assert run_job_json(_job(doc), to_json) == to_json(run_job(_job(doc)))


def test_an_underflowed_mass_is_refused_by_both_paths() -> None:
    doc = {"mass": 5e-324, "moments": [1.0, 2.0]}
    for run in (run_job, lambda job: run_job_json(job, to_json)):
        with pytest.raises(InvalidParameterError) as info:
            run(_job(doc))
        assert info.value.details["parameter"] == "density"
