"""The service itself: /healthz and /v1/formats."""

from __future__ import annotations

import json

from fastapi.testclient import TestClient

from tests.contract.helpers import assert_no_nulls


def test_healthz_reports_ok(client: TestClient) -> None:
    r = client.get("/healthz")
    assert r.status_code == 200
    assert r.json() == {"status": "ok"}


def test_healthz_answers_a_head_probe(client: TestClient) -> None:
    # load balancers and container health checks may probe with HEAD: the same status, no body
    r = client.head("/healthz")
    assert r.status_code == 200 and r.content == b""


def test_formats_lists_readable_formats_and_their_capabilities(client: TestClient) -> None:
    r = client.get("/v1/formats")
    assert r.status_code == 200
    body = r.json()
    assert_no_nulls(body)
    text = json.dumps(body).lower()
    for fmt in ("stl", "obj", "ply", "off", "glb", "gltf", "3mf", "vtu", "vtk", "msh"):
        assert f'"{fmt}"' in text, fmt
    for word in ("volume", "surface"):
        assert word in text
    assert "scene" in text or "parts" in text
