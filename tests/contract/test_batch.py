"""POST /v1/batch: NDJSON, one line per file."""

from __future__ import annotations

import io
import json
import zipfile
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from benchmarks.cases import stl_bytes
from tests.contract.helpers import SAMPLES, analyze, assert_error, assert_no_nulls, strip_elapsed, truncated_stl


def ndjson_lines(r: Any) -> list[dict[str, Any]]:
    assert r.status_code == 200, r.text
    assert r.headers["content-type"].split(";")[0].strip() == "application/x-ndjson"
    lines = [json.loads(x) for x in r.text.splitlines() if x.strip()]
    for line in lines:
        assert_no_nulls(line)
    return lines


BATCH_FILES = ["box.stl", "open_box.stl", "tetrahedron.stl", "l_bracket.stl"]


def check_batch_lines(client: TestClient, lines: list[dict[str, Any]], params: dict[str, Any]) -> None:
    assert [line["source"]["filename"].rsplit("/", 1)[-1] for line in lines] == BATCH_FILES
    assert set(lines[1]) == {"source", "error"}
    err = lines[1]["error"]
    assert err["code"] == "not_watertight" and err["message"] and isinstance(err["details"], dict)
    for i in (0, 2, 3):
        assert "error" not in lines[i]
        single = analyze(client, BATCH_FILES[i], **params)
        got = strip_elapsed(lines[i])
        want = strip_elapsed(single)
        got["source"].pop("filename")
        want["source"].pop("filename")
        assert got == want


def test_batch_streams_one_line_per_file_in_upload_order(client: TestClient) -> None:
    files = [("files", (name, (SAMPLES / name).read_bytes(), "application/octet-stream")) for name in BATCH_FILES]
    r = client.post("/v1/batch", files=files, params={"density": "2000", "reference": "0,0,0"})
    lines = ndjson_lines(r)
    assert len(lines) == 4
    assert lines[0]["mass"] == pytest.approx(12000, rel=1e-14, abs=0)
    check_batch_lines(client, lines, {"density": "2000", "reference": "0,0,0"})


def test_batch_accepts_one_zip_of_files(client: TestClient) -> None:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for name in BATCH_FILES:
            z.writestr(name, (SAMPLES / name).read_bytes())
    params = {"units": "mm", "omega": "0.1,2,0.1", "duration": "2", "samples": "3"}
    r = client.post("/v1/batch", files=[("files", ("meshes.zip", buf.getvalue(), "application/zip"))], params=params)
    lines = ndjson_lines(r)
    assert len(lines) == 4
    assert lines[0]["mass"] == pytest.approx(6e-6, rel=1e-13, abs=0)
    assert len(lines[0]["precession"]["trajectory"]["t"]) == 3
    check_batch_lines(client, lines, params)


def test_batch_unsupported_and_unreadable_files_are_error_lines(client: TestClient) -> None:
    files = [
        ("files", ("a.xyz123", b"nothing", "application/octet-stream")),
        ("files", ("b.stl", truncated_stl(), "application/octet-stream")),
        ("files", ("c.stl", (SAMPLES / "box.stl").read_bytes(), "application/octet-stream")),
    ]
    lines = ndjson_lines(client.post("/v1/batch", files=files))
    assert [line["source"]["filename"] for line in lines] == ["a.xyz123", "b.stl", "c.stl"]
    assert lines[0]["error"]["code"] == "unsupported_format"
    assert lines[1]["error"]["code"] == "unreadable_file"
    assert lines[2]["mass"] == pytest.approx(6000, rel=1e-14, abs=0)


def test_batch_with_an_invalid_parameter_is_rejected_with_the_envelope(client: TestClient) -> None:
    files = [("files", ("box.stl", (SAMPLES / "box.stl").read_bytes(), "application/octet-stream"))]
    assert_error(client.post("/v1/batch", files=files, params={"units": "parsec"}), 422, "invalid_parameter")


def test_batch_keeps_upload_order_with_files_of_very_different_cost(client: TestClient) -> None:
    n, m = 200, 100  # a 40 000-triangle torus next to 12-triangle boxes
    u = np.linspace(0, 2 * np.pi, n, endpoint=False)[:, None]
    w = np.linspace(0, 2 * np.pi, m, endpoint=False)[None, :]
    ring = 2 + 0.5 * np.cos(w)
    pts = np.stack([ring * np.cos(u), ring * np.sin(u), 0.5 * np.sin(w) + 0 * u], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    a, b = i * m + j, ((i + 1) % n) * m + j
    c, d = ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    torus = stl_bytes(pts, faces)
    box = (SAMPLES / "box.stl").read_bytes()
    names = [f"{k:02d}_{'torus' if k % 3 == 0 else 'box'}.stl" for k in range(9)]
    files = [("files", (nm, torus if "torus" in nm else box, "application/octet-stream")) for nm in names]
    lines = ndjson_lines(client.post("/v1/batch", files=files))
    assert [line["source"]["filename"] for line in lines] == names
    for nm, line in zip(names, lines):
        if "box" in nm:
            assert line["mass"] == pytest.approx(6000, rel=1e-14, abs=0)
        else:
            assert line["source"]["triangles"] == 2 * n * m
