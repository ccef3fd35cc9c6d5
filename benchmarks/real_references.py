"""References for the real volume and CAD files, computed by the files' own tools (not by this project).

    python -m benchmarks.real_references     # rewrites tests/data/real/{vtk,vtu,inp,vtkxml}/vtk_reference.json,
                                             # tests/data/real/3mf_production/lib3mf_reference.json
                                             # and tests/data/real/step/gmsh_reference.json

VTK files (legacy ``.vtk``, XML ``.vtu``, AVS UCD ``.inp``): read by VTK's own
readers (``vtkDataSetReader``, ``vtkXMLUnstructuredGridReader``,
``vtkAVSucdReader``; other data sets merged to an unstructured grid by
``vtkAppendFilter``), then every 3-D cell integrated with VTK's own element
definition: its interpolation functions and their derivatives
(``InterpolateFunctions``, ``InterpolateDerivs``) at the points of a
Gauss-Legendre product rule on the cell's parametric domain (the unit cube;
for tetrahedra and wedges the collapsed cube, Duffy's map), so that volume,
first and second moments are sum(w det J), sum(w det J x), sum(w det J x x^T).
With ``ORDER`` points per direction the rule is exact for every polynomial
element VTK defines up to the triquadratic hexahedron.  A cell whose
Jacobian keeps one sign counts with its absolute volume (VTK's own cell
sizes are signed: an inverted cell is the same solid); a cell whose Jacobian
changes sign is integrated with its sign, as ``vtkCellSizeFilter`` does.
Polyhedra and pentagonal or hexagonal prisms, which VTK defines by their
faces, are split by VTK's own ``Triangulate`` and each tetrahedron integrated
exactly (with its absolute volume; ``vtkCellSizeFilter``'s cell volumes are
checked to agree).

VTK's other XML data sets (``.vtp``, ``.vts``, ``.vtr``, ``.vti``) are read by
the XML reader of their type.  Grids are integrated as above (their points
merged in double precision: an image's are computed from its origin and
spacing).  A polydata file is a surface: its polygons and triangle strips as
VTK stores them (strips split as ``vtkTriangleStrip`` does, every other
triangle turned; polygons as fans from their first corner, the reading the
service documents for polygons that are not planar), kept where every edge,
once bit-identical points are merged, is used once in each direction, and
integrated exactly in rational arithmetic (``benchmarks/exact.py``), turned
outward where its volume comes out negative.

STEP files: imported by Gmsh's OpenCASCADE kernel (``gmsh.model.occ``) in
millimetres, each volume's ``getMass``, ``getCenterOfMass`` and
``getMatrixOfInertia`` combined (parallel axes) and converted back to the
file's own unit (``STEP_UNITS`` below, read from the file's ``LENGTH_UNIT``).
``getMass`` integrates each face with a fixed Gauss order, which is not
converged on some NURBS faces: so the volume is checked against Gmsh's own
surface mesh (``Mesh.MeshSizeFromCurvature`` 80 and 160 elements per 2 pi,
closed triangles summed as signed tetrahedra to the origin, extrapolated as
h^2; its precision ``mesh_rtol`` is the extrapolation's own step).  Where the
two disagree by more than three times that (and more than ``STEP_CHECK``)
the file's reference is the extrapolated volume alone, to the precision the
two meshes support (``rtol``), without a tensor.
"""

from __future__ import annotations

import itertools
import json
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
REAL = ROOT / "tests" / "data" / "real"
ORDER = 8
_SIMPLEX = {10, 24}  # tetrahedra: r + s + t <= 1
_WEDGE = {13, 26, 32}  # wedges: r + s <= 1, 0 <= t <= 1
_NOT_INTEGRATED: set[int] = set()
_BY_FACES = {15, 16, 42}  # pentagonal and hexagonal prisms, polyhedra: VTK's own split into tetrahedra
# STEP files and the length unit their solids are written in (mm per unit): the reference is in file units
STEP_UNITS = {
    "featuretype.STEP": 25.4,
    "base_interface_AP214.STEP": 25.4,
    "base_interface_AP203.STEP": 25.4,
    "red_cube_blue_cylinder.step": 1000.0,
    "as1_pe_203.stp": 25.4,
}


