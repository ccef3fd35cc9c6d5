"""A triangle surface made ready to integrate as a solid: welded, closed, wound outward.

Never a silently wrong tensor: seams (one point written twice with different
rounding) are merged first (``seams.merge_seams``), an open surface is refused
(``not_watertight`` with the count of open edges and the part's name),
inconsistent winding is repaired where the surface is orientable, and shells
whose windings disagree are oriented by nesting, each with a warning.

Shells all wound outward are each a solid: the file says so, as trimesh and
VTK's vtkMassProperties read it, and a shell inside another then adds its
material to the other's (a cavity wound outward by a tool that turned every
shell outward counts as material; its file has to wind it inward).  Where
that holds for every shell nothing is re-wound, wherever the shells lie.

Orientation by nesting.  Where some shells enclose negative volume as wound,
the file's orientation is unreliable.  A shell inside an odd number of other
shells bounds a cavity and must wind inward; one inside an even number (zero
included) bounds material and must wind outward.  Whether a shell is inside another is
decided by the generalised winding number of the other shell at a point of
the first (the solid angle it subtends, van Oosterom & Strackee, IEEE Trans.
Biomed. Eng. 30(2), 1983), which is exact for closed shells and does not
depend on bounding boxes.  A shell of zero volume is never flipped, and
shells that touch or coincide (a test point on the other shell) keep the
file's orientation: flipping shells must not manufacture volume.  Shells are
the components of faces joined across manifold edges, unless one of those is
not closed by itself (two rooms sharing a wall: the wall's edges are
non-manifold, and the wall's two sides come apart from their rooms); then the
shells are the components joined across every edge, each closed, so a piece
of a shell is never re-wound on its own.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from .blocks import for_each_block
from .body import MeshBody
from .errors import InvalidMeshError, NotWatertightError, ZeroVolumeError
from .integrals import CHUNK, Sums, gather_corners, local_origin, point_records, simplex_sums
from .tolerances import EPS
from .topology import SurfaceTopology, _components, face_components, orient_consistently, row_ids, surface_topology, weld

__all__ = ["FirstPass", "OrientedSurface", "closed_surface", "oriented_surface"]

INVERTED = "inverted winding corrected"  # API.md's words for a body whose faces all pointed inward


FirstPass = tuple[NDArray[np.float64], Sums]
"""The integrals of a closed surface about its local origin (``integrals.local_origin``), and that origin."""


class OrientedSurface(NamedTuple):
    """A closed surface ready to integrate, and its first integration pass where the orientation computed it."""

    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    warnings: tuple[str, ...]
    first_pass: FirstPass | None


def closed_surface(body: MeshBody) -> tuple[NDArray[np.float64], NDArray[np.int64], tuple[str, ...]]:
    """Weld, check closedness, repair winding; the geometry to integrate."""
    vertices, faces, warnings, _ = oriented_surface(body)
    return vertices, faces, warnings


def _collapse_cause(body: MeshBody) -> str:
    """Why every triangle collapsed, where the coordinates' storage explains it: float32 steps at the
    largest coordinate above 1e-6 of the body's size (a part far from the origin).  Where they are finer,
    the file's corners themselves coincide (a frame of an animation squashed flat), and nothing is said."""
    if body.coordinate_eps < 2.0**-24 or len(body.vertices) == 0:
        return ""
    span = float(np.max(np.ptp(body.vertices, axis=0)))
    step = body.coordinate_eps * float(np.max(np.abs(body.vertices)))
    if step < 1e-6 * span:
        return ""
    return "; its float32 coordinates are too coarse at that distance from the origin: export it in float64 or nearer the origin"


