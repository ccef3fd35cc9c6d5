"""Issue 12 (and issue 13's collinear points): nothing negative, non-finite or made of rounding comes back.

- A float32 STL of a part at growing offsets from the origin: while the stored
  coordinates still represent it, the moments are those of the stored float32
  polyhedron (exact rational integration, ``benchmarks/exact.py``) within the
  estimate; once float32 resolution at the offset is comparable to the part,
  the file is refused as ``insufficient_precision`` with a message that names
  the float32 resolution and says to export in float64 or nearer the origin.
- Zero-volume polyhedra made of many flat shells (float32 and float64) are
  refused; flipping their shells never makes them a body.
- Collinear points with omega are a linear rotator, with finite numbers and
  no negative moment, through the library, the HTTP API and the CLI's JSON.
"""

from __future__ import annotations

import json
import subprocess
import sys
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient
from scipy.spatial.transform import Rotation

from benchmarks.cases import box, flat_shells, obj_bytes, stl_bytes
from benchmarks.exact import exact_moments, relative_error
from inertia import analyze, analyze_points
from inertia.errors import DegenerateBodyError, InsufficientPrecisionError
from inertia.pipeline import AnalysisOptions
from tests.support.paths import ROOT

# a 1 x 0.5 x 0.2 box, turned so that no coordinate lies on a float32 grid line
ROT = Rotation.from_euler("zyx", [0.3, 0.5, -0.7]).as_matrix()
CORNERS, FACES = box(1.0, 0.5, 0.2)


@pytest.mark.parametrize("exponent", range(9))
def test_float32_part_at_growing_offsets_is_exact_or_refused(exponent: float) -> None:
    offset = 10.0**exponent * np.array([1.0, 0.7, 0.4])
    vertices = CORNERS @ ROT.T + offset
    data = stl_bytes(vertices, FACES)
    stored = vertices.astype(np.float32).astype(np.float64)
    resolution = 2.0**-24 * np.abs(stored).max()
    try:
        result = analyze(data, filename="part.stl")
    except InsufficientPrecisionError as exc:
        assert exc.code == "insufficient_precision"
        assert "float32" in exc.message and "float64" in exc.message and "nearer the origin" in exc.message
        assert resolution > 0.01  # refused only where float32 steps are a sizeable part of the 0.2 wall
        return
    except DegenerateBodyError as exc:  # the last offsets collapse every triangle: zero volume, naming float32
        assert exc.code == "zero_volume" and resolution > 0.1 and "float32" in exc.message, exc
        return
    assert resolution < 0.05, "a part whose wall is a few float32 steps thick must be refused"
    moments = np.sort(result.props.principal_moments)
    est = result.props.relative_error_estimate
    assert np.all(moments > 0) and np.isfinite(est) and est < 1e-9
    for got, want in zip(moments, exact_moments(stored, FACES)):
        assert relative_error(got / 1000.0, want) <= est
    json.dumps(result.as_dict(), allow_nan=False)
    if resolution > 1e-5:
        assert any("float32" in w for w in result.warnings)


def test_the_part_collapses_within_the_range() -> None:
    refused = []
    for exponent in range(9):
        vertices = CORNERS @ ROT.T + 10.0**exponent * np.array([1.0, 0.7, 0.4])
        try:
            analyze(stl_bytes(vertices, FACES), filename="part.stl")
        except DegenerateBodyError:  # insufficient_precision, or zero_volume once every triangle collapses
            refused.append(exponent)
    assert refused and refused == list(range(refused[0], refused[-1] + 1)) and refused[0] <= 7


@pytest.mark.parametrize("offset", [1e3, 1e5, 1e6, 4e6])
def test_float32_part_on_whole_units_far_away_is_exact_without_a_warning(offset: float) -> None:
    """A box from offset to offset + (1, 2, 3), stored exactly in float32 (steps of 1/4 at 4e6): the polyhedron
    read is the part (API.md: "exactly the polyhedron that was read ... float32 for binary STL")."""
    corners, faces = box(1.0, 2.0, 3.0)
    vertices = corners - corners.min(axis=0) + offset
    assert np.array_equal(vertices.astype(np.float32), vertices)
    for data, name in ((stl_bytes(vertices, faces), "part.stl"), (_ascii_stl(vertices, faces), "part_ascii.stl")):
        result = analyze(data, filename=name)
        # mass 1000 * 6; I = m (b^2 + c^2) / 12 and its cyclic companions
        assert result.props.mass == pytest.approx(6000.0, rel=1e-15)
        assert np.sort(result.props.principal_moments) == pytest.approx([2500.0, 5000.0, 6500.0], rel=1e-14)
        assert not any("float32" in w for w in result.warnings), result.warnings


