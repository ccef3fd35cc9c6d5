"""Black-box tests of the HTTP contract (API.md) and of the CLI.

Only public surfaces are used: the ASGI app through ``fastapi.testclient``
(``inertia.app.app``, or ``inertia.api.create_app()`` after setting the
``INERTIA_*`` environment variables the contract names) and the command line
through ``python -m inertia``.  Every expected value is computed here, from

* closed formulas (box m(b²+c²)/12, parallel-axis theorem, dumbbell
  m1 m2 l²/(m1+m2), isosceles triatomic molecule, Landau & Lifshitz §§33-37),
* exact rational integration of the vertices as written (``fractions``),
  with eigenvalues at 50 digits (``mpmath``),
* an independent high-accuracy integration of Euler's equations and of the
  attitude (``scipy.integrate.solve_ivp``, DOP853, rtol 1e-12),
* the complete elliptic integral K(k) (``scipy.special.ellipk``).

Nothing here imports the code under test except the app factory.
"""

from __future__ import annotations

import io
import json
import math
import os
import struct
import subprocess
import sys
import warnings
import zipfile
from collections.abc import Iterator
from contextlib import contextmanager
from fractions import Fraction
from pathlib import Path
from typing import Any, cast

import mpmath
import numpy as np
import pytest
from fastapi.testclient import TestClient
from scipy.special import ellipk

from benchmarks.cases import stl_bytes
from tests.support.motion import euler_reference

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    from fastapi.testclient import TestClient

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ROOT / "sample_meshes"
RHO = 1000.0  # default density [kg/m^3] (API.md)

UNIT_SCALE = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "in": 0.0254, "ft": 0.3048}


# ----------------------------------------------------------------------------------------
# clients
# ----------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def client() -> Iterator[TestClient]:
    from inertia.app import app

    with TestClient(app) as c:
        yield c


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


def post_mesh(client: TestClient, filename: str, data: bytes, **params: Any) -> Any:
    q = {k: (v if isinstance(v, str) else str(v)) for k, v in params.items()}
    return client.post("/v1/analyze/mesh", files={"file": (filename, data, "application/octet-stream")},
                       params=q)


def analyze(client: TestClient, filename: str, data: bytes | None = None, **params: Any) -> dict[str, Any]:
    if data is None:
        data = (SAMPLES / filename).read_bytes()
    r = post_mesh(client, filename, data, **params)
    assert r.status_code == 200, r.text
    body = r.json()
    assert_no_nulls(body)
    return cast("dict[str, Any]", body)


def assert_error(r: Any, status: int, code: str) -> dict[str, Any]:
    assert r.status_code == status, (r.status_code, r.text)
    body = r.json()
    assert set(body) == {"error"}, body
    err = body["error"]
    assert set(err) >= {"code", "message", "details"}, err
    assert err["code"] == code, err
    assert isinstance(err["message"], str) and err["message"].strip(), err
    assert isinstance(err["details"], dict), err
    return cast("dict[str, Any]", err)


def assert_no_nulls(obj: Any, path: str = "$") -> None:
    if obj is None:
        raise AssertionError(f"null at {path}")
    if isinstance(obj, dict):
        for k, v in obj.items():
            assert_no_nulls(v, f"{path}.{k}")
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            assert_no_nulls(v, f"{path}[{i}]")
    elif isinstance(obj, float):
        assert math.isfinite(obj), f"non-finite number at {path}"


def strip_elapsed(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {k: strip_elapsed(v) for k, v in obj.items() if k != "elapsed_s"}
    if isinstance(obj, list):
        return [strip_elapsed(v) for v in obj]
    return obj


# ----------------------------------------------------------------------------------------
# mesh writers and readers
# ----------------------------------------------------------------------------------------

BOX_FACES = np.array([
    [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5],
    [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],
    [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],
])


def box_corners(a: float, b: float, c: float) -> np.ndarray:
    """Corners of [0,a]x[0,b]x[0,c], indexed so that BOX_FACES wind outward."""
    return np.array([[x, y, z] for x in (0, a) for y in (0, b) for z in (0, c)], dtype=np.float64)


def obj_bytes(objects: list[tuple[str | None, np.ndarray, np.ndarray]]) -> bytes:
    """OBJ text, float64 coordinates written with repr (exact round trip)."""
    lines, base = [], 0
    for name, v, f in objects:
        if name is not None:
            lines.append(f"o {name}")
        lines += ["v " + " ".join(repr(float(x)) for x in p) for p in v]
        lines += ["f " + " ".join(str(base + int(i) + 1) for i in t) for t in f]
        base += len(v)
    return ("\n".join(lines) + "\n").encode()


def read_stl_triangles(data: bytes) -> np.ndarray:
    (n,) = struct.unpack("<I", data[80:84])
    rec = np.frombuffer(data[84:84 + 50 * n],
                        dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    return rec["v"].astype(np.float64)


def read_obj_triangles(data: bytes) -> np.ndarray:
    verts, tris = [], []
    for line in data.decode().splitlines():
        p = line.split()
        if not p:
            continue
        if p[0] == "v":
            verts.append([float(x) for x in p[1:4]])
        elif p[0] == "f":
            idx = [int(x.split("/")[0]) - 1 for x in p[1:]]
            for k in range(1, len(idx) - 1):
                tris.append([idx[0], idx[k], idx[k + 1]])
    return cast("np.ndarray", np.asarray(verts)[np.asarray(tris)])


# ----------------------------------------------------------------------------------------
# exact references
# ----------------------------------------------------------------------------------------

def exact_mass_properties(triangles: np.ndarray, density: float = RHO) -> Any:
    """Exact rational mass, centre of mass and inertia tensor (about the COM) of the closed
    polyhedron with these triangles (divergence theorem, tetrahedra from the origin:
    ∫x dV = V s/4, ∫x xᵀ dV = V/20 (Σ v vᵀ + s sᵀ))."""
    F = Fraction
    V = F(0)
    S1 = [F(0)] * 3
    S2 = [[F(0)] * 3 for _ in range(3)]
    for tri in triangles:
        a, b, c = ([F(float(x)) for x in p] for p in tri)
        det = (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
               + a[2] * (b[0] * c[1] - b[1] * c[0]))
        vol = det / 6
        s = [a[i] + b[i] + c[i] for i in range(3)]
        V += vol
        for i in range(3):
            S1[i] += vol * s[i] / 4
            for j in range(3):
                S2[i][j] += vol / 20 * (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + s[i] * s[j])
    if V < 0:  # inverted winding: the same solid
        V, S1, S2 = -V, [-x for x in S1], [[-x for x in r] for r in S2]
    rho = F(density)
    com = [x / V for x in S1]
    C = [[rho * (S2[i][j] - V * com[i] * com[j]) for j in range(3)] for i in range(3)]
    tr = C[0][0] + C[1][1] + C[2][2]
    inertia = [[(tr if i == j else 0) - C[i][j] for j in range(3)] for i in range(3)]
    return rho * V, com, inertia, V


def exact_moments(inertia: list[list[Fraction]]) -> list[float]:
    with mpmath.workdps(50):
        m = mpmath.matrix([[mpmath.mpf(x.numerator) / x.denominator for x in row] for row in inertia])
        ev, _ = mpmath.eigsy(m)
        return sorted(float(ev[i]) for i in range(3))


def exact_of(filename: str, data: bytes | None = None) -> Any:
    data = data if data is not None else (SAMPLES / filename).read_bytes()
    tris = read_stl_triangles(data) if filename.endswith(".stl") else read_obj_triangles(data)
    return exact_mass_properties(tris)


def parallel_axis(I_com: np.ndarray, mass: float, d: np.ndarray) -> np.ndarray:
    d = np.asarray(d, float)
    return cast("np.ndarray", I_com + mass * (d @ d * np.eye(3) - np.outer(d, d)))


def box_inertia(m: float, a: float, b: float, c: float) -> np.ndarray:
    return m / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def rotation(axis: Any, angle: float) -> np.ndarray:
    u = np.asarray(axis, float)
    u = u / np.linalg.norm(u)
    K = hat(u)
    return cast("np.ndarray", np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K)


def hat(w: Any) -> np.ndarray:
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]], dtype=float)


def quat_matrix(q: Any) -> np.ndarray:
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def ray_kappa(moments: Any) -> float:
    I1, I2, I3 = moments
    A, B, C = 1 / I1, 1 / I2, 1 / I3
    return cast("float", (2 * B - A - C) / (A - C))


def ll_asymmetric_period(I: Any, Omega: Any) -> float:
    """Landau & Lifshitz §37: period of Ω(t) in the body frame, I1 < I2 < I3."""
    I1, I2, I3 = I
    W = np.asarray(Omega, float)
    M2 = float(np.sum((np.asarray(I) * W) ** 2))
    E2 = float(np.sum(np.asarray(I) * W * W))  # 2E
    if M2 > E2 * I2:
        rate = math.sqrt((I3 - I2) * (M2 - E2 * I1) / (I1 * I2 * I3))
        k2 = (I2 - I1) * (E2 * I3 - M2) / ((I3 - I2) * (M2 - E2 * I1))
    else:
        rate = math.sqrt((I2 - I1) * (E2 * I3 - M2) / (I1 * I2 * I3))
        k2 = (I3 - I2) * (M2 - E2 * I1) / ((I2 - I1) * (E2 * I3 - M2))
    return 4 * float(ellipk(k2)) / rate


def reference_motion(moments: Any, axes: Any, omega0: Any, times: Any) -> Any:
    """Independent torque-free motion (``tests.support.motion.euler_reference``: Euler's equations and
    dR/dt = R [Ω]x by DOP853 at rtol 1e-12) with B(t) = axesᵀ R(t), the map principal frame -> fixed
    input frame. Returns (Ω(t), ω(t) = B Ω, R(t) = B(t) axes)."""
    A = np.asarray(axes, float)
    Ws, Rs_body = euler_reference(moments, A @ np.asarray(omega0, float), np.asarray(times, float))
    Bs = A.T @ Rs_body
    omegas = np.einsum("nij,nj->ni", Bs, Ws)
    return Ws, omegas, Bs @ A


# ----------------------------------------------------------------------------------------
# shared structural checks
# ----------------------------------------------------------------------------------------

def check_principal(res: dict[str, Any], tensor: np.ndarray | None = None) -> None:
    p = res["principal"]
    I = np.asarray(p["moments"], float)
    A = np.asarray(p["axes"], float)
    q = np.asarray(p["quaternion"], float)
    assert I.shape == (3,) and A.shape == (3, 3) and q.shape == (4,)
    assert I[0] <= I[1] <= I[2], "moments must be ascending"
    np.testing.assert_allclose(A @ A.T, np.eye(3), atol=1e-12)
    assert abs(np.linalg.det(A) - 1) < 1e-12, "axes must be right-handed (det +1)"
    assert abs(np.linalg.norm(q) - 1) < 1e-12
    # quaternion [w, x, y, z] rotates principal-frame vectors into the input frame
    np.testing.assert_allclose(quat_matrix(q), A.T, atol=1e-12)
    assert isinstance(p["unique_axes"], bool)
    if tensor is None and "inertia_tensor" in res:
        tensor = np.asarray(res["inertia_tensor"], float)
    if tensor is not None:
        scale = float(np.trace(tensor))
        np.testing.assert_allclose(tensor, tensor.T, atol=1e-14 * scale)
        for k in range(3):  # rows are eigenvectors with the moments in the same order
            np.testing.assert_allclose(tensor @ A[k], I[k] * A[k], atol=1e-11 * scale)


def check_classification(res: dict[str, Any], kind: str, shape: str | None = None,
                         planar: bool | None = None, tolerance: float = 1e-6) -> None:
    c = res["classification"]
    assert c["kind"] == kind, c
    assert c["tolerance"] == tolerance
    if planar is not None:
        assert c["planar"] is planar, c
    moments = res["principal"]["moments"]
    if kind == "symmetric_top":
        assert c.get("shape") == shape, c
    else:
        assert "shape" not in c, c
    if kind in ("spherical_top", "linear_rotator"):
        assert "asymmetry" not in c, c
    else:
        assert c["asymmetry"] == pytest.approx(ray_kappa(moments), rel=1e-12, abs=1e-12)
        assert -1 <= c["asymmetry"] <= 1
    if kind in ("symmetric_top", "linear_rotator"):
        n = np.asarray(c["symmetry_axis"], float)
        assert abs(np.linalg.norm(n) - 1) < 1e-12
        A = np.asarray(res["principal"]["axes"], float)
        unique = 0 if (kind == "linear_rotator" or shape == "prolate") else 2
        assert abs(abs(n @ A[unique]) - 1) < 1e-9, "symmetry axis is the unique principal axis"
    unique_axes = kind == "asymmetric_top"
    assert res["principal"]["unique_axes"] is unique_axes


# ----------------------------------------------------------------------------------------
# GET endpoints
# ----------------------------------------------------------------------------------------

def test_healthz_reports_ok(client: TestClient) -> None:
    r = client.get("/healthz")
    assert r.status_code == 200
    assert r.json() == {"status": "ok"}


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


# ----------------------------------------------------------------------------------------
# sample meshes: exact values
# ----------------------------------------------------------------------------------------