def oriented_surface(body: MeshBody) -> OrientedSurface:
    """``closed_surface``, with the first integration pass of the faces it returns where that came free.

    The orientation needs each face's signed volume about the local origin; the first pass of
    ``mass.refine`` integrates the same faces about the same origin.  Both are formed from one gather
    of the corners, and the pass is kept where the orientation left the faces as they were (the
    usual case), else dropped: re-wound faces are integrated afresh.
    """
    vertices, faces = (body.vertices, body.faces) if body.welded else weld(body.vertices, body.faces)
    degenerate = (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2])
    if np.any(degenerate):
        faces = faces[~degenerate]  # zero-area faces contribute nothing to any integral
    if len(faces) == 0:
        raise ZeroVolumeError(f"every triangle of the mesh is degenerate; the file holds no solid{_collapse_cause(body)}")
    topo = surface_topology(faces, len(vertices))
    warnings: list[str] = []
    if topo.nonmanifold_edges:  # a triangle listed twice shares each edge with its copy: four faces on an edge
        repeated = _repeated_faces(faces)
        once = faces[~repeated]
        once_topo = surface_topology(once, len(vertices)) if np.any(repeated) else topo
        if once_topo is not topo and not once_topo.open_edges:  # a closed body listed twice (an open one is refused below)
            warnings.append(
                f"{len(faces) - len(once)} of {len(faces)} triangles repeat another with the same corners and winding "
                "(the file lists them twice, as under a second material); each was weighed once, not twice"
            )
            faces, topo = once, once_topo
    if topo.open_edges:
        from .seams import merge_seams  # only an open surface needs it

        seams = merge_seams(vertices, faces, coordinate_eps=body.coordinate_eps)
        if seams.merged:
            faces = seams.faces
            topo = surface_topology(faces, len(vertices))
            warnings.append(seams.warning())
    if topo.open_edges:
        from .seams import close_t_junctions

        junctions = close_t_junctions(vertices, faces)
        if junctions is not None:
            faces = junctions.faces
            topo = surface_topology(faces, len(vertices))
            warnings.append(junctions.warning())
    if topo.open_edges:
        named = f"part {body.name!r} " if body.name else "mesh "
        raise NotWatertightError(
            f"{named}is not watertight ({topo.open_edges} open edges), so it does not bound a solid; "
            "repair it, or analyse it as a thin surface with model=shell and a thickness",
            open_edges=topo.open_edges,
            **({"part": body.name} if body.name else {}),
        )
    as_stored = None  # the faces as the file winds them, where their winding had to be made consistent
    if not topo.closed:
        as_stored = faces
        faces, _ = orient_consistently(faces, topo)
        topo = surface_topology(faces, len(vertices))
        if not topo.closed:
            shared = (
                f"; {topo.nonmanifold_edges} edges are shared by more than two faces (non-manifold), "
                "so the faces do not bound one solid"
                if topo.nonmanifold_edges
                else ""
            )
            raise NotWatertightError(
                f"mesh winding cannot be made consistent ({topo.unbalanced_edges} edges disagree{shared}); "
                "repair the mesh or use model=shell",
                unbalanced_edges=topo.unbalanced_edges,
                **({"nonmanifold_edges": topo.nonmanifold_edges} if topo.nonmanifold_edges else {}),
            )
    origin = local_origin(vertices)
    det, first = _volumes_and_first_pass(vertices - origin, faces)
    oriented, more = _orient_outward(vertices, faces, topo, det)
    del det
    first_pass = (origin, first) if oriented is faces and first is not None else None
    faces = oriented
    if as_stored is not None:
        # counted against the file: the consistent winding keeps the first face's, so a file whose first face
        # alone was reversed had every other face flipped, then all of them turned outward again
        flipped = int(np.count_nonzero(np.any(faces != as_stored, axis=1)))
        warnings.append(f"inconsistent winding repaired ({flipped} of {len(faces)} faces flipped)")
        more = [w for w in more if w != INVERTED]
    warnings.extend(more)
    return OrientedSurface(vertices, faces, tuple(warnings), first_pass)


def _repeated_faces(faces: NDArray[np.int64]) -> NDArray[np.bool_]:
    """Faces that repeat an earlier face: the same three corners in the same cyclic order (the same winding)."""
    first = np.argmin(faces, axis=1)  # each face turned to start at its smallest corner, its winding kept
    turned = np.take_along_axis(faces, (first[:, None] + np.arange(3)) % 3, axis=1)
    _, heads = row_ids(np.ascontiguousarray(turned).view(np.uint64))
    repeated = np.ones(len(faces), dtype=bool)
    repeated[heads] = False
    return repeated


