"""Errors: the envelope, the status codes, the size and time limits and the API key."""

from __future__ import annotations

import os
import struct
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from benchmarks.cases import stl_bytes
from tests.contract.helpers import (
    BOX_FACES,
    RHO,
    SAMPLES,
    TRIATOMIC,
    analyze,
    assert_error,
    box_corners,
    exact_moments,
    exact_of,
    obj_bytes,
    post_mesh,
    truncated_stl,
    two_cube_obj,
)


@contextmanager
def configured_client(**env: str) -> Iterator[TestClient]:
    """A fresh app created while the given ``INERTIA_*`` variables are set."""
    saved = {k: os.environ.get(k) for k in env}
    os.environ.update(env)
    try:
        from inertia.api import create_app

        app = create_app()
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    with TestClient(app) as c:
        yield c


@pytest.mark.parametrize(
    "filename",
    [
        "box.stl",
        "l_bracket.stl",
        "tetrahedron.stl",
        "hex_prism.stl",
        "icosahedron.stl",
        "needle.obj",
        "plate.obj",
        "inverted_box.stl",
    ],
)
def test_moments_are_those_of_the_polyhedron_as_written_within_the_error_estimate(client: TestClient, filename: str) -> None:
    """API.md Accuracy: exactly the polyhedron read (float32 for binary STL), each principal
    moment to within relative_error_estimate of its own value."""
    res = analyze(client, filename)
    mass, com, inertia, volume = exact_of(filename)
    assert res["mass"] == pytest.approx(float(mass), rel=1e-14, abs=0)
    assert res["volume"] == pytest.approx(float(volume), rel=1e-14, abs=0)
    assert res["density"] == RHO
    np.testing.assert_allclose(
        res["center_of_mass"], [float(x) for x in com], rtol=0, atol=1e-14 * max(1, max(abs(float(x)) for x in com))
    )
    est = res["diagnostics"]["relative_error_estimate"]
    assert est <= 1e-12
    for got, want in zip(res["principal"]["moments"], exact_moments(inertia)):
        assert abs(got - want) <= max(est, 2.3e-16) * abs(want), (got, want, est)
    tensor = np.array([[float(x) for x in row] for row in inertia])
    np.testing.assert_allclose(res["inertia_tensor"], tensor, rtol=0, atol=1e-13 * np.trace(tensor))


def flat_tetra_stl() -> bytes:
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float)
    f = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    return stl_bytes(v, f)


ERROR_CASES = [
    ("unsupported extension", "part.xyz123", b"hello", {}, 415, "unsupported_format"),
    ("unsupported format param", "box.stl", None, {"format": "nope"}, 415, "unsupported_format"),
    ("truncated binary stl", "bad.stl", truncated_stl(), {}, 422, "unreadable_file"),
    ("garbage glb", "bad.glb", b"\x00\x01garbage" * 10, {}, 422, "unreadable_file"),
    ("stl without triangles", "empty.stl", b"\0" * 80 + struct.pack("<I", 0), {}, 422, "empty_geometry"),
    ("obj without faces", "empty.obj", b"# nothing here\n", {}, 422, "empty_geometry"),
    ("open box", "open_box.stl", None, {}, 422, "not_watertight"),
    ("flat closed surface", "flat.stl", flat_tetra_stl(), {}, 422, "zero_volume"),
    ("unknown unit", "box.stl", None, {"units": "furlong"}, 422, "invalid_parameter"),
    ("negative density", "box.stl", None, {"density": "-1"}, 422, "invalid_parameter"),
    ("zero mass", "box.stl", None, {"mass": "0"}, 422, "invalid_parameter"),
    ("density not a number", "box.stl", None, {"density": "abc"}, 422, "invalid_parameter"),
    ("negative tolerance", "box.stl", None, {"tolerance": "-1"}, 422, "invalid_parameter"),
    ("unknown model", "box.stl", None, {"model": "foam"}, 422, "invalid_parameter"),
    ("negative thickness", "box.stl", None, {"model": "shell", "thickness": "-1"}, 422, "invalid_parameter"),
    ("reference of two numbers", "box.stl", None, {"reference": "1,2"}, 422, "invalid_parameter"),
    ("omega not numbers", "box.stl", None, {"omega": "a,b,c"}, 422, "invalid_parameter"),
    ("unknown method", "box.stl", None, {"omega": "0,0,1", "method": "euler"}, 422, "invalid_parameter"),
    ("zero samples", "box.stl", None, {"omega": "0,0,1", "duration": "1", "samples": "0"}, 422, "invalid_parameter"),
    ("negative duration", "box.stl", None, {"omega": "0,0,1", "duration": "-1", "samples": "3"}, 422, "invalid_parameter"),
    ("densities not json", "box.stl", None, {"densities": "{left: 1"}, 422, "invalid_parameter"),
    ("NaN density", "box.stl", None, {"density": "nan"}, 422, "invalid_parameter"),
    ("Inf mass", "box.stl", None, {"mass": "inf"}, 422, "invalid_parameter"),
    ("NaN tolerance", "box.stl", None, {"tolerance": "NaN"}, 422, "invalid_parameter"),
    ("NaN omega", "box.stl", None, {"omega": "nan,0,1"}, 422, "invalid_parameter"),
    ("Inf reference", "box.stl", None, {"reference": "0,0,inf"}, 422, "invalid_parameter"),
    ("-Inf duration", "box.stl", None, {"omega": "0,0,1", "duration": "-inf", "samples": "3"}, 422, "invalid_parameter"),
    ("Inf thickness", "box.stl", None, {"model": "shell", "thickness": "Infinity"}, 422, "invalid_parameter"),
    ("NaN in densities", "pair.obj", two_cube_obj(), {"densities": '{"left": NaN, "right": 1}'}, 422, "invalid_parameter"),
]


