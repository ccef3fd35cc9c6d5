"""Robotics export (API.md 1.1, "Robotics export"), checked by the simulators' own readers.

Each snippet is parsed back with lxml; the MJCF is compiled by MuJoCo itself
and the URDF by MuJoCo's URDF compiler, and the compiled body's mass, inertial
frame and tensor (R diag(I) R^T from MuJoCo's ``body_iquat`` and
``body_inertia``) must equal the service's result to 1e-12 relative.  The SDF
snippet is checked against the element names of the SDFormat specification's
``inertial.sdf`` (gazebosim/sdformat: ``inertial`` holds ``mass``, ``pose``
and ``inertia``, whose children are ``ixx ixy ixz iyy iyz izz``).

The bodies are off the origin and not aligned with the axes, so every
convention (origin at the centre of mass, tensor about it, quaternion
direction, moment order) is exercised.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tests.support.motion import rotation, unit_quaternion_matrix

mujoco = pytest.importorskip("mujoco")
etree = pytest.importorskip("lxml.etree")

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    from fastapi.testclient import TestClient

ROOT = Path(__file__).resolve().parents[1]
REL = 1e-12

# SDFormat specification, inertial.sdf: the elements an <inertial> may hold and the <inertia> components
SDF_INERTIAL_CHILDREN = {"mass", "pose", "inertia", "fluid_added_mass", "density", "auto"}
SDF_INERTIA_CHILDREN = {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"}
URDF_INERTIA_ATTRIBUTES = {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"}  # ROS urdf XML specification, <inertia>


@pytest.fixture(scope="module")
def client() -> Any:
    from inertia.app import app

    with TestClient(app) as c:
        yield c


# four unequal masses off the origin: a full, non-diagonal tensor
POINTS = [
    {"mass": 1.0, "position": [0.3, 0.1, -0.2]},
    {"mass": 2.5, "position": [1.2, 0.7, 0.4]},
    {"mass": 0.7, "position": [0.1, 1.5, 0.9]},
    {"mass": 1.9, "position": [0.8, -0.3, 1.4]},
]


BOX = (0.4, 0.25, 0.1)  # edge lengths [m]
BOX_R = rotation([1.0, 2.0, 0.5], 0.7)
BOX_OFFSET = np.array([1.5, -0.75, 2.25])


def _box_obj(name: str = "box", offset: np.ndarray = BOX_OFFSET) -> str:
    """An OBJ of the box, rotated and moved, coordinates written exactly (repr of float64)."""
    a, b, c = (x / 2 for x in BOX)
    corners = [np.array([sx * a, sy * b, sz * c]) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    lines = [f"o {name}"] + ["v " + " ".join(repr(float(x)) for x in BOX_R @ p + offset) for p in corners]
    faces = [(1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)]
    return "\n".join(lines + [f"f {q[0]} {q[1]} {q[2]} {q[3]}" for q in faces]) + "\n"


def _mesh(client: Any, text: str, fmt: str, **params: Any) -> Any:
    files = {"file": ("part.obj", text.encode(), "application/octet-stream")}
    return client.post("/v1/analyze/mesh", params={"export": fmt, **params}, files=files)


def _compiled(model: Any, body: int) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass (body frame) and tensor about it (body axes), as MuJoCo compiled them."""
    R = unit_quaternion_matrix(np.array(model.body_iquat[body]))
    tensor = R @ np.diag(model.body_inertia[body]) @ R.T
    return float(model.body_mass[body]), np.array(model.body_ipos[body]), tensor


def _assert_same_body(compiled: tuple[float, np.ndarray, np.ndarray], doc: dict[str, Any]) -> None:
    mass, com, tensor = compiled
    ours = np.array(doc["inertia_tensor"])
    assert mass == pytest.approx(doc["mass"], rel=REL)
    np.testing.assert_allclose(com, doc["center_of_mass"], rtol=0, atol=float(REL * np.linalg.norm(doc["center_of_mass"])))
    np.testing.assert_allclose(tensor, ours, rtol=0, atol=float(REL * np.abs(ours).max()))


