"""The 3x3 symmetric eigen-kernel: a cyclic Jacobi method.

Jacobi rotations compute every eigenvalue of a positive (semi-)definite matrix
to high *relative* accuracy (Demmel & Veselic, SIAM J. Matrix Anal. Appl. 13,
1992), unlike a tridiagonal QR whose error is relative to the largest moment:
that matters for the smallest moment of a needle, which can be 1e-12 of the
largest.  It is also a fixed sequence of float operations, so results are
bit-identical on every run.  A kernel beside ``integrals``: the mass stage
refines with it and the principal stage orders its output.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from .tolerances import DEFAULT_TOLERANCES, Tolerances

__all__ = ["jacobi_eigh", "jacobi_lists"]

_PAIRS = ((0, 1), (0, 2), (1, 2))
_TRIPLES = ((0, 1, 2), (0, 2, 1), (1, 2, 0))  # each pair (p, q) of the sweep, and the third index r


def jacobi_eigh(
    matrix: NDArray[np.float64], tolerances: Tolerances = DEFAULT_TOLERANCES
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Eigenvalues (unsorted) and eigenvectors (as rows) of a symmetric 3x3 matrix.

    Cyclic Jacobi with the rotation formulas of Rutishauser (Numer. Math. 9,
    1966): t = sgn(theta) / (|theta| + sqrt(theta^2 + 1)), which keeps |angle|
    <= pi/4 so that nearly diagonal input is barely rotated, and the updates
    a_pp - t a_pq, a_qq + t a_pq, which change a diagonal entry by exactly the
    amount the rotation moves between the two.
    """
    values, v = jacobi_lists(np.asarray(matrix, dtype=np.float64).tolist(), tolerances)
    return np.array(values), np.array(v).T.copy()


def jacobi_lists(m: list[list[float]], tolerances: Tolerances = DEFAULT_TOLERANCES) -> tuple[list[float], list[list[float]]]:
    """``jacobi_eigh`` on Python floats: the eigenvalues, and the eigenvectors as the *columns* of ``v``."""
    # Python floats: the same IEEE binary64 operations as numpy's, without its overhead per call on a 3x3.
    # Symmetrised without overflow: an entry equal to its mirror stays itself (even above 9e307, where x + x
    # is inf); otherwise 0.5 x + 0.5 y is the rounded mean, as 0.5 (x + y) is wherever that does not overflow
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = m
    # a diagonal entry is its own mean; each off-diagonal one keeps its own side's sign of zero
    a = [
        [m00, _mean(m01, m10), _mean(m02, m20)],
        [_mean(m10, m01), m11, _mean(m12, m21)],
        [_mean(m20, m02), _mean(m21, m12), m22],
    ]
    exponent = _safe_exponent(a)
    if exponent:
        a = [[math.ldexp(x, -exponent) for x in row] for row in a]
    v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    for _ in range(tolerances.jacobi_max_sweeps):
        if _off_diagonal_negligible(a, tolerances.jacobi_rel):
            break
        for p, q, r in _TRIPLES:
            _rotate(a[p], a[q], a[r], v, p, q, r)
    return [math.ldexp(a[0][0], exponent), math.ldexp(a[1][1], exponent), math.ldexp(a[2][2], exponent)], v


# The negligibility test multiplies two diagonal entries: entries beyond 2**±480 would overflow to inf (every
# off-diagonal then looks negligible and the matrix is returned unrotated) or underflow to 0.  Such a matrix is
# scaled by a power of two, which is exact, and its eigenvalues scaled back; any other is left untouched.
_EXPONENT_RANGE = 480


def _mean(x: float, y: float) -> float:
    return x if x == y else 0.5 * x + 0.5 * y


def _safe_exponent(a: list[list[float]]) -> int:
    entries = a[0] + a[1] + a[2]
    if not all(map(math.isfinite, entries)):  # NaN or inf: nothing to rescale (max would skip a NaN)
        return 0
    largest = max(map(abs, entries))
    if largest == 0.0:
        return 0
    exponent = math.frexp(largest)[1]
    return exponent if abs(exponent) > _EXPONENT_RANGE else 0


def _off_diagonal_negligible(a: list[list[float]], rel: float) -> bool:
    for p, q in _PAIRS:
        scale = math.sqrt(abs(a[p][p] * a[q][q]))
        if abs(a[p][q]) > rel * scale and a[p][q] != 0.0:
            return False
    return True


def _rotate(ap: list[float], aq: list[float], ar: list[float], v: list[list[float]], p: int, q: int, r: int) -> None:
    """One rotation in the (p, q) plane: a <- R^T a R and v <- v R, R = [[c, s], [-s, c]] in rows and
    columns p, q, chosen so that the new a[p][q] is zero.  ``ap``, ``aq``, ``ar`` are the rows p, q and
    r of a, r the third index."""
    apq = ap[q]
    if apq == 0.0:
        return
    # where a[p][q] is negligible theta * theta overflows to inf (Python floats raise no warning for it)
    # and t goes to 0 as it should
    theta = (aq[q] - ap[p]) / (2.0 * apq)
    t = math.copysign(1.0, theta) / (abs(theta) + math.sqrt(theta * theta + 1.0))
    c = 1.0 / math.sqrt(t * t + 1.0)
    s = t * c
    tau = s / (1.0 + c)  # c = 1 - s tau: the off-plane updates below add a small correction to each entry
    ap[p] -= t * apq
    aq[q] += t * apq
    ap[q] = aq[p] = 0.0
    arp, arq = ar[p], ar[q]
    ar[p] = ap[r] = arp - s * (arq + tau * arp)
    ar[q] = aq[r] = arq + s * (arp - tau * arq)
    for row in v:
        vp, vq = row[p], row[q]
        row[p] = vp - s * (vq + tau * vp)
        row[q] = vq + s * (vp - tau * vq)
