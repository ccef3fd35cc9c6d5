"""Surface meshes and scenes: OBJ, OFF and 3MF by our own readers, PLY and glTF through trimesh.

Only geometry is read: materials, textures, normals and colours are skipped
(``skip_materials``) and trimesh's processing is off (``process=False``) so
the polyhedron is exactly the one in the file.  Third-party exceptions are
translated at the call (``safe.guarded_read``); nothing above ``load/`` sees
them.  A scene node whose transform mirrors (negative determinant) has its
triangles' winding reversed, as the glTF 2.0 specification (section 3.7.4,
"Transformations") prescribes, so an outward mesh stays outward.
"""

from __future__ import annotations

import io
import itertools
import json
import math
import random
from collections.abc import Callable, Mapping
from dataclasses import replace
from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..body import MeshBody, Part
from ..errors import (
    EmptyGeometryError,
    InvalidParameterError,
    ServiceError,
    UnreadableFileError,
    UnsupportedFormatError,
    ZeroVolumeError,
)
from .safe import guarded_read

if TYPE_CHECKING:
    from .ply import PlyFaces

__all__ = ["read_trimesh_parts", "read_surface_parts", "mesh_part"]

# glTF extensions that store the geometry itself in another form (glTF extension registry)
_GEOMETRY_EXTENSIONS = {
    "KHR_draco_mesh_compression": "Draco mesh compression",
    "EXT_meshopt_compression": "meshopt compression",
    "KHR_meshopt_compression": "meshopt compression",
}
# glTF extensions that change nothing in the geometry we read: materials (KHR_techniques_webgl: shaders, carried
# over from glTF 1.0), textures, lights, metadata
_HARMLESS_GLTF_EXTENSIONS = (
    "EXT_mesh_gpu_instancing",  # applied before the file is read (``instancing``)
    "KHR_mesh_quantization",  # normalized positions scaled back before the file is read (``quantized``)
    "KHR_techniques_webgl",
    "KHR_technique_webgl",
    "KHR_materials_",
    "KHR_texture_",
    "KHR_lights_",
    "KHR_xmp",
    "KHR_animation_pointer",
    "EXT_texture_",
)


def read_surface_parts(
    data: bytes, fmt: str, length_scale: float, companions: Mapping[str, bytes] | None = None
) -> tuple[list[Part], str | None, list[str]]:
    """Parts of a surface file, the unit it declares, and notes on what was left out (not weighed)."""
    if fmt == "obj":
        from .obj import read_obj

        groups, notes = guarded_read(lambda: read_obj(data), fmt)  # our reader; any slip still becomes a sentence
        if len(groups) > 1:  # each part keeps the vertices its faces use, not the file's whole list
            groups = [(name, *_compact(v, f)) for name, v, f in groups]
        parts = [mesh_part(name or "body", v, f, length_scale, "obj") for name, v, f in groups]
        if len(parts) == 1 and not groups[0][0]:
            parts = [mesh_part("body", groups[0][1], groups[0][2], length_scale, "obj")]
        return parts, None, notes
    if fmt == "off":
        from .off import read_off

        vertices, triangles, notes = guarded_read(lambda: read_off(data), fmt)
        return [mesh_part("body", vertices, triangles, length_scale, "off")], None, notes
    if fmt == "3mf":
        from .threemf import read_3mf

        model = guarded_read(lambda: read_3mf(data), fmt)
        parts = [mesh_part(name, v, f, length_scale, "3mf", model.assumed.get(name, 0.0)) for name, v, f in model.parts]
        return parts, model.unit, model.notes
    parts, unit = read_trimesh_parts(data, fmt, length_scale, companions)
    return parts, unit, []


