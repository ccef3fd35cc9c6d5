"""STL reader: binary straight into a numpy array, ASCII by token scan.

Binary STL (80-byte header, uint32 count, 50-byte records of normal, three
float32 vertices and a uint16 attribute) is viewed with a structured dtype,
no per-triangle Python.  Normals are ignored: the winding defines the
orientation.  Binary vertices are welded here, on the float32 bit patterns
(exact: -0.0 equals 0.0, distinct points never merge; ``topology.row_ids``),
which is six times less data than welding the widened float64 copies and
keeps peak memory near the file size; the distinct vertices are numbered in
order of first appearance and widened exactly to float64.  ASCII vertices
are parsed as float64 and welded with ``topology.weld``.  Either way the
vertices come back welded, so ``solid.closed_surface`` need not weld again.
"""

from __future__ import annotations

import os
from typing import BinaryIO

import numpy as np
from numpy.typing import NDArray

from ..blocks import for_each_block
from ..errors import EmptyGeometryError, UnreadableFileError
from ..topology import row_ids, weld
from .safe import is_number

__all__ = ["StlMesh", "read_stl", "read_stl_file"]

_READ_BLOCK = 1 << 16  # records per read: 3.2 MB of file at a time
_GATHER_BLOCK = 1 << 16  # distinct vertices per block of the gather after the weld
_SAMPLE = 50 * 64  # bytes of records looked at to tell a binary file from text
_RECORD = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attr", "<u2")])


StlMesh = tuple[NDArray[np.float64], NDArray[np.int64], tuple[str, ...]]  # vertices, faces, warnings


def read_stl(data: bytes | memoryview) -> StlMesh:
    """Distinct vertices (k, 3), numbered by first appearance, faces (n, 3) and warnings of a binary or ASCII STL file."""
    buf = memoryview(data)
    layout = _binary_layout(bytes(buf[:84]), len(buf), bytes(buf[84 : 84 + _SAMPLE]))
    if layout is not None:
        count, tail = layout
        return (*_binary(buf, count), _tail_notes(count, tail))
    head = bytes(buf[:512]).removeprefix(b"\xef\xbb\xbf").lstrip()  # an editor's UTF-8 byte-order mark
    declared = int(np.frombuffer(buf[80:84], dtype="<u4")[0]) if len(buf) >= 84 else None
    if head[:5].lower() == b"solid":  # the keywords are lower case, but older CAD tools write them in capitals
        try:
            return (*_ascii(bytes(buf).removeprefix(b"\xef\xbb\xbf")), ())
        except (EmptyGeometryError, UnreadableFileError):  # no facets, or "facets without vertices"
            if declared is None or b"\0" not in bytes(buf[84 : 84 + _SAMPLE]):
                raise
            # binary records behind a header that begins with "solid" (SolidWorks and others write such headers)
            raise UnreadableFileError(_not_binary(len(buf), declared, solid=True)) from None
    raise UnreadableFileError(_not_binary(len(buf), declared))


def _binary_layout(header: bytes, size: int, sample: bytes) -> tuple[int, int] | None:
    """(triangles, bytes after the last one) where the file is binary STL; None where it is not.

    The header's count must fill the file exactly, or leave fewer bytes than a record after the last
    triangle (a byte a transfer appended; numpy-stl reads such files, its own test data has one).  With bytes
    left over the records must also hold a NUL byte, as binary records do and text never does: a text file
    whose bytes 80-83 happen to read as a fitting count stays text.
    """
    if len(header) < 84:
        return None
    count = int(np.frombuffer(header[80:84], dtype="<u4")[0])
    tail = size - 84 - 50 * count
    if tail == 0 or (0 < tail < 50 and count > 0 and b"\0" in sample):
        return count, tail
    return None


def _tail_notes(count: int, tail: int) -> tuple[str, ...]:
    if not tail:
        return ()
    return (
        f"the binary STL file holds {tail} byte(s) after its last triangle (its header declares {count} triangles, "
        f"{84 + 50 * count} bytes), too few for another one; they were ignored",
    )


def _not_binary(size: int, count: int | None, solid: bool = False) -> str:
    """Why a file that is not ASCII STL is not binary STL either, with the sizes that disagree."""
    if count is None:
        return f"the STL file is neither ASCII (starting with 'solid') nor binary ({size} bytes, fewer than a binary header's 84)"
    expected = 84 + 50 * count
    why = "its header begins with 'solid' but it holds binary data, no ASCII facets" if solid else "it does not start with 'solid'"
    if size < expected:
        return (
            f"the STL file is not ASCII ({why}), and as binary it declares {count} triangles "
            f"({expected} bytes) but holds {size}: it is truncated"
        )
    return (
        f"the STL file is not ASCII ({why}), and as binary it declares {count} triangles "
        f"({expected} bytes) but holds {size}, {size - expected} more: cut what follows its last triangle, or export it again"
    )


