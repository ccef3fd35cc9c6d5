"""Meshes written by the tests themselves, as binary STL bytes (the shapes and writers are ``benchmarks.cases``)."""

from __future__ import annotations

from benchmarks.cases import (
    BOX_FACES,
    box,
    icosahedron,
    l_bracket,
    prism,
    stl_bytes,
    torus,
    triangles_stl_bytes,
    write_obj,
    write_stl,
)

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
    """A closed torus of ``2 n m`` triangles, outward winding (``benchmarks.cases.torus``)."""
    return stl_bytes(*torus(n, m, major, minor))