def _compact(vertices: NDArray[np.float64], faces: NDArray[np.int64]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The vertices the faces use, and the faces renumbered onto them."""
    used, renumbered = np.unique(faces, return_inverse=True)
    return vertices[used], renumbered.reshape(faces.shape).astype(np.int64)


def mesh_part(
    name: str, vertices: NDArray[Any], faces: NDArray[Any], length_scale: float, fmt: str, assumed_error: float = 0.0
) -> Part:
    """A checked part: (n, 3) finite vertices, (m, 3) faces within range, or an ``UnreadableFileError``;
    ``assumed_error``: see ``MeshBody``."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    if v.ndim != 2 or v.shape[1] != 3:
        raise UnreadableFileError(
            f"the {fmt.upper()} file's vertices of {name!r} do not have three coordinates each; check the file or re-export it",
            format=fmt,
            part=name,
        )
    if f.ndim != 2 or f.shape[1] != 3 or not np.issubdtype(f.dtype, np.integer):
        raise UnreadableFileError(
            f"the {fmt.upper()} file's faces of {name!r} are not triangles of vertex numbers; check the file or re-export it",
            format=fmt,
            part=name,
        )
    if len(f) == 0:
        raise EmptyGeometryError(f"part {name!r} of the {fmt.upper()} file has no triangles", format=fmt, part=name)
    if f.min() < 0 or f.max() >= len(v):
        bad = int(f.min()) if f.min() < 0 else int(f.max())  # the number the file gives, not the largest good one
        raise UnreadableFileError(
            f"a triangle of {name!r} in the {fmt.upper()} file refers to a vertex that does "
            f"not exist (number {bad} of {len(v)}); the file is corrupt or truncated",
            format=fmt,
            part=name,
        )
    # non-finite coordinates: MeshBody refuses them as invalid_parameter (API.md)
    return Part(name, MeshBody(v, f.astype(np.int64), length_scale, name, assumed_error=assumed_error))


def read_trimesh_parts(
    data: bytes, fmt: str, length_scale: float, companions: Mapping[str, bytes] | None = None
) -> tuple[list[Part], str | None]:
    """Parts of a PLY/GLB/glTF file (one per scene node) and the unit it declares."""
    import trimesh

    if fmt == "gltf" and data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]  # a byte-order mark before the JSON (glTF 2.0 section 3.2 forbids it; trimesh cannot read past it)
    notes: list[str] = []
    declared = int.from_bytes(data[8:12], "little") if fmt == "glb" else len(data)
    if declared < len(data):  # checked by the guard: at least a header and a chunk's
        notes.append(
            f"the GLB file has {len(data) - declared} byte(s) after the {declared} its header declares; they are not "
            "part of the GLB and were left out, as glTF readers leave them"
        )
        data = data[:declared]
    if fmt in ("gltf", "glb"):
        doc = _gltf_document(data, fmt)  # parsed once: the checks read it, the rewrites below change it
        notes += _check_gltf_document(doc, fmt)
        if isinstance(doc, dict) and not doc.get("meshes"):  # a valid file of materials, images or cameras only
            raise EmptyGeometryError(
                f"the {fmt.upper()} file holds no meshes, so nothing in it has triangles; a solid needs a triangle mesh",
                format=fmt,
            )
    if fmt in ("gltf", "glb"):  # instances of EXT_mesh_gpu_instancing as nodes, which trimesh draws
        from .fans import fans_as_triangles
        from .gltf_indices import checked_indices
        from .instancing import expand_instances, with_document
        from .quantized import normalized_position_scales, scale_normalized_positions

        cameras = _without_cameras(doc)
        unplaced = _without_positionless(doc)
        original, _ = guarded_read(lambda: fans_as_triangles(doc, data, fmt, companions), fmt)
        cut = guarded_read(lambda: checked_indices(doc, original, fmt, companions), fmt)
        data, placed = guarded_read(lambda: expand_instances(original, fmt, doc, companions), fmt)
        # normalized integer positions (KHR_mesh_quantization), which trimesh reads as the raw integers
        divisors = guarded_read(lambda: normalized_position_scales(doc, original, fmt, companions), fmt)
        rescaled = scale_normalized_positions(doc, divisors)
        if cameras or unplaced or cut or rescaled:  # changed beside (or after) what expand_instances wrote: its instances
            data = with_document(original, fmt, doc)
        if unplaced:
            notes.append(
                f"{unplaced} primitive(s) of the glTF file have no positions (glTF draws nothing for them) and were left out"
            )
        notes += cut + placed
    if fmt == "ply":  # what trimesh's reader would misread: a header out of its order, binary faces of mixed
        # sizes, ASCII rows not each on a line of their own (every ASCII file is read here)
        from .ply import header_fault, header_in_order, read_ascii_ply_rows, read_binary_ply, uniform_face_rows

        problem = header_fault(data)
        if problem is not None:
            raise UnreadableFileError(problem, format=fmt)
        data = guarded_read(partial(header_in_order, data), fmt)
        if not guarded_read(partial(uniform_face_rows, data), fmt):
            own = _own_ply(guarded_read(partial(read_binary_ply, data), fmt), length_scale)
            if own is not None:
                return own, None
        found, overfilled = guarded_read(partial(read_ascii_ply_rows, data), fmt)  # an ASCII file, read word by word
        own = _own_ply(found, length_scale)
        if own is not None:
            return own, None
        if overfilled:
            notes.append(
                "the ASCII PLY file's numbers do not fill the rows its header declares when read one after another "
                "(its rows hold more values than declared); it was read one row per line, as trimesh reads it, "
                "and the values past each row's declared ones were ignored"
            )
    # the upload's own files, and nothing else: a name outside them (a texture that did not come along, a path)
    # is not found, never looked for on disk; images are not needed for the geometry (skip_materials)
    kwargs: dict[str, Any] = {"resolver": trimesh.resolvers.ZipResolver(dict(companions or {}))}
    try:
        scene = guarded_read(
            lambda: _same_names_every_read(
                lambda: trimesh.load_scene(
                    io.BytesIO(data), file_type=fmt, process=False, skip_materials=True, merge_primitives=False, **kwargs
                )
            ),
            fmt,
        )
    except UnreadableFileError:
        fault = _gltf_fault(data, fmt, companions) if fmt in ("gltf", "glb") else None
        if fault is not None:
            raise fault from None
        own = None
        if fmt == "ply":  # faces of several lengths, a \r header
            from .ply import read_binary_ply

            own = _own_ply(guarded_read(partial(read_binary_ply, data), fmt), length_scale)
        if own is None:
            raise
        return own, None
    if fmt == "ply":
        _with_triangle_strips(scene)
    parts: list[Part] = []
    skipped = 0
    nodes = guarded_read(lambda: sorted(scene.graph.nodes_geometry, key=str), fmt)  # node order is not stable
    for node in nodes:
        transform, geom_name = guarded_read(partial(_placement, scene.graph, node), fmt)
        geom = scene.geometry.get(geom_name)
        if not isinstance(geom, trimesh.Trimesh) or len(geom.faces) == 0:
            skipped += 1
            continue
        vertices = np.asarray(geom.vertices, dtype=np.float64)
        faces = np.asarray(geom.faces)
        t = np.asarray(transform, dtype=np.float64)
        bad = int(np.count_nonzero(~np.isfinite(vertices)))
        if bad:  # refused as stored (API.md: invalid_parameter), not as a placement would make them (inf x 0 = NaN)
            raise InvalidParameterError(
                f"the {fmt.upper()} file's vertex coordinates of {str(geom_name)!r} contain {bad} non-finite value(s) "
                "(NaN or infinity); fix the file",
                field="vertex coordinates",
                part=str(geom_name),
            )
        if not np.all(np.isfinite(t)):
            raise InvalidParameterError(
                f"the {fmt.upper()} file places {str(geom_name)!r} with a transform holding non-finite numbers "
                "(NaN or infinity); fix the file",
                field="transform",
                part=str(geom_name),
            )
        if not np.array_equal(t, np.eye(4)):
            if vertices.ndim == 2 and vertices.shape[1] == 3:
                vertices = vertices @ t[:3, :3].T + t[:3, 3]
            if np.linalg.det(t[:3, :3]) < 0 and faces.ndim == 2 and faces.shape[1] == 3:
                faces = faces[:, [0, 2, 1]]
        name = str(node) if node != geom_name or len(nodes) > 1 else str(geom_name)
        parts.append(mesh_part(name, vertices, faces, length_scale, fmt))
    if not parts:
        what = " its reader could take (it found only points or lines)" if skipped else ""
        raise EmptyGeometryError(f"the {fmt.upper()} file holds no triangles{what}; a solid needs a triangle mesh", format=fmt)
    if fmt == "ply":
        notes += _ply_split_notes(scene)
    if notes:
        first = parts[0]
        assert isinstance(first.body, MeshBody)
        parts[0] = Part(first.name, replace(first.body, warnings=(*first.body.warnings, *notes)))
    return parts, _declared_unit(scene, fmt)


