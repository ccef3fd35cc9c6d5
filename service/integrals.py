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

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Sums", "simplex_sums", "point_sums", "local_origin", "CHUNK"]

CHUNK = 1 << 15  # elements per vectorised block: its (n,) temporaries (256 KB each) stay in cache


@dataclass(frozen=True, slots=True)
class Sums:
    """Integrals over the body about the local origin (unit density or weights).

    m0 : int dm.  m1 : (3,) int x dm.  m2 : (3, 3) int x x^T dm.
    abs_m2 : (3, 3) sums of |contribution|, the scale of rounding errors.
    noise : rounding scale of m0 (sum of |a||b||c| / 6 for surfaces).
    terms : number of elements summed.
    """

    m0: float
    m1: NDArray[np.float64]
    m2: NDArray[np.float64]
    abs_m0: float
    abs_m2: NDArray[np.float64]
    noise: float
    terms: int
    element_err: NDArray[np.float64]  # (3,) per-element rounding scale of m2 diagonal


_IJ = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))
# rows of a block: m0, m1 x3, m2 x6 (xx yy zz xy xz yz), det noise, error scale of xx yy zz
ROWS = 14


def _block_terms(p: NDArray[np.float64], kind: str, weight: NDArray[np.float64] | None) -> NDArray[np.float64]:
    """Per-element [m0, m1 (3), m2 (6), noise] for one block of simplices."""
    if kind == "apex":  # tetrahedron (0, a, b, c) of a closed surface
        a, b, c = p[:, 0], p[:, 1], p[:, 2]
        cross = np.cross(b, c)
        dm = np.einsum("ij,ij->i", a, cross) / 6.0
        s = a + b + c
        f1, f2 = dm / 4.0, dm / 20.0
        noise = _det_condition(a, b, c) / 6.0
        verts = (a, b, c)
    elif kind == "tet":  # volume cell
        e1, e2, e3 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]
        cross = np.cross(e2, e3)
        dm = np.abs(np.einsum("ij,ij->i", e1, cross)) / 6.0
        s = p[:, 0] + p[:, 1] + p[:, 2] + p[:, 3]
        f1, f2 = dm / 4.0, dm / 20.0
        noise = _det_condition(e1, e2, e3) / 6.0
        verts = (p[:, 0], p[:, 1], p[:, 2], p[:, 3])
    else:  # "tri": thin shell, area measure
        a, b, c = p[:, 0], p[:, 1], p[:, 2]
        dm = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
        s = a + b + c
        f1, f2 = dm / 3.0, dm / 12.0
        noise = dm
        verts = (a, b, c)
    if weight is not None:
        dm, f1, f2 = dm * weight, f1 * weight, f2 * weight
    out = np.empty((ROWS, len(p)))
    out[0] = dm
    out[1:4] = (f1[:, None] * s).T
    for row, (i, j) in enumerate(_IJ, start=4):
        acc = s[:, i] * s[:, j]
        for v in verts:
            acc += v[:, i] * v[:, j]
        out[row] = f2 * acc
        if row < 7:  # diagonal: error of this element's term, |dm| + det noise
            out[row + 7] = acc * (np.abs(f2) + noise * (1.0 / 20.0 if weight is None else np.abs(weight) / 20.0))
    out[10] = noise if weight is None else noise * np.abs(weight)
    return out


def _det_condition(a: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64]) -> NDArray[np.float64]:
    """sum over permutations of |a_i b_j c_k|: rounding of a . (b x c) is a few eps times this."""
    i, j = [1, 2, 0], [2, 0, 1]
    abs_cross = np.abs(b[:, i] * c[:, j]) + np.abs(b[:, j] * c[:, i])
    return np.einsum("ij,ij->i", np.abs(a), abs_cross)


