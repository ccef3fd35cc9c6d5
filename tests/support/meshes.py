"""Meshes written by the tests themselves, as binary STL bytes (the shapes and writers are ``benchmarks.cases``)."""

from __future__ import annotations

import numpy as np

from benchmarks.cases import BOX_FACES, box, icosahedron, l_bracket, prism, stl_bytes, triangles_stl_bytes, write_obj, write_stl

__all__ = [
    "BOX_FACES",
    "box",
    "box_stl",
    "icosahedron",
    "l_bracket",
    "prism",
    "stl_bytes",
    "torus_stl",
    "triangles_stl_bytes",
    "write_obj",
    "write_stl",
]


def box_stl(a: float, b: float, c: float, origin: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> bytes:
    """A closed a x b x c box, outward winding, corner at ``origin``."""
    return stl_bytes(*box(a, b, c, origin))


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
