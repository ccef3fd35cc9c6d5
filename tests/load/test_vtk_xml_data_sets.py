"""VTK's serial XML data sets besides .vtu: polydata (.vtp), structured (.vts) and rectilinear (.vtr) grids,
image data (.vti); each read by VTK's own reader for the type the file declares.

Files are written by VTK's own writers.  Expected values: closed forms for boxes, and for a triangulated
sphere an exact rational sum over its triangles of the coordinates VTK reads back (``fractions``).
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from inertia import load_body
from inertia.errors import NotWatertightError, UnsupportedFormatError
from inertia.pipeline import AnalysisOptions, analyze

vtk = pytest.importorskip("vtk")

BOX = (1.0, 2.0, 3.0)


def box_moments(a: float, b: float, c: float, mass: float) -> list[float]:
    return sorted([mass * (b * b + c * c) / 12, mass * (a * a + c * c) / 12, mass * (a * a + b * b) / 12])


def write(writer_class: Any, data_set: Any, path: Path, ascii: bool = False) -> bytes:
    writer = writer_class()
    writer.SetFileName(str(path))
    writer.SetInputData(data_set)
    if ascii:
        writer.SetDataModeToAscii()
    assert writer.Write() == 1
    return path.read_bytes()


def run(data: bytes, filename: str | None, **options: Any) -> dict[str, Any]:
    return analyze(data, filename=filename, options=AnalysisOptions(density=1.0, **options)).as_dict()


def cube_source() -> Any:
    """VTK's cube: six quads with their own corners (24 points, welded by coordinates), float32 points."""
    cube = vtk.vtkCubeSource()
    cube.SetXLength(BOX[0])
    cube.SetYLength(BOX[1])
    cube.SetZLength(BOX[2])
    cube.SetCenter(10.0, -4.0, 0.5)
    cube.Update()
    return cube.GetOutput()


def test_a_closed_polydata_file_is_weighed_as_a_solid(tmp_path: Path) -> None:
    doc = run(write(vtk.vtkXMLPolyDataWriter, cube_source(), tmp_path / "cube.vtp"), "cube.vtp")
    assert doc["source"]["format"] == "vtp" and doc["source"]["kind"] == "mesh" and doc["source"]["watertight"] is True
    assert doc["mass"] == pytest.approx(6.0, rel=1e-15)
    assert doc["center_of_mass"] == pytest.approx([10.0, -4.0, 0.5], rel=1e-15)
    assert sorted(doc["principal"]["moments"]) == pytest.approx(box_moments(*BOX, 6.0), rel=1e-14)
    assert doc["warnings"] == []  # a polydata file is a surface by its kind: nothing was assumed


def exact_solid(points: np.ndarray, triangles: np.ndarray) -> tuple[Fraction, list[Fraction], list[list[Fraction]]]:
    """Volume, first moments and second moments (int x_i x_j dV) of a closed triangle surface, exactly."""
    p = [[Fraction(float(c)) for c in row] for row in points]
    vol = Fraction(0)
    first = [Fraction(0)] * 3
    second = [[Fraction(0)] * 3 for _ in range(3)]
    for i, j, k in triangles.tolist():
        a, b, c = p[i], p[j], p[k]
        det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])
        vol += det / 6
        s = [a[m] + b[m] + c[m] for m in range(3)]
        for m in range(3):
            first[m] += det * s[m] / 24
            for n in range(3):  # tetrahedron (0, a, b, c): det/120 (sum v v^T + s s^T)
                second[m][n] += det * (a[m] * a[n] + b[m] * b[n] + c[m] * c[n] + s[m] * s[n]) / 120
    return vol, first, second


