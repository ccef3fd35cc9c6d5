"""Seams: one point written twice with different rounding, and parts that close only together.

CAD exporters write each face of a B-rep as its own triangle patch, and the
vertices on the edge two patches share are computed twice: ``0.0`` in one
triangle, ``-2.7e-16`` in the next.  Bit-exact welding (``topology.weld``)
leaves such a seam open.  Here the vertices that lie on open edges and are
closer than ``Tolerances.seam_rel`` times the part's bounding-box diagonal
(in a file of float32 coordinates, ``SEAM_STEPS`` of their steps, which
their rounding alone can put between two writings of one point) are merged
onto one of them (the lowest-numbered), unless the merge would
collapse a triangle (two corners of one face in one cluster), in which case
that cluster is not merged at all.  The merged polyhedron is a polyhedron in
its own right, with the coordinates of the kept vertices, and every integral
of it is exact; what moved, and by how much at most, is reported.

A surface may also be closed as drawn but not along its edges: a corner of
one face lies in the middle of its neighbour's side (a T-junction), so the
neighbour's long edge and the two short ones beside it are each used once.
``close_t_junctions`` closes such a surface with flat slivers when every open
edge is matched that way, and with nothing else.

A file may also split one closed surface into parts that are open each (OBJ
``g``/``o`` groups, glTF primitives): ``join_open_parts`` finds the sets of
open parts that share their open edges and whose union is closed, and makes
each such set one body.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .body import MeshBody, Part
from .tolerances import DEFAULT_TOLERANCES, Tolerances
from .topology import face_components, surface_topology, weld

__all__ = [
    "SEAM_STEPS",
    "SeamMerge",
    "TJunctions",
    "close_pairs",
    "close_t_junctions",
    "join_open_parts",
    "merge_seams",
    "open_edge_vertices",
]


@dataclass(frozen=True, slots=True)
class SeamMerge:
    """The outcome of ``merge_seams``.

    faces : the faces re-indexed onto the kept vertices (vertices are unchanged).
    merged : how many vertices were moved onto another one.
    largest_gap : the largest distance from a moved vertex to the vertex it
        was merged onto [file units].
    tolerance : the merge distance used [file units].
    refused : clusters not merged because a triangle would have collapsed.
    """

    faces: NDArray[np.int64]
    merged: int
    largest_gap: float
    tolerance: float
    refused: int
    basis: str = "1e-12 of the part's size"

    def warning(self) -> str:
        text = (
            f"{self.merged} seam vertices merged onto a neighbour closer than {self.tolerance:.3g} "
            f"({self.basis}; largest gap {self.largest_gap:.3g} file units); "
            "the results are exact for the merged surface"
        )
        if self.refused:
            text += f"; {self.refused} closer groups were left apart because merging them would collapse a triangle"
        return text


def open_edge_vertices(faces: NDArray[np.int64]) -> NDArray[np.int64]:
    """Indices of the vertices on edges used by exactly one face."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    n = int(faces.max()) + 1 if len(faces) else 1
    keys = np.sort(edges[:, 0] * n + edges[:, 1])  # one integer per edge: a 1-D sort
    once = keys[_single(keys)]
    return _distinct(np.concatenate([once // n, once % n]), n)


def _distinct(indices: NDArray[np.int64], n: int) -> NDArray[np.int64]:
    """The distinct values of ``indices`` (all in 0..n-1), in increasing order: ``np.unique`` by a mask of
    n flags, without a sort (numpy's ``unique`` sorted or hashed each part's millions of indices)."""
    seen = np.zeros(n, dtype=bool)
    seen[indices] = True
    return np.flatnonzero(seen)


def _single(ordered: NDArray[np.int64]) -> NDArray[np.bool_]:
    """Which entries of a sorted array occur once (a sort and two comparisons: numpy's ``unique`` with counts
    hashes, several times slower on millions of edges)."""
    repeat = ordered[1:] == ordered[:-1]
    single = np.ones(len(ordered), dtype=bool)
    single[1:] &= ~repeat
    single[:-1] &= ~repeat
    return single


_SWEEP = np.array([0.8017837257372732, 0.5345224838248488, 0.2672612419124244])  # (3, 2, 1)/sqrt(14)


def close_pairs(points: NDArray[np.float64], tol: float) -> NDArray[np.int64]:
    """Index pairs (i < j) of points at most ``tol`` apart: a sweep along one oblique direction.

    Points closer than ``tol`` are closer than ``tol`` along any direction, so
    after sorting by the projection only neighbours within ``tol`` of it need
    a full test; an oblique direction keeps the grid-aligned vertices of CAD
    parts from sharing one projection.  No spatial index (and no scipy import)
    is needed for the common case of no close pair at all.
    """
    proj = points @ _SWEEP
    order = np.argsort(proj, kind="stable")
    ps, xs = proj[order], points[order]
    found: list[NDArray[np.int64]] = []
    k = 1
    while k < len(ps):
        near = np.flatnonzero(ps[k:] - ps[:-k] <= tol)
        if len(near) == 0:
            break
        d = np.linalg.norm(xs[near + k] - xs[near], axis=1)
        hit = near[d <= tol]
        if len(hit):
            found.append(np.stack([order[hit], order[hit + k]], axis=1))
        k += 1
    if not found:
        return np.empty((0, 2), dtype=np.int64)
    pairs = np.concatenate(found)
    return np.sort(pairs, axis=1)


SEAM_STEPS = 8
"""In a file of float32 coordinates a point written twice is apart by a few of their steps (one step is
2**-24 of the largest coordinate): seams within this many steps are merged too."""


def merge_seams(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    tolerances: Tolerances = DEFAULT_TOLERANCES,
    coordinate_eps: float = 2.0**-53,
) -> SeamMerge:
    """Merge the vertices of open edges that are closer than the seam tolerance.

    ``vertices`` must already be bit-exactly welded (distinct rows) and
    ``faces`` free of degenerate triangles.  ``coordinate_eps``: the unit
    roundoff of the file's coordinates (``MeshBody.coordinate_eps``); for
    float32 ones the tolerance is at least ``SEAM_STEPS`` of their steps at
    the largest coordinate, the gap their rounding leaves between two writings
    of one point (1e-12 of the size is below a single step there).
    """
    used = vertices[_distinct(faces.ravel(), len(vertices))]
    diagonal = float(np.linalg.norm(used.max(axis=0) - used.min(axis=0)))
    tol, basis = tolerances.seam_rel * diagonal, "1e-12 of the part's size"
    if coordinate_eps >= 2.0**-24:
        steps = SEAM_STEPS * coordinate_eps * float(np.abs(used).max())
        if steps > tol:
            tol, basis = steps, f"{SEAM_STEPS} steps of the file's float32 coordinates at their largest"
    candidates = open_edge_vertices(faces)
    none = SeamMerge(faces, 0, 0.0, tol, 0, basis)
    if len(candidates) < 2 or tol <= 0:
        return none
    pts = vertices[candidates]
    pairs = close_pairs(pts, tol)
    if len(pairs) == 0:
        return none
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(candidates)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    # representative of each cluster: its lowest-numbered vertex (candidates are sorted)
    first = np.full(label.max() + 1, n, dtype=np.int64)
    np.minimum.at(first, label, np.arange(n))
    target = np.arange(len(vertices), dtype=np.int64)
    target[candidates] = candidates[first[label]]
    cluster_of = np.full(len(vertices), -1, dtype=np.int64)
    cluster_of[candidates] = label
    mapped = target[faces]
    collapsed = (mapped[:, 0] == mapped[:, 1]) | (mapped[:, 1] == mapped[:, 2]) | (mapped[:, 0] == mapped[:, 2])
    refused_clusters = np.unique(cluster_of[faces[collapsed]])
    refused_clusters = refused_clusters[refused_clusters >= 0]
    refused_clusters = refused_clusters[np.bincount(label)[refused_clusters] > 1]
    if len(refused_clusters):
        undo = np.isin(label, refused_clusters)
        target[candidates[undo]] = candidates[undo]
        mapped = target[faces]  # undoing merges can only remove collapses, never create one
    moved = np.flatnonzero(target != np.arange(len(vertices)))
    if len(moved) == 0:
        return SeamMerge(faces, 0, 0.0, tol, len(refused_clusters), basis)
    gap = float(np.max(np.linalg.norm(vertices[moved] - vertices[target[moved]], axis=1)))
    return SeamMerge(mapped, len(moved), gap, tol, len(refused_clusters), basis)


def _welded_faces(vertices: NDArray[np.float64], faces: NDArray[np.int64]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    vertices, faces = weld(vertices, faces)
    good = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    return vertices, faces[good]


def _closed_after_seams(
    vertices: NDArray[np.float64], faces: NDArray[np.int64], tolerances: Tolerances
) -> tuple[bool, NDArray[np.int64]]:
    topo = surface_topology(faces, len(vertices))
    if topo.open_edges:
        faces = merge_seams(vertices, faces, tolerances).faces
        topo = surface_topology(faces, len(vertices))
    return topo.open_edges == 0, faces


def join_open_parts(parts: list[Part], tolerances: Tolerances = DEFAULT_TOLERANCES) -> tuple[list[Part], list[str]]:
    """Join open surface parts that together bound a closed surface.

    Parts that are closed on their own, and open parts whose neighbours do not
    close them, are returned as they are (an open part is then refused, by
    name, when it is integrated).  Each set of open parts that shares its open
    edges and is closed as a whole becomes one part named ``a+b+...``, with
    a warning: the parts' own mass properties are not defined (an open
    surface bounds no volume), only the whole's.
    """
    meshes = [(i, p) for i, p in enumerate(parts) if isinstance(p.body, MeshBody)]
    if len(meshes) < 2:
        return parts, []
    open_ids: list[int] = []
    for i, part in meshes:
        assert isinstance(part.body, MeshBody)
        v, f = _welded_faces(part.body.vertices, part.body.faces)
        if len(f) and not _closed_after_seams(v, f, tolerances)[0]:
            open_ids.append(i)
    if len(open_ids) < 2:
        return parts, []
    bodies = [parts[i].body for i in open_ids]
    scales = {b.length_scale for b in bodies}
    if len(scales) != 1:
        return parts, []
    all_v = np.concatenate([b.vertices for b in bodies if isinstance(b, MeshBody)])
    offsets = np.cumsum([0, *[len(b.vertices) for b in bodies if isinstance(b, MeshBody)][:-1]])
    all_f = np.concatenate([b.faces + off for b, off in zip(bodies, offsets) if isinstance(b, MeshBody)])
    owner = np.repeat(np.arange(len(bodies)), [len(b.faces) for b in bodies if isinstance(b, MeshBody)])
    v, f = weld(all_v, all_f)
    good = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
    f, owner = f[good], owner[good]
    f = merge_seams(v, f, tolerances).faces
    topo = surface_topology(f, len(v))
    _, comp = face_components(f, topo)
    # parts linked when they share a face component (i.e. a manifold edge)
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    k = len(bodies)
    n_comp = int(comp.max()) + 1
    links = np.unique(owner * n_comp + comp)  # one key per (part, component), sorted as integers (rows would be slow)
    size = k + n_comp
    graph = coo_matrix((np.ones(len(links)), (links // n_comp, links % n_comp + k)), shape=(size, size))
    _, group = connected_components(graph, directed=False)
    part_group = group[:k]
    joined: dict[int, Part] = {}
    drop: set[int] = set()
    warnings: list[str] = []
    for g in np.unique(part_group):
        members = np.flatnonzero(part_group == g)
        if len(members) < 2:
            continue
        sel = np.isin(owner, members)
        sub = f[sel]
        if surface_topology(sub, len(v)).open_edges:
            continue
        names = [parts[open_ids[m]].name for m in members]
        name = "+".join(names) if len(names) <= 4 else f"{names[0]}+{len(names) - 1} more"
        listed = ", ".join(repr(n) for n in names[:8]) + (f" and {len(names) - 8} more" if len(names) > 8 else "")
        note = (
            f"{len(names)} parts ({listed}) are open each but close together; "
            f"analysed as one body {name!r} (an open part bounds no volume of its own)"
        )
        member_bodies = [bodies[m] for m in members]
        body = MeshBody(
            np.concatenate([b.vertices for b in member_bodies if isinstance(b, MeshBody)]),
            np.concatenate(
                [
                    b.faces + off
                    for b, off in zip(
                        member_bodies, np.cumsum([0, *[len(b.vertices) for b in member_bodies if isinstance(b, MeshBody)][:-1]])
                    )
                    if isinstance(b, MeshBody)
                ]
            ),
            scales.copy().pop(),
            name,
            (*(w for b in member_bodies for w in b.warnings), note),
            assumed_error=max(b.assumed_error for b in member_bodies if isinstance(b, MeshBody)),
        )
        joined[open_ids[members[0]]] = Part(name, body)
        drop.update(open_ids[m] for m in members[1:])
        warnings.append(note)
    if not joined:
        return parts, []
    out = [joined.get(i, p) for i, p in enumerate(parts) if i not in drop]
    return out, warnings


@dataclass(frozen=True, slots=True)
class TJunctions:
    """The outcome of ``close_t_junctions``.

    faces : the faces with the slivers appended (vertices are unchanged).
    vertices_on_edges : how many times a vertex was found inside another face's edge.
    largest_offset : the largest distance of such a vertex from the edge, over the edge's length.
    """

    faces: NDArray[np.int64]
    vertices_on_edges: int
    largest_offset: float

    def warning(self) -> str:
        offset = "exactly on it" if self.largest_offset == 0 else f"at most {self.largest_offset:.2g} of its length off it"
        return (
            f"{self.vertices_on_edges} T-junction(s) closed: a corner of one face lies in the middle of its neighbour's "
            f"edge ({offset}), which left the surface open along those edges though it is closed as drawn; each was "
            "closed with a flat sliver, and the results are those of the closed surface"
        )


_T_PAIRS_MAX = 10_000_000  # (open edge, vertex) candidate pairs (three int64 arrays of them); beyond, refused as open
_T_CHUNK = 1 << 20  # pairs tested at a time


def close_t_junctions(
    vertices: NDArray[np.float64], faces: NDArray[np.int64], tolerances: Tolerances = DEFAULT_TOLERANCES
) -> TJunctions | None:
    """Close a surface whose only open edges meet at T-junctions; None where any open edge is left unmatched.

    Each open edge a -> b is split at the vertices of open edges that lie on it (within
    ``Tolerances.t_junction_rel`` of its length, and that far from both ends), in order along it.  If the
    pieces of all open edges then pair up, each u -> v with a v -> u, the surface is closed as drawn, and
    the fan (b, a, t1), (b, t1, t2), ... of each split edge closes it along its edges too: the first sliver
    pairs with a -> b, and the pieces' partners, b -> tk, ..., t1 -> a, pair with the fan's outer edges.
    """
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    n = len(vertices)
    undirected = np.minimum(directed[:, 0], directed[:, 1]) * n + np.maximum(directed[:, 0], directed[:, 1])
    order = np.argsort(undirected)
    edges = directed[order[_single(undirected[order])]]
    if len(edges) == 0:
        return None
    points = _distinct(edges.ravel(), n)
    tol = tolerances.t_junction_rel
    a, b = vertices[edges[:, 0]], vertices[edges[:, 1]]
    along = b - a
    length2 = np.einsum("ij,ij->i", along, along)
    # candidates by a sweep along one oblique direction: a point on an edge projects between its ends' projections
    # (widened by the tolerance), so each edge tests only the points of that slice, found by binary search
    proj = vertices[points] @ _SWEEP
    order = np.argsort(proj, kind="stable")
    ranked = proj[order]
    pa, pb = a @ _SWEEP, b @ _SWEEP
    slack = tol * np.sqrt(length2)
    first = np.searchsorted(ranked, np.minimum(pa, pb) - slack, side="left")
    last = np.searchsorted(ranked, np.maximum(pa, pb) + slack, side="right")
    sizes = last - first
    if int(sizes.sum()) > _T_PAIRS_MAX:
        return None
    edge_of = np.repeat(np.arange(len(edges)), sizes)
    rank = np.arange(len(edge_of)) - np.repeat(np.cumsum(sizes) - sizes, sizes) + np.repeat(first, sizes)
    point_of = points[order[rank]]
    hits: list[tuple[int, int, float, float]] = []  # (edge, vertex, position along it, offset over its length)
    for start in range(0, len(edge_of), _T_CHUNK):
        ei, pi = edge_of[start : start + _T_CHUNK], point_of[start : start + _T_CHUNK]
        rel = vertices[pi] - a[ei]
        s_ep = np.einsum("ij,ij->i", rel, along[ei]) / length2[ei]
        off2 = np.einsum("ij,ij->i", rel, rel) / length2[ei] - s_ep * s_ep
        on = (s_ep > tol) & (s_ep < 1 - tol) & (off2 <= tol * tol) & (pi != edges[ei, 0]) & (pi != edges[ei, 1])
        for k in np.flatnonzero(on):
            hits.append((int(ei[k]), int(pi[k]), float(s_ep[k]), float(np.sqrt(max(off2[k], 0.0)))))
    if not hits:
        return None
    inner: dict[int, list[tuple[float, int]]] = {}
    for e, p, s_ep, _ in hits:
        inner.setdefault(e, []).append((s_ep, p))
    pieces: list[tuple[int, int]] = []
    slivers: list[tuple[int, int, int]] = []
    for e, (u, v) in enumerate(edges.tolist()):
        chain = [u, *(p for _, p in sorted(inner.get(e, []))), v]
        pieces += list(itertools.pairwise(chain))
        slivers += [(v, chain[k], chain[k + 1]) for k in range(len(chain) - 2)]
    forward = np.array([u * n + v for u, v in pieces], dtype=np.int64)
    backward = np.array([v * n + u for u, v in pieces], dtype=np.int64)
    if not np.array_equal(np.sort(forward), np.sort(backward)):
        return None
    closed = np.concatenate([faces, np.array(slivers, dtype=faces.dtype).reshape(-1, 3)])
    return TJunctions(closed, len(hits), max(off for *_, off in hits))