def read_data_set(path: Path) -> Any:
    """The data set as VTK's reader for the file's extension reads it."""
    from vtkmodules import vtkIOXML
    from vtkmodules.vtkIOGeometry import vtkAVSucdReader
    from vtkmodules.vtkIOLegacy import vtkDataSetReader

    readers: dict[str, Any] = {
        ".vtu": vtkIOXML.vtkXMLUnstructuredGridReader,
        ".vtp": vtkIOXML.vtkXMLPolyDataReader,
        ".vts": vtkIOXML.vtkXMLStructuredGridReader,
        ".vtr": vtkIOXML.vtkXMLRectilinearGridReader,
        ".vti": vtkIOXML.vtkXMLImageDataReader,
        ".inp": vtkAVSucdReader,
    }
    reader: Any = readers.get(path.suffix.lower(), vtkDataSetReader)()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def read_vtk(path: Path) -> Any:
    from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm
    from vtkmodules.vtkFiltersCore import vtkAppendFilter

    grid = read_data_set(path)
    if grid.GetClassName() != "vtkUnstructuredGrid":
        merge = vtkAppendFilter()
        merge.SetOutputPointsPrecision(vtkAlgorithm.DOUBLE_PRECISION)
        merge.SetInputData(grid)
        merge.Update()
        grid = merge.GetOutput()
    return grid


