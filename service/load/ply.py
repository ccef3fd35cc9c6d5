"""PLY files read here, not by trimesh: binary face lists of more than one length, and every ASCII file.

trimesh reads a binary element's list property as if every row had the length of
the first (``trimesh.exchange.ply``), so a file mixing triangles and quads (Rhino's
export, draco's testdata/Box.ply) was "unexpected length".  The PLY format
(Turk, "The PLY Polygon File Format") gives each list its own count, so this
reader walks the rows: scalar properties by their declared types, each list by
its count.  Only the vertices' x, y, z and the faces' ``vertex_indices`` (or
``vertex_index``) are kept; other elements are stepped over.  Header lines may
end in ``\\r\\n``, ``\\n`` or a bare ``\\r``.

trimesh also reads an ASCII file line by line, one row per line: a row wrapped
onto a second line, two rows on one line or a blank line between rows shifted
every row after it (a closed box came back open), and a file cut short gave the
rows before the cut as the whole mesh.  The format's ASCII data is a sequence of
numbers separated by white space, and its readers (rply, VCG/MeshLab's) read it
so; ``read_ascii_ply`` reads the numbers in the same way (in one reshape where
every row's lists have the first row's lengths, else row by row), and refuses a
file whose numbers end before its vertex or face rows do.  A file it cannot read
(no faces, triangle strips, words that are no numbers) goes to trimesh as before.
"""

from __future__ import annotations

import re
import struct
import warnings

import numpy as np
from numpy.typing import NDArray

from ..errors import UnreadableFileError

__all__ = [
    "PlyFaces",
    "header_fault",
    "header_in_order",
    "read_ascii_ply",
    "read_ascii_ply_rows",
    "read_binary_ply",
    "uniform_face_rows",
]

_TYPES = {
    "char": "b",
    "int8": "b",
    "uchar": "B",
    "uint8": "B",
    "short": "h",
    "int16": "h",
    "ushort": "H",
    "uint16": "H",
    "int": "i",
    "int32": "i",
    "uint": "I",
    "uint32": "I",
    "float": "f",
    "float32": "f",
    "double": "d",
    "float64": "d",
}

Property = tuple[str, str, str | None]  # name, value type, count type (lists only)
# what the readers give: the vertices, every face's corners one after another, the corners per face
PlyFaces = tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]


# the line that ends a PLY header: ``end_header`` alone on it (a comment may mention the word)
_END = re.compile(rb"(?:\r\n|\n|\r)end_header[ \t]*(\r\n|\n|\r)")


def header_in_order(data: bytes) -> bytes:
    """The file with its header as trimesh's reader takes it, where it is written otherwise.

    trimesh reads the byte order from the header's second line and ends the header at the first line that
    mentions ``end_header``.  A header whose ``format`` line comes after a comment or obj_info line was read
    as little-endian binary, so a big-endian file's numbers were byte-swapped (a closed box came back with
    another mass and no word of it), and a comment naming ``end_header`` cut the header short.  The PLY
    format puts ``format`` after ``ply`` and ends the header at an ``end_header`` line (plyfile and this
    module's reader read both files so); the header is rewritten so, its data untouched.
    """
    end = _END.search(data)
    if not data.startswith(b"ply") or end is None:
        return data
    lines = data[: end.start()].replace(b"\r\n", b"\n").replace(b"\r", b"\n").split(b"\n")
    keep = [line for line in lines[1:] if not (line.split()[:1] in ([b"comment"], [b"obj_info"]) and b"end_header" in line)]
    formats = [line for line in keep if line.split()[:1] == [b"format"]]
    if len(formats) != 1 or (keep[:1] == formats and len(keep) == len(lines) - 1):
        return data  # in order already (or no single format line: the reader says what is wrong)
    header = [lines[0], formats[0], *(line for line in keep if line is not formats[0])]
    return b"\n".join([*header, b"end_header\n"]) + data[end.end() :]


# type names a reader may meet: the format's (Turk), their sized aliases, and the 64-bit and half types trimesh
# also reads
_KNOWN_TYPES = frozenset(_TYPES) | {"int64", "uint64", "float16"}