def read_stl_file(fh: BinaryIO, size: int) -> StlMesh:
    """Like ``read_stl`` for an open file of ``size`` bytes.

    A binary file is read in blocks of records straight into the corner
    array, so the file's bytes are never all in memory next to it; each
    block is read at its own offset (``os.pread``), on the block threads.
    """
    header = fh.read(84)
    layout = _binary_layout(header, size, fh.read(_SAMPLE))
    if layout is not None:
        count, tail = layout
        if count == 0:
            raise EmptyGeometryError("the STL file holds no triangles")
        corners = np.empty((count, 3, 3), dtype=np.float32)
        fd = fh.fileno()

        def read_block(start: int) -> None:
            n = min(_READ_BLOCK, count - start)
            raw = b""
            while len(raw) < 50 * n:  # pread may return less; at the end of the file it returns nothing
                try:
                    more = os.pread(fd, 50 * n - len(raw), 84 + 50 * start + len(raw))
                except OSError as exc:
                    raise UnreadableFileError(f"the STL file could not be read: {exc.strerror}") from exc
                if not more:
                    raise UnreadableFileError("the STL file ended before its last triangle; it may be truncated")
                raw += more
            corners[start : start + n] = np.frombuffer(raw, dtype=_RECORD)["vertices"]

        for_each_block(read_block, range(0, count, _READ_BLOCK))
        return (*_welded(corners), _tail_notes(count, tail))
    fh.seek(0)
    return read_stl(fh.read())


def _binary(buf: memoryview, count: int) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    if count == 0:
        raise EmptyGeometryError("the STL file holds no triangles")
    records = np.frombuffer(buf, dtype=_RECORD, count=count, offset=84)
    return _welded(records["vertices"].copy())


def _welded(corners: NDArray[np.float32]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Distinct vertices (first-appearance order, widened exactly) and face indices."""
    corners += np.float32(0.0)  # -0.0 + 0.0 is +0.0, so both weld together
    bits = corners.reshape(-1, 3).view(np.uint32)
    ids, heads = row_ids(bits)
    del bits
    rows = corners.reshape(-1, 3)
    vertices = np.empty((len(heads), 3))

    def gather(start: int) -> None:  # widened exactly, float32 to float64
        vertices[start : start + _GATHER_BLOCK] = rows[heads[start : start + _GATHER_BLOCK]]

    for_each_block(gather, range(0, len(heads), _GATHER_BLOCK))
    return vertices, ids.reshape(-1, 3)


def _facet_without_three_vertices(data: bytes) -> tuple[int, int] | None:
    """(its line, its vertex count) of the first facet ... endfacet block without three vertex lines, if any."""
    start, count = 0, -1  # count -1: outside a facet
    for number, line in enumerate(data.splitlines(), 1):
        word = line.split(maxsplit=1)[:1]
        key = word[0].lower() if word else b""
        if key == b"facet":
            if count not in (-1, 3):
                return start, count
            start, count = number, 0
        elif key == b"vertex" and count >= 0:
            count += 1
        elif key == b"endfacet":
            if count != 3:
                return start, max(count, 0)
            count = -1
    return (start, count) if count not in (-1, 3) else None


def _line_of_vertex_token(data: bytes, token: bytes) -> int | None:
    """The line of the first vertex line that holds ``token`` among its coordinates."""
    for number, line in enumerate(data.splitlines(), 1):
        words = line.split()
        if words[:1] and words[0].lower() == b"vertex" and token in words[1:4]:
            return number
    return None


def _ascii(data: bytes) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    tokens = np.array(data.split())
    idx = np.flatnonzero(tokens == b"vertex")
    if len(idx) == 0:  # SOLID / FACET NORMAL / VERTEX: admesh's own example block.stl, read by admesh and trimesh
        idx = np.flatnonzero(np.char.lower(tokens) == b"vertex")
    if len(idx) == 0:
        if b"facet" in data.lower():
            raise UnreadableFileError("the ASCII STL file has facets without vertices; it is corrupt")
        raise EmptyGeometryError("the STL file holds no triangles")
    if len(idx) % 3 or idx[-1] + 3 >= len(tokens):
        found = _facet_without_three_vertices(data)
        where = (
            f"'s facet at line {found[0]} has {found[1]} vertices, but a facet has three"
            if found
            else " has a facet without exactly three vertices"
        )
        raise UnreadableFileError(f"the ASCII STL file{where}; fix that facet or re-export the file")
    fields = tokens[idx[:, None] + np.arange(1, 4)]
    try:
        coords = fields.astype(np.float64)
    except ValueError as exc:
        bad = next((t for t in fields.ravel().tolist() if not is_number(t)), None)
        shown = "a token that is no number" if bad is None else repr(bad.decode("utf-8", "replace")[:40])
        line = _line_of_vertex_token(data, bad) if bad is not None else None
        at = f" (line {line})" if line else ""
        raise UnreadableFileError(
            f"the ASCII STL file has a malformed vertex line{at}: {shown} where a coordinate should be; fix that line "
            "or re-export the file"
        ) from exc
    return weld(coords, np.arange(len(idx), dtype=np.int64).reshape(-1, 3))