def _own_ply(found: PlyFaces | None, length_scale: float) -> list[Part] | None:
    """The part of a PLY file trimesh would misread, from our own reading of it (``ply.read_binary_ply``,
    ``ply.read_ascii_ply_rows``); None where that could not read it either (trimesh's reading then stands)."""
    from .polygons import fan_split_note, fan_triangles

    if found is None:
        return None
    vertices, corners, counts = found
    faces, _ = fan_triangles(corners, counts)
    part = mesh_part("mesh", vertices, faces, length_scale, "ply")
    note = fan_split_note(vertices, corners, counts, "ply")
    if note is not None:
        assert isinstance(part.body, MeshBody)
        part = Part(part.name, replace(part.body, warnings=(*part.body.warnings, note)))
    return [part]


def _placement(graph: Any, node: Any) -> tuple[NDArray[np.float64], Any]:
    """A node's world matrix and geometry, the product of the transforms from the root as the file gives them.

    trimesh's own lookup (``graph[node]``) leaves out every transform within 1e-8 of the identity and
    replaces a world matrix within 1e-5 of a rotation by that rotation (``repair_rigid``): a node scaled
    by 1.000004 came back 1.2e-5 light, without a word.  glTF composes its nodes' matrices exactly
    (glTF 2.0 section 3.5.3), and so does this.
    """
    forest = graph.transforms
    path = forest.shortest_path(graph.base_frame, node) if node != graph.base_frame else [node]
    matrix = np.eye(4)
    for parent, child in itertools.pairwise(path):
        edge = forest.edge_data.get((parent, child))
        if edge is None:
            raise UnreadableFileError(f"the scene's node {str(node)!r} is not below its root", node=str(node))
        if "matrix" in edge:
            matrix = matrix @ np.asarray(edge["matrix"], dtype=np.float64)
    return matrix, forest.node_data[node].get("geometry")


def _without_cameras(doc: Any) -> bool:
    """Take the cameras off the document's nodes; whether there were any.

    A camera places no geometry, but trimesh's reader skips a node that holds one, with its mesh, and
    leaves the node's children outside the scene (glTF 2.0 section 3.5.7 lets a node hold a camera,
    a mesh and children together).
    """
    nodes = doc.get("nodes") if isinstance(doc, dict) else None
    if not isinstance(nodes, list):
        return False
    found = False
    for node in nodes:
        if isinstance(node, dict) and "camera" in node:
            del node["camera"]
            found = True
    return found


