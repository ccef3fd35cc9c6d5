"""Volume cells integrated exactly as the elements they are.

Every cell is the image of a reference cell under its isoparametric map
x(xi) = sum_a N_a(xi) X_a (shape functions N_a, nodes X_a, VTK's parametric
coordinates and node order, which meshio shares).  The integrals of mass are

    int dV = int |det J(xi)| dxi,   int x_i dV,   int x_i x_j dV,

polynomials in xi times det J, so a Gauss rule of high enough degree gives
them exactly: the only error left is rounding.  The degree of every rule and
the reason for it are stated in ``_RULES``.

Shape functions.  Each element's functions are the Lagrange basis of its
polynomial space on its nodes (the monomials listed in ``_SPACES``, the
nodes in ``_NODES``), formed once by inverting the Vandermonde matrix:

- tetra10 : P2 (total degree <= 2);
- hexahedron (and VTK's voxel, in its own node order): Q1, the trilinear map,
  so a warped face is the bilinear patch through its four corners and the
  result does not depend on the node numbering (no fixed split diagonal);
- hexahedron20 : the 20-node serendipity space (exponents <= 2, superlinear
  degree <= 2; Arnold & Awanou, Found. Comput. Math. 11, 2011);
- hexahedron27 : Q2;
- wedge : P1(triangle) x P1(line); wedge15 : P2 x P1 + P1 x {t^2};
  wedge18 : P2 x P2;
- pyramid : VTK's pyramid is the trilinear hexahedron with its top face
  collapsed to the apex (N_4 = t); pyramid13 : VTK's 13-node pyramid
  (``vtkQuadraticPyramid``, VTK 9), polynomial of degree <= 2 in each
  parametric variable on the collapsed cube; written out in ``_pyramid13``.

A collapsed (degenerate) cell, e.g. a hexahedron with repeated nodes, is
integrated through the same map; det J vanishes where the cell collapses,
so it counts as its true shape (a wedge, pyramid or tetrahedron).

Quadrature.  Tensor Gauss-Legendre rules on the cube; on the triangle and the
tetrahedron the collapsed (Duffy) coordinates with Gauss-Jacobi rules that
absorb the collapse's Jacobian (Stroud, Approximate Calculation of Multiple
Integrals, 1971, §2.5 "conical product" rules; Karniadakis & Sherwin,
Spectral/hp Element Methods, 2nd ed., §4.1.1).  An n-point Gauss rule is exact
for degree 2n - 1 in each collapsed variable.

Orientation.  A cell whose node order is mirrored has det J < 0 everywhere;
it is integrated with |det J| (as the linear tetrahedra are).  A cell whose
det J changes sign is tangled (it folds over itself): ``tangled_cells`` counts
them so the loader can warn.  A tangled curved cell keeps the orientation of
its corners (the straight-sided cell through them), so its folded region
counts negatively, as Gmsh's signed Jacobians count it.
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from .blocks import for_each_block
from .integrals import IJ, ROWS, Sums, sums_from_rows

__all__ = ["CELL_NODES", "CellRule", "cell_rule", "cell_sums", "combined", "tangled_cells", "VOXEL_TO_HEXAHEDRON"]

# nodes per cell type (meshio's names)
CELL_NODES = {
    "tetra10": 10,
    "hexahedron": 8,
    "hexahedron20": 20,
    "hexahedron27": 27,
    "wedge": 6,
    "wedge15": 15,
    "wedge18": 18,
    "pyramid": 5,
    "pyramid13": 13,
}
# VTK's voxel numbers its corners x fastest, then y, then z; a hexahedron goes round each face
VOXEL_TO_HEXAHEDRON = np.array([0, 1, 3, 2, 4, 5, 7, 6])

# ----------------------------------------------------------------------------------------------
# Reference nodes (VTK parametric coordinates): corners, then edge midpoints, face centres, centre

_HEX_CORNERS = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
_HEX_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]
_HEX_FACES = ((0, 4, 7, 3), (1, 2, 6, 5), (0, 1, 5, 4), (3, 2, 6, 7), (0, 1, 2, 3), (4, 5, 6, 7))
_TET_CORNERS = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
_TET_EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
_WEDGE_CORNERS = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (0, 1, 1)]
_WEDGE_EDGES = [(0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (0, 3), (1, 4), (2, 5)]
_WEDGE_FACES = ((0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5))


def _with_midpoints(
    corners: list[tuple[int, int, int]], edges: list[tuple[int, int]], faces: tuple[tuple[int, ...], ...] = (), centre: bool = False
) -> NDArray[np.float64]:
    c = np.array(corners, dtype=np.float64)
    rows = [c, *(0.5 * (c[[a]] + c[[b]]) for a, b in edges), *(c[list(f)].mean(axis=0, keepdims=True) for f in faces)]
    if centre:
        rows.append(c.mean(axis=0, keepdims=True))
    return np.concatenate(rows)


_NODES = {
    "tetra10": _with_midpoints(_TET_CORNERS, _TET_EDGES),
    "hexahedron": _with_midpoints(_HEX_CORNERS, []),
    "hexahedron20": _with_midpoints(_HEX_CORNERS, _HEX_EDGES),
    "hexahedron27": _with_midpoints(_HEX_CORNERS, _HEX_EDGES, _HEX_FACES, centre=True),
    "wedge": _with_midpoints(_WEDGE_CORNERS, []),
    "wedge15": _with_midpoints(_WEDGE_CORNERS, _WEDGE_EDGES),
    "wedge18": _with_midpoints(_WEDGE_CORNERS, _WEDGE_EDGES, _WEDGE_FACES),
}

# Polynomial spaces as monomial exponents (a, b, c) of r^a s^b t^c
_cube = list(itertools.product(range(3), repeat=3))
_SPACES = {
    "tetra10": [e for e in _cube if sum(e) <= 2],
    "hexahedron": [e for e in itertools.product(range(2), repeat=3)],
    # serendipity: superlinear degree (the total degree not counting variables that appear linearly) <= 2
    "hexahedron20": [e for e in _cube if sum(x for x in e if x >= 2) <= 2],
    "hexahedron27": _cube,
    "wedge": [e for e in _cube if e[0] + e[1] <= 1 and e[2] <= 1],
    "wedge15": [e for e in _cube if (e[0] + e[1] <= 2 and e[2] <= 1) or (e[0] + e[1] <= 1 and e[2] == 2)],
    "wedge18": [e for e in _cube if e[0] + e[1] <= 2],
}


def _monomials(xi: NDArray[np.float64], exps: list[tuple[int, ...]]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Values (q, m) and parametric derivatives (3, q, m) of the monomials at the points xi (q, 3)."""
    e = np.array(exps, dtype=np.float64)  # (m, 3)
    val = np.prod(xi[:, None, :] ** e[None, :, :], axis=2)
    der = np.empty((3, *val.shape))
    for d in range(3):
        lowered = e.copy()
        lowered[:, d] = np.maximum(e[:, d] - 1, 0)
        der[d] = e[None, :, d] * np.prod(xi[:, None, :] ** lowered[None, :, :], axis=2)
    return val, der


