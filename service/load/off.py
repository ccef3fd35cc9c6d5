"""Geomview OFF: polygon geometry, read as Geomview's own reader reads it.

The format (Geomview manual, "OFF Files"; the same text in holmes3d.net's
offdesc.txt and JavaView's format pages):

    [ST][C][N][4][n]OFF      header keyword, optional
    [Ndim]                   present only with the n prefix
    NVertices NFaces NEdges  NEdges is neither used nor checked
    x y z [w] [nx ny nz] [r g b a] [s t]      NVertices times
    N v1 ... vN [colour]     NFaces times

The vertices are "dimension * NVertices floating-point values": whitespace,
line breaks included, only separates numbers, so a vertex may run over two
lines. With the ``4`` prefix each vertex has a fourth, homogeneous
coordinate w, and the point is (x/w, y/w, z/w). A face is its count, then
that many vertex numbers (0-based), then an optional colour that runs to the
end of the line: line breaks are significant there and only there.

Most writers put one vertex per line, and some put more numbers on it than
the keyword announces (a colour on an ``OFF`` vertex line); where every
vertex line holds at least the coordinates, each line is one vertex and its
extra numbers are skipped, as trimesh and MeshLab read them. Otherwise the
numbers are taken in order with the count the keyword gives, as Geomview
does. Polygons of more than three corners are split into a fan from their
first corner (``polygons.fan_split_note`` warns when that changes the
volume). Binary OFF and dimensions other than three are refused by name.
"""

from __future__ import annotations

import re

import numpy as np
from numpy.typing import NDArray

from ..errors import EmptyGeometryError, UnreadableFileError, UnsupportedFormatError
from .polygons import fan_split_note, fan_triangles

__all__ = ["read_off"]

_KEYWORD = re.compile(r"(ST)?(C)?(N)?(4)?(n)?OFF")


def _fail(why: str, line_no: int | None = None) -> UnreadableFileError:
    where = f" (line {line_no})" if line_no is not None else ""
    return UnreadableFileError(f"the OFF file {why}{where}; check the file or re-export it", format="off", line=line_no)


def _also(more: int) -> str:
    return f", and {more} more {'vertex' if more == 1 else 'vertices'} like it" if more > 0 else ""


def _shown(token: str) -> str:
    """A word of the file as a message quotes it: a binary file's "word" can be megabytes long."""
    return repr(token if len(token) <= 40 else token[:37] + "...")


def _lines(data: bytes) -> list[tuple[int, list[str]]]:
    """(1-based line number, tokens) of every line with something on it, comments (#) removed."""
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    text = data.decode("utf-8", errors="replace")
    out = []
    # lines end at \n, \r\n or \r only: str.splitlines also splits at form feeds and other separators
    for number, line in enumerate(text.replace("\r\n", "\n").replace("\r", "\n").split("\n"), start=1):
        if "#" in line:
            line = line.split("#", 1)[0]
        tokens = line.split()
        if tokens:
            out.append((number, tokens))
    return out


def _without_appearance(lines: list[tuple[int, list[str]]]) -> list[tuple[int, list[str]]]:
    """The lines after a leading ``appearance { ... }`` block (Geomview's shading and texture settings, which
    its files may put before the OFF object); unchanged where there is none or its braces never close."""
    if not lines or not lines[0][1][0].startswith("appearance"):
        return lines
    depth = 0
    for k, (line_no, tokens) in enumerate(lines):
        for j, token in enumerate(tokens):
            depth += token.count("{") - token.count("}")
            if depth == 0 and "}" in token:
                rest = tokens[j + 1 :]
                return ([(line_no, rest)] if rest else []) + lines[k + 1 :]
    return lines


