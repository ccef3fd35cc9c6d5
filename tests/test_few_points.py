"""The few-points document (``inertia.few_points``) is the general pipeline's, byte for byte.

The expected document is ``analyze_points(...).as_dict()``, the general path that the short one
stands in for on small plain requests; that path is checked against exact values elsewhere
(``tests/contract/test_points.py``, ``tests/test_molecules_published.py``).  The claim here is
identity, so nothing weaker than identical JSON (key order included) passes.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic_core import to_json

from inertia.api.jobs import PointsJob
from inertia.errors import ServiceError
from inertia.few_points import few_points_document
from inertia.mass.points import SMALL_POINTS
from inertia.options import AnalysisOptions
from inertia.pipeline import analyze_points

coordinates = st.one_of(
    st.floats(min_value=-1e3, max_value=1e3, allow_nan=False),
    st.integers(min_value=-50, max_value=50),
    st.sampled_from([0.0, -0.0, 1.0, -1.0, 0.5, 1e-300]),
    st.floats(min_value=-1e12, max_value=1e12, allow_nan=False),
)
masses = st.one_of(st.floats(min_value=1e-6, max_value=1e6), st.integers(min_value=1, max_value=20), st.sampled_from([1.0, 1e-3]))
offsets = st.sampled_from([0.0, 1e-3, 1.0, 1e6, -1e9])


def _without_time(doc: dict[str, Any]) -> bytes:
    doc = {**doc, "diagnostics": {k: v for k, v in doc["diagnostics"].items() if k != "elapsed_s"}}
    if "precession" in doc:  # the motion's own time
        motion = doc["precession"]
        doc["precession"] = {**motion, "diagnostics": {k: v for k, v in motion["diagnostics"].items() if k != "elapsed_s"}}
    return to_json(doc)


def _general(records: list[dict[str, Any]], options: AnalysisOptions) -> bytes:
    try:
        return _without_time(analyze_points(records, options).as_dict())
    except ServiceError as exc:
        return to_json(exc.as_dict())


def _job(records: list[dict[str, Any]], options: AnalysisOptions) -> bytes:
    try:
        return _without_time(PointsJob(records, options)())
    except ServiceError as exc:
        return to_json(exc.as_dict())


@st.composite
def requests(draw: st.DrawFn) -> tuple[list[dict[str, Any]], AnalysisOptions]:
    n = draw(st.integers(min_value=1, max_value=SMALL_POINTS))
    offset = draw(offsets)
    records = [
        {"mass": draw(masses), "position": [c + offset for c in draw(st.lists(coordinates, min_size=3, max_size=3))]}
        for _ in range(n)
    ]
    units = draw(st.sampled_from([None, "m", "mm", "in", "angstrom"]))
    tolerance = draw(st.sampled_from([1e-6, 1e-3, 0.2]))
    return records, AnalysisOptions(units=units, tolerance=tolerance)


@settings(max_examples=400, deadline=None)
@given(requests())
def test_the_document_is_the_general_paths(request: tuple[list[dict[str, Any]], AnalysisOptions]) -> None:
    records, options = request
    fast = few_points_document(records, options)
    want = _general(records, options)
    if fast is not None:
        assert _without_time(fast) == want
    assert _job(records, options) == want


def _corners(*points: tuple[float, float, float], mass: float = 1.0) -> list[dict[str, Any]]:
    return [{"mass": mass, "position": list(p)} for p in points]


SQUARE = _corners((1, 0, 0), (0, 1, 0), (-1, 0, 0), (0, -1, 0))  # oblate, planar
TETRAHEDRON = _corners((1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1))  # spherical
PRISM = _corners((1, 0, 0), (-0.5, 0.75**0.5, 0), (-0.5, -(0.75**0.5), 0), (1, 0, 5), (-0.5, 0.75**0.5, 5), (-0.5, -(0.75**0.5), 5))
NEAR_TOLERANCE = _corners((1, 0, 0), (-1, 0, 0), (0, 1 + 5e-7, 0), (0, -1 - 5e-7, 0), (0, 0, 0.3), (0, 0, -0.3))
FAR = [{"mass": r["mass"], "position": [c + 1e8 for c in r["position"]]} for r in SQUARE]


@pytest.mark.parametrize(
    "records", [SQUARE, TETRAHEDRON, PRISM, NEAR_TOLERANCE, FAR], ids=["square", "tetra", "prism", "near", "far"]
)
def test_symmetric_and_borderline_bodies_take_the_short_path_with_the_same_document(records: list[dict[str, Any]]) -> None:
    options = AnalysisOptions()
    fast = few_points_document(records, options)
    assert fast is not None
    assert _without_time(fast) == _general(records, options)


LINE = _corners((0, 0, 0), (1, 2, 3), (2, 4, 6))
ONE = _corners((1, 2, 3))
WITH_ELEMENT = [{"element": "O", "position": [0.0, 0.0, 0.0]}, {"element": "H", "position": [0.1, 0.0, 0.0]}]
NEGATIVE = _corners((0, 0, 0), (1, 0, 0), mass=-1.0)
BOOLEAN = [{"mass": True, "position": [0.0, 0.0, 0.0]}, {"mass": 1.0, "position": [1.0, 0.0, 0.0]}]
EXTRA_KEY = [{"mass": 1.0, "position": [0.0, 0.0, 0.0], "label": "a"}, {"mass": 1.0, "position": [0.0, 1.0, 0.0]}]
HUGE = _corners((1e200, 0, 0), (-1e200, 3e200, 0), (0, 0, 1e200))


@pytest.mark.parametrize(
    "records",
    [LINE, ONE, WITH_ELEMENT, NEGATIVE, BOOLEAN, EXTRA_KEY, HUGE, _corners(*[(i, i * i, 1) for i in range(SMALL_POINTS + 1)])],
    ids=["line", "one", "element", "negative", "boolean", "extra-key", "overflow", "many"],
)
def test_what_needs_a_warning_or_an_error_goes_the_general_way(records: list[dict[str, Any]]) -> None:
    options = AnalysisOptions()
    assert few_points_document(records, options) is None
    assert _job(records, options) == _general(records, options)


NON_DEFAULT: dict[str, Any] = {
    "mass": 2.0,
    "reference": (1.0, 0.0, 0.0),
    "omega": (0.0, 0.0, 1.0),
    "export": "urdf",
    "frame": (1.0, 0.0, 0.0, 0.0),
    "isotopes": "abundant",
    "mass_unit": "u",
    "method": "dop853",
}


@pytest.mark.parametrize("name", sorted(NON_DEFAULT))
def test_an_option_that_adds_or_changes_a_section_goes_the_general_way(name: str) -> None:
    options = dataclasses.replace(AnalysisOptions(), **{name: NON_DEFAULT[name]})
    assert few_points_document(PRISM, options) is None
    assert _job(PRISM, options) == _general(PRISM, options)


def test_every_option_is_either_applied_or_sends_the_request_the_general_way() -> None:
    """A new option is never dropped by the short path: all but units and tolerance must be at their default."""
    from inertia.few_points import _DEFAULTS, _FREE

    names = {f.name for f in dataclasses.fields(AnalysisOptions)}
    assert {name for name, _ in _DEFAULTS} | set(_FREE) == names
