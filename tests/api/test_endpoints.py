"""Every endpoint of API.md through the in-process client; reference values from exact formulas."""

from __future__ import annotations

import io
import json
import math
import zipfile
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from benchmarks.cases import box_inertia
from tests.support.meshes import box_stl

REL = 1e-12  # float32 box corners are exact; what is left is summation rounding


def close(actual: object, expected: object, rel: float = REL) -> bool:
    a, e = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    return a.shape == e.shape and bool(np.all(np.abs(a - e) <= rel * max(1.0, float(np.abs(e).max()))))


def upload(client: TestClient, data: bytes, name: str = "box.stl", **params: object) -> Any:
    return client.post("/v1/analyze/mesh", files={"file": (name, data)}, params=params)


def test_healthz_is_ok(client: TestClient) -> None:
    r = client.get("/healthz")
    assert r.status_code == 200 and r.json() == {"status": "ok"}


def test_box_mass_centre_and_tensor_match_closed_form(client: TestClient) -> None:
    r = upload(client, box_stl(1, 2, 3))
    assert r.status_code == 200, r.text
    doc = r.json()
    assert doc["mass"] == pytest.approx(6000, rel=REL, abs=0) and doc["volume"] == pytest.approx(6, rel=REL, abs=0)
    assert doc["density"] == 1000
    assert close(doc["center_of_mass"], [0.5, 1, 1.5])
    assert close(doc["inertia_tensor"], box_inertia(6000, 1, 2, 3))
    assert close(doc["principal"]["moments"], [2500, 5000, 6500])
    assert np.linalg.det(np.array(doc["principal"]["axes"])) == pytest.approx(1, rel=1e-12, abs=0)
    assert doc["classification"]["kind"] == "asymmetric_top"
    assert doc["source"] == {
        **doc["source"],
        "filename": "box.stl",
        "format": "stl",
        "kind": "mesh",
        "vertices": 8,
        "triangles": 12,
        "watertight": True,
    }


def test_response_holds_only_sections_asked_for(client: TestClient) -> None:
    doc = upload(client, box_stl(1, 2, 3)).json()
    for absent in ("reference_inertia", "precession", "parts"):
        assert absent not in doc
    assert "null" not in json.dumps(doc)
    with_omega = upload(client, box_stl(1, 2, 3), omega="0,0,1").json()
    assert "precession" in with_omega and "trajectory" not in with_omega["precession"]


def test_reference_tensor_follows_parallel_axis_theorem(client: TestClient) -> None:
    doc = upload(client, box_stl(1, 2, 3), reference="0,0,0").json()
    d = np.array([0.5, 1.0, 1.5])
    # Steiner: I_O = I_G + m (|d|^2 E - d d^T)
    expected = box_inertia(6000, 1, 2, 3) + 6000 * (d @ d * np.eye(3) - np.outer(d, d))
    assert close(doc["reference_inertia"]["point"], [0, 0, 0])
    assert close(doc["reference_inertia"]["tensor"], expected)


def test_units_density_and_mass_options_scale_as_expected(client: TestClient) -> None:
    mm = upload(client, box_stl(10, 20, 30), units="mm", density=7850).json()
    m = 7850 * 6e-6
    assert mm["source"]["units"] == "mm" and mm["mass"] == pytest.approx(m, rel=1e-12, abs=0)
    assert close(mm["inertia_tensor"], box_inertia(m, 0.01, 0.02, 0.03), rel=1e-6)
    by_mass = upload(client, box_stl(1, 2, 3), mass=12).json()
    assert by_mass["mass"] == pytest.approx(12, rel=REL, abs=0) and by_mass["density"] == pytest.approx(2, rel=REL, abs=0)


def test_format_parameter_overrides_the_file_name(client: TestClient) -> None:
    r = upload(client, box_stl(1, 2, 3), name="upload.bin", format="stl")
    assert r.status_code == 200 and r.json()["source"]["format"] == "stl"


