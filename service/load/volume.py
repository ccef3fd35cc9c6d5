"""Volume meshes: VTK files through VTK's own readers, the other formats through meshio.

Decision (measured with meshio 5.3.5 and VTK 9.7 on files written by VTK's own
writers, see ``tests/load/test_volume_readers.py``): meshio reads VTK's XML
files with raw, base64, zlib and lzma data, but

- raises ``AssertionError`` on lz4-compressed XML data,
- drops voxel cells (VTK type 11) without a word, so a voxel file came back
  as "no 3-D cells",
- raises ``KeyError`` on quadratic wedges and pyramids (types 26, 27) in both
  legacy and XML files (its table of cell dimensions lacks them; for the
  other formats we add the two entries, see ``_MESHIO_MISSING_DIMENSIONS``),
- refuses (or, with other counts, misreads) a legacy file whose cell lists
  hold more node ids than the cell type uses, which VTK reads with the
  first ids of each list,

so ``.vtk`` and ``.vtu`` files are read by VTK's readers (``vtkDataSetReader``,
``vtkXMLUnstructuredGridReader``): the body is then the one VTK and ParaView
show.  VTK is the optional extra ``vtk``; without it these two formats are
refused (415 ``unsupported_format``) with a message naming the extra, rather
than read by a reader that can get them wrong.  Other formats (Gmsh, Abaqus,
Medit, TetGen, ...) go through meshio, which converts their node orders to
VTK's.  An ``.inp`` file is Abaqus unless its content is AVS UCD (the other
format with that extension, binary or ASCII, see ``is_avs_ucd``), which
VTK's ``vtkAVSucdReader`` reads: meshio took it for Abaqus and answered "no
points" or a UTF-8 decoding error.  Abaqus decks are scanned for their
element types first (``_admit_abaqus_types``): solid variants meshio does not
name (lower case, C3D8T, C3D4H, DC3D10, ...) are taken as the solid of their
node count, other elements (springs, masses, user elements) refuse the file
by name, and shells, beams or trusses beside the solids are said to be left
out (their mass needs their sections).

Every reader call is fenced: anything it raises (``SystemExit`` from meshio's
``sys.exit(1)`` included; never ``KeyboardInterrupt``) becomes an
``UnreadableFileError`` whose message names the file (never a temporary
path) and what to do, and whatever the library prints is captured, not
written to our stdout or stderr.

Cells: linear tetrahedra stay a closed-form kernel (``VolumeBody.tets``);
every other 3-D cell becomes a ``CellBlock`` integrated as its element
(``cells``), voxels reordered to hexahedra.  VTK's cells bounded by flat
polygons (pentagonal and hexagonal prisms, polyhedra) become tetrahedra
(``_polyhedra``): prisms as VTK itself splits them, polyhedra from a
corner when their faces close them with one winding and they are
star-shaped from there (else the file is refused, naming the cell); bent
faces are said in a warning with the volume they put in doubt.  A 3-D cell
type we cannot integrate refuses the file (it is never dropped).

A file with no 3-D cells whose linear 2-D cells (triangles, quads, polygons,
VTK pixels and triangle strips: VTK polydata, a Gmsh surface mesh) may close
a solid is one surface part, read as an STL is (``_surface_part``), with a
warning saying so; the solid path weighs it when closed and refuses it as
``not_watertight`` when open.  Not for Abaqus: its 2-D elements are shells
and membranes, whose mass is their sections'.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import itertools
import os
import re
import sys
import tempfile
import threading
import types
import warnings
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..body import CellBlock, MeshBody, Part, VolumeBody, stored_eps
from ..cells import CELL_NODES, VOXEL_TO_HEXAHEDRON
from ..errors import EmptyGeometryError, ExternalReferenceError, InputTooLargeError, UnreadableFileError, UnsupportedFormatError
from .guard import INFLATE_RATIO, XDMF_DATA_ITEM, inflate_budget, own_name, refuse_reference, xml_attributes
from .polygons import fan_split_note, fan_triangles
from .sniff import VOLUME_FORMATS, VTK_FORMATS, VTK_XML_TYPES, vtk_xml_root_type

__all__ = ["read_volume_parts", "VTK_FORMATS", "VTK_CELL_TYPES"]

# VTK cell type id -> our (meshio's) name; voxels become hexahedra
VTK_CELL_TYPES = {
    10: "tetra",
    11: "voxel",
    12: "hexahedron",
    13: "wedge",
    14: "pyramid",
    24: "tetra10",
    25: "hexahedron20",
    26: "wedge15",
    27: "pyramid13",
    29: "hexahedron27",
    32: "wedge18",
}
# cells bounded by polygons: split into tetrahedra where that is exact (``_polyhedra``)
_VTK_POLYHEDRA = {15: "pentagonal prism", 16: "hexagonal prism", 42: "polyhedron"}
# 3-D VTK cells we cannot integrate (refused, never dropped)
_VTK_OTHER_3D = {
    31: "12-node wedge",
    33: "24-node hexahedron",
    37: "19-node pyramid",
    41: "convex point set",
    55: "parametric tetrahedral region",
    56: "parametric hexahedral region",
    64: "higher-order tetrahedron",
    65: "higher-order wedge",
    66: "higher-order pyramid",
    67: "higher-order hexahedron",
    71: "Lagrange tetrahedron",
    72: "Lagrange hexahedron",
    73: "Lagrange wedge",
    74: "Lagrange pyramid",
    78: "Bezier tetrahedron",
    79: "Bezier hexahedron",
    80: "Bezier wedge",
    81: "Bezier pyramid",
}
_NODES = {**CELL_NODES, "tetra": 4, "voxel": 8}
_ALIASES = {"tetra4": "tetra", "hexahedron8": "hexahedron", "wedge6": "wedge", "pyramid5": "pyramid"}
# meshio names of 3-D cells we cannot integrate
_MESHIO_OTHER_3D = (
    "pyramid14",
    "hexahedron24",
    "wedge12",
    "penta_prism",
    "hexa_prism",
    "polyhedron",
    "tetra20",
    "tetra35",
    "tetra56",
    "hexahedron64",
    "hexahedron125",
    "wedge40",
    "wedge75",
    "pyramid30",
    "pyramid55",
    "VTK_LAGRANGE_TETRAHEDRON",
    "VTK_LAGRANGE_HEXAHEDRON",
    "VTK_LAGRANGE_WEDGE",
    "VTK_LAGRANGE_PYRAMID",
    "VTK_BEZIER_TETRAHEDRON",
    "VTK_BEZIER_HEXAHEDRON",
    "VTK_BEZIER_WEDGE",
    "VTK_BEZIER_PYRAMID",
)
_FORMAT_NAMES = {
    "vtk": "legacy VTK",
    "vtu": "VTK XML (.vtu)",
    "vtp": "VTK XML polydata (.vtp)",
    "vts": "VTK XML structured grid (.vts)",
    "vtr": "VTK XML rectilinear grid (.vtr)",
    "vti": "VTK XML image data (.vti)",
    "msh": "Gmsh",
    "mesh": "Medit",
    "inp": "Abaqus",
    "xdmf": "XDMF",
    "med": "MED",
    "f3grid": "FLAC3D",
    "dat": "Tecplot",
    "ugrid": "UGRID",
    "ele": "TetGen",
    "ucd": "AVS UCD (.inp)",
}


@dataclass
class _Block:
    """Consecutive cells of one 3-D type: name, (k, n) nodes, and their indices in the file's cell list."""

    type: str
    nodes: NDArray[np.int64]
    cell_ids: NDArray[np.int64]
    name: str
    file_cells: int | None = None  # the file's cells, where a block's tetrahedra are split polyhedra


@dataclass
class _Mesh:
    points: NDArray[np.float64]
    blocks: list[_Block]
    density: NDArray[np.float64] | None  # one value per cell of the file (all cells, in file order)
    other: dict[str, int]  # cells that are not 3-D: type -> count (ignored, reported if nothing else)
    warnings: list[str] = field(default_factory=list)
    surface: _Surface | None = None  # the linear 2-D cells, kept where the file has no 3-D cells
    polydata: bool = False  # a VTK polydata set: a surface by its kind, so reading it as one assumes nothing


@dataclass
class _Surface:
    """Linear 2-D cells as polygons (triangles, quads, pixels reordered, polygons) and triangle strips."""

    corners: NDArray[np.int64]  # every polygon's node ids, one polygon after another
    counts: NDArray[np.int64]  # corners per polygon
    strips: list[NDArray[np.int64]]  # each strip's node ids
    cells: int  # the file's surface cells

    def triangles(self) -> NDArray[np.int64]:
        """Polygons split as fans from their first corner; strips as VTK orders them (every other one turned)."""
        out = [fan_triangles(self.corners, self.counts)[0]]
        for strip in self.strips:
            i = np.arange(max(len(strip) - 2, 0))
            odd = i % 2 == 1
            a, b = np.where(odd, strip[i + 1], strip[i]), np.where(odd, strip[i], strip[i + 1])
            out.append(np.stack([a, b, strip[i + 2]], axis=1))
        return np.concatenate(out).astype(np.int64)


def read_volume_parts(
    data: bytes, fmt: str, length_scale: float, *, filename: str | None = None, companions: Mapping[str, bytes] | None = None
) -> list[Part]:
    """Parts of a volume mesh: one per block of 3-D cells; a file of linear 2-D cells only is one surface part.

    companions : other files of the same upload by name (a TetGen ``.node``
        beside its ``.ele``, an XDMF's HDF5 file), written beside it for the reader.
    """
    if fmt == "mesh" and data[:64].lstrip()[:4].upper() == b"MFEM":  # the other format named .mesh: not Medit's
        raise UnsupportedFormatError(
            f"{repr(os.path.basename(filename)) if filename else 'the file'} is an MFEM mesh (its first line says "
            "so), not a Medit one, and this service does not read MFEM's format; convert it to VTK (.vtu) or Gmsh "
            "(.msh), e.g. with MFEM's own mesh tools",
            format=fmt,
        )
    if fmt == "msh" and data.strip() and not _GMSH_SECTION.match(data[:64]):
        # every Gmsh section starts with $ and its name (a binary file of MuJoCo's own .msh format may start with $)
        named = f"the .msh file {os.path.basename(filename)!r}" if filename else "the .msh file"
        first = data.lstrip().split(b"\n", 1)[0].split()
        freefem = len(first) == 3 and all(t.isdigit() for t in first)  # "vertices triangles boundary-edges"
        if freefem:
            raise UnsupportedFormatError(
                f"{named} is not a Gmsh file: it is in FreeFem++'s own .msh format (its first line "
                "counts vertices, triangles and boundary edges), which this service does not read; save the mesh "
                'as Medit (savemesh(Th, "mesh.mesh")) or Gmsh',
                format=fmt,
            )
        raise UnreadableFileError(
            f"{named} is not a Gmsh file: it does not start with a $ section ($MeshFormat); "
            "check that it is the mesh you meant to send",
            format=fmt,
        )
    if fmt == "msh" and b"$PartitionedEntities" in data:
        raise UnsupportedFormatError(
            f"{_label(filename, fmt)} is partitioned ($PartitionedEntities, with ghost elements), which its reader "
            "(meshio) does not read; save it again unpartitioned (gmsh.model.mesh.unpartition() in Gmsh's API, then "
            "write it), or as VTK (.vtu)",
            format=fmt,
        )
    version = _gmsh_format(data) if fmt == "msh" else None  # a version meshio reads: 2 or 4
    if version is not None and version[0] in (2, 4) and not re.search(rb"\$Elements\b", data):
        raise EmptyGeometryError(  # meshio's own answer: "$Element section not found."
            f"{_label(filename, fmt)} holds no elements (it has no $Elements section); send a mesh with 3-D cells",
            format=fmt,
        )
    if fmt == "msh" and _gmsh_node_count(data) == 0:  # meshio's own answer: "zero-size array to reduction ..."
        raise EmptyGeometryError(
            f"{_label(filename, fmt)} holds no nodes (its $Nodes section is empty); send a mesh with 3-D cells", format=fmt
        )
    if fmt == "msh" and data[:64].lstrip().startswith(b"$NOD"):  # MSH 1: $NOD, $ELM, no $MeshFormat
        raise UnsupportedFormatError(
            f"{_label(filename, fmt)} is in Gmsh's version-1 format ($NOD and $ELM sections), which its reader "
            "(meshio) does not read; save it again as MSH 2.2 or 4.1 (for example gmsh OLD.msh -save -format msh22 -o NEW.msh)",
            format=fmt,
        )
    if fmt == "inp" and is_avs_ucd(data):  # the other format named .inp: VTK reads it, meshio would take it for Abaqus
        label = _label(filename, "ucd")
        _refuse_negative_ucd_ids(data, label)
        mesh = _read_vtk(data, "ucd", label)
    else:
        label = _label(filename, fmt)
        mesh = _read_vtk(data, fmt, label) if fmt in VTK_FORMATS else _read_meshio(data, fmt, label, filename, companions)
    return _parts(mesh, label, length_scale)