def _volumes_and_first_pass(x: NDArray[np.float64], faces: NDArray[np.int64]) -> tuple[NDArray[np.float64], Sums | None]:
    """6 x the signed volume of each tetrahedron (origin, face), a . (b x c), and the faces' integrals about the
    origin of ``x`` (``integrals.simplex_sums``, "apex"), from one gather of the corners in blocks.

    The volumes are formed one coordinate column at a time (contiguous arrays), about three times faster than
    ``np.cross`` on rows.  The integrals are None where a value overflowed: the first pass, run again, then
    refuses the coordinates as it always has.
    """
    det = np.empty(len(faces))

    def volumes(start: int, corners: list[list[NDArray[np.float64]]]) -> None:
        a, b, c = corners
        det[start : start + len(a[0])] = (
            a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0])
        )

    with np.errstate(over="ignore", invalid="ignore"):
        sums = simplex_sums(x, faces, "apex", None, each_block=volumes)
    finite = all(
        np.isfinite(v).all()
        for v in (sums.m0, sums.m1, sums.m2, sums.abs_m0, sums.abs_m2, sums.noise, sums.element_err, sums.measure)
    )
    return det, sums if finite else None


def _volume_magnitudes(x: NDArray[np.float64], faces: NDArray[np.int64]) -> NDArray[np.float64]:
    """The sum of the magnitudes of the six products in each face's a . (b x c): the scale of its rounding.

    |a . (b x c)| itself is no such scale: for a face far from the local origin and nearly in line with it the
    products cancel, and the determinant's rounding (~eps x these products) can exceed it many times.
    """
    records = point_records(x)
    out = np.empty(len(faces))

    def block(start: int) -> None:
        a, b, c = (np.abs(v) for v in gather_corners(records, faces[start : start + CHUNK]))
        out[start : start + CHUNK] = (
            a[0] * (b[1] * c[2] + b[2] * c[1]) + a[1] * (b[2] * c[0] + b[0] * c[2]) + a[2] * (b[0] * c[1] + b[1] * c[0])
        )

    for_each_block(block, range(0, len(faces), CHUNK))
    return out