def test_client_paths_are_never_followed(client: TestClient) -> None:
    doc = upload(client, box_stl(1, 2, 3), name="../../etc/box.stl").json()
    assert doc["source"]["filename"] == "box.stl"


def test_omega_with_duration_and_samples_adds_a_trajectory(client: TestClient) -> None:
    doc = upload(client, box_stl(1, 2, 3), omega="0.01,1,0.01", duration=2, samples=5, method="dop853").json()
    traj = doc["precession"]["trajectory"]
    assert len(traj["t"]) == 5 and traj["t"][0] == 0 and traj["t"][-1] == pytest.approx(2, abs=0)
    assert close(traj["quaternion"][0], [1, 0, 0, 0])


def test_points_dumbbell_is_a_linear_rotator(client: TestClient) -> None:
    r = client.post(
        "/v1/analyze/points", json={"points": [{"mass": 1.0, "position": [0, 0, 0]}, {"mass": 1.0, "position": [1, 0, 0]}]}
    )
    assert r.status_code == 200, r.text
    doc = r.json()
    # two masses m at distance d: I = m d^2 / 2 about the centre, perpendicular to the rod
    assert doc["mass"] == 2 and close(doc["center_of_mass"], [0.5, 0, 0])
    assert close(doc["principal"]["moments"], [0, 0.5, 0.5])
    assert doc["classification"]["kind"] == "linear_rotator"
    assert "volume" not in doc and "density" not in doc


def test_points_example_of_the_contract_works(client: TestClient) -> None:
    body = {
        "points": [{"mass": 1.0, "position": [0, 0, 0]}, {"mass": 2.0, "position": [1, 0, 0]}],
        "units": "m",
        "tolerance": 1e-6,
        "reference": [0, 0, 0],
        "omega": [0, 0, 1],
        "duration": 10.0,
        "samples": 100,
        "method": "exact",
    }
    doc = client.post("/v1/analyze/points", json=body).json()
    # I about the centre: m1 m2 d^2 / (m1 + m2) = 2/3
    assert close(doc["principal"]["moments"], [0, 2 / 3, 2 / 3])
    assert close(doc["reference_inertia"]["tensor"], np.diag([0, 2, 2]))
    assert len(doc["precession"]["trajectory"]["t"]) == 100


def test_precession_of_symmetric_top_matches_landau_lifshitz(client: TestClient) -> None:
    I1, I3, w = 1.0, 2.0, np.array([0.1, 0.0, 1.0])
    r = client.post("/v1/precession", json={"principal_moments": [I1, I1, I3], "omega": w.tolist()})
    assert r.status_code == 200, r.text
    doc = r.json()
    p = doc["precession"]
    M = math.hypot(I1 * w[0], I3 * w[2])
    # L&L §33: Omega_pr = M / I1; body rate Omega3 (I3 - I1) / I1; cos theta = I3 Omega3 / M
    assert p["regime"] == "regular_precession"
    assert p["space_precession_rate"] == pytest.approx(M / I1, rel=1e-12, abs=0)
    assert p["body_precession_rate"] == pytest.approx(w[2] * (I3 - I1) / I1, rel=1e-12, abs=0)
    assert p["nutation_angle"] == pytest.approx(math.acos(I3 * w[2] / M), rel=1e-12, abs=0)
    assert p["spin_rate"] == pytest.approx(M * (I3 * w[2] / M) * (1 / I3 - 1 / I1), rel=1e-12, abs=0)
    assert p["period"] == pytest.approx(2 * math.pi, rel=1e-12, abs=0)
    assert doc["classification"]["kind"] == "symmetric_top" and doc["classification"]["shape"] == "oblate"
    assert set(doc) == {"principal", "classification", "precession", "warnings", "diagnostics"}