def test_a_triangulated_sphere_matches_the_exact_sum_over_its_triangles(tmp_path: Path) -> None:
    sphere = vtk.vtkSphereSource()
    sphere.SetThetaResolution(24)
    sphere.SetPhiResolution(13)
    sphere.SetRadius(0.75)
    sphere.SetCenter(0.25, 0.5, -2.0)
    sphere.SetOutputPointsPrecision(1)  # double
    sphere.Update()
    data = write(vtk.vtkXMLPolyDataWriter, sphere.GetOutput(), tmp_path / "sphere.vtp")
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(tmp_path / "sphere.vtp"))
    reader.Update()
    out = reader.GetOutput()
    pts = np.array([out.GetPoint(i) for i in range(out.GetNumberOfPoints())])
    polys = out.GetPolys()
    ids = vtk.vtkIdList()
    polys.InitTraversal()
    tris = []
    while polys.GetNextCell(ids):
        tris.append([ids.GetId(k) for k in range(ids.GetNumberOfIds())])
    vol, first, second = exact_solid(pts, np.array(tris))
    com = [f / vol for f in first]
    doc = run(data, "sphere.vtp")
    assert doc["mass"] == pytest.approx(float(vol), rel=1e-14)
    assert doc["center_of_mass"] == pytest.approx([float(c) for c in com], rel=1e-14)
    about = [[second[m][n] - vol * com[m] * com[n] for n in range(3)] for m in range(3)]
    trace = about[0][0] + about[1][1] + about[2][2]
    tensor = [[float((trace if m == n else 0) - about[m][n]) for n in range(3)] for m in range(3)]
    assert np.allclose(doc["inertia_tensor"], tensor, rtol=0, atol=1e-14 * float(trace))


def test_polydata_lines_and_vertices_are_left_out_by_name(tmp_path: Path) -> None:
    cube = cube_source()
    lines = vtk.vtkCellArray()
    line = vtk.vtkIdList()
    for i in (0, 1):
        line.InsertNextId(i)
    lines.InsertNextCell(line)
    cube.SetLines(lines)
    doc = run(write(vtk.vtkXMLPolyDataWriter, cube, tmp_path / "c.vtp"), "c.vtp")
    assert doc["mass"] == pytest.approx(6.0, rel=1e-15)
    assert any("1 line" in w and "left out" in w for w in doc["warnings"])


def test_an_open_polydata_surface_is_refused_as_not_watertight(tmp_path: Path) -> None:
    plane = vtk.vtkPlaneSource()
    plane.Update()
    with pytest.raises(NotWatertightError):
        run(write(vtk.vtkXMLPolyDataWriter, plane.GetOutput(), tmp_path / "p.vtp"), "p.vtp")


def test_image_data_is_its_voxels_and_says_its_values_weight_nothing(tmp_path: Path) -> None:
    image = vtk.vtkImageData()
    image.SetDimensions(3, 4, 5)  # 2 x 3 x 4 voxels
    image.SetSpacing(0.5, 1.0, 2.0)
    image.SetOrigin(100.0, 0.0, -3.0)
    doc = run(write(vtk.vtkXMLImageDataWriter, image, tmp_path / "box.vti"), "box.vti")
    assert doc["source"]["format"] == "vti" and doc["source"]["kind"] == "volume"
    size = (1.0, 3.0, 8.0)
    assert doc["mass"] == pytest.approx(24.0, rel=1e-14)
    assert doc["center_of_mass"] == pytest.approx([100.5, 1.5, 1.0], rel=1e-14)
    assert sorted(doc["principal"]["moments"]) == pytest.approx(box_moments(*size, 24.0), rel=1e-14)
    assert doc["warnings"] == []
    scalars = vtk.vtkFloatArray()
    scalars.SetName("CT")
    for i in range(60):
        scalars.InsertNextValue(float(i))
    image.GetPointData().SetScalars(scalars)
    doc = run(write(vtk.vtkXMLImageDataWriter, image, tmp_path / "ct.vti"), "ct.vti")
    assert doc["mass"] == pytest.approx(24.0, rel=1e-14)
    assert any("24 voxels" in w and "'CT'" in w for w in doc["warnings"])


def test_image_data_cell_density_weights_its_voxels(tmp_path: Path) -> None:
    image = vtk.vtkImageData()
    image.SetDimensions(3, 2, 2)  # two unit voxels along x
    density = vtk.vtkDoubleArray()
    density.SetName("density")
    density.InsertNextValue(1000.0)
    density.InsertNextValue(3000.0)
    image.GetCellData().AddArray(density)
    data = write(vtk.vtkXMLImageDataWriter, image, tmp_path / "two.vti")
    doc = analyze(data, filename="two.vti").as_dict()
    assert doc["mass"] == pytest.approx(4000.0, rel=1e-14)
    assert doc["center_of_mass"][0] == pytest.approx((1000 * 0.5 + 3000 * 1.5) / 4000, rel=1e-14)
    assert not any("voxels" in w for w in doc["warnings"])


