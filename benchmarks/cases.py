"""Bodies with known answers shared by the benchmarks and the tests: meshes and their writers.

The tests import these (``benchmarks.cases``); nothing here imports the tests.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "BOX_FACES",
    "box",
    "centred_box",
    "box_inertia",
    "cube",
    "prism",
    "icosahedron",
    "l_bracket",
    "uv_sphere",
    "torus",
    "flat_shells",
    "triangles_stl_bytes",
    "stl_bytes",
    "obj_bytes",
    "write_stl",
    "write_obj",
]

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


def cube(side: float, origin: Any = (0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """``box`` with three equal sides."""
    return box(side, side, side, origin)


def box_inertia(mass: float, a: float, b: float, c: float) -> np.ndarray:
    """Inertia tensor of a solid a x b x c box of ``mass`` about its centre, along its edges:
    m (b^2 + c^2) / 12, ... (any mechanics text, e.g. Landau & Lifshitz §32, problem 2)."""
    return mass / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def centred_box(a: float, b: float, c: float) -> tuple[np.ndarray, np.ndarray]:
    """``box`` with its centre at the origin."""
    return box(a, b, c, origin=-np.array([a, b, c]) / 2)


def prism(n: int, radius: float, height: float, centred: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Regular n-gon prism (a tessellated cylinder) about z, from z = 0 to ``height`` or centred on the origin."""
    ang = 2 * np.pi * np.arange(n) / n
    ring = np.stack([radius * np.cos(ang), radius * np.sin(ang)], axis=1)
    v = np.vstack([np.c_[ring, np.zeros(n)], np.c_[ring, np.full(n, height)], [[0, 0, 0], [0, 0, height]]])
    faces = []
    for i in range(n):
        j = (i + 1) % n
        faces += [[i, j, n + j], [i, n + j, n + i], [2 * n, j, i], [2 * n + 1, n + i, n + j]]
    if centred:
        v = v - np.array([0.0, 0.0, height / 2])
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


def uv_sphere(n_lat: int, n_lon: int, radius: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Latitude-longitude sphere: 2 n_lon (n_lat - 1) outward triangles, single-vertex poles."""
    theta = np.pi * np.arange(1, n_lat) / n_lat
    phi = 2 * np.pi * np.arange(n_lon) / n_lon
    ring = np.stack(
        [
            np.outer(np.sin(theta), np.cos(phi)),
            np.outer(np.sin(theta), np.sin(phi)),
            np.repeat(np.cos(theta)[:, None], n_lon, axis=1),
        ],
        axis=-1,
    ).reshape(-1, 3)
    v = radius * np.vstack([[0.0, 0.0, 1.0], ring, [0.0, 0.0, -1.0]])
    south = len(v) - 1
    idx = 1 + np.arange((n_lat - 1) * n_lon).reshape(n_lat - 1, n_lon)
    nxt = np.roll(idx, -1, axis=1)
    top = np.stack([np.zeros(n_lon, dtype=np.int64), idx[0], nxt[0]], axis=1)
    bottom = np.stack([np.full(n_lon, south), nxt[-1], idx[-1]], axis=1)
    a, b, c, d = idx[:-1], nxt[:-1], idx[1:], nxt[1:]
    quads = np.concatenate([np.stack([a, c, d], -1).reshape(-1, 3), np.stack([a, d, b], -1).reshape(-1, 3)])
    return v, np.vstack([top, quads, bottom]).astype(np.int64)


def torus(n_major: int, n_minor: int, major: float = 1.0, minor: float = 0.4) -> tuple[np.ndarray, np.ndarray]:
    """Torus about z, vertices on the exact surface: 2 n_major n_minor outward triangles."""
    u = 2 * np.pi * np.arange(n_major) / n_major
    v = 2 * np.pi * np.arange(n_minor) / n_minor
    uu, vv = np.meshgrid(u, v, indexing="ij")
    ring = major + minor * np.cos(vv)
    verts = np.stack([ring * np.cos(uu), ring * np.sin(uu), minor * np.sin(vv)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n_major), np.arange(n_minor), indexing="ij")
    a = i * n_minor + j
    b = ((i + 1) % n_major) * n_minor + j
    c = ((i + 1) % n_major) * n_minor + (j + 1) % n_minor
    d = i * n_minor + (j + 1) % n_minor
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return verts, faces.astype(np.int64)


def flat_shells(offset: float, count: int = 189) -> tuple[np.ndarray, np.ndarray]:
    """``count`` closed tetrahedral shells whose four corners lie in one plane (zero volume), about ``offset``."""
    rng = np.random.default_rng(0)
    vertices: list[np.ndarray] = []
    faces: list[list[int]] = []
    for _ in range(count):
        centre = rng.normal(size=3) * 10 + offset
        u, v = rng.normal(size=3), rng.normal(size=3)
        n = len(vertices)
        vertices += [centre + a * u + b * v for a, b in ((0, 0), (1, 0), (0, 1), (0.3, 0.4))]
        faces += [[n, n + 1, n + 2], [n, n + 3, n + 1], [n + 1, n + 3, n + 2], [n, n + 2, n + 3]]
    return np.array(vertices), np.array(faces)


def triangles_stl_bytes(triangles: np.ndarray, header: bytes = b"") -> bytes:
    """Binary STL of triangles (n, 3, 3): float32 coordinates, zero normals, ``header`` padded to 80 bytes."""
    tri = np.asarray(triangles, dtype=np.float64)
    rec = np.zeros(len(tri), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = tri
    return header.ljust(80, b"\0") + struct.pack("<I", len(tri)) + rec.tobytes()


def stl_bytes(vertices: np.ndarray, faces: np.ndarray, header: bytes = b"") -> bytes:
    """Binary STL of the triangles ``vertices[faces]``."""
    return triangles_stl_bytes(np.asarray(vertices, dtype=np.float64)[np.asarray(faces)], header)


def obj_bytes(objects: Sequence[tuple[str | None, ArrayLike, ArrayLike]]) -> bytes:
    """OBJ text of named (``o name``) or unnamed objects (name, vertices, faces); float64 coordinates
    written with repr, an exact round trip."""
    lines: list[str] = []
    base = 0
    for name, v, f in objects:
        if name is not None:
            lines.append(f"o {name}")
        vertices = np.asarray(v, dtype=np.float64)
        lines += ["v " + " ".join(repr(x) for x in p) for p in vertices.tolist()]
        lines += ["f " + " ".join(str(base + i + 1) for i in t) for t in np.asarray(f).tolist()]
        base += len(vertices)
    return ("\n".join(lines) + "\n").encode()


def write_stl(path: Path, v: np.ndarray, f: np.ndarray, header: bytes = b"sample mesh") -> None:
    path.write_bytes(stl_bytes(v, f, header.ljust(80, b" ")))


def write_obj(path: Path, v: np.ndarray, f: np.ndarray) -> None:
    path.write_bytes(obj_bytes([(None, v, f)]))