def _mjcf_model(snippets: list[str]) -> Any:
    bodies = "".join(f'<body name="b{i}"><freejoint/>{s}</body>' for i, s in enumerate(snippets))
    return mujoco.MjModel.from_xml_string(f"<mujoco><worldbody>{bodies}</worldbody></mujoco>")


def _urdf_model(snippets: list[str]) -> Any:
    links = "".join(f'<link name="p{i}">{s}</link>' for i, s in enumerate(snippets))
    joints = "".join(
        f'<joint name="j{i}" type="floating"><parent link="base"/><child link="p{i}"/></joint>' for i in range(len(snippets))
    )
    return mujoco.MjModel.from_xml_string(f'<robot name="r"><link name="base"/>{links}{joints}</robot>')


def _body_id(model: Any, name: str) -> int:
    return int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name))


@pytest.fixture(scope="module", params=["points", "mesh"])
def body_docs(request: Any, client: Any) -> dict[str, dict[str, Any]]:
    """The result of each export format for the point set or the rotated, moved box."""
    out = {}
    for fmt in ("urdf", "sdf", "mjcf"):
        if request.param == "points":
            r = client.post("/v1/analyze/points", json={"points": POINTS, "export": fmt})
        else:
            r = _mesh(client, _box_obj(), fmt, density=2700)
        assert r.status_code == 200, r.text
        out[fmt] = r.json()
    return out


