"""Small point requests answer with the pipeline's dict as JSON, skipping FastAPI's response validation.

The shortcut must send exactly what the declared response model would have sent: the same keys, in
the same order, with None sections left out. The reference here is AnalysisOut's own serialisation
of the same document (the path every other route takes), not the shortcut's code.
"""

from __future__ import annotations

from typing import Any

import pytest
from fastapi.testclient import TestClient

from inertia.api.jobs import PointsJob, run_job
from inertia.api.schemas import AnalysisOut, PointsRequest

TRIANGLE = [{"mass": 1.0, "position": [0, 0, 0]}, {"mass": 2.0, "position": [1, 0, 0]}, {"mass": 1.0, "position": [0, 1, 0]}]
LINE = [{"mass": 1.0, "position": [0, 0, 0]}, {"mass": 3.0, "position": [0, 0, 2.5]}]
WATER = [
    {"element": "O", "position": [0, 0, 0]},
    {"element": "H", "position": [0.757, 0.586, 0]},
    {"element": "H", "position": [-0.757, 0.586, 0]},
]

BODIES: list[dict[str, Any]] = [
    {"points": TRIANGLE},
    {"points": TRIANGLE, "reference": [1, 2, 3], "omega": [0.1, 0.2, 1.0]},
    {"points": TRIANGLE, "units": "mm", "export": "urdf", "frame": [1, 0, 0, 0]},
    {"points": LINE, "omega": [0.1, 0.0, 1.0]},
    {"points": [{"mass": 2.5, "position": [1, 2, 3]}], "reference": [0, 0, 0]},
    {"points": WATER, "units": "angstrom"},
]


@pytest.mark.parametrize("body", BODIES)
def test_inline_points_answer_as_the_response_model_would(client: TestClient, body: dict[str, Any]) -> None:
    request = PointsRequest.model_validate(body)
    doc = run_job(PointsJob(request.records(), request.as_options()))
    expected = AnalysisOut.model_validate(doc).model_dump(mode="json", by_alias=True, exclude_none=True)
    response = client.post("/v1/analyze/points", json=body)
    assert response.status_code == 200
    assert response.headers["content-type"] == "application/json"
    got = _untimed(response.json())
    expected = _untimed(expected)
    assert list(got) == list(expected)
    assert got == expected


def _untimed(doc: Any) -> Any:
    """The document without its elapsed times (the only numbers that differ between two runs)."""
    if isinstance(doc, dict):
        return {k: _untimed(v) for k, v in doc.items() if k != "elapsed_s"}
    if isinstance(doc, list):
        return [_untimed(v) for v in doc]
    return doc
