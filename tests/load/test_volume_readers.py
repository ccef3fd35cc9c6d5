"""Volume readers: VTK files as VTK reads them, never a crash, companion files.

Files are written by VTK's own writers (or by hand where a writer would not
produce the oddity), and the expected volumes come from VTK
(``vtkCellSizeFilter``) for linear cells, from VTK's shape functions
integrated independently (``volref``) for curved ones.
"""

from __future__ import annotations

import contextlib
import io
import sys
import zipfile
from pathlib import Path
from typing import Any

import meshio
import numpy as np
import pytest

from inertia import load_body
from inertia.errors import EmptyGeometryError, LoadError, NotWatertightError, UnreadableFileError, UnsupportedFormatError
from inertia.load.volume import VTK_CELL_TYPES
from inertia.mass import assembly_properties, mass_properties
from inertia.pipeline import AnalysisOptions, analyze, analyze_loaded
from tests.support.bodies import meshed

vtk = pytest.importorskip("vtk")
volref = pytest.importorskip("tests.load.volref")  # needs vtk

HEX = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]


def grid(cells: list[tuple[int, list[int]]], points: np.ndarray, density: list[float] | None = None) -> Any:
    ug = vtk.vtkUnstructuredGrid()
    pts = vtk.vtkPoints()
    pts.SetDataTypeToDouble()  # VTK stores float32 unless told
    for p in np.asarray(points, dtype=float):
        pts.InsertNextPoint(*p)
    ug.SetPoints(pts)
    for ctype, ids in cells:
        idl = vtk.vtkIdList()
        for i in ids:
            idl.InsertNextId(int(i))
        ug.InsertNextCell(ctype, idl)
    if density is not None:
        arr = vtk.vtkDoubleArray()
        arr.SetName("density")
        for d in density:
            arr.InsertNextValue(d)
        ug.GetCellData().AddArray(arr)
    return ug


def write_vtu(ug: float, path: Path, mode: str = "appended", compressor: str | None = "zlib", encode: bool = True) -> bytes:
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(str(path))
    w.SetInputData(ug)
    {"appended": w.SetDataModeToAppended, "binary": w.SetDataModeToBinary, "ascii": w.SetDataModeToAscii}[mode]()
    w.SetEncodeAppendedData(encode)
    {
        None: w.SetCompressorTypeToNone,
        "zlib": w.SetCompressorTypeToZLib,
        "lz4": w.SetCompressorTypeToLZ4,
        "lzma": w.SetCompressorTypeToLZMA,
    }[compressor]()
    assert w.Write() == 1
    return path.read_bytes()


def write_legacy(ug: float, path: Path, binary: bool = False) -> bytes:
    w = vtk.vtkUnstructuredGridWriter()
    w.SetFileName(str(path))
    w.SetInputData(ug)
    if binary:
        w.SetFileTypeToBinary()
    assert w.Write() == 1
    return path.read_bytes()


def points_as_vtk_reads_them(path: Path) -> np.ndarray:
    """The coordinates VTK reads back (a legacy ASCII file keeps fewer digits than float64 has)."""
    reader = vtk.vtkXMLUnstructuredGridReader() if path.suffix == ".vtu" else vtk.vtkUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    data = reader.GetOutput().GetPoints().GetData()
    return np.array([data.GetTuple3(i) for i in range(data.GetNumberOfTuples())])


def vtk_volume(ug: float) -> float:
    f = vtk.vtkCellSizeFilter()
    f.SetInputData(ug)
    f.Update()
    vols = f.GetOutput().GetCellData().GetArray("Volume")
    # signed by each cell's node order (an inverted wedge comes out negative): sizes are the absolute values
    return float(sum(abs(vols.GetValue(i)) for i in range(vols.GetNumberOfTuples())))


def volume_of(data: bytes, filename: str) -> float:
    loaded = load_body(data, filename=filename)
    if loaded.is_assembly:
        return assembly_properties([(meshed(p.body), 1.0) for p in loaded.parts]).mass
    return mass_properties(meshed(loaded.body), density=1.0).mass


def warped_hexes() -> tuple[np.ndarray, list[tuple[int, list[int]]]]:
    """Two hexahedra sharing a face, with warped (non-planar) outer faces."""
    pts = np.array(HEX + [(x, y, z + 1) for x, y, z in HEX[4:]], dtype=float)
    pts[6] += (0.1, 0.05, 0.3)
    pts[9] += (-0.05, 0.0, 0.4)
    return pts, [(12, list(range(8))), (12, [4, 5, 6, 7, 8, 9, 10, 11])]


# ---------------------------------------------------------------------------------------------
# VTK's formats, as VTK reads them


