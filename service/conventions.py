"""Conventions stated once: units, frames, axis order and the eigenvector sign rule.

- Inside the service everything is SI: metres, kilograms, seconds, radians,
  kg m^2 for inertia.  Lengths in other units are converted at the edge.
- The *input frame* is the frame of the uploaded coordinates.  The *principal*
  (body) frame has its axes along the principal axes of inertia, ordered by
  ascending moment (I1 <= I2 <= I3).
- Principal axes are the rows of a 3x3 matrix ``axes``; ``axes.T`` maps
  principal-frame components to input-frame components.  The frame is
  right-handed (det = +1).
- Sign rule: the component of largest magnitude of axes 1 and 2 is positive
  (the first such component on an exact tie); axis 3 = axis 1 x axis 2.
- Quaternions are [w, x, y, z] with w >= 0 (scalar first, as in the contract).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "DEFAULT_DENSITY",
    "LENGTH_UNITS",
    "length_scale",
    "orient_axes",
    "quaternion_from_matrix",
    "matrix_from_quaternion",
]

DEFAULT_DENSITY = 1000.0  # kg/m^3 (water), the API's default when neither density nor mass is given

LENGTH_UNITS: dict[str, float] = {
    "m": 1.0,
    "cm": 1e-2,
    "mm": 1e-3,
    "um": 1e-6,
    "in": 0.0254,  # exact by the 1959 international yard and pound agreement
    "ft": 0.3048,
    "angstrom": 1e-10,  # molecules (XYZ files, points); exact by definition
}


def length_scale(unit: str) -> float:
    """Metres per unit of ``unit``; raises ``InvalidParameterError`` when unknown."""
    from .errors import InvalidParameterError

    try:
        return LENGTH_UNITS[unit]
    except KeyError:
        known = ", ".join(LENGTH_UNITS)
        raise InvalidParameterError(f"unknown length unit {unit!r}; use one of {known}", parameter="units") from None


def orient_axes(axes: NDArray[np.float64] | list[list[float]]) -> NDArray[np.float64]:
    """Apply the sign rule to unit axes given as rows (an array, or lists of floats); returns a new array."""
    # Python floats for the 3x3 steps (numpy's per-call cost is most of the time on arrays this small); a
    # negation, the cross product's products and differences and the division by its norm round as
    # numpy's do, the norm stays numpy's (the same v.dot(v)); x + 0.0 turns -0.0 into 0.0 as numpy's does
    rows = list(axes) if isinstance(axes, list) else np.asarray(axes, dtype=np.float64).tolist()
    for i in (0, 1):
        row = rows[i]
        x0, x1, x2 = row
        if not math.isfinite(x0 + x1 + x2) and not all(math.isfinite(x) for x in row):
            k = int(np.argmax(np.abs(row)))  # numpy's argmax takes the first NaN: keep its rule
        else:
            m0, m1, m2 = abs(x0), abs(x1), abs(x2)
            k = 0 if m0 >= m1 and m0 >= m2 else (1 if m1 >= m2 else 2)  # the first maximum, as argmax
        if row[k] < 0:
            rows[i] = [-x0, -x1, -x2]
    (a0, a1, a2), (b0, b1, b2) = rows[0], rows[1]
    c0, c1, c2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0  # a x b
    n = _norm(np.array([c0, c1, c2]))
    return np.array([[a0 + 0.0, a1 + 0.0, a2 + 0.0], [b0 + 0.0, b1 + 0.0, b2 + 0.0], [c0 / n + 0.0, c1 / n + 0.0, c2 / n + 0.0]])


def _norm(v: NDArray[np.float64]) -> float:
    """``np.linalg.norm`` of a contiguous float64 vector without its dispatch: the root of the same
    ``v.dot(v)`` (BLAS, which may fuse its multiply-adds), correctly rounded in both."""
    return math.sqrt(float(v.dot(v)))


def _sqrt(x: float) -> float:
    """math.sqrt where it is defined; numpy's (NaN, with its warning) elsewhere, as before."""
    return math.sqrt(x) if x >= 0.0 else float(np.sqrt(x))


def quaternion_from_matrix(matrix: NDArray[np.float64]) -> NDArray[np.float64]:
    """Unit quaternion [w, x, y, z] (w >= 0) of a proper rotation matrix.

    Shepperd's method (J. Guidance and Control 1, 1978): pick the largest of
    the four squared components to divide by, so no step loses precision.
    """
    # Python floats (bit for bit numpy's scalar arithmetic: +, -, *, / and sqrt are correctly rounded in both)
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = np.asarray(matrix, dtype=np.float64).tolist()
    trace = m00 + m11 + m22
    candidates = (trace, m00, m11, m22)
    k = int(np.argmax(candidates)) if not all(math.isfinite(c) for c in candidates) else candidates.index(max(candidates))
    if k == 0:
        s = 2.0 * _sqrt(1.0 + trace)
        q = [0.25 * s, (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s]
    elif k == 1:
        s = 2.0 * _sqrt(1.0 + m00 - m11 - m22)
        q = [(m21 - m12) / s, 0.25 * s, (m01 + m10) / s, (m02 + m20) / s]
    elif k == 2:
        s = 2.0 * _sqrt(1.0 - m00 + m11 - m22)
        q = [(m02 - m20) / s, (m01 + m10) / s, 0.25 * s, (m12 + m21) / s]
    else:
        s = 2.0 * _sqrt(1.0 - m00 - m11 + m22)
        q = [(m10 - m01) / s, (m02 + m20) / s, (m12 + m21) / s, 0.25 * s]
    n = _norm(np.array(q, dtype=np.float64))
    w, x, y, z = q[0] / n, q[1] / n, q[2] / n, q[3] / n
    return np.array([-w, -x, -y, -z] if w < 0 else [w, x, y, z])


def matrix_from_quaternion(quaternion: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rotation matrix of a unit quaternion [w, x, y, z]."""
    w, x, y, z = np.asarray(quaternion, dtype=np.float64)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