def _lagrange(name: str, xi: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Shape functions (q, n) and their parametric derivatives (3, q, n) at the points xi."""
    if name == "pyramid13":
        return _pyramid13(xi)
    if name == "pyramid":  # the trilinear hexahedron with nodes 4-7 merged into the apex
        n, dn = _lagrange("hexahedron", xi)
        collapse = [0, 1, 2, 3, 4, 4, 4, 4]
        out, dout = np.zeros((len(xi), 5)), np.zeros((3, len(xi), 5))
        for a, b in enumerate(collapse):
            out[:, b] += n[:, a]
            dout[:, :, b] += dn[:, :, a]
        return out, dout
    exps = _SPACES[name]
    vander, _ = _monomials(_NODES[name], exps)
    inverse = np.linalg.inv(vander)  # N(xi) = monomials(xi) @ inverse: N_a(node_b) = delta_ab
    val, der = _monomials(xi, exps)
    return val @ inverse, der @ inverse


def _pyramid13(xi: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """VTK 9's 13-node pyramid: in R = 2r - 1, S = 2s - 1, T = 2t - 1 on the collapsed cube,

    corner a (signs ra, sa = -1 or +1 of its R, S):
        N_a = -(1 + ra R)(1 + sa S)(1 - T)(4 - 3 ra R - 3 sa S + 2 ra sa R S + 2T - ra R T - sa S T
              + 2 ra sa R S T) / 16,
    apex N_4 = T(1 + T)/2, base mid-edge nodes (1 - R^2)(1 + sa S)(1 - T)(2 - sa S (1 + T))/8 and
    the same with R and S exchanged, side mid-edges (1 + ra R)(1 + sa S)(1 - T^2)/4.
    Polynomial, each variable to degree <= 2.  The derivatives are those of these functions
    (product rule), so positions and Jacobian always belong to one map.
    """
    r, s, t = (2 * xi[:, k] - 1 for k in range(3))
    corners = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
    cols: list[NDArray[np.float64]] = []
    grads: list[tuple[NDArray[np.float64], ...]] = []
    for ra, sa in corners:
        a, b, c = 1 + ra * r, 1 + sa * s, 1 - t
        g = 4 - 3 * ra * r - 3 * sa * s + 2 * ra * sa * r * s + 2 * t - ra * r * t - sa * s * t + 2 * ra * sa * r * s * t
        gr = -3 * ra + 2 * ra * sa * s - ra * t + 2 * ra * sa * s * t
        gs = -3 * sa + 2 * ra * sa * r - sa * t + 2 * ra * sa * r * t
        gt = 2 - ra * r - sa * s + 2 * ra * sa * r * s
        cols.append(-a * b * c * g / 16)
        grads.append(
            (-(ra * b * c * g + a * b * c * gr) / 16, -(a * sa * c * g + a * b * c * gs) / 16, -(-a * b * g + a * b * c * gt) / 16)
        )
    cols.append(t * (1 + t) / 2)
    grads.append((0 * r, 0 * r, (1 + 2 * t) / 2))
    for along_r, sign in ((True, -1), (False, 1), (True, 1), (False, -1)):  # base edges 0-1, 1-2, 2-3, 3-0
        u, v = (r, s) if along_r else (s, r)
        h = 2 - sign * v * (1 + t)
        val = (1 - u * u) * (1 + sign * v) * (1 - t) * h / 8
        du = -2 * u * (1 + sign * v) * (1 - t) * h / 8
        dv = (1 - u * u) * (1 - t) * (sign * h - (1 + sign * v) * sign * (1 + t)) / 8
        dt = (1 - u * u) * (1 + sign * v) * (-h - (1 - t) * sign * v) / 8
        cols.append(val)
        grads.append((du, dv, dt) if along_r else (dv, du, dt))
    for ra, sa in corners:  # side edges 0-4, 1-4, 2-4, 3-4
        cols.append((1 + ra * r) * (1 + sa * s) * (1 - t * t) / 4)
        grads.append(
            (ra * (1 + sa * s) * (1 - t * t) / 4, (1 + ra * r) * sa * (1 - t * t) / 4, -(1 + ra * r) * (1 + sa * s) * 2 * t / 4)
        )
    n = np.stack(cols, axis=1)
    dn = np.stack([np.stack([g[d] for g in grads], axis=1) for d in range(3)]) * 2  # d/dr = 2 d/dR
    return n, dn


# ----------------------------------------------------------------------------------------------
# Quadrature rules


def _gauss_legendre(n: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """n-point Gauss-Legendre on [0, 1]: exact for degree 2n - 1."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1), 0.5 * w


def _gauss_jacobi(n: int, alpha: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """n-point Gauss rule on [0, 1] for the weight (1 - u)^alpha: exact for degree 2n - 1."""
    from scipy.special import roots_jacobi

    x, w = roots_jacobi(n, alpha, 0)  # weight (1 - x)^alpha on [-1, 1]
    return 0.5 * (x + 1), w / 2.0 ** (alpha + 1)


def _cube_rule(n: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    x, w = _gauss_legendre(n)
    pts = np.array(list(itertools.product(x, x, x)))
    return pts, np.array([a * b * c for a, b, c in itertools.product(w, w, w)])


def _tet_rule(n: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Collapsed coordinates r = u, s = v (1 - u), t = w (1 - u)(1 - v); dr ds dt = (1-u)^2 (1-v) du dv dw."""
    u, wu = _gauss_jacobi(n, 2)
    v, wv = _gauss_jacobi(n, 1)
    w, ww = _gauss_legendre(n)
    pts, wts = [], []
    for (a, wa), (b, wb), (c, wc) in itertools.product(zip(u, wu), zip(v, wv), zip(w, ww)):
        pts.append((a, b * (1 - a), c * (1 - a) * (1 - b)))
        wts.append(wa * wb * wc)
    return np.array(pts), np.array(wts)


def _wedge_rule(n_triangle: int, n_line: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Triangle r = u, s = v (1 - u) (dr ds = (1 - u) du dv) times a line rule in t."""
    u, wu = _gauss_jacobi(n_triangle, 1)
    v, wv = _gauss_legendre(n_triangle)
    t, wt = _gauss_legendre(n_line)
    pts, wts = [], []
    for (a, wa), (b, wb), (c, wc) in itertools.product(zip(u, wu), zip(v, wv), zip(t, wt)):
        pts.append((a, b * (1 - a), c))
        wts.append(wa * wb * wc)
    return np.array(pts), np.array(wts)


def _points_for(degree: int) -> int:
    """Gauss points per variable for exactness to ``degree`` (2n - 1 >= degree)."""
    return (degree + 2) // 2


# Degrees.  With x in a space of degree q per variable (tensor cells), each column
# dx/dxi_d of J has degree q - 1 in xi_d and q in the others, so det J has degree
# 3q - 1 per variable and x_i x_j det J degree 2q + 3q - 1 = 5q - 1:
#   Q1 (hexahedron, voxel, pyramid)                       q = 1 -> 4 -> 3 points
#   Q2 (hexahedron27; hexahedron20 and pyramid13 inside Q2) q = 2 -> 9 -> 5 points
# Tetrahedron of total degree p: det J has degree 3(p - 1), the integrand 5p - 3:
#   tetra10                                               p = 2 -> 7 -> 4 points
# Wedge P_p(triangle) x P_q(line): columns d/dr, d/ds have degrees (p-1, q), d/dt (p, q-1);
# det J (3p - 2, 3q - 1); the integrand (5p - 2, 5q - 1):
#   wedge                                                 (1, 1) -> (3, 4) -> 2 x 3 points
#   wedge15, wedge18 (inside P2 x P2)                     (2, 2) -> (8, 9) -> 5 x 5 points
_RULES = {
    "hexahedron": ("cube", 4),
    "pyramid": ("cube", 4),
    "hexahedron20": ("cube", 9),
    "hexahedron27": ("cube", 9),
    "pyramid13": ("cube", 9),
    "tetra10": ("tet", 7),
    "wedge": ("wedge", (3, 4)),
    "wedge15": ("wedge", (8, 9)),
    "wedge18": ("wedge", (8, 9)),
}


@dataclass(frozen=True, slots=True)
class CellRule:
    """A quadrature rule for one cell type, with the shape functions at its points.

    points : (q, 3) parametric.  weights : (q,) (sum = the reference cell's volume).
    shape : (q, n) N_a at the points.  grad : (3, q, n) dN_a/dxi_d at the points.
    degree : the polynomial degree integrated exactly (per variable, or (triangle, line)).
    """

    name: str
    points: NDArray[np.float64]
    weights: NDArray[np.float64]
    shape: NDArray[np.float64]
    grad: NDArray[np.float64]
    degree: int | tuple[int, int]
    shape_t: NDArray[np.float64] = field(init=False)
    """(n, q) contiguous: products with it run in BLAS (a transposed view takes a loop 400x slower)."""
    grad_t: NDArray[np.float64] = field(init=False)
    """(3, n, q) contiguous."""
    abs_shape_t: NDArray[np.float64] = field(init=False)
    """|shape_t|: sum_a |N_a| |D_a| scales the positions' rounding."""
    abs_grad_t: NDArray[np.float64] = field(init=False)
    """|grad_t|: sum_a |dN_a| |D_a| scales each Jacobian entry's rounding."""

    def __post_init__(self) -> None:
        shape_t = np.ascontiguousarray(self.shape.T)
        grad_t = np.ascontiguousarray(self.grad.transpose(0, 2, 1))
        derived = {"shape_t": shape_t, "grad_t": grad_t, "abs_shape_t": np.abs(shape_t), "abs_grad_t": np.abs(grad_t)}
        for key, value in derived.items():
            value.flags.writeable = False
            object.__setattr__(self, key, value)


@functools.cache
def cell_rule(name: str) -> CellRule:
    """The quadrature rule and shape functions of a cell type (meshio's name)."""
    kind, degree = _RULES[name]
    if kind == "cube":
        assert isinstance(degree, int)
        pts, wts = _cube_rule(_points_for(degree))
    elif kind == "tet":
        assert isinstance(degree, int)
        pts, wts = _tet_rule(_points_for(degree))
    else:
        assert isinstance(degree, tuple)
        pts, wts = _wedge_rule(_points_for(degree[0]), _points_for(degree[1]))
    n, dn = _lagrange(name, pts)
    for arr in (pts, wts, n, dn):
        arr.flags.writeable = False
    return CellRule(name, pts, wts, n, dn, degree)


def shape_functions(name: str, xi: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """N (q, n) and dN/dxi (3, q, n) of a cell type at parametric points xi (q, 3)."""
    return _lagrange(name, np.asarray(xi, dtype=np.float64))


# ----------------------------------------------------------------------------------------------
# Integration

_BLOCK_POINTS = 1 << 16  # quadrature points per vectorised block: its ~40 (cells, q) temporaries take ~20 MB


def _jacobians(
    xyz: list[NDArray[np.float64]], cells: NDArray[np.int64], rule: CellRule
) -> tuple[list[NDArray[np.float64]], NDArray[np.float64], NDArray[np.float64], list[NDArray[np.float64]]]:
    """Positions (3 of (c, q)), det J (c, q), its rounding scale (c, q) and the positions' (3 of (c, q)).

    Formed from the edges D_a = X_a - X_0 of each cell (sum N_a = 1, sum dN_a = 0, so
    x = X_0 + sum N_a D_a and J = sum dN_a D_a): a cell far from the local origin keeps its
    Jacobian to the relative precision of its own size, as the tetrahedra's edge form does.
    """
    nodes = [x.take(cells) for x in xyz]  # 3 of (c, n)
    base = [xk[:, :1] for xk in nodes]
    edges = [np.ascontiguousarray(xk[:, 1:] - b) for xk, b in zip(nodes, base)]  # 3 of (c, n - 1)
    magnitude = [np.abs(e) for e in edges]
    pos = [b + e @ rule.shape_t[1:] for b, e in zip(base, edges)]
    pos_scale = [np.abs(b) + m @ rule.abs_shape_t[1:] for b, m in zip(base, magnitude)]
    jac = [[e @ rule.grad_t[d, 1:] for e in edges] for d in range(3)]  # jac[d][k] = dx_k / dxi_d
    jac_abs = [[m @ rule.abs_grad_t[d, 1:] for m in magnitude] for d in range(3)]  # sum |dN_a| |D_a|
    a, b, c = jac
    det = a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0])
    aa, ba, ca = jac_abs
    # every product of the determinant, in bounds of its factors: det's rounding (each J entry a sum
    # of n - 1 products of rounded edges, then three products and five sums) is below (n + 6) u times this
    cond = (
        aa[0] * (ba[1] * ca[2] + ba[2] * ca[1]) + aa[1] * (ba[2] * ca[0] + ba[0] * ca[2]) + aa[2] * (ba[0] * ca[1] + ba[1] * ca[0])
    )
    return pos, det, cond, pos_scale


def tangled_cells(points: NDArray[np.float64], name: str, cells: NDArray[np.int64]) -> int:
    """Cells whose det J takes both signs at the quadrature points beyond rounding (folded cells)."""
    rule = cell_rule(name)
    xyz = [np.ascontiguousarray(points[:, k]) for k in range(3)]  # the edge form needs no shift
    n = rule.shape.shape[1]
    count = 0
    step = max(1, _BLOCK_POINTS // len(rule.weights))
    for start in range(0, len(cells), step):
        _, det, cond, _ = _jacobians(xyz, cells[start : start + step], rule)
        count += int(np.count_nonzero(_folded(det, cond, n)))
    return count


def _folded(det: NDArray[np.float64], cond: NDArray[np.float64], n: int) -> NDArray[np.bool_]:
    """Per cell: det J takes both signs at its quadrature points, each beyond its rounding."""
    tol = (n + 6) * 2.220446049250313e-16 * cond
    folded: NDArray[np.bool_] = np.any(det > tol, axis=1) & np.any(det < -tol, axis=1)
    return folded


# A curved cell's corners (its first nodes), as the straight-sided cell through them
_STRAIGHT = {
    "tetra10": "tetra",
    "hexahedron20": "hexahedron",
    "hexahedron27": "hexahedron",
    "wedge15": "wedge",
    "wedge18": "wedge",
    "pyramid13": "pyramid",
}


def _orientation(
    xyz: list[NDArray[np.float64]], cells: NDArray[np.int64], rule: CellRule, det: NDArray[np.float64], cond: NDArray[np.float64]
) -> NDArray[np.float64]:
    """+1 or -1 per cell: the sign its det J is integrated with.

    A cell whose det J keeps one sign takes that sign (a mirrored node order counts with |det J|).  A
    curved cell that folds over itself is oriented by its corners, the straight-sided cell through them,
    so its folded region counts negatively, as the loader's warning says; where those corners enclose
    no volume, or the cell is straight-sided itself, by the sign of its integral.
    """
    sign: NDArray[np.float64] = np.sign(det @ rule.weights)
    straight = _STRAIGHT.get(rule.name)
    if straight is None:
        return sign
    folded = np.flatnonzero(_folded(det, cond, rule.shape.shape[1]))
    if not len(folded):
        return sign
    corners = cells[folded, : CELL_NODES.get(straight, 4)]  # a linear tetrahedron (not a cell of this module): 4
    if straight == "tetra":  # the linear tetrahedron's map: det J = (b - a) . ((c - a) x (d - a)), one sign
        a, b, c, d = ([x.take(corners[:, j]) for x in xyz] for j in range(4))
        u, v, w = ([q[i] - a[i] for i in range(3)] for q in (b, c, d))
        volume = u[0] * (v[1] * w[2] - v[2] * w[1]) + u[1] * (v[2] * w[0] - v[0] * w[2]) + u[2] * (v[0] * w[1] - v[1] * w[0])
    else:
        linear = cell_rule(straight)
        volume = _jacobians(xyz, corners, linear)[1] @ linear.weights
    sign[folded] = np.where(volume != 0, np.sign(volume), sign[folded])
    return sign


def cell_sums(x: NDArray[np.float64], name: str, cells: NDArray[np.int64], weight: NDArray[np.float64] | None) -> Sums:
    """Integrals of cells of one type over the points ``x`` (already relative to the local origin).

    weight : (k,) density of each cell, or None (unit density).  Rows and rounding scales as
    ``integrals.simplex_sums``: each quadrature point is one term.
    """
    rule = cell_rule(name)
    xyz = [np.ascontiguousarray(x[:, k]) for k in range(3)]
    n = rule.shape.shape[1]
    step = max(1, _BLOCK_POINTS // len(rule.weights))
    starts = range(0, len(cells), step)
    rows: list[tuple[NDArray[np.float64], NDArray[np.float64]]] = [(np.empty(0), np.empty(0))] * len(starts)

    def block(start: int) -> None:  # on the block threads; each block fills its own entry
        w = None if weight is None else weight[start : start + step]
        rows[start // step] = _block_rows(xyz, cells[start : start + step], rule, w, n)

    for_each_block(block, starts)
    total = np.sum([r[0] for r in rows], axis=0) if rows else np.zeros(ROWS)  # in block order
    total_abs = np.sum([r[1] for r in rows], axis=0) if rows else np.zeros(ROWS)
    return sums_from_rows(total, total_abs, len(cells) * len(rule.weights), max(len(rows), 1))


def _block_rows(
    xyz: list[NDArray[np.float64]], cells: NDArray[np.int64], rule: CellRule, weight: NDArray[np.float64] | None, n: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The 15 rows of ``integrals`` (m0, m1, m2, noise, diagonal error scales, measure) of one block."""
    pos, det, cond, pos_scale = _jacobians(xyz, cells, rule)
    sign = _orientation(xyz, cells, rule, det, cond)
    dv = det * rule.weights * sign[:, None]
    noise = cond * rule.weights  # rounding scale of dv: its error is below (n + 6) u times this
    dm, dm_noise = (dv, noise) if weight is None else (dv * weight[:, None], noise * np.abs(weight)[:, None])
    terms = [dm, *(dm * p for p in pos), *(dm * pos[i] * pos[j] for i, j in IJ)]
    total = np.array([float(t.sum()) for t in terms] + [0.0] * 5)
    total_abs = np.array([float(np.abs(t).sum()) for t in terms] + [0.0] * 5)
    total[10] = total_abs[10] = float(dm_noise.sum() * (n + 6) / 8)  # as the tetrahedra's determinant scale
    # ``mass`` bounds an element's own error of a diagonal term by 8 EPS = 16 u times this row.
    # Per point, dm x_i^2 errs by at most u [2n |dm| + (n + 6) noise] (|N| |X|)^2 (x_i is a sum of n
    # products, rounded within n u |N| |X|; det J within (n + 6) u noise), below
    # 16 u (n + 3)/8 (|dm| + noise) (|N| |X|)^2; the rule's own nodes and weights are exact to
    # 16 u relative (measured against exact monomial integrals in the tests): 2 |dm| more.
    err_weight = (np.abs(dm) + dm_noise) * ((n + 3) / 8) + 2 * np.abs(dm)
    for i in range(3):
        total[11 + i] = total_abs[11 + i] = float((err_weight * pos_scale[i] ** 2).sum())
    total[14] = total_abs[14] = float(dv.sum())
    return total, total_abs


def combined(a: Sums, b: Sums) -> Sums:
    """The sums of two disjoint sets of elements."""
    return Sums(
        a.m0 + b.m0,
        a.m1 + b.m1,
        a.m2 + b.m2,
        a.abs_m0 + b.abs_m0,
        a.abs_m2 + b.abs_m2,
        a.noise + b.noise,
        a.element_err + b.element_err,
        a.measure + b.measure,
        a.terms + b.terms,
        a.blocks + b.blocks,
    )


def reference_volume(name: str) -> float:
    """Volume of the reference cell (1 for the cube, 1/2 the wedge, 1/6 the tetrahedron)."""
    return {"cube": 1.0, "wedge": 0.5, "tet": 1 / 6}[_RULES[name][0]] if name in _RULES else math.nan
