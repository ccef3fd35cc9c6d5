"""Bodies with known answers shared by the benchmarks and the tests: meshes and their writers.

The tests import these (``benchmarks.cases``); nothing here imports the tests.
"""

from __future__ import annotations

import struct
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["BOX_FACES", "box", "prism", "icosahedron", "l_bracket", "triangles_stl_bytes", "stl_bytes", "write_stl", "write_obj"]

BOX_FACES = np.array(
    [
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ]
)
"""Outward winding of the eight corners of ``box``: vertex k has bits (x, y, z) = (k&1, k&2, k&4)."""


def box(a: float, b: float, c: float, origin: Any = (0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned box with outward winding; vertex k has bits (x, y, z) = (k&1, k&2, k&4)."""
    o = np.asarray(origin, dtype=float)
    v = np.array([[(k & 1) * a, ((k >> 1) & 1) * b, ((k >> 2) & 1) * c] for k in range(8)]) + o
    return v, BOX_FACES.copy()


def prism(n: int, radius: float, height: float) -> tuple[np.ndarray, np.ndarray]:
    ang = 2 * np.pi * np.arange(n) / n
    ring = np.stack([radius * np.cos(ang), radius * np.sin(ang)], axis=1)
    v = np.vstack([np.c_[ring, np.zeros(n)], np.c_[ring, np.full(n, height)], [[0, 0, 0], [0, 0, height]]])
    faces = []
    for i in range(n):
        j = (i + 1) % n
        faces += [[i, j, n + j], [i, n + j, n + i], [2 * n, j, i], [2 * n + 1, n + i, n + j]]
    return v, np.array(faces)


def icosahedron(edge: float) -> tuple[np.ndarray, np.ndarray]:
    phi = (1 + 5**0.5) / 2
    s = edge / 2
    corners: list[list[float]] = []
    for a in (-1, 1):
        for b in (-1, 1):
            corners += [[0, a * s, b * s * phi], [a * s, b * s * phi, 0], [b * s * phi, 0, a * s]]
    v = np.array(corners)
    faces = []
    n = len(v)
    for i in range(n):
        for j in range(i + 1, n):
            for k in range(j + 1, n):
                d = [np.linalg.norm(v[p] - v[q]) for p, q in ((i, j), (j, k), (i, k))]
                if all(abs(x - edge) < 1e-9 * edge for x in d):
                    tri = [i, j, k]
                    if np.dot(np.cross(v[j] - v[i], v[k] - v[i]), v[i]) < 0:
                        tri = [i, k, j]
                    faces.append(tri)
    return v, np.array(faces)


def l_bracket(depth: float) -> tuple[np.ndarray, np.ndarray]:
    """L profile (0,0),(4,0),(4,1),(1,1),(1,3),(0,3) extruded by ``depth`` along z."""
    prof = [(0, 0), (4, 0), (4, 1), (1, 1), (1, 3), (0, 3)]
    n = len(prof)
    v = np.array([[x, y, 0.0] for x, y in prof] + [[x, y, depth] for x, y in prof])
    faces = []
    for i in range(1, n - 1):  # fan from vertex 0 covers the L exactly
        faces += [[0, i + 1, i], [n, n + i, n + i + 1]]
    for i in range(n):
        j = (i + 1) % n
        faces += [[i, j, n + j], [i, n + j, n + i]]
    return v, np.array(faces)


def triangles_stl_bytes(triangles: np.ndarray, header: bytes = b"") -> bytes:
    """Binary STL of triangles (n, 3, 3): float32 coordinates, zero normals, ``header`` padded to 80 bytes."""
    tri = np.asarray(triangles, dtype=np.float64)
    rec = np.zeros(len(tri), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = tri
    return header.ljust(80, b"\0") + struct.pack("<I", len(tri)) + rec.tobytes()


def stl_bytes(vertices: np.ndarray, faces: np.ndarray, header: bytes = b"") -> bytes:
    """Binary STL of the triangles ``vertices[faces]``."""
    return triangles_stl_bytes(np.asarray(vertices, dtype=np.float64)[np.asarray(faces)], header)


def write_stl(path: Path, v: np.ndarray, f: np.ndarray, header: bytes = b"sample mesh") -> None:
    path.write_bytes(stl_bytes(v, f, header.ljust(80, b" ")))


def write_obj(path: Path, v: np.ndarray, f: np.ndarray) -> None:
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in v.tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f.tolist()]
    path.write_text("\n".join(lines) + "\n")
