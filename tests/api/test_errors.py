"""Every error code of the contract, provoked by one request each; the envelope is asserted every time.

Table-driven from ``inertia.api.errors.STATUS``: each error class the API maps
has at least one request here that produces it.
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Callable
from typing import Any, cast

import numpy as np
import pytest
from fastapi.testclient import TestClient
from pytest import LogCaptureFixture

from inertia import errors as E
from inertia.api import Settings, create_app
from inertia.api import transport as T
from inertia.api.errors import STATUS
from tests.support.meshes import box_stl, stl_bytes, torus_stl

with warnings.catch_warnings():
    warnings.filterwarnings("ignore", message="Using `httpx` with `starlette.testclient`")
    from fastapi.testclient import TestClient

BOX = box_stl(1, 2, 3)
FLAT = stl_bytes(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2], [0, 2, 1]]))
OPEN = stl_bytes(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]), np.array([[0, 2, 1], [0, 1, 3]]))
TRUNCATED = b"\0" * 80 + (1000).to_bytes(4, "little") + b"\0" * 100


def mesh(data: bytes, name: str = "part.stl", **params: Any) -> Callable[[Any], Any]:
    return lambda c: c.post("/v1/analyze/mesh", files={"file": (name, data)}, params=params)


def points(body: Any) -> Callable[[Any], Any]:
    return lambda c: c.post("/v1/analyze/points", json=body)


def raw(path: str, content: bytes, ctype: str = "application/json") -> Callable[[Any], Any]:
    return lambda c: c.post(path, content=content, headers={"content-type": ctype})


def prec(body: Any) -> Callable[[Any], Any]:
    return lambda c: c.post("/v1/precession", json=body)


ONE = [{"mass": 1.0, "position": [0, 0, 0]}]

# (error class, code, status, request); the default-settings client
CASES: list[tuple[type[E.ServiceError], str, int, Callable[[Any], Any]]] = [
    (E.UnsupportedFormatError, "unsupported_format", 415, mesh(BOX, "part.xyz123")),
    (E.UnsupportedFormatError, "unsupported_format", 415, mesh(BOX, format="dwg")),
    (E.UnreadableFileError, "unreadable_file", 422, mesh(TRUNCATED)),
    (E.ExternalReferenceError, "external_reference", 422, mesh(b"*NODE\n1, 0, 0, 0\n*INCLUDE, INPUT=/etc/passwd\n", "deck.inp")),
    (E.EmptyGeometryError, "empty_geometry", 422, mesh(b"")),
    (E.NotWatertightError, "not_watertight", 422, mesh(OPEN)),
    (E.ZeroVolumeError, "zero_volume", 422, mesh(FLAT)),
    (E.InvalidParameterError, "invalid_parameter", 422, mesh(BOX, density="nan")),
    (E.InvalidParameterError, "invalid_parameter", 422, mesh(BOX, density="inf")),
    (E.InvalidParameterError, "invalid_parameter", 422, mesh(BOX, density=-1)),
    (E.InvalidParameterError, "invalid_parameter", 422, mesh(BOX, density=1, mass=2)),
    (E.InvalidParameterError, "invalid_parameter", 422, mesh(BOX, reference="1,2")),
    (E.InvalidParameterError, "invalid_parameter", 422, mesh(BOX, omega="0,nan,1")),
    (E.InvalidParameterError, "invalid_parameter", 422, mesh(BOX, units="parsec")),
    (E.InvalidParameterError, "invalid_parameter", 422, mesh(BOX, samples=3)),
    (E.InvalidParameterError, "invalid_parameter", 422, mesh(BOX, method="euler")),
    (E.InvalidParameterError, "invalid_parameter", 422, mesh(BOX, densities='{"a": NaN}')),
    (E.InvalidParameterError, "invalid_parameter", 422, mesh(BOX, unknown_option=1)),
    (E.InvalidParameterError, "invalid_parameter", 422, lambda c: c.post("/v1/analyze/mesh", files={"other": ("a.stl", BOX)})),
    (E.InvalidParameterError, "invalid_parameter", 422, points({"points": []})),
    (E.InvalidParameterError, "invalid_parameter", 422, points({"points": [{"mass": -1, "position": [0, 0, 0]}]})),
    (E.InvalidParameterError, "invalid_parameter", 422, points({"points": ONE, "extra": 1})),
    (E.InvalidParameterError, "invalid_parameter", 422, points({"points": [{"mass": 1, "position": [0, 0]}]})),
    (
        E.InvalidParameterError,
        "invalid_parameter",
        422,
        raw("/v1/analyze/points", b'{"points": [{"mass": NaN, "position": [0, 0, 0]}]}'),
    ),
    (
        E.InvalidParameterError,
        "invalid_parameter",
        422,
        raw("/v1/analyze/points", b'{"points": [{"mass": 1, "position": [Infinity, 0, 0]}]}'),
    ),
    (E.InvalidParameterError, "invalid_parameter", 422, raw("/v1/analyze/points", b'{"points": [')),
    (
        E.InvalidParameterError,
        "invalid_parameter",
        422,
        raw("/v1/analyze/mesh", b"--x\r\nnot multipart", "multipart/form-data; boundary=y"),
    ),
    (E.InvalidInertiaError, "invalid_inertia", 422, points({"points": ONE, "export": "mjcf"})),
    (E.InvalidParameterError, "invalid_parameter", 422, prec({"omega": [0, 0, 1]})),
    (E.InvalidParameterError, "invalid_parameter", 422, prec({"principal_moments": [1, 1, 5], "omega": [0, 0, 1]})),
    (
        E.InvalidParameterError,
        "invalid_parameter",
        422,
        prec({"inertia_tensor": [[1, 2, 0], [0, 1, 0], [0, 0, 1]], "omega": [0, 0, 1]}),
    ),
    (E.InvalidParameterError, "invalid_parameter", 422, prec({"principal_moments": [1, 2, 3], "omega": [0, 0, 1], "duration": 1})),
]


def assert_envelope(response: Any, code: str, status: int) -> dict[str, Any]:
    assert response.status_code == status, response.text
    assert response.headers["content-type"].startswith("application/json")
    body = response.json()
    assert set(body) == {"error"} and set(body["error"]) == {"code", "message", "details"}
    assert body["error"]["code"] == code
    assert isinstance(body["error"]["message"], str) and len(body["error"]["message"]) > 10
    assert isinstance(body["error"]["details"], dict)
    return cast("dict[str, Any]", body["error"])


@pytest.mark.parametrize(("cls", "code", "status", "request_"), CASES, ids=[f"{c[1]}-{i}" for i, c in enumerate(CASES)])
def test_bad_request_gets_its_code_and_status(
    client: TestClient, cls: type[E.ServiceError], code: str, status: int, request_: Any
) -> None:
    assert cls.code == code and STATUS[next(k for k in type.mro(cls) if k in STATUS)] == status
    assert_envelope(request_(client), code, status)


def busy(c: Any) -> Any:
    """A request while the only compute process is busy and no job may wait."""
    import threading
    import time

    pool = c.app.state.pool
    slow = threading.Thread(target=mesh(torus_stl(400, 400)), args=(c,))
    slow.start()
    deadline = time.monotonic() + 30
    while not (pool._slots and pool._slots[1].locked()) and time.monotonic() < deadline:
        time.sleep(0.01)
    response = mesh(BOX)(c)
    slow.join()
    return response


LIMITED = [
    (
        T.PayloadTooLargeError,
        "payload_too_large",
        413,
        Settings(max_upload_bytes=1000, compute_processes=1),
        mesh(box_stl(1, 2, 3) * 10),
    ),
    (T.UnauthorizedError, "unauthorized", 401, Settings(api_key="s3cret", compute_processes=1), mesh(BOX)),
    (
        T.ComputeTimeoutError,
        "timeout",
        503,
        Settings(timeout_s=0.05, compute_processes=1),
        mesh(torus_stl(500, 500)),
    ),
    (T.ServerBusyError, "server_busy", 503, Settings(max_waiting=0, compute_processes=1), busy),
]


@pytest.mark.parametrize(("cls", "code", "status", "settings", "request_"), LIMITED, ids=[c[1] for c in LIMITED])
def test_limits_get_their_code_and_status(
    cls: type[E.ServiceError], code: str, status: int, settings: Settings, request_: Any
) -> None:
    assert cls.code == code
    with TestClient(create_app(settings)) as c:
        assert_envelope(request_(c), code, status)


def test_every_mapped_error_class_is_provoked_by_a_test() -> None:
    provoked = {c[0] for c in CASES} | {c[0] for c in LIMITED}
    for cls in STATUS:
        if cls is not E.ServiceError:
            assert any(issubclass(p, cls) for p in provoked), cls


def test_unknown_path_and_method_use_the_envelope(client: TestClient) -> None:
    assert_envelope(client.get("/v2/nothing"), "not_found", 404)
    assert_envelope(client.get("/v1/precession"), "method_not_allowed", 405)


def test_unexpected_exception_is_500_envelope_with_logged_traceback(caplog: LogCaptureFixture) -> None:
    app = create_app(Settings(compute_processes=1))

    @app.get("/boom")
    async def boom() -> None:
        raise RuntimeError("secret internal detail")

    with caplog.at_level(logging.ERROR, logger="inertia.api"), TestClient(app, raise_server_exceptions=False) as c:
        error = assert_envelope(c.get("/boom"), "internal_error", 500)
    assert "secret" not in error["message"]
    assert any(r.exc_info and "secret internal detail" in str(r.exc_info[1]) for r in caplog.records)


def test_validation_error_names_the_field(client: TestClient) -> None:
    error = assert_envelope(points({"points": [{"mass": 1, "position": [0, 0, "x"]}]})(client), "invalid_parameter", 422)
    assert "points.0.position" in error["message"] and error["details"]["errors"][0]["loc"][0] == "body"


def test_a_numeric_bound_is_written_as_a_number(client: TestClient) -> None:
    # pydantic writes the float bound 1e100 as a 101-digit integer; a person reads 1e+100
    body = {"principal_moments": [1, 2, 3], "omega": [1, 0, 0], "duration": 1e101, "samples": 3}
    error = client.post("/v1/precession", json=body).json()["error"]
    assert error["code"] == "invalid_parameter" and error["details"]["parameter"] == "duration"
    assert "at most 1e+100;" in error["message"] and "0000000000" not in error["message"]