_GMSH_SECTION = re.compile(rb"\s*\$[A-Za-z]")  # a section name after its $: $MeshFormat, $NOD ...
_GMSH_FORMAT = re.compile(rb"\s*\$MeshFormat\s+(\d+)(?:\.(\d+))?\s+(\d)")
# Gmsh 4.0 writes its version as "4" (4.1 writes "4.1"); meshio reads a bare "4" as 4.1
_GMSH_BARE_4 = re.compile(rb"\A(\s*\$MeshFormat\s+)4(\s)")
_GMSH_NODES = re.compile(rb"\$Nodes[^\S\n]*\r?\n[^\S\n]*(\d+)(?:[^\S\n]+(\d+))?")


def _gmsh_format(data: bytes) -> tuple[int, int, bool] | None:
    """A Gmsh file's version (major, minor) and whether it is text, from its ``$MeshFormat``; None without one."""
    found = _GMSH_FORMAT.match(data[:64])
    return None if found is None else (int(found.group(1)), int(found.group(2) or 0), found.group(3) == b"0")


def _gmsh_node_count(data: bytes) -> int | None:
    """The node count a Gmsh file's ``$Nodes`` header declares (MSH 2: the count, in text even in a binary
    file; MSH 4 text: blocks, then nodes); None where it cannot be read (a binary MSH 4 header is binary)."""
    version, nodes = _gmsh_format(data), _GMSH_NODES.search(data)
    if version is None or nodes is None:
        return None
    major, _, text = version
    if major == 2:
        return int(nodes.group(1))
    return int(nodes.group(2)) if major == 4 and text and nodes.group(2) is not None else None


def is_avs_ucd(data: bytes) -> bool:
    """Whether an ``.inp`` file is AVS UCD rather than Abaqus.

    Binary UCD starts with the byte 7 (AVS's magic number); ASCII UCD, after
    ``#`` comment lines, with one line of five integers (numbers of nodes,
    cells, node data, cell data and model data).  An Abaqus input file's
    lines are ``*KEYWORD`` lines, ``**`` comments and data under a keyword,
    so its first line that is not a comment starts with ``*``.
    """
    if data[:1] == b"\x07":
        return True
    for raw in data[:4096].splitlines():
        line = raw.strip()
        if not line or line.startswith(b"#"):
            continue
        fields = line.split()
        return len(fields) == 5 and all(f.isdigit() for f in fields)
    return False


# ASCII UCD: a line that starts with a negative number (a node's or a cell's number: data values follow
# the number of their node or cell), or a cell line "number material type nodes..." with a negative node
_UCD_NEGATIVE_ID = re.compile(rb"^[ \t]*-[0-9]|^[ \t]*[0-9]+[ \t]+[0-9]+[ \t]+[A-Za-z]+[^\n]*?[ \t]-[0-9]", re.MULTILINE)


def _refuse_negative_ucd_ids(data: bytes, label: str) -> None:
    """VTK's UCD reader indexes its node map with node numbers as written: a negative one crashed the process."""
    if data[:1] != b"\x07" and (found := _UCD_NEGATIVE_ID.search(data)):
        line = data[found.start() : data.find(b"\n", found.start()) % (len(data) + 1)].decode("latin-1").strip()
        raise UnreadableFileError(
            f"{label} numbers a node or cell with a negative number ({line[:80]!r}); AVS UCD numbers are >= 0",
            format="inp",
        )


def _label(filename: str | None, fmt: str) -> str:
    kind = _FORMAT_NAMES.get(fmt, fmt.upper())
    return f"the {kind} file {os.path.basename(filename)!r}" if filename else f"the {kind} file"


# ----------------------------------------------------------------------------------------------
# Fences around third-party readers


@contextlib.contextmanager
def _quiet() -> Iterator[io.StringIO]:
    """Capture what a library prints to Python's stdout/stderr and its warnings."""
    sink = io.StringIO()
    with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield sink


@contextlib.contextmanager
def _upload_dir(data: bytes, fmt: str, filename: str | None, companions: Mapping[str, bytes] | None) -> Iterator[str]:
    """A private folder holding the upload (and its companion files); yields the main file's path."""
    stem = _safe_stem(filename)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, f"{stem}.{fmt}")
        for name, content in (companions or {}).items():
            safe = _safe_name(name)
            if safe and safe != os.path.basename(path):
                with open(os.path.join(tmp, safe), "wb") as fh:
                    fh.write(content)
        with open(path, "wb") as fh:
            fh.write(data)
        yield path


def _safe_stem(filename: str | None) -> str:
    base = os.path.basename(filename or "upload")
    stem = base.rsplit(".", 1)[0] if "." in base else base
    return re.sub(r"[^A-Za-z0-9_.-]", "_", stem).lstrip(".") or "upload"


def _safe_name(name: str) -> str:
    """A companion's base name, free of folders and odd characters (nothing is written outside the folder)."""
    base = os.path.basename(name.replace("\\", "/"))
    return re.sub(r"[^A-Za-z0-9_.-]", "_", base).lstrip(".")


def _reason(exc: BaseException, printed: str, tmp_paths: tuple[str, ...]) -> str:
    """One line saying what the library objected to, without our temporary paths."""
    text = str(exc).strip() if not isinstance(exc, SystemExit) else ""
    if isinstance(exc, KeyError) and exc.args:  # str() of a KeyError is the bare key: np.int32(7)
        key = exc.args[0]
        key = key.item() if hasattr(key, "item") else key
        text = f"it refers to {key!r} (a node, element, tag or entity number) without defining it"
    elif isinstance(exc, IndexError):
        text = f"it refers to an entry it does not hold, or announces more than it holds ({text or 'index out of range'})"
    if not text:  # what the library printed: its first line that is not a warning (a skipped keyword says nothing)
        lines = [ln.strip() for ln in printed.splitlines() if ln.strip()]
        text = next((ln for ln in lines if not ln.lower().startswith("warning")), lines[0] if lines else "")
        text = text or type(exc).__name__
    text = text.splitlines()[0]
    for p in tmp_paths:
        text = text.replace(f"file {p}", "the file").replace(p, "the file")  # meshio: "Couldn't read file <path>"
    text = re.sub(r"/\S*/(tmp|Temp)\S*", "the file", text)
    text = re.sub(r"\x1b\[[0-9;]*m|\[/?[a-z ]+\]", "", text)  # terminal colours and rich markup
    return _printable(text)[:200]


def _printable(text: str) -> str:
    """The text with what cannot be shown (a damaged file's own bytes, quoted by its reader) as '?'."""
    return "".join(ch if ch.isprintable() and ch != "\ufffd" else "?" for ch in text)


# ----------------------------------------------------------------------------------------------
# VTK files through VTK


_VTK_LOCK = threading.Lock()


def _vtk_missing(label: str, fmt: str) -> UnsupportedFormatError:
    return UnsupportedFormatError(
        f"reading {label} needs VTK's own reader, the optional extra 'vtk': "
        "install it with pip install 'inertia-service[vtk]', or convert the mesh to Gmsh (.msh)",
        format=fmt,
        extra="vtk",
    )


def _legacy_vtk_part4(data: bytes) -> bytes:
    """The first word after a legacy VTK file's three header lines (version, title, ASCII or BINARY): DATASET
    for a data set, FIELD for field data alone (VTK's file formats, \"Simple Legacy Formats\", parts 1-4)."""
    lines = data[:4096].splitlines()[3:]
    return next((line.split()[0].upper() for line in lines if line.strip()), b"")


def _read_vtk(data: bytes, fmt: str, label: str) -> _Mesh:
    try:
        from vtkmodules.util.numpy_support import vtk_to_numpy
        from vtkmodules.vtkCommonCore import vtkLogger, vtkOutputWindow, vtkStringOutputWindow
        from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm
        from vtkmodules.vtkFiltersCore import vtkAppendFilter
        from vtkmodules.vtkIOGeometry import vtkAVSucdReader
        from vtkmodules.vtkIOLegacy import vtkDataSetReader
        from vtkmodules.vtkIOXML import (
            vtkXMLImageDataReader,
            vtkXMLPolyDataReader,
            vtkXMLRectilinearGridReader,
            vtkXMLStructuredGridReader,
            vtkXMLUnstructuredGridReader,
        )
    except ImportError as exc:
        raise _vtk_missing(label, fmt) from exc

    kind, fmt = ("AVS UCD", "inp") if fmt == "ucd" else ("VTK", fmt)  # the file's own format, as the client named it
    readers: dict[str, Any] = {
        "vtu": vtkXMLUnstructuredGridReader,
        "vtp": vtkXMLPolyDataReader,
        "vts": vtkXMLStructuredGridReader,
        "vtr": vtkXMLRectilinearGridReader,
        "vti": vtkXMLImageDataReader,
        "inp": vtkAVSucdReader,
    }
    reader_for = _vtk_xml_reader(data, fmt, label) if fmt in VTK_XML_TYPES.values() else fmt
    if reader_for == "vtk" and _legacy_vtk_part4(data) == b"FIELD":
        raise EmptyGeometryError(
            f"{label} holds field data alone (FIELD where a legacy VTK file's DATASET would stand): no points or "
            "cells, nothing to weigh; send the data set the field belongs to",
            format=fmt,
        )
    window = vtkStringOutputWindow()
    polydata = False
    with _VTK_LOCK, _upload_dir(data, fmt, None, None) as path:  # the output window is process-wide
        previous = vtkOutputWindow.GetInstance()
        try:
            vtkOutputWindow.SetInstance(window)
            # VTK's logger writes errors to stderr beside the output window; it stays off for the process
            vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
            with _quiet():
                reader: Any = readers.get(reader_for, vtkDataSetReader)()
                reader.SetFileName(path)
                if reader_for == "vtk":
                    reader.ReadAllScalarsOn()
                reader.Update()
                grid = reader.GetOutput()
                polydata = grid is not None and grid.GetClassName() == "vtkPolyData"
                image = _image_note(grid, label)
                if grid is not None and grid.GetClassName() != "vtkUnstructuredGrid":
                    merge = vtkAppendFilter()  # image data (voxels), structured grids (hexahedra), polydata
                    # its points in double: an image's and a rectilinear grid's are computed (origin + i spacing),
                    # which the default precision stores as float32 (6e-9 of the volume off, unannounced)
                    merge.SetOutputPointsPrecision(vtkAlgorithm.DOUBLE_PRECISION)
                    merge.SetInputData(grid)
                    merge.Update()
                    grid = merge.GetOutput()
        except KeyboardInterrupt:
            raise
        except BaseException as exc:  # VTK's wrappers raise whatever the C++ side threw
            raise UnreadableFileError(
                f"could not read {label}: {_reason(exc, _text(window.GetOutput()), (path,))}; "
                f"check that it is a complete {kind} file",
                format=fmt,
            ) from exc
        finally:
            vtkOutputWindow.SetInstance(previous)
        log = _vtk_errors(_text(window.GetOutput()), path)
    if grid is None or (log and grid.GetNumberOfCells() == 0):
        raise UnreadableFileError(
            f"could not read {label}: {log or 'VTK found no data set in it'}; check that it is a complete, uncorrupted {kind} file",
            format=fmt,
        )
    if log:
        raise UnreadableFileError(f"{label} is damaged: VTK reported '{log}'; re-export it", format=fmt)
    mesh = _mesh_from_grid(grid, vtk_to_numpy, label)
    mesh.polydata = polydata
    mesh.warnings.extend(image)
    return mesh


def _image_note(grid: Any, label: str) -> list[str]:
    """What weighing an image's every voxel assumes, where the image carries values that might mean otherwise.

    An image data set (a CT or simulation volume) is a box of voxels with values at them; the body weighed
    is the whole box, at the density asked for (or a cell array named ``density``): its other arrays (a
    scalar field, a label map) neither mask voxels out nor weight them.
    """
    if grid is None or not grid.IsA("vtkImageData"):
        return []
    names = []
    for data in (grid.GetPointData(), grid.GetCellData()):
        for i in range(data.GetNumberOfArrays()):
            name = data.GetArrayName(i) or "unnamed"
            if name not in ("density", "vtkGhostType", "vtkValidPointMask"):
                names.append(name)
    if not names:
        return []
    shown = ", ".join(repr(n) for n in names[:5]) + (f" and {len(names) - 5} more" if len(names) > 5 else "")
    return [
        f"every one of the {grid.GetNumberOfCells()} voxels of {label} (image data) was weighed as solid; its "
        f"arrays ({shown}) neither mask voxels out nor weight them (a cell array named 'density' would weight them); "
        "to weigh a segmented part, export that part's surface or its voxels alone"
    ]


