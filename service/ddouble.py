"""Double-double arithmetic for rotating coordinates without losing small ones.

Error-free transformations: TwoSum (Knuth, TAOCP vol. 2, 4.2.2) and
TwoProduct by Dekker's splitting (Dekker, Numer. Math. 18, 1971), combined
into compensated dot products (Ogita, Rump & Oishi, SIAM J. Sci. Comput. 26,
2005).
"""

from __future__ import annotations

from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from .blocks import for_each_block

__all__ = ["SPLIT", "rotated", "two_prod", "two_sum"]

SPLIT = 134217729.0  # 2^27 + 1, Dekker's splitting constant for float64

# The same operations on Python floats (the small point-set path) or on arrays
Real = TypeVar("Real", float, NDArray[np.float64])


def two_sum(a: NDArray[np.float64], b: NDArray[np.float64] | float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)  # Knuth, TAOCP vol. 2, 4.2.2


def two_prod(a: Real | float, b: Real) -> tuple[Real, Real]:
    p = a * b
    ca = SPLIT * a
    ah = ca - (ca - a)
    al = a - ah
    cb = SPLIT * b
    bh = cb - (cb - b)
    bl = b - bh
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl  # Dekker 1971


ROTATE_BLOCK = 1 << 14  # points per block in ``rotated``: its (n,) temporaries stay ~130 KB


def _split(a: Real) -> tuple[Real, Real]:
    """Dekker's halves of ``a``: the high 26 bits and the rest, ``two_prod``'s first step."""
    ca = SPLIT * a
    ah = ca - (ca - a)
    return ah, a - ah


def rotated(points: NDArray[np.float64], origin: NDArray[np.float64], rotation: NDArray[np.float64]) -> NDArray[np.float64]:
    """(points - origin) @ rotation, each result rounded once from exact.

    The difference and the dot products are carried in double-double
    (Ogita, Rump & Oishi, SIAM J. Sci. Comput. 26, 2005), so a rotated
    coordinate is accurate to its own last bit, however small it is next to
    the body's size: the thin coordinates of a needle in its principal frame
    keep full relative precision.  A block of points is taken one coordinate
    column at a time, each a contiguous (n,) array, and each difference is
    split into Dekker's halves once for the three outputs it enters: the
    operations on every element are ``two_sum`` and ``two_prod``'s, in their
    order, without numpy's slow inner loops over rows of three.
    """
    out = np.empty((len(points), 3))
    r = [[float(v) for v in row] for row in rotation]
    r_halves = [[_split(v) for v in row] for row in r]

    def rotate_block(start: int) -> None:
        block = points[start : start + ROTATE_BLOCK]
        d_hi, d_lo, d_halves = [], [], []
        for i in range(3):
            hi, lo = two_sum(np.ascontiguousarray(block[:, i]), np.float64(-origin[i]))  # the exact difference
            d_hi.append(hi)
            d_lo.append(lo)
            d_halves.append(_split(hi))
        for j in range(3):  # output coordinate j sums rotation[i, j] * d_i over i
            hi, lo = _two_prod_split(r[0][j], r_halves[0][j], d_hi[0], d_halves[0])
            lo += r[0][j] * d_lo[0]
            for i in (1, 2):
                p, e = _two_prod_split(r[i][j], r_halves[i][j], d_hi[i], d_halves[i])
                hi, e2 = two_sum(hi, p)
                e += e2
                e += r[i][j] * d_lo[i]
                lo += e
            hi += lo
            out[start : start + ROTATE_BLOCK, j] = hi

    for_each_block(rotate_block, range(0, len(points), ROTATE_BLOCK))
    return out


def _two_prod_split(
    a: float, a_halves: tuple[float, float], b: NDArray[np.float64], b_halves: tuple[NDArray[np.float64], NDArray[np.float64]]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``two_prod(a, b)`` with both factors already split (``_split``): the same operations, in the same order."""
    (ah, al), (bh, bl) = a_halves, b_halves
    p = a * b
    err = ah * bh
    err -= p
    err += ah * bl
    err += al * bh
    err += al * bl
    return p, err