# file, mass, centre of mass, moments, kind, shape (sample_meshes/README.md; closed formulas)
PHI = (1 + 5 ** 0.5) / 2
ICO_MASS = RHO * 5 * (3 + 5 ** 0.5) / 12
SAMPLE_TABLE = [
    ("box.stl", 6000.0, (0.5, 1, 1.5), box_inertia(6000, 1, 2, 3).diagonal()[::-1],
     "asymmetric_top", None),
    ("l_bracket.stl", 12000.0, (1.5, 1, 1), (9000, 24000, 25000), "asymmetric_top", None),
    ("tetrahedron.stl", 1000 / 6, (0.25, 0.25, 0.25), (125 / 12, 125 / 12, 50 / 3),
     "symmetric_top", "oblate"),
    ("hex_prism.stl", 5196.15232944, (0, 0, 1), (2165.06343174, 2814.58247292, 2814.58251178),
     "symmetric_top", "prolate"),
    # float32 vertices: 2.2e-8 away from the ideal icosahedron, so the published exact values
    ("icosahedron.stl", 2181.69503867, (0, 0, 0), (571.175184819,) * 3, "spherical_top", None),
    ("needle.obj", 1e-3, (0, 0, 0), (1e-3 * 2e-6 / 12, 1e-3 * (1 + 1e-6) / 12, 1e-3 * (1 + 1e-6) / 12),
     "symmetric_top", "prolate"),
    ("plate.obj", 1.0, (0, 0, 0), ((1 + 1e-6) / 12, (1 + 1e-6) / 12, 2 / 12), "symmetric_top", "oblate"),
    ("inverted_box.stl", 6000.0, (0.5, 1, 1.5), (2500, 5000, 6500), "asymmetric_top", None),
    ("two_density.vtu", 9000.0, (1.38888888889, 0.5, 0.5), (1500, 2388.88888889, 2388.88888889),
     "symmetric_top", "prolate"),
]


@pytest.mark.parametrize("filename,mass,com,moments,kind,shape", SAMPLE_TABLE,
                         ids=[row[0] for row in SAMPLE_TABLE])
def test_sample_mesh_matches_published_values(client: TestClient, filename: str, mass: float, com: Any, moments: Any, kind: str, shape: str | None) -> None:
    res = analyze(client, filename)
    assert res["mass"] == pytest.approx(mass, rel=1e-10)
    size = max(1.0, float(np.max(np.abs(com))))
    np.testing.assert_allclose(res["center_of_mass"], com, rtol=0, atol=1e-10 * size)
    np.testing.assert_allclose(res["principal"]["moments"], moments, rtol=1e-10)
    check_principal(res)
    check_classification(res, kind, shape)
    assert "parts" not in res or filename.endswith(".vtu")
    assert res["source"]["filename"] == filename
    assert res["source"]["format"] == filename.rsplit(".", 1)[1]
    assert res["source"]["units"] == "m"
    assert isinstance(res["warnings"], list) if "warnings" in res else True
    d = res["diagnostics"]
    assert d["elapsed_s"] >= 0 and d["relative_error_estimate"] >= 0


@pytest.mark.parametrize("filename", ["box.stl", "l_bracket.stl", "tetrahedron.stl", "hex_prism.stl",
                                      "icosahedron.stl", "needle.obj", "plate.obj", "inverted_box.stl"])
def test_moments_are_those_of_the_polyhedron_as_written_within_the_error_estimate(client: TestClient, filename: str) -> None:
    """API.md Accuracy: exactly the polyhedron read (float32 for binary STL), each principal
    moment to within relative_error_estimate of its own value."""
    res = analyze(client, filename)
    mass, com, inertia, volume = exact_of(filename)
    assert res["mass"] == pytest.approx(float(mass), rel=1e-14)
    assert res["volume"] == pytest.approx(float(volume), rel=1e-14)
    assert res["density"] == RHO
    np.testing.assert_allclose(res["center_of_mass"], [float(x) for x in com], rtol=0,
                               atol=1e-14 * max(1, max(abs(float(x)) for x in com)))
    est = res["diagnostics"]["relative_error_estimate"]
    assert est <= 1e-12
    for got, want in zip(res["principal"]["moments"], exact_moments(inertia)):
        assert abs(got - want) <= max(est, 2.3e-16) * abs(want), (got, want, est)
    tensor = np.array([[float(x) for x in row] for row in inertia])
    np.testing.assert_allclose(res["inertia_tensor"], tensor, rtol=0, atol=1e-13 * np.trace(tensor))


def test_source_describes_the_uploaded_mesh(client: TestClient) -> None:
    res = analyze(client, "box.stl", units="mm")
    src = res["source"]
    assert src["filename"] == "box.stl" and src["format"] == "stl" and src["kind"] == "mesh"
    assert src["units"] == "mm"
    assert src["vertices"] == 8 and src["triangles"] == 12 and src["watertight"] is True


def test_box_tensor_in_input_frame_and_reference_by_parallel_axis_theorem(client: TestClient) -> None:
    res = analyze(client, "box.stl", reference="0,0,0")
    I_com = box_inertia(6000, 1, 2, 3)
    np.testing.assert_allclose(res["inertia_tensor"], I_com, rtol=0, atol=1e-12 * 6500)
    ref = res["reference_inertia"]
    np.testing.assert_allclose(ref["point"], [0, 0, 0], atol=0)
    np.testing.assert_allclose(ref["tensor"], parallel_axis(I_com, 6000, [0.5, 1, 1.5]),  # type: ignore[arg-type]
                               rtol=0, atol=1e-12 * 26000)
    assert res["volume"] == pytest.approx(6.0, rel=1e-15)
    assert res["density"] == RHO


def test_inverted_winding_is_corrected_with_a_warning(client: TestClient) -> None:
    good = analyze(client, "box.stl")
    bad = analyze(client, "inverted_box.stl")
    assert bad["mass"] == pytest.approx(good["mass"], rel=1e-15)
    np.testing.assert_allclose(bad["inertia_tensor"], good["inertia_tensor"], rtol=0, atol=1e-12 * 6500)
    np.testing.assert_allclose(bad["principal"]["moments"], good["principal"]["moments"], rtol=1e-14)
    assert bad["warnings"], "inverted winding must be reported in warnings"
    assert all(isinstance(w, str) and w for w in bad["warnings"])


# ----------------------------------------------------------------------------------------
# frames: generated, rotated and translated meshes
# ----------------------------------------------------------------------------------------

def rotated_box(a: float, b: float, c: float, R: Any, offset: Any) -> Any:
    v = (box_corners(a, b, c) - np.array([a, b, c]) / 2) @ R.T + np.asarray(offset, float)
    return v, BOX_FACES


def test_rotated_box_tensor_axes_and_quaternion_are_in_the_input_frame(client: TestClient) -> None:
    R = rotation([1, 2, 3], 0.7)
    v, f = rotated_box(1.0, 2.0, 3.0, R, [0.3, -0.2, 0.1])
    data = obj_bytes([(None, v, f)])
    res = analyze(client, "rotated.obj", data)
    _mass, _com, inertia, _ = exact_mass_properties(v[f])
    want = np.array([[float(x) for x in r] for r in inertia])
    np.testing.assert_allclose(res["inertia_tensor"], want, rtol=0, atol=1e-12 * 6500)
    np.testing.assert_allclose(want, R @ box_inertia(6000, 1, 2, 3) @ R.T, rtol=0, atol=1e-9)
    np.testing.assert_allclose(res["center_of_mass"], [0.3, -0.2, 0.1], atol=1e-14)
    check_principal(res)
    A = np.asarray(res["principal"]["axes"])
    # principal axes: the box's own axes, mapped by R (moments 2500: z, 5000: y, 6500: x)
    for k, body_axis in enumerate([[0, 0, 1], [0, 1, 0], [1, 0, 0]]):
        assert abs(abs(A[k] @ (R @ body_axis)) - 1) < 1e-12
    check_classification(res, "asymmetric_top")


def test_far_from_origin_rotated_box_keeps_every_moment_within_the_estimate(client: TestClient) -> None:
    """Accuracy: estimate <= 1e-12 for bodies up to 1e8 of their own sizes from the origin."""
    R = rotation([0.3, -1, 0.4], 1.1)
    v, f = rotated_box(1.0, 2.0, 3.0, R, [1e8, 5e7, -7e7])
    data = obj_bytes([(None, v, f)])
    res = analyze(client, "far.obj", data)
    _mass, com, inertia, _ = exact_mass_properties(v[f])
    est = res["diagnostics"]["relative_error_estimate"]
    assert est <= 1e-12
    for got, want in zip(res["principal"]["moments"], exact_moments(inertia)):
        assert abs(got - want) <= max(est, 2.3e-16) * want, (got, want, est)
    np.testing.assert_allclose(res["center_of_mass"], [float(x) for x in com], rtol=1e-15)


def test_far_from_origin_binary_stl_uses_its_float32_coordinates(client: TestClient) -> None:
    R = rotation([1, 1, 0], 0.4)
    v, f = rotated_box(1.0, 2.0, 3.0, R, [1e4, -2e4, 3e3])
    data = stl_bytes(v, f)
    res = analyze(client, "far32.stl", data)
    mass, _com, inertia, _ = exact_of("far32.stl", data)
    est = res["diagnostics"]["relative_error_estimate"]
    assert est <= 1e-12
    assert res["mass"] == pytest.approx(float(mass), rel=1e-13)
    for got, want in zip(res["principal"]["moments"], exact_moments(inertia)):
        assert abs(got - want) <= max(est, 2.3e-16) * want, (got, want, est)


@pytest.mark.parametrize("dims", [(1.0, 1e-6, 1e-6), (1.0, 1.0, 1e-6)], ids=["needle", "plate"])
def test_needle_and_plate_of_aspect_1e6_at_an_angle_keep_the_smallest_moment(client: TestClient, dims: Any) -> None:
    """Accuracy: estimate <= 1e-9 for the smallest moment of needles and plates of aspect
    ratio up to 1e6, at any orientation."""
    R = rotation([0.2, 0.9, -0.4], 0.83)
    v, f = rotated_box(*dims, R, [0.25, 0.5, -0.75])  # type: ignore[call-arg]
    data = obj_bytes([(None, v, f)])
    res = analyze(client, "thin.obj", data)
    _, _, inertia, _ = exact_mass_properties(v[f])
    want = exact_moments(inertia)
    est = res["diagnostics"]["relative_error_estimate"]
    assert est <= 1e-9
    for got, w in zip(res["principal"]["moments"], want):
        assert abs(got - w) <= max(est, 2.3e-16) * w, (got, w, est)


def test_same_input_gives_bit_identical_numbers(client: TestClient) -> None:
    data = (SAMPLES / "l_bracket.stl").read_bytes()
    params = dict(omega="0.3,1,-0.2", duration="3", samples="7", reference="1,2,3")
    a = strip_elapsed(analyze(client, "l_bracket.stl", data, **params))
    b = strip_elapsed(analyze(client, "l_bracket.stl", data, **params))
    assert json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


# ----------------------------------------------------------------------------------------
# options: units, density, mass, shell, tolerance, reference, format
# ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("unit", list(UNIT_SCALE))
def test_units_convert_file_lengths_to_si(client: TestClient, unit: str) -> None:
    s = UNIT_SCALE[unit]
    res = analyze(client, "box.stl", units=unit, reference="1,0,0")
    m = 6 * s ** 3 * RHO
    assert res["source"]["units"] == unit
    assert res["mass"] == pytest.approx(m, rel=1e-13)
    assert res["volume"] == pytest.approx(6 * s ** 3, rel=1e-13)
    assert res["density"] == pytest.approx(RHO, rel=1e-15)
    np.testing.assert_allclose(res["center_of_mass"], np.array([0.5, 1, 1.5]) * s, rtol=1e-14)
    I_com = box_inertia(m, s, 2 * s, 3 * s)
    np.testing.assert_allclose(res["inertia_tensor"], I_com, rtol=0, atol=1e-12 * np.trace(I_com))
    np.testing.assert_allclose(res["principal"]["moments"], sorted(I_com.diagonal()), rtol=1e-12)
    # the reference point is given in file units and reported in metres
    np.testing.assert_allclose(res["reference_inertia"]["point"], [s, 0, 0], rtol=1e-15)
    want = parallel_axis(I_com, m, np.array([0.5 - 1, 1, 1.5]) * s)
    np.testing.assert_allclose(res["reference_inertia"]["tensor"], want, rtol=0, atol=1e-12 * np.trace(want))


def test_reference_at_the_centre_of_mass_in_millimetres_gives_the_central_tensor(client: TestClient) -> None:
    res = analyze(client, "box.stl", units="mm", reference="0.5,1,1.5")
    np.testing.assert_allclose(res["reference_inertia"]["point"], [5e-4, 1e-3, 1.5e-3], rtol=1e-15)
    I = np.asarray(res["inertia_tensor"])
    np.testing.assert_allclose(res["reference_inertia"]["tensor"], I, rtol=0, atol=1e-12 * np.trace(I))


def test_density_option_scales_mass_and_inertia(client: TestClient) -> None:
    res = analyze(client, "box.stl", density=7850)
    assert res["mass"] == pytest.approx(6 * 7850, rel=1e-14)
    assert res["density"] == 7850
    np.testing.assert_allclose(res["principal"]["moments"], np.array([2500, 5000, 6500]) * 7.85, rtol=1e-13)


def test_mass_option_derives_the_density(client: TestClient) -> None:
    res = analyze(client, "box.stl", mass=12)
    assert res["mass"] == pytest.approx(12, rel=1e-14)
    assert res["density"] == pytest.approx(2.0, rel=1e-14)
    assert res["volume"] == pytest.approx(6.0, rel=1e-14)
    np.testing.assert_allclose(res["principal"]["moments"], np.array([2500, 5000, 6500]) * 12 / 6000,
                               rtol=1e-13)


