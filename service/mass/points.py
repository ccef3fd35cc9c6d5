"""The sums of a small point set on Python floats, bit for bit those of the numpy kernels.

For a handful of point masses the integrals themselves are a few dozen flops; numpy's cost is its
fixed overhead per call (~1-5 us each, about thirty calls per pass).  This module repeats the same
IEEE operations in the same order on Python floats (``float`` is the same binary64, rounded to
nearest, on every platform Python supports):

- ``ddouble.rotated``: the exact difference (TwoSum) and the compensated dot products (Dekker's
  TwoProduct) are elementwise, so their order is the expression's;
- ``integrals.point_sums``: numpy reduces an (n, 3) array along its rows one row after another,
  starting from 0.0; a contiguous vector is summed pairwise (``pairwise_sum``: numpy's
  ``pairwise_sum``, eight accumulators for up to 128 terms), also after 0.0.

Overflow: the numpy kernels run under ``errstate(over="raise", invalid="raise")``.  Here an overflow
gives an infinity, and every later operation is an addition or a multiplication (no division, no
comparison), so it reaches the sums as an infinity or a NaN: non-finite sums are that same error.
``tests/test_small_points.py`` checks the identity with hypothesis.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..ddouble import SPLIT
from ..integrals import IJ, Sums

__all__ = ["SMALL_POINTS", "Moments", "as_sums", "pairwise_sum", "point_moments", "small_point_sums"]

SMALL_POINTS = 16
"""Point sets up to this size are summed here (numpy wins above a few dozen points)."""


def pairwise_sum(a: list[float]) -> float:
    """numpy's sum of a contiguous float64 vector of at most 128 terms, in its order."""
    n = len(a)
    if n < 8:
        res = 0.0
        for v in a:
            res += v
        return res
    r0, r1, r2, r3, r4, r5, r6, r7 = a[:8]
    stop = n - n % 8
    for i in range(8, stop, 8):
        r0 += a[i]
        r1 += a[i + 1]
        r2 += a[i + 2]
        r3 += a[i + 3]
        r4 += a[i + 4]
        r5 += a[i + 5]
        r6 += a[i + 6]
        r7 += a[i + 7]
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    for i in range(stop, n):
        res += a[i]
    return 0.0 + res


def _shifted(points: list[list[float]], origin: list[float]) -> list[list[float]]:
    """``points - origin``."""
    return [[p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]] for p in points]


def _rotated(points: list[list[float]], origin: list[float], rotation: list[list[float]]) -> list[list[float]]:
    """``ddouble.rotated``: (points - origin) @ rotation, each coordinate rounded once from double-double.

    ``ddouble.two_prod`` and ``two_sum`` are written out in place (Dekker's TwoProduct and Knuth's
    TwoSum, the same operations in the same order), and the three terms of each coordinate unrolled:
    a call per product would cost more than the product.
    """
    split = SPLIT
    n0, n1, n2 = -origin[0], -origin[1], -origin[2]
    # each column of the rotation: its entries r, their high and low halves (Dekker's split), once
    columns = []
    for j in range(3):
        column: list[float] = []
        for i in range(3):
            r = rotation[i][j]
            cr = split * r
            rh = cr - (cr - r)
            column += (r, rh, r - rh)
        columns.append(column)
    out = []
    for x0, x1, x2 in points:
        # d = x - origin as double-double (TwoSum), and the split of its high part
        s0 = x0 + n0
        b = s0 - x0
        l0 = (x0 - (s0 - b)) + (n0 - b)
        c = split * s0
        h0 = c - (c - s0)
        t0 = s0 - h0
        s1 = x1 + n1
        b = s1 - x1
        l1 = (x1 - (s1 - b)) + (n1 - b)
        c = split * s1
        h1 = c - (c - s1)
        t1 = s1 - h1
        s2 = x2 + n2
        b = s2 - x2
        l2 = (x2 - (s2 - b)) + (n2 - b)
        c = split * s2
        h2 = c - (c - s2)
        t2 = s2 - h2
        row = []
        for r0, rh0, rl0, r1, rh1, rl1, r2, rh2, rl2 in columns:
            hi = r0 * s0
            lo = ((rh0 * h0 - hi) + rh0 * t0 + rl0 * h0) + rl0 * t0
            lo = lo + r0 * l0
            q = r1 * s1
            e = ((rh1 * h1 - q) + rh1 * t1 + rl1 * h1) + rl1 * t1
            s = hi + q
            b = s - hi
            lo = lo + (e + ((hi - (s - b)) + (q - b)) + r1 * l1)
            hi = s
            q = r2 * s2
            e = ((rh2 * h2 - q) + rh2 * t2 + rl2 * h2) + rl2 * t2
            s = hi + q
            b = s - hi
            lo = lo + (e + ((hi - (s - b)) + (q - b)) + r2 * l2)
            row.append(s + lo)
        out.append(row)
    return out