def _without_positionless(doc: Any) -> int:
    """Take off the meshes' primitives that have no POSITION attribute; how many there were.

    POSITION is optional (glTF 2.0 section 3.7.2.1): such a primitive draws nothing, and glTF's own viewers skip
    it, but trimesh's reader refuses the whole file.
    """
    meshes = doc.get("meshes") if isinstance(doc, dict) else None
    removed = 0
    for mesh in meshes if isinstance(meshes, list) else []:
        primitives = mesh.get("primitives") if isinstance(mesh, dict) else None
        if not isinstance(primitives, list):
            continue
        kept = [p for p in primitives if not (isinstance(p, dict) and "POSITION" not in (p.get("attributes") or {}))]
        removed += len(primitives) - len(kept)
        mesh["primitives"] = kept
    return removed


def _ply_split_notes(scene: Any) -> list[str]:
    """``polygons.fan_split_note`` on the PLY's faces as written (trimesh keeps them as ``_ply_raw``)."""
    from .polygons import fan_split_note

    notes = []
    for geom in scene.geometry.values():
        raw = (getattr(geom, "metadata", None) or {}).get("_ply_raw")
        faces = _ply_face_lists(raw)
        if faces is None:
            continue
        counts = np.fromiter((len(f) for f in faces), dtype=np.int64, count=len(faces))
        if not np.any(counts >= 4) or counts.min() < 3:
            continue
        corners = np.concatenate([np.asarray(f, dtype=np.int64) for f in faces])
        if corners.min() < 0 or corners.max() >= len(geom.vertices):
            continue  # the reader's own checks report a bad index
        note = fan_split_note(np.asarray(geom.vertices, dtype=np.float64), corners, counts, "ply")
        if note:
            notes.append(note)
    return notes


def _with_triangle_strips(scene: Any) -> None:
    """Add the triangles of a PLY file's ``tristrips`` element (trimesh reads no strips) to its mesh, in place.

    Each strip lists vertices; -1 starts a new strip.  Triangle i of a strip is (v_i, v_i+1, v_i+2), every
    other one turned (v_i+1, v_i, v_i+2) so that all wind alike; triangles that repeat a vertex (the joins
    of stitched strips) are left out.  Stanford's and VCG's tools write meshes this way (igea.ply).
    """
    import trimesh

    for name, geom in list(scene.geometry.items()):
        strips = _ply_face_lists((getattr(geom, "metadata", None) or {}).get("_ply_raw"), "tristrips")
        if not strips:
            continue
        lists = [np.asarray(strip, dtype=np.int64).reshape(-1) for strip in strips]
        runs = [run for strip in lists for run in np.split(strip, np.flatnonzero(strip < 0))]
        triangles = [_strip_triangles(run[run >= 0]) for run in runs]
        added = np.concatenate(triangles) if triangles else np.empty((0, 3), np.int64)
        faces = np.asarray(getattr(geom, "faces", np.empty((0, 3))), dtype=np.int64).reshape(-1, 3)
        mesh = trimesh.Trimesh(np.asarray(geom.vertices), np.concatenate([faces, added]), process=False)
        mesh.metadata.update(geom.metadata)
        scene.geometry[name] = mesh


def _strip_triangles(run: NDArray[np.int64]) -> NDArray[np.int64]:
    """The triangles of one triangle strip, all wound as its first (``_with_triangle_strips``)."""
    if len(run) < 3:
        return np.empty((0, 3), np.int64)
    a, b, c = run[:-2], run[1:-1], run[2:]
    odd = np.arange(len(a)) % 2 == 1
    triangles = np.stack([np.where(odd, b, a), np.where(odd, a, b), c], axis=1)
    kept: NDArray[np.int64] = triangles[(a != b) & (b != c) & (a != c)]
    return kept


def _ply_face_lists(raw: Any, element: str = "face") -> list[Any] | None:
    """Each face's vertex list from trimesh's raw PLY elements (a dict of arrays or a structured array), or None."""
    try:
        data = raw[element]["data"]
        for key in ("vertex_indices", "vertex_index"):
            named = isinstance(data, np.ndarray) and bool(data.dtype.names) and key in (data.dtype.names or ())
            if not ((isinstance(data, dict) and key in data) or named):
                continue
            array = np.asarray(data[key])
            if array.dtype.names and "f1" in array.dtype.names:  # binary lists of one length: (count, indices)
                array = np.asarray(array["f1"])
            return list(array) if array.ndim in (1, 2) and not array.dtype.names else None
        return None
    except (KeyError, TypeError, IndexError, ValueError):
        return None


_NAME_SEED = 0x1E27


def _same_names_every_read(read: Callable[[], Any]) -> Any:
    """``read()`` with Python's ``random`` seeded, its state restored after.

    trimesh names the node of each primitive of a glTF mesh with several
    primitives ``<node>_<6 random hex digits>`` (``util.unique_id``, drawn
    from ``random``): the same file gave other part names, and parts sorted
    by name in another order, on every read.  With a fixed seed a file's
    parts have the same names, in the same order, every time.
    """
    state = random.getstate()
    random.seed(_NAME_SEED)
    try:
        return read()
    finally:
        random.setstate(state)


def _gltf_document(data: bytes, fmt: str) -> Any:
    try:
        if fmt == "glb":
            size = int.from_bytes(data[12:16], "little")
            return json.loads(data[20 : 20 + size])
        return json.loads(data)
    except (ValueError, UnicodeDecodeError):
        return None  # the reader reports a malformed document in its own words