def header_fault(data: bytes) -> str | None:
    """What makes a PLY file's header unreadable, in a sentence a person can act on; None where nothing does
    (the readers take it from there).  Without this the reader's own ``KeyError`` named a type ('bool') or a run
    of header bytes as "an entry the format requires is missing"."""
    if not data.startswith(b"ply"):
        return None
    found = _END.search(data)
    if found is None:
        if b"end_header" in data:
            return None  # the word at the very end, or mid-line: the readers say what they make of it
        return "the PLY file's header has no 'end_header' line: the file is cut short, corrupt or not PLY; export it again"
    for line in data[: found.start()].decode("ascii", "replace").splitlines():
        words = line.split()
        if words[:1] != ["property"]:
            continue
        types = words[2:4] if words[1:2] == ["list"] else words[1:2]
        unknown = next((t for t in types if t not in _KNOWN_TYPES), None)
        if unknown is not None or len(words) < len(types) + 2 + (words[1:2] == ["list"]):
            shown = line.strip()[:80]
            why = (
                f"the type {unknown[:20]!r}, which is no PLY type"
                if unknown is not None
                else "no type and name as the format writes them"
            )
            return (
                f"the PLY file's header line {shown!r} gives {why} (PLY types: char, uchar, short, ushort, int, uint, "
                "float, double, or int8 to float64); the file is corrupt, or its writer used a type PLY readers do "
                "not know: export it again"
            )
    return None


def uniform_face_rows(data: bytes) -> bool:
    """Whether every face of a binary PLY file has lists as long as the first face's, as trimesh's reader assumes.

    trimesh reads a binary list property as if every row had the first row's length, and refuses the file
    only when the element's bytes then come out wrong: faces of 4, 3, 5, 4, 4, 5, 3 corners fill exactly seven
    quads, and were read as such (a box refused as open, or as pointing at vertex 83886080).  False where the
    faces' lists vary, or where the faces cannot be laid out without walking them (a list element before
    them); True for an ASCII file or one without faces.
    """
    found = _header(data)
    if found is None or found[0] == "ascii":
        return True
    order, elements, offset = found
    for name, count, props in elements:
        if name != "face":
            if any(counter is not None for _, _, counter in props):
                return False
            offset += count * sum(struct.calcsize(order + kind) for _, kind, _ in props)
            continue
        if count == 0:
            return True
        # the first face laid out: where each list's count sits in a row, and the row's length
        columns: list[tuple[int, str, int]] = []  # (offset in the row, count type, the first row's count)
        at = 0
        for _, kind, counter in props:
            if counter is None:
                at += struct.calcsize(order + kind)
                continue
            if offset + at + struct.calcsize(order + counter) > len(data):
                return False
            (first,) = struct.unpack_from(order + counter, data, offset + at)
            if first < 0:
                return False
            columns.append((at, counter, first))
            at += struct.calcsize(order + counter) + first * struct.calcsize(order + kind)
        if at <= 0 or offset + at * count > len(data):
            return False
        return all(
            bool(
                np.all(
                    np.ndarray((count,), dtype=np.dtype(order + counter), buffer=data, offset=offset + col, strides=(at,)) == first
                )
            )
            for col, counter, first in columns
        )
    return True


def _header(data: bytes) -> tuple[str, list[tuple[str, int, list[Property]]], int] | None:
    """Byte order ("<", ">", or "ascii"), elements (name, count, properties) and the offset of the data; None for
    no PLY this module reads."""
    found = _END.search(data)
    if not data.startswith(b"ply") or found is None:
        return None
    end, start = found.start(), found.end()
    lines = data[:end].decode("ascii", "replace").replace("\r\n", "\n").replace("\r", "\n").split("\n")
    order = None
    elements: list[tuple[str, int, list[Property]]] = []
    for line in lines:
        words = line.split()
        if words[:1] == ["format"] and len(words) >= 2:
            order = {"binary_little_endian": "<", "binary_big_endian": ">", "ascii": "ascii"}.get(words[1])
        elif words[:1] == ["element"] and len(words) == 3 and words[2].isdigit():
            elements.append((words[1], int(words[2]), []))
        elif words[:1] == ["property"] and elements:
            if words[1] == "list" and len(words) == 5 and words[2] in _TYPES and words[3] in _TYPES:
                elements[-1][2].append((words[4], _TYPES[words[3]], _TYPES[words[2]]))
            elif len(words) == 3 and words[1] in _TYPES:
                elements[-1][2].append((words[2], _TYPES[words[1]], None))
            else:
                return None
    return None if order is None else (order, elements, start)


