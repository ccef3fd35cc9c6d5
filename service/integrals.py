"""Exact integrals over simplices: the kernels behind ``mass``.

For a tetrahedron with vertices p_k and volume V, with S = sum p_k
(Tonon, J. Math. Stat. 1(1), 2004, eqs. 7-8 in our notation):

    int x_i dV     = V S_i / 4
    int x_i x_j dV = V / 20 (sum_k p_ki p_kj + S_i S_j)

A closed surface is the signed sum of the tetrahedra (0, a, b, c) spanned by
each face and the origin (divergence theorem; Mirtich, J. Graphics Tools
1(2), 1996; Eberly, "Polyhedral Mass Properties (Revisited)", 2002).  A
triangle of area A (thin shell) gives int x_i dA = A S_i / 3 and
int x_i x_j dA = A/12 (sum_k p_ki p_kj + S_i S_j).  Point masses are summed
directly.

Besides the sums, every kernel accumulates the scale of its rounding errors
(sums of absolute contributions and each determinant's condition) so that
``mass`` can state an honest error bound.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .arrays import column_bounds
from .blocks import for_each_block

__all__ = ["Sums", "simplex_sums", "sums_from_rows", "point_sums", "local_origin", "CHUNK", "point_records", "gather_corners", "IJ"]

CHUNK = 1 << 15  # elements per vectorised block: its (n,) temporaries (256 KB each) stay in cache
GATHER_STEP = 1 << 12  # cells whose corner records (~300 KB) are gathered and split at a time


@dataclass(frozen=True, slots=True)
class Sums:
    """Integrals over the body about the local origin (unit density or weights).

    m0 : int dm.  m1 : (3,) int x dm.  m2 : (3, 3) int x x^T dm.
    abs_m0, abs_m2 : sums of |contribution|, the scale of summation errors.
    noise : rounding scale of m0 (the determinants' condition, see ``_det_condition``).
    element_err : (3,) rounding scale of each element's own terms of the m2 diagonal.
    terms, blocks : elements summed, and the blocks they were summed in.
    """

    m0: float
    m1: NDArray[np.float64]
    m2: NDArray[np.float64]
    abs_m0: float
    abs_m2: NDArray[np.float64]
    noise: float
    element_err: NDArray[np.float64]
    measure: float  # int dV (or dA, or the count of points) without the weights
    terms: int
    blocks: int


IJ = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))  # the rows of a symmetric 3 x 3 tensor's six entries
# rows of a block's sums: m0, m1 (x y z), m2 (xx yy zz xy xz yz), det noise, error scale of xx yy zz
ROWS = 15
_NOISE, _ERR, _MEASURE = 10, 11, 14
# a simplex's measure dm, and the factors of its first and second moments (int x = f1 S, ...)
_FACTORS = {"apex": (1 / 6, 1 / 4, 1 / 20), "tet": (1 / 6, 1 / 4, 1 / 20), "tri": (1 / 2, 1 / 3, 1 / 12)}

Vec = list[NDArray[np.float64]]  # the three components of a block of vectors, each contiguous (n,)


def _cross(u: Vec, v: Vec) -> Vec:
    return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]


def _det_condition(a: Vec, u: Vec, v: Vec) -> NDArray[np.float64]:
    """sum over permutations of |a_i u_j v_k|: the rounding of a . (u x v) is a few eps times this."""
    cond: NDArray[np.float64] = (
        np.abs(a[0]) * (np.abs(u[1] * v[2]) + np.abs(u[2] * v[1]))
        + np.abs(a[1]) * (np.abs(u[2] * v[0]) + np.abs(u[0] * v[2]))
        + np.abs(a[2]) * (np.abs(u[0] * v[1]) + np.abs(u[1] * v[0]))
    )
    return cond


def _measure(corners: list[Vec], kind: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Twice-or-six-times the measure of each simplex (before ``_FACTORS``) and its rounding scale.

    A face's tetrahedron with the origin uses a . ((b - a) x (c - a)), equal to
    a . (b x c) but formed from the short edges: b x c of two long, nearly
    parallel position vectors cancels to ~1/n of its terms on a fine mesh, the
    edge form does not, so each determinant keeps its relative precision.
    """
    a = corners[0]
    edges = [[p[k] - a[k] for k in range(3)] for p in corners[1:]]
    if kind == "apex":
        normal = _cross(edges[0], edges[1])
        det = a[0] * normal[0] + a[1] * normal[1] + a[2] * normal[2]
        return det, _det_condition(a, edges[0], edges[1])
    if kind == "tet":
        normal = _cross(edges[1], edges[2])
        det = edges[0][0] * normal[0] + edges[0][1] * normal[1] + edges[0][2] * normal[2]
        return np.abs(det), _det_condition(edges[0], edges[1], edges[2])
    normal = _cross(edges[0], edges[1])  # "tri": |n| is twice the area, correct to a few eps
    twice_area = np.sqrt(normal[0] ** 2 + normal[1] ** 2 + normal[2] ** 2)
    return twice_area, twice_area


def point_records(points: NDArray[np.float64]) -> NDArray[np.void]:
    """The rows of an (n, 3) float64 array as n opaque 24-byte records, for ``gather_corners``."""
    return np.ascontiguousarray(points, dtype=np.float64).view(np.dtype((np.void, 24))).reshape(-1)


def gather_corners(records: NDArray[np.void], cells: NDArray[np.int64]) -> list[Vec]:
    """corners[k][j]: coordinate j of corner k of each cell, each a contiguous (n,) row.

    Each corner is gathered once as one 24-byte record (one random access per
    corner instead of three), then the coordinates are split into rows.  The
    records are gathered ``GATHER_STEP`` cells at a time, so each step's
    records are still in the cache when they are split: gathering a whole
    block of ``CHUNK`` cells first (2.4 MB) and splitting it afterwards took
    three to four times as long.
    """
    corners = cells.shape[1]
    rows = np.empty((corners, 3, len(cells)))
    for start in range(0, len(cells), GATHER_STEP):
        step = records.take(cells[start : start + GATHER_STEP]).view(np.float64).reshape(-1, corners, 3)
        rows[:, :, start : start + GATHER_STEP] = step.transpose(1, 2, 0)
    return [list(rows[k]) for k in range(corners)]


def _block_sums(
    xyz: NDArray[np.void],
    cells: NDArray[np.int64],
    kind: str,
    weight: NDArray[np.float64] | None,
    also: Callable[[list[Vec]], None] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Sums over one block of simplices of every row, and of their absolute values.

    Struct of arrays: each quantity is a contiguous (n,) row of one (10, n)
    array of terms, summed row by row (numpy's pairwise summation along each
    contiguous row, the same as summing each row alone) in one call.
    """
    corners = gather_corners(xyz, cells)
    if also is not None:
        also(corners)
    raw, cond = _measure(corners, kind)
    f0, f1, f2 = _FACTORS[kind]
    dm = raw * f0
    noise = cond * f0
    if weight is not None:
        dm *= weight
        noise *= np.abs(weight)
    s = [sum(c[k] for c in corners) for k in range(3)]
    terms = np.empty((_NOISE, len(dm)))  # rows m0, m1 (x y z), m2 (xx yy zz xy xz yz)
    errs = np.empty((3, len(dm)))
    terms[0] = dm
    f1_dm = f1 * dm
    for k in range(3):
        np.multiply(f1_dm, s[k], out=terms[1 + k])
    f2_dm = f2 * dm
    # an element's diagonal term f2 dm acc errs by ~eps (|f2 dm| + f2 noise) acc: acc >= 0 is exact to a few eps
    err_factor = f2 * (np.abs(dm) + noise)
    for row, (i, j) in enumerate(IJ, start=4):
        acc = s[i] * s[j]
        for c in corners:
            acc += c[i] * c[j]
        np.multiply(f2_dm, acc, out=terms[row])
        if i == j:
            np.multiply(err_factor, acc, out=errs[i])
    total, total_abs = np.empty(ROWS), np.empty(ROWS)
    total[:_NOISE] = terms.sum(axis=1)
    total_abs[:_NOISE] = np.abs(terms, out=terms).sum(axis=1)
    total[_NOISE] = total_abs[_NOISE] = noise.sum()
    total[_ERR : _ERR + 3] = total_abs[_ERR : _ERR + 3] = errs.sum(axis=1)
    total[_MEASURE] = total_abs[_MEASURE] = (raw * f0).sum()
    return total, total_abs


def simplex_sums(
    points: NDArray[np.float64],
    cells: NDArray[np.int64],
    kind: str,
    weight: NDArray[np.float64] | None,
    each_block: Callable[[int, list[Vec]], None] | None = None,
) -> Sums:
    """Integrals of the simplices ``points[cells]``: "apex" (faces of a closed
    surface, each with the origin), "tet" (volume cells) or "tri" (area).

    ``each_block(start, corners)`` is given each block's gathered corners
    (``gather_corners``, cells ``start:start + CHUNK``), for another quantity
    of the same cells from the same gather; it must not change them.
    """
    xyz = point_records(points)
    starts = range(0, len(cells), CHUNK)
    per_block = np.empty((2, ROWS, len(starts)))

    def block(start: int) -> None:
        w = None if weight is None else weight[start : start + CHUNK]
        b = start // CHUNK
        also = None if each_block is None else functools.partial(each_block, start)
        per_block[0, :, b], per_block[1, :, b] = _block_sums(xyz, cells[start : start + CHUNK], kind, w, also)

    for_each_block(block, starts)  # blocks on several threads; each fills its own column
    total, total_abs = per_block.sum(axis=2)  # pairwise over the blocks too, in block order
    return sums_from_rows(total, total_abs, len(cells), len(starts))


def sums_from_rows(total: NDArray[np.float64], total_abs: NDArray[np.float64], n: int, blocks: int) -> Sums:
    """``Sums`` from its ``ROWS`` rows of totals and of absolute totals, over ``n`` terms in ``blocks`` blocks."""
    m2 = np.empty((3, 3))
    a2 = np.empty((3, 3))
    for row, (i, j) in enumerate(IJ, start=4):
        m2[i, j] = m2[j, i] = total[row]
        a2[i, j] = a2[j, i] = total_abs[row]
    return Sums(
        float(total[0]),
        total[1:4].copy(),
        m2,
        float(total_abs[0]),
        a2,
        float(total[_NOISE]),
        total[_ERR : _ERR + 3].copy(),
        float(total[_MEASURE]),
        n,
        blocks,
    )


def point_sums(masses: NDArray[np.float64], x: NDArray[np.float64]) -> Sums:
    m1 = (masses[:, None] * x).sum(axis=0)
    m2 = np.empty((3, 3))
    for i, j in IJ:
        m2[i, j] = m2[j, i] = float((masses * x[:, i] * x[:, j]).sum())
    diag_scale = np.array([float((masses * x[:, i] ** 2).sum()) for i in range(3)])
    return Sums(float(masses.sum()), m1, m2, float(masses.sum()), np.abs(m2), 0.0, diag_scale, float(len(masses)), len(masses), 1)


def local_origin(points: NDArray[np.float64]) -> NDArray[np.float64]:
    """A point of the body's own float grid near its middle.

    The midpoint of the bounding box, rounded to float64, lies between the
    extreme coordinates, so for a body far from the origin every difference
    point - origin is exact (Sterbenz).
    """
    lo, hi = column_bounds(points)
    origin: NDArray[np.float64] = lo + 0.5 * (hi - lo)
    return origin
