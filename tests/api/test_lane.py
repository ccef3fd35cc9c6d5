"""The short way for small point requests (``api.lane``) answers exactly as FastAPI's route would.

Each request goes to two apps built alike, one without the lane in its middleware: status, content
type and document (elapsed times aside) must agree, for answers the lane gives itself and for every
case it leaves to FastAPI (invalid JSON, validation errors, another content type, a pooled job, an
error of the input). The lane in front of an app that answers only 404 shows which requests it answered.
"""

from __future__ import annotations

import gc
import json
from collections.abc import Iterator
from typing import Any

import pytest
from fastapi import FastAPI
from fastapi.testclient import TestClient
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import ValidationError
from starlette.responses import Response

from inertia.api import Settings, create_app
from inertia.api.lane import MAX_LANE_BYTES, POINTS_PATH, SmallPointsLane
from inertia.api.schemas import PointsRequest
from inertia.errors import ServiceError

from .test_points_inline import BODIES, TRIANGLE, _untimed


def _without_lane(app: FastAPI) -> FastAPI:
    app.user_middleware = [m for m in app.user_middleware if m.cls is not SmallPointsLane]  # type: ignore[comparison-overlap]
    return app


@pytest.fixture(scope="module")
def clients() -> Iterator[tuple[TestClient, TestClient, TestClient]]:
    settings = Settings(compute_processes=1, max_upload_bytes=4096)
    alone = TestClient(SmallPointsLane(Response(status_code=404)))  # the lane in front of nothing
    with TestClient(create_app(settings)) as lane, TestClient(_without_lane(create_app(settings))) as route:
        yield lane, route, alone


# (body, content type) of requests the lane answers itself
ANSWERED: list[tuple[bytes, str]] = [
    *[(json.dumps(b).encode(), "application/json") for b in BODIES],
    (json.dumps({"points": TRIANGLE}).encode(), "application/json; charset=utf-8"),
    # an error of the input itself: the error handler's envelope
    (json.dumps({"points": [{"element": "Xx", "position": [0, 0, 0]}]}).encode(), "application/json"),
    (json.dumps({"points": [{"mass": 1e-320, "position": [0, 0, 0]}]}).encode(), "application/json"),
    # what a JSON parser may read differently: repeated keys (the last one counts), long and odd numbers, escapes
    (
        b'{"points": [{"mass": 1, "mass": 2, "position": [0, 0, 0]}, {"mass": 1, "position": [1, 0, 0]}], '
        b'"units": "mm", "units": "cm"}',
        "application/json",
    ),
    (
        b'{"points": [{"mass": 123456789012345678901234567890, "position": [0.1000000000000000055511151231257827, 1e-300, 2]}, '
        b'{"mass": 1E0, "position": [-0.0, 1, 9.999999999999999e99]}]}',
        "application/json",
    ),
    (
        b'{"points": [{"mass": "1.5", "position": ["1", 0, 0]}, {"mass": 1, "position": [0, 2, 0]}], "tolerance": "0.001"}',
        "application/json",
    ),
    (rb'{"points": [{"position": [0, 0, 0], "element": "\u004f"}, {"element": "H", "position": [0, 1, 0]}]}', "application/json"),
]

# requests the lane leaves to FastAPI
PASSED_ON: list[tuple[bytes, str]] = [
    (b'{"points": [', "application/json"),  # not JSON
    (b'{"points": [{"mass": NaN, "position": [0, 0, 0]}]}', "application/json"),  # json.loads reads NaN: FastAPI decides
    ('{"points": [{"mass": 1, "position": [0, 0, 0]}]}'.encode("utf-16"), "application/json"),  # so does UTF-16
    (b'\xef\xbb\xbf{"points": [{"mass": 1, "position": [0, 0, 0]}]}', "application/json"),  # and a byte-order mark
    (b"[" * 5000 + b"]" * 5000, "application/json"),  # too deep for json.loads
    (json.dumps({"points": []}).encode(), "application/json"),  # fails validation
    (json.dumps({"points": TRIANGLE, "tolerance": 2}).encode(), "application/json"),
    (json.dumps({"points": TRIANGLE, "surprise": 1}).encode(), "application/json"),
    (json.dumps({"points": TRIANGLE}).encode(), "text/plain"),  # not a JSON body to FastAPI either
    (json.dumps({"points": TRIANGLE}).encode(), "application/vnd.api+json"),
    (json.dumps({"points": TRIANGLE, "omega": [0, 0, 1], "duration": 1, "samples": 8}).encode(), "application/json"),  # pooled
    (json.dumps({"points": TRIANGLE, "omega": [0, 0, 1], "samples": 8}).encode(), "application/json"),  # refused by the options
]


def _post(client: TestClient, body: bytes, content_type: str) -> tuple[int, dict[str, str], Any]:
    """Status, headers (but the length, which the elapsed time's digits move) and the untimed document."""
    response = client.post(POINTS_PATH, content=body, headers={"content-type": content_type})
    headers = {k: v for k, v in response.headers.items() if k != "content-length"}
    return response.status_code, headers, _untimed(response.json()) if response.content else None