def _vtk_xml_reader(data: bytes, fmt: str, label: str) -> str:
    """Which VTK reader reads a file named as one of the XML formats: the one for the data set type its root
    declares (as the file says, whatever its extension), the legacy reader for a legacy file, else the
    extension's own (which then says what is wrong)."""
    head = data[:1024]
    name = vtk_xml_root_type(head)
    if name in VTK_XML_TYPES:
        return VTK_XML_TYPES[name]
    if head.lstrip().startswith(b"# vtk DataFile"):
        return "vtk"
    if name is not None:
        parallel = " (a parallel file's pieces are separate files: send each piece's own file)" if name.startswith("P") else ""
        raise UnsupportedFormatError(
            f"{label} holds a VTK {name!r} data set{parallel}; this service reads the serial data sets "
            f"{', '.join(VTK_XML_TYPES)} and legacy .vtk files",
            format=fmt,
            data_set=name,
        )
    return fmt


def _text(output: str | bytes) -> str:
    """VTK's log as text (the wrapper hands back bytes when the file's own bytes are in it)."""
    return output.decode("utf-8", "replace") if isinstance(output, bytes) else output


def _vtk_errors(text: str, path: str) -> str:
    """The first error VTK logged, as one line without the object address or our path."""
    for chunk in text.split("ERROR:")[1:]:
        lines = [ln.strip() for ln in chunk.splitlines()[1:] if ln.strip()]
        if lines:
            msg = re.sub(r"^\w+ \(0x[0-9a-f]+\): ", "", lines[0]).replace(path, "the file")
            return _printable(re.sub(r"/\S*/(tmp|Temp)\S*", "the file", msg))[:200]
    return ""


def _mesh_from_grid(grid: Any, to_numpy: Any, label: str) -> _Mesh:
    n_cells = grid.GetNumberOfCells()
    if grid.GetPoints() is None or n_cells == 0:
        raise EmptyGeometryError(f"{label} holds no cells; send a mesh with 3-D cells (tetrahedra, hexahedra, ...)")
    points = np.asarray(to_numpy(grid.GetPoints().GetData()), dtype=np.float64).reshape(-1, 3)
    cells = grid.GetCells()
    offsets = np.asarray(to_numpy(cells.GetOffsetsArray()), dtype=np.int64)
    conn = np.asarray(to_numpy(cells.GetConnectivityArray()), dtype=np.int64)
    # GetCellTypes returns the per-cell array from VTK 9.6 on (GetCellTypesArray before)
    type_array = grid.GetCellTypes() if grid.GetCellTypes().GetClassName() == "vtkUnsignedCharArray" else None
    types = np.asarray(to_numpy(type_array if type_array is not None else grid.GetCellTypesArray()), dtype=np.int64)
    density = _vtk_density(grid, to_numpy, n_cells, label)
    mesh = _Mesh(points, [], density, {})
    unsupported = {_VTK_OTHER_3D[t]: int(np.count_nonzero(types == t)) for t in _VTK_OTHER_3D if np.any(types == t)}
    if unsupported:
        raise UnsupportedFormatError(_unsupported_cells(label, unsupported), cell_types=sorted(unsupported))
    for t in np.unique(types):
        if int(t) not in VTK_CELL_TYPES and int(t) not in _VTK_POLYHEDRA:
            mesh.other[_VTK_2D_NAMES.get(int(t), f"VTK cell type {int(t)}")] = int(np.count_nonzero(types == t))
    # one block per cell type, in order of first appearance (as meshio groups a VTK file's cells; by type, not
    # by consecutive runs, so a mesh whose types alternate does not become thousands of parts)
    present, first = np.unique(types, return_index=True)
    for vtk_type in (int(t) for t in present[np.argsort(first)]):
        if vtk_type in _VTK_POLYHEDRA:
            ids = np.flatnonzero(types == vtk_type)
            nodes, cell_of, mesh.points, note = _polyhedra(grid, ids, vtk_type, conn, offsets, mesh.points, label)
            mesh.warnings.append(
                f"{len(ids)} {_VTK_POLYHEDRA[vtk_type]} cells were weighed as {len(nodes)} tetrahedra "
                "(source.tetrahedra counts those, source.cells the file's cells)"
            )
            mesh.warnings.extend([note] if note else [])
            name = _VTK_POLYHEDRA[vtk_type].replace(" ", "_")
            mesh.blocks.append(_Block("tetra", nodes, cell_of, f"{name}_{len(mesh.blocks)}", len(ids)))
            continue
        if vtk_type not in VTK_CELL_TYPES:
            continue
        name = VTK_CELL_TYPES[vtk_type]
        ids = np.flatnonzero(types == vtk_type)
        nodes = _fixed_width(conn, offsets, ids, _NODES[name], name, label, mesh.warnings)
        if name == "voxel":
            nodes, name = nodes[:, VOXEL_TO_HEXAHEDRON], "hexahedron"
        mesh.blocks.append(_Block(name, nodes, ids, f"{VTK_CELL_TYPES[vtk_type]}_{len(mesh.blocks)}"))
    if mesh.blocks:
        lower = ~np.isin(types, list(VTK_CELL_TYPES) + list(_VTK_POLYHEDRA))
        if lower.any():  # the corners of every cell that is not 3-D, by each connectivity entry's cell
            _surface_apart_warning(mesh, conn[np.repeat(lower, np.diff(offsets))], label)
    ghosts = grid.GetCellData().GetArray("vtkGhostType")
    if ghosts is not None:
        _drop_ghost_cells(mesh, np.asarray(to_numpy(ghosts), dtype=np.int64).reshape(-1), label)
    if not mesh.blocks:
        mesh.surface = _vtk_surface(types, conn, offsets, label, mesh.warnings)
    return mesh


def _surface_apart_warning(mesh: _Mesh, lower_nodes: NDArray[np.int64], label: str) -> None:
    """Say so where the file's 2-D (or 1-D, 0-D) cells reach points no 3-D cell uses: a body of its own
    (a closed skin beside the volume), which the volume's weight leaves out; boundary faces of the
    volume itself, as Gmsh writes its physical surfaces, use only the volume's points."""
    if len(lower_nodes) == 0:
        return
    used = np.zeros(len(mesh.points), dtype=bool)
    for b in mesh.blocks:  # a node number past the points is refused later, by name, with the cells' checks
        nodes = b.nodes.ravel()
        used[nodes[(nodes >= 0) & (nodes < len(used))]] = True
    inside = (lower_nodes >= 0) & (lower_nodes < len(used))
    apart = np.unique(lower_nodes[inside][~used[lower_nodes[inside]]])
    if len(apart):
        mesh.warnings.append(
            f"{label} also holds surface, line or point cells on {_count(len(apart), 'point')} that no 3-D cell "
            "uses (a body apart from the volume); only the 3-D cells were weighed"
        )


# vtkDataSetAttributes::DUPLICATECELL | HIDDENCELL: the cells VTK's own integration (vtkIntegrateAttributes)
# leaves out, a neighbouring piece's copy or a blanked cell
_VTK_GHOST_SKIPPED = 1 | 32


def _drop_ghost_cells(mesh: _Mesh, ghosts: NDArray[np.int64], label: str) -> None:
    """Leave out the cells a ``vtkGhostType`` array marks as another piece's copy or as hidden, as VTK does."""
    if len(ghosts) == 0 or not np.any(ghosts & _VTK_GHOST_SKIPPED):
        return
    skipped = (ghosts & _VTK_GHOST_SKIPPED) != 0
    dropped = 0
    for b in mesh.blocks:
        keep = ~skipped[b.cell_ids] if len(ghosts) > int(b.cell_ids.max(initial=-1)) else np.ones(len(b.cell_ids), bool)
        if not keep.all():
            dropped += len(np.unique(b.cell_ids[~keep]))
            b.nodes, b.cell_ids = b.nodes[keep], b.cell_ids[keep]
            b.file_cells = None if b.file_cells is None else len(np.unique(b.cell_ids))
    mesh.blocks = [b for b in mesh.blocks if len(b.nodes)]
    if dropped:
        mesh.warnings.append(
            f"{label} marks {_count(dropped, 'cell')} as ghost cells (vtkGhostType: a neighbouring piece's copy "
            "or hidden); they were left out, as VTK's own integration leaves them out"
        )


# linear 2-D VTK cells of a fixed size: corners in order around the face (a pixel's go row by row: 0 1 3 2)
_VTK_FIXED_FACES = {5: ("triangle", 3, [0, 1, 2]), 9: ("quad", 4, [0, 1, 2, 3]), 8: ("pixel", 4, [0, 1, 3, 2])}
_VTK_POLYGON, _VTK_STRIP = 7, 6  # any number of corners


def _vtk_surface(
    types: NDArray[np.int64], conn: NDArray[np.int64], offsets: NDArray[np.int64], label: str, notes: list[str]
) -> _Surface | None:
    """The linear 2-D cells of a VTK data set, or None when it has none."""
    faces: list[NDArray[np.int64]] = []
    for vtk_type, (name, width, order) in _VTK_FIXED_FACES.items():
        ids = np.flatnonzero(types == vtk_type)
        if len(ids):  # the first ``width`` ids of each list, as VTK reads them; a shorter list is refused
            faces.append(_fixed_width(conn, offsets, ids, width, name, label, notes)[:, order].ravel())
    polygons = np.flatnonzero(types == _VTK_POLYGON)
    counts = offsets[polygons + 1] - offsets[polygons]
    owner = np.repeat(np.arange(len(polygons)), counts)
    faces.append(conn[offsets[polygons][owner] + np.arange(len(owner)) - np.repeat(np.cumsum(counts) - counts, counts)])
    strips = [conn[offsets[i] : offsets[i + 1]].astype(np.int64) for i in np.flatnonzero(types == _VTK_STRIP)]
    widths = [np.full(int(np.count_nonzero(types == t)), _VTK_FIXED_FACES[t][1]) for t in _VTK_FIXED_FACES]
    all_counts = np.concatenate([*widths, counts]).astype(np.int64)
    if not len(all_counts) and not strips:
        return None
    cells = int(np.count_nonzero(all_counts >= 3)) + sum(len(s) >= 3 for s in strips)
    return _Surface(np.concatenate(faces).astype(np.int64), all_counts, strips, cells)


def _polyhedron_faces(grid: Any, cells: NDArray[np.int64]) -> tuple[list[list[int]], list[int]]:
    """The faces of polyhedron cells (point ids, from VTK's face streams) and the cell of each face."""
    from vtkmodules.vtkCommonCore import vtkIdList

    faces: list[list[int]] = []
    owner: list[int] = []
    stream = vtkIdList()
    for cell in (int(c) for c in cells):
        grid.GetFaceStream(cell, stream)
        ids = [stream.GetId(k) for k in range(stream.GetNumberOfIds())]
        at = 1
        for _ in range(ids[0] if ids else 0):
            face = ids[at + 1 : at + 1 + ids[at]]
            at += 1 + ids[at]
            kept = [a for a, b in zip(face, [*face[1:], face[0]], strict=True) if a != b]  # a collapsed edge: one corner
            if len(kept) >= 3:
                faces.append(kept)
                owner.append(cell)
    return faces, owner


def _prism_faces(
    cells: NDArray[np.int64], vtk_type: int, conn: NDArray[np.int64], offsets: NDArray[np.int64]
) -> tuple[list[list[int]], list[int]]:
    """The faces of VTK's prisms (bottom polygon 0..n-1, top n..2n-1 above it), wound outward alike."""
    n = 5 if vtk_type == 15 else 6
    v = conn[offsets[cells][:, None] + np.arange(2 * n)[None, :]]
    local = [list(range(n - 1, -1, -1)), list(range(n, 2 * n))]
    local += [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n)]
    faces: list[list[int]] = []
    owner: list[int] = []
    for row, cell in zip(v.tolist(), cells.tolist(), strict=True):
        for f in local:
            face = [row[i] for i in f]
            kept = [a for a, b in zip(face, [*face[1:], face[0]], strict=True) if a != b]
            if len(kept) >= 3:
                faces.append(kept)
                owner.append(cell)
    return faces, owner


