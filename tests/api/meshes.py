"""Meshes written by the tests themselves, as binary STL bytes."""

from __future__ import annotations

import struct

import numpy as np

__all__ = ["box_stl", "torus_stl", "stl_bytes"]


def stl_bytes(vertices: np.ndarray, faces: np.ndarray) -> bytes:
    """Binary STL of triangles ``vertices[faces]`` (float32, zero normals)."""
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)]
    records = np.zeros(len(tri), dtype=[("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    records["v"] = tri
    return b"\0" * 80 + struct.pack("<I", len(tri)) + records.tobytes()


def box_stl(a: float, b: float, c: float, origin: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> bytes:
    """A closed a x b x c box, outward winding, corner at ``origin``."""
    corners = np.array([[x, y, z] for x in (0, a) for y in (0, b) for z in (0, c)], dtype=np.float64)
    corners += np.asarray(origin)
    faces = np.array([
        [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5],  # x = 0, x = a
        [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],  # y = 0, y = b
        [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],  # z = 0, z = c
    ])
    return stl_bytes(corners, faces)


def torus_stl(n: int, m: int, major: float = 2.0, minor: float = 0.5) -> bytes:
    """A closed torus of ``2 n m`` triangles, outward winding."""
    u = np.linspace(0, 2 * np.pi, n, endpoint=False)[:, None]
    v = np.linspace(0, 2 * np.pi, m, endpoint=False)[None, :]
    ring = major + minor * np.cos(v)
    pts = np.stack([ring * np.cos(u), ring * np.sin(u), minor * np.sin(v) + 0 * u], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    a, b = i * m + j, ((i + 1) % n) * m + j
    c, d = ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return stl_bytes(pts, faces)
