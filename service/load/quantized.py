"""glTF positions stored as normalized integers (KHR_mesh_quantization), scaled back before the file is read.

The extension (Khronos, "KHR_mesh_quantization") lets POSITION accessors hold
signed or unsigned 8- or 16-bit integers, normalized or not.  A normalized
component c stands for c / 127, c / 255, c / 32767 or c / 65535, signed
values clamped at -1 (the extension's text, and glTF 2.0 section 3.6.2 on
normalized accessors); a plain integer stands for itself, the node's
transform carrying any scale (as gltfpack writes them).

trimesh reads such accessors as the raw integers, which is right for plain
ones and off by the normalizing divisor for normalized ones.  Here every
node that draws a mesh whose positions are normalized draws it through a
child node scaled by 1 / divisor: the integers stay as stored (exact) and
the division joins the node transforms, which ``meshes._placement``
composes in float64.  A mesh whose primitives use different divisors, or
that stores the one value the clamp changes (-128, -32768), is refused.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..errors import UnsupportedFormatError
from .instancing import NORMALIZED_DIVISORS, Buffers, accessor_values

__all__ = ["EXTENSION", "normalized_position_scales", "scale_normalized_positions"]

EXTENSION = "KHR_mesh_quantization"
_SIGNED = {5120, 5122}


def normalized_position_scales(doc: Any, data: bytes, fmt: str, companions: Mapping[str, bytes] | None) -> dict[int, float]:
    """The divisor of each mesh whose POSITION accessors are normalized integers, by mesh index."""
    meshes = doc.get("meshes") if isinstance(doc, dict) else None
    accessors = doc.get("accessors") if isinstance(doc, dict) else None
    if not isinstance(meshes, list) or not isinstance(accessors, list):
        return {}
    buffers = Buffers(doc, data, fmt, companions or {})
    out: dict[int, float] = {}
    for index, mesh in enumerate(meshes):
        primitives = mesh.get("primitives") if isinstance(mesh, dict) else None
        divisors = set()
        for prim in primitives if isinstance(primitives, list) else []:
            attrs = prim.get("attributes") if isinstance(prim, dict) else None
            key = attrs.get("POSITION") if isinstance(attrs, dict) else None
            if not isinstance(key, int) or not 0 <= key < len(accessors) or not isinstance(accessors[key], dict):
                continue
            acc = accessors[key]
            component = acc.get("componentType")
            divisors.add(NORMALIZED_DIVISORS[component] if acc.get("normalized") and component in NORMALIZED_DIVISORS else None)
            if acc.get("normalized") and component in _SIGNED and "bufferView" in acc:
                raw = accessor_values(doc, key, buffers, fmt, normalize=False)
                if raw.size and float(raw.min()) < -NORMALIZED_DIVISORS[component]:
                    raise UnsupportedFormatError(
                        f"the {fmt.upper()} file's mesh {index} stores a quantized position of {int(raw.min())}, which "
                        "glTF clamps to -1 (so its corner is not where the integers put it); export it with float positions",
                        format=fmt,
                        extension=EXTENSION,
                    )
        scaled = {d for d in divisors if d is not None}
        if scaled and len(divisors) > 1:
            raise UnsupportedFormatError(
                f"the {fmt.upper()} file's mesh {index} mixes primitives whose positions are quantized differently "
                f"({EXTENSION}); export it with one quantization for the whole mesh, or with float positions",
                format=fmt,
                extension=EXTENSION,
            )
        if scaled:
            out[index] = scaled.pop()
    return out


def scale_normalized_positions(doc: Any, divisors: Mapping[int, float]) -> int:
    """Draw each mesh of ``divisors`` through a child node scaled by 1 / divisor, in place; the nodes changed."""
    nodes = doc.get("nodes") if isinstance(doc, dict) else None
    if not isinstance(nodes, list) or not divisors:
        return 0
    changed = 0
    for node in list(nodes):
        mesh = node.get("mesh") if isinstance(node, dict) else None
        if not isinstance(mesh, int) or mesh not in divisors:
            continue
        s = 1.0 / divisors[mesh]
        child: dict[str, Any] = {"mesh": mesh, "matrix": [s, 0, 0, 0, 0, s, 0, 0, 0, 0, s, 0, 0, 0, 0, 1]}
        if "weights" in node:
            child["weights"] = node["weights"]
        if "name" in node:  # the part keeps the node's name
            child["name"] = node.pop("name")
        nodes.append(child)
        node["children"] = [*(node.get("children") or []), len(nodes) - 1]
        del node["mesh"]
        changed += 1
    return changed