def _orient_outward(
    vertices: NDArray[np.float64], faces: NDArray[np.int64], topo: SurfaceTopology, det: NDArray[np.float64]
) -> tuple[NDArray[np.int64], list[str]]:
    """Keep shells that all wind outward; otherwise orient every shell by its nesting depth: material outward,
    cavities inward.  ``det``: 6 x each face's signed volume about the local origin."""
    if np.all(det >= 0):  # every face sees the local origin from outside: outward already
        count, label = face_components(faces, topo)
        if count == 1:
            return faces, []
        x = vertices - local_origin(vertices)
        noise = np.bincount(label, weights=_volume_magnitudes(x, faces), minlength=count)
        solid = np.abs(np.bincount(label, weights=det, minlength=count)) > 64 * EPS * noise
        return faces, _overlap_note(x, faces, label, solid)
    total = float(det.sum())
    count, label = face_components(faces, topo)
    if count == 1:  # one shell: the file's winding or its reverse; no shell noise to weigh
        return (faces[:, [0, 2, 1]], [INVERTED]) if total < 0 else (faces, [])
    scale = _volume_magnitudes(vertices - local_origin(vertices), faces)  # each face's rounding scale, for the shells' noise
    vol = np.bincount(label, weights=det, minlength=count)
    if count > 1 and np.any(vol < 0) and not _each_closed(faces, label):
        # components split at non-manifold edges (two rooms sharing a wall) are not shells by themselves:
        # re-winding one of them would make volume; the shells are the components joined across every edge
        count, label = _edge_connected(faces)
        vol = np.bincount(label, weights=det, minlength=count)
    noise = np.bincount(label, weights=scale, minlength=count)
    flat = np.abs(vol) <= 64 * EPS * noise  # a shell of zero volume: no orientation makes it a body
    if count == 1:  # one shell once the non-manifold splits are joined
        return (faces[:, [0, 2, 1]], [INVERTED]) if total < 0 else (faces, [])
    if bool(np.all((vol > 0) | flat)):
        # every shell encloses positive volume as the file winds it: the file says each is a solid (one inside
        # another is a second body there, not a cavity), as when all its faces see the local origin from outside;
        # nesting decides only where the file's windings disagree with each other
        return faces, _overlap_note(vertices - local_origin(vertices), faces, label, ~flat)
    shifted = vertices - local_origin(vertices)  # formed again: not held above
    depth = _nesting_depth(shifted, faces, label, count)
    if isinstance(depth, str):  # nesting undecidable: keep the file's orientation
        if total < 0 and np.all(vol <= 0):
            return faces[:, [0, 2, 1]], [INVERTED]
        return faces, [
            f"the {count} shells are kept as the file winds them ({depth}, so nesting was not tested); "
            f"{int(np.count_nonzero(vol < 0))} of them enclose negative volume (cavities)"
        ]
    found = _crossing_shell(shifted, faces, label, count, depth, every=True)
    del shifted
    want_positive = depth % 2 == 0
    if found is not None:
        crossing, crosses = found
        disagree = ((vol > 0) != want_positive) & ~flat & ~crosses
        if not np.any(disagree) and np.all(vol[crosses & ~flat] > 0):
            # the file winds every other shell as its nesting says (bodies outward, cavities inward) and the
            # crossing ones outward: its signed volumes are a reading, bodies overlapping where they cross
            return faces, [
                f"the mesh has {int(np.count_nonzero(crosses))} shell(s) wound outward that lie partly inside another "
                f"of its {count} shells: every shell is weighed as the file winds it (cavities subtracted, bodies added), so the "
                "volume the crossing ones share counts once for each (as trimesh and MuJoCo read the file); if the "
                "part is their union, join them into one closed surface (a boolean union) or send them as separate parts"
            ]
        raise InvalidMeshError(
            f"the mesh's shells cross each other: a shell of {crossing[0]} faces lies partly inside and partly "
            f"outside another (its largest face inside {crossing[1]} other shell(s), one of its vertices inside "
            f"{crossing[2]}), so it is neither a cavity nor a body of its own and its winding defines no volume; "
            "join the shells into one closed surface (a boolean union) or send them as separate parts",
            faces=crossing[0],
        )
    flip_shell = ((vol > 0) != want_positive) & ~flat
    if not np.any(flip_shell):
        return faces, []
    out = faces.copy()
    sel = flip_shell[label]
    out[sel] = out[sel][:, [0, 2, 1]]
    if np.all(flip_shell | flat):
        return out, [INVERTED]
    return out, [
        f"winding corrected on {int(flip_shell.sum())} of {count} shells by their nesting "
        "(a shell inside an odd number of others is a cavity)"
    ]


def _overlap_note(
    x: NDArray[np.float64], faces: NDArray[np.int64], label: NDArray[np.int64], solid: NDArray[np.bool_]
) -> list[str]:
    """A warning where shells that all wind outward share volume, else nothing.

    Each such shell is weighed as a solid of its own, so the volume two of them share counts twice: the
    sum of the signed volumes, as trimesh, numpy-stl and MuJoCo read the file; the part may be their
    union (a CAD export of touching bodies), which the file does not say.  Shared volume is seen where
    two shells have a face in common (a body stored twice), a vertex of one lies inside another, or an
    edge of one passes through a face of another (two bars laid across as a plus sign, neither with a
    vertex inside the other: ``_edges_cross``).  ``solid``: the shells that enclose volume (flat ones add
    none).  Beyond the tests' work limits nothing is said.
    """
    kept = np.flatnonzero(solid)
    if len(kept) < 2:
        return []
    renumber = np.full(len(solid), -1, dtype=np.int64)
    renumber[kept] = np.arange(len(kept))
    chosen = renumber[label] >= 0
    faces, label = faces[chosen], renumber[label[chosen]]
    count = len(kept)
    # after the weld a face stored twice has the same three vertices (row_ids: 0.06 s at 1e6 faces where
    # np.unique's row mode takes 1 s)
    corners = np.ascontiguousarray(np.sort(faces, axis=1)).astype(np.uint64)
    stored_twice = len(row_ids(corners)[1]) < len(corners)
    # a vertex of one shell clearly inside another (winding number not 0) is volume the two share: with
    # every depth taken as 0, the crossing test looks for exactly that (vertices on another shell, where
    # shells merely touch, decide nothing)
    if (
        not stored_twice
        and _crossing_shell(x, faces, label, count, np.zeros(count, dtype=np.int64), _OVERLAP_SAMPLES) is None
        and not _edges_cross(x, faces, label, count)
    ):
        return []
    return [
        f"the mesh's {count} shells all wind outward and overlap (some lie inside or across others): each is "
        "weighed as a solid of its own, so the volume they share counts once for each (as trimesh and MuJoCo "
        "read the file); if the part is their union, join them into one closed surface (a boolean union) or "
        "send them as separate parts"
    ]


