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


def two_sum(a: NDArray[np.float64], b: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
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


ROTATE_BLOCK = 1 << 14  # points per block in ``rotated``: its (n, 3) temporaries stay ~400 KB


def rotated(points: NDArray[np.float64], origin: NDArray[np.float64], rotation: NDArray[np.float64]) -> NDArray[np.float64]:
    """(points - origin) @ rotation, each result rounded once from exact.

    The difference and the dot products are carried in double-double
    (Ogita, Rump & Oishi, SIAM J. Sci. Comput. 26, 2005), so a rotated
    coordinate is accurate to its own last bit, however small it is next to
    the body's size: the thin coordinates of a needle in its principal frame
    keep full relative precision.  The three output coordinates of a block
    of points are formed together, as (n, 3) arrays.
    """
    out = np.empty((len(points), 3))

    def rotate_block(start: int) -> None:
        block = points[start : start + ROTATE_BLOCK]
        d_hi, d_lo = two_sum(block, np.broadcast_to(-origin, block.shape))  # the exact difference
        # output coordinate j sums rotation[i, j] * d[:, i] over i: rows of ``rotation`` broadcast over j
        hi, lo = two_prod(rotation[0], d_hi[:, 0:1])
        lo = lo + rotation[0] * d_lo[:, 0:1]
        for i in (1, 2):
            p, e = two_prod(rotation[i], d_hi[:, i : i + 1])
            hi, e2 = two_sum(hi, p)
            lo = lo + (e + e2 + rotation[i] * d_lo[:, i : i + 1])
        out[start : start + ROTATE_BLOCK] = hi + lo

    for_each_block(rotate_block, range(0, len(points), ROTATE_BLOCK))
    return out
