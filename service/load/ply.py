"""PLY files that trimesh's reader misreads: binary face lists of more than one length, ASCII rows off their lines.

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
every row after it (a closed box came back open).  The format's ASCII data is a
sequence of numbers separated by white space, and its readers (rply, VCG/MeshLab's)
read it so; ``read_ascii_ply`` walks the numbers in the same way, for the files
whose rows are not each on a line of their own.
"""

from __future__ import annotations

import re
import struct

import numpy as np
from numpy.typing import NDArray

from ..errors import UnreadableFileError

__all__ = [
    "PlyFaces",
    "header_fault",
    "header_in_order",
    "read_ascii_ply",
    "read_binary_ply",
    "rows_on_their_lines",
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


def rows_on_their_lines(data: bytes) -> bool:
    """Whether an ASCII PLY file has each row of its elements on a line of its own, as trimesh's reader assumes.

    A row wrapped onto the next line, two rows on one line or a blank line among them changes the count of
    lines, unless another such change makes up for it (lines after the last row, which trimesh leaves alone,
    count too: ``read_ascii_ply`` then declines the file); a file cut short has fewer lines, or a last line
    shorter than a row.  True for a binary file, or one this module cannot lay out.
    """
    found = _header(data)
    if found is None or found[0] != "ascii":
        return True
    _, elements, start = found
    rows = sum(count for _, count, _ in elements)
    body = data[start:].strip()
    newline = b"\n" if b"\n" in body else b"\r"  # \r\n counts as one line break, as trimesh's splitlines has it
    lines = body.count(newline) + 1 if body else 0
    last = next((props for _, count, props in reversed(elements) if count), None)
    return lines == rows and (last is None or _fills_one_row(body.rsplit(newline, 1)[-1].split(), last))


def _fills_one_row(words: list[bytes], props: list[Property]) -> bool:
    """Whether ``words`` are one row of an element of ``props``, no more, no fewer (a file cut within its last
    row still has a line for it)."""
    at = 0
    for _, _, counter in props:
        if counter is None:
            at += 1
            continue
        try:
            n = int(words[at])
        except (IndexError, ValueError):
            return False
        at += 1 + n
    return at == len(words)


def read_ascii_ply(data: bytes) -> PlyFaces | None:
    """The vertices (x, y, z rounded to their declared types), every face's corners one after another, and
    the corners per face, of an ASCII PLY file read as numbers separated by white space, whatever its lines.

    None where the numbers do not fill its elements exactly, as words that are no numbers or numbers left over
    (the caller's own reading then stands); ``UnreadableFileError`` where they end before the vertex or face
    rows its header declares: a truncated file, which read row by row gave the rows before the cut as the
    whole mesh.
    """
    found = _header(data)
    if found is None or found[0] != "ascii":
        return None
    _, elements, start = found
    try:
        numbers = np.asarray(data[start:].split(), dtype=np.float64)
    except ValueError:  # a word that is no number
        return None
    vertices: NDArray[np.float64] | None = None
    corners: list[NDArray[np.float64]] = []
    counts: list[int] = []
    at = 0
    for name, count, props in elements:
        if all(counter is None for _, _, counter in props):  # fixed rows: one reshape
            width = len(props)
            if width == 0:
                return None
            if at + width * count > len(numbers):
                _refuse_if_cut(name, count, (len(numbers) - at) // width, _geometry_read(name, vertices, counts))
                return None
            rows = numbers[at : at + width * count].reshape(count, width)
            at += width * count
            if name == "vertex":
                names = [p for p, _, _ in props]
                if not {"x", "y", "z"} <= set(names):
                    return None
                with np.errstate(invalid="ignore", over="ignore"):  # non-finite values are refused later
                    vertices = np.stack(
                        [rows[:, names.index(c)].astype(props[names.index(c)][1]).astype(np.float64) for c in "xyz"], axis=1
                    )
            continue
        keep = "vertex_indices" if any(p == "vertex_indices" for p, _, _ in props) else "vertex_index"
        for row in range(count):
            for prop, _, counter in props:
                if counter is None:
                    at += 1
                    continue
                if at >= len(numbers):
                    _refuse_if_cut(name, count, row, _geometry_read(name, vertices, counts))
                    return None
                n = numbers[at]
                if not (n.is_integer() and n >= 0):
                    return None
                if n > len(numbers) - at - 1:
                    _refuse_if_cut(name, count, row, _geometry_read(name, vertices, counts))
                    return None
                if name == "face" and prop == keep:
                    corners.append(numbers[at + 1 : at + 1 + int(n)])
                    counts.append(int(n))
                at += 1 + int(n)
        if at > len(numbers):  # the last row's scalars ran past the end
            _refuse_if_cut(name, count, count - 1, _geometry_read(name, vertices, counts))
            return None
    if vertices is None or not counts or at != len(numbers):
        return None
    flat = np.concatenate(corners)
    if not np.all(flat == np.round(flat)):  # an index that is no integer
        return None
    return vertices, flat.astype(np.int64), np.asarray(counts, dtype=np.int64)


def _geometry_read(element: str, vertices: NDArray[np.float64] | None, counts: list[int]) -> bool:
    """Whether the vertex and face rows were all read before ``element``'s, which the numbers did not fill."""
    return element not in ("vertex", "face") and vertices is not None and bool(counts)


def _refuse_if_cut(element: str, declared: int, whole: int, geometry_read: bool) -> None:
    """Where the numbers end before the rows an element declares: nothing to say if the vertices and faces were
    all read before it (an element the geometry does not need, left to trimesh's reading as before), else the
    file is refused as truncated."""
    if geometry_read:
        return
    raise UnreadableFileError(
        f"the ASCII PLY file ends after {whole} of the {declared} '{element}' rows its header declares: it is "
        "truncated, or its header's count is wrong; export it again"
    )