Moments = tuple[list[float], list[list[float]], list[float], float]
"""m1, m2, the m2 diagonal summed as ``m (x x)``, and the total mass."""


def point_moments(
    masses: list[float], points: list[list[float]], origin: list[float], rotation: list[list[float]] | None
) -> Moments | None:
    """The point sums about ``origin`` in the frame ``rotation`` as Python floats: m1, m2, the m2
    diagonal's terms summed as ``m (x x)`` (the error scale), and the total mass; None if not finite."""
    x = _shifted(points, origin) if rotation is None else _rotated(points, origin, rotation)
    # under eight points numpy's pairwise sum is a plain one from 0.0: every sum in one loop
    found = _short_sums(masses, x) if len(masses) < 8 else _long_sums(masses, x)
    m1, m2, diag, total = found
    # a finite sum has finite terms; only where it is not (or overflows) is each one looked at
    (a0, a1, a2), ((s00, s01, s02), (_, s11, s12), (_, _, s22)) = m1, m2
    if not math.isfinite(a0 + a1 + a2 + s00 + s01 + s02 + s11 + s12 + s22 + diag[0] + diag[1] + diag[2] + total) and not all(
        math.isfinite(v) for v in (*m1, *m2[0], *m2[1], *m2[2], *diag, total)
    ):
        return None
    return found


def small_point_sums(
    masses: list[float], points: list[list[float]], origin: NDArray[np.float64], rotation: NDArray[np.float64] | None
) -> Sums | None:
    """``integrals.point_sums`` of the points about ``origin`` in the frame ``rotation``; None if not finite."""
    found = point_moments(masses, points, origin.tolist(), None if rotation is None else rotation.tolist())
    return None if found is None else as_sums(found, len(masses))


def as_sums(found: Moments, n: int) -> Sums:
    """``point_moments``' lists as ``integrals.point_sums`` returns them."""
    m1, m2, diag, total = found
    m2_array = np.array(m2)
    return Sums(total, np.array(m1), m2_array, total, np.abs(m2_array), 0.0, np.array(diag), float(n), n, 1)


def _short_sums(masses: list[float], x: list[list[float]]) -> Moments:
    """The sums of fewer than eight points, each accumulated in point order from 0.0 (``pairwise_sum``)."""
    a0 = a1 = a2 = s00 = s11 = s22 = s01 = s02 = s12 = d0 = d1 = d2 = total = 0.0
    for m, (x0, x1, x2) in zip(masses, x):
        mx0, mx1, mx2 = m * x0, m * x1, m * x2
        a0 += mx0
        a1 += mx1
        a2 += mx2
        s00 += mx0 * x0
        s11 += mx1 * x1
        s22 += mx2 * x2
        s01 += mx0 * x1
        s02 += mx0 * x2
        s12 += mx1 * x2
        d0 += m * (x0 * x0)
        d1 += m * (x1 * x1)
        d2 += m * (x2 * x2)
        total += m
    return [a0, a1, a2], [[s00, s01, s02], [s01, s11, s12], [s02, s12, s22]], [d0, d1, d2], total


def _long_sums(masses: list[float], x: list[list[float]]) -> Moments:
    m1 = [0.0, 0.0, 0.0]
    for m, xi in zip(masses, x):
        m1[0] += m * xi[0]
        m1[1] += m * xi[1]
        m1[2] += m * xi[2]
    m2 = [[0.0] * 3 for _ in range(3)]
    for i, j in IJ:
        m2[i][j] = m2[j][i] = pairwise_sum([m * xi[i] * xi[j] for m, xi in zip(masses, x)])
    diag = [pairwise_sum([m * (xi[i] * xi[i]) for m, xi in zip(masses, x)]) for i in range(3)]
    return m1, m2, diag, pairwise_sum(masses)
