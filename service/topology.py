"""Topology of triangle surfaces: welding, closedness, winding.

A surface bounds a solid exactly when it is a closed, consistently oriented
2-chain: every undirected edge is traversed as often in one direction as in
the other.  Then the divergence theorem holds and the signed-tetrahedron
integrals in ``mass`` are exact.  Everything here is vectorised and
sort-based: one sort of the vertices (welding) and one of the edges.

Speed.  numpy sorts plain integers far faster than it argsorts them (a SIMD
value sort), so a sort that must also return the permutation packs the key
into the high bits of a uint64 and the element index into the low bits, and
sorts the values: equal keys come out in index order, as a stable argsort
would give them.  Connected components use vectorised union-find (hook each
root to the smaller one, then pointer jumping), so the common path needs no
scipy import.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .blocks import for_each_block
from .errors import NotWatertightError

__all__ = ["weld", "row_ids", "SurfaceTopology", "surface_topology", "orient_consistently", "face_components"]

_MIX = (np.uint64(0x9E3779B97F4A7C15), np.uint64(0xBF58476D1CE4E5B9), np.uint64(0x94D049BB133111EB))
MIN_HASH_BITS = 16  # below this many hash bits beside the index, collisions would dominate: argsort instead
SCATTER_CHUNK = 1 << 18  # rows per block when scattering ids back: bounds the temporaries to ~4 MB
BLOCK = 1 << 15  # elements per block of an element-wise chain: its temporaries (256 KB) stay in the cache


def weld(vertices: NDArray[np.float64], faces: NDArray[np.int64]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Merge vertices with bit-identical coordinates (-0.0 equals 0.0).

    Distinct vertices are numbered in order of first occurrence, so an
    already welded mesh comes back unchanged (the same arrays, no copy).
    """
    v = np.ascontiguousarray(vertices + 0.0)  # turns -0.0 into 0.0 so both weld together
    ids, heads = row_ids(v.view(np.uint64).reshape(-1, 3))
    if len(heads) == len(vertices):
        return vertices, faces  # every vertex distinct: ids is the identity
    return vertices[heads], ids[faces]