@pytest.mark.parametrize("mode", ["appended", "binary", "ascii"])
@pytest.mark.parametrize("compressor", [None, "zlib", "lz4", "lzma"])
def test_vtu_data_modes_and_compressors_read_as_vtk_reads_them(tmp_path: Path, mode: str, compressor: str | None) -> None:
    pts, cells = warped_hexes()
    ug = grid(cells, pts)
    data = write_vtu(ug, tmp_path / "m.vtu", mode, compressor)
    reference = sum(volref.reference_integrals("hexahedron", pts[ids])[0] for _, ids in cells)
    assert volume_of(data, "m.vtu") == pytest.approx(reference, rel=1e-14)


def test_raw_appended_data_is_read(tmp_path: Path) -> None:
    pts, cells = warped_hexes()
    data = write_vtu(grid(cells, pts), tmp_path / "raw.vtu", "appended", None, encode=False)
    assert b'encoding="raw"' in data
    reference = sum(volref.reference_integrals("hexahedron", pts[ids])[0] for _, ids in cells)
    assert volume_of(data, "raw.vtu") == pytest.approx(reference, rel=1e-14)


def test_linear_cells_agree_with_vtks_cell_sizes_where_vtk_is_exact(tmp_path: Path) -> None:
    """Tetrahedra, planar-faced hexahedra, wedges and pyramids: VTK's own volumes (vtkCellSizeFilter)."""
    rng = np.random.default_rng(3)
    affine = np.eye(3) + 0.2 * rng.uniform(-1, 1, (3, 3))
    base = np.array(HEX, dtype=float) @ affine.T
    apex = base[:4].mean(axis=0) + affine @ np.array([0.0, 0.0, 1.0])
    pts = np.vstack([base, base + affine @ np.array([2.0, 0, 0]), apex])
    cells = [(12, list(range(8))), (13, [8, 9, 12, 11, 10, 13]), (14, [0, 1, 2, 3, 16]), (10, [8, 9, 11, 16])]
    ug = grid(cells, pts)
    for name, data in [("m.vtu", write_vtu(ug, tmp_path / "m.vtu")), ("m.vtk", write_legacy(ug, tmp_path / "m.vtk"))]:
        as_read = grid(cells, points_as_vtk_reads_them(tmp_path / name))
        assert volume_of(data, name) == pytest.approx(vtk_volume(as_read), rel=1e-14)


@pytest.mark.parametrize("ext", ["vtu", "vtk"])
def test_voxels_are_read_in_vtks_node_order(tmp_path: Path, ext: str) -> None:
    pts = np.array([(0, 0, 0), (2, 0, 0), (0, 3, 0), (2, 3, 0), (0, 0, 5), (2, 0, 5), (0, 3, 5), (2, 3, 5)], float)
    ug = grid([(11, list(range(8)))], pts)
    data = write_vtu(ug, tmp_path / f"v.{ext}") if ext == "vtu" else write_legacy(ug, tmp_path / f"v.{ext}")
    props = mass_properties(meshed(load_body(data, filename=f"v.{ext}").body), density=1.0)
    assert props.mass == pytest.approx(30.0, rel=1e-15) == vtk_volume(ug)
    # a box 2 x 3 x 5: I_xx = m (b^2 + c^2) / 12
    np.testing.assert_allclose(
        np.diag(props.inertia.matrix), 30 * np.array([3**2 + 5**2, 2**2 + 5**2, 2**2 + 3**2]) / 12, rtol=1e-14
    )


@pytest.mark.parametrize("name", ["tetra10", "hexahedron20", "hexahedron27", "wedge15", "wedge18", "pyramid13"])
@pytest.mark.parametrize("ext", ["vtu", "vtk"])
def test_quadratic_cells_in_vtk_files(tmp_path: Path, name: str, ext: str) -> None:
    rng = np.random.default_rng(11)
    nodes = volref.parametric_nodes(name) + 0.05 * rng.uniform(-1, 1, (len(volref.parametric_nodes(name)), 3))
    if name == "pyramid13":
        nodes[4] = (0.5, 0.5, 1.0)
        nodes[9:13] = 0.5 * (nodes[[0, 1, 2, 3]] + nodes[4])
    ug = grid([(volref.VTK_TYPE_IDS[name], list(range(len(nodes))))], nodes, density=[2500.0])
    data = write_vtu(ug, tmp_path / f"q.{ext}") if ext == "vtu" else write_legacy(ug, tmp_path / f"q.{ext}")
    props = mass_properties(meshed(load_body(data, filename=f"q.{ext}").body))
    m0 = volref.reference_integrals(name, points_as_vtk_reads_them(tmp_path / f"q.{ext}"))[0]
    assert props.mass == pytest.approx(2500.0 * m0, rel=1e-13)  # the cell's own density


