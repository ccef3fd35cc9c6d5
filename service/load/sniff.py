"""Format detection: the explicit ``format`` wins, then the file name, then content."""

from __future__ import annotations

import importlib.util
import re
from functools import cache

from ..errors import UnsupportedFormatError

__all__ = [
    "SURFACE_FORMATS",
    "VOLUME_FORMATS",
    "SCENE_FORMATS",
    "POINT_FORMATS",
    "CAD_FORMATS",
    "VTK_FORMATS",
    "sniff_format",
    "FORMATS",
    "OPTIONAL_READERS",
    "unavailable_formats",
]

# surface meshes: read through our STL reader or trimesh, and VTK XML polydata (.vtp) through VTK
SURFACE_FORMATS = ("stl", "obj", "ply", "off", "glb", "gltf", "3mf", "vtp")
# volume meshes read through meshio (extension -> meshio file_format), those of ``VTK_FORMATS`` through VTK
VOLUME_FORMATS = {
    "vtu": "vtu",
    "vtk": "vtk",
    "vts": "vts",
    "vtr": "vtr",
    "vti": "vti",
    "msh": "gmsh",
    "mesh": "medit",
    "inp": "abaqus",
    "xdmf": "xdmf",
    "med": "med",
    "f3grid": "flac3d",
    "dat": "tecplot",
    "ugrid": "ugrid",
    "ele": "tetgen",
}
# read by VTK's own readers (the ``vtk`` extra): the legacy format and the serial XML data sets, by the
# data set type each XML file declares
VTK_FORMATS = ("vtk", "vtu", "vtp", "vts", "vtr", "vti")
VTK_XML_TYPES = {
    "UnstructuredGrid": "vtu",
    "PolyData": "vtp",
    "StructuredGrid": "vts",
    "RectilinearGrid": "vtr",
    "ImageData": "vti",
}
# formats that can hold several named bodies
SCENE_FORMATS = ("glb", "gltf", "3mf", "obj", "vtu", "vtk", "msh", "mesh", "inp", "xdmf", "med", "step", "iges")
POINT_FORMATS = ("json", "csv", "xyz")  # xyz: atoms by element, in angstrom
# B-rep solids read through OpenCASCADE (the ``cad`` extra)
CAD_FORMATS = ("step", "iges")
FORMATS = SURFACE_FORMATS + tuple(VOLUME_FORMATS) + CAD_FORMATS

# format -> (module its reader imports, what to install)
OPTIONAL_READERS: dict[str, tuple[str, str]] = {
    "xdmf": ("h5py", "the 'hdf5' extra: pip install 'inertia-service[hdf5]'"),
    "med": ("h5py", "the 'hdf5' extra: pip install 'inertia-service[hdf5]'"),
    **{f: ("vtkmodules", "the 'vtk' extra: pip install 'inertia-service[vtk]'") for f in VTK_FORMATS},
    "step": ("OCP", "the 'cad' extra: pip install 'inertia-service[cad]'"),
    "iges": ("OCP", "the 'cad' extra: pip install 'inertia-service[cad]'"),
}


@cache
def unavailable_formats() -> dict[str, str]:
    """Formats whose reader cannot be imported here, with what enables each."""
    return {fmt: needs for fmt, (module, needs) in OPTIONAL_READERS.items() if importlib.util.find_spec(module) is None}


def _readable() -> str:
    """The formats this installation reads, for a message (those missing a package named apart)."""
    missing = unavailable_formats()
    text = ", ".join(f for f in FORMATS + POINT_FORMATS if f not in missing)
    return text + (f" ({', '.join(missing)} need an optional extra, see /v1/formats)" if missing else "")


_ALIASES = {"extxyz": "xyz", "gmsh": "msh", "stla": "stl", "stlb": "stl", "ascii_stl": "stl", "stp": "step", "igs": "iges"}


def sniff_format(filename: str | None, declared: str | None, head: bytes = b"") -> str:
    """The format key of an input, or ``UnsupportedFormatError``."""
    if declared:
        fmt = _ALIASES.get(declared.lower().lstrip("."), declared.lower().lstrip("."))
        if fmt not in FORMATS and fmt not in POINT_FORMATS:
            raise UnsupportedFormatError(
                f"format {declared!r} is not supported; readable formats are {_readable()}",
                format=declared,
            )
        return fmt
    if filename and "." in filename:
        ext = filename.rsplit(".", 1)[1].lower()
        ext = _ALIASES.get(ext, ext)
        if ext in FORMATS or ext in POINT_FORMATS:
            return ext
        part = " (a .model file is the XML part inside a 3MF package: send the .3mf file itself)" if ext == "model" else ""
        raise UnsupportedFormatError(
            f"cannot read files ending in .{ext}{part}; readable formats are {_readable()} "
            "(or pass format=... if the name is misleading)",
            format=ext,
        )
    guessed = _from_content(head)
    if guessed:
        return guessed
    raise UnsupportedFormatError(
        "cannot tell the file's format from its name; pass format=stl (or obj, ply, ...)", filename=filename
    )


def _from_content(head: bytes) -> str | None:
    if head.startswith(b"glTF"):
        return "glb"
    if head.startswith(b"ply"):
        return "ply"
    if head.startswith(b"OFF"):
        return "off"
    if head.startswith(b"$MeshFormat"):
        return "msh"
    if head.lstrip()[:5].lower() == b"solid":
        return "stl"
    if b"<VTKFile" in head[:200]:
        return vtk_xml_type(head) or "vtu"
    if head.lstrip().startswith(b"ISO-10303-21"):
        return "step"
    if len(head) >= 80 and head[72:73] == b"S" and head[73:80].strip().isdigit():  # IGES start section, column 73
        return "iges"
    return None


_VTK_XML_ROOT = re.compile(rb"<VTKFile\b[^>]*?\btype\s*=\s*[\"']([^\"']*)[\"']")


def vtk_xml_root_type(head: bytes) -> str | None:
    """The data set type a VTK XML file's root declares (``<VTKFile type="PolyData"``), else None."""
    match = _VTK_XML_ROOT.search(head[:1024])
    return match.group(1).decode("utf-8", "replace")[:60] if match else None


def vtk_xml_type(head: bytes) -> str | None:
    """The format key of the serial data set a VTK XML file declares, else None."""
    return VTK_XML_TYPES.get(vtk_xml_root_type(head) or "")