def read_off(data: bytes) -> tuple[NDArray[np.float64], NDArray[np.int64], list[str]]:
    """Vertices, triangles (polygons split into fans) and warnings on what was assumed."""
    lines = _without_appearance(_lines(data))
    if not lines:
        raise EmptyGeometryError("the OFF file is empty; send a mesh with vertices and faces", format="off")
    if any(ord(c) < 32 for c in lines[0][1][0]):
        raise UnreadableFileError("the OFF file holds binary data, not OFF text; check the file and its extension", format="off")
    # the header's words with the index of their line: the keyword, Ndim, the counts span at most four lines
    words = [(k, word) for k, (_, tokens) in enumerate(lines[:4]) for word in tokens]
    keyword = _KEYWORD.match(words[0][1])
    if keyword is not None and keyword.end() < len(words[0][1]):  # "OFF8 6 12": the counts written onto the keyword
        words[:1] = [(0, keyword.group()), (0, words[0][1][keyword.end() :])]
    homogeneous = False
    per_vertex = 3  # numbers of one vertex as the keyword announces them
    i = 0
    if keyword is not None:  # the keyword is optional: without it the counts come first
        st, colour, normal, four, n_dim = (g is not None for g in keyword.groups())
        i = 1
        if words[i:] and words[i][1] == "BINARY":
            raise UnsupportedFormatError("binary OFF is not supported; export the mesh as ASCII OFF, PLY or STL", format="off")
        if n_dim:
            dimension = _count(words, i, lines, "dimension (Ndim)")
            if dimension != 3:
                raise UnsupportedFormatError(
                    f"the OFF file's vertices have {dimension} dimensions; a solid needs three", format="off"
                )
            i += 1
        homogeneous = four
        per_vertex = 3 + four + 3 * normal + 4 * colour + 2 * st
    n_vertices = _count(words, i, lines, "vertex count (NVertices)")
    n_faces = _count(words, i + 1, lines, "face count (NFaces)")
    if n_vertices == 0 or n_faces == 0:
        raise EmptyGeometryError(
            f"the OFF file declares {n_vertices} vertices and {n_faces} faces; a solid needs both", format="off"
        )
    at = words[i + 1][0] + 1  # the vertices start on the line after the counts (NEdges, if there, ends it)
    if _edges_alone(words, i, lines, at):
        at += 1  # "NVertices NFaces", then NEdges on a line of its own: the header's third number, as Geomview reads it
    coordinates = 3 + homogeneous
    vertices, corners, counts = _geometry(lines, at, n_vertices, n_faces, coordinates, per_vertex)
    if homogeneous:
        w = vertices[:, 3]
        bad = (w == 0) | ~np.isfinite(w)
        if np.any(bad):
            k = int(np.flatnonzero(bad)[0])
            raise UnreadableFileError(
                f"the OFF file's vertex {k} (counting from 0) has the homogeneous coordinate w = {float(w[k])!r}, so it is "
                f"no point in space (w = 0 is a point at infinity){_also(int(np.count_nonzero(bad)) - 1)}; check the "
                "file or re-export it",
                format="off",
                vertex=k,
            )
        vertices = vertices[:, :3] / w[:, None]
    triangles, _ = fan_triangles(corners, counts)
    if len(triangles) == 0:
        raise EmptyGeometryError("the OFF file's faces have fewer than three corners each; a solid needs polygons", format="off")
    note = fan_split_note(vertices, corners, counts, "off")
    return vertices, triangles, [note] if note else []


def _edges_alone(words: list[tuple[int, str]], i: int, lines: list[tuple[int, list[str]]], at: int) -> bool:
    """The line after a counts line without NEdges holds one whole number and nothing else: NEdges.

    Geomview reads the header as numbers in order, so the count of edges may sit on its own line; no
    vertex line holds a single whole number (three coordinates at least, unless a vertex runs over
    lines, which no writer we know of does in its first line).
    """
    if (i + 2 < len(words) and words[i + 2][0] == words[i + 1][0]) or at >= len(lines):
        return False  # NEdges is on the counts' line
    tokens = lines[at][1]
    return len(tokens) == 1 and tokens[0].isdigit()


def _count(words: list[tuple[int, str]], i: int, lines: list[tuple[int, list[str]]], what: str) -> int:
    """The header's i-th word as a count."""
    if i >= len(words):
        raise _fail(f"ends before its {what}")
    k, token = words[i]
    return _natural(token, lines[k][0], f"its {what}")


def _natural(token: str, line_no: int, what: str) -> int:
    """A count of the file, ``what`` it is named in a message."""
    try:
        value = int(token)
    except ValueError:
        raise _fail(f"has {_shown(token)} where {what} belongs", line_no) from None
    if value < 0:
        raise _fail(f"gives {what} as {value}, a negative number", line_no)
    return value


