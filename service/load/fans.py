"""glTF triangle fans (mode 6) as indexed triangle lists, which trimesh's reader draws (it skips fans).

glTF 2.0 section 3.7.2.1: a fan of vertices v0, v1, ..., vn is the triangles
{v(i+1), v(i+2), v0}; each is written here as (v0, v(i+1), v(i+2)), the same
triangle wound the same way.  The vertices are the primitive's indices in
order, or, without indices, its attributes' elements in order.  The new
indices (unsigned 32-bit) go after a GLB's binary chunk, or into a new
data-URI buffer of a .gltf file; the primitive then becomes mode 4 with them.
"""

from __future__ import annotations

import base64
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import UnreadableFileError
from .instancing import Buffers, accessor_values, glb_binary, with_document

__all__ = ["fans_as_triangles"]

_UNSIGNED_INT = 5125
_POINTS = 0


def fans_as_triangles(doc: Any, data: bytes, fmt: str, companions: Mapping[str, bytes] | None = None) -> tuple[bytes, int]:
    """The file with every triangle-fan primitive of ``doc`` rewritten as triangles (``doc`` changed in place),
    and how many were rewritten; the file unchanged where it has none."""
    if not isinstance(doc, dict):
        return data, 0  # a malformed document: the reader reports it in its own words
    meshes = doc.get("meshes")
    fans = [
        prim
        for mesh in (meshes if isinstance(meshes, list) else [])
        if isinstance(mesh, dict) and isinstance(mesh.get("primitives"), list)
        for prim in mesh["primitives"]
        if isinstance(prim, dict) and prim.get("mode") == 6
    ]
    if not fans:
        return data, 0
    buffers = Buffers(doc, data, fmt, companions or {})
    glb_chunk = fmt == "glb" and _has_binary_chunk(doc)
    added = bytearray(glb_binary(data)) if glb_chunk else bytearray()
    target = 0 if glb_chunk else len(doc.get("buffers") or [])  # the binary chunk, or a new buffer after the others
    for prim in fans:
        order = _fan_vertices(doc, prim, buffers, fmt)
        if len(order) < 3:  # no triangle: nothing to draw, as a point primitive is
            prim["mode"] = _POINTS
            continue
        triangles = np.empty((len(order) - 2, 3), dtype="<u4")
        triangles[:, 0] = order[0]
        triangles[:, 1] = order[1:-1]
        triangles[:, 2] = order[2:]
        added += b"\0" * (-len(added) % 4)
        doc.setdefault("bufferViews", []).append({"buffer": target, "byteOffset": len(added), "byteLength": triangles.nbytes})
        added += triangles.tobytes()
        doc.setdefault("accessors", []).append(
            {"bufferView": len(doc["bufferViews"]) - 1, "componentType": _UNSIGNED_INT, "count": triangles.size, "type": "SCALAR"}
        )
        prim["indices"] = len(doc["accessors"]) - 1
        prim["mode"] = 4
    if glb_chunk:
        doc["buffers"][0]["byteLength"] = len(added)
        return with_document(data, fmt, doc, binary=bytes(added)), len(fans)
    if not added:  # every fan had fewer than three vertices
        return with_document(data, fmt, doc), len(fans)
    doc.setdefault("buffers", []).append(
        {"byteLength": len(added), "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(added)).decode()}
    )
    return with_document(data, fmt, doc), len(fans)


def _has_binary_chunk(doc: Any) -> bool:
    """A GLB whose buffer 0 is its binary chunk (no uri), glTF 2.0 section 4.4.3.3."""
    buffers = doc.get("buffers")
    return isinstance(buffers, list) and bool(buffers) and isinstance(buffers[0], dict) and "uri" not in buffers[0]


def _fan_vertices(doc: Any, prim: dict[str, Any], buffers: Buffers, fmt: str) -> np.ndarray[Any, np.dtype[np.int64]]:
    """The fan's vertices in order: its indices, else every element of its attributes."""
    if "indices" in prim:
        order = accessor_values(doc, prim["indices"], buffers, fmt, normalize=False).reshape(-1).astype(np.int64)
        if len(order) and (order.min() < 0 or order.max() >= 2**32):
            raise UnreadableFileError(f"the {fmt.upper()} file's triangle fan has indices out of range", format=fmt)
        return order
    attributes = prim.get("attributes")
    position = attributes.get("POSITION") if isinstance(attributes, dict) else None
    accessors = doc.get("accessors") if isinstance(doc.get("accessors"), list) else []
    accessor = accessors[position] if isinstance(position, int) and 0 <= position < len(accessors) else None
    count = accessor.get("count") if isinstance(accessor, dict) else None
    if not isinstance(count, int) or count < 0:
        raise UnreadableFileError(f"the {fmt.upper()} file's triangle fan has no valid POSITION accessor", format=fmt)
    return np.arange(count, dtype=np.int64)
