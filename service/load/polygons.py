"""Polygons of more than three corners, split into triangles: how much the split matters.

A face of four or more corners that are not in one plane does not define a
surface: each way of cutting it into triangles bounds a different volume.
Our readers (and trimesh's for PLY, and Blender) cut it as a fan from its
first corner; the PLY faces as written are read back from the file
(``meshes._ply_split_notes``); VTK cuts by ear clipping, and the two volumes differ (VTK's
``shark.ply`` by 3.7e-5).  ``fan_split_note`` measures the difference that
flipping each inner diagonal of every fan makes, sum over polygons of
|det(c[i+1] - c0, c[i+2] - c0, c[i+3] - c0)| / 6, which for a quadrilateral is
exactly the volume between its two splits, and says it in a warning when it
is more than ``NOTE_REL`` of the volume: the number that comes back then
holds for the fan split, and the warning names that assumption.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["NOTE_REL", "fan_split_note", "fan_triangles"]

NOTE_REL = 1e-9  # below this share of the volume, the split is lost in the file's own rounding


def fan_triangles(corners: NDArray[np.int64], counts: NDArray[np.int64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Every face split as a fan from its first corner: (k, 3) corner values, and the face of each triangle.

    corners : every face's values (vertex numbers, or positions in another array), one face after
    another; counts : corners per face (a face of fewer than three gives no triangle).
    """
    counts = np.asarray(counts, dtype=np.int64)
    fans = np.maximum(counts - 2, 0)
    face = np.repeat(np.arange(len(counts)), fans)
    step = np.arange(len(face)) - np.repeat(np.cumsum(fans) - fans, fans)
    first = (np.cumsum(counts) - counts)[face]
    return np.stack([corners[first], corners[first + 1 + step], corners[first + 2 + step]], axis=1), face


def fan_split_note(
    vertices: NDArray[np.float64],
    corners: NDArray[np.int64],
    counts: NDArray[np.int64],
    what: str,
    *,
    volume: float | None = None,
    how: str = "as a fan from its first corner (as Blender and trimesh do)",
) -> str | None:
    """A warning when the file's non-planar polygons make the volume depend on how they are split.

    corners : every face's vertex numbers, one face after another; counts : corners per face;
    what : the format ("ply": "faces of the PLY file") or the cells ("polyhedron": "faces of its
    polyhedron cells"); volume : the volume to weigh the change against, by default the one the
    faces enclose as one surface.
    """
    counts = np.asarray(counts, dtype=np.int64)
    if not np.any(counts >= 4):
        return None
    x = np.asarray(vertices, dtype=np.float64)
    x = x - x.mean(axis=0) if len(x) else x
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    # the fan's volume, to weigh the difference against: sum of det(c0, ci, ci+1) / 6 over every face
    tri, _ = fan_triangles(corners, counts)
    a, b, c = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
    if volume is None:
        volume = abs(float(np.einsum("ij,ij->", a, np.cross(b, c)))) / 6
    # each inner diagonal of a fan flipped: the tetrahedron (c0, ci+1, ci+2, ci+3)
    flips = np.maximum(counts - 3, 0)
    face = np.repeat(np.arange(len(counts)), flips)
    step = np.arange(len(face)) - np.repeat(np.cumsum(flips) - flips, flips)
    first = starts[face]
    c0 = x[corners[first]]
    d1, d2, d3 = (x[corners[first + 1 + step + j]] - c0 for j in range(3))
    tet = np.abs(np.einsum("ij,ij->i", d1, np.cross(d2, d3))) / 6
    size = float(np.ptp(x, axis=0).max()) if len(x) else 0.0
    bent = tet > 1e-12 * (size * size * size)  # beyond float64 rounding of a planar face (inf, never OverflowError)
    change = float(tet[bent].sum())
    if volume == 0.0 or change <= NOTE_REL * volume:
        return None
    polygons = int(np.count_nonzero(counts >= 4))
    bent_faces = int(np.unique(face[bent]).size)
    where = f"the {what.upper()} file" if what in ("ply", "obj", "off") else f"the {what} cells"
    return (
        f"{bent_faces} of the {polygons} faces of {where} with more than three corners are not planar; "
        f"each was split into triangles {how}, and splitting "
        f"them along other diagonals changes the volume by up to about {change / volume:.1g} of it"
    )
