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
  trimesh do (with a warning when they are not planar, so that the split
  changes the volume: ``polygons.fan_split_note``);
- ``o`` and ``g`` name the part the following faces belong to (the pair of
  both names, as trimesh's ``split_objects``/``split_groups``); a name used
  twice gathers its faces in one part;
- a trailing backslash continues a line; ``#`` starts a comment.
Everything else (``vt``, ``vn``, ``usemtl``, ``mtllib``, ``s``, ``l``,
``p``, curves) is skipped: it does not change the solid.
"""

from __future__ import annotations

import re

import numpy as np
from numpy.typing import NDArray

from ..errors import EmptyGeometryError, InvalidParameterError, UnreadableFileError, UnsupportedFormatError
from .polygons import fan_split_note, fan_triangles
from .safe import is_number

__all__ = ["read_obj"]


# 1.#IND, 1.#INF, 1.#QNAN, 1.#SNAN (with a sign): how Microsoft's C runtime prints non-finite numbers
_MSVC_NON_FINITE = re.compile(r"[-+]?\d\.#(?:IND|INF|QNAN|SNAN)\w*", re.IGNORECASE)


def _fail(line_no: int, text: str, why: str) -> UnreadableFileError:
    shown = text if len(text) <= 60 else text[:57] + "..."
    return UnreadableFileError(
        f"the OBJ file's line {line_no} ({shown!r}) {why}; fix that line or re-export the file", format="obj", line=line_no
    )


# byte-order marks of the Unicode encodings an OBJ file is written in besides UTF-8 (Windows editors' "Unicode")
_WIDE_BOMS = (
    (b"\xff\xfe\x00\x00", "utf-32-le"),
    (b"\x00\x00\xfe\xff", "utf-32-be"),
    (b"\xff\xfe", "utf-16-le"),
    (b"\xfe\xff", "utf-16-be"),
)


def _lines(data: bytes) -> list[str]:
    text = None
    for bom, encoding in _WIDE_BOMS:
        if data.startswith(bom):  # UTF-16 or UTF-32 text: every ASCII character has NUL bytes beside it
            try:
                text = data[len(bom) :].decode(encoding)
            except UnicodeDecodeError as exc:
                raise UnreadableFileError(
                    f"the OBJ file starts with a {encoding.upper()} byte-order mark but is not {encoding.upper()} text "
                    f"({exc.reason})",
                    format="obj",
                ) from exc
            break
    if text is None:
        if data.startswith(b"\xef\xbb\xbf"):  # a UTF-8 byte-order mark (Notepad's "UTF-8 with BOM") is no text:
            data = data[3:]  # left on the first line, it hid a first "v" line and shifted every face's indices
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            text = data.decode("latin-1")  # names only; numbers are ASCII in every encoding OBJ files use
    if "\x00" in text:
        raise UnreadableFileError(
            "the OBJ file holds binary data (NUL bytes), not OBJ text; check the file and its extension", format="obj"
        )
    return text.replace("\\\r\n", " ").replace("\\\n", " ").splitlines()


def read_obj(data: bytes) -> tuple[list[tuple[str, NDArray[np.float64], NDArray[np.int64]]], list[str]]:
    """(name, vertices, triangles) of each named group, in order of first use; vertices shared (all of them);
    and warnings on what was assumed (the split of non-planar polygons).

    One pass sorts the lines by kind (and records, for each face line, its
    group and how many vertices precede it); numbers are then converted by
    numpy in bulk.  A line that breaks a rule is found again and named.
    """
    lines = _lines(data)
    v_rows: list[list[str]] = []
    v_line: list[int] = []
    f_rows: list[list[str]] = []
    f_line: list[int] = []
    f_part: list[int] = []
    f_seen: list[int] = []
    names: dict[str, int] = {}
    obj_name, group_name = "", ""
    part = -1
    for line_no, raw in enumerate(lines, start=1):
        if raw[:2] in ("vt", "vn", "vp"):  # texture coordinates, normals: not geometry (skipped unsplit: fast)
            continue
        if "#" in raw:
            raw = raw.split("#", 1)[0]
        tokens = raw.split()
        if not tokens:
            continue
        head = tokens[0]
        if head == "v":
            v_rows.append(tokens)
            v_line.append(line_no)
        elif head == "f":
            if part < 0:
                part = names.setdefault(_part_name(obj_name, group_name), len(names))
            f_rows.append(tokens)
            f_line.append(line_no)
            f_part.append(part)
            f_seen.append(len(v_rows))
        elif head == "o":
            obj_name, group_name, part = " ".join(tokens[1:]), "", -1
        elif head == "g":
            group_name, part = " ".join(tokens[1:]), -1
    if not v_rows:
        _refuse_mni(lines)
        raise EmptyGeometryError("the OBJ file has no vertices (v lines); send a mesh with geometry", format="obj")
    vertices = _vertices(v_rows, v_line, lines)
    if not f_rows:
        raise EmptyGeometryError(
            "the OBJ file has vertices but no faces (f lines); a solid needs triangles or polygons", format="obj"
        )
    triangles, owner, idx, corners = _faces(f_rows, f_line, f_part, f_seen, lines)
    order = sorted(names, key=names.__getitem__)
    parts = []
    for index, name in enumerate(order):
        tris = triangles[owner == index]
        if len(tris):
            parts.append((name, vertices, tris))
    note = fan_split_note(vertices, idx, corners, "obj")
    return parts, [note] if note else []


def _refuse_mni(lines: list[str]) -> None:
    """An MNI/BIC object file (brain-imaging surfaces, also named .obj) is not Wavefront OBJ: say which it is.

    Its first line is ``P`` with the surface's five shading numbers and its point count (or ``L`` for
    lines); Wavefront OBJ has no such statement.
    """
    first = next((line.split() for line in lines if line.strip()), [])
    if first[:1] in (["P"], ["L"]) and len(first) >= 3 and all(is_number(t) for t in first[1:]):
        raise UnsupportedFormatError(
            "the .obj file is an MNI object file (brain-imaging surfaces; its first line is "
            f"{' '.join(first[:7])!r}), not a Wavefront OBJ; convert it to STL, PLY or Wavefront OBJ first "
            "(VTK's vtkMNIObjectReader reads it)",
            format="obj",
        )


def _vertices(rows: list[list[str]], line_nos: list[int], lines: list[str]) -> NDArray[np.float64]:
    counts = np.fromiter((len(r) - 1 for r in rows), dtype=np.int64, count=len(rows))
    bad = np.flatnonzero(~np.isin(counts, (3, 4, 6, 7)))
    if len(bad):
        i = int(bad[0])
        line = lines[line_nos[i] - 1].strip()
        msvc = _MSVC_NON_FINITE.search(line)
        if msvc:  # "1.#IND": the '#' began a comment, so the line seemed short of numbers
            raise InvalidParameterError(
                f"the OBJ file's line {line_nos[i]} ({line[:60]!r}) holds {msvc.group(0)!r}, how Microsoft's C library "
                "writes a non-finite number (NaN or infinity), where a coordinate belongs; fix the file",
                format="obj",
                line=line_nos[i],
                field="vertex coordinates",
            )
        numbers = f"{counts[i]} number" + ("" if counts[i] == 1 else "s")
        raise _fail(line_nos[i], line, f"gives {numbers}; a vertex needs x y z (and optionally w, or r g b)")
    try:
        xyz = np.array([r[1:4] for r in rows], dtype=np.float64)
        weighted = np.flatnonzero(np.isin(counts, (4, 7)))
        w = np.array([rows[i][4] for i in weighted], dtype=np.float64)
    except ValueError:
        for i, r in enumerate(rows):
            for text in r[1:5] if counts[i] in (4, 7) else r[1:4]:
                _number(text, line_nos[i], lines[line_nos[i] - 1].strip())
        raise  # unreachable: some number failed above
    if np.any(w != 1.0):
        i = int(weighted[np.flatnonzero(w != 1.0)[0]])
        raise _fail(line_nos[i], lines[line_nos[i] - 1].strip(), "has a weight w other than 1, which only curves use")
    return xyz


def _faces(
    rows: list[list[str]], line_nos: list[int], part: list[int], seen: list[int], lines: list[str]
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """Triangles (0-based, polygons split into fans from their first corner), the part of each,
    and the faces as written: every corner's vertex number, and the number of corners of each face."""
    corners = np.fromiter((len(r) - 1 for r in rows), dtype=np.int64, count=len(rows))
    short = np.flatnonzero(corners < 3)
    if len(short):
        i = int(short[0])
        raise _fail(line_nos[i], lines[line_nos[i] - 1].strip(), f"has {corners[i]} corners; a face needs at least 3")
    flat = [c.split("/", 1)[0] if "/" in c else c for r in rows for c in r[1:]]
    try:
        refs = np.array(flat, dtype=np.int64)
    except (ValueError, OverflowError):
        for i, r in enumerate(rows):
            for c in r[1:]:
                _index(c, seen[i], line_nos[i], lines[line_nos[i] - 1].strip())
        raise
    face_of = np.repeat(np.arange(len(rows)), corners)
    before = np.asarray(seen, dtype=np.int64)[face_of]
    idx = np.where(refs > 0, refs - 1, before + refs)
    bad = np.flatnonzero((refs == 0) | (idx < 0) | (idx >= before))
    if len(bad):
        i = int(face_of[bad[0]])
        raise _fail(line_nos[i], lines[line_nos[i] - 1].strip(), _bad_reference(int(refs[bad[0]]), seen[i]))
    triangles, tri_face = fan_triangles(idx, corners)
    return triangles, np.asarray(part, dtype=np.int64)[tri_face], idx, corners


def _part_name(obj_name: str, group_name: str) -> str:
    if obj_name and group_name and obj_name != group_name:
        return f"{obj_name}/{group_name}"
    return group_name or obj_name or ""


def _number(text: str, line_no: int, line: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise _fail(line_no, line, f"has {text!r}, which is not a number, where a coordinate belongs") from None


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
    raise _fail(line_no, line, _bad_reference(k, count))


def _bad_reference(k: int, count: int) -> str:
    if k == 0:
        return "refers to vertex 0, but OBJ numbers vertices from 1 (and back from -1 for the latest)"
    return f"refers to vertex {k}, but only {count} vertices come before it"