def _polyhedra(
    grid: Any,
    ids: NDArray[np.int64],
    vtk_type: int,
    conn: NDArray[np.int64],
    offsets: NDArray[np.int64],
    points: NDArray[np.float64],
    label: str,
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64], str | None]:
    """Polyhedral cells as tetrahedra, where exact; the file cell of each, the points (unchanged), a warning.

    Prisms are split as VTK splits them (its own local tetrahedra, ``TriangulateLocalIds``; a cell
    whose pieces turn both ways folds over itself and is refused).  A polyhedron is split from its
    first corner: exact when its faces close it with one winding (each edge once each way) and every
    tetrahedron from that corner turns the same way (the cell is star-shaped from there, as every
    convex cell is, so the pieces neither overlap nor leave a gap); a cell that fails refuses the
    file, naming the cell and why.  No point is added.  A face that is not flat (float32 rounding,
    warped faces) bounds a volume that depends on how it is split: when that matters by more than
    ``polygons.NOTE_REL`` of the volume a warning says by how much (``polygons.fan_split_note``).
    Vectorised over the cells but for reading VTK's face streams.
    """
    kind = _VTK_POLYHEDRA[vtk_type]

    def refuse(cell: int, why: str) -> UnsupportedFormatError:
        return UnsupportedFormatError(
            f"{label} has a {kind} cell ({cell}) that cannot be weighed exactly: {why}; split such cells into "
            "tetrahedra, hexahedra, wedges or pyramids (for example with VTK's vtkTessellatorFilter or Gmsh)",
            cell_types=[kind],
        )

    faces, face_cell = _polyhedron_faces(grid, ids) if vtk_type == 42 else _prism_faces(ids, vtk_type, conn, offsets)
    counts = np.fromiter((len(f) for f in faces), dtype=np.int64, count=len(faces))
    flat = np.fromiter((i for f in faces for i in f), dtype=np.int64, count=int(counts.sum()))
    cell_of_face = np.asarray(face_cell, dtype=np.int64)
    if len(flat) == 0 or flat.min() < 0 or flat.max() >= len(points) or len(np.unique(cell_of_face)) != len(ids):
        raise UnreadableFileError(f"{label} has {kind} cells whose faces do not bound a solid; fix the mesh")
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    corner_face = np.repeat(np.arange(len(counts)), counts)
    nxt = np.arange(len(flat)) + 1
    nxt[starts + counts - 1] = starts  # each corner's successor around its face
    # one winding: within each cell every edge runs once each way
    a, b = flat, flat[nxt]
    cell = cell_of_face[corner_face]
    lo, hi, sign = np.minimum(a, b), np.maximum(a, b), np.where(a < b, 1, -1)
    order = np.lexsort((hi, lo, cell))
    key_change = np.r_[
        True, (lo[order][1:] != lo[order][:-1]) | (hi[order][1:] != hi[order][:-1]) | (cell[order][1:] != cell[order][:-1])
    ]
    runs = np.flatnonzero(key_change)
    unbalanced = np.add.reduceat(sign[order], runs) != 0
    if np.any(unbalanced):
        raise refuse(int(cell[order][runs[np.argmax(unbalanced)]]), "its faces do not close it with one winding")
    # fan triangles of every face, from its first corner
    tri, tri_face = fan_triangles(flat, counts)
    x = points[tri]
    area2 = np.zeros((len(counts), 3))
    np.add.at(area2, tri_face, np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]))
    cell_lo = np.full((len(ids), 3), np.inf)
    cell_hi = np.full((len(ids), 3), -np.inf)
    slot = np.searchsorted(ids, cell_of_face[corner_face])
    for k in range(3):
        np.minimum.at(cell_lo[:, k], slot, points[flat, k])
        np.maximum.at(cell_hi[:, k], slot, points[flat, k])
    size = (cell_hi - cell_lo).max(axis=1)  # per cell, in the order of ids
    face_size = size[np.searchsorted(ids, cell_of_face)]
    flat_face = np.linalg.norm(area2, axis=1) <= 1e-24 * face_size**2
    if np.any(flat_face):
        raise refuse(int(cell_of_face[np.argmax(flat_face)]), "a face has no area")
    if vtk_type == 42:
        first_face = np.searchsorted(cell_of_face, ids)  # faces are grouped by cell, in the order of ids
        apex = flat[starts[first_face]]
        tri_cell = np.searchsorted(ids, cell_of_face[tri_face])
        o = points[apex[tri_cell]]
        through = np.zeros(len(counts), dtype=bool)  # faces through their cell's apex: split from it, they add nothing
        np.logical_or.at(through, corner_face, flat == apex[np.searchsorted(ids, cell_of_face[corner_face])])
        keep = ~through[tri_face]
        nodes = np.concatenate([apex[tri_cell][:, None], tri], axis=1)[keep]
        owner = ids[tri_cell][keep]
        o, x = o[keep], x[keep]
        det = np.einsum("ij,ij->i", x[:, 0] - o, np.cross(x[:, 1] - o, x[:, 2] - o))
        tol = 1e-12 * size[tri_cell[keep]] ** 3
    else:
        from vtkmodules.vtkCommonCore import vtkIdList

        local = vtkIdList()
        grid.GetCell(int(ids[0])).TriangulateLocalIds(0, local)
        pattern = np.asarray([local.GetId(k) for k in range(local.GetNumberOfIds())], dtype=np.int64).reshape(-1, 4)
        n_nodes = 10 if vtk_type == 15 else 12
        cell_nodes = conn[offsets[ids][:, None] + np.arange(n_nodes)[None, :]]
        nodes = cell_nodes[:, pattern].reshape(-1, 4)
        owner = np.repeat(ids, len(pattern))
        t = points[nodes]
        det = np.einsum("ij,ij->i", t[:, 1] - t[:, 0], np.cross(t[:, 2] - t[:, 0], t[:, 3] - t[:, 0]))
        tol = 1e-12 * np.repeat(size, len(pattern)) ** 3
    positive = np.zeros(len(ids), dtype=bool)
    negative = np.zeros(len(ids), dtype=bool)
    np.logical_or.at(positive, np.searchsorted(ids, owner), det > tol)
    np.logical_or.at(negative, np.searchsorted(ids, owner), det < -tol)
    both = positive & negative
    if np.any(both):
        why = (
            "it is not star-shaped from its first corner (not convex)"
            if vtk_type == 42
            else "VTK's own split of it turns both ways (it folds over itself)"
        )
        raise refuse(int(ids[np.argmax(both)]), why)
    nodes = nodes.copy()
    nodes[det < 0] = nodes[det < 0][:, [0, 2, 1, 3]]  # each cell's pieces share a sign (checked): wind them positively
    how = "as a fan from one corner" if vtk_type == 42 else "as VTK splits its own cells (vtkCell::Triangulate)"
    note = fan_split_note(points, flat, counts, kind, volume=float(np.abs(det).sum()) / 6, how=how)
    return nodes, owner.astype(np.int64), points, note


_VTK_2D_NAMES = {
    1: "vertex",
    2: "polyvertex",
    3: "line",
    4: "polyline",
    5: "triangle",
    6: "triangle strip",
    7: "polygon",
    8: "pixel",
    9: "quad",
    21: "quadratic edge",
    22: "quadratic triangle",
    23: "quadratic quad",
    28: "biquadratic quad",
}


def _fixed_width(
    conn: NDArray[np.int64], offsets: NDArray[np.int64], ids: NDArray[np.int64], width: int, name: str, label: str, notes: list[str]
) -> NDArray[np.int64]:
    """The first ``width`` node ids of each cell, as VTK's cells use them; refuse too-short lists."""
    counts = offsets[ids + 1] - offsets[ids]
    if np.any(counts < width):
        bad = int(ids[np.argmax(counts < width)])
        raise UnreadableFileError(
            f"{label} is inconsistent: cell {bad} is a {name} but lists {int(counts[np.argmax(counts < width)])} "
            f"node ids where {width} are needed; fix the cell's type or its node list",
        )
    longer = int(np.count_nonzero(counts > width))
    if longer:
        notes.append(
            f"{longer} {name} cells list more node ids than a {name} has ({int(counts.max())} for {width}); "
            f"their first {width} were used, as VTK reads them: if the cells are meant to be quadratic, "
            "write them with the quadratic cell type"
        )
    nodes: NDArray[np.int64] = conn[offsets[ids][:, None] + np.arange(width)[None, :]]
    return nodes


def _vtk_density(grid: Any, to_numpy: Any, n_cells: int, label: str) -> NDArray[np.float64] | None:
    array = grid.GetCellData().GetArray("density")
    if array is None:
        return None
    values = np.asarray(to_numpy(array), dtype=np.float64)
    if values.shape != (n_cells,):
        raise UnreadableFileError(
            f"{label} has a 'density' cell array of shape {values.shape}; it needs one value per cell ({n_cells})", field="density"
        )
    return values


# ----------------------------------------------------------------------------------------------
# Other formats through meshio


# meshio 5.3.5's table of cell dimensions lacks these 3-D types, so reading them raised KeyError in
# every format (its readers and node orders know them); the entries are added, never changed
_MESHIO_MISSING_DIMENSIONS = {"wedge15": 3, "pyramid13": 3, "hexahedron24": 3}


def _read_meshio(data: bytes, fmt: str, label: str, filename: str | None, companions: Mapping[str, bytes] | None) -> _Mesh:
    from meshio import _mesh

    table = getattr(_mesh, "topological_dimension", None)
    if isinstance(table, dict):
        for key, dim in _MESHIO_MISSING_DIMENSIONS.items():
            table.setdefault(key, dim)

    if fmt == "inp":  # one deck, as Abaqus reads it: meshio then opens no other file
        data = abaqus_flatten(data, companions or {}, label)
        _admit_abaqus_types([data], label)
        data = abaqus_one_node_block(abaqus_plain(data), label)
        _refuse_renumbered(data, label)
        companions = None

    if fmt == "mesh":
        data = medit_layout(data)
        medit_dimension(data, label)
    if fmt == "msh":
        _msh2_element_lengths(data, label)
        data = _GMSH_BARE_4.sub(rb"\g<1>4.0\g<2>", data, count=1)  # MSH 4.0 as Gmsh 4.0 wrote it, for meshio's 4.0 reader
    try:
        mesh = _meshio_read(data, fmt, label, filename, companions)
    except UnreadableFileError as exc:
        again = _gmsh_retry(data, exc, label) if fmt == "msh" else None
        if again is None:
            raise
        mesh = _meshio_read(again, fmt, label, filename, companions)
        if b"$Entities" not in again:  # read without its entities: their physical tags name the blocks again
            _restore_physical_tags(mesh, gmsh_entity_physicals(data))
    if fmt == "msh":
        _gmsh_node_order(mesh)
    out = _mesh_from_meshio(mesh, label)
    if fmt == "xdmf" and isinstance(mesh.info, list):  # what the time series' reading chose (_xdmf_time_series_mesh)
        out.warnings.extend(str(note) for note in mesh.info)
    version = _gmsh_format(data) if fmt == "msh" else None
    if version is not None and version[0] <= 2:  # MSH 4 lists an element once
        _drop_repeated_cells(out, label)
    ghosts = mesh.cell_data.get("vtkGhostType")
    if ghosts is not None:
        _drop_ghost_cells(out, np.concatenate([np.asarray(g, dtype=np.int64).reshape(-1) for g in ghosts]), label)
    if fmt == "inp":  # Abaqus's 2-D elements are shells and membranes: their mass is their sections', not a solid's
        out.surface = None
    if fmt == "inp" and out.blocks and out.other:  # Abaqus shells, beams, trusses have mass through their sections
        listed = ", ".join(f"{n} {t}" for t, n in sorted(out.other.items()))
        out.warnings.append(
            f"{label} also holds {listed} elements (shells, membranes, beams or trusses), whose mass depends on "
            "section properties; they were not weighed: the result is the solid elements alone"
        )
    return out


# the Medit keywords meshio reads whose entry count comes next (libMeshb's GmfKwdFmt)
_MEDIT_COUNTED = (
    b"Vertices|Edges|Triangles|Quadrilaterals|Tetrahedra|Prisms|Pyramids|Hexahedra|Hexaedra|Corners|Normals|"
    b"NormalAtVertices|SubDomainFromMesh|VertexOnGeometricVertex|VertexOnGeometricEdge|EdgeOnGeometricEdge"
)
_MEDIT_VERSION_APART = re.compile(rb"(?m)^([ \t]*MeshVersionFormatted)[ \t]*\r?\n\s*(\d+)")
_MEDIT_COUNT_BESIDE = re.compile(rb"(?m)^([ \t]*(?:" + _MEDIT_COUNTED + rb"))[ \t]+(\d+)[ \t]*(?=\r?$)")


def medit_layout(data: bytes) -> bytes:
    """A Medit file laid out as meshio's line reader expects it: a keyword's value on its line for the version,
    a block's count on the next line.

    libMeshb, Medit's own library, reads keywords and numbers as whitespace-separated tokens, so
    ``MeshVersionFormatted`` and its number may sit on two lines, and a count beside its keyword; meshio
    reads line by line and failed on both ("list index out of range", or a count taken from the first entry).
    """
    data = _MEDIT_VERSION_APART.sub(rb"\1 \2", data)
    data = _MEDIT_COUNT_BESIDE.sub(rb"\1\n\2", data)
    return _MEDIT_WEIGHTLESS.sub(b"", data)