# The glTF 2.0 schema's shapes of what the readers here and trimesh's use (section 5, "Properties Reference"):
# top-level arrays of objects, and in each object the fields' kinds.  "index": an integer (not a boolean) >= 0.
_GLTF_ARRAYS = ("accessors", "buffers", "bufferViews", "meshes", "nodes", "scenes", "skins", "materials")
_GLTF_FIELDS: dict[str, dict[str, str]] = {
    "accessors": {
        "bufferView": "index",
        "byteOffset": "index",
        "componentType": "index",
        "count": "index",
        "type": "string",
        "normalized": "boolean",
        "sparse": "object",
    },
    "buffers": {"byteLength": "index", "uri": "string"},
    "bufferViews": {"buffer": "index", "byteOffset": "index", "byteLength": "index", "byteStride": "index"},
    "meshes": {"weights": "numbers"},  # "primitives" not an array: the readers below name it
    "nodes": {
        "children": "indices",
        "mesh": "index",
        "skin": "index",
        "camera": "index",
        "matrix": "numbers",
        "rotation": "numbers",
        "scale": "numbers",
        "translation": "numbers",
        "extensions": "object",
    },
    "scenes": {"nodes": "indices"},
}
_GLTF_PRIMITIVE = {"attributes": "object", "indices": "index", "mode": "index", "targets": "objects"}


def _gltf_index(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool) and v >= 0


def _gltf_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


_GLTF_KINDS: dict[str, Callable[[Any], bool]] = {
    "index": lambda v: _gltf_index(v) or (isinstance(v, float) and v.is_integer() and v >= 0),
    "string": lambda v: isinstance(v, str),
    "boolean": lambda v: isinstance(v, bool),
    "object": lambda v: isinstance(v, dict),
    "objects": lambda v: isinstance(v, list) and all(isinstance(x, dict) for x in v),
    "indices": lambda v: isinstance(v, list) and all(_gltf_index(x) for x in v),
    "numbers": lambda v: isinstance(v, list) and all(_gltf_number(x) for x in v),
}


def _gltf_kind_fault(value: Any, kind: str) -> bool:
    """Whether ``value`` is not of the schema's ``kind``."""
    return not _GLTF_KINDS[kind](value)


def _refuse_misshapen_gltf(doc: dict[str, Any], fmt: str) -> None:
    """Refuse a glTF document whose arrays or fields are not of the schema's kinds, naming the first one: each
    reader would otherwise fail on it with an error of its own (``len()`` of a boolean, a list as a key)."""

    def fault(path: str, kind: str) -> UnreadableFileError:
        return UnreadableFileError(
            f"the {fmt.upper()} file's {path} is not {_GLTF_KIND_WORDS[kind]}, as the glTF 2.0 schema requires; "
            "the file is corrupt or not glTF 2.0",
            format=fmt,
        )

    for name in _GLTF_ARRAYS:
        if name in doc and _gltf_kind_fault(doc[name], "objects"):
            raise fault(name, "objects")
        for i, item in enumerate(doc.get(name) or []):
            for field, kind in _GLTF_FIELDS.get(name, {}).items():
                if field in item and _gltf_kind_fault(item[field], kind):
                    raise fault(f"{name}[{i}].{field}", kind)
            primitives = item.get("primitives") if name == "meshes" else None
            for j, primitive in enumerate(primitives if isinstance(primitives, list) else []):
                for field, kind in _GLTF_PRIMITIVE.items() if isinstance(primitive, dict) else ():
                    if field in primitive and _gltf_kind_fault(primitive[field], kind):
                        raise fault(f"{name}[{i}].primitives[{j}].{field}", kind)


_GLTF_KIND_WORDS = {
    "index": "a whole number >= 0",
    "string": "a string",
    "boolean": "true or false",
    "object": "an object",
    "objects": "an array of objects",
    "indices": "an array of whole numbers >= 0",
    "numbers": "an array of numbers",
}


