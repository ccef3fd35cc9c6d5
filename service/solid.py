"""A triangle surface made ready to integrate as a solid: welded, closed, wound outward.

Never a silently wrong tensor: an open surface is refused (``not_watertight``
with the count of open edges), inconsistent winding is repaired where the
surface is orientable, and inverted shells are turned outward, each with a
warning.  Cavities (a negative shell inside a positive one) are kept.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .body import MeshBody
from .errors import NotWatertightError, ZeroVolumeError
from .integrals import CHUNK, local_origin
from .topology import SurfaceTopology, face_components, orient_consistently, surface_topology, weld

__all__ = ["closed_surface"]


def closed_surface(body: MeshBody) -> tuple[NDArray[np.float64], NDArray[np.int64], tuple[str, ...]]:
    """Weld, check closedness, repair winding; the geometry to integrate."""
    vertices, faces = (body.vertices, body.faces) if body.welded else weld(body.vertices, body.faces)
    degenerate = (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2])
    if np.any(degenerate):
        faces = faces[~degenerate]  # zero-area faces contribute nothing to any integral
    if len(faces) == 0:
        raise ZeroVolumeError("every triangle of the mesh is degenerate; the file holds no solid")
    topo = surface_topology(faces, len(vertices))
    warnings: list[str] = []
    if topo.open_edges:
        raise NotWatertightError(
            f"mesh is not watertight ({topo.open_edges} open edges), so it does not bound a solid; "
            "repair it, or analyse it as a thin surface with model=shell and a thickness",
            open_edges=topo.open_edges,
        )
    if not topo.closed:
        faces, flipped = orient_consistently(faces, topo)
        topo = surface_topology(faces, len(vertices))
        if not topo.closed:
            raise NotWatertightError(
                f"mesh winding cannot be made consistent ({topo.unbalanced_edges} edges disagree); "
                "repair the mesh or use model=shell",
                unbalanced_edges=topo.unbalanced_edges,
            )
        warnings.append(f"inconsistent winding repaired ({flipped} of {len(faces)} faces flipped)")
    faces, more = _orient_outward(vertices, faces, topo)
    warnings.extend(more)
    return vertices, faces, tuple(warnings)


def _signed_volumes(x: NDArray[np.float64], faces: NDArray[np.int64]) -> NDArray[np.float64]:
    """6 x the signed volume of each tetrahedron (origin, face), a . (b x c), in blocks.

    Formed one coordinate column at a time (contiguous arrays), about three
    times faster than ``np.cross`` on rows for the meshes of a part library.
    """
    xs = [np.ascontiguousarray(x[:, k]) for k in range(3)]
    det = np.empty(len(faces))
    for start in range(0, len(faces), CHUNK):
        block = faces[start : start + CHUNK]
        a, b, c = ([xk.take(block[:, j]) for xk in xs] for j in range(3))
        det[start : start + CHUNK] = (a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2])
                                      + a[2] * (b[0] * c[1] - b[1] * c[0]))
    return det


def _orient_outward(
    vertices: NDArray[np.float64], faces: NDArray[np.int64], topo: SurfaceTopology
) -> tuple[NDArray[np.int64], list[str]]:
    """Make every shell bound positive volume, except cavities inside another shell."""
    x = vertices - local_origin(vertices)
    det = _signed_volumes(x, faces)
    if np.all(det >= 0):  # every face sees the local origin from outside: outward already
        return faces, []
    count, label = face_components(faces, topo)
    vol = np.bincount(label, weights=det, minlength=count)
    if count == 1 or np.all(vol < 0):
        if vol.sum() < 0:
            return faces[:, [0, 2, 1]], ["inverted winding corrected (all faces pointed inward)"]
        return faces, []
    if np.all(vol > 0):
        return faces, []
    lo = np.full((count, 3), np.inf)
    hi = np.full((count, 3), -np.inf)
    for k in range(3):
        for corner in range(3):
            coord = x[faces[:, corner], k]
            np.minimum.at(lo[:, k], label, coord)
            np.maximum.at(hi[:, k], label, coord)
    flip_shell = np.zeros(count, dtype=bool)
    for shell in np.flatnonzero(vol < 0):
        inside = (vol > 0) & np.all(lo <= lo[shell], axis=1) & np.all(hi >= hi[shell], axis=1)
        flip_shell[shell] = not np.any(inside)
    if not np.any(flip_shell):
        return faces, []
    out = faces.copy()
    sel = flip_shell[label]
    out[sel] = out[sel][:, [0, 2, 1]]
    return out, [f"inverted winding corrected on {int(flip_shell.sum())} of {count} shells"]