# Medit blocks that weigh nothing and that meshio refuses or misreads: libMeshb's "required" entities (ids of
# what a remesher must keep; meshio knows RequiredVertices alone, and counts its lines, so a blank line after
# the count breaks it, as it does Ridges and Tangents), and ParMmg's parallel communicators (a distributed
# mesh's pieces). Each goes from its keyword (and a count beside it) to the next keyword: a block's entries
# are numbers.
_MEDIT_WEIGHTLESS = re.compile(
    rb"(?m)^[ \t]*(?:Required[A-Za-z]*|Parallel[A-Za-z]*|Ridges|Tangents|TangentAtVertices)(?:[ \t]+\d+)?[ \t]*\r?$"
    rb"(?:\n(?![ \t]*[A-Za-z]).*$)*\n?"
)
_MEDIT_DIMENSION = re.compile(rb"(?m)^[ \t]*Dimension\s+(\d+)")


def medit_dimension(data: bytes, label: str) -> None:
    """Refuse a Medit mesh of dimension 1 or 2 by name (bamg's geometry files, 1-D meshes), before meshio
    stops at a keyword of theirs it does not know, or finds "no points"."""
    found = _MEDIT_DIMENSION.search(data[:4096])
    if found is not None and found.group(1) in (b"1", b"2"):
        kind = "one" if found.group(1) == b"1" else "two"
        raise EmptyGeometryError(
            f"{label} is {kind}-dimensional (Dimension {found.group(1).decode()}); a volume needs a 3-D mesh "
            "(tetrahedra, hexahedra, ...)"
        )


# Gmsh numbers an 18-node prism's nodes its own way (edges 0-1, 0-2, 0-3, 1-2, 1-4, 2-5, 3-4, 3-5, 4-5, then the
# quadrilateral faces 0-1-4-3, 0-2-5-3, 1-2-5-4; gmsh.info, "Node ordering"), VTK another (edges 0-1, 1-2, 2-0,
# 3-4, 4-5, 5-3, 0-3, 1-4, 2-5, faces 0-1-4-3, 1-2-5-4, 2-0-3-5; vtkBiQuadraticQuadraticWedge).  meshio 5.3.5
# reorders the 15-node prism but passes the 18-node one on as it is: every such cell came back folded.
_GMSH_TO_VTK = {"wedge18": [0, 1, 2, 3, 4, 5, 6, 9, 7, 12, 14, 13, 8, 10, 11, 15, 17, 16]}


def _gmsh_node_order(mesh: Any) -> None:
    """Put the Gmsh cells meshio leaves in Gmsh's node order into VTK's (``_GMSH_TO_VTK``), in place."""
    try:
        from meshio.gmsh.common import _gmsh_to_meshio_order as meshio_order
    except ImportError:  # pragma: no cover - a meshio without it reorders nothing we know of
        meshio_order = None
    for block in mesh.cells:
        order = _GMSH_TO_VTK.get(block.type)
        if order is None:
            continue
        probe = np.arange(len(order))[None, :]
        if meshio_order is not None and not np.array_equal(meshio_order(block.type, probe), probe):
            continue  # a meshio that reorders it itself
        block.data = np.asarray(block.data)[:, order]


def _drop_repeated_cells(mesh: _Mesh, label: str) -> None:
    """Weigh once a 3-D cell that a Gmsh file lists more than once.

    MSH 2.2 writes an element once for each physical group it belongs to (MSH 4 once, with its entity's
    groups): a volume in two groups came back twice as heavy.  A repeat (the same type on the same nodes)
    is left out of the later block, and a warning says how many there were.
    """
    repeated = 0
    for ctype in dict.fromkeys(b.type for b in mesh.blocks):
        blocks = [b for b in mesh.blocks if b.type == ctype]
        rows = np.concatenate([np.sort(b.nodes, axis=1) for b in blocks])
        order = np.lexsort(rows.T[::-1])  # stable: equal rows stay in file order
        ranked = rows[order]
        again = np.zeros(len(rows), dtype=bool)
        again[1:] = np.all(ranked[1:] == ranked[:-1], axis=1)
        if not again.any():
            continue
        keep = np.ones(len(rows), dtype=bool)
        keep[order[again]] = False  # every listing after the first, in file order
        repeated += int(again.sum())
        start = 0
        for b in blocks:
            mine = keep[start : start + len(b.nodes)]
            start += len(b.nodes)
            if not mine.all():
                b.nodes, b.cell_ids, b.file_cells = b.nodes[mine], b.cell_ids[mine], None
    if repeated:
        mesh.blocks = [b for b in mesh.blocks if len(b.nodes)]
        mesh.warnings.append(
            f"{label} lists {_count(repeated, '3-D cell')} more than once (MSH 2.2 writes an element once for each "
            "physical group it is in); each was weighed once, in the first group that lists it"
        )


_XDMF_NOT_XML = re.compile(rb"""<DataItem\b[^>]*\bFormat\s*=\s*["'](?!XML["'])""", re.IGNORECASE)


@contextlib.contextmanager
def _without_hdf5(data: bytes, fmt: str) -> Iterator[None]:
    """Where h5py is not installed, let meshio read an XDMF file whose data are all in its XML.

    meshio's XDMF reader imports h5py before it reads any data item, HDF5 or not; a file whose items are
    all ``Format="XML"`` (XDMF's default, as dolfinx's test meshes) needs none. For such a file, and while
    it is read, ``h5py`` is a module that has nothing: an HDF5 item all the same fails as h5py missing.
    """
    if fmt != "xdmf" or "h5py" in sys.modules or importlib.util.find_spec("h5py") is not None or _XDMF_NOT_XML.search(data):
        yield
        return
    stand_in = types.ModuleType("h5py")
    sys.modules["h5py"] = stand_in
    try:
        yield
    finally:
        if sys.modules.get("h5py") is stand_in:
            del sys.modules["h5py"]


def _hdf5_missing(label: str, fmt: str, exc: ImportError) -> UnsupportedFormatError:
    """meshio imports h5py for XDMF and MED only when such a file is read: absent, or installed but broken."""
    state = "is not installed" if exc.name == "h5py" else f"cannot be imported here ({exc})"
    return UnsupportedFormatError(
        f"reading {label} needs h5py (HDF5), which {state}: install the optional extra 'hdf5' with "
        "pip install 'inertia-service[hdf5]', or convert the mesh to Gmsh (.msh) or VTK (.vtu)",
        format=fmt,
        extra="hdf5",
    )


# Abaqus solid elements by node count: C3D<n> with any suffix (R reduced, H hybrid, I incompatible modes,
# M modified, T coupled temperature, P pore pressure, ...), DC3D<n> heat transfer, SC6R/SC8R continuum
# shells; the node layout depends on <n> alone.  Variable-node elements (C3D15V, C3D27) are not among them.
_ABAQUS_SOLID = re.compile(r"^(?:D?C3D(?P<n>4|6|8|10|15|20)[A-UW-Z]*|SC(?P<sc>6|8)R[A-Z]*)$")
_ABAQUS_SOLID_TYPE = {"4": "tetra", "6": "wedge", "8": "hexahedron", "10": "tetra10", "15": "wedge15", "20": "hexahedron20"}
# Abaqus elements that weigh by their section, not as solids, by node count where meshio lacks the name
# (it has S8R but not S8, B32 but not B32R): shells, membranes, plane and axisymmetric elements (2-D), beams
# and trusses. They are read so that the warning can count them, and never weighed.
_ABAQUS_FACE = re.compile(r"^(?:S|STRI|DS|M3D|SFM3D|CPE|CPEG|CPS|CAX|CGAX|DC2D|DCAX)(?P<n>[34689])(?![0-9])[A-Z0-9]*$")
_ABAQUS_FACE_TYPE = {"3": "triangle", "4": "quad", "6": "triangle6", "8": "quad8", "9": "quad9"}
_ABAQUS_LINE = re.compile(r"^(?:(?:B|PIPE)[23](?P<beam>[123])|T[23]D(?P<truss>[23]))(?![0-9])[A-Z0-9]*$")
_ABAQUS_LINE_TYPE = {"1": "line", "2": "line3", "3": "line"}  # B21/B31 two nodes, B22/B32 three, B23/B33 two (cubic)
_ABAQUS_ELEMENT = re.compile(rb"^[ \t]*\*[ \t]*ELEMENT[ \t]*(?:,(?P<params>[^\r\n]*))?$", re.IGNORECASE | re.MULTILINE)
_ABAQUS_TYPE = re.compile(rb"(?:^|,)[ \t]*TYPE[ \t]*=[ \t]*(?P<type>[^,\s]+)", re.IGNORECASE)


def abaqus_element_types(texts: list[bytes]) -> list[str]:
    """The element types an Abaqus input deck declares (``*ELEMENT, TYPE=...``), as written."""
    found: set[str] = set()
    for text in texts:
        for m in _ABAQUS_ELEMENT.finditer(text):
            t = _ABAQUS_TYPE.search(m.group("params") or b"")
            if t:
                found.add(t.group("type").decode("latin-1"))
    return sorted(found)


def _admit_abaqus_types(texts: list[bytes], label: str) -> None:
    """Teach meshio the deck's solid element names it lacks; refuse, by name, the elements it cannot read.

    Abaqus reads keywords and element names in any case and has many solid
    variants (C3D8T, C3D10HS, DC3D4, ...) of the few node layouts meshio
    knows by a handful of names (its table has C3D8R but not c3d8r or
    C3D8T); meshio refused every other spelling with "Element type not
    available".  Each such solid is added to meshio's table under the name
    as written (entries are only added, never changed).  Springs, dashpots,
    point masses, connectors, user elements and the like are not solids and
    some of them carry mass (MASS, ROTARYI): the file is refused, naming them.
    """
    from meshio import _common, _mesh
    from meshio.abaqus import _abaqus

    table = getattr(_abaqus, "abaqus_to_meshio_type", None)
    if not isinstance(table, dict):
        return
    # meshio 5.3.5 names C3D4H's cells "tetra4" but knows neither their node count nor their dimension
    # (KeyError on every C3D4H deck): the two entries are added
    for nodes_or_dim, value in (
        (getattr(_common, "num_nodes_per_cell", None), 4),
        (getattr(_mesh, "topological_dimension", None), 3),
    ):
        if isinstance(nodes_or_dim, dict):
            nodes_or_dim.setdefault("tetra4", value)
    unknown = []
    for name in abaqus_element_types(texts):
        known = table.get(name) or table.get(name.upper())
        m = _ABAQUS_SOLID.match(name.upper())
        target = known or (_ABAQUS_SOLID_TYPE[m.group("n") or m.group("sc")] if m else _abaqus_sectioned(name.upper()))
        if target is None:
            unknown.append(name)
        else:
            table.setdefault(name, target)
    if unknown:
        raise UnsupportedFormatError(
            f"{label} holds elements this service does not read ({', '.join(unknown)}): it weighs continuum "
            "solids (C3D4 ... C3D20 and their variants), and springs, dashpots, point masses (MASS, ROTARYI), "
            "connectors or user elements would be left out although some carry mass; export the solid mesh alone",
            element_types=unknown,
        )


def _abaqus_sectioned(name: str) -> str | None:
    """meshio's cell type for an Abaqus shell, membrane, 2-D, beam or truss element it does not know by name."""
    face = _ABAQUS_FACE.match(name)
    if face:
        return _ABAQUS_FACE_TYPE[face.group("n")]
    line = _ABAQUS_LINE.match(name)
    if line:
        return _ABAQUS_LINE_TYPE[line.group("beam")] if line.group("beam") else ("line" if line.group("truss") == "2" else "line3")
    return None


# keywords that make or move nodes or elements from others (generation, copies, mappings, placed instances):
# meshio reads none of them, and the mesh it returned without them was the wrong body, silently
_ABAQUS_GENERATED = {
    b"NGEN": "generates nodes",
    b"NFILL": "generates nodes",
    b"NCOPY": "copies nodes",
    b"NMAP": "maps node coordinates",
    b"ELGEN": "generates elements",
    b"ELCOPY": "copies elements",
}
_ABAQUS_SYSTEM = re.compile(rb"(?:^|,)[ \t]*SYSTEM[ \t]*=[ \t]*(?P<system>[^,\s]+)", re.IGNORECASE)


def _abaqus_keyword(line: bytes) -> bytes | None:
    """The keyword of an Abaqus keyword line (``*Node, nset=A`` -> ``NODE``); None for data and comment lines."""
    if not line.startswith(b"*") or line.startswith(b"**"):
        return None
    return line.partition(b",")[0].strip().lstrip(b"*").replace(b" ", b"").upper()


# blanks before a keyword's asterisk, which CalculiX reads (its own refined decks write " *ELEMENT") and meshio
# took for a data line
_ABAQUS_INDENT = re.compile(rb"^[ \t]+(?=\*)", re.MULTILINE)
_ABAQUS_INPUT_PARAMETER = re.compile(rb",[ \t]*input[ \t]*=[ \t]*(?P<name>[^,\r\n]*)", re.IGNORECASE)
MAX_INCLUDE_DEPTH = 16


def _abaqus_lines(data: bytes) -> bytes:
    """The deck's lines ended by \\n alone (meshio reads \\r\\n and a bare \\r as line ends too), keywords unindented."""
    if b"\r" in data:
        data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
    return _ABAQUS_INDENT.sub(b"", data)