def test_density_and_mass_are_exclusive(client: TestClient) -> None:
    r = post_mesh(client, "box.stl", (SAMPLES / "box.stl").read_bytes(), density=1000, mass=2)
    assert_error(r, 422, "invalid_parameter")


def thin_box_shell_inertia(a: float, b: float, c: float, sigma: float, faces: Any=("x0", "x1", "y0", "y1", "z0", "z1")) -> Any:
    """Inertia about the COM of the faces of [0,a]x[0,b]x[0,c] as laminae of areal density
    sigma (rectangle p x q: I_normal = m(p²+q²)/12, in-plane m q²/12, m p²/12)."""
    dims = np.array([a, b, c], float)
    items = []
    for face in faces:
        axis = "xyz".index(face[0])
        side = int(face[1])
        centre = dims / 2
        centre[axis] = dims[axis] * side
        u, w = [k for k in range(3) if k != axis]
        m = sigma * dims[u] * dims[w]
        I = np.zeros((3, 3))
        I[axis, axis] = m * (dims[u] ** 2 + dims[w] ** 2) / 12
        I[u, u] = m * dims[w] ** 2 / 12
        I[w, w] = m * dims[u] ** 2 / 12
        items.append((m, centre, I))
    M = sum(m for m, _, _ in items)
    com = sum(m * c for m, c, _ in items) / M
    total = sum(parallel_axis(I, m, c - com) for m, c, I in items)
    return M, com, total


def test_shell_model_integrates_a_thin_wall_of_given_thickness(client: TestClient) -> None:
    t = 1e-4  # file units (m): thin against the 1 x 2 x 3 box, so wall placement is second order
    res = analyze(client, "box.stl", model="shell", thickness=t)
    M, com, I = thin_box_shell_inertia(1, 2, 3, RHO * t)
    assert res["mass"] == pytest.approx(M, rel=1e-3)
    np.testing.assert_allclose(res["center_of_mass"], com, atol=1e-3)
    np.testing.assert_allclose(res["inertia_tensor"], I, rtol=0, atol=1e-3 * np.trace(I))
    assert "volume" not in res and "density" not in res, "volume, density: solids only"


def test_shell_thickness_is_in_file_units(client: TestClient) -> None:
    res = analyze(client, "box.stl", model="shell", thickness=0.1, units="mm")
    M, _com, I = thin_box_shell_inertia(1e-3, 2e-3, 3e-3, RHO * 1e-4)
    assert res["mass"] == pytest.approx(M, rel=1e-3)
    np.testing.assert_allclose(res["inertia_tensor"], I, rtol=0, atol=1e-3 * np.trace(I))


def test_shell_model_accepts_an_open_surface(client: TestClient) -> None:
    t = 1e-4
    res = analyze(client, "open_box.stl", model="shell", thickness=t)
    M, com, I = thin_box_shell_inertia(1, 2, 3, RHO * t, faces=("x0", "y0", "y1", "z0", "z1"))
    assert res["mass"] == pytest.approx(M, rel=1e-3)
    np.testing.assert_allclose(res["center_of_mass"], com, atol=1e-3)
    np.testing.assert_allclose(res["inertia_tensor"], I, rtol=0, atol=1e-3 * np.trace(I))


def test_shell_model_needs_a_thickness(client: TestClient) -> None:
    r = post_mesh(client, "box.stl", (SAMPLES / "box.stl").read_bytes(), model="shell")
    assert_error(r, 422, "invalid_parameter")


def test_tolerance_decides_which_moments_are_equal(client: TestClient) -> None:
    # hex_prism.stl (float32): the two large moments differ by ~1.4e-8 relative
    loose = analyze(client, "hex_prism.stl")
    check_classification(loose, "symmetric_top", "prolate")
    kappa = loose["classification"]["asymmetry"]
    assert kappa == pytest.approx(ray_kappa(loose["principal"]["moments"]), rel=1e-12)
    assert kappa != -1.0, "asymmetry is computed from the reported moments, not rounded to -1"
    assert kappa == pytest.approx(-1, abs=1e-6)
    strict = analyze(client, "hex_prism.stl", tolerance="1e-10")
    check_classification(strict, "asymmetric_top", tolerance=1e-10)


def test_planar_uses_the_tolerance(client: TestClient) -> None:
    # plate.obj 1 x 1 x 1e-3: (I1 + I2 - I3)/I3 = 1e-6 exactly
    assert analyze(client, "plate.obj", tolerance="1e-5")["classification"]["planar"] is True
    assert analyze(client, "plate.obj", tolerance="1e-7")["classification"]["planar"] is False
    assert analyze(client, "box.stl")["classification"]["planar"] is False


def test_spherical_top_has_no_asymmetry_or_shape(client: TestClient) -> None:
    res = analyze(client, "icosahedron.stl")
    check_classification(res, "spherical_top")
    assert res["principal"]["unique_axes"] is False


def test_format_parameter_overrides_the_file_name(client: TestClient) -> None:
    res = analyze(client, "blob.bin", (SAMPLES / "box.stl").read_bytes(), format="stl")
    assert res["mass"] == pytest.approx(6000, rel=1e-14)
    assert res["source"]["format"] == "stl"


def test_volume_mesh_cell_density_takes_precedence_and_mass_scales_it(client: TestClient) -> None:
    base = analyze(client, "two_density.vtu", density=5)
    assert base["mass"] == pytest.approx(9000, rel=1e-12)
    np.testing.assert_allclose(base["principal"]["moments"], [1500, 21500 / 9, 21500 / 9], rtol=1e-12)
    np.testing.assert_allclose(base["center_of_mass"], [12.5 / 9, 0.5, 0.5], rtol=1e-12)
    scaled = analyze(client, "two_density.vtu", mass=18)
    assert scaled["mass"] == pytest.approx(18, rel=1e-12)
    np.testing.assert_allclose(scaled["principal"]["moments"],
                               np.array([1500, 21500 / 9, 21500 / 9]) * 18 / 9000, rtol=1e-12)
    np.testing.assert_allclose(scaled["center_of_mass"], [12.5 / 9, 0.5, 0.5], rtol=1e-12)


def two_cube_obj() -> bytes:
    cube = box_corners(1, 1, 1)
    return obj_bytes([("left", cube, BOX_FACES), ("right", cube + np.array([2, 0, 0]), BOX_FACES)])


def test_parts_of_a_scene_with_densities_per_part(client: TestClient) -> None:
    res = analyze(client, "pair.obj", two_cube_obj(), densities=json.dumps({"left": 1000, "right": 3000}))
    parts = {p["name"]: p for p in res["parts"]}
    assert set(parts) == {"left", "right"}
    for name, m, c in (("left", 1000, [0.5, 0.5, 0.5]), ("right", 3000, [2.5, 0.5, 0.5])):
        p = parts[name]
        assert p["mass"] == pytest.approx(m, rel=1e-13)
        np.testing.assert_allclose(p["center_of_mass"], c, rtol=1e-13)
        np.testing.assert_allclose(p["inertia_tensor"], np.eye(3) * m / 6, rtol=0, atol=1e-12 * m)
    assert res["mass"] == pytest.approx(4000, rel=1e-13)
    com = np.array([2.0, 0.5, 0.5])
    np.testing.assert_allclose(res["center_of_mass"], com, rtol=1e-13)
    want = (parallel_axis(np.eye(3) * 1000 / 6, 1000, np.array([0.5, 0.5, 0.5]) - com)
            + parallel_axis(np.eye(3) * 3000 / 6, 3000, np.array([2.5, 0.5, 0.5]) - com))
    np.testing.assert_allclose(res["inertia_tensor"], want, rtol=0, atol=1e-12 * np.trace(want))
    check_principal(res)


def test_parts_without_densities_use_the_density_option(client: TestClient) -> None:
    res = analyze(client, "pair.obj", two_cube_obj(), density=2000)
    assert {p["name"] for p in res["parts"]} == {"left", "right"}
    assert res["mass"] == pytest.approx(4000, rel=1e-13)
    for p in res["parts"]:
        assert p["mass"] == pytest.approx(2000, rel=1e-13)


def test_single_body_has_no_parts(client: TestClient) -> None:
    assert "parts" not in analyze(client, "box.stl")
    assert "parts" not in analyze(client, "needle.obj")


def test_only_requested_sections_are_present(client: TestClient) -> None:
    res = analyze(client, "box.stl")
    for key in ("precession", "reference_inertia", "parts"):
        assert key not in res
    res = analyze(client, "box.stl", omega="0,1,0.1")  # no samples: no trajectory
    assert "trajectory" not in res["precession"]
    # duration without samples: API.md does not say whether this is an error; either reading
    # (no trajectory, or invalid_parameter) is accepted
    r = post_mesh(client, "box.stl", (SAMPLES / "box.stl").read_bytes(), omega="0,1,0.1", duration=2)
    if r.status_code == 200:
        assert "trajectory" not in r.json()["precession"]
    else:
        assert_error(r, 422, "invalid_parameter")
    res = analyze(client, "box.stl", omega="0,1,0.1", duration=2, samples=5)
    assert len(res["precession"]["trajectory"]["t"]) == 5


# ----------------------------------------------------------------------------------------
# errors
# ----------------------------------------------------------------------------------------

def flat_tetra_stl() -> bytes:
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float)
    f = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    return stl_bytes(v, f)


def truncated_stl() -> bytes:
    data = (SAMPLES / "box.stl").read_bytes()
    return data[:80] + struct.pack("<I", 1000) + data[84:84 + 100]


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
    ("zero samples", "box.stl", None, {"omega": "0,0,1", "duration": "1", "samples": "0"}, 422,
     "invalid_parameter"),
    ("negative duration", "box.stl", None, {"omega": "0,0,1", "duration": "-1", "samples": "3"}, 422,
     "invalid_parameter"),
    ("densities not json", "box.stl", None, {"densities": "{left: 1"}, 422, "invalid_parameter"),
    ("NaN density", "box.stl", None, {"density": "nan"}, 422, "invalid_parameter"),
    ("Inf mass", "box.stl", None, {"mass": "inf"}, 422, "invalid_parameter"),
    ("NaN tolerance", "box.stl", None, {"tolerance": "NaN"}, 422, "invalid_parameter"),
    ("NaN omega", "box.stl", None, {"omega": "nan,0,1"}, 422, "invalid_parameter"),
    ("Inf reference", "box.stl", None, {"reference": "0,0,inf"}, 422, "invalid_parameter"),
    ("-Inf duration", "box.stl", None, {"omega": "0,0,1", "duration": "-inf", "samples": "3"}, 422,
     "invalid_parameter"),
    ("Inf thickness", "box.stl", None, {"model": "shell", "thickness": "Infinity"}, 422, "invalid_parameter"),
    ("NaN in densities", "pair.obj", two_cube_obj(), {"densities": '{"left": NaN, "right": 1}'}, 422,
     "invalid_parameter"),
]


@pytest.mark.parametrize("label,filename,data,params,status,code", ERROR_CASES,
                         ids=[c[0] for c in ERROR_CASES])
def test_mesh_errors_use_the_envelope_code_and_status(client: TestClient, label: str, filename: str, data: bytes, params: dict[str, Any], status: int, code: str) -> None:
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


# ----------------------------------------------------------------------------------------
# /v1/analyze/points
# ----------------------------------------------------------------------------------------

def post_points(client: TestClient, body: dict[str, Any] | str) -> Any:
    if isinstance(body, str):
        return client.post("/v1/analyze/points", content=body, headers={"content-type": "application/json"})
    return client.post("/v1/analyze/points", json=body)


def points_ok(client: TestClient, body: Any) -> dict[str, Any]:
    r = post_points(client, body)
    assert r.status_code == 200, r.text
    res = r.json()
    assert_no_nulls(res)
    return cast("dict[str, Any]", res)


TRIATOMIC = json.loads((SAMPLES / "triatomic.json").read_text())


def test_triatomic_molecule_moments_match_closed_form(client: TestClient) -> None:
    res = points_ok(client, TRIATOMIC)
    m1, m2, a, h = 1.0, 16.0, 2.0, 1.0  # L&L §32 problem: isosceles triatomic molecule
    mu = 2 * m1 + m2
    I1, I2 = 2 * m1 * m2 * h * h / mu, m1 * a * a / 2
    assert res["mass"] == pytest.approx(mu, rel=1e-15)
    np.testing.assert_allclose(res["center_of_mass"], [0, m2 * h / mu, 0], atol=1e-15)
    np.testing.assert_allclose(res["principal"]["moments"], sorted([I1, I2, I1 + I2]), rtol=1e-14)
    check_principal(res)
    check_classification(res, "asymmetric_top", planar=True)
    A = np.asarray(res["principal"]["axes"])
    assert abs(abs(A[2] @ [0, 0, 1]) - 1) < 1e-12  # I3 normal to the molecule's plane
    assert abs(abs(A[0] @ [1, 0, 0]) - 1) < 1e-12  # I1 = 2 m1 m2 h²/μ: about x, across the height
    assert abs(abs(A[1] @ [0, 1, 0]) - 1) < 1e-12  # I2 = m1 a²/2: about the symmetry axis y
    assert "volume" not in res and "density" not in res
    assert "parts" not in res and "precession" not in res and "reference_inertia" not in res