def _check_gltf_document(doc: Any, fmt: str) -> list[str]:
    """Refuse what trimesh's glTF reader would read as other geometry than the file's; notes on what is left out.

    glTF 2.0 specification: required extensions that change the geometry
    (Draco or meshopt compression; quantized positions are scaled back by
    ``quantized``), sparse accessors (section 3.6.2.3; trimesh does not
    apply them), skinned meshes (posed by their joints, section 3.7.3: the
    node's own transform is ignored), morph targets with non-zero default
    weights (section 3.7.2.2) and node hierarchies that are not trees
    (section 3.5.2) are refused with a sentence; triangle fans (mode 6) are
    rewritten as triangles (``fans``); point and line primitives
    (modes 0-3) hold no volume and are left out with a note.  ``doc``: the parsed JSON (``_gltf_document``),
    which this only reads.
    """
    if not isinstance(doc, dict):
        return []

    def refuse(what: str, **details: Any) -> UnsupportedFormatError:
        return UnsupportedFormatError(f"the {fmt.upper()} file {what}", format=fmt, **details)

    asset = doc.get("asset")
    version = str(asset.get("version", "")) if isinstance(asset, dict) else ""
    if version.startswith("1") or (not version and isinstance(doc.get("meshes"), dict)):  # 1.0 keys meshes by id
        raise refuse(
            "is glTF 1.0, which this service does not read (glTF 2.0 only); convert it to glTF 2.0, "
            "e.g. with gltf-pipeline or by importing and exporting it in Blender",
            version=version or "1.0",
        )
    minimum = str(asset.get("minVersion", "2.0")) if isinstance(asset, dict) else "2.0"
    if (version and version.split(".")[0] != "2") or minimum not in ("2", "2.0"):
        raise refuse(
            f"is glTF {minimum if minimum not in ('2', '2.0') else version}, and this service reads glTF 2.0 "
            "(asset.version and asset.minVersion, section 5.2); export it as glTF 2.0",
            version=version,
        )

    _refuse_misshapen_gltf(doc, fmt)
    required = doc.get("extensionsRequired", [])
    unknown = (
        [str(e) for e in required if isinstance(e, str) and not e.startswith(_HARMLESS_GLTF_EXTENSIONS)]
        if isinstance(required, list)
        else []
    )
    if unknown:
        kinds = sorted({_GEOMETRY_EXTENSIONS[e] for e in unknown if e in _GEOMETRY_EXTENSIONS})
        raise refuse(
            f"requires the extension(s) {', '.join(unknown)}, which this service does not decode"
            + (f" ({', '.join(kinds)})" if kinds else "")
            + "; export it without them",
            extensions=unknown,
        )
    accessors: list[Any] = doc["accessors"] if isinstance(doc.get("accessors"), list) else []
    meshes: list[Any] = doc["meshes"] if isinstance(doc.get("meshes"), list) else []
    nodes: list[Any] = doc["nodes"] if isinstance(doc.get("nodes"), list) else []
    notes: list[str] = []
    lines = 0
    for mi, mesh in enumerate(meshes):
        if not isinstance(mesh, dict):
            continue
        label = mesh.get("name") or f"mesh {mi}"
        # a node's weights override its mesh's (section 3.7.2.2); a mesh no node draws has no shape to weigh
        drawn = [n.get("weights", mesh.get("weights")) for n in nodes if isinstance(n, dict) and n.get("mesh") == mi]
        if any(isinstance(w, list) and any(isinstance(x, (int, float)) and x != 0 for x in w) for w in drawn):
            raise refuse(
                f"gives mesh {label!r} morph-target weights, so its shape is not the stored positions; "
                "export it with the morph applied"
            )
        for prim in mesh.get("primitives", []) if isinstance(mesh.get("primitives"), list) else []:
            if not isinstance(prim, dict):
                continue
            mode = prim.get("mode", 4)
            if mode in (0, 1, 2, 3):
                lines += 1
                continue
            attrs: dict[str, Any] = prim["attributes"] if isinstance(prim.get("attributes"), dict) else {}
            position = attrs.get("POSITION")
            extensions = prim.get("extensions")
            compressed = [e for e in extensions if e in _GEOMETRY_EXTENSIONS] if isinstance(extensions, dict) else []
            if (
                compressed
                and isinstance(position, int)
                and 0 <= position < len(accessors)
                and isinstance(accessors[position], dict)
                and "bufferView" not in accessors[position]
            ):
                # an optional extension whose uncompressed fallback is absent: read without it, the positions are
                # all zero (an accessor without a buffer view, section 3.6.2.3), and the mesh would seem flat
                raise refuse(
                    f"stores mesh {label!r} only with {', '.join(compressed)} "
                    f"({', '.join(sorted({_GEOMETRY_EXTENSIONS[e] for e in compressed}))}), which this service does "
                    "not decode; export it without mesh compression",
                    extensions=compressed,
                )
            if (
                not compressed
                and isinstance(position, int)
                and 0 <= position < len(accessors)
                and isinstance(accessors[position], dict)
                and "bufferView" not in accessors[position]
                and "sparse" not in accessors[position]
            ):
                # an accessor without a buffer view holds zeros (section 3.6.2.3): every corner at the origin
                raise EmptyGeometryError(
                    f"the {fmt.upper()} file's mesh {label!r} has positions without a buffer view, which glTF reads as "
                    "all zero (section 3.6.2.3): every corner is at the origin and the mesh bounds no volume",
                    format=fmt,
                )
            for key in (position, prim.get("indices")):
                if (
                    isinstance(key, int)
                    and 0 <= key < len(accessors)
                    and isinstance(accessors[key], dict)
                    and "sparse" in accessors[key]
                ):
                    raise refuse(
                        f"stores mesh {label!r} with a sparse accessor, which this service does not "
                        "apply; export it without sparse storage"
                    )
    scenes = doc.get("scenes")
    if meshes and not (isinstance(scenes, list) and scenes):
        raise EmptyGeometryError(
            f"the {fmt.upper()} file has no scene, so its meshes are placed nowhere (glTF 2.0 section 3.5: without "
            "scenes the file is a library of objects); export it with a scene that holds the part's nodes",
            format=fmt,
        )
    _check_node_trees(nodes, scenes, fmt)
    notes += _check_node_transforms(nodes, fmt)
    if any(isinstance(n, dict) and "skin" in n and "mesh" in n for n in nodes):
        raise refuse(
            "holds a skinned mesh, whose shape is set by its joints (the node's own transform is "
            "ignored, glTF 2.0 section 3.7.3); export the mesh with the skin applied"
        )
    if lines:
        notes.append(f"{lines} point or line primitive(s) of the glTF file hold no volume and were left out")
    return notes