def test_legacy_cell_lists_longer_than_the_type_use_vtks_first_ids(tmp_path: Path) -> None:
    """A hexahedron20 written with the linear type 12: VTK uses the first 8 ids, and we say so."""
    corners = np.array(HEX, dtype=float) * 2
    edges = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]
    pts = np.vstack([corners, [(corners[a] + corners[b]) / 2 for a, b in edges]])
    text = [
        "# vtk DataFile Version 3.0",
        "hex20 as type 12",
        "ASCII",
        "DATASET UNSTRUCTURED_GRID",
        f"POINTS {len(pts)} double",
        *(" ".join(repr(float(v)) for v in p) for p in pts),
        "CELLS 1 21",
        "20 " + " ".join(map(str, range(20))),
        "CELL_TYPES 1",
        "12",
        "",
    ]
    data = "\n".join(text).encode()
    path = tmp_path / "long.vtk"
    path.write_bytes(data)
    reader = vtk.vtkUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    loaded = load_body(data, filename="long.vtk")
    props = mass_properties(meshed(loaded.body), density=1.0)
    assert props.mass == pytest.approx(vtk_volume(reader.GetOutput()), rel=1e-14) == 8.0
    assert any("first 8" in w for w in props.warnings)


def test_legacy_cell_lists_shorter_than_the_type_are_refused() -> None:
    text = "\n".join(
        [
            "# vtk DataFile Version 3.0",
            "short",
            "ASCII",
            "DATASET UNSTRUCTURED_GRID",
            "POINTS 4 double",
            "0 0 0",
            "1 0 0",
            "0 1 0",
            "0 0 1",
            "CELLS 1 5",
            "4 0 1 2 3",
            "CELL_TYPES 1",
            "12",
            "",
        ]
    )
    with pytest.raises(LoadError) as info:
        load_body(text.encode(), filename="short.vtk")
    assert "hexahedron" in info.value.message


def test_cell_density_arrays_apply_to_every_cell_kind(tmp_path: Path) -> None:
    pts, cells = warped_hexes()
    data = write_vtu(grid(cells, pts, density=[1000.0, 3000.0]), tmp_path / "d.vtu")
    doc = analyze(data, filename="d.vtu").as_dict()
    v = [volref.reference_integrals("hexahedron", pts[ids])[0] for _, ids in cells]
    assert doc["mass"] == pytest.approx(1000 * v[0] + 3000 * v[1], rel=1e-13)
    assert doc["source"]["cells"] == 2


def test_surface_only_vtk_file_says_what_it_holds(tmp_path: Path) -> None:
    pts = np.array([(0, 0, 0), (1, 0, 0), (0, 1, 0)], float)
    # 2-D cells are read as a surface (refused when open, as an STL is), and the note says what the file held
    data = write_vtu(grid([(5, [0, 1, 2])], pts), tmp_path / "tri.vtu")
    loaded = load_body(data, filename="tri.vtu")
    assert "its 1 surface cell (1 triangle)" in loaded.parts[0].body.warnings[0]
    with pytest.raises(NotWatertightError):
        analyze_loaded(loaded, AnalysisOptions())
    # lines only: nothing to read as a surface either
    lines = write_vtu(grid([(3, [0, 1]), (3, [1, 2])], pts), tmp_path / "lines.vtu")
    with pytest.raises(EmptyGeometryError) as info:
        load_body(lines, filename="lines.vtu")
    assert "2 line" in info.value.message and "found: none" not in info.value.message


def test_cells_we_cannot_integrate_refuse_the_file_rather_than_vanish(tmp_path: Path) -> None:
    pts = np.array(HEX, float)
    ug = grid([(12, list(range(8)))], pts)
    # a Lagrange hexahedron (type 72) beside it
    ids = vtk.vtkIdList()
    for i in range(8):
        ids.InsertNextId(i)
    ug.InsertNextCell(72, ids)
    data = write_vtu(ug, tmp_path / "lagrange.vtu")
    with pytest.raises(UnsupportedFormatError) as info:
        load_body(data, filename="lagrange.vtu")
    assert "Lagrange hexahedron" in info.value.message


def test_every_vtk_type_we_map_is_a_3d_cell_of_the_right_size() -> None:
    for type_id, name in VTK_CELL_TYPES.items():
        cell = vtk.vtkGenericCell()
        cell.SetCellType(type_id)
        assert cell.GetCellDimension() == 3
        assert cell.GetNumberOfPoints() in (0, volref.vtk_cell(name).GetNumberOfPoints())