def abaqus_input_names(data: bytes) -> set[str]:
    """The file names a deck's keyword lines read (``*INCLUDE, INPUT=name`` and the like)."""
    names = set()
    for line in data.splitlines():
        m = _ABAQUS_INPUT_PARAMETER.search(line) if _abaqus_keyword(line) is not None else None
        if m is not None:
            names.add(_input_name(m))
    return names


def _input_name(m: re.Match[bytes]) -> str:
    return own_name(m.group("name").strip().strip(b"'\"").decode("utf-8", "replace"))


def abaqus_flatten(data: bytes, companions: Mapping[str, bytes], label: str) -> bytes:
    """The deck with each file it reads written in its place, as Abaqus reads it, keywords unindented.

    ``*INCLUDE, INPUT=name`` is replaced by the named file's lines, and a
    keyword that reads its data lines from a file (``*NODE, INPUT=name``)
    is followed by them; includes in included files too.  meshio read an
    included file as a mesh of its own, merged before the node table that
    the deck's next ``*NODE`` then replaced (an included tetrahedron came
    back as the deck's own), and looked for the file in the process's
    working directory first.  Every name must be one of ``companions`` (the
    upload's own files; on the caller's disk, the files beside the model,
    see ``load_body``); the result is bounded by the upload's inflation
    budget, so a file that includes itself or others many times is refused.
    """
    data = _abaqus_lines(data)
    if not _ABAQUS_INPUT_PARAMETER.search(data):  # most decks read no other file: no pass over their lines
        return data
    budget = inflate_budget(len(data) + sum(len(v) for v in companions.values()))
    out: list[bytes] = []
    total = 0

    def expand(text: bytes, depth: int) -> None:
        nonlocal total
        if depth > MAX_INCLUDE_DEPTH:
            raise UnreadableFileError(
                f"{label}'s includes nest more than {MAX_INCLUDE_DEPTH} deep (does a file include itself?)", format="inp"
            )
        for line in text.splitlines(keepends=True):
            keyword = _abaqus_keyword(line)
            m = _ABAQUS_INPUT_PARAMETER.search(line) if keyword is not None else None
            if m is not None:
                name = _input_name(m)
                refuse_reference("inp", name, "INPUT=", companions)
                if keyword != b"INCLUDE":  # the keyword stays; its data lines come from the file
                    line = line[: m.start()] + line[m.end() :]
                    out.append(line if line.endswith((b"\n", b"\r")) else line + b"\n")
                content = _abaqus_lines(companions[name])
                expand(content if content.endswith((b"\n", b"\r")) else content + b"\n", depth + 1)
                continue
            out.append(line)
            total += len(line)
            if total > budget:
                raise InputTooLargeError(
                    f"{label}'s includes expand to more than {budget} bytes; at most {INFLATE_RATIO} times the "
                    "size of its files is accepted",
                    limit_bytes=budget,
                    format="inp",
                )

    expand(data, 0)
    return b"".join(out)


_ABAQUS_COMMENT = re.compile(rb"^\*\*[^\n]*(?:\n|$)", re.MULTILINE)
_ABAQUS_KEYWORD_LINE = re.compile(rb"^\*(?!\*)[^\n]*", re.MULTILINE)
_ABAQUS_SETS = {b"NSET", b"ELSET"}
_EMPTY_FIELD = re.compile(rb",[ \t]*(?:,|\r?\n|\r?$)")


def _line_words(rows: bytes) -> NDArray[np.int64]:
    """Each line's number of words (runs of characters other than commas and blanks), in a few passes over
    the bytes: the blocks of a large deck hold millions of lines."""
    arr = np.frombuffer(rows, dtype=np.uint8)
    ends = np.flatnonzero(arr == 10)
    if len(arr) and arr[-1] != 10:
        ends = np.append(ends, len(arr))
    word = _WORD_BYTE[arr]
    first = np.flatnonzero(word[1:] & ~word[:-1]) + 1  # where a word starts (after a comma or a blank)
    if len(word) and word[0]:
        first = np.concatenate([[0], first])
    return np.bincount(np.searchsorted(ends, first), minlength=len(ends))[: len(ends)].astype(np.int64)


_WORD_BYTE = np.ones(256, dtype=bool)
_WORD_BYTE[np.frombuffer(b", \t\r\n", dtype=np.uint8)] = False


def _node_rows(rows: bytes) -> bytes:
    """A node block's data lines with Abaqus's defaults written out: the number and three coordinates, an
    omitted or empty one 0, nothing after the third (a normal's direction cosines), no comma at the end."""
    words = _line_words(rows)
    if np.all((words == 4) | (words == 0)) and _EMPTY_FIELD.search(rows) is None:
        return rows
    lines = rows.split(b"\n")
    for k in range(len(lines)):
        line = lines[k]
        if not line.strip():
            continue
        fields = [f.strip() for f in line.rstrip(b"\r").split(b",")]
        while len(fields) > 1 and not fields[-1]:
            fields.pop()  # a comma at the end starts no field
        fields = [f or b"0" for f in fields[:4]] + [b"0"] * (4 - len(fields[:4]))
        lines[k] = b", ".join(fields) + (b"\r" if line.endswith(b"\r") else b"")
    return b"\n".join(lines)


def abaqus_plain(data: bytes) -> bytes:
    """The deck as meshio's line reader takes it right: what Abaqus ignores or defaults, written out.

    - Comment lines (``**``) go: Abaqus allows them anywhere, and meshio
      ended a node or element block at one, then skipped the block's
      remaining lines as an unknown keyword's (CalculiX's beamptied5.inp lost
      2 of its 30 elements, rotor3.inp half its volume, without a word).
    - Node and element sets (``*NSET``, ``*ELSET``) go: they name groups
      and change no solid, and meshio failed on sets it cannot read (a
      ``GENERATE`` line without its increment, which defaults to 1; a set
      naming a node the deck does not define).
    - Node lines get the coordinates Abaqus defaults: an omitted or empty
      coordinate is 0, a comma at the end starts no field, and what follows
      the third coordinate (a normal's direction cosines) is no coordinate.
    - Element lines are read as CalculiX reads them: an element's node
      numbers, from its first line and as many lines after it as it needs,
      up to the number its type has; numbers past that on a line are not
      nodes.  meshio took all numbers of a block as one run and cut it into
      rows of the type's length: one line with two numbers too many failed
      the block (CalculiX's transition.inp), and lines that made up a
      multiple of the length would have been cut at the wrong places.
    """
    if data.startswith(b"**") or b"\n**" in data:
        data = _ABAQUS_COMMENT.sub(b"", data)
    keywords = [(m.start(), _abaqus_keyword(m.group()) or b"") for m in _ABAQUS_KEYWORD_LINE.finditer(data)]
    if not any(k in _ABAQUS_SETS or k in (b"NODE", b"ELEMENT") for _, k in keywords):
        return data
    pieces = [data[: keywords[0][0]] if keywords else data]
    for (start, keyword), (end, _) in zip(keywords, [*keywords[1:], (len(data), b"")], strict=True):
        block = data[start:end]
        if keyword in _ABAQUS_SETS:
            continue
        if keyword == b"NODE":
            head, newline, rows = block.partition(b"\n")
            block = head + newline + _node_rows(rows)
        if keyword == b"ELEMENT":
            head, newline, rows = block.partition(b"\n")
            nodes = _abaqus_element_nodes(head)
            if nodes is not None:
                block = head + newline + _element_rows(rows, nodes)
        pieces.append(block)
    return b"".join(pieces)


def _abaqus_element_nodes(keyword_line: bytes) -> int | None:
    """Nodes per element of an ``*ELEMENT`` line's type, as meshio's tables give it; None where unknown."""
    from meshio import _common
    from meshio.abaqus import _abaqus

    t = _ABAQUS_TYPE.search(keyword_line.partition(b",")[2])
    table = getattr(_abaqus, "abaqus_to_meshio_type", None)
    counts = getattr(_common, "num_nodes_per_cell", None)
    if t is None or not isinstance(table, dict) or not isinstance(counts, dict):
        return None
    name = t.group("type").decode("latin-1")
    cell = table.get(name) or table.get(name.upper())
    nodes = counts.get(cell) if cell is not None else None
    return int(nodes) if isinstance(nodes, int) else None


def _element_rows(rows: bytes, nodes: int) -> bytes:
    """An element block's data lines, one element per line: its number and its first ``nodes`` node numbers,
    gathered from as many lines as it takes (CalculiX's ``elements.f``); the rows as they are where an element
    is left incomplete (meshio then names the fault), or where every element already ends at a line's end
    (meshio's reading is then the same)."""
    counts = _line_words(rows)
    ends = np.cumsum(counts[counts > 0])
    total = int(ends[-1]) if len(ends) else 0
    if total % (nodes + 1) == 0 and np.all(np.isin(np.arange(nodes + 1, total + 1, nodes + 1), ends)):
        return rows
    out: list[bytes] = []
    element: list[bytes] = []
    for line in rows.splitlines():
        words = [w.strip() for w in line.split(b",") if w.strip()]
        if not words:
            continue
        if not element:
            element = words[: nodes + 1]
        else:
            element += words[: nodes + 1 - len(element)]
        if len(element) == nodes + 1:
            out.append(b", ".join(element))
            element = []
    if element:
        return rows
    return b"\n".join(out) + b"\n" if out else rows


def abaqus_one_node_block(data: bytes, label: str) -> bytes:
    """The deck with every ``*NODE`` block's data in its first one, as meshio needs; refuse what it would misread.

    meshio 5.3.5 starts its node table afresh at each ``*NODE``: the elements
    of a deck that lists its nodes in two blocks pointed into the wrong block
    (two tetrahedra came back as the second one twice), or the read failed on
    a node id.  Node ids are the deck's own names, so the blocks are joined
    (ids repeated across blocks, as the parts of an assembly number theirs,
    are refused; the assembly's own reference nodes are left out).  Also refused: node coordinates in a cylindrical or
    spherical system, nodes or elements generated or copied from others,
    and more than one part instance or a placed one, none of which meshio
    applies.
    """
    lines = data.splitlines(keepends=True)
    keywords = [_abaqus_keyword(line) for line in lines]
    starts = [i for i, k in enumerate(keywords) if k is not None] + [len(lines)]
    spans = list(itertools.pairwise(starts))  # each keyword line and the end of its data lines
    for i, j in spans:
        _refuse_unapplied(keywords[i] or b"", lines[i], lines[i + 1 : j], label)
    if sum(k == b"INSTANCE" for k in keywords) > 1:
        raise UnsupportedFormatError(
            f"{label} places more than one part instance (*INSTANCE), which this reader does not do; export the "
            "assembly flattened (without *PART and *INSTANCE)",
            keyword="INSTANCE",
        )
    # nodes of the assembly itself (reference points, between *ASSEMBLY and *END ASSEMBLY outside an instance)
    # are numbered apart from the parts' nodes and are no solid's corners: left out
    blocks: list[tuple[int, int]] = []
    reference_points: list[tuple[int, int]] = []
    section: dict[bytes, bool] = {b"ASSEMBLY": False, b"INSTANCE": False}
    for i, j in spans:
        keyword = keywords[i] or b""
        for name in section:
            if keyword in (name, b"END" + name):
                section[name] = keyword == name
        if keyword == b"NODE":
            (reference_points if section[b"ASSEMBLY"] and not section[b"INSTANCE"] else blocks).append((i, j))
    if len(blocks) < 2 and not reference_points:
        return data
    if len(blocks) < 2:
        dropped = {i for start, end in reference_points for i in range(start, end)}
        return b"".join(line for i, line in enumerate(lines) if i not in dropped)
    rows = [line for start, end in blocks for line in lines[start + 1 : end] if line.strip() and not line.startswith(b"**")]
    seen: set[int] = set()
    for row in rows:
        try:
            node = int(row.partition(b",")[0])  # as meshio reads it: 01 and 1 are one node
        except ValueError:
            continue  # not a node id: meshio says so
        if node in seen:
            raise UnsupportedFormatError(
                f"{label} defines node {node} in two *NODE blocks (as the parts of an assembly "
                "number their nodes each from 1); export the model flattened, with one numbering",
                keyword="NODE",
            )
        seen.add(node)
    if rows and not rows[-1].endswith((b"\n", b"\r")):
        rows[-1] += b"\n"
    first = blocks[0][0]
    dropped = {i for start, end in blocks + reference_points for i in range(start, end)}
    return b"".join([*lines[: first + 1], *rows, *(line for i, line in enumerate(lines) if i > first and i not in dropped)])


_ABAQUS_ROW_NUMBER = re.compile(rb"^[ \t]*([0-9]+)[ \t]*,", re.MULTILINE)


