"""Loading every format, units, assemblies and bad files."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import meshio
import numpy as np
import pytest
import trimesh

from benchmarks.cases import box
from inertia.errors import EmptyGeometryError, InvalidParameterError, UnreadableFileError, UnsupportedFormatError
from inertia.load import load_body
from inertia.mass import parallel_axis
from inertia.pipeline import AnalysisOptions, analyze

BOX_MOMENTS = sorted([6000 * (4 + 9) / 12, 6000 * (1 + 9) / 12, 6000 * (1 + 4) / 12])


def box_mesh() -> trimesh.Trimesh:
    return trimesh.Trimesh(*box(1.0, 2.0, 3.0), process=False)


def export(obj: trimesh.Trimesh | trimesh.Scene, fmt: str, **kw: Any) -> bytes:
    data = obj.export(file_type=fmt, **kw)
    if isinstance(data, dict):  # gltf with embedded buffers
        data = data["model.gltf"]
    return data.encode() if isinstance(data, str) else data


@pytest.mark.parametrize(
    "fmt,ext",
    [("stl", "stl"), ("stl_ascii", "stl"), ("obj", "obj"), ("ply", "ply"), ("off", "off"), ("glb", "glb"), ("3mf", "3mf")],
)
def test_every_surface_format_gives_the_box(fmt: str, ext: str) -> None:
    doc = analyze(export(box_mesh(), fmt), filename=f"part.{ext}").as_dict()
    scale = 1e-3 if ext == "3mf" else 1.0  # 3MF declares millimetres
    assert doc["mass"] == pytest.approx(6000 * scale**3, rel=1e-14)
    np.testing.assert_allclose(doc["principal"]["moments"], np.array(BOX_MOMENTS) * scale**5, rtol=1e-14)
    assert doc["source"]["triangles"] == 12 and doc["source"]["vertices"] == 8


@pytest.mark.parametrize("filename", ["part.stl", None])
def test_ascii_stl_in_capitals_is_read(filename: str | None) -> None:
    # SOLID / FACET NORMAL / OUTER LOOP / VERTEX: older CAD tools write the keywords so (admesh's own block.stl)
    data = export(box_mesh(), "stl_ascii").upper()
    assert b"VERTEX" in data and b"vertex" not in data
    doc = analyze(data, filename=filename).as_dict()
    assert doc["mass"] == pytest.approx(6000, rel=1e-14)
    np.testing.assert_allclose(doc["principal"]["moments"], BOX_MOMENTS, rtol=1e-14)


def test_gltf_with_embedded_buffers_is_read_in_metres() -> None:
    data = export(trimesh.Scene(box_mesh()), "gltf", embed_buffers=True)
    doc = analyze(data, filename="part.gltf").as_dict()
    assert doc["source"]["units"] == "m" and doc["source"]["units_from"] == "file"
    assert doc["mass"] == pytest.approx(6000, rel=1e-14)


def test_3mf_declared_unit_is_used_and_reported() -> None:
    doc = analyze(export(box_mesh(), "3mf"), filename="part.3mf").as_dict()
    assert doc["source"]["units"] == "mm" and doc["source"]["units_from"] == "file"
    assert any("taken from the file" in w for w in doc["warnings"])


def test_requested_unit_overrides_the_file() -> None:
    doc = analyze(export(box_mesh(), "3mf"), filename="part.3mf", options=AnalysisOptions(units="m")).as_dict()
    assert doc["source"]["units_from"] == "request"
    assert doc["mass"] == pytest.approx(6000, rel=1e-14)


def two_box_scene() -> trimesh.Scene:
    scene = trimesh.Scene()
    scene.add_geometry(trimesh.Trimesh(*box(1.0, 1.0, 1.0), process=False), node_name="left", geom_name="left")
    shift = np.eye(4)
    shift[:3, 3] = [3.0, 1.0, 0.0]
    scene.add_geometry(trimesh.Trimesh(*box(1.0, 2.0, 1.0), process=False), node_name="right", geom_name="right", transform=shift)
    return scene


def expected_two_boxes(rho_left: float, rho_right: float) -> tuple[float, np.ndarray, np.ndarray]:
    m1, c1 = rho_left * 1.0, np.array([0.5, 0.5, 0.5])
    i1 = np.diag([m1 * 2 / 12, m1 * 2 / 12, m1 * 2 / 12])
    m2, c2 = rho_right * 2.0, np.array([3.5, 2.0, 0.5])
    i2 = np.diag([m2 * (4 + 1) / 12, m2 * (1 + 1) / 12, m2 * (1 + 4) / 12])
    m = m1 + m2
    com = (m1 * c1 + m2 * c2) / m
    return m, com, parallel_axis(i1, m1, c1 - com) + parallel_axis(i2, m2, c2 - com)


@pytest.mark.parametrize("fmt", ["glb", "obj"])
def test_assembly_is_the_parallel_axis_sum_of_its_parts(fmt: str) -> None:
    doc = analyze(
        export(two_box_scene(), fmt), filename=f"asm.{fmt}", options=AnalysisOptions(densities={"right": 2000.0})
    ).as_dict()
    m, com, tensor = expected_two_boxes(1000.0, 2000.0)
    assert doc["mass"] == pytest.approx(m, rel=1e-14)
    np.testing.assert_allclose(doc["center_of_mass"], com, rtol=1e-14)
    np.testing.assert_allclose(doc["inertia_tensor"], tensor, rtol=1e-13, atol=1e-12 * np.abs(tensor).max())
    names = [p["name"] for p in doc["parts"]]
    assert names == ["left", "right"]
    assert [p["mass"] for p in doc["parts"]] == pytest.approx([1000.0, 4000.0], rel=1e-14)
    assert doc["source"]["parts"] == 2


def test_assembly_equals_its_parts_as_separate_files() -> None:
    whole = analyze(export(two_box_scene(), "glb"), filename="asm.glb").as_dict()
    scene = two_box_scene()
    singles = []
    for node in ("left", "right"):
        transform, geom = scene.graph[node]
        mesh = scene.geometry[geom].copy()
        mesh.apply_transform(transform)
        singles.append(analyze(export(mesh, "stl"), filename=f"{node}.stl").as_dict())
    assert whole["mass"] == pytest.approx(sum(s["mass"] for s in singles), rel=1e-14)
    for part, single in zip(whole["parts"], singles):
        np.testing.assert_allclose(part["inertia_tensor"], single["inertia_tensor"], rtol=1e-13, atol=1e-10)


def test_assembly_total_mass_scales_every_part() -> None:
    doc = analyze(
        export(two_box_scene(), "glb"), filename="asm.glb", options=AnalysisOptions(mass=10.0, densities={"right": 2000.0})
    ).as_dict()
    assert doc["mass"] == pytest.approx(10.0, rel=1e-14)
    assert [p["mass"] for p in doc["parts"]] == pytest.approx([2.0, 8.0], rel=1e-14)


@pytest.mark.parametrize("mass", [10.0, 7.0, 0.3, 3.3])
def test_assembly_total_mass_is_the_requested_one_exactly(mass: float) -> None:
    # three parts of unequal volume: sharing out the requested total and adding it up again rounds
    scene = trimesh.Scene()
    for i, extents in enumerate([(1, 1, 1), (1.3, 0.7, 2.9), (0.1, 3.7, 0.3)]):
        scene.add_geometry(trimesh.creation.box(extents=extents).apply_translation([5.0 * i, 0.3, 0.1]), node_name=f"p{i}")
    doc = analyze(export(scene, "glb"), filename="three.glb", options=AnalysisOptions(mass=mass)).as_dict()
    assert doc["mass"] == mass
    assert sum(p["mass"] for p in doc["parts"]) == pytest.approx(mass, rel=4e-16, abs=0)


def test_single_body_scene_has_no_parts() -> None:
    doc = analyze(export(trimesh.Scene(box_mesh()), "glb"), filename="one.glb").as_dict()
    assert "parts" not in doc


def hex_wedge_pyramid_mesh() -> meshio.Mesh:
    """Unit cube as one hexahedron, a unit wedge beside it, a pyramid on top."""
    pts = np.array(
        [
            [0, 0, 0],
            [1, 0, 0],
            [1, 1, 0],
            [0, 1, 0],
            [0, 0, 1],
            [1, 0, 1],
            [1, 1, 1],
            [0, 1, 1],
            [2, 0, 0],
            [2, 0, 1],
            [0.5, 0.5, 2.0],
        ],
        dtype=float,
    )
    cells = [
        ("hexahedron", np.array([[0, 1, 2, 3, 4, 5, 6, 7]])),
        ("wedge", np.array([[1, 8, 2, 5, 9, 6]])),
        ("pyramid", np.array([[4, 5, 6, 7, 10]])),
    ]
    return meshio.Mesh(pts, cells)


@pytest.mark.parametrize("ext,fmt", [("vtu", "vtu"), ("vtk", "vtk"), ("msh", "gmsh22")])
def test_volume_cells_of_every_kind_integrate_exactly(tmp_path: Path, ext: str, fmt: str) -> None:
    path = tmp_path / f"cells.{ext}"
    meshio.write(path, hex_wedge_pyramid_mesh(), file_format=fmt, **({"binary": False} if fmt.startswith("gmsh") else {}))
    doc = analyze(path, options=AnalysisOptions(density=1.0)).as_dict()
    volumes = [1.0, 0.5, 1.0 / 3.0]  # cube, wedge (triangle 1x1/2 times 1), pyramid (base 1, height 1)
    assert sum(p.get("volume", 0) for p in doc["parts"]) == pytest.approx(sum(volumes), rel=1e-14)
    assert doc["source"]["kind"] == "volume"
    wedge_com = np.array([1 + 1 / 3, 1 / 3, 0.5])
    pyramid_com = np.array([0.5, 0.5, 1.25])  # apex height 1 above the base: a quarter up
    com = (np.array([0.5, 0.5, 0.5]) * 1.0 + wedge_com * 0.5 + pyramid_com / 3) / sum(volumes)
    np.testing.assert_allclose(doc["center_of_mass"], com, rtol=1e-14)


def test_points_files_json_and_csv(tmp_path: Path) -> None:
    pts = [{"mass": 1.0, "position": [0, 0, 0]}, {"mass": 3.0, "position": [2, 0, 0]}]
    (tmp_path / "p.json").write_text(json.dumps(pts))
    (tmp_path / "p.csv").write_text("mass,x,y,z\n1,0,0,0\n3,2,0,0\n")
    expected = 1 * 3 * 4 / 4  # m1 m2 l² / (m1 + m2)
    for name in ("p.json", "p.csv"):
        doc = analyze(tmp_path / name).as_dict()
        assert doc["source"]["kind"] == "points"
        np.testing.assert_allclose(doc["principal"]["moments"][1:], [expected, expected], rtol=1e-15)
        assert doc["classification"]["kind"] == "linear_rotator"


@pytest.mark.parametrize("end", ["\r", "\r\n", "\n"], ids=["cr", "crlf", "lf"])
def test_a_points_csv_reads_the_same_with_any_line_ending(end: str) -> None:
    # a lone \r (classic Mac, some spreadsheet exports) ends a row for the csv module's readers; it had escaped
    # as csv.Error "new-line character seen in unquoted field"
    doc = analyze(end.join(["mass,x,y,z", "1,0,0,0", "3,2,0,0", ""]).encode(), filename="p.csv").as_dict()
    assert doc["mass"] == 4.0 and doc["center_of_mass"] == [1.5, 0.0, 0.0]


def test_a_points_number_past_a_doubles_range_is_an_invalid_parameter() -> None:
    # JSON integers have no limit: 10^400 was float()'s OverflowError, seen only by the catch-all
    data = json.dumps({"points": [{"mass": 1, "position": [10**400, 0, 0]}, {"mass": 1, "position": [0, 0, 0]}]}).encode()
    with pytest.raises(InvalidParameterError, match="point 0 has a number too large for a double"):
        analyze(data, filename="p.json")


def test_truncated_binary_stl_is_unreadable() -> None:
    data = export(box_mesh(), "stl")
    with pytest.raises(UnreadableFileError):
        analyze(data[:-7], filename="cut.stl")


def test_garbage_is_unreadable() -> None:
    with pytest.raises(UnreadableFileError):
        analyze(b"\x00\x01garbage" * 20, filename="junk.ply")


def test_empty_file_is_empty_geometry() -> None:
    with pytest.raises(EmptyGeometryError):
        analyze(b"", filename="empty.stl")


def test_stl_without_triangles_is_empty_geometry() -> None:
    with pytest.raises(EmptyGeometryError):
        analyze(b"solid empty\nendsolid empty\n", filename="empty.stl")


def test_unknown_extension_is_unsupported() -> None:
    with pytest.raises(UnsupportedFormatError) as err:
        analyze(b"whatever", filename="part.xyz123")
    assert err.value.code == "unsupported_format"


def test_content_sniffing_without_a_name() -> None:
    doc = analyze(export(box_mesh(), "stl_ascii")).as_dict()
    assert doc["source"]["format"] == "stl"


def test_gltf_with_external_buffers_is_refused_with_advice() -> None:
    data = trimesh.Scene(box_mesh()).export(file_type="gltf")["model.gltf"]
    with pytest.raises(UnreadableFileError) as err:
        analyze(data, filename="part.gltf")
    assert "same upload" in err.value.message and "gltf_buffer_0.bin" in err.value.message


def test_gltf_with_its_bin_in_one_upload_is_read() -> None:
    files = trimesh.Scene(box_mesh()).export(file_type="gltf")
    pairs = [(name, data if isinstance(data, bytes) else data.encode()) for name, data in files.items()]
    from inertia.load import load_body
    from inertia.pipeline import analyze_loaded

    loaded = load_body(pairs)
    assert loaded.format == "gltf" and loaded.filename == "model.gltf"
    doc = analyze_loaded(loaded, AnalysisOptions()).as_dict()
    assert doc["mass"] == pytest.approx(6000, rel=1e-14)
    import io
    import zipfile

    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        for name, data in pairs:
            zf.writestr(f"export/{name}", data)
    zipped = load_body(buf.getvalue(), filename="part.zip")
    assert analyze_loaded(zipped, AnalysisOptions()).as_dict()["mass"] == pytest.approx(6000, rel=1e-14)


def test_assembly_far_from_the_origin_keeps_every_moment() -> None:
    from benchmarks.exact import exact_eigenvalues, exact_solid

    offset = np.array([1e6, -6e5, 3e5])  # OBJ text keeps float64 coordinates
    left = trimesh.Trimesh(*box(1.0, 1.0, 1.0), process=False)
    right = trimesh.Trimesh(*box(1.0, 2.0, 1.0), process=False)
    left.apply_translation(offset)
    right.apply_translation(offset + np.array([3.0, 1.0, 0.0]))
    scene = trimesh.Scene()
    scene.add_geometry(left, node_name="left", geom_name="left")
    scene.add_geometry(right, node_name="right", geom_name="right")
    doc = analyze(export(scene, "obj", digits=17), filename="far.obj", options=AnalysisOptions(density=1.0)).as_dict()
    vertices = np.vstack([left.vertices, right.vertices])
    faces = np.vstack([left.faces, right.faces + len(left.vertices)])
    exact = sorted(float(x) for x in exact_eigenvalues(exact_solid(vertices, faces)[2]))
    errors = np.abs(np.array(doc["principal"]["moments"]) - exact) / np.array(exact)
    assert doc["diagnostics"]["relative_error_estimate"] <= 1e-12
    assert np.all(errors <= doc["diagnostics"]["relative_error_estimate"])


_LFS = (
    b"version https://git-lfs.github.com/spec/v1\n"
    b"oid sha256:4d7a214614ab2935c943f9e0ff69d22eadbb8f32b1258daaa5e2ca24d17e2393\nsize 12345\n"
)


@pytest.mark.parametrize("name", ["part.stl", "grid.vtk", "model.3mf", "mesh.msh", "m.obj"])
def test_a_git_lfs_pointer_is_named_as_one(name: str, tmp_path: Path) -> None:
    # what a clone without git-lfs holds in place of the file: named as such, whatever the format says
    with pytest.raises(UnreadableFileError, match="Git LFS pointer"):
        analyze(_LFS, filename=name)
    path = tmp_path / name
    path.write_bytes(_LFS)
    with pytest.raises(UnreadableFileError, match="git lfs pull"):
        analyze(str(path))


def test_a_git_lfs_pointer_as_a_zip_or_a_companion_is_named_as_one(tmp_path: Path) -> None:
    with pytest.raises(UnreadableFileError, match="Git LFS pointer"):
        analyze(_LFS, filename="meshes.zip")
    (tmp_path / "meshes.zip").write_bytes(_LFS)
    with pytest.raises(UnreadableFileError, match="Git LFS pointer"):
        analyze(str(tmp_path / "meshes.zip"))
    gltf = b'{"asset": {"version": "2.0"}, "buffers": [{"uri": "model.bin", "byteLength": 12345}]}'
    with pytest.raises(UnreadableFileError, match=r"Git LFS pointer"):
        load_body([("model.gltf", gltf), ("model.bin", _LFS)])


_XDMF = b"""<?xml version="1.0"?>
<Xdmf Version="3.0"><Domain><Grid Name="g" GridType="Uniform">
<Topology TopologyType="Tetrahedron" NumberOfElements="1"><DataItem Dimensions="1 4" NumberType="Int" Format="XML">0 1 2 3
</DataItem></Topology>
<Geometry GeometryType="XYZ"><DataItem Dimensions="4 3" Format="XML">0 0 0 1 0 0 0 1 0 0 0 1</DataItem></Geometry>
</Grid></Domain></Xdmf>
"""


def test_xdmf_without_h5py_names_the_extra_or_is_read() -> None:
    import importlib.util

    # data in the XML itself: read with or without the 'hdf5' extra (the unit corner tetrahedron)
    assert analyze(_XDMF, filename="t.xdmf", options=AnalysisOptions(units="m", density=1.0)).props.mass == pytest.approx(1 / 6)
    if importlib.util.find_spec("h5py") is not None:
        return
    # data in an HDF5 file beside it: without h5py, the refusal names the extra
    hdf = _XDMF.replace(b'Format="XML">0 0 0 1 0 0 0 1 0 0 0 1', b'Format="HDF">t.h5:/geometry')
    with pytest.raises(UnsupportedFormatError, match=r"inertia-service\[hdf5\]"):
        load_body([("t.xdmf", hdf), ("t.h5", b"\x89HDF\r\n\x1a\n" + bytes(64))])


@pytest.mark.parametrize(
    ("missing", "error", "words"),
    [
        ("h5py._errors", UnsupportedFormatError, "cannot be imported"),  # installed, its library broken
        ("lzma", UnreadableFileError, "could not read"),  # any other import a reader makes: the file's failure
    ],
)
def test_an_import_failure_inside_meshio_is_an_answer_not_a_crash(
    missing: str, error: type[Exception], words: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    def broken(*args: Any, **kwargs: Any) -> None:
        raise ImportError(f"No module named {missing!r}", name=missing)

    monkeypatch.setattr(meshio, "read", broken)
    with pytest.raises(error, match=words):
        analyze(_XDMF, filename="t.xdmf")


# --- volume formats holding only a surface ------------------------------------------------------------

_BOX_QUADS = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]  # outward


def _polydata(keyword: str, cells: list[list[int]], sides: tuple[float, float, float]) -> bytes:
    v, _ = box(*sides)
    points = "\n".join(" ".join(repr(float(c)) for c in p) for p in v)
    listed = "\n".join(f"{len(c)} " + " ".join(map(str, c)) for c in cells)
    size = sum(len(c) + 1 for c in cells)
    return (
        f"# vtk DataFile Version 3.0\nbox\nASCII\nDATASET POLYDATA\nPOINTS 8 double\n{points}\n"
        f"{keyword} {len(cells)} {size}\n{listed}\n"
    ).encode()


@pytest.mark.parametrize(
    ("keyword", "cells"),
    [
        ("POLYGONS", _BOX_QUADS),
        # a strip a b d c is the quad a b c d: triangles (a, b, d) and, turned as every odd one is, (d, b, c)
        ("TRIANGLE_STRIPS", [[a, b, d, c] for a, b, c, d in _BOX_QUADS]),
    ],
)
def test_a_closed_vtk_polydata_surface_is_weighed_as_a_solid(keyword: str, cells: list[list[int]]) -> None:
    doc = analyze(_polydata(keyword, cells, (1.0, 2.0, 3.0)), filename="box.vtk", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(6.0, rel=1e-15)
    assert sorted(doc["principal"]["moments"]) == pytest.approx(BOX_MOMENTS_6, rel=1e-14)
    assert doc["source"]["kind"] == "mesh" and doc["source"]["watertight"] is True
    # polydata is a surface by its kind: reading it as one assumes nothing, so nothing is said
    assert doc["warnings"] == []


BOX_MOMENTS_6 = sorted([6 * (4 + 9) / 12, 6 * (1 + 9) / 12, 6 * (1 + 4) / 12])


@pytest.mark.parametrize("fmt", ["vtu", "gmsh22"])
def test_a_closed_triangle_surface_in_a_volume_format_is_weighed_as_a_solid(fmt: str, tmp_path: Path) -> None:
    v, f = box(1.0, 2.0, 3.0)
    name = "box.vtu" if fmt == "vtu" else "box.msh"
    meshio.write(tmp_path / name, meshio.Mesh(v, [("triangle", f)]), file_format=fmt)
    doc = analyze(str(tmp_path / name), options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(6.0, rel=1e-15)
    assert sorted(doc["principal"]["moments"]) == pytest.approx(BOX_MOMENTS_6, rel=1e-14)


def test_an_open_surface_in_a_volume_format_is_not_watertight_and_weighs_as_a_shell() -> None:
    from inertia.errors import NotWatertightError

    data = _polydata("POLYGONS", _BOX_QUADS[1:], (1.0, 2.0, 3.0))  # the bottom left open
    with pytest.raises(NotWatertightError):
        analyze(data, filename="open.vtk")
    shell = analyze(data, filename="open.vtk", options=AnalysisOptions(model="shell", thickness=0.01, density=1.0)).as_dict()
    assert shell["mass"] == pytest.approx((1 * 2 + 2 * 1 * 3 + 2 * 2 * 3) * 0.01, rel=1e-12)  # top, front/back, sides


def test_vtk_pixels_closing_a_box_are_weighed_as_its_solid() -> None:
    # a pixel lists its corners row by row (a b d c of the face a b c d): VTK's cell type 8
    v, _ = box(1.0, 2.0, 3.0)
    points = "\n".join(" ".join(repr(float(c)) for c in p) for p in v)
    cells = "\n".join(f"4 {a} {b} {d} {c}" for a, b, c, d in _BOX_QUADS)
    data = (
        f"# vtk DataFile Version 3.0\nbox\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 8 double\n{points}\n"
        f"CELLS 6 30\n{cells}\nCELL_TYPES 6\n" + "8\n" * 6
    ).encode()
    doc = analyze(data, filename="pixels.vtk", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(6.0, rel=1e-15)
    assert not any("winding" in w for w in doc["warnings"])


def _prism_polydata(sides_as_strip: bool) -> tuple[bytes, float]:
    # a regular pentagonal prism (circumradius 1, height 2): two pentagons and five quads, or the five sides
    # as one triangle strip going round; volume (5/2) sin(72 deg) x 2, exactly that of the rounded corners to 1e-15
    ring = [(math.cos(2 * math.pi * k / 5), math.sin(2 * math.pi * k / 5)) for k in range(5)]
    points = [(x, y, 0.0) for x, y in ring] + [(x, y, 2.0) for x, y in ring]
    caps = [[4, 3, 2, 1, 0], [5, 6, 7, 8, 9]]
    text = "\n".join(" ".join(repr(c) for c in p) for p in points)
    body = f"# vtk DataFile Version 3.0\nprism\nASCII\nDATASET POLYDATA\nPOINTS 10 double\n{text}\n"
    if sides_as_strip:
        strip = [i for k in range(5) for i in (5 + k, k)] + [5, 0]
        body += "POLYGONS 2 12\n" + "\n".join("5 " + " ".join(map(str, c)) for c in caps) + "\n"
        body += f"TRIANGLE_STRIPS 1 {len(strip) + 1}\n{len(strip)} " + " ".join(map(str, strip)) + "\n"
    else:
        quads = [[k, (k + 1) % 5, 5 + (k + 1) % 5, 5 + k] for k in range(5)]
        cells = caps + quads
        listed = "\n".join(f"{len(c)} " + " ".join(map(str, c)) for c in cells)
        body += f"POLYGONS 7 {sum(len(c) + 1 for c in cells)}\n{listed}\n"
    return body.encode(), 2.5 * math.sin(2 * math.pi / 5) * 2.0


@pytest.mark.parametrize("sides_as_strip", [False, True])
def test_a_closed_prism_of_mixed_polygons_or_a_long_strip_is_weighed(sides_as_strip: bool) -> None:
    data, volume = _prism_polydata(sides_as_strip)
    doc = analyze(data, filename="prism.vtk", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(volume, rel=1e-14)
    assert not any("winding" in w for w in doc["warnings"])


def test_a_pixel_listing_three_ids_is_refused_not_misread() -> None:
    data = (
        b"# vtk DataFile Version 3.0\nbad\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 3 double\n0 0 0\n1 0 0\n0 1 0\n"
        b"CELLS 2 8\n3 0 1 2\n3 0 1 2\nCELL_TYPES 2\n5\n8\n"
    )
    with pytest.raises(UnreadableFileError, match="pixel but lists 3 node ids"):
        analyze(data, filename="bad.vtk")


def test_an_abaqus_deck_of_shell_elements_is_not_weighed_as_a_solid() -> None:
    # S4R shells closing a box: their mass is their section's thickness, not the box's volume
    v, _ = box(1.0, 2.0, 3.0)
    nodes = "\n".join(f"{i + 1}, {x!r}, {y!r}, {z!r}" for i, (x, y, z) in enumerate(v.tolist()))
    elements = "\n".join(f"{k + 1}, " + ", ".join(str(i + 1) for i in q) for k, q in enumerate(_BOX_QUADS))
    deck = f"*NODE\n{nodes}\n*ELEMENT, TYPE=S4R, ELSET=SKIN\n{elements}\n".encode()
    with pytest.raises((EmptyGeometryError, UnsupportedFormatError)):
        analyze(deck, filename="skin.inp")


def test_bent_polygons_near_the_top_of_float64_are_an_overflow_not_an_unreadable_file() -> None:
    # a box 1e110 across with one corner pulled out (so its quads are bent): the split note cubed the size in
    # Python floats (OverflowError, reported as a file that "does not follow the format"); the integrals
    # overflow, which is said as such
    import warnings

    from inertia.errors import InvalidParameterError

    v = np.array([[(k & 1), (k >> 1) & 1, (k >> 2) & 1] for k in range(8)], float) * 1e110
    v[7, 2] += 0.5e110
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in v.tolist()]
    lines += ["f " + " ".join(str(i + 1) for i in q) for q in _BOX_QUADS]
    with pytest.raises(InvalidParameterError, match="overflow"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # numpy says so on the way; the answer is the error
        analyze(("\n".join(lines) + "\n").encode(), filename="big.obj")


def test_a_malformed_ascii_stl_vertex_is_named_as_the_file_writes_it() -> None:
    # OpenSCAD's tests/data/stl/invalidvertex.stl: the message showed numpy's repr, np.bytes_(b'blah')
    text = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 blah 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n"
    with pytest.raises(UnreadableFileError) as caught:
        analyze(text, filename="invalidvertex.stl")
    assert "'blah' where a coordinate should be" in caught.value.message and "np." not in caught.value.message
    assert "vertex line (line 5)" in caught.value.message


def test_an_ascii_stl_facet_without_three_vertices_is_named_by_its_line() -> None:
    # OpenSCAD's tests/data/stl/toomanyvertices.stl: a facet of four vertex lines
    facet = "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n{extra}endloop\nendfacet\n"
    text = "solid t\n" + facet.format(extra="") + facet.format(extra="vertex 0 1 1\n") + "endsolid t\n"
    with pytest.raises(UnreadableFileError, match=r"facet at line 9 has 4 vertices, but a facet has three"):
        analyze(text.encode(), filename="toomanyvertices.stl")
