"""A triangle surface made ready to integrate as a solid: welded, closed, wound outward.

Never a silently wrong tensor: seams (one point written twice with different
rounding) are merged first (``seams.merge_seams``), an open surface is refused
(``not_watertight`` with the count of open edges and the part's name),
inconsistent winding is repaired where the surface is orientable, and shells
are oriented by nesting, each with a warning.

Orientation by nesting.  A shell inside an odd number of other shells bounds
a cavity and must wind inward; one inside an even number (zero included)
bounds material and must wind outward.  Whether a shell is inside another is
decided by the generalised winding number of the other shell at a point of
the first (the solid angle it subtends, van Oosterom & Strackee, IEEE Trans.
Biomed. Eng. 30(2), 1983), which is exact for closed shells and does not
depend on bounding boxes.  A shell of zero volume is never flipped, and
shells that touch or coincide (a test point on the other shell) keep the
file's orientation: flipping shells must not manufacture volume.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .body import MeshBody
from .errors import NotWatertightError, ZeroVolumeError
from .integrals import CHUNK, local_origin
from .seams import merge_seams
from .tolerances import EPS
from .topology import SurfaceTopology, face_components, orient_consistently, surface_topology, weld

__all__ = ["closed_surface"]


def closed_surface(body: MeshBody) -> tuple[NDArray[np.float64], NDArray[np.int64], tuple[str, ...]]:
    """Weld, check closedness, repair winding; the geometry to integrate."""
    vertices, faces = (body.vertices, body.faces) if body.welded else weld(body.vertices, body.faces)
    degenerate = (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2])
    if np.any(degenerate):
        faces = faces[~degenerate]  # zero-area faces contribute nothing to any integral
    if len(faces) == 0:
        cause = ("; its float32 coordinates are too coarse at that distance from the origin: export it in float64 "
                 "or nearer the origin") if body.coordinate_eps >= 2.0**-24 else ""
        raise ZeroVolumeError(f"every triangle of the mesh is degenerate; the file holds no solid{cause}")
    topo = surface_topology(faces, len(vertices))
    warnings: list[str] = []
    if topo.open_edges:
        seams = merge_seams(vertices, faces)
        if seams.merged:
            faces = seams.faces
            topo = surface_topology(faces, len(vertices))
            warnings.append(seams.warning())
    if topo.open_edges:
        named = f"part {body.name!r} " if body.name else "mesh "
        raise NotWatertightError(
            f"{named}is not watertight ({topo.open_edges} open edges), so it does not bound a solid; "
            "repair it, or analyse it as a thin surface with model=shell and a thickness",
            open_edges=topo.open_edges, **({"part": body.name} if body.name else {}),
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
    """Orient every shell by its nesting depth: material outward, cavities inward."""
    x = vertices - local_origin(vertices)
    det = _signed_volumes(x, faces)
    if np.all(det >= 0):  # every face sees the local origin from outside: outward already
        return faces, []
    total = float(det.sum())
    count, label = face_components(faces, topo)
    vol = np.bincount(label, weights=det, minlength=count)
    noise = np.bincount(label, weights=np.abs(det), minlength=count)
    flat = np.abs(vol) <= 64 * EPS * noise  # a shell of zero volume: no orientation makes it a body
    if count == 1:
        if total < 0:
            return faces[:, [0, 2, 1]], ["inverted winding corrected (all faces pointed inward)"]
        return faces, []
    depth = _nesting_depth(x, faces, label, count)
    if depth is None:  # a shell touches another: nesting undecidable, keep the file's orientation
        if total < 0 and np.all(vol <= 0):
            return faces[:, [0, 2, 1]], ["inverted winding corrected (all faces pointed inward)"]
        return faces, []
    want_positive = depth % 2 == 0
    flip_shell = ((vol > 0) != want_positive) & ~flat
    if not np.any(flip_shell):
        return faces, []
    out = faces.copy()
    sel = flip_shell[label]
    out[sel] = out[sel][:, [0, 2, 1]]
    if np.all(flip_shell | flat):
        return out, ["inverted winding corrected (all faces pointed inward)"]
    return out, [f"winding corrected on {int(flip_shell.sum())} of {count} shells by their nesting "
                 "(a shell inside an odd number of others is a cavity)"]


def winding_numbers(x: NDArray[np.float64], faces: NDArray[np.int64], points: NDArray[np.float64]) -> NDArray[np.float64]:
    """Generalised winding number of the triangles ``faces`` at each of ``points``.

    The sum of the signed solid angles of the triangles seen from the point
    over 4 pi (van Oosterom & Strackee 1983: tan(Omega/2) = a.(b x c) /
    (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|)); an integer for a closed
    surface and a point off it.
    """
    out = np.empty(len(points))
    for i, p in enumerate(points):
        total = 0.0
        for start in range(0, len(faces), CHUNK):
            block = faces[start : start + CHUNK]
            a, b, c = (x[block[:, k]] - p for k in range(3))
            la, lb, lc = (np.sqrt(np.einsum("ij,ij->i", v, v)) for v in (a, b, c))
            num = np.einsum("ij,ij->i", a, np.cross(b, c))
            den = (la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", a, c) * lb
                   + np.einsum("ij,ij->i", b, c) * la)
            total += float(np.sum(np.arctan2(num, den)))
        out[i] = total / (2 * np.pi)
    return out


def _nesting_depth(x: NDArray[np.float64], faces: NDArray[np.int64], label: NDArray[np.int64],
                   count: int) -> NDArray[np.int64] | None:
    """How many other shells contain each shell; None when a test point lies on another shell."""
    lo = np.full((count, 3), np.inf)
    hi = np.full((count, 3), -np.inf)
    for k in range(3):
        for corner in range(3):
            coord = x[faces[:, corner], k]
            np.minimum.at(lo[:, k], label, coord)
            np.maximum.at(hi[:, k], label, coord)
    order = np.argsort(label, kind="stable")
    starts = np.searchsorted(label[order], np.arange(count))
    depth = np.zeros(count, dtype=np.int64)
    for shell in range(count):
        # a test point: the centroid of the shell's largest face (well inside the shell's surface)
        own = order[starts[shell] : starts[shell + 1] if shell + 1 < count else len(order)]
        tri = x[faces[own]]
        area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
        point = tri[int(np.argmax(area))].mean(axis=0)
        holders = np.flatnonzero(np.all(lo <= point, axis=1) & np.all(hi >= point, axis=1))
        for other in holders:
            if other == shell:
                continue
            theirs = order[starts[other] : starts[other + 1] if other + 1 < count else len(order)]
            w = float(winding_numbers(x, faces[theirs], point[None, :])[0])
            if abs(w - round(w)) > 0.25:
                return None  # the point lies on the other shell: they touch or overlap
            depth[shell] += round(w) != 0
    return depth