def test_points_units_tolerance_and_reference(client: TestClient) -> None:
    body = {**TRIATOMIC, "units": "mm", "tolerance": 1e-8, "reference": [0, 1000, 0]}
    res = points_ok(client, body)
    s = 1e-3
    mu = 18.0
    I = np.diag([2 * 16 * 1 / mu + 0.0, 0, 0])  # placeholder, rebuilt below
    pos = np.array([p["position"] for p in TRIATOMIC["points"]], float) * s
    ms = np.array([p["mass"] for p in TRIATOMIC["points"]], float)
    com = ms @ pos / ms.sum()
    I = sum(m * ((r - com) @ (r - com) * np.eye(3) - np.outer(r - com, r - com)) for m, r in zip(ms, pos))
    np.testing.assert_allclose(res["center_of_mass"], com, rtol=1e-14, atol=1e-18)
    np.testing.assert_allclose(res["inertia_tensor"], I, rtol=0, atol=1e-14 * np.trace(I))
    np.testing.assert_allclose(res["reference_inertia"]["point"], [0, 1.0, 0], rtol=1e-15)
    np.testing.assert_allclose(res["reference_inertia"]["tensor"], parallel_axis(I, mu, com - [0, 1.0, 0]),
                               rtol=0, atol=1e-14 * np.trace(I))
    assert res["classification"]["tolerance"] == 1e-8


def test_two_point_masses_are_a_linear_rotator(client: TestClient) -> None:
    res = points_ok(client, {"points": [{"mass": 1.0, "position": [0, 0, 0]},
                                        {"mass": 2.0, "position": [1, 0, 0]}]})
    I = 1 * 2 * 1 ** 2 / 3  # m1 m2 l² / (m1 + m2)
    moments = res["principal"]["moments"]
    assert abs(moments[0]) <= 1e-15 * I
    np.testing.assert_allclose(moments[1:], [I, I], rtol=1e-14)
    check_principal(res)
    check_classification(res, "linear_rotator", planar=True)
    assert abs(abs(res["classification"]["symmetry_axis"][0]) - 1) < 1e-14
    np.testing.assert_allclose(res["center_of_mass"], [2 / 3, 0, 0], rtol=1e-15)


def test_single_point_mass_is_accepted(client: TestClient) -> None:
    res = points_ok(client, {"points": [{"mass": 2.5, "position": [1, 2, 3]}]})
    assert res["mass"] == 2.5
    np.testing.assert_allclose(res["center_of_mass"], [1, 2, 3])
    np.testing.assert_allclose(res["inertia_tensor"], np.zeros((3, 3)), atol=0)


POINTS_ERRORS = [
    ("no points", {"points": []}),
    ("missing points", {"units": "m"}),
    ("zero mass", {"points": [{"mass": 0.0, "position": [0, 0, 0]}]}),
    ("negative mass", {"points": [{"mass": -1.0, "position": [0, 0, 0]}, {"mass": 1, "position": [1, 0, 0]}]}),
    ("position of two numbers", {"points": [{"mass": 1.0, "position": [0, 0]}]}),
    ("unknown unit", {"points": [{"mass": 1.0, "position": [0, 0, 0]}], "units": "parsec"}),
    ("bad method", {"points": TRIATOMIC["points"], "omega": [0, 0, 1], "method": "magic"}),
    ("not json", "{points: ["),
    ("NaN position", '{"points": [{"mass": 1.0, "position": [NaN, 0, 0]}]}'),
    ("Infinity mass", '{"points": [{"mass": Infinity, "position": [0, 0, 0]}]}'),
    ("overflowing literal", '{"points": [{"mass": 1e999, "position": [0, 0, 0]}]}'),
    ("-Infinity omega", '{"points": [{"mass": 1, "position": [0, 0, 0]}, {"mass": 1, "position": [1, 1, 0]}],'
                        ' "omega": [0, -Infinity, 0]}'),
    ("NaN tolerance", '{"points": [{"mass": 1, "position": [0, 0, 0]}], "tolerance": NaN}'),
    ("NaN reference", '{"points": [{"mass": 1, "position": [0, 0, 0]}], "reference": [0, NaN, 0]}'),
]


@pytest.mark.parametrize("label,body", POINTS_ERRORS, ids=[c[0] for c in POINTS_ERRORS])
def test_points_errors_are_invalid_parameter(client: TestClient, label: str, body: Any) -> None:
    assert_error(post_points(client, body), 422, "invalid_parameter")


# ----------------------------------------------------------------------------------------
# /v1/precession
# ----------------------------------------------------------------------------------------

def post_precession(client: TestClient, body: Any) -> Any:
    if isinstance(body, str):
        return client.post("/v1/precession", content=body, headers={"content-type": "application/json"})
    return client.post("/v1/precession", json=body)


def precession_ok(client: TestClient, body: Any) -> dict[str, Any]:
    r = post_precession(client, body)
    assert r.status_code == 200, r.text
    res = r.json()
    assert_no_nulls(res)
    assert {"principal", "classification", "precession", "diagnostics"} <= set(res) <= {
        "principal", "classification", "precession", "diagnostics", "warnings"}, set(res)
    return cast("dict[str, Any]", res)


def check_invariants(pre: dict[str, Any], I_input: np.ndarray, omega0: Any) -> None:
    w = np.asarray(omega0, float)
    M = I_input @ w
    scale = np.linalg.norm(M) + 1e-300
    np.testing.assert_allclose(pre["angular_momentum"], M, rtol=0, atol=1e-13 * scale)  # type: ignore[call-overload]
    assert pre["angular_momentum_magnitude"] == pytest.approx(np.linalg.norm(M), rel=1e-13, abs=1e-300)
    assert pre["kinetic_energy"] == pytest.approx(0.5 * w @ I_input @ w, rel=1e-13, abs=1e-300)


def check_symmetric_rates(pre: dict[str, Any], I_perp: float, I_sym: float, n: Any, omega0: Any) -> None:
    """L&L §33: ω = Ω3(I3 − I1)/I1, |M|/I1, ψ̇ = |M| cos θ (1/I3 − 1/I1), cos θ = I3 Ω3/|M|."""
    W3 = float(np.asarray(n, float) @ np.asarray(omega0, float))
    W = np.asarray(omega0, float)
    W_perp2 = W @ W - W3 * W3
    M = math.sqrt((I_sym * W3) ** 2 + I_perp ** 2 * W_perp2)
    body = W3 * (I_sym - I_perp) / I_perp
    cos_theta = I_sym * W3 / M
    assert pre["regime"] == "regular_precession"
    assert pre["body_precession_rate"] == pytest.approx(body, rel=1e-12)
    assert pre["space_precession_rate"] == pytest.approx(M / I_perp, rel=1e-12)
    assert pre["spin_rate"] == pytest.approx(M * cos_theta * (1 / I_sym - 1 / I_perp), rel=1e-12)
    assert pre["nutation_angle"] == pytest.approx(math.acos(cos_theta), rel=1e-12)
    assert pre["period"] == pytest.approx(2 * math.pi / abs(body), rel=1e-12)


def check_trajectory(pre: dict[str, Any], moments: Any, axes: Any, omega0: Any, duration: float, samples: int, I_input: Any, tol: float=1e-8) -> None:
    tr = pre["trajectory"]
    t = np.asarray(tr["t"], float)
    assert len(t) == samples
    np.testing.assert_allclose(t, np.linspace(0, duration, samples), rtol=1e-14, atol=1e-14 * duration)
    assert t[0] == 0 and t[-1] == pytest.approx(duration, rel=1e-15)
    W = np.asarray(tr["omega_body"], float)
    w = np.asarray(tr["omega"], float)
    Q = np.asarray(tr["quaternion"], float)
    assert W.shape == (samples, 3) and w.shape == (samples, 3) and Q.shape == (samples, 4)
    np.testing.assert_allclose(np.linalg.norm(Q, axis=1), 1, atol=1e-12)
    np.testing.assert_allclose(quat_matrix(Q[0]), np.eye(3), atol=1e-14)
    A = np.asarray(axes, float)
    np.testing.assert_allclose(W[0], pre["omega_body"], rtol=0, atol=1e-13 * np.linalg.norm(omega0))  # type: ignore[call-overload]
    np.testing.assert_allclose(w[0], omega0, rtol=0, atol=1e-13 * np.linalg.norm(omega0))  # type: ignore[call-overload]
    M0 = I_input @ np.asarray(omega0, float)
    wscale = np.linalg.norm(omega0)
    for k in range(samples):
        R = quat_matrix(Q[k])
        # omega(t) in the fixed input frame is the rotated body omega
        np.testing.assert_allclose(w[k], R @ A.T @ W[k], rtol=0, atol=max(tol, 1e-12) * wscale)  # type: ignore[call-overload]
        # M stays constant in the fixed frame: I(t) = R I0 Rᵀ
        np.testing.assert_allclose(R @ I_input @ R.T @ w[k], M0, rtol=0,  # type: ignore[call-overload]
                                   atol=max(tol, 1e-12) * np.linalg.norm(M0) + 1e-300)
    if moments[0] > 0:
        Wr, wr, Rr = reference_motion(moments, A, omega0, t)
        np.testing.assert_allclose(W, Wr, rtol=0, atol=tol * wscale)  # type: ignore[call-overload]
        np.testing.assert_allclose(w, wr, rtol=0, atol=tol * wscale)  # type: ignore[call-overload]
        for k in range(samples):
            np.testing.assert_allclose(quat_matrix(Q[k]), Rr[k], rtol=0, atol=tol)
    d = pre["diagnostics"]
    for key in ("energy_drift", "momentum_drift"):
        assert d[key] >= 0 and math.isfinite(d[key])


def test_precession_from_principal_moments_asymmetric_intermediate_start(client: TestClient) -> None:
    moments, omega = [1.0, 2.0, 3.0], [0.1, 1.0, 0.05]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": 10, "samples": 41})
    np.testing.assert_allclose(res["principal"]["moments"], moments, rtol=1e-15)
    # the input frame is the principal frame
    np.testing.assert_allclose(np.abs(res["principal"]["axes"]), np.eye(3), atol=1e-15)
    check_principal(res, np.diag(moments))
    check_classification(res, "asymmetric_top", planar=True)  # 1 + 2 = 3
    pre = res["precession"]
    assert pre["regime"] == "asymmetric"
    check_invariants(pre, np.diag(moments), omega)
    A = np.asarray(res["principal"]["axes"])
    np.testing.assert_allclose(pre["omega_body"], A @ omega, atol=1e-15)
    T = ll_asymmetric_period(moments, omega)
    assert pre["period"] == pytest.approx(T, rel=1e-10)
    assert pre["stable"] is False
    assert pre["flip_interval"] == pytest.approx(T / 2, rel=1e-10)
    check_trajectory(pre, moments, A, omega, 10.0, 41, np.diag(moments))


@pytest.mark.parametrize("omega,branch", [([0.05, 0.3, 1.0], "near I3"), ([1.0, 0.3, 0.05], "near I1")])
def test_asymmetric_period_both_branches_and_stable_starts(client: TestClient, omega: Any, branch: str) -> None:
    moments = [1.0, 2.0, 3.0]
    pre = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": 6,
                                 "samples": 13})["precession"]
    assert pre["regime"] == "asymmetric"
    T = ll_asymmetric_period(moments, omega)
    assert pre["period"] == pytest.approx(T, rel=1e-10)
    assert pre["stable"] is True
    assert "flip_interval" not in pre
    check_trajectory(pre, moments, np.eye(3), omega, 6.0, 13, np.diag(moments))


def test_asymmetric_motion_returns_to_its_start_after_one_period(client: TestClient) -> None:
    moments, omega = [1.0, 2.0, 3.0], [0.2, 0.7, 0.4]
    T = ll_asymmetric_period(moments, omega)
    pre = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": T,
                                 "samples": 5})["precession"]
    W = np.asarray(pre["trajectory"]["omega_body"])
    np.testing.assert_allclose(W[-1], W[0], atol=1e-9)
    assert not np.allclose(W[2], W[0], atol=1e-3)  # but not after half of it


def test_separatrix_has_no_period_and_a_warning(client: TestClient) -> None:
    # 2E I2 = |M|²  <=>  I1(I1 − I2) Ω1² + I3(I3 − I2) Ω3² = 0; here Ω1 = √3 Ω3
    moments = [1.0, 2.0, 3.0]
    omega = [0.1 * math.sqrt(3), 1.0, 0.1]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega})
    pre = res["precession"]
    assert pre["regime"] == "asymmetric"
    assert "period" not in pre
    assert "flip_interval" not in pre
    warnings_ = list(res.get("warnings", [])) + list(pre.get("warnings", []))
    assert warnings_, "a warning must say why the period is absent"
    check_invariants(pre, np.diag(moments), omega)


def test_precession_from_a_rotated_inertia_tensor(client: TestClient) -> None:
    R = rotation([1, -1, 2], 0.9)
    moments = np.array([1.0, 2.0, 3.0])
    I = R @ np.diag(moments) @ R.T
    I = (I + I.T) / 2
    omega = [0.4, -0.3, 0.9]
    res = precession_ok(client, {"inertia_tensor": I.tolist(), "omega": omega, "duration": 5, "samples": 11,
                                 "tolerance": 1e-9})
    check_principal(res, I)
    check_classification(res, "asymmetric_top", tolerance=1e-9)
    np.testing.assert_allclose(res["principal"]["moments"], moments, rtol=1e-13)
    pre = res["precession"]
    check_invariants(pre, I, omega)
    A = np.asarray(res["principal"]["axes"])
    np.testing.assert_allclose(pre["omega_body"], A @ omega, atol=1e-13)
    Wb = R.T @ omega
    assert pre["period"] == pytest.approx(ll_asymmetric_period(moments, Wb), rel=1e-9)
    check_trajectory(pre, moments, A, omega, 5.0, 11, I)