def _ascii_stl(vertices: np.ndarray, faces: np.ndarray) -> bytes:
    facets = "".join(
        "facet normal 0 0 0\nouter loop\n"
        + "".join(f"vertex {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in vertices[f])
        + "endloop\nendfacet\n"
        for f in faces
    )
    return f"solid part\n{facets}endsolid part\n".encode()


def test_zero_volume_float32_shells_are_refused_not_flipped_into_a_body() -> None:
    vertices, faces = flat_shells(1e4)
    with pytest.raises(InsufficientPrecisionError, match="float32"):
        analyze(stl_bytes(vertices, faces), filename="shells.stl")


def test_zero_volume_float64_shells_are_refused_not_flipped_into_a_body() -> None:
    vertices, faces = flat_shells(1e6)
    with pytest.raises(InsufficientPrecisionError, match="degenerate shells"):
        analyze(obj_bytes([(None, vertices, faces)]), filename="shells.obj")


COLLINEAR = [
    {"mass": 1.0, "position": [0.0, 0.0, 1e5]},
    {"mass": 2.0, "position": [1.0, 1.0, 1e5 + 1.0]},
    {"mass": 1.0, "position": [3.0, 3.0, 1e5 + 3.0]},
]


def _collinear(seed: int) -> list[dict[str, object]]:
    rng = np.random.default_rng(seed)
    d, p0 = rng.normal(size=3), rng.normal(size=3) * 10 ** rng.uniform(-3, 5)
    return [{"mass": float(m), "position": (p0 + t * d).tolist()} for m, t in zip(rng.uniform(0.1, 10, 4), rng.normal(size=4))]


@pytest.mark.parametrize("points", [COLLINEAR] + [_collinear(s) for s in range(20)])
def test_collinear_points_with_omega_are_a_rotator(points: Any) -> None:
    result = analyze_points(points, AnalysisOptions(omega=(0.1, 1.0, 0.3)))
    assert result.classification.kind == "linear_rotator"
    assert result.motion is not None and result.motion.regime.value == "rotator"
    assert np.all(result.frame.moments >= 0) and result.frame.moments[0] == 0.0
    assert np.isfinite(result.props.relative_error_estimate) and result.props.relative_error_estimate < 1e-6
    # the exact moments of the points as given: the two equal ones within the estimate
    m = np.array([p["mass"] for p in points])
    x = np.array([p["position"] for p in points])
    d = x - m @ x / m.sum()
    with np.errstate(all="ignore"):
        along = np.linalg.svd(d)[2][0]
    about_normal = np.sum(m * (d @ along) ** 2)  # a normal axis through the centre: sum m |d|^2
    assert result.frame.moments[2] == pytest.approx(about_normal, rel=1e-9)
    json.dumps(result.as_dict(), allow_nan=False)


@pytest.fixture(scope="module")
def client() -> Iterator[object]:
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Using `httpx` with `starlette.testclient`")
        from fastapi.testclient import TestClient
    from inertia.app import app

    with TestClient(app) as c:
        yield c


def test_http_collinear_points_with_omega(client: TestClient) -> None:
    res = client.post("/v1/analyze/points", json={"points": COLLINEAR, "omega": [0.1, 1, 0.3]})
    assert res.status_code == 200, res.text
    doc = res.json()
    assert doc["precession"]["regime"] == "rotator" and doc["principal"]["moments"][0] == 0.0
    assert "Infinity" not in res.text and "NaN" not in res.text


def test_http_float32_collapse_is_a_422_naming_the_cause(client: TestClient) -> None:
    vertices = CORNERS @ ROT.T + 1e7 * np.array([1.0, 0.7, 0.4])
    res = client.post("/v1/analyze/mesh", files={"file": ("part.stl", stl_bytes(vertices, FACES))})
    assert res.status_code == 422
    err = res.json()["error"]
    assert err["code"] == "insufficient_precision" and "float32" in err["message"]


def test_cli_json_never_prints_infinity(tmp_path: Path) -> None:
    path = tmp_path / "line.json"
    path.write_text(json.dumps({"points": COLLINEAR}))
    out = subprocess.run(
        [sys.executable, "-m", "inertia", "analyze", str(path), "--json", "--omega", "0.1,1,0.3"],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert out.returncode == 0, out.stderr
    assert "Infinity" not in out.stdout and "NaN" not in out.stdout
    assert json.loads(out.stdout)["precession"]["regime"] == "rotator"
    stl = tmp_path / "far.stl"
    stl.write_bytes(stl_bytes(CORNERS @ ROT.T + 1e7 * np.array([1.0, 0.7, 0.4]), FACES))
    out = subprocess.run([sys.executable, "-m", "inertia", "analyze", str(stl), "--json"], capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 4
    assert json.loads(out.stderr)["error"]["code"] == "insufficient_precision"