def read_binary_ply(data: bytes) -> PlyFaces | None:
    """The vertices (x, y, z in their declared types), every face's corners one after another, and the
    corners per face, of a binary PLY file; None where it is no binary PLY with vertices and faces this
    reader can walk (the caller's own error then stands)."""
    found = _header(data)
    if found is None or found[0] == "ascii":
        return None
    try:
        return _walk(data, *found)
    except (ValueError, struct.error):  # a header numpy or struct cannot lay out (no properties, a bad count)
        return None


def _walk(data: bytes, order: str, elements: list[tuple[str, int, list[Property]]], offset: int) -> PlyFaces | None:
    vertices: NDArray[np.float64] | None = None
    corners: list[int] = []
    counts: list[int] = []
    for name, count, props in elements:
        if all(kind is None for _, _, kind in props):  # fixed rows: one read
            dtype = np.dtype([(f"_{k}", order + t) for k, (_, t, _) in enumerate(props)])  # names may repeat
            if offset + dtype.itemsize * count > len(data):
                return None
            rows = np.frombuffer(data, dtype, count, offset)
            offset += dtype.itemsize * count
            if name == "vertex":
                names = [p for p, _, _ in props]
                if not {"x", "y", "z"} <= set(names):
                    return None
                with np.errstate(invalid="ignore"):  # a signalling NaN widened: non-finite values are refused later
                    vertices = np.stack([rows[f"_{names.index(c)}"].astype(np.float64) for c in "xyz"], axis=1)
            continue
        steps = [(p, struct.Struct(order + t), None if c is None else struct.Struct(order + c)) for p, t, c in props]
        keep = "vertex_indices" if any(p == "vertex_indices" for p, _, _ in props) else "vertex_index"
        for _ in range(count):
            for prop, value, counter in steps:
                if counter is None:
                    offset += value.size
                    continue
                if offset + counter.size > len(data):
                    return None
                (n,) = counter.unpack_from(data, offset)
                offset += counter.size
                if n < 0 or offset + n * value.size > len(data):
                    return None
                if name == "face" and prop == keep:
                    corners.extend(struct.unpack_from(f"{order}{n}{value.format[-1]}", data, offset))
                    counts.append(n)
                offset += n * value.size
    if vertices is None or not counts or offset > len(data):
        return None
    return vertices, np.asarray(corners, dtype=np.int64), np.asarray(counts, dtype=np.int64)


def read_ascii_ply(data: bytes) -> PlyFaces | None:
    """See ``read_ascii_ply_rows``."""
    return read_ascii_ply_rows(data)[0]


def read_ascii_ply_rows(data: bytes) -> tuple[PlyFaces | None, bool]:
    """The vertices (x, y, z rounded to their declared types), every face's corners one after another, and
    the corners per face, of an ASCII PLY file read as numbers separated by white space, whatever its lines.

    None where the numbers do not fill its elements exactly (words that are no numbers, numbers left over, a
    list count that is no count: rows with more values than the header declares, which trimesh reads line by
    line), or where it has no vertices and faces (the caller's own reading then stands); beside it, whether
    the numbers were read but did not fill the rows exactly (numbers left over, or a count that is no count);
    ``UnreadableFileError`` where they end before the vertex or face rows its header declares (a truncated
    file, which read row by row gave the rows before the cut as the whole mesh) or where they fill every row
    but a face corner is no whole number.
    """
    found = _header(data)
    if found is None or found[0] != "ascii":
        return None, False
    _, elements, start = found
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # numpy stops at a word that is no number and warns (or raises)
            numbers = np.fromstring(data[start:].decode("latin-1"), dtype=np.float64, sep=" ")
    except (ValueError, DeprecationWarning):
        return None, False
    vertices: NDArray[np.float64] | None = None
    corners: list[NDArray[np.float64]] = []
    counts: list[NDArray[np.int64]] = []
    at = 0
    for name, count, props in elements:
        if count == 0:
            continue
        names = [p for p, _, _ in props]
        if not props or (name == "vertex" and not {"x", "y", "z"} <= set(names)):
            return None, False
        keep = "vertex_indices" if "vertex_indices" in names else "vertex_index"
        want = [names.index(c) for c in "xyz"] if name == "vertex" else []
        listed = names.index(keep) if name == "face" and keep in names else None
        geometry_read = name not in ("vertex", "face") and vertices is not None and bool(counts)
        rows = _uniform_rows(numbers, at, count, props, want, listed)
        if rows is None:
            rows = _walked_rows(numbers, at, count, props, want, listed, name, geometry_read)
        if rows is None:
            return None, True
        at, picked, element_corners, element_counts = rows
        if name == "vertex":
            for k, j in enumerate(want):
                column = picked[:, k]
                if np.issubdtype(np.dtype(props[j][1]), np.integer) and np.any(column != np.round(column)):
                    # read as the declared integers they would silently lose their fractions (rply refuses such a word)
                    raise UnreadableFileError(
                        f"the ASCII PLY file declares vertex property {props[j][0]!r} as an integer but has the value "
                        f"{float(column[np.argmax(column != np.round(column))])!r}; declare it float in the header",
                        format="ply",
                    )
            with np.errstate(invalid="ignore", over="ignore"):  # non-finite values are refused later
                vertices = np.stack([picked[:, k].astype(props[j][1]).astype(np.float64) for k, j in enumerate(want)], axis=1)
        if listed is not None:
            corners.append(element_corners)
            counts.append(element_counts)
    if vertices is None or not counts:
        return None, False
    if at != len(numbers):
        return None, True
    flat = np.concatenate(corners)
    fractional = flat != np.round(flat)
    if np.any(fractional):
        raise UnreadableFileError(
            f"the ASCII PLY file has a face corner {float(flat[np.argmax(fractional)])!r}, which is no vertex number; "
            "fix that face or export the file again",
            format="ply",
        )
    return (vertices, flat.astype(np.int64), np.concatenate(counts)), False