def _apex_block_sums(xyz: list[NDArray[np.float64]], cells: NDArray[np.int64],
                     total: NDArray[np.float64], total_abs: NDArray[np.float64]) -> None:
    """Add the row sums of ``_block_terms(points[cells], "apex", None)`` to total, total_abs.

    The same terms with the same arithmetic, element by element, on
    contiguous (n,) component arrays: no (n, 3) strided views, no np.cross or
    einsum dispatch, and each row is summed as soon as it is formed (numpy's
    pairwise sum over a contiguous row, as ``terms.sum(axis=1)`` does).
    """
    idx = [cells[:, k] for k in range(3)]
    a, b, c = ([x.take(i) for x in xyz] for i in idx)  # a[k]: component k of the first corners
    crx = b[1] * c[2] - b[2] * c[1]  # b x c, as np.cross forms it
    cry = b[2] * c[0] - b[0] * c[2]
    crz = b[0] * c[1] - b[1] * c[0]
    dm = (a[0] * crx + a[1] * cry + a[2] * crz) / 6.0
    del crx, cry, crz
    abs_a = [np.abs(v) for v in a]
    noise = (abs_a[0] * (np.abs(b[1] * c[2]) + np.abs(b[2] * c[1]))  # _det_condition
             + abs_a[1] * (np.abs(b[2] * c[0]) + np.abs(b[0] * c[2]))
             + abs_a[2] * (np.abs(b[0] * c[1]) + np.abs(b[1] * c[0]))) / 6.0
    del abs_a
    s = [a[k] + b[k] + c[k] for k in range(3)]
    f1, f2 = dm / 4.0, dm / 20.0
    err_factor = np.abs(f2) + noise * (1.0 / 20.0)
    _add_row(total, total_abs, 0, dm)
    for k in range(3):
        _add_row(total, total_abs, 1 + k, f1 * s[k])
    for row, (i, j) in enumerate(_IJ, start=4):
        acc = s[i] * s[j]
        for v in (a, b, c):
            acc += v[i] * v[j]
        _add_row(total, total_abs, row, f2 * acc)
        if row < 7:  # diagonal: error of this element's term (non-negative)
            acc *= err_factor
            total[row + 7] += acc.sum()
            total_abs[row + 7] += acc.sum()
    total[10] += noise.sum()
    total_abs[10] += noise.sum()


def _add_row(total: NDArray[np.float64], total_abs: NDArray[np.float64], row: int, terms: NDArray[np.float64]) -> None:
    total[row] += terms.sum()
    total_abs[row] += np.abs(terms).sum()


def simplex_sums(
    points: NDArray[np.float64],
    cells: NDArray[np.int64],
    kind: str,
    weight: NDArray[np.float64] | None,
) -> Sums:
    total = np.zeros(ROWS)
    total_abs = np.zeros(ROWS)
    if kind == "apex" and weight is None:
        xyz = [np.ascontiguousarray(points[:, k]) for k in range(3)]  # struct of arrays
        for start in range(0, len(cells), CHUNK):
            _apex_block_sums(xyz, cells[start : start + CHUNK], total, total_abs)
        return _sums_from_rows(total, total_abs, len(cells))
    for start in range(0, len(cells), CHUNK):
        block = points[cells[start : start + CHUNK]]
        w = None if weight is None else weight[start : start + CHUNK]
        terms = _block_terms(block, kind, w)
        total += terms.sum(axis=1)
        total_abs += np.abs(terms).sum(axis=1)
    return _sums_from_rows(total, total_abs, len(cells))


def _sums_from_rows(total: NDArray[np.float64], total_abs: NDArray[np.float64], n: int) -> Sums:
    m2 = np.empty((3, 3))
    a2 = np.empty((3, 3))
    for row, (i, j) in enumerate(_IJ, start=4):
        m2[i, j] = m2[j, i] = total[row]
        a2[i, j] = a2[j, i] = total_abs[row]
    return Sums(float(total[0]), total[1:4].copy(), m2, float(total_abs[0]), a2, float(total[10]), n,
                 total[11:14].copy())


def point_sums(masses: NDArray[np.float64], x: NDArray[np.float64]) -> Sums:
    m1 = (masses[:, None] * x).sum(axis=0)
    m2 = np.empty((3, 3))
    for i, j in _IJ:
        m2[i, j] = m2[j, i] = float((masses * x[:, i] * x[:, j]).sum())
    diag_scale = np.array([float((masses * x[:, i] ** 2).sum()) for i in range(3)])
    return Sums(float(masses.sum()), m1, m2, float(masses.sum()), np.abs(m2), 0.0, len(masses), diag_scale)


def local_origin(points: NDArray[np.float64]) -> NDArray[np.float64]:
    """A point of the body's own float grid near its middle.

    The midpoint of the bounding box, rounded to float64, lies between the
    extreme coordinates, so for a body far from the origin every difference
    point - origin is exact (Sterbenz).
    """
    lo = points.min(axis=0)
    hi = points.max(axis=0)
    return lo + 0.5 * (hi - lo)
