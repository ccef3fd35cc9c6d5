"""Topology of triangle surfaces: welding, closedness, winding.

A surface bounds a solid exactly when it is a closed, consistently oriented
2-chain: every undirected edge is traversed as often in one direction as in
the other.  Then the divergence theorem holds and the signed-tetrahedron
integrals in ``mass`` are exact.  Everything here is vectorised and
sort-based: one sort of the vertices (welding) and one of the edges.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .errors import NotWatertightError

__all__ = ["weld", "SurfaceTopology", "surface_topology", "orient_consistently"]


def weld(vertices: NDArray[np.float64], faces: NDArray[np.int64]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Merge vertices with bit-identical coordinates (-0.0 equals 0.0).

    Sorting the raw 24-byte rows would need a slow row-wise unique; instead
    the rows are hashed to uint64, sorted once, and runs of equal hash are
    checked for equal coordinates (a hash collision falls back to lexsort).
    """
    v = vertices + 0.0  # turns -0.0 into 0.0 so both weld together
    bits = np.ascontiguousarray(v).view(np.uint64).reshape(-1, 3)
    with np.errstate(over="ignore"):
        h = bits[:, 0] * np.uint64(0x9E3779B97F4A7C15)
        h ^= (h >> np.uint64(29)) + bits[:, 1] * np.uint64(0xBF58476D1CE4E5B9)
        h ^= (h >> np.uint64(31)) + bits[:, 2] * np.uint64(0x94D049BB133111EB)
    order = np.argsort(h, kind="stable")
    hs = h[order]
    vs = bits[order]
    same_hash = hs[1:] == hs[:-1]
    same_xyz = np.all(vs[1:] == vs[:-1], axis=1)
    if np.any(same_hash & ~same_xyz):
        order = np.lexsort((bits[:, 2], bits[:, 1], bits[:, 0]))
        vs = bits[order]
        same_xyz = np.all(vs[1:] == vs[:-1], axis=1)
    new_run = np.empty(len(v), dtype=bool)
    new_run[0] = True
    new_run[1:] = ~same_xyz
    ids_sorted = np.cumsum(new_run) - 1
    remap = np.empty(len(v), dtype=np.int64)
    remap[order] = ids_sorted
    unique_vertices = vertices[order[new_run]]
    return unique_vertices, remap[faces]


@dataclass(frozen=True, slots=True)
class SurfaceTopology:
    """Edge statistics of a welded surface.

    open_edges : undirected edges used by exactly one face.
    unbalanced_edges : edges traversed a different number of times in the two
        directions (open edges, or winding that disagrees across the edge).
    nonmanifold_edges : edges shared by more than two faces.
    """

    open_edges: int
    unbalanced_edges: int
    nonmanifold_edges: int
    edge_faces: NDArray[np.int64]  # (k, 2) pairs of faces sharing a manifold edge
    edge_same_direction: NDArray[np.bool_]  # (k,) the pair traverses the edge the same way

    @property
    def closed(self) -> bool:
        return self.unbalanced_edges == 0


def surface_topology(faces: NDArray[np.int64], n_vertices: int) -> SurfaceTopology:
    """Count open, unbalanced and non-manifold edges in one sort of the edges."""
    u = faces.reshape(-1)
    v = faces[:, [1, 2, 0]].reshape(-1)
    lo = np.minimum(u, v)
    hi = np.maximum(u, v)
    key = lo * np.int64(n_vertices) + hi
    forward = (u < v).astype(np.int64) * 2 - 1  # +1 if traversed lo->hi
    order = np.argsort(key, kind="stable")
    ks = key[order]
    starts = np.flatnonzero(np.r_[True, ks[1:] != ks[:-1]])
    counts = np.diff(np.r_[starts, len(ks)])
    balance = np.add.reduceat(forward[order], starts)
    face_of = order // 3
    pair = counts == 2
    first = starts[pair]
    edge_faces = np.stack([face_of[first], face_of[first + 1]], axis=1)
    same = balance[pair] != 0
    return SurfaceTopology(
        open_edges=int(np.count_nonzero(counts == 1)),
        unbalanced_edges=int(np.count_nonzero(balance != 0)),
        nonmanifold_edges=int(np.count_nonzero(counts > 2)),
        edge_faces=edge_faces,
        edge_same_direction=same,
    )


def orient_consistently(faces: NDArray[np.int64], topo: SurfaceTopology) -> tuple[NDArray[np.int64], int]:
    """Flip faces so that neighbours agree across every manifold edge.

    Works on the doubled graph (each face in both orientations): an edge that
    neighbours traverse the same way links opposite orientations.  A face
    whose two orientations fall in one component lies on a non-orientable
    surface.  Returns the re-wound faces and the number of flipped faces.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(faces)
    f1, f2 = topo.edge_faces[:, 0], topo.edge_faces[:, 1]
    flip = topo.edge_same_direction.astype(np.int64) * n
    rows = np.concatenate([f1, f1 + n])
    cols = np.concatenate([f2 + flip, f2 + n - flip])
    graph = coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(2 * n, 2 * n))
    _, label = connected_components(graph, directed=False)
    a, b = label[:n], label[n:]
    if np.any(a == b):
        raise NotWatertightError(
            "the surface is not orientable (a Moebius-like strip), so it does not bound a solid; "
            "repair the mesh or use model=shell",
            non_orientable_faces=int(np.count_nonzero(a == b)),
        )
    pair_id = np.minimum(a, b)
    # keep the orientation the lowest-numbered face of each component already has
    first_face = np.full(label.max() + 1, n, dtype=np.int64)
    np.minimum.at(first_face, pair_id, np.arange(n))
    keep = a[first_face[pair_id]]
    to_flip = a != keep
    out = faces.copy()
    out[to_flip] = out[to_flip][:, [0, 2, 1]]
    return out, int(np.count_nonzero(to_flip))


def face_components(faces: NDArray[np.int64], topo: SurfaceTopology) -> tuple[int, NDArray[np.int64]]:
    """Connected components of faces joined across manifold edges."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(faces)
    e = topo.edge_faces
    graph = coo_matrix((np.ones(len(e), dtype=np.int8), (e[:, 0], e[:, 1])), shape=(n, n))
    count, label = connected_components(graph, directed=False)
    return int(count), label.astype(np.int64)