def test_precession_from_a_tensor_rotates_into_the_input_frame(client: TestClient) -> None:
    r = client.post(
        "/v1/precession",
        json={"inertia_tensor": [[3, 0, 0], [0, 2, 0], [0, 0, 4]], "omega": [0, 0, 1], "duration": 1, "samples": 3},
    )
    doc = r.json()
    assert close(doc["principal"]["moments"], [2, 3, 4])
    assert doc["precession"]["regime"] == "permanent_rotation"
    assert close(doc["precession"]["trajectory"]["omega"], [[0, 0, 1]] * 3, rel=1e-9)


def test_formats_lists_surfaces_volumes_and_scenes(client: TestClient) -> None:
    doc = client.get("/v1/formats").json()
    names = {f["format"]: f for f in doc["formats"]}
    assert {"stl", "obj", "ply", "off", "glb", "gltf", "3mf", "vtu", "vtk", "msh"} <= set(names)
    assert names["stl"] == {"format": "stl", "kind": "surface", "parts": False}
    assert names["vtu"]["kind"] == "volume" and names["3mf"]["parts"] is True
    assert "msh" in doc["volume"] and "glb" in doc["scene"] and "stl" in doc["surface"]


def _lines(response: Any) -> list[dict[str, Any]]:
    assert response.status_code == 200, response.text
    assert response.headers["content-type"].startswith("application/x-ndjson")
    return [json.loads(line) for line in response.text.splitlines()]


def test_batch_streams_one_line_per_file_in_upload_order(client: TestClient) -> None:
    files = [
        ("files", ("a.stl", box_stl(1, 2, 3))),
        ("files", ("notes.txt", b"hello")),
        ("files", ("empty.stl", b"")),
        ("files", ("b.stl", box_stl(2, 2, 2))),
    ]
    lines = _lines(client.post("/v1/batch", files=files, params={"density": 500}))
    assert [line["source"]["filename"] for line in lines] == ["a.stl", "notes.txt", "empty.stl", "b.stl"]
    assert lines[0]["mass"] == pytest.approx(3000, abs=0) and lines[3]["mass"] == pytest.approx(4000, abs=0)
    assert lines[1]["error"]["code"] == "unsupported_format"
    assert lines[2]["error"]["code"] == "empty_geometry"


def test_batch_of_a_zip_expands_members_in_archive_order(client: TestClient) -> None:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("parts/", b"")
        zf.writestr("parts/one.stl", box_stl(1, 1, 1))
        zf.writestr("__MACOSX/parts/._one.stl", b"junk")
        zf.writestr("readme.md", b"# not a mesh")
        zf.writestr("parts/two.stl", box_stl(1, 1, 2))
    files = [("files", ("parts.zip", buf.getvalue())), ("files", ("broken.zip", b"PK not really"))]
    lines = _lines(client.post("/v1/batch", files=files))
    assert [line["source"]["filename"] for line in lines] == ["parts/one.stl", "readme.md", "parts/two.stl", "broken.zip"]
    assert lines[0]["mass"] == pytest.approx(1000, abs=0) and lines[2]["mass"] == pytest.approx(2000, abs=0)
    assert lines[1]["error"]["code"] == "unsupported_format"
    assert lines[3]["error"]["code"] == "unreadable_file"


def test_openapi_documents_every_endpoint_with_an_example(client: TestClient) -> None:
    spec = client.get("/openapi.json").json()
    paths = spec["paths"]
    for path in ("/v1/analyze/mesh", "/v1/analyze/points", "/v1/precession", "/v1/batch"):
        assert "post" in paths[path]
    assert "get" in paths["/healthz"] and "get" in paths["/v1/formats"]
    schemas = spec["components"]["schemas"]
    assert schemas["PointsRequest"]["examples"] and schemas["PrecessionRequest"]["examples"]
    assert "curl" in paths["/v1/analyze/mesh"]["post"]["description"]
    assert client.get("/docs").status_code == 200