def row_ids(
    rows: NDArray[np.unsignedinteger] | Sequence[NDArray[np.unsignedinteger]],
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Group equal rows of integers exactly.

    ``rows`` is an (n, k) array (preferred: each row is gathered as one
    record) or a sequence of k columns of length n.  Returns ``ids`` (n,):
    the group of each row, numbered in order of first occurrence, and
    ``heads`` (k,): the first row of each group, ascending.  Rows are hashed
    to uint64 and sorted once; rows are then compared exactly, and a run of
    equal hash holding different rows (a collision) is re-sorted by the
    columns themselves, so distinct rows never merge.

    Cache.  In the hash order, neighbours are rows far apart in memory: the
    exact comparison gathers each row once, as one record of its k integers
    (one cache line), not each column separately (k misses per row), and the
    groups are numbered through flags indexed by row, not a second sort.
    Element-wise chains (hash, packing, comparisons) run in blocks of
    ``BLOCK`` rows so their temporaries stay in the cache.
    """
    table = _row_table(rows)
    columns = [table[:, j] for j in range(table.shape[1])]
    n = len(table)
    order, same_hash = _hash_order(_row_hash(columns))
    index: type[np.signedinteger] = np.int32 if n < 2**31 else np.int64
    order = order.astype(index, copy=False)  # half the memory of int64 while ids are built
    same = _equal_neighbours(table, order)
    collided = same_hash & ~same
    if np.any(collided):
        order = _resolve_collisions(table, order, same_hash, same)
    del same_hash, collided
    new = np.empty(n, dtype=bool)
    new[0] = True
    np.logical_not(same, out=new[1:])
    del same
    # runs keep index order, so the first row of each run is its group's smallest row
    firsts = order[np.flatnonzero(new)]  # hash-order group -> its first row
    is_head = np.zeros(n, dtype=bool)
    is_head[firsts] = True
    heads = np.flatnonzero(is_head)
    group_rank: NDArray[np.signedinteger] = np.cumsum(is_head, dtype=index)[firsts]
    group_rank -= 1  # hash-order group -> its number in order of first occurrence
    del is_head, firsts
    ids = np.empty(n, dtype=np.int64)
    starts = range(0, n, SCATTER_CHUNK)
    # groups that start before each block, so that the blocks are independent
    before = np.cumsum([0] + [np.count_nonzero(new[start : start + SCATTER_CHUNK]) for start in starts[:-1]])

    def scatter(start: int) -> None:
        stop = start + SCATTER_CHUNK
        group = np.cumsum(new[start:stop], dtype=index)  # hash-order group of each sorted row, less ``before``
        group += before[start // SCATTER_CHUNK] - 1
        ids[order[start:stop]] = group_rank[group]

    for_each_block(scatter, starts)
    return ids, heads


def _row_table(rows: NDArray[np.unsignedinteger] | Sequence[NDArray[np.unsignedinteger]]) -> NDArray[np.unsignedinteger]:
    """The rows as one C-contiguous (n, k) array (columns are stacked)."""
    if isinstance(rows, np.ndarray) and rows.ndim == 2:
        return np.ascontiguousarray(rows)
    return np.stack(list(rows), axis=1)


def _row_hash(columns: Sequence[NDArray[np.unsignedinteger]]) -> NDArray[np.uint64]:
    """A 64-bit hash of each row, well mixed in its high bits (multiply-xorshift), in blocks."""
    n = len(columns[0])
    h = np.empty(n, dtype=np.uint64)

    def block(start: int) -> None:
        stop = min(n, start + BLOCK)
        hb, t = h[start:stop], np.empty(stop - start, dtype=np.uint64)
        with np.errstate(over="ignore"):  # numpy's error state is per thread
            hb[...] = columns[0][start:stop]
            hb *= _MIX[0]
            for col in columns[1:]:
                np.right_shift(hb, np.uint64(31), out=t)
                hb ^= t
                t[...] = col[start:stop]
                hb += t
                hb *= _MIX[1]
            np.right_shift(hb, np.uint64(29), out=t)
            hb ^= t
            hb *= _MIX[2]
            np.right_shift(hb, np.uint64(32), out=t)
            hb ^= t

    for_each_block(block, range(0, n, BLOCK))
    return h


def _hash_order(h: NDArray[np.uint64]) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
    """Row order sorted by hash (ties by index) and whether neighbours share a hash.

    Consumes ``h``: only its top ``64 - index_bits`` bits are compared.
    """
    n = len(h)
    index_bits = max(1, (n - 1).bit_length())
    if 64 - index_bits < MIN_HASH_BITS:
        order = np.argsort(h, kind="stable")
        hs = h[order]
        return order, hs[1:] == hs[:-1]
    return _packed_sort(h, index_bits, shift=True)


def _packed_sort(key: NDArray[np.uint64], index_bits: int, shift: bool = False) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
    """Indices sorting ``key`` (< 2**(64 - index_bits)) stably, and equal-neighbour flags.

    With ``shift``, ``key`` is any uint64 and only its top ``64 - index_bits``
    bits are compared.  Consumes ``key``: it is packed and sorted in place.
    """
    n = len(key)
    low = np.uint64((1 << index_bits) - 1)
    bits = np.uint64(index_bits)

    def pack(start: int) -> None:
        part = key[start : start + BLOCK]
        if shift:
            part &= ~low
        else:
            part <<= bits
        part |= np.arange(start, start + len(part), dtype=np.uint64)

    for_each_block(pack, range(0, n, BLOCK))
    key.sort()
    same = np.empty(max(n - 1, 0), dtype=bool)

    # the comparisons read key[stop], the first key of the next block: compare every block, then unpack
    for_each_block(functools.partial(_compare, key, low, same, n), range(0, n - 1, BLOCK))
    for_each_block(functools.partial(_unpack, key, low), range(0, n, BLOCK))
    return key.view(np.int64), same


def _pack_bucket(
    part: NDArray[np.uint64],
    key: NDArray[np.uint64],
    sub: NDArray[np.signedinteger],
    low: np.uint64,
    index_bits: np.uint64,
    start: int,
) -> None:
    block = part[start : start + BLOCK]
    block[...] = key[sub[start : start + BLOCK]]
    block &= low
    block <<= index_bits
    block |= sub[start : start + BLOCK].view(np.uint64)


def _compare(key: NDArray[np.uint64], low: np.uint64, same: NDArray[np.bool_], n: int, start: int) -> None:
    stop = min(n - 1, start + BLOCK)
    t = np.bitwise_xor(key[start + 1 : stop + 1], key[start:stop])
    np.less_equal(t, low, out=same[start:stop])  # equal above the index bits


def _unpack(key: NDArray[np.uint64], low: np.uint64, start: int) -> None:
    key[start : start + BLOCK] &= low


def _equal_neighbours(table: NDArray[np.unsignedinteger], order: NDArray[np.int64]) -> NDArray[np.bool_]:
    """Rows ``order[i]`` and ``order[i + 1]`` of ``table`` (n, k) equal in every column.

    Each row is gathered once, as one opaque record of k integers (one
    memory access per row; the columns then compare in the gathered copy),
    in blocks.
    """
    n, k = table.shape
    records = table.view(np.dtype((np.void, table.dtype.itemsize * k))).reshape(-1)
    same = np.empty(max(n - 1, 0), dtype=bool)
    if n < 2:
        return same

    def block(start: int) -> None:
        stop = min(n - 1, start + BLOCK)
        gathered = records.take(order[start : stop + 1]).view(table.dtype).reshape(-1, k)
        out, e = same[start:stop], np.empty(stop - start, dtype=bool)
        np.equal(gathered[1:, 0], gathered[:-1, 0], out=out)
        for j in range(1, k):
            np.equal(gathered[1:, j], gathered[:-1, j], out=e)
            out &= e

    for_each_block(block, range(0, n - 1, BLOCK))
    return same


def _resolve_collisions(
    table: NDArray[np.unsignedinteger], order: NDArray[np.int64], same_hash: NDArray[np.bool_], same: NDArray[np.bool_]
) -> NDArray[np.int64]:
    """Re-sort the hash runs that hold distinct rows by (run, columns, index); ``same`` is updated for the new order."""
    n = len(order)
    run = np.empty(n, dtype=order.dtype)  # the hash run of each sorted row, from 1
    run[0] = 1
    np.cumsum(~same_hash, dtype=order.dtype, out=run[1:])
    run[1:] += 1
    bad_runs = np.zeros(int(run[-1]) + 1, dtype=bool)
    bad_runs[run[1:][same_hash & ~same]] = True
    pos = np.flatnonzero(bad_runs[run])
    sub = order[pos]
    keys = [table[sub, j] for j in reversed(range(table.shape[1]))] + [run[pos]]
    out = order.copy()
    out[pos] = sub[np.lexsort(keys)]  # lexsort is stable: index order kept among equal rows
    # only neighbours inside the re-sorted runs changed; a run's edges border another hash, never equal
    inner = pos[:-1][np.diff(pos) == 1]
    inner = inner[same_hash[inner]]
    a, b = table[out[inner]], table[out[inner + 1]]
    same[inner] = np.all(a == b, axis=1)
    return out


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
    edge_faces: NDArray[np.signedinteger]  # (k, 2) pairs of faces sharing a manifold edge (int32 when that holds twice the faces)
    edge_same_direction: NDArray[np.bool_]  # (k,) the pair traverses the edge the same way

    @property
    def closed(self) -> bool:
        return self.unbalanced_edges == 0


def surface_topology(faces: NDArray[np.int64], n_vertices: int) -> SurfaceTopology:
    """Count open, unbalanced and non-manifold edges in one sort of the edges."""
    half, forward = _edge_keys(faces, n_vertices)
    key_bits = max(1, (n_vertices * n_vertices - 1).bit_length())
    order, starts = _edge_order(half, key_bits)
    del half
    m = len(order)
    small: type[np.signedinteger] = np.int32 if m < 2**31 else np.int64  # order, starts, counts, balances: half the memory
    order = order.astype(small, copy=False)
    starts = starts.astype(small, copy=False)
    counts: NDArray[np.signedinteger] = np.empty(len(starts), dtype=small)
    np.subtract(starts[1:], starts[:-1], out=counts[:-1])
    if len(starts):
        counts[-1] = m - starts[-1]
    balance = np.empty(len(starts), dtype=small)  # half-edges of each run that go lo -> hi
    for_each_block(functools.partial(_forward_counts, forward, order, starts, counts, balance), range(0, len(starts), BLOCK))
    del forward
    balance *= 2
    balance -= counts
    pair = counts == 2
    open_edges = int(np.count_nonzero(counts == 1))
    nonmanifold = int(np.count_nonzero(counts > 2))
    unbalanced = int(np.count_nonzero(balance))
    same = balance[pair] != 0
    del balance, counts
    first = starts[pair]
    del starts, pair
    # the two faces of each manifold edge, smaller index first; built in blocks to bound memory
    pair_index = np.int32 if 2 * (m // 3) < 2**31 else np.int64  # half the memory of every later pass over the pairs
    edge_faces = np.empty((len(first), 2), dtype=pair_index)
    for_each_block(functools.partial(_face_pairs, first, order, edge_faces), range(0, len(first), BLOCK))
    del first, order
    return SurfaceTopology(
        open_edges=open_edges,
        unbalanced_edges=unbalanced,
        nonmanifold_edges=nonmanifold,
        edge_faces=edge_faces,
        edge_same_direction=same,
    )


def _forward_counts(
    forward: NDArray[np.bool_],
    order: NDArray[np.signedinteger],
    starts: NDArray[np.signedinteger],
    counts: NDArray[np.signedinteger],
    out: NDArray[np.signedinteger],
    start: int,
) -> None:
    """For the runs ``start:start + BLOCK`` of equal edges, how many of their half-edges go lo -> hi.

    A run's half-edges are consecutive in ``order``, so a block of runs
    gathers one slice of the flags.  Nearly every run is a pair (a manifold
    edge): its first and second flags are added for all runs at once, and
    only runs of three or more (non-manifold edges) are visited again;
    ``np.add.reduceat`` took three times as long over millions of pairs.
    """
    s, c = starts[start : start + BLOCK], counts[start : start + BLOCK]
    first = int(s[0])
    fwd = forward[order[first : int(s[-1] + c[-1])]]
    local = s - first
    total = fwd[local].astype(out.dtype)
    second = fwd[np.minimum(local + 1, len(fwd) - 1)]
    second &= c > 1
    total += second
    for k in range(2, int(c.max())):
        more = np.flatnonzero(c > k)
        total[more] += fwd[local[more] + k]
    out[start : start + BLOCK] = total


def _face_pairs(
    first: NDArray[np.signedinteger], order: NDArray[np.signedinteger], out: NDArray[np.signedinteger], start: int
) -> None:
    """The two faces of the edges whose runs start at ``first[start:start + BLOCK]``, smaller first."""
    at = first[start : start + BLOCK]
    face_a = order[at]
    face_b = order[at + 1]
    face_a //= 3
    face_b //= 3
    np.minimum(face_a, face_b, out=out[start : start + BLOCK, 0])
    np.maximum(face_a, face_b, out=out[start : start + BLOCK, 1])


def _edge_keys(faces: NDArray[np.int64], n_vertices: int) -> tuple[NDArray[np.uint64], NDArray[np.bool_]]:
    """Undirected key lo * n + hi of each half-edge (face-major) and whether it runs lo -> hi.

    Built in blocks of faces, one corner column at a time, straight into the
    output, so the only full-size arrays are the keys and the direction flags.
    """
    n = len(faces)
    key = np.empty((n, 3), dtype=np.uint64)
    forward = np.empty((n, 3), dtype=bool)
    step = max(1, BLOCK // 3)

    def block(start: int) -> None:
        faces_b = faces[start : start + step]
        m = len(faces_b)
        lo = np.empty(m, dtype=np.int64)
        hi = np.empty(m, dtype=np.int64)
        for k in range(3):
            u, v = faces_b[:, k], faces_b[:, (k + 1) % 3]
            np.less(u, v, out=forward[start : start + m, k])
            np.minimum(u, v, out=lo)
            np.maximum(u, v, out=hi)
            lk = lo.view(np.uint64)
            lk *= np.uint64(n_vertices)
            lk += hi.view(np.uint64)
            key[start : start + m, k] = lk

    for_each_block(block, range(0, n, step))
    return key.reshape(-1), forward.reshape(-1)


def _edge_order(key: NDArray[np.uint64], key_bits: int) -> tuple[NDArray[np.signedinteger], NDArray[np.signedinteger]]:
    """Half-edges sorted by key (ties in index order) and the start of each run of equal key.

    The key and the index are packed into one uint64 and value-sorted; when
    they need more than 64 bits, the half-edges are first split by the top
    bits of the key (a radix pass) and each bucket is packed and sorted.
    """
    m = len(key)
    index_bits = max(1, (m - 1).bit_length())
    spill = key_bits + index_bits - 64
    if spill <= 0:
        order, same = _packed_sort(key, index_bits)
        return order, np.flatnonzero(np.r_[True, ~same])
    if spill > 16:
        order = np.argsort(key, kind="stable")
        ks = key[order]
        return order, np.flatnonzero(np.r_[True, ks[1:] != ks[:-1]])
    low_bits = key_bits - spill
    small = np.int32 if m < 2**31 else np.int64  # order and starts: half the memory of int64
    bucket = (key >> np.uint64(low_bits)).astype(np.uint16)
    few = spill <= 4  # a few buckets: each found by a comparison, no full permutation held
    by_bucket = None if few else np.argsort(bucket, kind="stable")  # radix sort for 16-bit keys
    bounds = np.zeros((1 << spill) + 1, dtype=np.int64)
    if few:  # counted in place (bincount would widen every id to intp first)
        np.cumsum([np.count_nonzero(bucket == b) for b in range(1 << spill)], out=bounds[1:])
    else:
        np.cumsum(np.bincount(bucket, minlength=1 << spill), out=bounds[1:])
    low = np.uint64((1 << low_bits) - 1)
    index_mask = np.uint64((1 << index_bits) - 1)
    order = np.empty(m, dtype=small)
    starts = []
    for b, (b0, b1) in enumerate(itertools.pairwise(bounds)):
        if b1 == b0:
            continue
        sub = np.flatnonzero(bucket == b) if by_bucket is None else by_bucket[b0:b1]  # ascending either way
        part = np.empty(b1 - b0, dtype=np.uint64)
        # the low key bits and the index, packed in blocks
        for_each_block(functools.partial(_pack_bucket, part, key, sub, low, np.uint64(index_bits)), range(0, len(part), BLOCK))
        del sub
        part.sort()
        same = np.empty(len(part) - 1, dtype=bool)
        for_each_block(functools.partial(_compare, part, index_mask, same, len(part)), range(0, len(part) - 1, BLOCK))
        first: NDArray[np.signedinteger] = np.flatnonzero(np.r_[True, ~same]).astype(small)
        first += b0
        starts.append(first)
        for_each_block(functools.partial(_unpack, part, index_mask), range(0, len(part), BLOCK))
        order[b0:b1] = part
    return order, np.concatenate(starts)


def _components(
    n: int, a: NDArray[np.signedinteger], b: NDArray[np.signedinteger], ordered: bool = False
) -> tuple[int, NDArray[np.int64]]:
    """Connected components of the undirected graph on n nodes with edges (a, b).

    Vectorised union-find: every edge hooks the larger of its two roots onto
    the smaller, then pointer jumping flattens the trees into stars; repeat
    until no edge joins two roots.  Labels are numbered by the smallest node
    of each component, as a breadth-first search from node 0 upwards would.
    ``ordered``: a < b for every edge, so the first round hooks each b onto
    its smallest a as it stands, without sorting the ends of every edge.
    """
    index = np.int32 if n < 2**31 else np.int64  # half the memory of every temporary below
    parent: NDArray[np.signedinteger] = np.arange(n, dtype=index)
    first = True
    if ordered and len(a):
        np.minimum.at(parent, b, a.astype(index, copy=False))  # every edge joins two roots: the first round's hooks
        while _jump(parent):
            pass
        first = False
        a, b = a.astype(index, copy=False), b.astype(index, copy=False)
    while True:  # the first round reads the given (a, b) in place; later rounds keep compact copies
        # every node is its own root before the first round: its roots are the ends themselves
        ra, rb = (a.astype(index), b.astype(index)) if first else (parent[a], parent[b])
        first = False
        join = ra != rb
        if not np.any(join):
            break
        every = bool(np.all(join))  # the first round joins every edge: no compressed copies of all of them
        if not every:
            ra = ra[join]
            rb = rb[join]
        hi = np.maximum(ra, rb)
        np.minimum(ra, rb, out=ra)
        del rb
        np.minimum.at(parent, hi, ra)
        del hi, ra
        while _jump(parent):  # until every node points at its root
            pass
        if not every:
            a, b = a[join], b[join]
        a, b = a.astype(index, copy=False), b.astype(index, copy=False)
    roots = parent == np.arange(n, dtype=index)
    if n and int(np.count_nonzero(roots)) == 1:  # one component (the usual solid): no labels to number
        return 1, np.zeros(n, dtype=np.int64)
    rank: NDArray[np.signedinteger] = np.cumsum(roots, dtype=index)
    del roots
    rank -= 1
    label: NDArray[np.int64] = rank[parent].astype(np.int64)
    return int(rank[-1] + 1) if n else 0, label


def _jump(parent: NDArray[np.signedinteger]) -> bool:
    """One step of pointer jumping in place, ``parent = parent[parent]``, in blocks; whether any entry moved.

    In place is safe although blocks read entries other blocks write: an
    entry only ever moves to an ancestor of the same tree, so a read of a
    block's new value still gives an ancestor, and the loop ends only once
    a whole pass moved nothing, when every entry is its root.
    """
    starts = range(0, len(parent), BLOCK)
    moved = np.zeros(len(starts), dtype=bool)

    def block(start: int) -> None:
        own = parent[start : start + BLOCK]
        grand = parent[own]
        moved[start // BLOCK] = not np.array_equal(grand, own)
        own[...] = grand

    for_each_block(block, starts)
    return bool(moved.any())


def orient_consistently(faces: NDArray[np.int64], topo: SurfaceTopology) -> tuple[NDArray[np.int64], int]:
    """Flip faces so that neighbours agree across every manifold edge.

    Works on the doubled graph (each face in both orientations): an edge that
    neighbours traverse the same way links opposite orientations.  A face
    whose two orientations fall in one component lies on a non-orientable
    surface.  Returns the re-wound faces and the number of flipped faces.
    """
    n = len(faces)
    f1, f2 = topo.edge_faces[:, 0].astype(np.int64), topo.edge_faces[:, 1].astype(np.int64)
    flip = topo.edge_same_direction.astype(np.int64) * n
    rows = np.concatenate([f1, f1 + n])
    cols = np.concatenate([f2 + flip, f2 + n - flip])
    _, label = _components(2 * n, rows, cols)
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
    e = topo.edge_faces
    return _components(len(faces), e[:, 0], e[:, 1], ordered=True)  # each pair is written smaller face first