def _geometry(
    lines: list[tuple[int, list[str]]], at: int, n_vertices: int, n_faces: int, coordinates: int, per_vertex: int
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:
    """Vertex coordinates, and every face's vertex numbers and corner count: one vertex per line where
    that reads the whole file, else the numbers in order (a vertex over two lines, or two on one, moves
    every line after it)."""
    by_line = _by_line(lines, at, n_vertices, coordinates)
    if by_line is not None:
        try:
            return by_line, *_faces(lines, at + n_vertices, n_faces, n_vertices)
        except UnreadableFileError as exc:
            line_error = exc
    try:
        vertices, after = _by_number(lines, at, n_vertices, coordinates, per_vertex)
        return vertices, *_faces(lines, after, n_faces, n_vertices)
    except UnreadableFileError:
        if by_line is None:
            raise
        raise line_error from None  # the reading by line, which every ordinary file follows, names the fault


def _by_line(lines: list[tuple[int, list[str]]], at: int, n: int, coordinates: int) -> NDArray[np.float64] | None:
    """One vertex per line, numbers past the coordinates skipped (every writer we know of); None where a
    line is too short for that."""
    rows = lines[at : at + n]
    if len(rows) < n or any(len(tokens) < coordinates for _, tokens in rows):
        return None
    try:
        return np.array([tokens[:coordinates] for _, tokens in rows], dtype=np.float64)
    except ValueError:
        for line_no, tokens in rows:
            _numbers(tokens[:coordinates], line_no)
        raise  # unreachable: a number failed above


def _by_number(
    lines: list[tuple[int, list[str]]], at: int, n: int, coordinates: int, per_vertex: int
) -> tuple[NDArray[np.float64], int]:
    """The numbers in order, ``per_vertex`` for each vertex, whatever the line breaks (Geomview's reading);
    the coordinates, and the index of the line after the last vertex."""
    values: list[str] = []
    line_no = lines[at][0] if at < len(lines) else lines[-1][0]
    while len(values) < n * per_vertex:
        if at >= len(lines):
            raise _fail(f"ends after {len(values) // per_vertex} of its {n} vertices", line_no)
        line_no, tokens = lines[at]
        values += tokens
        at += 1
    if len(values) != n * per_vertex:  # the last vertex ends inside a line
        raise _fail(f"has {len(values) - n * per_vertex} numbers after its {n} vertices on the line where they end", line_no)
    block = np.array(_numbers(values, line_no), dtype=np.float64).reshape(n, per_vertex)
    return block[:, :coordinates], at


def _numbers(tokens: list[str], line_no: int | None) -> list[float]:
    out = []
    for token in tokens:
        try:
            out.append(float(token))
        except ValueError:
            raise _fail(f"has {_shown(token)}, which is not a number, where a coordinate belongs", line_no) from None
    return out


def _faces(lines: list[tuple[int, list[str]]], at: int, n: int, n_vertices: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Every face's vertex numbers, one face after another, and the number of corners of each face.

    A face's vertex numbers may continue on the next lines; its colour is what follows them on the
    line where they end.
    """
    corners: list[str] = []
    counts: list[int] = []
    for _ in range(n):
        if at >= len(lines):
            raise _fail(f"ends after {len(counts)} of its {n} faces", lines[-1][0])
        line_no, tokens = lines[at]
        at += 1
        size = _natural(tokens[0], line_no, "a face's number of corners")
        taken = tokens[1 : 1 + size]
        while len(taken) < size:  # the vertex numbers go on on the next line
            if at >= len(lines):
                raise _fail(f"ends inside face {len(counts)}", line_no)
            line_no, tokens = lines[at]
            at += 1
            taken += tokens[: size - len(taken)]
        corners += taken
        counts.append(size)
    try:
        idx = np.array(corners, dtype=np.int64)
    except (ValueError, OverflowError):
        bad = next((c for c in corners if not c.lstrip("-").isdigit() or abs(int(c)) >= 2**63), corners[0])
        raise _fail(f"has {_shown(bad)}, which is not a vertex number, in a face") from None
    if len(idx) and (idx.min() < 0 or idx.max() >= n_vertices):
        k = int(idx.min()) if idx.min() < 0 else int(idx.max())
        raise _fail(f"has a face that refers to vertex {k}, but the vertices are numbered 0 to {n_vertices - 1}")
    return idx, np.asarray(counts, dtype=np.int64)
