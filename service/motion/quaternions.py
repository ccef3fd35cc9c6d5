"""Vectorised unit quaternions [w, x, y, z] (scalar first, ``service.conventions``).

All functions broadcast over leading axes.  ``q`` represents the rotation
v -> q v q*, i.e. the matrix ``conventions.matrix_from_quaternion(q)``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "multiply",
    "conjugate",
    "rotate",
    "from_axis_angle",
    "from_matrices",
    "to_matrices",
    "canonical",
]

Array = NDArray[np.float64]


def multiply(a: ArrayLike, b: ArrayLike) -> Array:
    """Hamilton product a b (apply b first, then a)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def conjugate(q: ArrayLike) -> Array:
    """Inverse of a unit quaternion."""
    out = np.array(q, dtype=np.float64)
    out[..., 1:] *= -1.0
    return out


def rotate(q: ArrayLike, v: ArrayLike) -> Array:
    """Rotate vectors v (..., 3) by unit quaternions q (..., 4).

    v' = v + 2 w (u x v) + 2 u x (u x v), u the vector part: two cross
    products, no matrix, exact for the identity.
    """
    q = np.asarray(q, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    w = q[..., :1]
    u = q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def from_axis_angle(axis: ArrayLike, angle: ArrayLike) -> Array:
    """Rotation by ``angle`` [rad] about the unit ``axis`` (right-hand rule)."""
    axis = np.asarray(axis, dtype=np.float64)
    half = 0.5 * np.asarray(angle, dtype=np.float64)
    s = np.sin(half)[..., None]
    return np.concatenate([np.cos(half)[..., None], s * axis], axis=-1)


def canonical(q: ArrayLike) -> Array:
    """Normalise and pick the sign with w >= 0 (``service.conventions``)."""
    arr = np.asarray(q, dtype=np.float64)
    unit = arr / np.linalg.norm(arr, axis=-1, keepdims=True)
    signed: Array = np.where(unit[..., :1] < 0.0, -unit, unit)
    return signed


def to_matrices(q: ArrayLike) -> Array:
    """Rotation matrices (..., 3, 3) of unit quaternions (..., 4)."""
    q = np.asarray(q, dtype=np.float64)
    w, x, y, z = np.moveaxis(q, -1, 0)
    rows = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def from_matrices(m: ArrayLike) -> Array:
    """Unit quaternions (w >= 0) of rotation matrices (..., 3, 3).

    Shepperd's method (J. Guidance and Control 1, 1978), vectorised: for each
    matrix divide by the largest of the four squared components, so no
    branch loses precision (as ``conventions.quaternion_from_matrix``).
    """
    m = np.asarray(m, dtype=np.float64)
    m00, m11, m22 = m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]
    d21, d02, d10 = m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0], m[..., 1, 0] - m[..., 0, 1]
    s01, s02, s12 = m[..., 0, 1] + m[..., 1, 0], m[..., 0, 2] + m[..., 2, 0], m[..., 1, 2] + m[..., 2, 1]
    # 4 q_i^2 for i = w, x, y, z
    sq = np.stack([1 + m00 + m11 + m22, 1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22], -1)
    k = np.argmax(sq, axis=-1)
    r = 0.5 * np.sqrt(np.maximum(np.take_along_axis(sq, k[..., None], -1)[..., 0], 0.0))
    inv = 0.25 / r
    cand = np.stack(
        [
            np.stack([r, d21 * inv, d02 * inv, d10 * inv], -1),
            np.stack([d21 * inv, r, s01 * inv, s02 * inv], -1),
            np.stack([d02 * inv, s01 * inv, r, s12 * inv], -1),
            np.stack([d10 * inv, s02 * inv, s12 * inv, r], -1),
        ],
        -2,
    )
    q = np.take_along_axis(cand, k[..., None, None], -2)[..., 0, :]
    return canonical(q)