@pytest.mark.parametrize("moments,shape", [([2.0, 2.0, 3.0], "oblate"), ([1.0, 3.0, 3.0], "prolate")])
def test_symmetric_top_rates_follow_landau_lifshitz(client: TestClient, moments: Any, shape: str | None) -> None:
    omega = [0.3, -0.4, 1.2]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": 4, "samples": 9})
    check_classification(res, "symmetric_top", shape)
    n = np.asarray(res["classification"]["symmetry_axis"], float)
    unique = 2 if shape == "oblate" else 0
    assert abs(abs(n[unique]) - 1) < 1e-15
    I_sym, I_perp = moments[unique], moments[1]
    pre = res["precession"]
    check_invariants(pre, np.diag(moments), omega)
    check_symmetric_rates(pre, I_perp, I_sym, n, omega)
    check_trajectory(pre, moments, res["principal"]["axes"], omega, 4.0, 9, np.diag(moments))


def test_symmetric_top_in_a_rotated_frame(client: TestClient) -> None:
    R = rotation([2, 1, -1], 1.3)
    I = R @ np.diag([1.5, 1.5, 2.5]) @ R.T
    I = (I + I.T) / 2
    omega = [1.0, 0.2, -0.5]
    res = precession_ok(client, {"inertia_tensor": I.tolist(), "omega": omega, "duration": 3, "samples": 7})
    check_classification(res, "symmetric_top", "oblate")
    n = np.asarray(res["classification"]["symmetry_axis"], float)
    assert abs(abs(n @ (R @ [0, 0, 1])) - 1) < 1e-12
    pre = res["precession"]
    check_invariants(pre, I, omega)
    check_symmetric_rates(pre, 1.5, 2.5, n, omega)
    check_trajectory(pre, [1.5, 1.5, 2.5], res["principal"]["axes"], omega, 3.0, 7, I)


def test_symmetric_mesh_regular_precession_in_the_input_frame(client: TestClient) -> None:
    # tetrahedron.stl: oblate, symmetry axis (1,1,1)/√3, I⊥ = 125/12, I3 = 50/3
    omega = [0.5, -0.2, 0.1]
    res = analyze(client, "tetrahedron.stl", omega=",".join(map(str, omega)), duration=5, samples=6)
    I = np.asarray(res["inertia_tensor"], float)
    n = np.asarray(res["classification"]["symmetry_axis"], float)
    assert abs(abs(n @ np.ones(3) / math.sqrt(3)) - 1) < 1e-12
    pre = res["precession"]
    check_invariants(pre, I, omega)
    I_perp = res["principal"]["moments"][0]
    I_sym = res["principal"]["moments"][2]
    assert I_perp == pytest.approx(125 / 12, rel=1e-12) and I_sym == pytest.approx(50 / 3, rel=1e-12)
    check_symmetric_rates(pre, I_perp, I_sym, n, omega)
    check_trajectory(pre, res["principal"]["moments"], res["principal"]["axes"], omega, 5.0, 6, I)


def test_asymmetric_mesh_precession_in_the_input_frame(client: TestClient) -> None:
    omega = [0.1, 2.0, 0.1]
    res = analyze(client, "box.stl", omega="0.1,2,0.1", duration=10, samples=21)
    pre = res["precession"]
    I = box_inertia(6000, 1, 2, 3)
    check_invariants(pre, I, omega)
    assert pre["regime"] == "asymmetric"
    # principal axes are ±z, ±y, ±x: the period depends only on the squares of Ω
    T = ll_asymmetric_period([2500, 5000, 6500], [0.1, 2.0, 0.1])
    assert pre["period"] == pytest.approx(T, rel=1e-10)
    assert pre["stable"] is False
    assert pre["flip_interval"] == pytest.approx(T / 2, rel=1e-10)
    check_trajectory(pre, [2500, 5000, 6500], res["principal"]["axes"], omega, 10.0, 21, I)


def test_flip_interval_is_the_time_between_reversals_of_omega2(client: TestClient) -> None:
    moments, omega = [1.0, 2.0, 3.0], [0.05, 1.0, 0.02]
    pre = precession_ok(client, {"principal_moments": moments, "omega": omega})["precession"]
    # independent: zero crossings of Ω2 in a reference integration
    T = ll_asymmetric_period(moments, omega)
    t = np.linspace(0, 2.2 * T, 4001)
    W, _, _ = reference_motion(moments, np.eye(3), omega, t)
    s = W[:, 1]
    idx = np.nonzero(np.sign(s[1:]) != np.sign(s[:-1]))[0]
    crossings = [t[i] - s[i] * (t[i + 1] - t[i]) / (s[i + 1] - s[i]) for i in idx]
    gaps = np.diff(crossings)
    assert len(gaps) >= 2
    np.testing.assert_allclose(gaps, pre["flip_interval"], rtol=1e-4)


@pytest.mark.parametrize("method", ["dop853", "rk45", "splitting"])
def test_numerical_methods_follow_the_same_motion(client: TestClient, method: str) -> None:
    moments, omega = [1.0, 2.0, 3.0], [0.3, 0.8, 0.5]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": 3, "samples": 7,
                                 "method": method})
    pre = res["precession"]
    assert pre["regime"] == "asymmetric"
    check_invariants(pre, np.diag(moments), omega)
    # the contract states no accuracy for the integrators: a loose 1e-4 is asked
    check_trajectory(pre, moments, res["principal"]["axes"], omega, 3.0, 7, np.diag(moments), tol=1e-4)


def test_rest(client: TestClient) -> None:
    res = precession_ok(client, {"principal_moments": [1, 2, 3], "omega": [0, 0, 0], "duration": 1,
                                 "samples": 3})
    pre = res["precession"]
    assert pre["regime"] == "rest"
    assert pre["angular_momentum_magnitude"] == 0 and pre["kinetic_energy"] == 0
    np.testing.assert_allclose(pre["angular_momentum"], [0, 0, 0], atol=0)
    for q in pre["trajectory"]["quaternion"]:
        np.testing.assert_allclose(quat_matrix(q), np.eye(3), atol=1e-15)
    np.testing.assert_allclose(pre["trajectory"]["omega"], np.zeros((3, 3)), atol=0)


@pytest.mark.parametrize("axis,stable", [(0, True), (1, False), (2, True)])
def test_permanent_rotation_about_a_principal_axis(client: TestClient, axis: Any, stable: bool) -> None:
    omega = [0.0, 0.0, 0.0]
    omega[axis] = 1.5
    # box.stl: x has the largest moment (6500), y the intermediate, z the smallest
    res = analyze(client, "box.stl", omega=",".join(map(str, omega)), duration=2, samples=5)
    pre = res["precession"]
    assert pre["regime"] == "permanent_rotation"
    I = box_inertia(6000, 1, 2, 3)
    check_invariants(pre, I, omega)
    if "stable" in pre:
        assert pre["stable"] is stable
    for t, q, w in zip(pre["trajectory"]["t"], pre["trajectory"]["quaternion"], pre["trajectory"]["omega"]):
        np.testing.assert_allclose(quat_matrix(q), rotation(omega, 1.5 * t), atol=1e-12)
        np.testing.assert_allclose(w, omega, atol=1e-12)


def test_spherical_top_keeps_omega_constant(client: TestClient) -> None:
    omega = [0.3, -0.2, 0.5]
    res = analyze(client, "icosahedron.stl", omega="0.3,-0.2,0.5", duration=4, samples=5)
    pre = res["precession"]
    assert pre["regime"] == "spherical"
    I0 = ICO_MASS * PHI ** 2 / 10  # ideal icosahedron; the float32 file is 4e-8 away
    np.testing.assert_allclose(res["inertia_tensor"], np.eye(3) * I0, rtol=0, atol=1e-7 * I0)
    check_invariants(pre, np.asarray(res["inertia_tensor"]), omega)
    w = np.linalg.norm(omega)
    for t, q, om, Wb in zip(*(pre["trajectory"][k] for k in ("t", "quaternion", "omega", "omega_body"))):
        np.testing.assert_allclose(om, omega, atol=1e-12)
        np.testing.assert_allclose(Wb, pre["omega_body"], atol=1e-12)
        np.testing.assert_allclose(quat_matrix(q), rotation(omega, w * t), atol=1e-12)


def test_linear_rotator_precession(client: TestClient) -> None:
    body = {"points": [{"mass": 1.0, "position": [0, 0, 0]}, {"mass": 2.0, "position": [1, 0, 0]}],
            "omega": [0, 0, 2.0], "duration": 3.0, "samples": 4}
    res = points_ok(client, body)
    pre = res["precession"]
    assert pre["regime"] == "rotator"
    I = 2 / 3
    np.testing.assert_allclose(pre["angular_momentum"], [0, 0, 2 * I], atol=1e-14)
    assert pre["angular_momentum_magnitude"] == pytest.approx(2 * I, rel=1e-14)
    assert pre["kinetic_energy"] == pytest.approx(0.5 * I * 4, rel=1e-14)
    tr = pre["trajectory"]
    np.testing.assert_allclose(tr["t"], [0, 1, 2, 3], atol=1e-15)
    for t, q, w in zip(tr["t"], tr["quaternion"], tr["omega"]):
        np.testing.assert_allclose(quat_matrix(q), rotation([0, 0, 1], 2 * t), atol=1e-12)
        np.testing.assert_allclose(w, [0, 0, 2], atol=1e-12)


def test_points_precession_matches_the_mesh_contract(client: TestClient) -> None:
    body = {**TRIATOMIC, "omega": [0.2, 1.0, 0.3], "duration": 2.0, "samples": 5}
    res = points_ok(client, body)
    pre = res["precession"]
    I = np.asarray(res["inertia_tensor"], float)
    check_invariants(pre, I, body["omega"])
    check_trajectory(pre, res["principal"]["moments"], res["principal"]["axes"], body["omega"], 2.0, 5, I)


PRECESSION_ERRORS = [
    ("no omega", {"principal_moments": [1, 2, 3]}),
    ("no inertia", {"omega": [0, 0, 1]}),
    ("both inertia forms", {"principal_moments": [1, 2, 3], "inertia_tensor": np.eye(3).tolist(),
                            "omega": [0, 0, 1]}),
    ("tensor not 3x3", {"inertia_tensor": [[1, 0], [0, 1]], "omega": [0, 0, 1]}),
    ("omega of two numbers", {"principal_moments": [1, 2, 3], "omega": [0, 1]}),
    ("unknown method", {"principal_moments": [1, 2, 3], "omega": [0, 0, 1], "method": "leapfrog"}),
    ("negative moment", {"principal_moments": [-1, 2, 3], "omega": [0, 0, 1]}),
    ("NaN moment", '{"principal_moments": [NaN, 2, 3], "omega": [0, 0, 1]}'),
    ("Infinity in tensor", '{"inertia_tensor": [[Infinity,0,0],[0,1,0],[0,0,1]], "omega": [0, 0, 1]}'),
    ("NaN omega", '{"principal_moments": [1, 2, 3], "omega": [0, NaN, 1]}'),
    ("Inf duration", '{"principal_moments": [1, 2, 3], "omega": [0, 0, 1], "duration": Infinity, '
                     '"samples": 3}'),
    ("1e999 omega", '{"principal_moments": [1, 2, 3], "omega": [0, 1e999, 1]}'),
]


@pytest.mark.parametrize("label,body", PRECESSION_ERRORS, ids=[c[0] for c in PRECESSION_ERRORS])
def test_precession_errors_are_invalid_parameter(client: TestClient, label: str, body: Any) -> None:
    assert_error(post_precession(client, body), 422, "invalid_parameter")


# ----------------------------------------------------------------------------------------
# /v1/batch
# ----------------------------------------------------------------------------------------

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
    assert lines[0]["mass"] == pytest.approx(12000, rel=1e-14)
    check_batch_lines(client, lines, {"density": "2000", "reference": "0,0,0"})


def test_batch_accepts_one_zip_of_files(client: TestClient) -> None:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for name in BATCH_FILES:
            z.writestr(name, (SAMPLES / name).read_bytes())
    params = {"units": "mm", "omega": "0.1,2,0.1", "duration": "2", "samples": "3"}
    r = client.post("/v1/batch", files=[("files", ("meshes.zip", buf.getvalue(), "application/zip"))],
                    params=params)
    lines = ndjson_lines(r)
    assert len(lines) == 4
    assert lines[0]["mass"] == pytest.approx(6e-6, rel=1e-13)
    assert len(lines[0]["precession"]["trajectory"]["t"]) == 3
    check_batch_lines(client, lines, params)


def test_batch_unsupported_and_unreadable_files_are_error_lines(client: TestClient) -> None:
    files = [("files", ("a.xyz123", b"nothing", "application/octet-stream")),
             ("files", ("b.stl", truncated_stl(), "application/octet-stream")),
             ("files", ("c.stl", (SAMPLES / "box.stl").read_bytes(), "application/octet-stream"))]
    lines = ndjson_lines(client.post("/v1/batch", files=files))
    assert [line["source"]["filename"] for line in lines] == ["a.xyz123", "b.stl", "c.stl"]
    assert lines[0]["error"]["code"] == "unsupported_format"
    assert lines[1]["error"]["code"] == "unreadable_file"
    assert lines[2]["mass"] == pytest.approx(6000, rel=1e-14)


def test_batch_with_an_invalid_parameter_is_rejected_with_the_envelope(client: TestClient) -> None:
    files = [("files", ("box.stl", (SAMPLES / "box.stl").read_bytes(), "application/octet-stream"))]
    assert_error(client.post("/v1/batch", files=files, params={"units": "parsec"}), 422, "invalid_parameter")


