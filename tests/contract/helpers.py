"""Shared helpers of the contract suite: clients, uploads, closed-form and exact references, checks."""

from __future__ import annotations

import json
import math
import struct
import warnings
from fractions import Fraction
from pathlib import Path
from typing import Any, cast

import numpy as np
import pytest
from fastapi.testclient import TestClient
from numpy.typing import ArrayLike

from benchmarks.cases import BOX_FACES as BOX_FACES  # re-exported for the contract tests
from benchmarks.cases import box
from benchmarks.cases import box_inertia as box_inertia
from benchmarks.cases import obj_bytes as obj_bytes
from benchmarks.exact import Tensor, exact_eigenvalues, exact_solid
from tests.support.motion import euler_reference, unit_quaternion_matrix
from tests.support.motion import hat as hat  # re-exported for the contract tests
from tests.support.motion import rotation as rotation

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    from fastapi.testclient import TestClient

ROOT = Path(__file__).resolve().parents[2]

SAMPLES = ROOT / "sample_meshes"

RHO = 1000.0  # default density [kg/m^3] (API.md)

UNIT_SCALE = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "in": 0.0254, "ft": 0.3048}


def post_mesh(client: TestClient, filename: str, data: bytes, **params: Any) -> Any:
    q = {k: (v if isinstance(v, str) else str(v)) for k, v in params.items()}
    return client.post("/v1/analyze/mesh", files={"file": (filename, data, "application/octet-stream")}, params=q)


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


def box_corners(a: float, b: float, c: float) -> np.ndarray:
    """Corners of [0,a]x[0,b]x[0,c] (``benchmarks.cases.box``), indexed so that BOX_FACES wind outward."""
    return box(a, b, c)[0]