# what one element's rows give: the position after them, the wanted scalars (rows, len(want)), and the corners
# and corner counts of the listed property
Rows = tuple[int, NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]


def _uniform_rows(
    numbers: NDArray[np.float64], at: int, count: int, props: list[Property], want: list[int], listed: int | None
) -> Rows | None:
    """The rows in one reshape where each list has the same length in every row as in the first (the usual
    file: scalars only, or faces of one size); None where they do not, or the first row cannot be laid out."""
    offsets, heads, width = [], [], 0
    for _, _, counter in props:
        offsets.append(width)
        if counter is None:
            width += 1
            continue
        if at + width >= len(numbers):
            return None
        n = numbers[at + width]
        if not (n.is_integer() and n >= 0):
            return None
        heads.append((width, n))
        width += 1 + int(n)
    if at + width * count > len(numbers):
        return None
    table = numbers[at : at + width * count].reshape(count, width)
    if any(not np.all(table[:, col] == n) for col, n in heads):
        return None
    picked = table[:, [offsets[j] for j in want]]
    if listed is None:
        return at + width * count, picked, np.empty(0), np.empty(0, dtype=np.int64)
    n = int(table[0, offsets[listed]])
    corners = table[:, offsets[listed] + 1 : offsets[listed] + 1 + n].ravel()
    return at + width * count, picked, corners, np.full(count, n, dtype=np.int64)


def _walked_rows(
    numbers: NDArray[np.float64],
    at: int,
    count: int,
    props: list[Property],
    want: list[int],
    listed: int | None,
    element: str,
    geometry_read: bool,
) -> Rows | None:
    """The rows one by one, each list by its own count; None where a count is no count, or where the numbers
    end in an element the geometry does not need after the vertices and faces; else a cut is refused."""
    picked = np.empty((count, len(want)))
    corners: list[NDArray[np.float64]] = []
    sizes = np.empty(count if listed is not None else 0, dtype=np.int64)
    total = len(numbers)
    for row in range(count):
        for j, (_, _, counter) in enumerate(props):
            if at >= total:
                _refuse_if_cut(element, count, row, geometry_read)
                return None
            if counter is None:
                if j in want:
                    picked[row, want.index(j)] = numbers[at]
                at += 1
                continue
            n = numbers[at]
            if not (n.is_integer() and n >= 0):
                return None
            if at + 1 + n > total:
                _refuse_if_cut(element, count, row, geometry_read)
                return None
            if j == listed:
                corners.append(numbers[at + 1 : at + 1 + int(n)])
                sizes[row] = int(n)
            at += 1 + int(n)
    return at, picked, (np.concatenate(corners) if corners else np.empty(0)), sizes


def _refuse_if_cut(element: str, declared: int, whole: int, geometry_read: bool) -> None:
    """Where the numbers end before the rows an element declares: nothing to say if the vertices and faces were
    all read before it (an element the geometry does not need, left to trimesh's reading as before), else the
    file is refused as truncated."""
    if geometry_read:
        return
    raise UnreadableFileError(
        f"the ASCII PLY file ends after {whole} of the {declared} '{element}' rows its header declares: it is "
        "truncated, or its header's count is wrong; export it again",
        format="ply",
    )