def _refuse_renumbered(data: bytes, label: str) -> None:
    """Refuse a deck (plain, its nodes in one block) that gives two nodes or two elements one number: meshio
    kept the last coordinates of a node and counted a repeated element twice, a body no other reader gives."""
    keywords = [(m.start(), _abaqus_keyword(m.group()) or b"") for m in _ABAQUS_KEYWORD_LINE.finditer(data)]
    numbers: dict[bytes, list[bytes]] = {b"NODE": [], b"ELEMENT": []}
    for (start, keyword), (end, _) in zip(keywords, [*keywords[1:], (len(data), b"")], strict=True):
        head, _, rows = data[start:end].partition(b"\n")
        # an element block of a type meshio's tables lack may keep continuation lines, which start with a node
        if keyword == b"NODE" or (keyword == b"ELEMENT" and _abaqus_element_nodes(head) is not None):
            numbers[keyword] += _ABAQUS_ROW_NUMBER.findall(rows)
    for keyword, found in numbers.items():
        values = np.sort(np.array([int(n) for n in found], dtype=np.int64))
        repeated = values[1:][values[1:] == values[:-1]]
        if len(repeated):
            what = "node" if keyword == b"NODE" else "element"
            raise UnreadableFileError(
                f"{label} defines {what} {int(repeated[0])} more than once ({len(repeated)} repeated {what} numbers), "
                f"so which body it means is ambiguous: number each {what} once",
                keyword=keyword.decode(),
            )


def _all_zero(rows: list[bytes]) -> bool:
    """Whether every number on the data lines ``rows`` (comments aside) is zero; False if one is not a number."""
    try:
        return all(float(v) == 0.0 for row in rows if not row.startswith(b"**") for v in row.split(b",") if v.strip())
    except ValueError:
        return False


def _refuse_unapplied(keyword: bytes, line: bytes, data: list[bytes], label: str) -> None:
    """Refuse a keyword that makes, copies or moves nodes or elements, which meshio ignores."""
    if keyword in _ABAQUS_GENERATED:
        raise UnsupportedFormatError(
            f"{label} {_ABAQUS_GENERATED[keyword]} with *{keyword.decode()}, which this reader does not apply; "
            "export the deck with every node and element written out (*NODE and *ELEMENT data)",
            keyword=keyword.decode(),
        )
    if keyword == b"NODE":
        system = _ABAQUS_SYSTEM.search(line.partition(b",")[2])
        if system and system.group("system").upper() != b"R":
            raise UnsupportedFormatError(
                f"{label} gives node coordinates in another system than Cartesian (*NODE, SYSTEM="
                f"{system.group('system').decode('latin-1')[:8]}), which this reader does not convert; "
                "export them in Cartesian coordinates",
                keyword="NODE",
            )
    if keyword == b"SYSTEM" and not _all_zero(data):
        raise UnsupportedFormatError(
            f"{label} sets a local coordinate system for the nodes after it (*SYSTEM), which this reader does not "
            "apply; export the node coordinates in the global system",
            keyword="SYSTEM",
        )
    if keyword == b"INSTANCE":
        placement = [row for row in data if row.strip() and not row.startswith(b"**")]
        if len(placement) > 1 or not _all_zero(placement):
            raise UnsupportedFormatError(
                f"{label} places a part instance (a translation or rotation under *INSTANCE), which this reader "
                "does not apply; export the assembly flattened (without *PART and *INSTANCE)",
                keyword="INSTANCE",
            )


def _binary_items_beside(path: str) -> None:
    """Point the XDMF file's ``Binary`` data items at the files of its private folder, by absolute path.

    meshio reads a Binary item's file name relative to the process's working directory (``np.fromfile``),
    not to the XDMF file: a name that is a file of the server's working directory would have been read
    instead of the upload's own file.  The guard admits plain names of the upload's files only; each is
    written here as the path of that file in the folder (missing there: meshio says the file is not found).
    """
    folder = os.path.dirname(path)
    with open(path, "rb") as fh:
        text = fh.read()

    def beside(m: re.Match[bytes]) -> bytes:
        if xml_attributes(m.group(1)).get("Format", "").upper() != "BINARY" or not m.group(2).strip():
            return m.group(0)
        name = _safe_name(m.group(2).strip().decode("utf-8", "replace"))
        return m.group(0)[: m.start(2) - m.start(0)] + os.path.join(folder, name or "missing").encode()

    changed = XDMF_DATA_ITEM.sub(beside, text)
    if changed != text:
        with open(path, "wb") as out:
            out.write(changed)


_XDMF_TEMPORAL = re.compile(rb"CollectionType\s*=\s*[\"']Temporal[\"']", re.IGNORECASE)


def _xdmf_time_series_mesh(path: str) -> Any:
    """The mesh of an XDMF time series (a temporal collection of grids over one mesh, as dolfinx and meshio's
    ``TimeSeriesWriter`` write results): its points and cells, the steps' fields left aside.

    meshio's ``TimeSeriesReader`` takes the last grid beside the collection, else the first step's own
    mesh: several grids beside it, or a spatial collection, are refused as ``meshio.read`` refuses them;
    steps that each carry their own mesh (one that moves) are weighed at the first step, with a note.
    """
    import xml.etree.ElementTree as ET

    import meshio

    domain = ET.parse(path).getroot().find("Domain")  # the guard has refused entities and document types
    grids = [] if domain is None else domain.findall("Grid")
    meshes = [g for g in grids if g.get("GridType", "Uniform") == "Uniform"]
    kinds = {g.get("CollectionType", "Spatial") for g in grids if g.get("GridType") == "Collection"}
    if len(meshes) > 1 or kinds - {"Temporal"}:
        what = f"{len(meshes)} meshes beside its time series" if len(meshes) > 1 else "a spatial collection of grids"
        raise UnsupportedFormatError(
            f"the XDMF file holds {what}, which are not read as one body; send one mesh per file", format="xdmf"
        )
    notes = []
    steps = [s for g in grids if g.get("GridType") == "Collection" for s in g.findall("Grid")]
    own = [s for s in steps if s.find("Geometry") is not None]
    if not meshes and len(own) > 1:
        notes.append(f"the XDMF time series' {len(steps)} steps each carry their own mesh; the mesh of its first step was weighed")
    points, cells = meshio.xdmf.TimeSeriesReader(path).read_points_cells()
    return meshio.Mesh(points, cells, info=notes)


def _meshio_read(data: bytes, fmt: str, label: str, filename: str | None, companions: Mapping[str, bytes] | None) -> Any:
    """``meshio.read`` of the upload in its private folder; every failure an ``UnreadableFileError``."""
    import meshio

    with _upload_dir(data, fmt, filename, companions) as path, _quiet() as printed, _without_hdf5(data, fmt):
        try:
            if fmt == "xdmf":
                _binary_items_beside(path)
            if fmt == "xdmf" and _XDMF_TEMPORAL.search(data):
                return _xdmf_time_series_mesh(path)
            return meshio.read(path, file_format=VOLUME_FORMATS[fmt])
        except (KeyboardInterrupt, UnsupportedFormatError):  # ours: said as it stands
            raise
        except BaseException as exc:  # meshio calls sys.exit(1) and raises KeyError, ValueError, ...
            if isinstance(exc, ImportError) and (exc.name or "").partition(".")[0] == "h5py":
                raise _hdf5_missing(label, fmt, exc) from exc
            if fmt == "ele" and isinstance(exc, OSError) and not companions:
                # a reference like any other: the command line reads it from beside the .ele
                node = f"{os.path.splitext(os.path.basename(filename or 'upload.ele'))[0]}.node"
                raise ExternalReferenceError(
                    f"{label} needs its companion file {node!r} (the point coordinates): upload both, as a .zip or as two files",
                    format=fmt,
                    reference=node,
                    reference_kind="TetGen node file",
                ) from exc
            raise UnreadableFileError(_meshio_failure(exc, printed.getvalue(), path, fmt, label, companions), format=fmt) from exc


def _gmsh_retry(data: bytes, exc: UnreadableFileError, label: str) -> bytes | None:
    """The Gmsh file without what meshio could not split between its cell blocks ("Incompatible cell data"),
    where that weighs nothing; None where there is no such part to leave out.

    - An MSH 4 file whose elements lie in entities of which only some carry physical tags (Gmsh's
      ``Mesh.SaveAll``: a physical volume beside untagged surfaces): the tags only name the parts, so the
      file is read without its ``$Entities``, and a text file's parts are named from them again
      (``gmsh_entity_physicals``; a binary file's by cell type).
    - A data field over several cell blocks (libigl's tutorial hand.msh): results and tags weigh nothing,
      so the file is read without its data sections; a ``density`` field is refused by name instead.
    - A text MSH 2 file whose elements carry different numbers of tags (FreeFem's: lines with one, triangles
      with two; legal in MSH 2): meshio cannot split them between its blocks, so each element is given the
      two tags (physical, elementary) it lacks as 0 (``_msh2_two_tags``).
    """
    cause = exc.__cause__
    if not isinstance(cause, ValueError) or "Incompatible cell data" not in str(cause):
        return None
    version = _gmsh_format(data)
    padded = _msh2_two_tags(data) if version is not None and version[0] == 2 and version[2] else None
    if padded is not None:
        return padded
    if "'gmsh:" in str(cause):
        return _GMSH_ENTITIES.sub(b"", data, count=1)
    fields = _gmsh_data_fields(data)
    if not fields:
        return None
    if "density" in fields:
        raise UnreadableFileError(
            f"{label} has a 'density' field that its reader (meshio) cannot split between the file's cell "
            f"blocks ({cause}); write the density for the 3-D elements alone, or convert the mesh to VTK (.vtu)",
            format="msh",
        ) from exc
    return _GMSH_DATA.sub(b"", data)


_MSH2_ELEMENTS = re.compile(rb"(\$Elements[^\S\n]*\r?\n[^\n]*\n)(.*?)(\$EndElements)", re.DOTALL)


def _msh2_element_lengths(data: bytes, label: str) -> None:
    """Refuse a text MSH 2 file with an element line longer or shorter than its type's node count.

    An element line is ``number type ntags tag... node...`` (gmsh.info, "MSH file format version 2"), the
    node count fixed by the type; Gmsh refuses a line that lists another count, and meshio takes the last
    nodes of the line as the element's, silently (a hexahedron written with the type number of a
    tetrahedron became a tetrahedron of four of its nodes).
    """
    version = _gmsh_format(data)
    section = _MSH2_ELEMENTS.search(data) if version is not None and version[0] == 2 and version[2] else None
    if section is None:
        return
    from meshio._common import num_nodes_per_cell
    from meshio.gmsh.common import _gmsh_to_meshio_type

    length: dict[tuple[bytes, bytes], int] = {}  # (type, ntags) as written -> the line's field count (0: unknown)
    for line in section.group(2).split(b"\n"):
        fields = line.split()
        if len(fields) < 3:
            continue  # not an element line: meshio names what is wrong with it
        key = (fields[1], fields[2])
        expected = length.get(key)
        if expected is None:
            kind = _gmsh_to_meshio_type.get(int(key[0])) if key[0].isdigit() and key[1].isdigit() else None
            nodes = num_nodes_per_cell.get(kind, 0) if kind is not None else 0
            expected = length[key] = 3 + int(key[1]) + nodes if nodes else 0
        if expected and len(fields) != expected:
            kind, tags = _gmsh_to_meshio_type[int(key[0])], int(key[1])
            raise UnreadableFileError(
                f"element {fields[0].decode(errors='replace')} of {label} has type {int(key[0])} (a "
                f"{num_nodes_per_cell[kind]}-node {kind}) but lists {len(fields) - 3 - tags} nodes after its {tags} "
                "tags; Gmsh itself refuses such a line: correct its type number or its nodes, or export the mesh again",
                format="msh",
            )


def _msh2_two_tags(data: bytes) -> bytes | None:
    """A text MSH 2 file with every element's tags padded with zeros to two, or None where none has fewer.

    An element line is ``number type ntags tag... node...`` (gmsh.info, "MSH file format version 2").
    """
    section = _MSH2_ELEMENTS.search(data)
    if section is None:
        return None
    lines = section.group(2).split(b"\n")
    changed = False
    for k, line in enumerate(lines):
        fields = line.split()
        if len(fields) >= 3 and fields[2].isdigit() and int(fields[2]) < 2:
            tags = int(fields[2])
            fields[2 : 3 + tags] = [b"2", *fields[3 : 3 + tags], *([b"0"] * (2 - tags))]
            lines[k] = b" ".join(fields)
            changed = True
    if not changed:
        return None
    return data[: section.start(2)] + b"\n".join(lines) + data[section.end(2) :]


_GMSH_ENTITIES = re.compile(rb"\$Entities\r?\n.*?\$EndEntities[^\S\n]*\r?(\n|\Z)", re.DOTALL)
# a Gmsh file's data sections (gmsh.info, "MSH file format": $NodeData, $ElementData, $ElementNodeData), from the
# section's name to its end marker; their first string tag is the field's name
_GMSH_DATA = re.compile(rb"\$(NodeData|ElementData|ElementNodeData)\r?\n.*?\$End\1[^\S\n]*\r?(\n|\Z)", re.DOTALL)
_GMSH_FIELD_NAME = re.compile(rb"\A\$\w+\r?\n\s*\d+\s*\r?\n\s*\"([^\"\n]*)\"")