# ----------------------------------------------------------------------------------------
# configuration through the environment
# ----------------------------------------------------------------------------------------

BIG_STL = stl_bytes(np.random.default_rng(0).normal(size=(3000, 3)),
                    np.arange(3000).reshape(1000, 3))  # 50 kB


def test_upload_larger_than_the_limit_is_413() -> None:
    with configured_client(INERTIA_MAX_UPLOAD_BYTES="10000", INERTIA_COMPUTE_PROCESSES="1") as c:
        err = assert_error(post_mesh(c, "big.stl", BIG_STL), 413, "payload_too_large")
        assert err["message"]
        files = [("files", ("big.stl", BIG_STL, "application/octet-stream"))]
        assert_error(c.post("/v1/batch", files=files), 413, "payload_too_large")
        ok = post_mesh(c, "box.stl", (SAMPLES / "box.stl").read_bytes())
        assert ok.status_code == 200, ok.text


def test_compute_past_the_time_limit_is_503_timeout() -> None:
    with configured_client(INERTIA_TIMEOUT_S="0.05", INERTIA_COMPUTE_PROCESSES="1") as c:
        r = post_mesh(c, "box.stl", (SAMPLES / "box.stl").read_bytes(),
                      omega="0.1,2,0.1", duration="3000", samples="10", method="rk45")
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
        assert_error(c.post("/v1/precession", json={"principal_moments": [1, 2, 3], "omega": [0, 0, 1]}),
                     401, "unauthorized")
        assert_error(c.post("/v1/analyze/points", json=TRIATOMIC), 401, "unauthorized")
        files = [("files", ("box.stl", (SAMPLES / "box.stl").read_bytes(), "application/octet-stream"))]
        assert_error(c.post("/v1/batch", files=files), 401, "unauthorized")
        key = {"X-API-Key": "s3cret"}
        assert c.get("/v1/formats", headers=key).status_code == 200
        r = c.post("/v1/analyze/mesh", files={"file": ("box.stl", (SAMPLES / "box.stl").read_bytes())},
                   headers=key)
        assert r.status_code == 200 and r.json()["mass"] == pytest.approx(6000, rel=1e-14)


# ----------------------------------------------------------------------------------------
# command line
# ----------------------------------------------------------------------------------------

def run_cli(*args: str, cwd: Path = SAMPLES) -> subprocess.CompletedProcess:  # type: ignore[type-arg]
    env = {k: v for k, v in os.environ.items() if not k.startswith("INERTIA_")}
    return subprocess.run([sys.executable, "-m", "inertia", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=60)


def test_cli_json_equals_the_http_response(client: TestClient) -> None:
    opts = {"units": "mm", "density": "7850", "reference": "0,0,0", "omega": "0.1,2,0.1",
            "duration": "1", "samples": "3", "tolerance": "1e-8"}
    args = ["analyze", "box.stl", "--json"]
    for k, v in opts.items():
        args += [f"--{k}", v]
    p = run_cli(*args)
    assert p.returncode == 0, p.stderr
    cli = json.loads(p.stdout)
    http = analyze(client, "box.stl", **opts)  # type: ignore[arg-type]
    assert strip_elapsed(cli) == strip_elapsed(http)


def test_cli_table_output_is_readable(client: TestClient) -> None:
    p = run_cli("analyze", "l_bracket.stl")
    assert p.returncode == 0, p.stderr
    out = p.stdout
    assert out.strip()
    with pytest.raises(json.JSONDecodeError):
        json.loads(out)
    assert "12000" in out.replace(",", "").replace(" ", "") or "1.2e+04" in out
    assert "asymmetric" in out


def test_cli_errors_go_to_stderr_with_non_zero_exit() -> None:
    p = run_cli("analyze", "open_box.stl", "--json")
    assert p.returncode != 0
    assert not p.stdout.strip()
    try:
        env = json.loads(p.stderr)
    except json.JSONDecodeError:
        env = json.loads(next(x for x in reversed(p.stderr.splitlines()) if x.startswith("{")))
    assert env["error"]["code"] == "not_watertight" and env["error"]["message"]
    p = run_cli("analyze", "box.stl", "--units", "parsec")
    assert p.returncode != 0 and "invalid_parameter" in p.stderr


def test_cli_batch_writes_one_line_per_file_and_resumes(tmp_path: Path) -> None:
    folder = tmp_path / "in"
    (folder / "sub").mkdir(parents=True)
    (folder / "box.stl").write_bytes((SAMPLES / "box.stl").read_bytes())
    (folder / "sub" / "open_box.stl").write_bytes((SAMPLES / "open_box.stl").read_bytes())
    (folder / "notes.txt").write_text("not a mesh: files of unknown extensions are not read")
    out = tmp_path / "results.jsonl"
    p = run_cli("batch", str(folder), "--out", str(out), cwd=tmp_path)
    assert p.returncode in (0, 1, 2, 3, 4), p.stderr
    lines = [json.loads(x) for x in out.read_text().splitlines() if x.strip()]
    assert len(lines) == 2
    by_name = {Path(line["source"]["filename"]).name: line for line in lines}
    assert by_name["box.stl"]["mass"] == pytest.approx(6000, rel=1e-14)
    assert by_name["open_box.stl"]["error"]["code"] == "not_watertight"
    (folder / "tetrahedron.stl").write_bytes((SAMPLES / "tetrahedron.stl").read_bytes())
    p = run_cli("batch", str(folder), "--out", str(out), "--resume", cwd=tmp_path)
    lines = [json.loads(x) for x in out.read_text().splitlines() if x.strip()]
    assert len(lines) == 3, "resume analyses only the new file, error lines included as done"
    names = [Path(line["source"]["filename"]).name for line in lines]
    assert sorted(names) == ["box.stl", "open_box.stl", "tetrahedron.stl"]


# ----------------------------------------------------------------------------------------
# more formats, scenes and volume meshes
# ----------------------------------------------------------------------------------------

def ply_ascii(v: np.ndarray, f: np.ndarray) -> bytes:
    head = ["ply", "format ascii 1.0", f"element vertex {len(v)}", "property double x",
            "property double y", "property double z", f"element face {len(f)}",
            "property list uchar int vertex_indices", "end_header"]
    body = [" ".join(repr(float(x)) for x in p) for p in v] + ["3 " + " ".join(map(str, t)) for t in f]
    return ("\n".join(head + body) + "\n").encode()


def off_ascii(v: np.ndarray, f: np.ndarray) -> bytes:
    lines = ["OFF", f"{len(v)} {len(f)} 0"] + [" ".join(repr(float(x)) for x in p) for p in v]
    lines += ["3 " + " ".join(map(str, t)) for t in f]
    return ("\n".join(lines) + "\n").encode()


@pytest.mark.parametrize("fmt", ["ply", "off", "obj", "stl"])
def test_surface_formats_give_the_same_box(client: TestClient, fmt: str) -> None:
    v = box_corners(1, 2, 3) + np.array([1, -1, 2])
    writer = {"ply": ply_ascii, "off": off_ascii, "obj": lambda a, b: obj_bytes([(None, a, b)]),
              "stl": stl_bytes}[fmt]
    res = analyze(client, f"box.{fmt}", writer(v, BOX_FACES))  # type: ignore[no-untyped-call]
    assert res["source"]["format"] == fmt
    assert res["mass"] == pytest.approx(6000, rel=1e-14)
    np.testing.assert_allclose(res["center_of_mass"], [1.5, 0, 3.5], rtol=0, atol=1e-14 * 4)
    np.testing.assert_allclose(res["inertia_tensor"], box_inertia(6000, 1, 2, 3), rtol=0, atol=1e-12 * 6500)
    check_classification(res, "asymmetric_top")


def two_box_scene() -> Any:
    import trimesh  # a writer only: the expected values below are closed formulas

    tf = trimesh.transformations
    scene = trimesh.Scene()
    scene.add_geometry(trimesh.creation.box([1, 2, 3]), node_name="alpha", geom_name="g_alpha",
                       transform=tf.translation_matrix([5, 0, 0]))
    rot = tf.rotation_matrix(0.5, [1, 0, 0])
    scene.add_geometry(trimesh.creation.box([1, 1, 2]), node_name="beta", geom_name="g_beta",
                       transform=tf.concatenate_matrices(tf.translation_matrix([0, 4, 0]), rot))
    return scene, rot[:3, :3]


def check_two_box_scene(res: dict[str, Any], s: float = 1.0) -> None:
    R = rotation([1, 0, 0], 0.5)
    ma, mb = 6000 * s ** 3, 2000 * s ** 3
    Ia = box_inertia(ma, s, 2 * s, 3 * s)
    Ib = R @ box_inertia(mb, s, s, 2 * s) @ R.T
    ca, cb = np.array([5.0, 0, 0]) * s, np.array([0, 4.0, 0]) * s
    parts = {p["name"]: p for p in res["parts"]}
    assert set(parts) == {"alpha", "beta"}, "parts are named after the scene's nodes"
    for name, m, c, I in (("alpha", ma, ca, Ia), ("beta", mb, cb, Ib)):
        p = parts[name]
        assert p["mass"] == pytest.approx(m, rel=1e-12)
        np.testing.assert_allclose(p["center_of_mass"], c, rtol=0, atol=1e-12 * s)
        np.testing.assert_allclose(p["inertia_tensor"], I, rtol=0, atol=1e-12 * np.trace(I))
    M = ma + mb
    com = (ma * ca + mb * cb) / M
    assert res["mass"] == pytest.approx(M, rel=1e-12)
    np.testing.assert_allclose(res["center_of_mass"], com, rtol=0, atol=1e-12 * s)
    want = parallel_axis(Ia, ma, ca - com) + parallel_axis(Ib, mb, cb - com)
    np.testing.assert_allclose(res["inertia_tensor"], want, rtol=0, atol=1e-12 * np.trace(want))
    check_principal(res)


def test_glb_scene_reports_parts_in_the_scene_frame(client: TestClient) -> None:
    scene, _ = two_box_scene()
    res = analyze(client, "scene.glb", scene.export(file_type="glb"))
    check_two_box_scene(res)


def test_gltf_with_embedded_buffers_reports_parts(client: TestClient) -> None:
    scene, _ = two_box_scene()
    files = scene.export(file_type="gltf", embed_buffers=True)
    (data,) = files.values()
    res = analyze(client, "scene.gltf", data)
    check_two_box_scene(res)


def test_3mf_objects_are_parts_and_explicit_units_win(client: TestClient) -> None:
    scene, _ = two_box_scene()
    data = scene.export(file_type="3mf")
    check_two_box_scene(analyze(client, "scene.3mf", data, units="m"))
    check_two_box_scene(analyze(client, "scene.3mf", data, units="cm"), s=1e-2)


def test_3mf_default_units(client: TestClient) -> None:
    """API.md: `units` default `m`.  A 3MF file declares its own unit (millimetre here, and by the
    3MF spec when absent).  Ambiguous: the default may be read as `m` or as the file's own unit;
    both are accepted, but source.units must say which was used."""
    scene, _ = two_box_scene()
    res = analyze(client, "scene.3mf", scene.export(file_type="3mf"))
    unit = res["source"]["units"]
    assert unit in ("m", "mm")
    check_two_box_scene(res, s=UNIT_SCALE[unit])


def kuhn_tetrahedra(origin: Any, size: Any) -> tuple[np.ndarray, np.ndarray]:
    """The cube [origin, origin + size]³ as six positively oriented tetrahedra on its diagonal."""
    from itertools import permutations

    o = np.asarray(origin, float)
    pts, cells = [], []  # type: ignore[var-annotated]
    for perm in permutations(range(3)):
        p = [o.copy()]
        for axis in perm:
            q = p[-1].copy()
            q[axis] += size
            p.append(q)
        if np.linalg.det(np.array([p[1] - p[0], p[2] - p[0], p[3] - p[0]])) < 0:
            p[2], p[3] = p[3], p[2]
        cells.append(list(range(len(pts), len(pts) + 4)))
        pts += p
    return np.array(pts), np.array(cells)


def two_cube_volume_mesh() -> Any:
    """Cubes [0,1]³ (1000 kg/m³) and [1,2]x[0,1]² (8000 kg/m³) in one tetra block."""
    pa, ca = kuhn_tetrahedra([0, 0, 0], 1.0)
    pb, cb = kuhn_tetrahedra([1, 0, 0], 1.0)
    points = np.vstack([pa, pb])
    cells = np.vstack([ca, cb + len(pa)])
    density = np.array([1000.0] * 6 + [8000.0] * 6)
    return points, cells, density


TWO_CUBES_MOMENTS = [1500.0, 1500 + 1000 * (0.5 - 12.5 / 9) ** 2 + 8000 * (1.5 - 12.5 / 9) ** 2] * 1
TWO_CUBES_MOMENTS = [1500.0, TWO_CUBES_MOMENTS[1], TWO_CUBES_MOMENTS[1]]


@pytest.mark.parametrize("fmt", ["vtu", "vtk", "msh"])
def test_volume_meshes_with_cell_density(client: TestClient, fmt: str, tmp_path: Path) -> None:
    import meshio  # a writer only

    points, cells, density = two_cube_volume_mesh()
    mesh = meshio.Mesh(points, [("tetra", cells)], cell_data={"density": [density]})
    path = tmp_path / f"cubes.{fmt}"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if fmt == "msh":
            mesh.cell_data["gmsh:physical"] = [np.ones(12, dtype=int)]
            mesh.cell_data["gmsh:geometrical"] = [np.ones(12, dtype=int)]
            meshio.write(path, mesh, file_format="gmsh22", binary=True)  # meshio misreads its ascii ElementData
        else:
            meshio.write(path, mesh)
    res = analyze(client, path.name, path.read_bytes(), density=1)
    assert res["mass"] == pytest.approx(9000, rel=1e-12)
    np.testing.assert_allclose(res["center_of_mass"], [12.5 / 9, 0.5, 0.5], rtol=1e-12)
    np.testing.assert_allclose(res["principal"]["moments"], TWO_CUBES_MOMENTS, rtol=1e-12)
    check_classification(res, "symmetric_top", "prolate")
    assert res["source"]["format"] == fmt


def test_volume_mesh_without_density_array_uses_the_density_option(client: TestClient, tmp_path: Path) -> None:
    import meshio

    points, cells, _ = two_cube_volume_mesh()
    path = tmp_path / "plain.vtu"
    meshio.write(path, meshio.Mesh(points, [("tetra", cells)]))
    res = analyze(client, "plain.vtu", path.read_bytes(), density=500)
    assert res["mass"] == pytest.approx(1000, rel=1e-12)
    assert res["volume"] == pytest.approx(2, rel=1e-12)
    np.testing.assert_allclose(res["inertia_tensor"], box_inertia(1000, 2, 1, 1), rtol=0, atol=1e-12 * 500)


def test_volume_mesh_cell_blocks_are_parts(client: TestClient, tmp_path: Path) -> None:
    import meshio

    # VTU merges consecutive cells of one type, so the blocks are of different cell types
    pa, ca = kuhn_tetrahedra([0, 0, 0], 1.0)
    pb = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (3, 4)], float)
    cb = np.array([[0, 1, 3, 2, 4, 5, 7, 6]])
    mesh = meshio.Mesh(np.vstack([pa, pb]), [("tetra", ca), ("hexahedron", cb + len(pa))])
    path = tmp_path / "blocks.vtu"
    meshio.write(path, mesh)
    res = analyze(client, "blocks.vtu", path.read_bytes())
    assert len(res["parts"]) == 2
    assert sorted(p["mass"] for p in res["parts"]) == pytest.approx([1000, 1000], rel=1e-12)
    coms = sorted(tuple(p["center_of_mass"]) for p in res["parts"])
    np.testing.assert_allclose(coms, [[0.5, 0.5, 0.5], [3.5, 0.5, 0.5]], rtol=1e-12)
    for p in res["parts"]:
        np.testing.assert_allclose(p["inertia_tensor"], np.eye(3) * 1000 / 6, rtol=0, atol=1e-12 * 1000)
    assert res["mass"] == pytest.approx(2000, rel=1e-12)
    np.testing.assert_allclose(res["center_of_mass"], [2, 0.5, 0.5], rtol=1e-12)