def _rule(cell_type: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(ORDER)
    x, w = (x + 1) / 2, w / 2
    u, v, t = (a.ravel() for a in np.meshgrid(x, x, x, indexing="ij"))
    weights = np.einsum("i,j,k->ijk", w, w, w).ravel()
    if cell_type in _SIMPLEX:
        return np.c_[u, v * (1 - u), t * (1 - u) * (1 - v)], weights * (1 - u) ** 2 * (1 - v)
    if cell_type in _WEDGE:
        return np.c_[u, v * (1 - u), t], weights * (1 - u)
    return np.c_[u, v, t], weights


def vtk_moments(grid: Any) -> tuple[float, np.ndarray, np.ndarray, dict[int, int]]:
    """Volume, first and second moments (unit density) of the 3-D cells; counts of the cells left out by type."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    to_numpy: Any = vtk_to_numpy  # untyped in VTK's wheel
    points = np.asarray(to_numpy(grid.GetPoints().GetData()), dtype=np.float64)
    by_type: dict[int, list[int]] = {}
    for i in range(grid.GetNumberOfCells()):
        by_type.setdefault(grid.GetCellType(i), []).append(i)
    m0, m1, m2 = 0.0, np.zeros(3), np.zeros((3, 3))
    skipped: dict[int, int] = {}
    for cell_type, ids in sorted(by_type.items()):
        cell = grid.GetCell(ids[0])
        if cell.GetCellDimension() != 3 or cell_type in _NOT_INTEGRATED:
            skipped[cell_type] = len(ids)
            continue
        if cell_type in _BY_FACES:
            v, first, second = _split_moments(grid, ids)
            m0, m1, m2 = m0 + v, m1 + first, m2 + second
            continue
        n = cell.GetNumberOfPoints()
        pcoords, weights = _rule(cell_type)
        shape = np.zeros((len(pcoords), n))
        derivs = np.zeros((len(pcoords), 3, n))
        for q, p in enumerate(pcoords):
            f, d = [0.0] * n, [0.0] * (3 * n)
            cell.InterpolateFunctions(list(p), f)
            cell.InterpolateDerivs(list(p), d)
            shape[q], derivs[q] = f, np.reshape(d, (3, n))
        conn = np.array([[grid.GetCell(i).GetPointId(k) for k in range(n)] for i in ids])
        x = points[conn]
        xq = np.einsum("qn,cnd->cqd", shape, x)
        det = np.linalg.det(np.einsum("qjn,cnd->cqjd", derivs, x))
        wdet = det * weights[None, :]
        sign = np.where(wdet.sum(axis=1) < 0, -1.0, 1.0)[:, None]  # an inverted cell is the same solid
        wdet = wdet * sign
        m0 += float(wdet.sum())
        m1 += np.einsum("cq,cqd->d", wdet, xq)
        m2 += np.einsum("cq,cqd,cqe->de", wdet, xq, xq)
    return m0, m1, m2, skipped


def _split_moments(grid: Any, ids: list[int]) -> tuple[float, np.ndarray, np.ndarray]:
    """Moments of cells split into tetrahedra by VTK (``Triangulate``), each tetrahedron exactly (closed form)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkCommonCore import vtkIdList, vtkPoints

    to_numpy: Any = vtk_to_numpy
    points = np.asarray(to_numpy(grid.GetPoints().GetData()), dtype=np.float64)
    m0, m1, m2 = 0.0, np.zeros(3), np.zeros((3, 3))
    for i in ids:
        split = vtkIdList()
        grid.GetCell(i).Triangulate(0, split, vtkPoints())  # the points it also returns are float32: ids are used
        t = points[[split.GetId(k) for k in range(split.GetNumberOfIds())]].reshape(-1, 4, 3)
        v = np.abs(np.einsum("ij,ij->i", t[:, 1] - t[:, 0], np.cross(t[:, 2] - t[:, 0], t[:, 3] - t[:, 0]))) / 6
        c = t.sum(axis=1)  # sum of the four corners
        m0 += float(v.sum())
        m1 += (v[:, None] * c).sum(axis=0) / 4
        # integral of x x^T over a tetrahedron: V/20 (sum_i x_i x_i^T + (sum x_i)(sum x_i)^T)
        m2 += np.einsum("t,tkd,tke->de", v, t, t) / 20 + np.einsum("t,td,te->de", v, c, c) / 20
    return m0, m1, m2


def _about_centre(m0: float, m1: np.ndarray, m2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c = m1 / m0
    s = m2 - m0 * np.outer(c, c)
    return c, np.trace(s) * np.eye(3) - s


def polydata_triangles(data: Any) -> tuple[np.ndarray, np.ndarray]:
    """Points (float64) and the triangles of a polydata's polygons and strips, as VTK stores them."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    to_numpy: Any = vtk_to_numpy  # untyped
    points = np.asarray(to_numpy(data.GetPoints().GetData()), dtype=np.float64).reshape(-1, 3)
    tris: list[list[int]] = []
    for cells, strip in ((data.GetPolys(), False), (data.GetStrips(), True)):
        offsets = np.asarray(to_numpy(cells.GetOffsetsArray()), dtype=np.int64)
        conn = np.asarray(to_numpy(cells.GetConnectivityArray()), dtype=np.int64)
        for start, stop in itertools.pairwise(offsets.tolist()):
            ids = conn[start:stop].tolist()
            for k in range(len(ids) - 2):
                if strip:
                    a, b = (ids[k + 1], ids[k]) if k % 2 else (ids[k], ids[k + 1])
                    tris.append([a, b, ids[k + 2]])
                else:
                    tris.append([ids[0], ids[k + 1], ids[k + 2]])
    return points, np.array(tris, dtype=np.int64).reshape(-1, 3)


def closed_and_consistent(points: np.ndarray, tris: np.ndarray) -> bool:
    """Every edge used once in each direction, once bit-identical points are merged."""
    _, ids = np.unique(points + 0.0, axis=0, return_inverse=True)
    t = ids.reshape(-1)[tris]
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])]
    directed = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    forward, count_f = np.unique(directed, axis=0, return_counts=True)
    backward, count_b = np.unique(directed[:, ::-1], axis=0, return_counts=True)
    return bool(len(t)) and np.array_equal(forward, backward) and np.array_equal(count_f, count_b) and bool(np.all(count_f == 1))


def surface_reference(path: Path) -> dict[str, Any] | None:
    from benchmarks.exact import exact_solid

    data = read_data_set(path)
    if data.GetPoints() is None:
        return None  # not polydata VTK can read (a multi-block file named .vtp): the service refuses it
    points, tris = polydata_triangles(data)
    if not closed_and_consistent(points, tris):
        return None  # open or inconsistently wound: the service refuses it or repairs it, no reading to compare
    volume, centre, tensor = exact_solid(points, tris)
    if volume < 0:  # wound inward as stored
        volume, tensor = -volume, [[-v for v in row] for row in tensor]
    return {
        "volume": float(volume),
        "center": [float(c) for c in centre],
        "inertia_unit_density": [[float(v) for v in row] for row in tensor],
        "reader": f"VTK {_vtk_version()} XML polydata reader; polygons as first-corner fans, exact rational integration",
    }


def vtk_references(folder: Path) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for path in sorted(folder.iterdir()):
        if path.suffix.lower() == ".vtp":
            ref = surface_reference(path)
            if ref:
                out[path.name] = ref
            continue
        if path.suffix.lower() not in (".vtk", ".vtu", ".inp", ".vts", ".vtr", ".vti"):
            continue
        m0, m1, m2, skipped = vtk_moments(read_vtk(path))
        if m0 <= 0 or any(t in _NOT_INTEGRATED for t in skipped):
            continue  # no 3-D cells, or cells the service refuses: no number to compare
        c, inertia = _about_centre(m0, m1, m2)
        out[path.name] = {
            "volume": m0,
            "center": c.tolist(),
            "inertia_unit_density": inertia.tolist(),
            "reader": f"VTK {_vtk_version()}, Gauss-Legendre {ORDER}^3 on each cell's own interpolation",
        }
    return out


def _vtk_version() -> str:
    from vtkmodules.vtkCommonCore import vtkVersion

    return str(vtkVersion.GetVTKVersion())


STEP_CHECK = 1e-6


def _gmsh_mesh_volume(curvature: int) -> float:
    """The volume enclosed by Gmsh's surface mesh of the current model (model units)."""
    import gmsh

    gmsh.model.mesh.clear()
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", curvature)
    gmsh.model.mesh.generate(2)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    x = np.zeros((int(tags.max()) + 1, 3))
    x[tags.astype(int)] = np.reshape(coords, (-1, 3))
    volume = 0.0
    for _, tag in gmsh.model.getEntities(2):
        _, _, nodes = gmsh.model.mesh.getElements(2, tag)
        for nn in nodes:
            t = x[np.asarray(nn, dtype=int).reshape(-1, 3)]
            volume += float(np.einsum("ij,ij->", t[:, 0], np.cross(t[:, 1], t[:, 2]))) / 6
    return abs(volume)


def gmsh_references(folder: Path) -> dict[str, Any]:
    import gmsh

    out: dict[str, Any] = {}
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        for name, mm in STEP_UNITS.items():
            gmsh.clear()
            gmsh.model.occ.importShapes(str(folder / name))
            gmsh.model.occ.synchronize()
            m0, m1, m2 = 0.0, np.zeros(3), np.zeros((3, 3))
            for _, tag in gmsh.model.getEntities(3):
                v = gmsh.model.occ.getMass(3, tag) / mm**3
                c = np.array(gmsh.model.occ.getCenterOfMass(3, tag)) / mm
                j = np.reshape(gmsh.model.occ.getMatrixOfInertia(3, tag), (3, 3)) / mm**5  # about the volume's centre
                s = np.trace(j) / 2 * np.eye(3) - j + v * np.outer(c, c)  # second moment about the origin
                m0, m1, m2 = m0 + v, m1 + v * c, m2 + s
            c, inertia = _about_centre(m0, m1, m2)
            coarse, fine = (_gmsh_mesh_volume(n) / mm**3 for n in (80, 160))
            meshed = fine - (coarse - fine) / 3  # h^2 extrapolation
            entry: dict[str, Any] = {
                "volume": m0,
                "center": c.tolist(),
                "inertia_unit_density": inertia.tolist(),
                "reader": f"Gmsh {gmsh.__version__} OpenCASCADE getMass/getCenterOfMass/getMatrixOfInertia",
                "unit_mm": mm,
                "mesh_volume": meshed,
            }
            mesh_rtol = abs(fine - coarse) / 3 / meshed  # the extrapolation's own step: its precision
            entry["mesh_rtol"] = mesh_rtol
            if abs(meshed - m0) > max(STEP_CHECK, 3 * mesh_rtol) * m0:
                entry.update(
                    volume=meshed,
                    rtol=max(mesh_rtol, 1e-9),
                    inertia_unit_density=None,
                    reader=f"Gmsh {gmsh.__version__} surface mesh, extrapolated (getMass gave {m0!r}, not converged)",
                )
            out[name] = entry
    finally:
        gmsh.finalize()
    return out


# 3MF packages whose references come from lib3mf, the 3MF Consortium's own library (``pip install lib3mf``): it
# stores coordinates in single precision, so its reading is within ~1e-7 of the file's decimal coordinates
# (the service reads them as doubles), and these references are compared to LIB3MF_RTOL
LIB3MF_RTOL = 1e-6


def lib3mf_reference(path: Path) -> dict[str, Any]:
    """The build of a 3MF package as lib3mf reads it: every build item's ``model`` objects (components followed,
    each transform applied as the specification's row-vector matrices), placed in the build's frame in the
    file's unit, integrated exactly in rational arithmetic."""
    import lib3mf

    from benchmarks.exact import exact_solid

    model = lib3mf.get_wrapper().CreateModel()
    model.QueryReader("3mf").ReadFromFile(str(path))
    vertices: list[np.ndarray] = []
    faces: list[np.ndarray] = []

    def matrix(transform: Any) -> np.ndarray:
        rows = np.array([list(r) for r in transform.Fields], dtype=np.float64)  # 4 x 3, applied to row vectors
        out = np.eye(4)
        out[:3, :3] = rows[:3].T
        out[:3, 3] = rows[3]
        return out

    def place(resource: Any, placement: np.ndarray) -> None:
        if resource.GetType() != lib3mf.ObjectType.Model:
            return  # support and other objects are not weighed (core specification, chapter 4.1)
        if resource.IsMeshObject():
            mesh = model.GetMeshObjectByID(resource.GetResourceID())
            v = np.array([list(x.Coordinates) for x in mesh.GetVertices()], dtype=np.float64)
            f = np.array([list(x.Indices) for x in mesh.GetTriangleIndices()], dtype=np.int64)
            faces.append(f + sum(len(x) for x in vertices))
            vertices.append(v @ placement[:3, :3].T + placement[:3, 3])
            if np.linalg.det(placement[:3, :3]) < 0:
                faces[-1] = faces[-1][:, [0, 2, 1]]
            return
        components = model.GetComponentsObjectByID(resource.GetResourceID())
        for i in range(components.GetComponentCount()):
            part = components.GetComponent(i)
            inner = matrix(part.GetTransform()) if part.HasTransform() else np.eye(4)
            place(part.GetObjectResource(), placement @ inner)

    items = model.GetBuildItems()
    while items.MoveNext():
        item = items.GetCurrent()
        place(item.GetObjectResource(), matrix(item.GetObjectTransform()) if item.HasObjectTransform() else np.eye(4))
    volume, centre, tensor = exact_solid(np.concatenate(vertices), np.concatenate(faces))
    return {
        "volume": float(volume),
        "center": [float(c) for c in centre],
        "inertia_unit_density": [[float(v) for v in row] for row in tensor],
        "rtol": LIB3MF_RTOL,
        "reader": f"lib3mf {'.'.join(map(str, lib3mf.get_wrapper().GetLibraryVersion()))}, single-precision coordinates; "
        "build items and components placed, exact rational integration",
    }


def main() -> int:
    for sub in ("vtk", "vtu", "inp", "vtkxml"):
        refs = vtk_references(REAL / sub)
        if refs:
            (REAL / sub / "vtk_reference.json").write_text(json.dumps(refs, indent=1) + "\n")
        print(f"{sub}: {len(refs)} references")
    refs = {p.name: lib3mf_reference(p) for p in sorted((REAL / "3mf_production").glob("*.3mf"))}
    (REAL / "3mf_production" / "lib3mf_reference.json").write_text(json.dumps(refs, indent=1) + "\n")
    print(f"3mf_production: {len(refs)} references")
    refs = gmsh_references(REAL / "step")
    (REAL / "step" / "gmsh_reference.json").write_text(json.dumps(refs, indent=1) + "\n")
    print(f"step: {len(refs)} references")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