def test_box_tensor_is_the_rotated_closed_form(body_docs: dict[str, dict[str, Any]]) -> None:
    doc = body_docs["mjcf"]
    if doc["source"]["kind"] != "mesh":
        pytest.skip("closed form is for the box")
    a, b, c = BOX
    m = 2700 * a * b * c
    expected = BOX_R @ np.diag([m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12]) @ BOX_R.T
    np.testing.assert_allclose(doc["inertia_tensor"], expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    assert abs(expected[0, 1]) > 1e-3 * expected.max()  # really non-diagonal


def test_mjcf_compiled_by_mujoco_equals_our_body(body_docs: dict[str, dict[str, Any]]) -> None:
    doc = body_docs["mjcf"]
    model = _mjcf_model([doc["export"]["text"]])
    _assert_same_body(_compiled(model, _body_id(model, "b0")), doc)
    # MuJoCo's own inertial frame: diaginertia in our order, quat ours
    element = etree.fromstring(doc["export"]["text"])
    assert element.tag == "inertial"
    assert set(element.attrib) == {"pos", "quat", "mass", "diaginertia"}
    np.testing.assert_array_equal([float(v) for v in element.get("diaginertia").split()], doc["principal"]["moments"])


def test_urdf_compiled_by_mujocos_urdf_compiler_equals_our_body(body_docs: dict[str, dict[str, Any]]) -> None:
    doc = body_docs["urdf"]
    model = _urdf_model([doc["export"]["text"]])
    _assert_same_body(_compiled(model, _body_id(model, "p0")), doc)
    element = etree.fromstring(doc["export"]["text"])
    origin, mass, inertia = element.find("origin"), element.find("mass"), element.find("inertia")
    assert origin.get("rpy") == "0 0 0"
    assert float(mass.get("value")) == doc["mass"]
    assert set(inertia.attrib) == URDF_INERTIA_ATTRIBUTES
    t = doc["inertia_tensor"]
    assert [float(inertia.get(k)) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")] == [
        t[0][0],
        t[0][1],
        t[0][2],
        t[1][1],
        t[1][2],
        t[2][2],
    ]


def test_sdf_uses_sdformat_names_and_our_numbers(body_docs: dict[str, dict[str, Any]]) -> None:
    doc = body_docs["sdf"]
    element = etree.fromstring(doc["export"]["text"])
    assert element.tag == "inertial"
    assert {child.tag for child in element} <= SDF_INERTIAL_CHILDREN
    assert {child.tag for child in element.find("inertia")} == SDF_INERTIA_CHILDREN
    pose = [float(v) for v in element.findtext("pose").split()]
    assert pose[:3] == doc["center_of_mass"] and pose[3:] == [0, 0, 0]
    assert float(element.findtext("mass")) == doc["mass"]
    t = doc["inertia_tensor"]
    got = {k: float(element.find("inertia").findtext(k)) for k in SDF_INERTIA_CHILDREN}
    assert got == {"ixx": t[0][0], "ixy": t[0][1], "ixz": t[0][2], "iyy": t[1][1], "iyz": t[1][2], "izz": t[2][2]}


def test_numbers_have_17_significant_digits(body_docs: dict[str, dict[str, Any]]) -> None:
    text = body_docs["urdf"]["export"]["text"]
    mass = etree.fromstring(text).find("mass").get("value")
    digits = mass.lstrip("-").split("e")[0].replace(".", "").lstrip("0")
    assert len(digits) <= 17 and float(mass) == body_docs["urdf"]["mass"]


@pytest.mark.parametrize(
    "points, reason",
    [
        ([{"mass": 1.0, "position": [0, 0, 0]}, {"mass": 2.0, "position": [1, 1, 1]}], "zero_moment"),  # rotator
        ([{"mass": 1.0, "position": [0.5, 0.2, 0.1]}], "zero_moment"),  # a single point
    ],
)
@pytest.mark.parametrize("fmt", ["urdf", "sdf", "mjcf"])
def test_body_a_simulator_rejects_is_invalid_inertia(client: Any, points: list[Any], reason: str, fmt: str) -> None:
    r = client.post("/v1/analyze/points", json={"points": points, "export": fmt})
    assert r.status_code == 422
    error = r.json()["error"]
    assert error["code"] == "invalid_inertia" and error["details"]["reason"] == reason
    assert "thickness" in error["message"]
    # the same body without export is fine
    assert client.post("/v1/analyze/points", json={"points": points}).status_code == 200


def test_mujoco_itself_rejects_what_we_refuse() -> None:
    """The refusals above are MuJoCo's: a zero moment and moments below mjMINVAL fail to compile."""
    for diag, mass in (("0 1 1", 1.0), ("1e-16 1 1", 1.0), ("1 1 1", 1e-16), ("1 1 2.0000000000000004", 1.0)):
        with pytest.raises(ValueError):
            _mjcf_model([f'<inertial pos="0 0 0" mass="{mass}" diaginertia="{diag}"/>'])


@pytest.mark.parametrize("fmt", ["urdf", "mjcf"])
def test_molecule_scale_body_is_refused_for_mujoco_formats(client: Any, fmt: str) -> None:
    water = [
        {"element": "O", "position": [0, 0, 0.1173]},
        {"element": "H", "position": [0, 0.7572, -0.4692]},
        {"element": "H", "position": [0, -0.7572, -0.4692]},
    ]
    r = client.post("/v1/analyze/points", json={"points": water, "units": "angstrom", "export": fmt})
    assert r.status_code == 422 and r.json()["error"]["details"]["reason"] == "below_mjminval"
    sdf = client.post("/v1/analyze/points", json={"points": water, "units": "angstrom", "export": "sdf"})
    assert sdf.status_code == 200


@pytest.mark.parametrize("seed", range(8))
def test_planar_bodies_load_in_mujoco(client: Any, seed: int) -> None:
    """I1 + I2 = I3 exactly for a planar set: the snippets must still pass MuJoCo's exact A + B >= C."""
    rng = np.random.default_rng(seed)
    R = rotation(list(rng.normal(size=3)), float(rng.uniform(0, math.pi)))
    plane = [np.array([x, y, 0.0]) for x, y in rng.uniform(-1, 1, size=(5, 2))]
    points = [{"mass": float(m), "position": (R @ p + 3.0).tolist()} for m, p in zip(rng.uniform(0.5, 2, 5), plane)]
    for fmt, build, body in (("mjcf", _mjcf_model, "b0"), ("urdf", _urdf_model, "p0")):
        r = client.post("/v1/analyze/points", json={"points": points, "export": fmt})
        assert r.status_code == 200, r.text
        doc = r.json()
        model = build([doc["export"]["text"]])  # compiles: MuJoCo accepted it
        mass, _, tensor = _compiled(model, _body_id(model, body))
        ours = np.array(doc["inertia_tensor"])
        # the largest moment may be lowered by at most a few hundred eps (stated in a warning)
        np.testing.assert_allclose(tensor, ours, rtol=0, atol=1e-13 * np.abs(ours).max())
        assert mass == doc["mass"]


def test_assembly_exports_each_part(client: Any) -> None:
    text = _box_obj("left") + _box_obj("right", BOX_OFFSET + np.array([1.0, 0.0, 0.0])).replace("\nf ", "\nf ")
    # the second object's face indices continue after the first object's 8 vertices
    first, second = text.split("o right\n")
    second_lines = [
        (f"f {' '.join(str(int(i) + 8) for i in ln.split()[1:])}" if ln.startswith("f ") else ln) for ln in second.splitlines()
    ]
    text = first + "o right\n" + "\n".join(second_lines) + "\n"
    r = _mesh(client, text, "mjcf")
    assert r.status_code == 200, r.text
    doc = r.json()
    parts = {p["name"]: p for p in doc["parts"]}
    exported = {p["name"]: p["text"] for p in doc["export"]["parts"]}
    assert set(exported) == set(parts) == {"left", "right"}
    model = _mjcf_model([doc["export"]["text"], exported["left"], exported["right"]])
    _assert_same_body(_compiled(model, _body_id(model, "b0")), doc)
    _assert_same_body(_compiled(model, _body_id(model, "b1")), parts["left"])
    _assert_same_body(_compiled(model, _body_id(model, "b2")), parts["right"])


def test_cli_export_prints_the_snippet_alone(tmp_path: Path) -> None:
    path = tmp_path / "part.obj"
    path.write_text(_box_obj())
    run = subprocess.run(
        [sys.executable, "-m", "inertia", "analyze", str(path), "--export", "mjcf"],
        capture_output=True,
        text=True,
        check=False,
        cwd=ROOT,
    )
    assert run.returncode == 0, run.stderr
    element = etree.fromstring(run.stdout.strip())
    assert element.tag == "inertial"
    as_json = subprocess.run(
        [sys.executable, "-m", "inertia", "analyze", str(path), "--export", "mjcf", "--json"],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    )
    assert json.loads(as_json.stdout)["export"]["text"] == run.stdout.strip()


def test_export_rejects_an_unknown_format(client: Any) -> None:
    r = client.post("/v1/analyze/points", json={"points": POINTS, "export": "step"})
    assert r.status_code == 422 and r.json()["error"]["code"] == "invalid_parameter"


@pytest.mark.parametrize("fmt", ["mjcf", "urdf"])
def test_moments_rounded_just_past_the_triangle_inequality_still_load(fmt: str) -> None:
    """A lamina's I3 one ulp above I1 + I2 (rounding) is written so that MuJoCo's exact check passes."""
    from inertia.export import Inertial, inertial_snippet

    i3 = np.nextafter(np.nextafter(3.0, 4.0), 4.0)  # 1 + 2 = 3 < i3 by two ulps: MuJoCo refuses these moments as they are
    with pytest.raises(ValueError):
        _mjcf_model([f'<inertial pos="0 0 0" mass="1" diaginertia="1 2 {i3!r}"/>'])
    R = rotation([0.3, 1.0, -0.4], 1.1)
    body = Inertial(
        2.0,
        np.array([0.5, -0.25, 1.0]),
        R @ np.diag([1.0, 2.0, i3]) @ R.T,
        np.array([1.0, 2.0, i3]),
        R.T,
        _quaternion_of(R),
        relative_error=1e-15,
    )
    snippet = inertial_snippet(fmt, body)
    assert any("planar" in w for w in snippet.warnings)
    model = (_mjcf_model if fmt == "mjcf" else _urdf_model)([snippet.text])
    mass, _, tensor = _compiled(model, 1)
    assert mass == 2.0
    np.testing.assert_allclose(tensor, body.tensor, rtol=0, atol=1e-13 * i3)


def _quaternion_of(R: np.ndarray) -> np.ndarray:
    """[w, x, y, z] of a rotation matrix (scipy's, scalar last, reordered)."""
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(R).as_quat()
    return np.array([w, x, y, z])