@pytest.mark.parametrize(("body", "content_type"), ANSWERED + PASSED_ON)
def test_the_lane_answers_as_the_route(clients: tuple[TestClient, TestClient, TestClient], body: bytes, content_type: str) -> None:
    lane, route, _ = clients
    assert _post(lane, body, content_type) == _post(route, body, content_type)


@pytest.mark.parametrize(("body", "content_type"), ANSWERED)
def test_small_valid_requests_never_reach_the_router(
    clients: tuple[TestClient, TestClient, TestClient], body: bytes, content_type: str
) -> None:
    _, route, alone = clients
    assert _post(alone, body, content_type) == _post(route, body, content_type)


@pytest.mark.parametrize(("body", "content_type"), PASSED_ON)
def test_everything_else_is_left_to_fastapi(
    clients: tuple[TestClient, TestClient, TestClient], body: bytes, content_type: str
) -> None:
    _, _, alone = clients
    assert alone.post(POINTS_PATH, content=body, headers={"content-type": content_type}).status_code == 404


def test_a_large_body_is_passed_on_unparsed(clients: tuple[TestClient, TestClient, TestClient]) -> None:
    # past MAX_LANE_BYTES no job is small: parsing it here would only be done again by the route
    _, _, alone = clients
    body = json.dumps({"points": [{"mass": 1.0, "position": [k, 0.5, 0.25]} for k in range(30_000)]}).encode()
    assert len(body) > MAX_LANE_BYTES
    assert alone.post(POINTS_PATH, content=body, headers={"content-type": "application/json"}).status_code == 404


def test_the_guard_still_stands_in_front(clients: tuple[TestClient, TestClient, TestClient]) -> None:
    lane, _, _ = clients
    big = json.dumps({"points": TRIANGLE * 200}).encode()  # over this app's 4096-byte limit
    response = lane.post(POINTS_PATH, content=big, headers={"content-type": "application/json"})
    assert response.status_code == 413
    assert response.json()["error"]["code"] == "payload_too_large"


def test_the_api_key_is_checked_before_the_lane() -> None:
    with TestClient(create_app(Settings(compute_processes=1, api_key="k"))) as client:
        body = {"points": TRIANGLE}
        assert client.post(POINTS_PATH, json=body).status_code == 401
        assert client.post(POINTS_PATH, json=body, headers={"X-API-Key": "k"}).status_code == 200


def test_another_method_or_a_mounted_app_goes_the_usual_way(clients: tuple[TestClient, TestClient, TestClient]) -> None:
    lane, route, _ = clients
    assert lane.get(POINTS_PATH).status_code == route.get(POINTS_PATH).status_code == 405
    with TestClient(create_app(Settings(compute_processes=1)), root_path="/mounted") as mounted:
        response = mounted.post(POINTS_PATH, json={"points": TRIANGLE})
        assert response.status_code == 200
        assert response.json()["mass"] == 4.0


def test_what_start_up_built_is_out_of_the_collectors_sight_while_serving() -> None:
    # a full collection would otherwise walk every module, schema and route object every few hundred small requests
    gc.unfreeze()
    with TestClient(create_app(Settings(compute_processes=1))):
        assert gc.get_freeze_count() > 10_000
    assert gc.get_freeze_count() == 0


_number = st.one_of(
    st.floats(min_value=-1e6, max_value=1e6),
    st.integers(min_value=-1000, max_value=1000),
    st.floats(min_value=-1e6, max_value=1e6).map(repr),  # numbers as text, which the model's lax mode reads
    st.booleans(),
)
_points = st.lists(
    st.fixed_dictionaries(
        {"position": st.lists(_number, min_size=3, max_size=3)},
        optional={
            "mass": st.one_of(st.floats(min_value=1e-3, max_value=1e3), st.integers(min_value=1, max_value=100), st.booleans()),
            "element": st.sampled_from(["O", "H", "13C", "Xx", None]),
        },
    ),
    min_size=1,
    max_size=4,
)
_options = st.fixed_dictionaries(
    {},
    optional={
        "units": st.sampled_from(["m", "mm", None, "furlong"]),
        "tolerance": st.one_of(st.floats(min_value=1e-9, max_value=0.5), st.sampled_from(["0.01", 2])),
        "omega": st.lists(_number, min_size=3, max_size=3),
        "mass_unit": st.sampled_from(["kg", "u"]),
        "extra": st.integers(),
    },
)


@settings(max_examples=400, deadline=None)
@given(_points, _options, st.booleans())
def test_the_lanes_parser_builds_what_fastapis_builds(points: list[dict[str, Any]], options: dict[str, Any], spaced: bool) -> None:
    """Where pydantic's JSON parser accepts a body, ``json.loads`` and the model give the same request."""
    body = json.dumps({"points": points, **options}, indent=1 if spaced else None).encode()
    try:
        fast = PointsRequest.model_validate_json(body)
    except ValidationError:
        return  # FastAPI decides, as without the lane
    slow = PointsRequest.model_validate(json.loads(body))
    assert _job_of(fast) == _job_of(slow)


def _job_of(request: PointsRequest) -> Any:
    try:
        return request.records(), request.as_options()
    except ServiceError as exc:  # an option the route refuses: the same refusal either way
        return exc.as_dict()