def _gltf_fault(data: bytes, fmt: str, companions: Mapping[str, bytes] | None) -> ServiceError | None:
    """For a glTF file trimesh could not read: the first fault of its meshes that can be named, else None.

    A buffer view that runs past its buffer's bytes (glTF 2.0 section 3.6.1), a mesh's primitives that are not
    an array of objects with attributes (section 5.23-5.24), or an accessor of a primitive that names no buffer
    view or runs past its buffer (section 3.6.2).
    """
    from .instancing import Buffers, accessor_values

    doc = _gltf_document(data, fmt)
    if not isinstance(doc, dict):
        return None
    meshes = doc.get("meshes", [])
    if not isinstance(meshes, list):
        return UnreadableFileError(f"the {fmt.upper()} file's meshes are not an array; the file is corrupt", format=fmt)
    accessors: list[Any] = doc["accessors"] if isinstance(doc.get("accessors"), list) else []
    buffers = Buffers(doc, data, fmt, companions or {})
    views: list[Any] = doc["bufferViews"] if isinstance(doc.get("bufferViews"), list) else []
    for vi, view in enumerate(views):
        b = view.get("buffer") if isinstance(view, dict) else None
        offset, length = (view.get("byteOffset", 0), view.get("byteLength")) if isinstance(view, dict) else (None, None)
        if not (isinstance(b, int) and isinstance(offset, int) and isinstance(length, int)):
            continue
        try:
            size = len(buffers.get(b))
        except ServiceError as exc:
            return exc
        if offset + length > size:
            return UnreadableFileError(
                f"the {fmt.upper()} file's buffer view {vi} runs past the end of buffer {b} (bytes {offset} to "
                f"{offset + length} of its {size}); the file is corrupt or truncated",
                format=fmt,
            )
    for mi, mesh in enumerate(meshes):
        primitives = mesh.get("primitives") if isinstance(mesh, dict) else None
        if not isinstance(primitives, list) or not all(isinstance(p, dict) for p in primitives):
            return UnreadableFileError(
                f"the {fmt.upper()} file's mesh {mi} has no array of primitives (meshes[{mi}].primitives, glTF 2.0 "
                "section 5.23); the file is corrupt, re-export it",
                format=fmt,
            )
        for prim in primitives:
            attributes = prim.get("attributes")
            if not isinstance(attributes, dict):
                return UnreadableFileError(
                    f"a primitive of the {fmt.upper()} file's mesh {mi} has no attributes object; the file is corrupt",
                    format=fmt,
                )
            for key in [*attributes.values(), prim.get("indices")]:
                acc = accessors[key] if isinstance(key, int) and 0 <= key < len(accessors) else None
                sparse = isinstance(acc, dict) and "sparse" in acc
                if key is None or sparse:
                    continue
                try:
                    accessor_values(doc, key, buffers, fmt, normalize=False)
                except ServiceError as exc:
                    return type(exc)(f"{exc.message} (mesh {mi}); the file is corrupt or truncated", **exc.details)
    return None


_IDENTITY = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]
_QUATERNION_SLACK = 1e-5  # a rotation written in float32 is a unit quaternion to ~1e-7
_AFFINE_SLACK = 1e-6  # rounding in an exporter's matrix product; its last row is dropped, as readers do


def _check_node_transforms(nodes: list[Any], fmt: str) -> list[str]:
    """Refuse node transforms glTF 2.0 does not define (section 5.25): a matrix beside translation, rotation or
    scale (readers apply one, the other or both), a matrix that is not affine; note rotations that are not unit
    quaternions, which are taken as the rotations they point to (as trimesh does; a viewer that does not
    normalise them draws the mesh scaled)."""
    notes: list[str] = []
    placing = _nodes_placing_meshes(nodes)
    for i, node in enumerate(nodes):
        if not isinstance(node, dict):
            continue
        matrix = _node_numbers(node, "matrix", 16, i, fmt)
        trs = [k for k in ("translation", "rotation", "scale") if k in node]
        if matrix is not None:
            if trs and matrix != _IDENTITY:
                raise UnreadableFileError(
                    f"the {fmt.upper()} file's node {i} has both a matrix and {', '.join(trs)}, which glTF 2.0 "
                    "forbids (section 5.25): readers apply one, the other or both, so where it stands is not "
                    "defined; keep one of them",
                    format=fmt,
                )
            last = matrix[3::4]
            if max(abs(a - b) for a, b in zip(last, (0.0, 0.0, 0.0, 1.0))) > _AFFINE_SLACK:
                raise UnreadableFileError(
                    f"the {fmt.upper()} file's node {i} has a matrix whose last row is {last}, "
                    "not [0, 0, 0, 1]: glTF node matrices are translations, rotations and scales (section 5.25), "
                    "and a projective one places no solid; fix the file",
                    format=fmt,
                )
        _node_numbers(node, "translation", 3, i, fmt)
        scale = _node_numbers(node, "scale", 3, i, fmt)
        rotation = _node_numbers(node, "rotation", 4, i, fmt)
        if i not in placing:  # a camera's or a light's own transform moves no solid
            continue
        if scale is not None and 0.0 in scale:
            raise ZeroVolumeError(
                f"the {fmt.upper()} file's node {i} has the scale {scale}, which flattens what it places to no "
                "volume (a viewer draws nothing of it); remove the node or give it a scale that is not 0",
                format=fmt,
            )
        if rotation is not None and abs(math.hypot(*rotation) - 1.0) > _QUATERNION_SLACK:
            notes.append(
                f"the glTF file's node {i} has a rotation quaternion of length {math.hypot(*rotation):.6g}, not 1 as "
                "glTF 2.0 requires (section 5.25); it was taken as the rotation it points to (a viewer that does not "
                "normalise it draws the mesh scaled)"
            )
    return notes