# ----------------------------------------------------------------------------------------
# rotators and thin bodies
# ----------------------------------------------------------------------------------------

def test_needle_of_aspect_1e6_is_a_linear_rotator_within_the_default_tolerance(client: TestClient) -> None:
    """I1/I3 = 2e-12: 'smallest moment zero within tolerance, the other two equal: ... a thin rod'."""
    R = rotation([1, 2, 2], 0.6)
    v, f = rotated_box(1.0, 1e-6, 1e-6, R, [0, 0, 0])
    data = obj_bytes([(None, v, f)])
    res = analyze(client, "rod.obj", data)
    check_classification(res, "linear_rotator", planar=True)
    n = np.asarray(res["classification"]["symmetry_axis"])
    assert abs(abs(n @ (R @ [1, 0, 0])) - 1) < 1e-9
    strict = analyze(client, "rod.obj", data, tolerance="1e-14")
    check_classification(strict, "symmetric_top", "prolate", planar=False, tolerance=1e-14)
    spin = analyze(client, "rod.obj", data, omega=",".join(repr(float(x)) for x in R @ [0, 0, 1.0]))
    # labelled a rotator, it moves as the thin prolate top its moments make (issue 12): spun
    # perpendicular to its axis, that is a permanent rotation
    assert spin["precession"]["regime"] == "permanent_rotation"


def test_collinear_points_along_a_diagonal_are_a_linear_rotator(client: TestClient) -> None:
    d = np.array([1.0, -2.0, 2.0]) / 3
    pts = [{"mass": m, "position": (s * d + [1, 1, 1]).tolist()} for m, s in ((1, 0), (2, 1.5), (3, -1))]
    res = points_ok(client, {"points": pts})
    ms = np.array([1.0, 2, 3])
    ss = np.array([0, 1.5, -1])
    sc = ms @ ss / ms.sum()
    I = float(ms @ (ss - sc) ** 2)
    np.testing.assert_allclose(res["principal"]["moments"][1:], [I, I], rtol=1e-13)
    assert abs(res["principal"]["moments"][0]) <= 1e-14 * I
    check_classification(res, "linear_rotator", planar=True)
    assert abs(abs(np.asarray(res["classification"]["symmetry_axis"]) @ d) - 1) < 1e-13


def test_size_limit_applies_to_chunked_and_json_bodies() -> None:
    def chunks() -> Any:
        for _ in range(50):
            yield b"x" * 1000

    with configured_client(INERTIA_MAX_UPLOAD_BYTES="10000", INERTIA_COMPUTE_PROCESSES="1") as c:
        r = c.post("/v1/analyze/mesh", params={"format": "stl"}, content=chunks(),
                   headers={"content-type": "multipart/form-data; boundary=abc"})
        assert_error(r, 413, "payload_too_large")
        pts = {"points": [{"mass": 1.0, "position": [i, 0, 0]} for i in range(2000)]}
        assert_error(c.post("/v1/analyze/points", json=pts), 413, "payload_too_large")


# ----------------------------------------------------------------------------------------
# harder corners
# ----------------------------------------------------------------------------------------

def test_every_error_uses_the_envelope_even_for_unknown_routes_and_bad_bodies(client: TestClient) -> None:
    for r in (client.get("/v1/no-such-endpoint"), client.get("/v1/analyze/mesh"),
              client.post("/v1/analyze/mesh", content=b"garbage",
                          headers={"content-type": "multipart/form-data; boundary=zzz"}),
              client.post("/v1/batch")):
        assert 400 <= r.status_code < 600
        body = r.json()
        assert set(body) == {"error"} and set(body["error"]) >= {"code", "message", "details"}
        assert body["error"]["code"].replace("_", "").isalpha() and body["error"]["code"].islower()
    for r in (client.post("/v1/analyze/points", content=b"[1, 2]", headers={"content-type": "application/json"}),
              client.post("/v1/precession", content=b"hello", headers={"content-type": "application/json"})):
        assert_error(r, 422, "invalid_parameter")


def test_random_convex_body_far_from_the_origin_within_the_estimate(client: TestClient) -> None:
    from scipy.spatial import ConvexHull

    rng = np.random.default_rng(7)
    local = rng.normal(size=(40, 3)) * [1.0, 0.6, 0.3]
    hull = ConvexHull(local)
    faces = hull.simplices.copy()
    centre = local[hull.vertices].mean(axis=0)
    for t in faces:  # outward winding
        a, b, c = local[t]
        if np.cross(b - a, c - a) @ (a - centre) < 0:
            t[1], t[2] = t[2], t[1]
    v = local @ rotation([3, 1, -2], 2.0).T + [3e7, -4e7, 5e7]
    data = obj_bytes([(None, v, faces)])
    res = analyze(client, "hull.obj", data)
    mass, _com, inertia, _ = exact_mass_properties(v[faces])
    est = res["diagnostics"]["relative_error_estimate"]
    assert est <= 1e-12
    assert res["mass"] == pytest.approx(float(mass), rel=1e-13)
    for got, want in zip(res["principal"]["moments"], exact_moments(inertia)):
        assert abs(got - want) <= max(est, 2.3e-16) * want, (got, want, est)
    check_principal(res)


def test_nearly_symmetric_mesh_reports_momentum_and_energy_of_its_own_tensor(client: TestClient) -> None:
    """hex_prism.stl is symmetric only within the tolerance (moments 1.4e-8 apart).  M = I Ω and
    E = ½ Ω·I Ω are properties of the initial state of the body whose tensor is reported; the
    moments are not to be rounded (cf. 'asymmetry ... is not rounded to ±1')."""
    omega = [0.3, 0.2, 1.0]
    res = analyze(client, "hex_prism.stl", omega="0.3,0.2,1", duration=20, samples=5)
    I = np.asarray(res["inertia_tensor"], float)
    pre = res["precession"]
    # labelled symmetric by the tolerance, it moves as the asymmetric top its moments make (issue 12)
    assert res["classification"]["kind"] == "symmetric_top"
    assert pre["regime"] == "asymmetric"
    check_invariants(pre, I, omega)
    check_trajectory(pre, res["principal"]["moments"], res["principal"]["axes"], omega, 20.0, 5, I, tol=1e-9)


def test_exact_motion_over_many_periods(client: TestClient) -> None:
    moments, omega = [1.0, 2.0, 3.0], [0.3, 0.8, 0.5]
    T = ll_asymmetric_period(moments, omega)
    duration = 60 * T
    res = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": duration,
                                 "samples": 9})
    check_trajectory(res["precession"], moments, res["principal"]["axes"], omega, duration, 9,
                     np.diag(moments), tol=1e-7)


@pytest.mark.parametrize("eps", [1e-3, -1e-3, 1e-5, -1e-5])
def test_period_near_the_separatrix(client: TestClient, eps: float) -> None:
    moments = [1.0, 2.0, 3.0]
    omega = [0.1 * math.sqrt(3) * (1 + eps), 1.0, 0.1]
    pre = precession_ok(client, {"principal_moments": moments, "omega": omega})["precession"]
    T = ll_asymmetric_period(moments, omega)
    assert pre["period"] == pytest.approx(T, rel=1e-9)
    assert pre["stable"] is False
    assert pre["flip_interval"] == pytest.approx(T / 2, rel=1e-9)


def test_separatrix_of_a_mesh_body(client: TestClient) -> None:
    # box.stl: I = 2500, 5000, 6500 (axes z, y, x); 2E I2 = |M|² when 2500² Ωz² = 6500·1500 Ωx²
    wx = 0.1
    wz = wx * math.sqrt(6500 * 1500) / 2500
    res = analyze(client, "box.stl", omega=f"{wx!r},1.0,{wz!r}")
    pre = res["precession"]
    assert pre["regime"] == "asymmetric" and "period" not in pre
    assert list(res.get("warnings", [])) + list(pre.get("warnings", []))


@pytest.mark.parametrize("omega", [[0.3, -0.4, -1.2], [-0.7, 0.1, 0.05], [0.0, 0.5, -2.0]])
def test_symmetric_top_signs_follow_the_reported_symmetry_axis(client: TestClient, omega: Any) -> None:
    moments = [2.0, 2.0, 3.0]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": 2, "samples": 5})
    n = res["classification"]["symmetry_axis"]
    check_symmetric_rates(res["precession"], 2.0, 3.0, n, omega)
    check_trajectory(res["precession"], moments, res["principal"]["axes"], omega, 2.0, 5, np.diag(moments))


def test_parts_carry_their_own_frames_consistently(client: TestClient) -> None:
    scene, _ = two_box_scene()
    res = analyze(client, "scene.glb", scene.export(file_type="glb"))
    for p in res["parts"]:
        assert_no_nulls(p)
        if "principal" in p:
            check_principal(p, np.asarray(p["inertia_tensor"], float))


# ----------------------------------------------------------------------------------------
# command line: entry point, batch outputs, serve
# ----------------------------------------------------------------------------------------

