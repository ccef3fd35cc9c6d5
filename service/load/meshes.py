"""Adapters to trimesh (surface meshes and scenes) and meshio (volume meshes).

Only geometry is read: materials, textures, normals and colours are skipped
(``skip_materials``) and trimesh's processing is off (``process=False``) so
the polyhedron is exactly the one in the file.  Third-party exceptions are
translated here; nothing above ``load/`` sees them.
"""

from __future__ import annotations

import io
import os
import tempfile
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..body import MeshBody, Part, VolumeBody
from ..errors import EmptyGeometryError, UnreadableFileError
from .sniff import VOLUME_FORMATS

__all__ = ["read_trimesh_parts", "read_meshio_parts", "TET_SPLITS"]

# Each 3-D cell type split into tetrahedra by node index (VTK/meshio node order).
# Hexahedron: six tetrahedra around the diagonal 0-6; wedge: three; pyramid: two.
TET_SPLITS: dict[str, NDArray[np.int64]] = {
    "tetra": np.array([[0, 1, 2, 3]]),
    "hexahedron": np.array([[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]),
    "wedge": np.array([[0, 1, 2, 3], [1, 2, 3, 4], [2, 3, 4, 5]]),
    "pyramid": np.array([[0, 1, 2, 4], [0, 2, 3, 4]]),
}
_HIGHER_ORDER = {"tetra10": "tetra", "hexahedron20": "hexahedron", "hexahedron27": "hexahedron",
                 "wedge15": "wedge", "wedge18": "wedge", "pyramid13": "pyramid", "pyramid14": "pyramid"}


def read_trimesh_parts(data: bytes, fmt: str, length_scale: float) -> tuple[list[Part], str | None]:
    """Parts of a surface file (one per scene node) and the unit it declares."""
    import trimesh

    if fmt == "gltf":
        _check_gltf_self_contained(data)
    extra: dict[str, Any] = {"split_objects": True, "split_groups": True, "group_material": False} if fmt == "obj" else {}
    try:
        scene = trimesh.load_scene(
            io.BytesIO(data), file_type=fmt, process=False, skip_materials=True, merge_primitives=False, **extra
        )
    except Exception as exc:  # trimesh raises many types for bad input
        raise UnreadableFileError(f"could not read the {fmt.upper()} file: {_short(exc)}", format=fmt) from exc
    parts: list[Part] = []
    # sorted: the scene graph's node order is not stable across processes
    for node in sorted(scene.graph.nodes_geometry, key=str):
        transform, geom_name = scene.graph[node]
        geom = scene.geometry.get(geom_name)
        if not isinstance(geom, trimesh.Trimesh) or len(geom.faces) == 0:
            continue
        vertices = np.asarray(geom.vertices, dtype=np.float64)
        t = np.asarray(transform, dtype=np.float64)
        if not np.array_equal(t, np.eye(4)):
            vertices = vertices @ t[:3, :3].T + t[:3, 3]
        name = str(node) if node != geom_name or len(scene.graph.nodes_geometry) > 1 else str(geom_name)
        parts.append(Part(name, MeshBody(vertices, np.asarray(geom.faces, dtype=np.int64), length_scale, name)))
    if not parts:
        raise EmptyGeometryError(f"the {fmt.upper()} file holds no triangles")
    return parts, _declared_unit(scene, fmt)


def _check_gltf_self_contained(data: bytes) -> None:
    """A .gltf upload must carry its buffers; external files are never read."""
    import json

    try:
        doc = json.loads(data)
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise UnreadableFileError(f"the glTF file is not valid JSON ({exc})", format="gltf") from exc
    buffers = doc.get("buffers", []) if isinstance(doc, dict) else []
    external = [b.get("uri") for b in buffers if isinstance(b, dict) and b.get("uri")
                and not str(b.get("uri")).startswith("data:")]
    if external:
        raise UnreadableFileError(
            f"the glTF file refers to external buffer files ({', '.join(map(str, external))}); "
            "upload a .glb, or a .gltf with embedded (data URI) buffers",
            format="gltf",
        )


def _declared_unit(scene: Any, fmt: str) -> str | None:
    if fmt in ("glb", "gltf"):
        return "m"  # glTF 2.0 specification, section 3.4: units are metres
    units = (scene.metadata or {}).get("units") or getattr(scene, "units", None)
    if not units:
        for geom in scene.geometry.values():
            units = (geom.metadata or {}).get("units")
            if units:
                break
    return _UNIT_NAMES.get(str(units).lower()) if units else None


_UNIT_NAMES = {
    "micron": "um", "micrometer": "um", "micrometre": "um", "um": "um",
    "millimeter": "mm", "millimetre": "mm", "millimeters": "mm", "mm": "mm",
    "centimeter": "cm", "centimetre": "cm", "centimeters": "cm", "cm": "cm",
    "meter": "m", "metre": "m", "meters": "m", "m": "m",
    "inch": "in", "inches": "in", "in": "in",
    "foot": "ft", "feet": "ft", "ft": "ft",
}


def read_meshio_parts(data: bytes, fmt: str, length_scale: float) -> list[Part]:
    """Parts of a volume mesh: one per block of 3-D cells, split into tetrahedra."""
    import meshio

    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, f"upload.{fmt}")
        with open(path, "wb") as fh:
            fh.write(data)
        try:
            mesh = meshio.read(path, file_format=VOLUME_FORMATS[fmt])
        except Exception as exc:  # meshio raises ReadError, KeyError, ValueError, ...
            raise UnreadableFileError(f"could not read the {fmt.upper()} file: {_short(exc)}", format=fmt) from exc
    points = np.asarray(mesh.points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise UnreadableFileError("the volume mesh has no 3-D points")
    if points.shape[1] == 2:
        raise EmptyGeometryError("the mesh is two-dimensional; a volume needs 3-D cells")
    densities = mesh.cell_data.get("density")
    names = _block_names(mesh)
    parts: list[Part] = []
    for i, block in enumerate(mesh.cells):
        ctype = _HIGHER_ORDER.get(block.type, block.type)
        if ctype not in TET_SPLITS:
            continue
        split = TET_SPLITS[ctype]
        nodes = np.asarray(block.data, dtype=np.int64)[:, : split.max() + 1]
        tets = nodes[:, split].reshape(-1, 4)
        rho = None
        if densities is not None:
            rho = np.repeat(np.asarray(densities[i], dtype=np.float64).reshape(-1), len(split))
        parts.append(Part(names[i], VolumeBody(points, tets, rho, length_scale, names[i])))
    if not parts:
        kinds = ", ".join(sorted({b.type for b in mesh.cells})) or "none"
        raise EmptyGeometryError(
            f"the file has no 3-D cells (found: {kinds}); send tetrahedra, hexahedra, wedges or pyramids, "
            "or a closed surface mesh"
        )
    return parts


def _block_names(mesh: Any) -> list[str]:
    tags = mesh.cell_data.get("gmsh:physical")
    by_tag = {int(v[0]): k for k, v in (mesh.field_data or {}).items()}
    names = []
    for i, block in enumerate(mesh.cells):
        name = f"{block.type}_{i}"
        if tags is not None and len(tags[i]) and np.all(tags[i] == tags[i][0]):
            name = by_tag.get(int(tags[i][0]), name)
        names.append(name)
    return names


def _short(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    return text[:200]
