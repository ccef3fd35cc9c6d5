"""Adapters to trimesh (surface meshes and scenes); volume meshes are in ``volume``.

Only geometry is read: materials, textures, normals and colours are skipped
(``skip_materials``) and trimesh's processing is off (``process=False``) so
the polyhedron is exactly the one in the file.  Third-party exceptions are
translated here; nothing above ``load/`` sees them.
"""

from __future__ import annotations

import io
from typing import Any

import numpy as np

from ..body import MeshBody, Part
from ..errors import EmptyGeometryError, UnreadableFileError

__all__ = ["read_trimesh_parts"]

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


def _short(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    return text[:200]
