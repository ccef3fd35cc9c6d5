"""glTF meshes placed many times by EXT_mesh_gpu_instancing, made ordinary nodes before the file is read.

The extension (Khronos, "EXT_mesh_gpu_instancing") gives a node holding a mesh
accessors TRANSLATION (VEC3), ROTATION (VEC4 unit quaternion x y z w, float or
normalized integers) and SCALE (VEC3), one entry per instance; each instance
draws the node's mesh at the node's own transform times the instance's
T * R * S, and the mesh is drawn by its instances only. Being optional, a
reader that ignores it (trimesh's) draws each such mesh once, at the node.

Here each instance becomes a child node of the instanced one, with the
instance's matrix (column-major, as glTF writes matrices), and the node gives
up its mesh and the extension: the document trimesh then reads draws every
instance. Rotations are normalised (the nearest rotation to a quaternion
stored in float32 or in integers), as trimesh treats the rotations of nodes.
"""

from __future__ import annotations

import base64
import json
import struct
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputTooLargeError, UnreadableFileError, UnsupportedFormatError

__all__ = [
    "EXTENSION",
    "MAX_INSTANCED_TRIANGLES",
    "MAX_INSTANCES",
    "NORMALIZED_DIVISORS",
    "Buffers",
    "accessor_values",
    "expand_instances",
    "glb_binary",
    "with_document",
]

EXTENSION = "EXT_mesh_gpu_instancing"
MAX_INSTANCED_TRIANGLES = 20_000_000
"""Triangles the instances may expand to (each instance is a copy of its mesh)."""
MAX_INSTANCES = 10_000
"""Instances in one file (each becomes a part of its own, a few milliseconds each)."""

_COMPONENTS = {5120: "<i1", 5121: "<u1", 5122: "<i2", 5123: "<u2", 5125: "<u4", 5126: "<f4"}
NORMALIZED_DIVISORS = {5120: 127.0, 5121: 255.0, 5122: 32767.0, 5123: 65535.0}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}


def expand_instances(data: bytes, fmt: str, doc: Any, companions: Mapping[str, bytes] | None = None) -> tuple[bytes, list[str]]:
    """The file with every instanced node's instances as child nodes, and a note saying how many; the file
    unchanged where no node uses the extension."""
    nodes = doc.get("nodes") if isinstance(doc, dict) else None
    if not isinstance(nodes, list):
        return data, []
    instanced = [
        k
        for k, n in enumerate(nodes)
        if isinstance(n, dict)
        and isinstance(n.get("mesh"), int)
        and isinstance(n.get("extensions"), dict)
        and EXTENSION in n["extensions"]
    ]
    if not instanced:
        return data, []
    buffers = Buffers(doc, data, fmt, companions or {})
    taken = {n["name"] for n in nodes if isinstance(n, dict) and isinstance(n.get("name"), str)}
    triangles = 0
    count_all = 0
    for k in instanced:
        node = nodes[k]
        label = node.get("name") or f"node {k}"
        matrices = _instance_matrices(doc, node["extensions"][EXTENSION], buffers, str(label), fmt)
        triangles += len(matrices) * _mesh_triangles(doc, node["mesh"])
        if triangles > MAX_INSTANCED_TRIANGLES or count_all + len(matrices) > MAX_INSTANCES:
            raise InputTooLargeError(
                f"the {fmt.upper()} file's {EXTENSION} instances expand to more than {MAX_INSTANCES} parts or "
                f"{MAX_INSTANCED_TRIANGLES} triangles, more than one request analyses; send fewer instances",
                limit_instances=MAX_INSTANCES,
                limit_triangles=MAX_INSTANCED_TRIANGLES,
            )
        first = len(nodes)
        nodes.extend(
            {"name": _instance_name(str(label), i, taken), "mesh": node["mesh"], "matrix": m.T.ravel().tolist()}
            for i, m in enumerate(matrices)
        )
        node["children"] = [*(node.get("children") or []), *range(first, len(nodes))]
        del node["mesh"]
        node["extensions"] = {key: value for key, value in node["extensions"].items() if key != EXTENSION}
        count_all += len(matrices)
    note = (
        f"{count_all} instance(s) of {len(instanced)} mesh node(s) placed by {EXTENSION} were weighed, each as its "
        "node's transform times the instance's"
    )
    return with_document(data, fmt, doc), [note]


def _instance_name(label: str, i: int, taken: set[str]) -> str:
    """'<node> instance <i>' (the part's name in results and messages), made unique among the document's node names."""
    name = f"{label} instance {i}"
    while name in taken:
        name += "'"
    taken.add(name)
    return name