def test_rectilinear_and_structured_grids(tmp_path: Path) -> None:
    xs, ys, zs = [0.0, 1.0, 3.0], [0.0, 2.0], [0.0, 0.5, 1.0]
    rect = vtk.vtkRectilinearGrid()
    rect.SetDimensions(len(xs), len(ys), len(zs))
    for setter, values in ((rect.SetXCoordinates, xs), (rect.SetYCoordinates, ys), (rect.SetZCoordinates, zs)):
        arr = vtk.vtkDoubleArray()
        for v in values:
            arr.InsertNextValue(v)
        setter(arr)
    doc = run(write(vtk.vtkXMLRectilinearGridWriter, rect, tmp_path / "r.vtr", ascii=True), "r.vtr")
    assert doc["source"]["format"] == "vtr"
    assert doc["mass"] == pytest.approx(6.0, rel=1e-14)
    assert sorted(doc["principal"]["moments"]) == pytest.approx(box_moments(3.0, 2.0, 1.0, 6.0), rel=1e-14)

    structured = vtk.vtkStructuredGrid()
    structured.SetDimensions(len(xs), len(ys), len(zs))
    pts = vtk.vtkPoints()
    pts.SetDataTypeToDouble()
    for z in zs:
        for y in ys:
            for x in xs:
                pts.InsertNextPoint(x, y, z + 0.25 * x * y)  # sheared: warped faces, the volume unchanged
    structured.SetPoints(pts)
    doc = run(write(vtk.vtkXMLStructuredGridWriter, structured, tmp_path / "s.vts"), "s.vts")
    assert doc["source"]["format"] == "vts"
    assert doc["mass"] == pytest.approx(6.0, rel=1e-14)


def test_the_data_set_type_the_file_declares_chooses_the_reader(tmp_path: Path) -> None:
    data = write(vtk.vtkXMLPolyDataWriter, cube_source(), tmp_path / "cube.vtp")
    named_wrongly = run(data, "cube.vtu")  # ParaView would pick its reader by the name and fail
    unnamed = analyze(data, options=AnalysisOptions(density=1.0)).as_dict()
    assert unnamed["source"]["format"] == "vtp"
    for doc in (named_wrongly, unnamed):
        assert doc["mass"] == pytest.approx(6.0, rel=1e-15)


def test_a_data_set_type_we_do_not_read_is_refused_by_name(tmp_path: Path) -> None:
    blocks = vtk.vtkMultiBlockDataSet()
    blocks.SetBlock(0, cube_source())
    writer = vtk.vtkXMLMultiBlockDataWriter()
    writer.SetFileName(str(tmp_path / "m.vtm"))
    writer.SetInputData(blocks)
    assert writer.Write() == 1
    with pytest.raises(UnsupportedFormatError) as info:
        load_body((tmp_path / "m.vtm").read_bytes(), filename="m.vtp")
    assert "vtkMultiBlockDataSet" in info.value.message


def test_the_formats_endpoint_lists_them_by_kind() -> None:
    from fastapi.testclient import TestClient

    from inertia.api.app import create_app

    with TestClient(create_app()) as client:
        body = client.get("/v1/formats").json()
    assert "vtp" in body["surface"]
    assert {"vts", "vtr", "vti"} <= set(body["volume"])


@pytest.mark.parametrize("writer", ["xml", "legacy"])
def test_image_points_are_computed_in_double_not_float32(tmp_path: Path, writer: str) -> None:
    """An image's points are origin + i spacing: with a spacing float32 cannot hold (0.1), VTK's default
    output precision put the volume 6e-9 off (pyvista's HierarchicalBoxDataset) under a 7e-14 estimate."""
    image = vtk.vtkImageData()
    image.SetDimensions(4, 3, 2)  # 3 x 2 x 1 voxels
    image.SetSpacing(0.1, 0.3, 0.7)
    image.SetOrigin(0.3, -1.1, 2.9)
    cls, name = (vtk.vtkXMLImageDataWriter, "g.vti") if writer == "xml" else (vtk.vtkDataSetWriter, "g.vtk")
    doc = run(write(cls, image, tmp_path / name), name)
    size = [Fraction(3) * Fraction(0.1), Fraction(2) * Fraction(0.3), Fraction(0.7)]
    mass = size[0] * size[1] * size[2]
    assert abs(doc["mass"] - float(mass)) <= 1e-15 * float(mass)
    assert doc["diagnostics"]["relative_error_estimate"] >= abs(doc["mass"] - float(mass)) / float(mass)
