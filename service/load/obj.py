"""Wavefront OBJ: polygon geometry and its groups, read exactly and strictly.

Our own reader rather than trimesh's, because trimesh's drops what it does
not understand without a word (a ``v`` line with two coordinates becomes a
two-dimensional vertex array; a face index past the end raises a bare
``IndexError``).  What is read (Wavefront's "Object Files (.obj)", Appendix
B1 of the Advanced Visualizer manual):

- ``v x y z [w]`` and the common ``v x y z r g b`` colour extension; ``w``
  other than 1 (a rational weight, meaningful only for curves) is refused;
- ``f`` with ``v``, ``v/vt``, ``v//vn`` or ``v/vt/vn`` references, 1-based
  or negative (relative to the vertices read so far); polygons of more than
  three corners are split into a fan from their first corner, as Blender and
  trimesh do;
- ``o`` and ``g`` name the part the following faces belong to (the pair of
  both names, as trimesh's ``split_objects``/``split_groups``); a name used
  twice gathers its faces in one part;
- a trailing backslash continues a line; ``#`` starts a comment.
Everything else (``vt``, ``vn``, ``usemtl``, ``mtllib``, ``s``, ``l``,
``p``, curves) is skipped: it does not change the solid.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..errors import EmptyGeometryError, UnreadableFileError

__all__ = ["read_obj"]


def _fail(line_no: int, text: str, why: str) -> UnreadableFileError:
    shown = text if len(text) <= 60 else text[:57] + "..."
    return UnreadableFileError(f"the OBJ file's line {line_no} ({shown!r}) {why}; fix that line or re-export the file",
                               format="obj", line=line_no)


def _lines(data: bytes) -> list[str]:
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")  # names only; numbers are ASCII in every encoding OBJ files use
    if "\x00" in text:
        raise UnreadableFileError("the OBJ file holds binary data (NUL bytes), not OBJ text; check the file and "
                                  "its extension", format="obj")
    return text.replace("\\\r\n", " ").replace("\\\n", " ").splitlines()


def read_obj(data: bytes) -> list[tuple[str, NDArray[np.float64], NDArray[np.int64]]]:
    """(name, vertices, triangles) of each named group, in order of first use; vertices shared (all of them)."""
    coords: list[list[str]] = []
    faces_by_part: dict[str, list[list[int]]] = {}
    obj_name, group_name = "", ""
    current: list[list[int]] | None = None
    for line_no, raw in enumerate(_lines(data), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        head, _, rest = line.partition(" ")
        if head == "v":
            values = rest.split()
            if len(values) not in (3, 4, 6, 7):
                raise _fail(line_no, line, f"gives {len(values)} numbers; a vertex needs x y z (and optionally w, "
                            "or r g b)")
            if len(values) in (4, 7) and _number(values[3], line_no, line) != 1.0:
                raise _fail(line_no, line, "has a weight w other than 1, which only curves use")
            coords.append(values[:3])
        elif head == "f":
            corners = rest.split()
            if len(corners) < 3:
                raise _fail(line_no, line, f"has {len(corners)} corners; a face needs at least 3")
            idx = [_index(c, len(coords), line_no, line) for c in corners]
            if current is None:
                current = faces_by_part.setdefault(_part_name(obj_name, group_name), [])
            current.extend([idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1))
        elif head == "o":
            obj_name, group_name, current = rest.strip(), "", None
        elif head == "g":
            group_name, current = rest.strip(), None
    if not coords:
        raise EmptyGeometryError("the OBJ file has no vertices (v lines); send a mesh with geometry", format="obj")
    try:
        vertices = np.array(coords, dtype=np.float64)
    except ValueError as exc:
        bad = next(i for i, c in enumerate(coords) if not all(_is_number(x) for x in c))
        raise UnreadableFileError(f"vertex {bad + 1} of the OBJ file has a coordinate that is not a number "
                                  f"({' '.join(coords[bad])!r}); fix it or re-export the file", format="obj") from exc
    parts = [(name, vertices, np.array(tris, dtype=np.int64).reshape(-1, 3)) for name, tris in faces_by_part.items()
             if tris]
    if not parts:
        raise EmptyGeometryError("the OBJ file has vertices but no faces (f lines); a solid needs triangles or "
                                 "polygons", format="obj")
    return parts


def _part_name(obj_name: str, group_name: str) -> str:
    if obj_name and group_name and obj_name != group_name:
        return f"{obj_name}/{group_name}"
    return group_name or obj_name or ""


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _number(text: str, line_no: int, line: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise _fail(line_no, line, f"has {text!r} where a number belongs") from None


def _index(corner: str, count: int, line_no: int, line: str) -> int:
    ref = corner.split("/", 1)[0]
    try:
        k = int(ref)
    except ValueError:
        raise _fail(line_no, line, f"has the corner {corner!r}, whose vertex number is not an integer") from None
    if k > 0 and k <= count:
        return k - 1
    if k < 0 and -k <= count:
        return count + k
    raise _fail(line_no, line, f"refers to vertex {k}, but only {count} vertices come before it")