def _instance_matrices(doc: Any, ext: Any, buffers: Buffers, label: str, fmt: str) -> NDArray[np.float64]:
    """(n, 4, 4) T * R * S of each instance."""
    attributes = ext.get("attributes") if isinstance(ext, dict) else None
    if not isinstance(attributes, dict):
        raise UnreadableFileError(f"the {fmt.upper()} file's {EXTENSION} of {label!r} has no attributes", format=fmt)
    columns = {
        name: accessor_values(doc, attributes[name], buffers, fmt) if name in attributes else None
        for name in ("TRANSLATION", "ROTATION", "SCALE")
    }
    counts = {len(v) for v in columns.values() if v is not None}
    if len(counts) != 1:
        raise UnreadableFileError(
            f"the {fmt.upper()} file's {EXTENSION} of {label!r} gives "
            + ("no TRANSLATION, ROTATION or SCALE" if not counts else "its attributes different counts")
            + " (the extension requires one entry per instance in each)",
            format=fmt,
        )
    n = counts.pop()
    t, r, s = columns["TRANSLATION"], columns["ROTATION"], columns["SCALE"]
    for name, value, width in (("TRANSLATION", t, 3), ("ROTATION", r, 4), ("SCALE", s, 3)):
        if value is not None and value.shape[1] != width:
            raise UnreadableFileError(f"the {fmt.upper()} file's {EXTENSION} {name} of {label!r} is not VEC{width}", format=fmt)
    out = np.tile(np.eye(4), (n, 1, 1))
    rotation = np.tile(np.eye(3), (n, 1, 1)) if r is None else _rotations(r, label, fmt)
    scale = np.ones((n, 3)) if s is None else s
    out[:, :3, :3] = rotation * scale[:, None, :]  # R @ diag(S): column j scaled by S_j
    if t is not None:
        out[:, :3, 3] = t
    if not np.all(np.isfinite(out)):
        raise UnreadableFileError(
            f"the {fmt.upper()} file's {EXTENSION} of {label!r} holds a number that is not finite", format=fmt
        )
    return out


def _rotations(q: NDArray[np.float64], label: str, fmt: str) -> NDArray[np.float64]:
    """Rotation matrices of quaternions x y z w, each normalised first."""
    norm = np.linalg.norm(q, axis=1)
    if np.any(~(norm > 0)):
        raise UnreadableFileError(f"the {fmt.upper()} file's {EXTENSION} ROTATION of {label!r} has a zero quaternion", format=fmt)
    x, y, z, w = (q / norm[:, None]).T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=1),
        ],
        axis=1,
    )


def _mesh_triangles(doc: Any, mesh: int) -> int:
    """About how many triangles the mesh has (its primitives' index or position counts over 3)."""
    meshes, accessors = doc.get("meshes") or [], doc.get("accessors") or []
    total = 0
    primitives = meshes[mesh].get("primitives", []) if 0 <= mesh < len(meshes) and isinstance(meshes[mesh], dict) else []
    for prim in primitives if isinstance(primitives, list) else []:
        key = prim.get("indices", (prim.get("attributes") or {}).get("POSITION")) if isinstance(prim, dict) else None
        if isinstance(key, int) and 0 <= key < len(accessors) and isinstance(accessors[key], dict):
            total += int(accessors[key].get("count", 0)) // 3
    return total


class Buffers:
    """The bytes of each buffer: a GLB's own chunk, a data URI, or a file of the upload (plain names only)."""

    def __init__(self, doc: Any, data: bytes, fmt: str, companions: Mapping[str, bytes]) -> None:
        self.doc, self.data, self.fmt, self.companions = doc, data, fmt, companions
        self.cache: dict[int, bytes] = {}

    def get(self, index: int) -> bytes:
        if index not in self.cache:
            self.cache[index] = self._load(index)
        return self.cache[index]

    def _load(self, index: int) -> bytes:
        buffers = self.doc.get("buffers") or []
        if not (0 <= index < len(buffers)) or not isinstance(buffers[index], dict):
            raise UnreadableFileError(
                f"the {self.fmt.upper()} file names buffer {index}, which it does not define", format=self.fmt
            )
        uri = buffers[index].get("uri")
        if uri is None:
            if self.fmt != "glb" or index != 0:
                raise UnreadableFileError(f"the {self.fmt.upper()} file's buffer {index} has no uri", format=self.fmt)
            return glb_binary(self.data)
        if isinstance(uri, str) and uri.startswith("data:"):
            try:
                return base64.b64decode(uri.split(",", 1)[1])
            except (IndexError, ValueError) as exc:
                raise UnreadableFileError(
                    f"the {self.fmt.upper()} file's buffer {index} is not valid base64", format=self.fmt
                ) from exc
        if isinstance(uri, str) and uri in self.companions:
            return self.companions[uri]
        raise UnreadableFileError(
            f"the {self.fmt.upper()} file's buffer {index} ({str(uri)[:80]!r}) did not come with the upload; "
            "send it along (or the model as .glb)",
            format=self.fmt,
        )


