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

__all__ = ["jacobi_eigh"]

_PAIRS = ((0, 1), (0, 2), (1, 2))


def jacobi_eigh(
    matrix: NDArray[np.float64], tolerances: Tolerances = DEFAULT_TOLERANCES
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Eigenvalues (unsorted) and eigenvectors (as rows) of a symmetric 3x3 matrix.

    Cyclic Jacobi with the rotation formulas of Rutishauser (Numer. Math. 9,
    1966): t = sgn(theta) / (|theta| + sqrt(theta^2 + 1)), which keeps |angle|
    <= pi/4 so that nearly diagonal input is barely rotated.
    """
    a = np.array(matrix, dtype=np.float64)
    a = 0.5 * (a + a.T)
    exponent = _safe_exponent(a)
    if exponent:
        a = np.ldexp(a, -exponent)
    v = np.eye(3)
    for _ in range(tolerances.jacobi_max_sweeps):
        if _off_diagonal_negligible(a, tolerances.jacobi_rel):
            break
        for p, q in _PAIRS:
            _rotate(a, v, p, q)
    return np.ldexp(np.diag(a), exponent), v.T.copy()


# The negligibility test multiplies two diagonal entries: entries beyond 2**±480 would overflow to inf (every
# off-diagonal then looks negligible and the matrix is returned unrotated) or underflow to 0.  Such a matrix is
# scaled by a power of two, which is exact, and its eigenvalues scaled back; any other is left untouched.
_EXPONENT_RANGE = 480


def _safe_exponent(a: NDArray[np.float64]) -> int:
    largest = float(np.max(np.abs(a)))
    if largest == 0.0 or not math.isfinite(largest):
        return 0
    exponent = math.frexp(largest)[1]
    return exponent if abs(exponent) > _EXPONENT_RANGE else 0


def _off_diagonal_negligible(a: NDArray[np.float64], rel: float) -> bool:
    t = a.tolist()  # Python floats: the same IEEE products and correctly rounded sqrt, without numpy's scalar overhead
    for p, q in _PAIRS:
        scale = math.sqrt(abs(t[p][p] * t[q][q]))
        if abs(t[p][q]) > rel * scale and t[p][q] != 0.0:
            return False
    return True


def _rotate(a: NDArray[np.float64], v: NDArray[np.float64], p: int, q: int) -> None:
    apq = float(a[p, q])
    if apq == 0.0:
        return
    # Python floats, the same IEEE arithmetic as numpy's scalars: where a[p, q] is negligible theta * theta
    # overflows and t goes to 0 as it should, without numpy's overflow warning
    theta = (float(a[q, q]) - float(a[p, p])) / (2.0 * apq)
    t = math.copysign(1.0, theta) / (abs(theta) + math.sqrt(theta * theta + 1.0))
    c = 1.0 / math.sqrt(t * t + 1.0)
    s = t * c
    rot = np.eye(3)
    rot[p, p] = c
    rot[q, q] = c
    rot[p, q] = s
    rot[q, p] = -s
    a[:] = rot.T @ a @ rot
    a[p, q] = a[q, p] = 0.0
    v[:] = v @ rot
