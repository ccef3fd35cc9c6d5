"""Exact references for mass properties (rational integration, 50-digit eigenvalues) and for the
torque-free motion of an asymmetric top (Landau & Lifshitz's closed form at 50 digits).

Every float64 is a dyadic rational, so a polyhedron given by float64 vertices
has exact rational mass properties.  This module computes them with Python
integers (each coordinate written as k * 2**e with one common exponent e per
array), which is exact and much faster than ``fractions.Fraction`` (no gcd per
operation); only the final few sums become ``Fraction``.  Nothing here uses
the service's own code.

Formulas (Tonon, J. Math. Stat. 1(1), 2004, eq. 7-8; signed tetrahedra from
an origin for closed surfaces, Mirtich 1996): for a tetrahedron of volume V
with vertices p_k and S = sum_k p_k,

    int x_i dV     = V S_i / 4        (tetrahedron with apex at the origin:
    int x_i x_j dV = V / 20 (sum_k p_ki p_kj + S_i S_j)    the origin is p_0 = 0)

Eigenvalues of the exact tensor are taken with ``mpmath.eigsy`` at 50 digits.
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction

import mpmath
import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "exact_solid",
    "exact_tetrahedra",
    "exact_points",
    "exact_eigenvalues",
    "exact_moments",
    "relative_error",
    "to_mpf",
    "elliptic_omega",
]

Tensor = list[list[Fraction]]
DIGITS = 50  # mp.dps for eigenvalues: the smallest moment of a 1e-6 needle is 1e-12 of the largest


def _as_integers(values: ArrayLike) -> tuple[np.ndarray, int]:
    """Integers k (object array, same shape) and one exponent e with values == k * 2**e exactly."""
    arr = np.asarray(values, dtype=np.float64)
    if not np.all(np.isfinite(arr)):
        raise ValueError("exact references need finite inputs")
    mant, expo = np.frexp(arr)  # arr = mant * 2**expo, 0.5 <= |mant| < 1
    ints = (mant * 2.0**53).astype(np.int64)  # exact: 53-bit integer mantissas
    expo = expo.astype(np.int64) - 53
    nonzero = ints != 0
    e = int(expo[nonzero].min()) if np.any(nonzero) else 0
    shifts = np.where(nonzero, expo - e, 0)
    flat = [int(k) << int(s) for k, s in zip(ints.ravel().tolist(), shifts.ravel().tolist())]
    out = np.empty(len(flat), dtype=object)
    out[:] = flat
    return out.reshape(arr.shape), e


def _pow2(e: int) -> Fraction:
    return Fraction(2) ** e


def _moments_to_tensor(m0: Fraction, m1: list[Fraction], m2: Tensor) -> tuple[list[Fraction], Tensor]:
    """Centre and inertia tensor about it from int dm, int x dm, int x x^T dm."""
    com = [x / m0 for x in m1]
    cov = [[m2[i][j] - m0 * com[i] * com[j] for j in range(3)] for i in range(3)]
    trace = cov[0][0] + cov[1][1] + cov[2][2]
    tensor = [[(trace if i == j else Fraction(0)) - cov[i][j] for j in range(3)] for i in range(3)]
    return com, tensor  # Landau & Lifshitz eq. (32.2)


BLOCK = 1 << 18  # cells per block: bounds the object-array temporaries to ~100 MB


def _integer_sums(
    points: np.ndarray, cells: np.ndarray, weights: np.ndarray | None, signed: bool
) -> tuple[int, list[int], list[list[int]]]:
    """6 V, 24 int x, 120 int x x^T (times 2**(3e), 2**(4e), 2**(5e)) as exact integers."""
    p = [points[cells[:, k]] for k in range(cells.shape[1])]
    if cells.shape[1] == 3:  # surface triangle + apex at the (integer) origin
        verts, a, b, c = p, p[0], p[1], p[2]
    else:  # tetrahedron p0..p3: edges from p0
        verts = p
        a, b, c = p[1] - p[0], p[2] - p[0], p[3] - p[0]
    det = (
        a[:, 0] * (b[:, 1] * c[:, 2] - b[:, 2] * c[:, 1])
        - a[:, 1] * (b[:, 0] * c[:, 2] - b[:, 2] * c[:, 0])
        + a[:, 2] * (b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0])
    )
    if not signed:
        det = np.abs(det)
    if weights is not None:
        det = det * weights
    s = sum(verts[1:], verts[0])
    m1 = [int((det * s[:, i]).sum()) for i in range(3)]
    m2 = [[0] * 3 for _ in range(3)]
    for i in range(3):
        for j in range(i, 3):
            q = s[:, i] * s[:, j]
            for v in verts:
                q = q + v[:, i] * v[:, j]
            m2[i][j] = m2[j][i] = int((det * q).sum())
    return int(det.sum()), m1, m2


def _integrate(
    points: np.ndarray, e: int, cells: np.ndarray, weights: tuple[np.ndarray, int] | None, signed: bool
) -> tuple[Fraction, list[Fraction], Tensor]:
    """int dm, int x dm, int x x^T dm over simplices (apex at the origin for surfaces)."""
    d0, d1, d2 = 0, [0] * 3, [[0] * 3 for _ in range(3)]
    for start in range(0, len(cells), BLOCK):
        w = None if weights is None else weights[0][start : start + BLOCK]
        b0, b1, b2 = _integer_sums(points, cells[start : start + BLOCK], w, signed)
        d0 += b0
        d1 = [x + y for x, y in zip(d1, b1)]
        d2 = [[x + y for x, y in zip(r1, r2)] for r1, r2 in zip(d2, b2)]
    scale = Fraction(1) if weights is None else _pow2(weights[1])
    m0 = Fraction(d0, 6) * _pow2(3 * e) * scale  # V = det / 6
    m1 = [Fraction(x, 24) * _pow2(4 * e) * scale for x in d1]  # V S / 4
    m2 = [[Fraction(x, 120) * _pow2(5 * e) * scale for x in row] for row in d2]  # V / 20 (...)
    return m0, m1, m2


def _local(points: ArrayLike) -> tuple[np.ndarray, int, list[Fraction]]:
    """Integer coordinates relative to an integer origin (exact), and that origin."""
    ints, e = _as_integers(points)
    origin = ints[0].copy() if len(ints) else np.zeros(3, dtype=object)
    return ints - origin, e, [Fraction(int(o)) * _pow2(e) for o in origin]


def exact_solid(vertices: ArrayLike, faces: ArrayLike) -> tuple[Fraction, list[Fraction], Tensor]:
    """Volume, centre of volume and inertia tensor about it (unit density) of a closed,
    outward-wound triangle surface, exactly, for the float64 vertices as given."""
    pts, e, origin = _local(vertices)
    m0, m1, m2 = _integrate(pts, e, np.asarray(faces, dtype=np.int64), None, signed=True)
    com, tensor = _moments_to_tensor(m0, m1, m2)
    return m0, [c + o for c, o in zip(com, origin)], tensor


def exact_tetrahedra(
    points: ArrayLike, tets: ArrayLike, density: ArrayLike | None = None
) -> tuple[Fraction, list[Fraction], Tensor]:
    """Mass (volume if ``density`` is None), centre of mass and inertia tensor about it
    of a set of tetrahedra with per-cell densities, exactly."""
    pts, e, origin = _local(points)
    weights = None if density is None else _as_integers(density)
    m0, m1, m2 = _integrate(pts, e, np.asarray(tets, dtype=np.int64), weights, signed=False)
    com, tensor = _moments_to_tensor(m0, m1, m2)
    return m0, [c + o for c, o in zip(com, origin)], tensor


def exact_points(masses: ArrayLike, positions: ArrayLike) -> tuple[Fraction, list[Fraction], Tensor]:
    """Total mass, centre of mass and inertia tensor about it of point masses, exactly."""
    m, em = _as_integers(masses)
    x, e, origin = _local(positions)
    m0 = Fraction(int(m.sum())) * _pow2(em)
    m1 = [Fraction(int((m * x[:, i]).sum())) * _pow2(em + e) for i in range(3)]
    m2 = [[Fraction(0)] * 3 for _ in range(3)]
    for i in range(3):
        for j in range(i, 3):
            m2[i][j] = m2[j][i] = Fraction(int((m * x[:, i] * x[:, j]).sum())) * _pow2(em + 2 * e)
    com, tensor = _moments_to_tensor(m0, m1, m2)
    return m0, [c + o for c, o in zip(com, origin)], tensor


def to_mpf(x: Fraction) -> mpmath.mpf:
    with mpmath.workdps(DIGITS):
        return mpmath.mpf(x.numerator) / x.denominator


def exact_eigenvalues(tensor: Sequence[Sequence[Fraction]]) -> list[mpmath.mpf]:
    """Ascending eigenvalues of an exact symmetric 3x3 tensor, to ``DIGITS`` digits."""
    with mpmath.workdps(DIGITS):
        matrix = mpmath.matrix([[to_mpf(x) for x in row] for row in tensor])
        values = mpmath.eigsy(matrix, eigvals_only=True)
        return sorted(values[i] for i in range(3))


def exact_moments(vertices: ArrayLike, faces: ArrayLike) -> list[mpmath.mpf]:
    """Ascending principal moments (unit density) of exactly this polyhedron."""
    return exact_eigenvalues(exact_solid(vertices, faces)[2])


def relative_error(value: float, exact: mpmath.mpf | Fraction) -> float:
    """|value - exact| / |exact|, evaluated at ``DIGITS`` digits (inf for a non-finite value)."""
    if not np.isfinite(value):
        return float("inf")
    with mpmath.workdps(DIGITS):
        ref = to_mpf(exact) if isinstance(exact, Fraction) else mpmath.mpf(exact)
        return float(abs(mpmath.mpf(float(value)) - ref) / abs(ref))


def elliptic_omega(moments: ArrayLike, omega_body: ArrayLike, t: ArrayLike, dps: int = DIGITS) -> np.ndarray:
    """Omega(t) (N, 3) in the body frame of an asymmetric top (I1 < I2 < I3), from the
    closed form of L&L §37 (eqs. 37.10-37.12) evaluated with mpmath's Jacobi
    functions at ``dps`` digits, for the moments exactly as given.

    Written from the textbook without the service's conventions: the
    circulation axis c is x3 when M^2 > 2 E I2, else x1; with a the other
    extreme axis and b = 2 the intermediate one,
    Omega_a = rho A_a cn u, Omega_b = rho s A_b sn u, Omega_c = s A_c dn u,
    u = lambda t + u0; the sign of lambda is fixed by Euler's equations at t = 0
    (the relabelling 1 <-> 3 reverses the sense of rotation).
    """
    with mpmath.workdps(dps):
        I_ = [mpmath.mpf(float(x)) for x in np.asarray(moments, dtype=np.float64)]
        W = [mpmath.mpf(float(x)) for x in np.asarray(omega_body, dtype=np.float64)]
        times = np.asarray(t, dtype=np.float64)
        E2 = sum(I_[i] * W[i] ** 2 for i in range(3))
        M2 = sum((I_[i] * W[i]) ** 2 for i in range(3))
        c, a = (2, 0) if E2 * I_[1] < M2 else (0, 2)
        b = 1
        Ia, Ib, Ic = I_[a], I_[b], I_[c]
        Aa = mpmath.sqrt((E2 * Ic - M2) / (Ia * (Ic - Ia)))
        Ab = mpmath.sqrt((E2 * Ic - M2) / (Ib * (Ic - Ib)))
        Ac = mpmath.sqrt((M2 - E2 * Ia) / (Ic * (Ic - Ia)))
        lam = mpmath.sqrt((Ic - Ib) * (M2 - E2 * Ia) / (Ia * Ib * Ic))
        m = (Ib - Ia) * (E2 * Ic - M2) / ((Ic - Ib) * (M2 - E2 * Ia))
        rho = -1 if W[a] < 0 else 1
        s = -1 if W[c] < 0 else 1
        sn0 = max(-1, min(1, W[b] / (rho * s * Ab)))
        u0 = mpmath.ellipf(mpmath.asin(sn0), m)

        def euler(w: list[mpmath.mpf]) -> list[mpmath.mpf]:
            return [
                (I_[1] - I_[2]) / I_[0] * w[1] * w[2],
                (I_[2] - I_[0]) / I_[1] * w[2] * w[0],
                (I_[0] - I_[1]) / I_[2] * w[0] * w[1],
            ]

        rhs = euler(W)
        # d/du of the formula at u0, component by component; the sign of lambda matches Euler
        dformula = [mpmath.mpf(0)] * 3
        sn, cn, dn = (mpmath.ellipfun(kind, u0, m=m) for kind in ("sn", "cn", "dn"))
        dformula[a] = -rho * Aa * sn * dn
        dformula[b] = rho * s * Ab * cn * dn
        dformula[c] = -s * Ac * m * sn * cn
        k = max(range(3), key=lambda i: abs(rhs[i]))
        if rhs[k] * dformula[k] < 0:
            lam = -lam
        out = np.empty((len(times), 3))
        for n, tn in enumerate(times):
            u = lam * mpmath.mpf(float(tn)) + u0
            sn, cn, dn = (mpmath.ellipfun(kind, u, m=m) for kind in ("sn", "cn", "dn"))
            w = [mpmath.mpf(0)] * 3
            w[a], w[b], w[c] = rho * Aa * cn, rho * s * Ab * sn, s * Ac * dn
            out[n] = [float(x) for x in w]
        return out
