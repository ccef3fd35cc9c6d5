"""Huge and tiny scales: a power-of-two change of scale changes the results by exactly that power.

Scaling a body's tensor by 2**k is exact in floating point, so every eigenvalue must scale by exactly 2**k
and the eigenvectors must not change at all, until the values themselves leave float64's range.  Before the
eigen-kernel rescaled such matrices, the product of two diagonal entries overflowed above ~2**512: every
off-diagonal then looked negligible and a rotated tensor came back unrotated, its "principal moments" the
diagonal of the rotated matrix (43 % off for a box 1e40 m across).
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia.eigen import jacobi_eigh

_ROTATION_ANGLES = st.tuples(*(st.floats(-math.pi, math.pi) for _ in range(3)))
_MOMENTS = st.tuples(*(st.floats(0.01, 100.0) for _ in range(3)))


def _rotation(angles: tuple[float, float, float]) -> np.ndarray:
    ax, ay, az = angles
    rx = np.array([[1, 0, 0], [0, math.cos(ax), -math.sin(ax)], [0, math.sin(ax), math.cos(ax)]])
    ry = np.array([[math.cos(ay), 0, math.sin(ay)], [0, 1, 0], [-math.sin(ay), 0, math.cos(ay)]])
    rz = np.array([[math.cos(az), -math.sin(az), 0], [math.sin(az), math.cos(az), 0], [0, 0, 1]])
    rotation: np.ndarray = rz @ ry @ rx
    return rotation


@settings(max_examples=60, deadline=None)
@given(_ROTATION_ANGLES, _MOMENTS, st.integers(-1000, 1000))
def test_eigen_kernel_is_exactly_scale_invariant(
    angles: tuple[float, float, float], moments: tuple[float, float, float], exponent: int
) -> None:
    rotation = _rotation(angles)
    tensor = rotation @ np.diag(moments) @ rotation.T
    tensor = 0.5 * (tensor + tensor.T)
    values, vectors = jacobi_eigh(tensor)
    scaled_values, scaled_vectors = jacobi_eigh(np.ldexp(tensor, exponent))
    assert np.array_equal(scaled_values, np.ldexp(values, exponent))
    assert np.array_equal(scaled_vectors, vectors)


def test_rotated_tensor_of_1e200_is_diagonalised() -> None:
    rotation = _rotation((0.3, 0.5, 0.7))
    moments = np.array([1.0, 2.0, 3.0])
    tensor = rotation @ np.diag(moments) @ rotation.T * 1e200
    values, vectors = jacobi_eigh(tensor)
    order = np.argsort(values)
    assert np.allclose(values[order] / 1e200, moments, rtol=1e-14, atol=0)
    # each eigenvector is (up to sign) a column of the rotation
    alignment = np.abs(vectors[order] @ rotation)
    assert np.allclose(alignment, np.eye(3), atol=1e-14)