_EDGE_CROSSING_WORK = 4_000_000  # edge-face pairs the overlap warning tests at most, ~1 s (beyond: nothing said)
_EDGE_CROSSING_BLOCK = 1 << 16  # pairs per block: ~30 MB of temporaries
# how clearly an edge must pass through a face, of the smaller shell's size: touching parts tessellated apart
# cut into each other by their chordal error (4 um of a 22 mm thumb link in unitree_ros, 1.9e-4), which
# shares no volume worth a word
_EDGE_CROSSING_MARGIN = 1e-3


def _edges_cross(x: NDArray[np.float64], faces: NDArray[np.int64], label: NDArray[np.int64], count: int) -> bool:
    """Whether an edge of one shell passes through a face of another, clearly: its ends on either side of
    the face's plane and the crossing inside the triangle, each by more than ``_EDGE_CROSSING_MARGIN`` of
    the smaller shell's size (shells that touch, face on face or along an edge, do not count).

    Two closed surfaces that cross have such an edge, of one or of the other: where two triangles cross,
    the ends of their common segment lie on their edges.  Only the edges and faces within both shells'
    boxes are paired, and at most ``_EDGE_CROSSING_WORK`` pairs in all (beyond, nothing is said).
    """
    order = np.argsort(label, kind="stable")
    bounds = np.searchsorted(label[order], np.arange(count + 1))
    lo, hi = _shell_boxes(x, faces, label, count)
    spent = 0
    for t, partners in _box_partners(lo, hi):
        if len(partners) == 0:
            continue
        lo_e, hi_e, _, _ = _undirected_edges(faces[order[bounds[t] : bounds[t + 1]]])
        keys = np.unique(lo_e * len(x) + hi_e)  # each edge once (both its faces list it)
        p, q = x[keys // len(x)], x[keys % len(x)]
        for other in partners.tolist():
            box_lo, box_hi = np.maximum(lo[t], lo[other]), np.minimum(hi[t], hi[other])
            near = np.all((np.minimum(p, q) <= box_hi) & (np.maximum(p, q) >= box_lo), axis=1)
            tri = faces[order[bounds[other] : bounds[other + 1]]]
            a, b, c = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
            inside = np.all((np.minimum(np.minimum(a, b), c) <= box_hi) & (np.maximum(np.maximum(a, b), c) >= box_lo), axis=1)
            n_edges, n_faces = int(near.sum()), int(inside.sum())
            spent += n_edges * n_faces + len(p) + len(tri)  # the pairs, and the selection itself
            if spent > _EDGE_CROSSING_WORK:
                return False
            if n_edges == 0 or n_faces == 0:
                continue
            margin = _EDGE_CROSSING_MARGIN * float(min(np.max(hi[t] - lo[t]), np.max(hi[other] - lo[other])))
            if _segments_pierce(p[near], q[near], a[inside], b[inside], c[inside], margin):
                return True
    return False


def _segments_pierce(
    p: NDArray[np.float64],
    q: NDArray[np.float64],
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    c: NDArray[np.float64],
    margin: float,
) -> bool:
    """Whether any segment pq passes through any triangle abc by more than ``margin`` (every pair, in blocks)."""
    step = max(1, _EDGE_CROSSING_BLOCK // len(a))
    normal = np.cross(b - a, c - a)
    size = np.linalg.norm(normal, axis=1)
    flat = size == 0.0
    unit = normal / np.where(flat, 1.0, size)[:, None]
    sides = [(a, b), (b, c), (c, a)]
    # each side's inward normal within the triangle's plane, unit length: distances of a point from the sides
    inward = []
    for u, v in sides:
        d = np.cross(unit, v - u)
        length = np.linalg.norm(d, axis=1)
        inward.append(d / np.where(length == 0.0, 1.0, length)[:, None])
    for start in range(0, len(p), step):
        ps, qs = p[start : start + step, None, :], q[start : start + step, None, :]
        dp = np.einsum("ijk,jk->ij", ps - a[None], unit)
        dq = np.einsum("ijk,jk->ij", qs - a[None], unit)
        across = ((dp > margin) & (dq < -margin)) | ((dp < -margin) & (dq > margin))
        across &= ~flat[None, :]
        if not np.any(across):
            continue
        i, j = np.nonzero(across)
        t = dp[i, j] / (dp[i, j] - dq[i, j])
        hit = p[start + i] + t[:, None] * (q[start + i] - p[start + i])
        clear = np.ones(len(i), dtype=bool)
        for (u, _), w in zip(sides, inward, strict=True):
            clear &= np.einsum("ij,ij->i", hit - u[j], w[j]) > margin
        if np.any(clear):
            return True
    return False


def _undirected_edges(
    faces: NDArray[np.int64],
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """Every face's three edges: lower vertex, higher vertex, +1/-1 for the face's direction, face number."""
    a = faces.ravel()
    b = faces[:, [1, 2, 0]].ravel()
    return np.minimum(a, b), np.maximum(a, b), np.where(a < b, 1, -1), np.repeat(np.arange(len(faces)), 3)


def _each_closed(faces: NDArray[np.int64], label: NDArray[np.int64]) -> bool:
    """Whether every component is closed by itself: each of its edges crossed as often one way as the other."""
    lo, hi, sign, face = _undirected_edges(faces)
    comp = label[face]
    order = np.lexsort((hi, lo, comp))
    lo, hi, comp, sign = lo[order], hi[order], comp[order], sign[order]
    starts = np.flatnonzero(np.r_[True, (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1]) | (comp[1:] != comp[:-1])])
    return bool(np.all(np.add.reduceat(sign, starts) == 0))


def _edge_connected(faces: NDArray[np.int64]) -> tuple[int, NDArray[np.int64]]:
    """Components of faces joined across every shared edge, manifold or not (each is closed when the surface is)."""
    lo, hi, _, face = _undirected_edges(faces)
    order = np.lexsort((hi, lo))
    lo, hi, face = lo[order], hi[order], face[order]
    same = (lo[1:] == lo[:-1]) & (hi[1:] == hi[:-1])
    return _components(len(faces), face[:-1][same], face[1:][same])


def winding_numbers(x: NDArray[np.float64], faces: NDArray[np.int64], points: NDArray[np.float64]) -> NDArray[np.float64]:
    """Generalised winding number of the triangles ``faces`` at each of ``points``.

    The sum of the signed solid angles of the triangles seen from the point
    over 4 pi (van Oosterom & Strackee 1983: tan(Omega/2) = a.(b x c) /
    (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|)); an integer for a closed
    surface and a point off it; NaN for a point on (or within 1e-12 of the
    size of) one of the triangles, where it is undefined.  Evaluated in blocks of points x faces of at
    most ``_WINDING_BLOCK`` pairs.
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    out = np.zeros(len(points))
    tri = [x[faces[:, k]] for k in range(3)]
    step = max(1, _WINDING_BLOCK // max(1, len(points)))
    for start in range(0, len(faces), step):
        a, b, c = (t[None, start : start + step, :] - points[:, None, :] for t in tri)
        la, lb, lc = (np.sqrt(np.einsum("pfi,pfi->pf", v, v)) for v in (a, b, c))
        num = np.einsum("pfi,pfi->pf", a, np.cross(b, c))
        den = (
            la * lb * lc
            + np.einsum("pfi,pfi->pf", a, b) * lc
            + np.einsum("pfi,pfi->pf", a, c) * lb
            + np.einsum("pfi,pfi->pf", b, c) * la
        )
        out += np.arctan2(num, den).sum(axis=1)
        scale = la * lb * lc
        on = (np.abs(num) <= 1e-12 * scale) & (den <= 1e-12 * scale)  # in a triangle's plane and inside it
        out[np.any(on, axis=1)] = np.nan
    return out / (2 * np.pi)


_WINDING_BLOCK = 1 << 18  # point-face pairs per block: ~50 MB of temporaries
NESTING_WORK_LIMIT = 400_000_000
"""Most point-triangle pairs the nesting test evaluates (a few seconds); past it, shells keep their stored orientation
with a warning rather than the request stalling (a part with many thousands of cavities inside a fine outer skin)."""


def _nesting_depth(
    x: NDArray[np.float64], faces: NDArray[np.int64], label: NDArray[np.int64], count: int
) -> NDArray[np.int64] | str:
    """How many other shells contain each shell, or why that cannot be decided.

    A shell's test point is the centroid of its largest triangle; only shells
    whose bounding box holds that point are evaluated.
    """
    lo, hi = _shell_boxes(x, faces, label, count)
    tri = x[faces]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    by_shell = np.lexsort((-area, label))  # per shell, its faces from the largest down
    order = np.argsort(label, kind="stable")
    bounds = np.searchsorted(label[order], np.arange(count + 1))
    sizes = np.diff(bounds)
    depth = np.zeros(count, dtype=np.int64)
    todo = np.arange(count)
    spent = 0
    for attempt in range(_NESTING_ATTEMPTS):  # a test point on another shell: try the shell's next largest face
        todo = todo[sizes[todo] > attempt]
        if len(todo) == 0:
            return depth
        points = tri[by_shell[bounds[todo] + attempt]].mean(axis=1)
        inside = [np.flatnonzero(np.all(lo[t] <= points, axis=1) & np.all(hi[t] >= points, axis=1)) for t in range(count)]
        inside = [i[todo[i] != t] for t, i in enumerate(inside)]
        spent += sum(len(i) * int(sizes[t]) for t, i in enumerate(inside))
        if spent > NESTING_WORK_LIMIT:
            return f"{spent:.2g} point-triangle tests would be needed"
        found = np.zeros(len(todo), dtype=np.int64)
        unclear = np.zeros(len(todo), dtype=bool)
        for t, i in enumerate(inside):
            if len(i) == 0:
                continue
            w = winding_numbers(x, faces[order[bounds[t] : bounds[t + 1]]], points[i])
            bad = ~(np.abs(w - np.round(w)) <= 0.25)  # NaN (on the shell) or far from an integer
            unclear[i[bad]] = True
            found[i[~bad]] += np.round(w[~bad]) != 0
        depth[todo[~unclear]] = found[~unclear]
        todo = todo[unclear]
        if len(todo) == 0:
            return depth
    return "shells touch or overlap"


def _shell_boxes(
    x: NDArray[np.float64], faces: NDArray[np.int64], label: NDArray[np.int64], count: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Each shell's bounding box: (count, 3) lower and upper corners."""
    lo = np.full((count, 3), np.inf)
    hi = np.full((count, 3), -np.inf)
    for k in range(3):
        for corner in range(3):
            coord = x[faces[:, corner], k]
            np.minimum.at(lo[:, k], label, coord)
            np.maximum.at(hi[:, k], label, coord)
    return lo, hi


def _box_partners(lo: NDArray[np.float64], hi: NDArray[np.float64], rows: int = 256) -> Iterator[tuple[int, NDArray[np.int64]]]:
    """Each shell with the other shells whose bounding boxes meet its own.

    The shells are swept in order of their boxes' lower x, a block of ``rows`` at a time against the
    shells whose x ranges reach the block's: disjoint shells (a part library's thousand screws) cost a
    sort, not every pair.
    """
    order = np.argsort(lo[:, 0], kind="stable")
    lo_s, hi_s = lo[order], hi[order]
    for start in range(0, len(lo), rows):
        block = slice(start, start + rows)
        stop = int(np.searchsorted(lo_s[:, 0], hi_s[block, 0].max(), side="right"))
        reach = np.flatnonzero(hi_s[:stop, 0] >= lo_s[block, 0].min())
        meets = np.all((lo_s[block, None, :] <= hi_s[None, reach, :]) & (hi_s[block, None, :] >= lo_s[None, reach, :]), axis=2)
        for r, row in enumerate(meets):
            t = int(order[start + r])
            found = order[reach[row]]
            yield t, found[found != t]


_NESTING_ATTEMPTS = 4
_CROSSING_SAMPLES = 24  # vertices of each nested shell tested against the shells around it
_OVERLAP_SAMPLES = 256  # vertices of each outward shell tested for lying inside another (a warning, not a refusal)


def _crossing_shell(
    x: NDArray[np.float64],
    faces: NDArray[np.int64],
    label: NDArray[np.int64],
    count: int,
    depth: NDArray[np.int64],
    samples: int = _CROSSING_SAMPLES,
    every: bool = False,
) -> tuple[tuple[int, int, int], NDArray[np.bool_]] | None:
    """A shell whose vertices are not all as deep as its test point: (its faces, its depth, a vertex's depth),
    and which shells were found crossing (all of them with ``every``, else the first); None where none is.

    The depth of a shell comes from one point of it; a shell lies wholly inside the shells around it (or
    wholly outside them) only if it crosses none of them, which a few of its vertices (its extremes along
    each axis, and an even spread of the rest) show: a vertex clearly inside a different number of shells
    means they cross. Vertices on another shell (touching shells) decide nothing. Only the shells whose
    bounding boxes hold such a vertex are evaluated, within the nesting test's work limit (beyond it
    nothing is refused).
    """
    order = np.argsort(label, kind="stable")
    bounds = np.searchsorted(label[order], np.arange(count + 1))
    lo, hi = _shell_boxes(x, faces, label, count)
    sizes = np.diff(bounds)
    spent = 0
    first: tuple[int, int, int] | None = None
    crossing = np.zeros(count, dtype=bool)
    for t, partners in _box_partners(lo, hi):
        if len(partners) == 0:
            continue  # no other shell's box meets this one's: nothing to cross
        used = np.unique(faces[order[bounds[t] : bounds[t + 1]]])
        ends = np.concatenate([used[np.argmin(x[used], axis=0)], used[np.argmax(x[used], axis=0)]])
        spread = used[np.linspace(0, len(used) - 1, min(len(used), samples - len(ends))).astype(np.int64)]
        points = x[np.unique(np.concatenate([ends, spread]))]
        # the partners whose boxes hold each point, all at once (points x partners)
        held = (lo[partners][None, :, :] <= points[:, None, :]) & (hi[partners][None, :, :] >= points[:, None, :])
        near = np.zeros((len(points), count), dtype=bool)
        near[:, partners] = np.all(held, axis=2)
        per_shell = near.sum(axis=0)
        others = np.flatnonzero(per_shell)
        if len(others) == 0:
            continue
        spent += int(per_shell[others] @ sizes[others])
        if spent > NESTING_WORK_LIMIT:
            return None  # beyond the work limit nothing is said, not even what was found
        found = np.zeros(len(points), dtype=np.int64)
        decided = np.ones(len(points), dtype=bool)
        for other in others.tolist():
            inside = np.flatnonzero(near[:, other])
            w = winding_numbers(x, faces[order[bounds[other] : bounds[other + 1]]], points[inside])
            clear = np.abs(w - np.round(w)) <= 0.25  # NaN (on the other shell) is not clear
            decided[inside[~clear]] = False
            found[inside[clear]] += np.round(w[clear]) != 0
        wrong = decided & (found != depth[t])
        if np.any(wrong):
            crossing[t] = True
            if first is None:
                first = int(sizes[t]), int(depth[t]), int(found[np.flatnonzero(wrong)[0]])
            if not every:
                break
    return None if first is None else (first, crossing)