def test_inertia_console_script_runs_analyze() -> None:
    import shutil

    exe = shutil.which("inertia", path=str(Path(sys.executable).parent)) or shutil.which("inertia")
    assert exe, "the `inertia` command must be installed"
    p = subprocess.run([exe, "analyze", "tetrahedron.stl", "--json"], cwd=SAMPLES, capture_output=True,
                       text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    res = json.loads(p.stdout)
    assert res["mass"] == pytest.approx(1000 / 6, rel=1e-14)
    assert res["classification"]["kind"] == "symmetric_top"


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_cli_batch_tabular_outputs_have_one_row_per_file(tmp_path: Path, suffix: str) -> None:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for name in ("box.stl", "open_box.stl", "l_bracket.stl"):
            z.writestr(name, (SAMPLES / name).read_bytes())
    (tmp_path / "m.zip").write_bytes(buf.getvalue())
    out = tmp_path / f"results{suffix}"
    p = run_cli("batch", "m.zip", "--out", str(out), "--workers", "2", cwd=tmp_path)
    assert out.exists(), p.stderr
    if suffix == ".csv":
        import csv

        with out.open(newline="") as fh:
            rows = list(csv.DictReader(fh))
    else:
        import pyarrow.parquet as pq

        rows = pq.read_table(out).to_pylist()
    assert len(rows) == 3
    text = json.dumps(rows, default=str)
    assert "not_watertight" in text
    assert "6000" in text and "12000" in text


def test_inertia_serve_starts_the_http_service(tmp_path: Path) -> None:
    import socket
    import time

    import httpx

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    env = {k: v for k, v in os.environ.items() if not k.startswith("INERTIA_")}
    env["INERTIA_COMPUTE_PROCESSES"] = "1"
    proc = subprocess.Popen([sys.executable, "-m", "inertia", "serve", "--host", "127.0.0.1", "--port", str(port)],
                            cwd=tmp_path, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 30
        while True:
            try:
                r = httpx.get(f"http://127.0.0.1:{port}/healthz", timeout=1)
                break
            except httpx.TransportError:
                assert proc.poll() is None and time.monotonic() < deadline, "server did not start"
                time.sleep(0.1)
        assert r.json() == {"status": "ok"}
        r = httpx.post(f"http://127.0.0.1:{port}/v1/analyze/mesh",
                       files={"file": ("box.stl", (SAMPLES / "box.stl").read_bytes())}, timeout=30)
        assert r.status_code == 200 and r.json()["mass"] == pytest.approx(6000, rel=1e-14)
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def test_unsorted_principal_moments_keep_the_given_frame_as_input_frame(client: TestClient) -> None:
    given = [3.0, 1.0, 2.0]
    omega = [0.2, 0.5, 1.0]
    res = precession_ok(client, {"principal_moments": given, "omega": omega, "duration": 3, "samples": 4})
    I = np.diag(given)
    np.testing.assert_allclose(res["principal"]["moments"], [1, 2, 3], rtol=1e-15)
    check_principal(res, I)
    A = np.abs(np.asarray(res["principal"]["axes"]))
    np.testing.assert_allclose(A, [[0, 1, 0], [0, 0, 1], [1, 0, 0]], atol=1e-15)
    pre = res["precession"]
    check_invariants(pre, I, omega)
    check_trajectory(pre, [1, 2, 3], res["principal"]["axes"], omega, 3.0, 4, I)


def test_mass_option_scales_parts_with_their_own_densities(client: TestClient) -> None:
    res = analyze(client, "pair.obj", two_cube_obj(), densities=json.dumps({"left": 1000, "right": 3000}),
                  mass=8)
    assert res["mass"] == pytest.approx(8, rel=1e-13)
    parts = {p["name"]: p for p in res["parts"]}
    assert parts["left"]["mass"] == pytest.approx(2, rel=1e-13)
    assert parts["right"]["mass"] == pytest.approx(6, rel=1e-13)
    np.testing.assert_allclose(res["center_of_mass"], [2.0, 0.5, 0.5], rtol=1e-13)


def test_cavity_is_subtracted_not_mistaken_for_inverted_winding(client: TestClient) -> None:
    outer, inner = box_corners(4, 4, 4) - 2, box_corners(2, 2, 2) - 1
    v = np.vstack([outer, inner])
    f = np.vstack([BOX_FACES, BOX_FACES[:, ::-1] + 8])  # the cavity's faces point into the hole
    res = analyze(client, "hollow.stl", stl_bytes(v, f))
    assert res["mass"] == pytest.approx(RHO * (64 - 8), rel=1e-14)
    assert res["volume"] == pytest.approx(56, rel=1e-14)
    I = box_inertia(64000, 4, 4, 4) - box_inertia(8000, 2, 2, 2)
    np.testing.assert_allclose(res["inertia_tensor"], I, rtol=0, atol=1e-13 * np.trace(I))
    check_classification(res, "spherical_top")


def test_a_separate_inverted_shell_is_corrected_with_a_warning(client: TestClient) -> None:
    v = np.vstack([box_corners(1, 1, 1), box_corners(1, 1, 1) + np.array([3, 0, 0])])
    f = np.vstack([BOX_FACES, BOX_FACES[:, ::-1] + 8])
    res = analyze(client, "two.stl", stl_bytes(v, f))
    assert res["mass"] == pytest.approx(2000, rel=1e-14)
    np.testing.assert_allclose(res["center_of_mass"], [2, 0.5, 0.5], rtol=1e-14)
    assert res["warnings"]


def test_inconsistent_winding_is_repaired_with_a_warning(client: TestClient) -> None:
    f = BOX_FACES.copy()
    f[[0, 5, 9]] = f[[0, 5, 9]][:, ::-1]
    res = analyze(client, "mixed.stl", stl_bytes(box_corners(1, 2, 3), f))
    assert res["mass"] == pytest.approx(6000, rel=1e-14)
    np.testing.assert_allclose(res["inertia_tensor"], box_inertia(6000, 1, 2, 3), rtol=0, atol=1e-12 * 6500)
    assert res["warnings"]


def test_obj_groups_are_parts(client: TestClient) -> None:
    text = obj_bytes([("left", box_corners(1, 1, 1), BOX_FACES),
                      ("right", box_corners(1, 1, 1) + np.array([2, 0, 0]), BOX_FACES)]).decode()
    res = analyze(client, "groups.obj", text.replace("o left", "g left").replace("o right", "g right").encode(),
                  densities=json.dumps({"right": 500}))
    parts = {p["name"]: p for p in res["parts"]}
    assert set(parts) == {"left", "right"}
    assert parts["left"]["mass"] == pytest.approx(1000, rel=1e-13)
    assert parts["right"]["mass"] == pytest.approx(500, rel=1e-13)
    assert res["mass"] == pytest.approx(1500, rel=1e-13)


@pytest.mark.parametrize("name,data", [("empty.stl", b""), ("ascii.stl", b"solid x\nendsolid x\n"),
                                       ("points.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n")],
                         ids=["zero bytes", "ascii stl without facets", "obj without faces"])
def test_files_without_triangles_are_empty_geometry(client: TestClient, name: str, data: bytes) -> None:
    r = post_mesh(client, name, data)
    if name == "empty.stl" and r.json().get("error", {}).get("code") == "unreadable_file":
        # a zero-byte file is arguably not a readable STL at all: both codes are accepted
        assert_error(r, 422, "unreadable_file")
    else:
        assert_error(r, 422, "empty_geometry")


def test_point_masses_far_from_the_origin_keep_their_moments(client: TestClient) -> None:
    shift = np.array([1e8, -1e8, 3e7])
    pts = [{"mass": p["mass"], "position": (np.array(p["position"]) + shift).tolist()} for p in TRIATOMIC["points"]]
    res = points_ok(client, {"points": pts})
    est = res["diagnostics"]["relative_error_estimate"]
    want = [32 / 18, 2.0, 32 / 18 + 2]
    for got, w in zip(res["principal"]["moments"], want):
        assert abs(got - w) <= max(est, 4.5e-16) * w, (got, w, est)
    np.testing.assert_allclose(res["center_of_mass"], shift + np.array([0, 16 / 18, 0]), rtol=1e-16)


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
            assert line["mass"] == pytest.approx(6000, rel=1e-14)
        else:
            assert line["source"]["triangles"] == 2 * n * m


@pytest.mark.filterwarnings("ignore:Port 8787 is already in use")  # a dashboard elsewhere on this machine
# the in-process LocalCluster (distributed's code, not ours: the CLI runs in a subprocess) leaves a
# listening socket to the garbage collector, which warnings-as-errors turns into a failure
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning", "ignore:unclosed:ResourceWarning")
def test_cli_batch_runs_on_an_existing_dask_cluster(tmp_path: Path) -> None:
    from distributed import LocalCluster

    folder = tmp_path / "in"
    folder.mkdir()
    for name in ("box.stl", "open_box.stl", "tetrahedron.stl"):
        (folder / name).write_bytes((SAMPLES / name).read_bytes())
    out = tmp_path / "dask.jsonl"
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None,
                      protocol="tcp://", host="127.0.0.1") as cluster:
        p = run_cli("batch", str(folder), "--out", str(out), "--scheduler", cluster.scheduler_address,
                    cwd=tmp_path)
    assert out.exists(), p.stderr
    lines = {Path(x["source"]["filename"]).name: x for x in map(json.loads, out.read_text().splitlines())}
    assert set(lines) == {"box.stl", "open_box.stl", "tetrahedron.stl"}
    assert lines["open_box.stl"]["error"]["code"] == "not_watertight"
    assert lines["tetrahedron.stl"]["mass"] == pytest.approx(1000 / 6, rel=1e-14)


def test_pyramid_and_wedge_cells(client: TestClient, tmp_path: Path) -> None:
    """[0,1]³ as three pyramids (apex at the origin, bases on x=1, y=1, z=1) and [1,2]x[0,1]²
    as two wedges: together the 2 x 1 x 1 box."""
    import meshio

    pts: list[list[float]] = []

    def P(p: Any) -> Any:
        pts.append(list(map(float, p)))
        return len(pts) - 1

    apex = P([0, 0, 0])
    pyramids = []
    for quad in ([[1, 0, 0], [1, 0, 1], [1, 1, 1], [1, 1, 0]], [[0, 1, 0], [1, 1, 0], [1, 1, 1], [0, 1, 1]],
                 [[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]]):
        a, b, c = (np.array(x, float) for x in quad[:3])
        ids = [P(x) for x in quad]
        if np.cross(b - a, c - a) @ (-a) < 0:  # VTK: base normal towards the apex
            ids = ids[::-1]
        pyramids.append([*ids, apex])
    wedges = []
    for tri in ([[1, 0], [2, 0], [2, 1]], [[1, 0], [2, 1], [1, 1]]):
        wedges.append([P([x, y, 0]) for x, y in tri] + [P([x, y, 1]) for x, y in tri])
    path = tmp_path / "pw.vtu"
    meshio.write(path, meshio.Mesh(np.array(pts), [("pyramid", np.array(pyramids)), ("wedge", np.array(wedges))]))
    res = analyze(client, "pw.vtu", path.read_bytes())
    assert res["mass"] == pytest.approx(2000, rel=1e-14)
    np.testing.assert_allclose(res["center_of_mass"], [1, 0.5, 0.5], rtol=1e-14)
    np.testing.assert_allclose(res["inertia_tensor"], box_inertia(2000, 2, 1, 1), rtol=0, atol=1e-13 * 2000)
    assert sorted(p["mass"] for p in res["parts"]) == pytest.approx([1000, 1000], rel=1e-14)


@pytest.mark.parametrize("method", ["exact", "dop853", "rk45", "splitting"])
def test_drift_diagnostics_are_honest(client: TestClient, method: str) -> None:
    """'diagnostics reports how well the trajectory keeps [M] and the energy': the reported drift
    is at least what the returned samples show (half of it, for definitions that differ)."""
    moments, omega = [1.0, 2.0, 3.0], [0.3, 0.8, 0.5]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": 50, "samples": 201,
                                 "method": method})
    pre = res["precession"]
    W = np.asarray(pre["trajectory"]["omega_body"])
    I = np.asarray(moments)
    E = 0.5 * (I * W * W).sum(axis=1)
    M = np.linalg.norm(I * W, axis=1)
    E0, M0 = 0.5 * I @ (np.asarray(omega) ** 2), np.linalg.norm(I * omega)
    seen_e = float(np.max(np.abs(E / E0 - 1)))
    seen_m = float(np.max(np.abs(M / M0 - 1)))
    d = pre["diagnostics"]
    assert d["energy_drift"] >= 0.5 * seen_e - 1e-15, (d, seen_e)
    assert d["momentum_drift"] >= 0.5 * seen_m - 1e-15, (d, seen_m)


def test_points_endpoint_accepts_the_method(client: TestClient) -> None:
    body = {**TRIATOMIC, "omega": [0.2, 1.0, 0.3], "duration": 2.0, "samples": 5, "method": "dop853"}
    res = points_ok(client, body)
    I = np.asarray(res["inertia_tensor"], float)
    check_trajectory(res["precession"], res["principal"]["moments"], res["principal"]["axes"], body["omega"],
                     2.0, 5, I, tol=1e-5)


def test_moments_equal_only_within_tolerance_are_not_rounded_in_momentum_and_energy(client: TestClient) -> None:
    """Same as the hex_prism case through /v1/precession: M = diag(I) Ω exactly for the given moments."""
    moments, omega = [1.0, 2.0, 2.0 + 1e-9], [0.3, 0.4, 0.5]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega})
    assert res["classification"]["kind"] == "symmetric_top"
    assert res["classification"]["asymmetry"] == pytest.approx(ray_kappa(moments), rel=1e-12)
    check_invariants(res["precession"], np.diag(moments), omega)


# ---- API 1.1: the added sections appear only when asked for --------------------------------------------


def test_v11_sections_absent_unless_asked(client: TestClient) -> None:
    """A plain request carries none of export, frame, rotational_constants; a surface mesh carries surface_area."""
    res = client.post("/v1/analyze/mesh", files={"file": ("box.stl", (SAMPLES / "box.stl").read_bytes())})
    assert res.status_code == 200
    doc = res.json()
    assert not {"export", "frame", "rotational_constants"} & set(doc)
    assert doc["surface_area"] == pytest.approx(2 * (1 * 2 + 2 * 3 + 3 * 1), rel=1e-12)  # the 1 x 2 x 3 m box
    m, moments = doc["mass"], doc["principal"]["moments"]
    assert doc["principal"]["radii_of_gyration"] == pytest.approx([math.sqrt(i / m) for i in moments], rel=1e-12)


def test_cli_batch_reads_xyz_files_from_a_folder(tmp_path: Path) -> None:
    folder = tmp_path / "molecules"
    folder.mkdir()
    (folder / "co2.xyz").write_text("3\ncarbon dioxide\nO 0 0 -1.162\nC 0 0 0\nO 0 0 1.162\n")
    out = tmp_path / "out.jsonl"
    run = subprocess.run([sys.executable, "-m", "inertia", "batch", str(folder), "--out", str(out), "--workers", "1",
                          "--no-progress"], capture_output=True, text=True, cwd=ROOT, check=False)
    assert run.returncode == 0, run.stderr
    (line,) = [json.loads(x) for x in out.read_text().splitlines()]
    assert line["classification"]["kind"] == "linear_rotator"
    assert len(line["rotational_constants"]["MHz"]) == 1