@pytest.mark.parametrize("label,filename,data,params,status,code", ERROR_CASES, ids=[c[0] for c in ERROR_CASES])
def test_mesh_errors_use_the_envelope_code_and_status(
    client: TestClient, label: str, filename: str, data: bytes, params: dict[str, Any], status: int, code: str
) -> None:
    if data is None:
        data = (SAMPLES / filename).read_bytes()
    assert_error(post_mesh(client, filename, data, **params), status, code)


def test_missing_file_part_is_invalid_parameter(client: TestClient) -> None:
    r = client.post("/v1/analyze/mesh", files={"upload": ("box.stl", b"x")})
    assert_error(r, 422, "invalid_parameter")


@pytest.mark.parametrize("fmt", ["stl", "obj"])
def test_non_finite_coordinates_in_a_file_are_invalid_parameter(client: TestClient, fmt: str) -> None:
    """API.md: Non-finite numbers (NaN, ±Inf) anywhere in an input are invalid_parameter."""
    v = box_corners(1, 2, 3)
    v[7] = [np.nan, 2, 3]
    data = stl_bytes(v, BOX_FACES) if fmt == "stl" else obj_bytes([(None, v, BOX_FACES)])
    assert_error(post_mesh(client, f"nan.{fmt}", data), 422, "invalid_parameter")


BIG_STL = stl_bytes(np.random.default_rng(0).normal(size=(3000, 3)), np.arange(3000).reshape(1000, 3))  # 50 kB


def test_upload_larger_than_the_limit_is_413() -> None:
    with configured_client(INERTIA_MAX_UPLOAD_BYTES="10000", INERTIA_COMPUTE_PROCESSES="1") as c:
        err = assert_error(post_mesh(c, "big.stl", BIG_STL), 413, "payload_too_large")
        assert err["message"]
        files = [("files", ("big.stl", BIG_STL, "application/octet-stream"))]
        assert_error(c.post("/v1/batch", files=files), 413, "payload_too_large")
        ok = post_mesh(c, "box.stl", (SAMPLES / "box.stl").read_bytes())
        assert ok.status_code == 200, ok.text


def test_compute_past_the_time_limit_is_503_timeout() -> None:
    # the rk45 job takes ~8 s of CPU; 1 s leaves the box after it room on a busy machine (0.05 s did not)
    with configured_client(INERTIA_TIMEOUT_S="1", INERTIA_COMPUTE_PROCESSES="1") as c:
        r = post_mesh(
            c, "box.stl", (SAMPLES / "box.stl").read_bytes(), omega="0.1,2,0.1", duration="3000", samples="10", method="rk45"
        )
        assert_error(r, 503, "timeout")
        ok = post_mesh(c, "box.stl", (SAMPLES / "box.stl").read_bytes())
        assert ok.status_code == 200, ok.text


def test_api_key_guards_v1_but_not_healthz() -> None:
    with configured_client(INERTIA_API_KEY="s3cret", INERTIA_COMPUTE_PROCESSES="1") as c:
        assert c.get("/healthz").status_code == 200
        assert c.get("/healthz").json() == {"status": "ok"}
        assert_error(c.get("/v1/formats"), 401, "unauthorized")
        assert_error(c.get("/v1/formats", headers={"X-API-Key": "wrong"}), 401, "unauthorized")
        assert_error(post_mesh(c, "box.stl", (SAMPLES / "box.stl").read_bytes()), 401, "unauthorized")
        assert_error(c.post("/v1/precession", json={"principal_moments": [1, 2, 3], "omega": [0, 0, 1]}), 401, "unauthorized")
        assert_error(c.post("/v1/analyze/points", json=TRIATOMIC), 401, "unauthorized")
        files = [("files", ("box.stl", (SAMPLES / "box.stl").read_bytes(), "application/octet-stream"))]
        assert_error(c.post("/v1/batch", files=files), 401, "unauthorized")
        # RFC 9110: a 401 carries a WWW-Authenticate challenge; it names the header the key goes in
        assert "X-API-Key" in c.get("/v1/formats").headers.get("www-authenticate", "")
        key = {"X-API-Key": "s3cret"}
        assert c.get("/v1/formats", headers=key).status_code == 200
        r = c.post("/v1/analyze/mesh", files={"file": ("box.stl", (SAMPLES / "box.stl").read_bytes())}, headers=key)
        assert r.status_code == 200 and r.json()["mass"] == pytest.approx(6000, rel=1e-14, abs=0)