def gmsh_entity_physicals(data: bytes) -> dict[tuple[int, int], list[int]]:
    """The physical tags of each entity (dimension, tag) of a text MSH 4 file's ``$Entities``; empty where
    there are none to read (binary files, or a section that does not parse).

    gmsh.info, "MSH file format" (4.1): a line of the four entity counts, then a point per line
    ``tag x y z numPhysicalTags tags...`` (4.0: a box of six numbers instead of x y z), then curves,
    surfaces and volumes ``tag minX minY minZ maxX maxY maxZ numPhysicalTags tags... numBounding tags...``.
    """
    version = _gmsh_format(data)
    section = _GMSH_ENTITIES.search(data)
    if version is None or version[0] != 4 or not version[2] or section is None:
        return {}
    point_box = 6 if version[1] == 0 else 3
    try:
        tokens = [int(float(t)) for t in section.group(0).split()[1:-1]]
        counts, pos = tokens[:4], 4
        out: dict[tuple[int, int], list[int]] = {}
        for dim, n in enumerate(counts):
            for _ in range(n):
                tag = tokens[pos]
                pos += 1 + (point_box if dim == 0 else 6)
                n_phys = tokens[pos]
                out[(dim, tag)] = tokens[pos + 1 : pos + 1 + n_phys]
                pos += 1 + n_phys
                if dim > 0:
                    pos += 1 + abs(tokens[pos])
    except (ValueError, IndexError, OverflowError):  # a token that is no number, "inf", a count past the end
        return {}
    return out


def _restore_physical_tags(mesh: Any, physicals: dict[tuple[int, int], list[int]]) -> None:
    """``gmsh:physical`` of each cell block from its entity's tags (0 where it has none or several), in place."""
    from meshio import _mesh

    entities = mesh.cell_data.get("gmsh:geometrical")
    if not physicals or entities is None:
        return
    dims = getattr(_mesh, "topological_dimension", {})
    tags = []
    for block, entity in zip(mesh.cells, entities, strict=True):
        found = physicals.get((dims.get(block.type, -1), int(entity[0]) if len(entity) else -1), [])
        tags.append(np.full(len(block.data), found[0] if len(found) == 1 else 0, dtype=np.int64))
    mesh.cell_data["gmsh:physical"] = tags


def _gmsh_data_fields(data: bytes) -> set[str]:
    """The names of a Gmsh file's data fields (``"?"`` for one whose name cannot be read)."""
    names = set()
    for match in _GMSH_DATA.finditer(data):
        name = _GMSH_FIELD_NAME.match(match.group(0))
        names.add(name.group(1).decode("utf-8", "replace") if name else "?")
    return names


def _meshio_failure(
    exc: BaseException, printed: str, path: str, fmt: str, label: str, companions: Mapping[str, bytes] | None
) -> str:
    reason = _reason(exc, printed, (path, os.path.dirname(path)))
    if isinstance(exc, (FileNotFoundError, OSError)) and ".node" in str(exc):
        return f"{label} refers to a companion file that was not uploaded ({reason}); upload it with the mesh"
    return f"could not read {label}: {reason}; check that the file is complete and of the format its name says"


def _mesh_from_meshio(mesh: Any, label: str) -> _Mesh:
    try:
        points = np.asarray(mesh.points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise UnreadableFileError(f"{label} has point coordinates that are not numbers") from exc
    if points.ndim != 2 or points.shape[1] not in (2, 3) or len(points) == 0:
        raise EmptyGeometryError(f"{label} holds no points; send a mesh with 3-D cells")
    if points.shape[1] == 2:
        raise EmptyGeometryError(f"{label} is two-dimensional; a volume needs 3-D cells (tetrahedra, hexahedra, ...)")
    densities = mesh.cell_data.get("density")
    names = _block_names(mesh)
    out = _Mesh(points, [], None, {})
    unsupported: dict[str, int] = {}
    per_cell: list[NDArray[np.float64]] = []
    start = 0
    for i, block in enumerate(mesh.cells):
        ctype = _ALIASES.get(block.type, block.type)
        nodes = np.asarray(block.data, dtype=np.int64)
        ids = np.arange(start, start + len(nodes))
        start += len(nodes)
        if densities is not None:
            per_cell.append(np.asarray(densities[i], dtype=np.float64).reshape(-1))
        if ctype in _MESHIO_OTHER_3D:
            unsupported[ctype] = unsupported.get(ctype, 0) + len(nodes)
        elif ctype not in _NODES:
            out.other[ctype] = out.other.get(ctype, 0) + len(nodes)
        elif len(nodes):
            if nodes.ndim != 2 or nodes.shape[1] != _NODES[ctype]:
                raise UnreadableFileError(
                    f"{label} has {ctype} cells with {nodes.shape[-1]} nodes each; "
                    f"a {ctype} has {_NODES[ctype]}: the file is inconsistent"
                )
            if ctype == "voxel":
                nodes, ctype = nodes[:, VOXEL_TO_HEXAHEDRON], "hexahedron"
            out.blocks.append(_Block(ctype, nodes, ids, names[i]))
    if unsupported:
        raise UnsupportedFormatError(_unsupported_cells(label, unsupported), cell_types=sorted(unsupported))
    if out.blocks:
        flat = [np.asarray(b.data, dtype=np.int64).ravel() for b in mesh.cells if _ALIASES.get(b.type, b.type) not in _NODES]
        _surface_apart_warning(out, np.concatenate(flat) if flat else np.empty(0, np.int64), label)
    if not out.blocks:
        faces = [np.asarray(b.data, dtype=np.int64) for b in mesh.cells if b.type in _MESHIO_POLYGONS]
        faces = [f for f in faces if f.ndim == 2 and f.shape[1] >= 3 and len(f)]
        if faces:
            counts = np.concatenate([np.full(len(f), f.shape[1]) for f in faces])
            out.surface = _Surface(np.concatenate([f.ravel() for f in faces]), counts, [], len(counts))
    if densities is not None:
        values = np.concatenate(per_cell) if per_cell else np.empty(0)
        if len(values) != start:
            raise UnreadableFileError(f"{label} has a 'density' cell array that does not give one value per cell", field="density")
        out.density = values
    return out


_MESHIO_POLYGONS = ("triangle", "quad", "polygon")  # linear faces, corners in order around each


def _block_names(mesh: Any) -> list[str]:
    tags = mesh.cell_data.get("gmsh:physical")
    by_tag = {int(v[0]): k for k, v in (mesh.field_data or {}).items() if np.size(v)}
    names = []
    for i, block in enumerate(mesh.cells):
        name = f"{block.type}_{i}"
        if tags is not None and len(tags[i]) and np.all(tags[i] == tags[i][0]):
            name = by_tag.get(int(tags[i][0]), name)
        names.append(name)
    return names


# ----------------------------------------------------------------------------------------------
# Parts


def _surface_part(mesh: _Mesh, surface: _Surface, label: str, length_scale: float) -> Part:
    """A file without 3-D cells whose linear 2-D cells may close a solid: read as its surface, as STL is.

    The solid path then decides: a closed surface is weighed (its winding made outward, with the
    usual warnings), an open one is refused as ``not_watertight`` (or weighed with ``model=shell``).
    """
    tris = surface.triangles()
    if len(tris) == 0:
        raise EmptyGeometryError(f"{label} has no 3-D cells and its surface cells have fewer than three corners each")
    if tris.min() < 0 or tris.max() >= len(mesh.points):
        raise UnreadableFileError(f"{label} has a surface cell that refers to a point that does not exist; the file is corrupt")
    if not np.all(np.isfinite(mesh.points)):
        raise UnreadableFileError(f"{label} has point coordinates that are NaN or infinite; fix the mesh")
    used, faces = np.unique(tris, return_inverse=True)  # only the surface's own points
    vertices = mesh.points[used]
    faces = faces.reshape(-1, 3)
    left_out = [(t, n) for t, n in sorted(mesh.other.items()) if t not in _SURFACE_CELL_NAMES]
    rest = ", ".join(f"{n} {t}" for t, n in left_out)
    if mesh.polydata:  # a surface by its kind: only what was left out needs saying
        cells = ", ".join(_count(n, f"{t} cell") for t, n in left_out)
        notes = [f"{label} also holds {cells}, which bound no solid and were left out"] if cells else []
    else:
        notes = [
            f"{label} has no 3-D cells: its {_count(surface.cells, 'surface cell')} ({_count(len(faces), 'triangle')}) "
            f"{'was' if surface.cells == 1 else 'were'} read as a triangle surface, as an STL file is"
            + (f"; its other cells ({rest}) were left out" if rest else "")
        ]
    if mesh.density is not None:
        notes.append(f"{label} has a 'density' cell array: a surface has no cells of its own, so it was not used")
    with np.errstate(all="ignore"):  # coordinates near float64's limits: the solid path refuses them by name
        x = vertices - vertices.mean(axis=0)
        volume = abs(float(np.einsum("ij,ij->", x[faces[:, 0]], np.cross(x[faces[:, 1]], x[faces[:, 2]])))) / 6
        split = fan_split_note(mesh.points, surface.corners, surface.counts, "surface", volume=volume)
    notes += [split] if split else []
    # float32 points (VTK's "POINTS n float") resolve the body only so finely: the solid path checks it
    body = MeshBody(vertices, faces, length_scale, "surface", (*notes, *mesh.warnings), coordinate_eps=stored_eps(vertices))
    return Part("surface", body)


_SURFACE_CELL_NAMES = frozenset({"triangle", "quad", "polygon", "pixel", "triangle strip"})


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" + ("" if n == 1 else "s")


def _unsupported_cells(label: str, counts: Mapping[str, int]) -> str:
    listed = ", ".join(f"{n} {t}" for t, n in sorted(counts.items()))
    # Gmsh's default second order adds a node at each quadrilateral face (pyramid14, Gmsh's 14-node pyramid):
    # its "incomplete" second order leaves those out (13 nodes), which is read
    incomplete = "; in Gmsh, set Mesh.SecondOrderIncomplete = 1 for 13-node pyramids" if "pyramid14" in counts else ""
    return (
        f"{label} holds 3-D cells we cannot integrate exactly ({listed}); convert them to tetrahedra, "
        f"hexahedra, wedges or pyramids (linear or quadratic), for example with Gmsh{incomplete}"
    )


def _parts(mesh: _Mesh, label: str, length_scale: float) -> list[Part]:
    if not mesh.blocks and mesh.surface is not None:
        return [_surface_part(mesh, mesh.surface, label, length_scale)]
    if not mesh.blocks and mesh.polydata:
        found = ", ".join(_count(n, f"{t} cell") for t, n in sorted(mesh.other.items())) or "no cells at all"
        raise EmptyGeometryError(
            f"{label} holds no polygons or triangle strips (only {found}), so nothing in it bounds a solid; send a closed surface"
        )
    if not mesh.blocks:
        found = ", ".join(f"{n} {t}" for t, n in sorted(mesh.other.items())) or "no cells at all"
        raise EmptyGeometryError(
            f"{label} has no 3-D cells (it holds {found}); send tetrahedra, hexahedra, wedges or pyramids, "
            "or a closed surface of linear triangles or polygons (here, or in STL, OBJ, PLY, ...)"
        )
    if not np.all(np.isfinite(mesh.points)):
        raise UnreadableFileError(f"{label} has point coordinates that are NaN or infinite; fix the mesh")
    if mesh.density is not None and mesh.blocks and np.any(mesh.density[np.concatenate([b.cell_ids for b in mesh.blocks])] <= 0):
        raise UnreadableFileError(
            f"{label} has cells whose 'density' is zero or negative; densities must be positive (kg/m^3)", field="density"
        )
    for b in mesh.blocks:
        if b.nodes.size and (b.nodes.min() < 0 or b.nodes.max() >= len(mesh.points)):
            raise UnreadableFileError(
                f"{label} has a {b.type} cell that refers to a point that does not exist; the file is corrupt"
            )
    parts: list[Part] = []
    for i, b in enumerate(mesh.blocks):
        notes = tuple(mesh.warnings) if i == 0 else ()  # file-wide notes, said once
        rho = None if mesh.density is None else mesh.density[b.cell_ids]
        if b.type == "tetra":
            body = VolumeBody(mesh.points, b.nodes, rho, length_scale, b.name, notes, tet_cells=b.file_cells)
        else:
            body = VolumeBody(
                mesh.points, np.empty((0, 4), np.int64), None, length_scale, b.name, notes, (CellBlock(b.type, b.nodes, rho),)
            )
        parts.append(Part(b.name, body))
    return parts
