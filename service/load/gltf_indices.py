"""glTF index lists that trimesh would read otherwise than glTF 2.0 defines them (section 3.7.2.1).

- An index equal to its type's largest value (255 for unsigned bytes, 65535
  for unsigned shorts) is the primitive restart value, which glTF forbids:
  WebGL 2 always restarts at it, so viewers drop the triangles that use it,
  while trimesh reads it as a vertex number.  The file is refused.
- A triangle list (mode 4) whose index count is not a multiple of 3 ends in
  a partial triangle that viewers leave out; trimesh refuses the whole
  primitive.  The partial triangle is left out, with a note.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import UnreadableFileError
from .instancing import Buffers, accessor_values

__all__ = ["checked_indices"]

_RESTART = {5121: 255, 5123: 65535}  # unsigned byte, unsigned short: the primitive restart value of each
_TRIANGLES = 4


def checked_indices(doc: Any, data: bytes, fmt: str, companions: Mapping[str, bytes] | None = None) -> list[str]:
    """Refuse restart values among the primitives' indices; cut partial triangles off triangle lists (``doc``
    changed in place), with a note for each such primitive."""
    if not isinstance(doc, dict):
        return []
    meshes = doc.get("meshes")
    accessors = doc.get("accessors")
    if not isinstance(meshes, list) or not isinstance(accessors, list):
        return []
    buffers: Buffers | None = None
    notes: list[str] = []
    for mi, mesh in enumerate(meshes):
        primitives = mesh.get("primitives") if isinstance(mesh, dict) else None
        for prim in primitives if isinstance(primitives, list) else []:
            key = prim.get("indices") if isinstance(prim, dict) else None
            acc = accessors[key] if isinstance(key, int) and 0 <= key < len(accessors) else None
            if not isinstance(acc, dict) or "sparse" in acc:
                continue
            label = mesh.get("name") or f"mesh {mi}"
            restart = _RESTART.get(acc.get("componentType", 0))
            if restart is not None and "bufferView" in acc:
                buffers = buffers or Buffers(doc, data, fmt, companions or {})
                if np.any(accessor_values(doc, key, buffers, fmt, normalize=False) == restart):
                    raise UnreadableFileError(
                        f"the {fmt.upper()} file's mesh {label!r} has the index {restart}, the primitive restart "
                        "value of its index type, which glTF 2.0 forbids (section 3.7.2.1): viewers drop the "
                        "triangles that use it, and a reader that does not takes it as a vertex; re-export the "
                        "mesh with a larger index type",
                        format=fmt,
                    )
            count = acc.get("count")
            if prim.get("mode", _TRIANGLES) == _TRIANGLES and isinstance(count, int) and count % 3:
                acc["count"] = count - count % 3
                notes.append(
                    f"the glTF file's mesh {label!r} lists {count} indices for its triangles, not a multiple of 3: "
                    f"the last {count % 3} were left out, as viewers leave them"
                )
    return notes