def read_stl_triangles(data: bytes) -> np.ndarray:
    (n,) = struct.unpack("<I", data[80:84])
    rec = np.frombuffer(data[84 : 84 + 50 * n], dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
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


def exact_mass_properties(triangles: np.ndarray, density: float = RHO) -> tuple[Fraction, list[Fraction], Tensor, Fraction]:
    """Exact rational mass, centre of mass, inertia tensor (about the COM) and volume of the closed
    polyhedron with these triangles (``benchmarks.exact.exact_solid``); an inverted winding is the same solid."""
    tri = np.asarray(triangles, dtype=np.float64)
    volume, com, tensor = exact_solid(tri.reshape(-1, 3), np.arange(3 * len(tri)).reshape(-1, 3))
    if volume < 0:
        volume, tensor = -volume, [[-x for x in row] for row in tensor]
    rho = Fraction(density)
    return rho * volume, com, [[rho * x for x in row] for row in tensor], volume


def exact_moments(inertia: Tensor) -> list[float]:
    """Ascending principal moments of an exact tensor (50-digit eigenvalues), as floats."""
    return [float(x) for x in exact_eigenvalues(inertia)]


def exact_of(filename: str, data: bytes | None = None) -> tuple[Fraction, list[Fraction], Tensor, Fraction]:
    data = data if data is not None else (SAMPLES / filename).read_bytes()
    tris = read_stl_triangles(data) if filename.endswith(".stl") else read_obj_triangles(data)
    return exact_mass_properties(tris)


def parallel_axis(I_com: np.ndarray, mass: float, d: ArrayLike) -> np.ndarray:
    d = np.asarray(d, float)
    return cast("np.ndarray", I_com + mass * (d @ d * np.eye(3) - np.outer(d, d)))


def ray_kappa(moments: Any) -> float:
    I1, I2, I3 = moments
    A, B, C = 1 / I1, 1 / I2, 1 / I3
    return cast("float", (2 * B - A - C) / (A - C))


def reference_motion(moments: Any, axes: Any, omega0: Any, times: Any) -> Any:
    """Independent torque-free motion (``tests.support.motion.euler_reference``: Euler's equations and
    dR/dt = R [Ω]x by DOP853 at rtol 1e-12) with B(t) = axesᵀ R(t), the map principal frame -> fixed
    input frame. Returns (Ω(t), ω(t) = B Ω, R(t) = B(t) axes)."""
    A = np.asarray(axes, float)
    Ws, Rs_body = euler_reference(moments, A @ np.asarray(omega0, float), np.asarray(times, float))
    Bs = A.T @ Rs_body
    omegas = np.einsum("nij,nj->ni", Bs, Ws)
    return Ws, omegas, Bs @ A


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
    np.testing.assert_allclose(unit_quaternion_matrix(q), A.T, atol=1e-12)
    assert isinstance(p["unique_axes"], bool)
    if tensor is None and "inertia_tensor" in res:
        tensor = np.asarray(res["inertia_tensor"], float)
    if tensor is not None:
        scale = float(np.trace(tensor))
        np.testing.assert_allclose(tensor, tensor.T, atol=1e-14 * scale)
        for k in range(3):  # rows are eigenvectors with the moments in the same order
            np.testing.assert_allclose(tensor @ A[k], I[k] * A[k], atol=1e-11 * scale)


def check_classification(
    res: dict[str, Any], kind: str, shape: str | None = None, planar: bool | None = None, tolerance: float = 1e-6
) -> None:
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


def thin_box_shell_inertia(a: float, b: float, c: float, sigma: float, faces: Any = ("x0", "x1", "y0", "y1", "z0", "z1")) -> Any:
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


def two_cube_obj() -> bytes:
    cube = box_corners(1, 1, 1)
    return obj_bytes([("left", cube, BOX_FACES), ("right", cube + np.array([2, 0, 0]), BOX_FACES)])


def truncated_stl() -> bytes:
    data = (SAMPLES / "box.stl").read_bytes()
    return data[:80] + struct.pack("<I", 1000) + data[84 : 84 + 100]


def post_json(client: TestClient, path: str, body: Any) -> Any:
    """POST a JSON body: an object, or a string sent as it is (for malformed JSON)."""
    if isinstance(body, str):
        return client.post(path, content=body, headers={"content-type": "application/json"})
    return client.post(path, json=body)


def post_points(client: TestClient, body: dict[str, Any] | str) -> Any:
    return post_json(client, "/v1/analyze/points", body)


def points_ok(client: TestClient, body: Any) -> dict[str, Any]:
    r = post_points(client, body)
    assert r.status_code == 200, r.text
    res = r.json()
    assert_no_nulls(res)
    return cast("dict[str, Any]", res)


TRIATOMIC = json.loads((SAMPLES / "triatomic.json").read_text())


def post_precession(client: TestClient, body: Any) -> Any:
    return post_json(client, "/v1/precession", body)


def precession_ok(client: TestClient, body: Any) -> dict[str, Any]:
    r = post_precession(client, body)
    assert r.status_code == 200, r.text
    res = r.json()
    assert_no_nulls(res)
    assert (
        {"principal", "classification", "precession", "diagnostics"}
        <= set(res)
        <= {"principal", "classification", "precession", "diagnostics", "warnings"}
    ), set(res)
    return cast("dict[str, Any]", res)


def check_invariants(pre: dict[str, Any], I_input: np.ndarray, omega0: Any) -> None:
    w = np.asarray(omega0, float)
    M = I_input @ w
    scale = np.linalg.norm(M) + 1e-300
    np.testing.assert_allclose(pre["angular_momentum"], M, rtol=0, atol=float(1e-13 * scale))
    assert pre["angular_momentum_magnitude"] == pytest.approx(np.linalg.norm(M), rel=1e-13, abs=1e-300)
    assert pre["kinetic_energy"] == pytest.approx(0.5 * w @ I_input @ w, rel=1e-13, abs=1e-300)


def check_symmetric_rates(pre: dict[str, Any], I_perp: float, I_sym: float, n: Any, omega0: Any) -> None:
    """L&L §33: ω = Ω3(I3 − I1)/I1, |M|/I1, ψ̇ = |M| cos θ (1/I3 − 1/I1), cos θ = I3 Ω3/|M|."""
    W3 = float(np.asarray(n, float) @ np.asarray(omega0, float))
    W = np.asarray(omega0, float)
    W_perp2 = W @ W - W3 * W3
    M = math.sqrt((I_sym * W3) ** 2 + I_perp**2 * W_perp2)
    body = W3 * (I_sym - I_perp) / I_perp
    cos_theta = I_sym * W3 / M
    assert pre["regime"] == "regular_precession"
    assert pre["body_precession_rate"] == pytest.approx(body, rel=1e-12, abs=0)
    assert pre["space_precession_rate"] == pytest.approx(M / I_perp, rel=1e-12, abs=0)
    assert pre["spin_rate"] == pytest.approx(M * cos_theta * (1 / I_sym - 1 / I_perp), rel=1e-12, abs=0)
    assert pre["nutation_angle"] == pytest.approx(math.acos(cos_theta), rel=1e-12, abs=0)
    assert pre["period"] == pytest.approx(2 * math.pi / abs(body), rel=1e-12, abs=0)


def check_trajectory(
    pre: dict[str, Any], moments: Any, axes: Any, omega0: Any, duration: float, samples: int, I_input: Any, tol: float = 1e-8
) -> None:
    tr = pre["trajectory"]
    t = np.asarray(tr["t"], float)
    assert len(t) == samples
    np.testing.assert_allclose(t, np.linspace(0, duration, samples), rtol=1e-14, atol=1e-14 * duration)
    assert t[0] == 0 and t[-1] == pytest.approx(duration, rel=1e-15, abs=0)
    W = np.asarray(tr["omega_body"], float)
    w = np.asarray(tr["omega"], float)
    Q = np.asarray(tr["quaternion"], float)
    assert W.shape == (samples, 3) and w.shape == (samples, 3) and Q.shape == (samples, 4)
    np.testing.assert_allclose(np.linalg.norm(Q, axis=1), 1, atol=1e-12)
    np.testing.assert_allclose(unit_quaternion_matrix(Q[0]), np.eye(3), atol=1e-14)
    A = np.asarray(axes, float)
    np.testing.assert_allclose(W[0], pre["omega_body"], rtol=0, atol=float(1e-13 * np.linalg.norm(omega0)))
    np.testing.assert_allclose(w[0], omega0, rtol=0, atol=float(1e-13 * np.linalg.norm(omega0)))
    M0 = I_input @ np.asarray(omega0, float)
    wscale = float(np.linalg.norm(omega0))
    for k in range(samples):
        R = unit_quaternion_matrix(Q[k])
        # omega(t) in the fixed input frame is the rotated body omega
        np.testing.assert_allclose(w[k], R @ A.T @ W[k], rtol=0, atol=max(tol, 1e-12) * wscale)
        # M stays constant in the fixed frame: I(t) = R I0 Rᵀ
        np.testing.assert_allclose(
            R @ I_input @ R.T @ w[k],
            M0,
            rtol=0,
            atol=float(max(tol, 1e-12) * np.linalg.norm(M0) + 1e-300),
        )
    if moments[0] > 0:
        Wr, wr, Rr = reference_motion(moments, A, omega0, t)
        np.testing.assert_allclose(W, Wr, rtol=0, atol=tol * wscale)
        np.testing.assert_allclose(w, wr, rtol=0, atol=tol * wscale)
        for k in range(samples):
            np.testing.assert_allclose(unit_quaternion_matrix(Q[k]), Rr[k], rtol=0, atol=tol)
    d = pre["diagnostics"]
    for key in ("energy_drift", "momentum_drift"):
        assert d[key] >= 0 and math.isfinite(d[key])


def two_box_scene() -> Any:
    import trimesh  # a writer only: the expected values below are closed formulas

    tf = trimesh.transformations
    scene = trimesh.Scene()
    scene.add_geometry(
        trimesh.creation.box([1, 2, 3]), node_name="alpha", geom_name="g_alpha", transform=tf.translation_matrix([5, 0, 0])
    )
    rot = tf.rotation_matrix(0.5, [1, 0, 0])
    scene.add_geometry(
        trimesh.creation.box([1, 1, 2]),
        node_name="beta",
        geom_name="g_beta",
        transform=tf.concatenate_matrices(tf.translation_matrix([0, 4, 0]), rot),
    )
    return scene, rot[:3, :3]


_TWO_CUBES_PERPENDICULAR = 1500 + 1000 * (0.5 - 12.5 / 9) ** 2 + 8000 * (1.5 - 12.5 / 9) ** 2
TWO_CUBES_MOMENTS = [1500.0, _TWO_CUBES_PERPENDICULAR, _TWO_CUBES_PERPENDICULAR]