def test_size_limit_applies_to_chunked_and_json_bodies() -> None:
    def chunks() -> Any:
        for _ in range(50):
            yield b"x" * 1000

    with configured_client(INERTIA_MAX_UPLOAD_BYTES="10000", INERTIA_COMPUTE_PROCESSES="1") as c:
        r = c.post(
            "/v1/analyze/mesh",
            params={"format": "stl"},
            content=chunks(),
            headers={"content-type": "multipart/form-data; boundary=abc"},
        )
        assert_error(r, 413, "payload_too_large")
        pts = {"points": [{"mass": 1.0, "position": [i, 0, 0]} for i in range(2000)]}
        assert_error(c.post("/v1/analyze/points", json=pts), 413, "payload_too_large")


def test_every_error_uses_the_envelope_even_for_unknown_routes_and_bad_bodies(client: TestClient) -> None:
    for r in (
        client.get("/v1/no-such-endpoint"),
        client.get("/v1/analyze/mesh"),
        client.post("/v1/analyze/mesh", content=b"garbage", headers={"content-type": "multipart/form-data; boundary=zzz"}),
        client.post("/v1/batch"),
    ):
        assert 400 <= r.status_code < 600
        body = r.json()
        assert set(body) == {"error"} and set(body["error"]) >= {"code", "message", "details"}
        assert body["error"]["code"].replace("_", "").isalpha() and body["error"]["code"].islower()
    for r in (
        client.post("/v1/analyze/points", content=b"[1, 2]", headers={"content-type": "application/json"}),
        client.post("/v1/precession", content=b"hello", headers={"content-type": "application/json"}),
    ):
        assert_error(r, 422, "invalid_parameter")


@pytest.mark.parametrize(
    "name,data",
    [("empty.stl", b""), ("ascii.stl", b"solid x\nendsolid x\n"), ("points.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n")],
    ids=["zero bytes", "ascii stl without facets", "obj without faces"],
)
def test_files_without_triangles_are_empty_geometry(client: TestClient, name: str, data: bytes) -> None:
    r = post_mesh(client, name, data)
    if name == "empty.stl" and r.json().get("error", {}).get("code") == "unreadable_file":
        # a zero-byte file is arguably not a readable STL at all: both codes are accepted
        assert_error(r, 422, "unreadable_file")
    else:
        assert_error(r, 422, "empty_geometry")


@pytest.mark.parametrize("content_type", [None, "text/plain", "application/x-www-form-urlencoded"])
def test_a_json_body_sent_without_the_json_content_type_is_told_what_header_to_send(
    client: TestClient, content_type: str | None
) -> None:
    # `curl -d @points.json` sends application/x-www-form-urlencoded: the message must say what to change
    body = b'{"points": [{"mass": 1.0, "position": [0, 0, 0]}]}'
    headers = {"content-type": content_type} if content_type else {}
    err = assert_error(client.post("/v1/analyze/points", content=body, headers=headers), 422, "invalid_parameter")
    assert "Content-Type: application/json" in err["message"], err


def test_malformed_json_is_named_as_such(client: TestClient) -> None:
    r = client.post("/v1/precession", content=b'{"omega": [1, 0, }', headers={"content-type": "application/json"})
    err = assert_error(r, 422, "invalid_parameter")
    assert "not valid JSON" in err["message"] and err["details"]["parameter"] == "body", err


@pytest.mark.parametrize(
    "path,body,field",
    [
        ("/v1/precession", {"principal_moments": [1, 2, 3], "omega": [1, "x", 0]}, "omega"),
        ("/v1/precession", {"inertia_tensor": [[1, 0, 0], [0, 2, 0], [0, 0, "x"]], "omega": [1, 0, 0]}, "inertia_tensor"),
        ("/v1/analyze/points", {"points": [{"mass": 1, "position": [0, 0, "x"]}]}, "position"),
        ("/v1/analyze/points", {"points": [{"mass": 1, "position": [0, 0, 0]}], "frame": [1, 0, 0, "x"]}, "frame"),
    ],
)
def test_a_bad_vector_component_names_its_field_not_the_index(client: TestClient, path: str, body: Any, field: str) -> None:
    err = assert_error(client.post(path, json=body), 422, "invalid_parameter")
    assert err["details"]["parameter"] == field, err


@pytest.mark.parametrize("path,part", [("/v1/analyze/mesh", "file"), ("/v1/batch", "files")])
def test_a_file_part_without_a_file_name_is_told_to_send_a_file(client: TestClient, path: str, part: str) -> None:
    # curl -F 'file=<box.stl' (or a client that omits the file name) sends a form field, not a file
    data = (SAMPLES / "box.stl").read_bytes()
    err = assert_error(client.post(path, files={part: (None, data)}, params={"format": "stl"}), 422, "invalid_parameter")
    assert "file name" in err["message"] and f"{part}=@" in err["message"], err
    assert err["details"]["parameter"] == part
