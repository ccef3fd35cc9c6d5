"""Against a real uvicorn server (``python -m inertia serve`` on a free loopback port)."""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import httpx
import pytest

from tests.support.meshes import box_stl, torus_stl

BOX = box_stl(1, 2, 3)


def post_mesh(
    url: str, data: bytes, name: str = "box.stl", headers: dict[str, str] | None = None, timeout: float = 60.0, **params: Any
) -> httpx.Response:
    return httpx.post(f"{url}/v1/analyze/mesh", files={"file": (name, data)}, params=params, headers=headers, timeout=timeout)


def without_timing(doc: Any) -> Any:
    """The document without its wall-clock fields (``elapsed_s``)."""
    if isinstance(doc, dict):
        return {k: without_timing(v) for k, v in doc.items() if k != "elapsed_s"}
    if isinstance(doc, list):
        return [without_timing(v) for v in doc]
    return doc


def test_every_endpoint_answers_over_http(server: Any) -> None:
    url = server.url
    assert httpx.get(f"{url}/healthz").json() == {"status": "ok"}
    assert "stl" in httpx.get(f"{url}/v1/formats").json()["surface"]
    doc = post_mesh(url, BOX, omega="0,0,1").json()
    assert doc["mass"] == pytest.approx(6000, rel=1e-12, abs=0) and doc["precession"]["regime"] == "permanent_rotation"
    pts = httpx.post(
        f"{url}/v1/analyze/points", json={"points": [{"mass": 1, "position": [0, 0, -1]}, {"mass": 1, "position": [0, 0, 1]}]}
    ).json()
    assert pts["mass"] == 2 and pts["classification"]["kind"] == "linear_rotator"
    pr = httpx.post(f"{url}/v1/precession", json={"principal_moments": [1, 2, 3], "omega": [1, 0, 0]}).json()
    assert pr["precession"]["regime"] == "permanent_rotation"
    batch = httpx.post(f"{url}/v1/batch", files=[("files", ("a.stl", BOX)), ("files", ("b.obj", b"nonsense"))])
    lines = [json.loads(line) for line in batch.text.splitlines()]
    assert [line["source"]["filename"] for line in lines] == ["a.stl", "b.obj"] and "error" in lines[1]
    assert httpx.get(f"{url}/docs").status_code == 200
    assert httpx.get(f"{url}/openapi.json").json()["paths"]["/v1/batch"]


def test_access_log_has_method_path_status_elapsed(server: Any) -> None:
    httpx.get(f"{server.url}/v1/formats?probe=1")
    time.sleep(0.2)
    records = [json.loads(line[line.index("{") :]) for line in server.output().splitlines() if '"event": "access"' in line]
    formats = [r for r in records if r["path"] == "/v1/formats"]
    assert formats and formats[-1]["method"] == "GET" and formats[-1]["status"] == 200
    assert formats[-1]["elapsed_ms"] >= 0


def _multipart_chunks(data: bytes, chunk: int = 64 * 1024) -> Iterator[bytes]:
    yield (
        b'--BOUNDARY\r\nContent-Disposition: form-data; name="file"; filename="big.stl"\r\n'
        b"Content-Type: application/octet-stream\r\n\r\n"
    )
    for i in range(0, len(data), chunk):
        yield data[i : i + chunk]
    yield b"\r\n--BOUNDARY--\r\n"


def test_upload_limit_refuses_large_bodies_with_413(live_server: Any) -> None:
    url = live_server(INERTIA_MAX_UPLOAD_BYTES="200000").url
    big = torus_stl(60, 60) * 3  # ~1 MB
    declared = post_mesh(url, big)
    assert declared.status_code == 413 and declared.json()["error"]["code"] == "payload_too_large"
    assert declared.json()["error"]["details"]["content_length"] > 200_000
    chunked = httpx.post(
        f"{url}/v1/analyze/mesh",
        content=_multipart_chunks(big),
        timeout=30,
        headers={"content-type": "multipart/form-data; boundary=BOUNDARY"},
    )
    assert chunked.status_code == 413 and chunked.json()["error"]["code"] == "payload_too_large"
    small = httpx.post(
        f"{url}/v1/analyze/mesh", content=_multipart_chunks(BOX), headers={"content-type": "multipart/form-data; boundary=BOUNDARY"}
    )
    assert small.status_code == 200 and small.json()["source"]["filename"] == "big.stl"


def test_api_key_guards_v1_but_not_healthz(live_server: Any) -> None:
    url = live_server(INERTIA_API_KEY="k3y").url
    assert httpx.get(f"{url}/healthz").status_code == 200
    for headers in ({}, {"X-API-Key": "wrong"}):
        r = post_mesh(url, BOX, headers=headers)
        assert r.status_code == 401 and r.json()["error"]["code"] == "unauthorized"
        assert httpx.get(f"{url}/v1/formats", headers=headers).status_code == 401
    assert post_mesh(url, BOX, headers={"X-API-Key": "k3y"}).status_code == 200
    spec = httpx.get(f"{url}/openapi.json").json()
    assert "X-API-Key" in json.dumps(spec["components"]["securitySchemes"])


def test_timeout_stops_a_long_computation_with_503_and_the_server_recovers(live_server: Any) -> None:
    url = live_server(INERTIA_TIMEOUT_S="0.3").url
    start = time.monotonic()
    r = post_mesh(url, torus_stl(600, 600), name="torus.stl")
    assert r.status_code == 503 and r.json()["error"]["code"] == "timeout"
    assert r.json()["error"]["details"]["timeout_s"] == pytest.approx(0.3, abs=0)
    assert time.monotonic() - start < 10
    assert post_mesh(url, BOX).status_code == 200


def test_32_parallel_clients_get_identical_answers(server: Any) -> None:
    def one(_: int) -> Any:
        r = post_mesh(server.url, BOX, omega="0.1,1,0.1", duration=1, samples=20)
        assert r.status_code == 200, r.text
        return without_timing(r.json())

    with ThreadPoolExecutor(32) as pool:
        answers = list(pool.map(one, range(32)))
    assert all(a == answers[0] for a in answers)
    assert answers[0]["mass"] == pytest.approx(6000, rel=1e-12, abs=0)


@pytest.mark.slow
def test_healthz_answers_within_a_second_during_a_long_analysis(server: Any) -> None:
    big = torus_stl(1000, 1000)  # 2,000,000 triangles
    result: dict[str, Any] = {}

    def analyse() -> None:
        result["response"] = post_mesh(server.url, big, name="torus.stl", timeout=120)

    worker = threading.Thread(target=analyse)
    worker.start()
    latencies: list[float] = []
    time.sleep(0.5)  # let the upload reach the server
    while worker.is_alive() and len(latencies) < 20:
        start = time.monotonic()
        assert httpx.get(f"{server.url}/healthz", timeout=5).status_code == 200
        latencies.append(time.monotonic() - start)
        time.sleep(0.1)
    worker.join()
    assert len(latencies) >= 3, "the analysis ended before /healthz could be polled during it"
    assert max(latencies) < 1.0
    doc = result["response"].json()
    assert result["response"].status_code == 200 and doc["source"]["triangles"] == 2_000_000
