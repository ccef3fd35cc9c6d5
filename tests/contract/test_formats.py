"""Readable formats beyond STL: OBJ, PLY, OFF, glTF/GLB scenes, 3MF, volume meshes with cell densities."""

from __future__ import annotations

import json
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from benchmarks.cases import stl_bytes
from tests.contract.helpers import (
    BOX_FACES,
    SAMPLES,
    TWO_CUBES_MOMENTS,
    UNIT_SCALE,
    analyze,
    box_corners,
    box_inertia,
    check_classification,
    check_principal,
    obj_bytes,
    parallel_axis,
    rotation,
    two_box_scene,
)


def test_format_parameter_overrides_the_file_name(client: TestClient) -> None:
    res = analyze(client, "blob.bin", (SAMPLES / "box.stl").read_bytes(), format="stl")
    assert res["mass"] == pytest.approx(6000, rel=1e-14, abs=0)
    assert res["source"]["format"] == "stl"


def test_volume_mesh_cell_density_takes_precedence_and_mass_scales_it(client: TestClient) -> None:
    base = analyze(client, "two_density.vtu", density=5)
    assert base["mass"] == pytest.approx(9000, rel=1e-12, abs=0)
    np.testing.assert_allclose(base["principal"]["moments"], [1500, 21500 / 9, 21500 / 9], rtol=1e-12)
    np.testing.assert_allclose(base["center_of_mass"], [12.5 / 9, 0.5, 0.5], rtol=1e-12)
    assert any("density 5 kg/m^3 was not used" in w for w in base["warnings"])  # never silently ignored
    scaled = analyze(client, "two_density.vtu", mass=18)
    assert not any("was not used" in w for w in scaled["warnings"])  # mass scales the cells' densities: all used
    assert scaled["mass"] == pytest.approx(18, rel=1e-12, abs=0)
    np.testing.assert_allclose(scaled["principal"]["moments"], np.array([1500, 21500 / 9, 21500 / 9]) * 18 / 9000, rtol=1e-12)
    np.testing.assert_allclose(scaled["center_of_mass"], [12.5 / 9, 0.5, 0.5], rtol=1e-12)


