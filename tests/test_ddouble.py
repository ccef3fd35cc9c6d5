"""``ddouble.rotated`` against exact rational arithmetic.

(points - origin) @ rotation is formed in double-double, so each output coordinate is its exact value
rounded, up to the double-double's own error: eps**2 times the magnitudes summed.  The exact value is
computed here with ``fractions.Fraction`` from the same float64 inputs.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia.ddouble import ROTATE_BLOCK, rotated

EPS = 2.0**-53


def _exact(points: np.ndarray, origin: np.ndarray, rotation: np.ndarray) -> list[list[Fraction]]:
    out = []
    for p in points.tolist():
        d = [Fraction(p[i]) - Fraction(float(origin[i])) for i in range(3)]
        out.append([sum((d[i] * Fraction(float(rotation[i, j])) for i in range(3)), Fraction(0)) for j in range(3)])
    return out


def _check(points: np.ndarray, origin: np.ndarray, rotation: np.ndarray) -> None:
    got = rotated(points, origin, rotation)
    for row, (p, exact_row) in enumerate(zip(points, _exact(points, origin, rotation))):
        for j, exact in enumerate(exact_row):
            scale = sum(abs((float(p[i]) - float(origin[i])) * float(rotation[i, j])) for i in range(3))
            allowed = math.ulp(float(exact)) + 8 * EPS * EPS * scale
            assert abs(Fraction(float(got[row, j])) - exact) <= Fraction(allowed), (row, j)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    exponent=st.integers(-200, 200),
    offset=st.sampled_from([0.0, 1e3, 1e8]),
)
def test_rotated_coordinates_are_the_exact_ones_rounded(seed: int, exponent: int, offset: float) -> None:
    rng = np.random.default_rng(seed)
    scale = 2.0**exponent
    origin = rng.normal(size=3) * scale * offset
    points = origin + rng.normal(size=(40, 3)) * scale
    rotation, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    _check(points, origin, rotation)


def test_thin_coordinates_of_a_needle_far_from_the_origin_keep_their_precision() -> None:
    # points 1e8 from the origin along a diagonal, spread 1e-6 across it: the principal frame's thin
    # coordinates are ~1e-14 of the distance, where a float64 dot product would keep none of their digits
    rng = np.random.default_rng(7)
    axis = np.array([1.0, 1.0, 1.0]) / math.sqrt(3.0)
    t = rng.uniform(-1.0, 1.0, size=50)
    across = rng.normal(size=(50, 3)) * 1e-6
    points = 1e8 * axis + np.outer(t, axis) + across
    rotation, _ = np.linalg.qr(np.column_stack([axis, [1.0, -1.0, 0.0], [1.0, 1.0, -2.0]]))
    _check(points, points.mean(axis=0), rotation)


def test_blocks_and_their_boundaries_give_the_rows_alone() -> None:
    rng = np.random.default_rng(3)
    points = rng.normal(size=(2 * ROTATE_BLOCK + 5, 3)) * 1e3
    origin = points.mean(axis=0)
    rotation, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    whole = rotated(points, origin, rotation)
    for start in (0, ROTATE_BLOCK - 1, ROTATE_BLOCK, 2 * ROTATE_BLOCK + 4):
        row = rotated(points[start : start + 1], origin, rotation)
        assert np.array_equal(row.view(np.uint64), whole[start : start + 1].view(np.uint64))
    _check(points[ROTATE_BLOCK - 3 : ROTATE_BLOCK + 3], origin, rotation)