def _node_numbers(node: dict[str, Any], key: str, size: int, index: int, fmt: str) -> list[float] | None:
    """A node's ``key`` as floats where it is a list of ``size`` numbers (else None: the reader says what is
    wrong); a number that is no finite double (NaN, infinity, or an integer beyond 1e308) is refused."""
    value = node.get(key)
    if not (
        isinstance(value, list)
        and len(value) == size
        and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in value)
    ):
        return None
    try:
        numbers = [float(x) for x in value]
    except OverflowError:
        numbers = [math.inf]
    if not all(math.isfinite(x) for x in numbers):
        raise InvalidParameterError(
            f"the {fmt.upper()} file's node {index} has a {key} holding a number that is not finite; fix the file",
            field=key,
            format=fmt,
        )
    return numbers


def _node_parents(nodes: list[Any]) -> dict[int, list[int]]:
    """Each node that is some node's child: the nodes that list it as a child, in order."""
    parents: dict[int, list[int]] = {}
    for i, node in enumerate(nodes):
        children = node.get("children") if isinstance(node, dict) else None
        for child in children if isinstance(children, list) else []:
            if isinstance(child, int) and not isinstance(child, bool):
                parents.setdefault(child, []).append(i)
    return parents


def _nodes_placing_meshes(nodes: list[Any]) -> set[int]:
    """The nodes that hold a mesh or have one below them (the hierarchy is a set of trees by now)."""
    parents = _node_parents(nodes)
    placing: set[int] = set()
    for i, node in enumerate(nodes):
        at: int | None = i if isinstance(node, dict) and "mesh" in node else None
        while at is not None and at not in placing:  # up to the root, or to a node already marked
            placing.add(at)
            at = parents[at][0] if at in parents else None
    return placing


def _check_node_trees(nodes: list[Any], scenes: Any, fmt: str) -> None:
    """Refuse a node hierarchy that is not a set of disjoint strict trees (glTF 2.0 section 3.5.2): a node with
    two parents, or a scene root that is also a child, stands in two places, of which a reader draws one; a
    cycle places nothing."""
    parents = _node_parents(nodes)
    fix = "; to draw a mesh twice, give it two nodes"
    for child, its in sorted(parents.items()):
        if len(its) > 1:
            raise UnreadableFileError(
                f"the {fmt.upper()} file's node {child} is a child of nodes {its[0]} and {its[1]}, but a glTF node has "
                f"at most one parent (glTF 2.0 section 3.5.2), so where it stands is not defined{fix}",
                format=fmt,
            )
    for s, scene in enumerate(scenes if isinstance(scenes, list) else []):
        roots = scene.get("nodes") if isinstance(scene, dict) else None
        for root in roots if isinstance(roots, list) else []:
            if isinstance(root, int) and root in parents:
                raise UnreadableFileError(
                    f"the {fmt.upper()} file's node {root} is a root of scene {s} and a child of node {parents[root][0]}, "
                    f"but a glTF scene's roots have no parent (glTF 2.0 section 3.5.2){fix}",
                    format=fmt,
                )
    rooted: set[int] = set()  # nodes whose line of parents ends at a root: each node is walked once
    for start in parents:
        path = [start]
        on_path = {start}
        node = start
        while node in parents and node not in rooted:  # one parent each by now: up to a root, or round a cycle
            node = parents[node][0]
            if node in on_path:
                raise UnreadableFileError(
                    f"the {fmt.upper()} file's node hierarchy has a cycle through node {node}, so its nodes are placed "
                    "nowhere (glTF 2.0 section 3.5.2: the hierarchy is a set of trees); fix the file",
                    format=fmt,
                )
            path.append(node)
            on_path.add(node)
        rooted.update(path)


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
    "micron": "um",
    "micrometer": "um",
    "micrometre": "um",
    "um": "um",
    "millimeter": "mm",
    "millimetre": "mm",
    "millimeters": "mm",
    "mm": "mm",
    "centimeter": "cm",
    "centimetre": "cm",
    "centimeters": "cm",
    "cm": "cm",
    "meter": "m",
    "metre": "m",
    "meters": "m",
    "m": "m",
    "inch": "in",
    "inches": "in",
    "in": "in",
    "foot": "ft",
    "feet": "ft",
    "ft": "ft",
}