def ply_ascii(v: np.ndarray, f: np.ndarray) -> bytes:
    head = [
        "ply",
        "format ascii 1.0",
        f"element vertex {len(v)}",
        "property double x",
        "property double y",
        "property double z",
        f"element face {len(f)}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    body = [" ".join(repr(float(x)) for x in p) for p in v] + ["3 " + " ".join(map(str, t)) for t in f]
    return ("\n".join(head + body) + "\n").encode()


def off_ascii(v: np.ndarray, f: np.ndarray) -> bytes:
    lines = ["OFF", f"{len(v)} {len(f)} 0"] + [" ".join(repr(float(x)) for x in p) for p in v]
    lines += ["3 " + " ".join(map(str, t)) for t in f]
    return ("\n".join(lines) + "\n").encode()


@pytest.mark.parametrize("fmt", ["ply", "off", "obj", "stl"])
def test_surface_formats_give_the_same_box(client: TestClient, fmt: str) -> None:
    v = box_corners(1, 2, 3) + np.array([1, -1, 2])
    writers: dict[str, Callable[[np.ndarray, np.ndarray], bytes]] = {
        "ply": ply_ascii,
        "off": off_ascii,
        "obj": lambda a, b: obj_bytes([(None, a, b)]),
        "stl": stl_bytes,
    }
    res = analyze(client, f"box.{fmt}", writers[fmt](v, BOX_FACES))
    assert res["source"]["format"] == fmt
    assert res["mass"] == pytest.approx(6000, rel=1e-14, abs=0)
    np.testing.assert_allclose(res["center_of_mass"], [1.5, 0, 3.5], rtol=0, atol=1e-14 * 4)
    np.testing.assert_allclose(res["inertia_tensor"], box_inertia(6000, 1, 2, 3), rtol=0, atol=1e-12 * 6500)
    check_classification(res, "asymmetric_top")


def check_two_box_scene(res: dict[str, Any], s: float = 1.0) -> None:
    R = rotation([1, 0, 0], 0.5)
    ma, mb = 6000 * s**3, 2000 * s**3
    Ia = box_inertia(ma, s, 2 * s, 3 * s)
    Ib = R @ box_inertia(mb, s, s, 2 * s) @ R.T
    ca, cb = np.array([5.0, 0, 0]) * s, np.array([0, 4.0, 0]) * s
    parts = {p["name"]: p for p in res["parts"]}
    assert set(parts) == {"alpha", "beta"}, "parts are named after the scene's nodes"
    for name, m, c, I in (("alpha", ma, ca, Ia), ("beta", mb, cb, Ib)):
        p = parts[name]
        assert p["mass"] == pytest.approx(m, rel=1e-12, abs=0)
        np.testing.assert_allclose(p["center_of_mass"], c, rtol=0, atol=1e-12 * s)
        np.testing.assert_allclose(p["inertia_tensor"], I, rtol=0, atol=1e-12 * np.trace(I))
    M = ma + mb
    com = (ma * ca + mb * cb) / M
    assert res["mass"] == pytest.approx(M, rel=1e-12, abs=0)
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
    pts: list[np.ndarray] = []
    cells: list[list[int]] = []
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
    assert res["mass"] == pytest.approx(9000, rel=1e-12, abs=0)
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
    assert res["mass"] == pytest.approx(1000, rel=1e-12, abs=0)
    assert res["volume"] == pytest.approx(2, rel=1e-12, abs=0)
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
    assert sorted(p["mass"] for p in res["parts"]) == pytest.approx([1000, 1000], rel=1e-12, abs=0)
    coms = sorted(tuple(p["center_of_mass"]) for p in res["parts"])
    np.testing.assert_allclose(coms, [[0.5, 0.5, 0.5], [3.5, 0.5, 0.5]], rtol=1e-12)
    for p in res["parts"]:
        np.testing.assert_allclose(p["inertia_tensor"], np.eye(3) * 1000 / 6, rtol=0, atol=1e-12 * 1000)
    assert res["mass"] == pytest.approx(2000, rel=1e-12, abs=0)
    np.testing.assert_allclose(res["center_of_mass"], [2, 0.5, 0.5], rtol=1e-12)


def test_obj_groups_are_parts(client: TestClient) -> None:
    text = obj_bytes(
        [("left", box_corners(1, 1, 1), BOX_FACES), ("right", box_corners(1, 1, 1) + np.array([2, 0, 0]), BOX_FACES)]
    ).decode()
    res = analyze(
        client,
        "groups.obj",
        text.replace("o left", "g left").replace("o right", "g right").encode(),
        densities=json.dumps({"right": 500}),
    )
    parts = {p["name"]: p for p in res["parts"]}
    assert set(parts) == {"left", "right"}
    assert parts["left"]["mass"] == pytest.approx(1000, rel=1e-13, abs=0)
    assert parts["right"]["mass"] == pytest.approx(500, rel=1e-13, abs=0)
    assert res["mass"] == pytest.approx(1500, rel=1e-13, abs=0)


@pytest.mark.parametrize("objects", [2, 3])
def test_source_counts_each_vertex_of_a_multi_object_obj_once(client: TestClient, objects: int) -> None:
    # API.md's source section counts the body's vertices (8 for a box); n cubes written as n objects hold 8 n
    text = obj_bytes([(f"cube{i}", box_corners(1, 1, 1) + np.array([2 * i, 0, 0]), BOX_FACES) for i in range(objects)])
    source = analyze(client, "cubes.obj", text)["source"]
    assert source["triangles"] == 12 * objects
    assert source["vertices"] == 8 * objects


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
    for quad in (
        [[1, 0, 0], [1, 0, 1], [1, 1, 1], [1, 1, 0]],
        [[0, 1, 0], [1, 1, 0], [1, 1, 1], [0, 1, 1]],
        [[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]],
    ):
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
    assert res["mass"] == pytest.approx(2000, rel=1e-14, abs=0)
    np.testing.assert_allclose(res["center_of_mass"], [1, 0.5, 0.5], rtol=1e-14)
    np.testing.assert_allclose(res["inertia_tensor"], box_inertia(2000, 2, 1, 1), rtol=0, atol=1e-13 * 2000)
    assert sorted(p["mass"] for p in res["parts"]) == pytest.approx([1000, 1000], rel=1e-14, abs=0)
