"""Double-double arithmetic for rotating coordinates without losing small ones.

Error-free transformations: TwoSum (Knuth, TAOCP vol. 2, 4.2.2) and
TwoProduct by Dekker's splitting (Dekker, Numer. Math. 18, 1971), combined
into compensated dot products (Ogita, Rump & Oishi, SIAM J. Sci. Comput. 26,
2005).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["two_sum", "two_prod", "rotated"]

_SPLIT = 134217729.0  # 2^27 + 1, Dekker's splitting constant for float64


def two_sum(a: NDArray[np.float64], b: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)  # Knuth, TAOCP vol. 2, 4.2.2


def two_prod(a: NDArray[np.float64] | float, b: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    p = a * b
    ca = _SPLIT * a
    ah = ca - (ca - a)
    al = a - ah
    cb = _SPLIT * b
    bh = cb - (cb - b)
    bl = b - bh
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl  # Dekker 1971


def rotated(points: NDArray[np.float64], origin: NDArray[np.float64], rotation: NDArray[np.float64]) -> NDArray[np.float64]:
    """(points - origin) @ rotation, each result rounded once from exact.

    The difference and the dot products are carried in double-double
    (Ogita, Rump & Oishi, SIAM J. Sci. Comput. 26, 2005), so a rotated
    coordinate is accurate to its own last bit, however small it is next to
    the body's size: the thin coordinates of a needle in its principal frame
    keep full relative precision.
    """
    n = len(points)
    d_hi = np.empty((n, 3))
    d_lo = np.empty((n, 3))
    for i in range(3):
        d_hi[:, i], d_lo[:, i] = two_sum(points[:, i], np.full(n, -origin[i]))
    out = np.empty((n, 3))
    for j in range(3):
        hi, lo = two_prod(rotation[0, j], d_hi[:, 0])
        lo = lo + rotation[0, j] * d_lo[:, 0]
        for i in (1, 2):
            p, e = two_prod(rotation[i, j], d_hi[:, i])
            hi, e2 = two_sum(hi, p)
            lo = lo + (e + e2 + rotation[i, j] * d_lo[:, i])
        out[:, j] = hi + lo
    return out
