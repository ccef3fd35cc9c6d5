"""Surface area of a body's boundary [m^2], as CAD mass-property dialogs report it.

A triangle surface's area is the sum of its triangles' areas, |(b - a) x (c - a)| / 2,
with coordinates shifted to a local origin first (as ``mass`` does) and summed
pairwise by numpy.  A loader whose bodies are not triangle surfaces but know
their boundary's area (CAD B-reps) puts it, in m^2, into the part's
``extras["surface_area"]``; ``part_surface_area`` takes that first.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .body import MeshBody, Part

__all__ = ["triangle_area", "part_surface_area", "SURFACE_AREA_KEY"]

SURFACE_AREA_KEY = "surface_area"
AREA_BLOCK = 1 << 16  # triangles per block: ~10 MB of temporaries, not ~150 bytes per triangle at once


def triangle_area(vertices: NDArray[np.float64], faces: NDArray[np.int64]) -> float:
    """Total area of the triangles ``faces`` over ``vertices`` (in the vertices' units squared)."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if len(f) == 0:
        return 0.0
    origin = v[f[0, 0]]
    # each triangle's |n| in blocks (temporaries bounded), then one pairwise sum over all of them
    norms = np.empty(len(f))
    # each row gathered whole as one 24-byte record: ~3x faster than v[block[:, k]] on large meshes
    records = np.ascontiguousarray(v).view(np.dtype((np.void, 3 * v.itemsize))).reshape(-1)
    for start in range(0, len(f), AREA_BLOCK):
        corners = records.take(f[start : start + AREA_BLOCK]).view(np.float64).reshape(-1, 3, 3)
        a, b, c = (corners[:, k] - origin for k in range(3))
        cross = np.cross(b - a, c - a)
        norms[start : start + AREA_BLOCK] = np.sqrt(np.einsum("ij,ij->i", cross, cross))
    return float(0.5 * np.sum(norms))


def part_surface_area(part: Part) -> float | None:
    """The part's surface area [m^2]: its loader's own figure, a mesh's triangles, else None."""
    given = part.extras.get(SURFACE_AREA_KEY)
    if isinstance(given, (int, float)):
        return float(given)
    body = part.body
    if isinstance(body, MeshBody):
        return triangle_area(body.vertices, body.faces) * body.length_scale**2
    return None