def test_without_the_vtk_extra_vtk_files_get_a_message_naming_it(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    pts, cells = warped_hexes()
    data = write_vtu(grid(cells, pts), tmp_path / "m.vtu")
    for module in ("vtkmodules.vtkIOXML", "vtkmodules.vtkIOLegacy"):
        monkeypatch.setitem(sys.modules, module, None)
    with pytest.raises(UnsupportedFormatError) as info:
        load_body(data, filename="m.vtu")
    assert "inertia-service[vtk]" in info.value.message and info.value.code == "unsupported_format"


# ---------------------------------------------------------------------------------------------
# never a crash, never chatter


GARBAGE = [
    b"",
    b"\x00\x01\x02garbage" * 50,
    b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 3\n",
    b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 3 double\n0 0",
    b'<?xml version="1.0"?><VTKFile type="UnstructuredGrid"><UnstructuredGrid><Piece NumberOfPoints="2"',
    "caf\u00e9 \u2603".encode("utf-16"),
    b"*NODE\n1, 0, 0\n*ELEMENT, TYPE=C3D8\n1, 1, 2\n",
    b"MeshVersionFormatted 2\nDimension 3\nVertices\n2\n0 0 0 1\n",
]


@pytest.mark.parametrize(
    "ext", ["vtu", "vtp", "vts", "vtr", "vti", "vtk", "msh", "mesh", "inp", "xdmf", "med", "f3grid", "dat", "ugrid", "ele"]
)
@pytest.mark.parametrize("blob", range(len(GARBAGE)))
def test_broken_files_are_classified_errors_without_chatter(capfd: pytest.CaptureFixture[str], ext: str, blob: int) -> None:
    with pytest.raises(LoadError) as info:
        load_body(GARBAGE[blob], filename=f"broken.{ext}")
    out, err = capfd.readouterr()
    assert out == "" and err == ""
    message = info.value.message
    assert "/tmp" not in message and "upload." not in message and "Traceback" not in message
    # a TetGen .ele alone names its .node, which the command line then reads from beside it
    expected = ("unreadable_file", "empty_geometry", "unsupported_format") + (("external_reference",) if ext == "ele" else ())
    assert info.value.code in expected


def test_meshio_sys_exit_becomes_unreadable_file(capfd: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(UnreadableFileError) as info:
        load_body(b"$MeshFormat\n9.9 0 8\n$EndMeshFormat\n", filename="future.msh")
    assert "future.msh" in info.value.message
    assert capfd.readouterr() == ("", "")


def test_cli_json_stays_json_on_a_broken_volume_file(tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    import json

    from inertia.cli import main

    path = tmp_path / "broken.msh"
    path.write_bytes(b"$MeshFormat\n9.9 0 8\n$EndMeshFormat\n")
    with contextlib.suppress(SystemExit):
        main(["analyze", str(path), "--json"])
    out, err = capfd.readouterr()
    if out.strip():
        json.loads(out)
    assert str(tmp_path) not in out + err.replace(str(path), "")


# ---------------------------------------------------------------------------------------------
# companion files


def tetgen_files() -> tuple[bytes, bytes]:
    node = b"5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n"
    ele = b"2 4 0\n1 1 2 3 4\n2 2 3 4 5\n"
    return node, ele


def test_tetgen_ele_with_its_node_file_as_pairs_and_as_a_zip() -> None:
    node, ele = tetgen_files()
    expected = 1 / 6 + 1 / 3  # the corner tetrahedron; the second has |det [e1 e2 e3]| = 2
    pairs = load_body([("cube/mesh.ele", ele), ("cube/mesh.node", node)])
    assert pairs.format == "ele" and pairs.filename == "mesh.ele"
    assert assembly_properties([(meshed(p.body), 1.0) for p in pairs.parts]).mass == pytest.approx(expected, rel=1e-15)
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("mesh.node", node)
        zf.writestr("mesh.ele", ele)
    zipped = load_body(buf.getvalue(), filename="mesh.zip")
    assert assembly_properties([(meshed(p.body), 1.0) for p in zipped.parts]).mass == pytest.approx(expected, rel=1e-15)


def test_tetgen_ele_alone_asks_for_its_node_file() -> None:
    _, ele = tetgen_files()
    with pytest.raises(UnreadableFileError) as info:
        load_body(ele, filename="mesh.ele")
    assert ".node" in info.value.message


def test_an_upload_of_several_meshes_is_refused() -> None:
    node, ele = tetgen_files()
    with pytest.raises(LoadError) as info:
        load_body([("a.ele", ele), ("b.ele", ele), ("a.node", node)])
    assert "a.ele" in info.value.message and "b.ele" in info.value.message


def test_meshio_reorders_gmsh_quadratic_cells_to_vtk_order(tmp_path: Path) -> None:
    """A curved tetra10 through Gmsh's format: meshio's node reordering, then our element."""
    nodes = volref.parametric_nodes("tetra10") + np.random.default_rng(2).uniform(-0.04, 0.04, (10, 3))
    path = tmp_path / "t.msh"
    meshio.write(path, meshio.Mesh(nodes, [("tetra10", np.arange(10)[None, :])]), file_format="gmsh", binary=False)
    props = mass_properties(meshed(load_body(path).body), density=1.0)
    assert props.mass == pytest.approx(volref.reference_integrals("tetra10", nodes)[0], rel=1e-13)


def test_analyze_options_still_apply_to_volume_cells(tmp_path: Path) -> None:
    pts, cells = warped_hexes()
    data = write_vtu(grid(cells, pts), tmp_path / "m.vtu")
    doc = analyze(data, filename="m.vtu", options=AnalysisOptions(mass=2.0)).as_dict()
    assert doc["mass"] == pytest.approx(2.0, rel=1e-14)


@pytest.mark.parametrize("kind", ["image", "rectilinear", "structured"])
def test_structured_vtk_data_sets_are_their_voxels_and_hexahedra(tmp_path: Path, kind: str) -> None:
    """Legacy STRUCTURED_POINTS, RECTILINEAR_GRID and STRUCTURED_GRID files: the cells VTK makes of them."""
    xs, ys, zs = [0.0, 1.0, 3.0], [0.0, 2.0], [0.0, 0.5, 1.0, 4.0]
    if kind == "image":
        data_set = vtk.vtkImageData()
        data_set.SetDimensions(3, 2, 4)
        data_set.SetSpacing(1.5, 2.0, 0.5)
        expected = (2 * 1.5) * 2.0 * (3 * 0.5)
    elif kind == "rectilinear":
        data_set = vtk.vtkRectilinearGrid()
        data_set.SetDimensions(len(xs), len(ys), len(zs))
        for setter, values in ((data_set.SetXCoordinates, xs), (data_set.SetYCoordinates, ys), (data_set.SetZCoordinates, zs)):
            arr = vtk.vtkDoubleArray()
            for v in values:
                arr.InsertNextValue(v)
            setter(arr)
        expected = 3.0 * 2.0 * 4.0
    else:
        data_set = vtk.vtkStructuredGrid()
        data_set.SetDimensions(len(xs), len(ys), len(zs))
        pts = vtk.vtkPoints()
        pts.SetDataTypeToDouble()
        for z in zs:
            for y in ys:
                for x in xs:
                    pts.InsertNextPoint(x, y, z + 0.25 * x * y)  # sheared: hexahedra with warped faces
        data_set.SetPoints(pts)
        expected = 3.0 * 2.0 * 4.0  # the shear moves top and bottom alike: volume unchanged
    writer = vtk.vtkDataSetWriter()
    writer.SetFileName(str(tmp_path / "grid.vtk"))
    writer.SetInputData(data_set)
    assert writer.Write() == 1
    assert volume_of((tmp_path / "grid.vtk").read_bytes(), "grid.vtk") == pytest.approx(expected, rel=1e-14)


def test_alternating_cell_types_make_one_part_per_type(tmp_path: Path) -> None:
    """Cells of two types interleaved: two parts (one per type), each cell keeping its own density."""
    pts = np.array([*HEX, *[(x + 1.0, y, z) for x, y, z in HEX]], dtype=float)
    cells = []
    density = []
    for k in range(6):
        offset = 8 * (k % 2)
        cells.append((12, [i + offset for i in range(8)]) if k % 3 else (10, [offset, offset + 1, offset + 3, offset + 4]))
        density.append(1000.0 + k)
    data = write_vtu(grid(cells, pts, density=density), tmp_path / "mixed.vtu")
    loaded = load_body(data, filename="mixed.vtu")
    assert [p.name for p in loaded.parts] == ["tetra_0", "hexahedron_1"]
    expected = sum(rho * (1.0 if ctype == 12 else 1 / 6) for (ctype, _), rho in zip(cells, density))
    assert assembly_properties([(meshed(p.body), None) for p in loaded.parts]).mass == pytest.approx(expected, rel=1e-14)


def test_an_mfem_mesh_is_named_as_such_not_misread_as_medit() -> None:
    # MFEM's format shares the .mesh extension with Medit's; meshio answered "Unknown keyword 'MFEM'"
    data = b"MFEM mesh v1.0\n\ndimension\n3\n\nelements\n1\n1 4 0 1 2 3\n"
    with pytest.raises(UnsupportedFormatError, match="is an MFEM mesh"):
        analyze(data, filename="beam-tet.mesh")


@pytest.mark.parametrize("ext", ["vtu", "vtk"])
@pytest.mark.parametrize("ghost", [0, 1, 2, 32, 33])
def test_ghost_cells_are_left_out_as_vtks_integration_leaves_them(tmp_path: Path, ext: str, ghost: int) -> None:
    # a piece of a parallel data set carries its neighbour's cells marked vtkGhostType: they were weighed
    points = np.array([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (3, 0, 0), (5, 0, 0), (3, 2, 0), (3, 0, 2)], float)
    ug = grid([(vtk.VTK_TETRA, [0, 1, 2, 3]), (vtk.VTK_TETRA, [4, 5, 6, 7])], points)
    marks = vtk.vtkUnsignedCharArray()
    marks.SetName("vtkGhostType")
    marks.InsertNextValue(0)
    marks.InsertNextValue(ghost)
    ug.GetCellData().AddArray(marks)
    integrate = vtk.vtkIntegrateAttributes()
    integrate.SetInputData(ug)
    integrate.Update()
    expected = integrate.GetOutput().GetCellData().GetArray("Volume").GetValue(0)  # VTK's own figure
    path = tmp_path / f"piece.{ext}"
    data = write_vtu(ug, path) if ext == "vtu" else write_legacy(ug, path)
    doc = analyze(data, filename=path.name).as_dict()
    assert doc["mass"] / doc["density"] == pytest.approx(expected, rel=1e-14)
    assert any("ghost" in w for w in doc["warnings"]) is bool(ghost & 33)


def test_a_surface_cell_apart_from_the_volume_is_named(tmp_path: Path) -> None:
    points = np.array([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (5, 0, 0), (6, 0, 0), (5, 1, 0)], float)
    apart = grid([(vtk.VTK_TETRA, [0, 1, 2, 3]), (vtk.VTK_TRIANGLE, [4, 5, 6])], points)
    face = grid([(vtk.VTK_TETRA, [0, 1, 2, 3]), (vtk.VTK_TRIANGLE, [0, 1, 2])], points)
    docs = [
        analyze(write_vtu(ug, tmp_path / f"{name}.vtu"), filename=f"{name}.vtu").as_dict()
        for name, ug in (("a", apart), ("f", face))
    ]
    assert docs[0]["mass"] == docs[1]["mass"] == pytest.approx(1000 / 6, rel=1e-14)
    assert any("3 points that no 3-D cell uses" in w for w in docs[0]["warnings"])
    assert not any("no 3-D cell uses" in w for w in docs[1]["warnings"])


MEDIT_TET = "Vertices{v}4\n0 0 0 1\n0.1 0 0 1\n0 0.1 0 1\n0 0 0.1 1\nTetrahedra{t}1\n1 2 3 4 0\nEnd\n"


@pytest.mark.parametrize(
    ("head", "v", "t"),
    [
        ("MeshVersionFormatted 2\nDimension 3\n", "\n", "\n"),  # as libMeshb writes it
        ("MeshVersionFormatted\n2\n\nDimension\n3\n", "\n", "\n"),  # keyword and number on two lines
        ("MeshVersionFormatted 2\r\nDimension 3\r\n", " ", " "),  # counts beside their keywords
    ],
)
def test_medit_keywords_and_numbers_are_tokens_as_libmeshb_reads_them(head: str, v: str, t: str) -> None:
    """libMeshb reads whitespace-separated tokens; meshio reads lines and failed on the last two layouts."""
    data = (head + MEDIT_TET.format(v=v, t=t)).encode()
    doc = analyze(data, filename="tet.mesh", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(0.1**3 / 6, rel=1e-15)


def test_medit_version_1_reals_are_single_precision_as_mmg_reads_them() -> None:
    """MeshVersionFormatted 1 means single-precision reals, in text files too: MMG scans them with "%f"
    into a float (mmg3d inout.c, mesh->ver < 2), and meshio reads them as float32."""
    data = ("MeshVersionFormatted 1\nDimension 3\n" + MEDIT_TET.format(v="\n", t="\n")).encode()
    doc = analyze(data, filename="tet.mesh", options=AnalysisOptions(density=1.0)).as_dict()
    a = float(np.float32(0.1))
    assert doc["mass"] == pytest.approx(a**3 / 6, rel=1e-15)
    assert abs(doc["mass"] - 0.1**3 / 6) > 1e-8 * doc["mass"]  # not the decimal's double


def test_medit_blocks_that_weigh_nothing_are_read_past_whatever_their_layout() -> None:
    """MmgTools' Ridges with a blank line after its count (meshio counts lines and stopped there), and ParMmg's
    parallel communicators of a distributed mesh's piece (meshio: "Unknown keyword")."""
    head = "MeshVersionFormatted 2\nDimension 3\n" + MEDIT_TET.format(v="\n", t="\n").replace("End\n", "")
    tail = "Ridges\n2\n\n1\n2\nParallelTriangleCommunicators\n1\n3 7 0\nParallelCommunicatorTriangles\n2\n1 0 0\n2 1 0\nEnd\n"
    doc = analyze((head + tail).encode(), filename="piece.mesh", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(0.1**3 / 6, rel=1e-15)


@pytest.mark.parametrize(("dimension", "word"), [(2, "two"), (1, "one")])
def test_medit_meshes_of_lower_dimension_are_refused_as_such(dimension: int, word: str) -> None:
    # bamg's geometry files (Dimension 2, with keywords meshio does not know) and 1-D meshes ("no points" before)
    text = f"MeshVersionFormatted 1\nDimension {dimension}\nMaximalAngleOfCorner 46\nVertices\n2\n" + "0 0 1\n1 0 1\nEnd\n"
    with pytest.raises(EmptyGeometryError) as info:
        analyze(text.encode(), filename="geometry.mesh")
    assert f"{word}-dimensional" in info.value.message


XDMF_XML = """<?xml version="1.0"?>
<Xdmf Version="3.0"><Domain><Grid Name="mesh" GridType="Uniform">
<Topology TopologyType="Tetrahedron" NumberOfElements="1" NodesPerElement="4">
<DataItem Dimensions="1 4" NumberType="Int" Format="XML">0 1 2 3</DataItem></Topology>
<Geometry GeometryType="XYZ"><DataItem Dimensions="4 3" Format="XML">0 0 0 2 0 0 0 2 0 0 0 2</DataItem></Geometry>
</Grid></Domain></Xdmf>
"""


def test_an_xdmf_file_with_its_data_in_its_xml_needs_no_hdf5() -> None:
    # dolfinx's test meshes: meshio imports h5py before reading any data item, so without h5py such a file was
    # refused as needing it (the test extras install no h5py: this runs without it)
    doc = analyze(XDMF_XML.encode(), filename="cube.xdmf", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(8 / 6, rel=1e-15)
    assert doc["center_of_mass"] == pytest.approx([0.5, 0.5, 0.5], rel=1e-15)
    assert "h5py" not in sys.modules or hasattr(sys.modules["h5py"], "File")  # no stand-in left behind


def test_a_damaged_files_own_bytes_quoted_by_its_reader_are_shown_printable() -> None:
    # a copy of three.js's liver.vtk damaged by a text conversion: VTK quotes the bytes it stopped at
    data = b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 float\n0 0 0\nva\xef\xbf\xbd\x19\x07b\n"
    with pytest.raises(LoadError) as info:
        load_body(data, filename="liver.vtk")
    assert info.value.message.isprintable() and "\ufffd" not in info.value.message


@pytest.mark.parametrize("mode", ["ASCII", "BINARY"])
def test_a_legacy_vtk_file_of_field_data_alone_says_so(mode: str) -> None:
    # pyvista's vtk-data financial.vtk has this layout: FIELD where DATASET would stand; vtkDataSetReader
    # answered "did not create output for port 0"
    data = f"# vtk DataFile Version 2.0\nfinancial records\n{mode}\n\nFIELD records 1\ntime 1 3 float\n".encode()
    data += b"1 2 3\n" if mode == "ASCII" else np.array([1, 2, 3], dtype=">f4").tobytes()
    with pytest.raises(EmptyGeometryError, match="holds field data alone \\(FIELD where a legacy VTK file's DATASET"):
        load_body(data, filename="records.vtk")


def test_the_document_type_xdmf_files_declare_is_read_an_entity_still_refused() -> None:
    # dolfinx and legacy FEniCS write <!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>: a DTD named, nothing declared
    from inertia.errors import ExternalReferenceError

    declaration = '<?xml version="1.0"?>\n'
    named = XDMF_XML.replace(declaration, declaration + '<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>\n', 1)
    doc = analyze(named.encode(), filename="cube.xdmf", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(8 / 6, rel=1e-15)
    hostile = XDMF_XML.replace(declaration, declaration + '<!DOCTYPE Xdmf [<!ENTITY e SYSTEM "file:///etc/hostname">]>\n', 1)
    with pytest.raises(ExternalReferenceError, match="declares a document type or entities"):
        analyze(hostile.encode(), filename="cube.xdmf")


def test_an_xdmf_time_series_is_weighed_by_its_mesh(tmp_path: Path) -> None:
    # a temporal collection of grids over one mesh (results over time, as dolfinx and meshio write them; each
    # step includes the mesh by an XInclude xpointer into the same document): the corner tetrahedron of
    # edge 2, volume 8/6, centroid (1/2, 1/2, 1/2)
    points = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]])
    path = tmp_path / "series.xdmf"
    with meshio.xdmf.TimeSeriesWriter(str(path), data_format="XML") as writer:
        writer.write_points_cells(points, [("tetra", np.array([[0, 1, 2, 3]]))])
        for t in (0.0, 1.0):
            writer.write_data(t, point_data={"u": np.full(4, t)})
    assert b'CollectionType="Temporal"' in path.read_bytes()
    doc = analyze(path.read_bytes(), filename="series.xdmf", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(8 / 6, rel=1e-15)
    assert doc["center_of_mass"] == pytest.approx([0.5, 0.5, 0.5], rel=1e-15)


def test_an_xdmf_binary_item_is_the_uploads_file_never_one_in_the_working_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # meshio reads a Binary item's name relative to the process's working directory: a decoy there (the
    # corner tetrahedron of edge 5) must not be read in place of the upload's own file (edge 1, volume 1/6)
    monkeypatch.chdir(tmp_path)
    np.array([[0, 0, 0], [5, 0, 0], [0, 5, 0], [0, 0, 5]], dtype=np.float32).tofile("pts.bin")
    upload = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32).tobytes()
    doc = (
        b'<Xdmf Version="3.0"><Domain><Grid Name="mesh" GridType="Uniform"><Geometry GeometryType="XYZ">'
        b'<DataItem Dimensions="4 3" Format="Binary" DataType="Float" Precision="4">pts.bin</DataItem></Geometry>'
        b'<Topology TopologyType="Tetrahedron" NumberOfElements="1"><DataItem Dimensions="1 4" Format="XML" '
        b'DataType="Int">0 1 2 3</DataItem></Topology></Grid><Grid Name="ts" GridType="Collection" '
        b'CollectionType="Temporal"><Grid Name="s" GridType="Uniform"><Time Value="0"/></Grid></Grid></Domain></Xdmf>'
    )
    loaded = load_body([("a.xdmf", doc), ("pts.bin", upload)])
    props = analyze_loaded(loaded, AnalysisOptions(density=1.0)).as_dict()
    assert props["mass"] == pytest.approx(1 / 6, rel=1e-12)


@pytest.mark.parametrize(
    "declaration",
    [
        '<!DOCTYPE Xdmf SYSTEM "file:///etc/passwd" []>',  # a DTD named by a URL or a path is no bare name
        '<!DOCTYPE Xdmf PUBLIC "-//x" "http://example.org/x.dtd">',
    ],
)
def test_a_document_type_naming_a_dtd_by_path_or_url_is_refused(declaration: str) -> None:
    from inertia.errors import ExternalReferenceError

    declared = XDMF_XML.replace('<?xml version="1.0"?>\n', '<?xml version="1.0"?>\n' + declaration + "\n", 1)
    with pytest.raises(ExternalReferenceError, match="declares a document type or entities"):
        analyze(declared.encode(), filename="cube.xdmf")


def test_an_xinclude_href_after_a_quoted_angle_bracket_is_still_checked() -> None:
    from inertia.errors import ExternalReferenceError

    tricked = XDMF_XML.replace("<Domain>", '<Domain><xi:include xpointer="a>b" href="/etc/passwd"/>', 1)
    with pytest.raises(ExternalReferenceError, match="XInclude href '/etc/passwd'"):
        analyze(tricked.encode(), filename="cube.xdmf")


def _series(inner: str) -> bytes:
    return (
        '<?xml version="1.0"?><Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude"><Domain>' + inner + "</Domain></Xdmf>"
    ).encode()


def _grid(name: str, edge: int, extra: str = "") -> str:
    return (
        f'<Grid Name="{name}" GridType="Uniform"><Geometry GeometryType="XYZ"><DataItem Dimensions="4 3" Format="XML">'
        f'0 0 0 {edge} 0 0 0 {edge} 0 0 0 {edge}</DataItem></Geometry><Topology TopologyType="Tetrahedron" '
        f'NumberOfElements="1"><DataItem Dimensions="1 4" Format="XML" DataType="Int">0 1 2 3</DataItem></Topology>'
        f"{extra}</Grid>"
    )


def test_an_xdmf_time_series_beside_two_meshes_is_refused_one_that_moves_is_weighed_at_its_first_step() -> None:
    temporal = '<Grid Name="ts" GridType="Collection" CollectionType="Temporal">{}</Grid>'
    two = _series(_grid("mesh", 1) + _grid("other", 2) + temporal.format(_grid("s", 1, '<Time Value="0"/>')))
    with pytest.raises(UnsupportedFormatError, match="holds 2 meshes beside its time series"):
        analyze(two, filename="two.xdmf")
    moving = _series(temporal.format(_grid("a", 1, '<Time Value="0"/>') + _grid("b", 2, '<Time Value="1"/>')))
    doc = analyze(moving, filename="moving.xdmf", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(1 / 6, rel=1e-12)  # the first step's tetrahedron of edge 1
    assert any("2 steps each carry their own mesh; the mesh of its first step was weighed" in w for w in doc["warnings"])