def accessor_values(doc: Any, index: Any, buffers: Buffers, fmt: str, normalize: bool = True) -> NDArray[np.float64]:
    """An accessor's values as (count, width) float64, normalized integers scaled (glTF 2.0 section 3.6.2)
    unless ``normalize`` is False (the integers as stored)."""
    accessors = doc.get("accessors") or []
    if not isinstance(index, int) or not (0 <= index < len(accessors)) or not isinstance(accessors[index], dict):
        raise UnreadableFileError(f"the {fmt.upper()} file names accessor {index!r}, which it does not define", format=fmt)
    acc = accessors[index]
    if "sparse" in acc:
        raise UnsupportedFormatError(
            f"the {fmt.upper()} file stores {EXTENSION} data in a sparse accessor, which this service does not apply",
            format=fmt,
        )
    count, width, component = acc.get("count"), _WIDTH.get(acc.get("type", "")), acc.get("componentType")
    if not isinstance(count, int) or count < 0 or width is None or component not in _COMPONENTS:
        raise UnreadableFileError(
            f"the {fmt.upper()} file's accessor {index} has no valid count, type or componentType", format=fmt
        )
    if "bufferView" not in acc:  # an accessor without a buffer view is all zeros (section 3.6.2.3)
        return np.zeros((count, width))
    views = doc.get("bufferViews") or []
    view = views[acc["bufferView"]] if isinstance(acc["bufferView"], int) and 0 <= acc["bufferView"] < len(views) else None
    if not isinstance(view, dict) or not isinstance(view.get("buffer"), int):
        raise UnreadableFileError(f"the {fmt.upper()} file's accessor {index} names no valid buffer view", format=fmt)
    raw = buffers.get(view["buffer"])
    dtype = np.dtype(_COMPONENTS[component])
    item = dtype.itemsize * width
    # the schema's check (``meshes._refuse_misshapen_gltf``) made these whole numbers >= 0 (12.0 may be a float)
    stride = int(view.get("byteStride") or item)
    view_start = int(view.get("byteOffset", 0))
    start = view_start + int(acc.get("byteOffset", 0))
    end = start + (count - 1) * stride + item if count else start
    if start < view_start or stride < item or end > len(raw) or end > view_start + int(view.get("byteLength", len(raw))):
        raise UnreadableFileError(f"the {fmt.upper()} file's accessor {index} runs past its buffer", format=fmt)
    values = np.empty((count, width), dtype=np.float64)
    for k in range(width):  # each component: a strided view of the buffer, copied out
        values[:, k] = np.ndarray((count,), dtype=dtype, buffer=raw, offset=start + k * dtype.itemsize, strides=(stride,))
    if normalize and acc.get("normalized") and component in NORMALIZED_DIVISORS:
        values = np.maximum(values / NORMALIZED_DIVISORS[component], -1.0)
    return values


def glb_binary(data: bytes) -> bytes:
    """The BIN chunk of a GLB container (glTF 2.0 section 4.4), the first chunk after the JSON one."""
    if len(data) < 20:
        raise UnreadableFileError("the GLB file is shorter than its header", format="glb")
    json_length = struct.unpack_from("<I", data, 12)[0]
    at = 20 + json_length
    if at + 8 > len(data):
        raise UnreadableFileError("the GLB file has no binary chunk for its buffer", format="glb")
    length, kind = struct.unpack_from("<II", data, at)
    if kind != 0x004E4942:  # "BIN\0"
        raise UnreadableFileError("the GLB file's second chunk is not its binary buffer", format="glb")
    return data[at + 8 : at + 8 + length]


def with_document(data: bytes, fmt: str, doc: Any, binary: bytes | None = None) -> bytes:
    """The file with ``doc`` as its JSON: a GLB keeps its other chunks as they are, or, with ``binary``, has
    that as its binary chunk (padded to 4 bytes with zeros)."""
    text = json.dumps(doc, separators=(",", ":")).encode()
    if fmt != "glb":
        return text
    text += b" " * (-len(text) % 4)  # chunks are 4-byte aligned, JSON padded with spaces
    if binary is None:
        rest = data[20 + struct.unpack_from("<I", data, 12)[0] :]
    else:
        binary += b"\0" * (-len(binary) % 4)
        rest = struct.pack("<II", len(binary), 0x004E4942) + binary  # "BIN"
    body = struct.pack("<II", len(text), 0x4E4F534A) + text + rest  # "JSON"
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body
