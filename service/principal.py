"""Principal frame: ascending principal moments, right-handed principal axes.

The eigen-decomposition is ``eigen.jacobi_eigh``, a cyclic Jacobi method with
high relative accuracy for every moment, the smallest of a needle included.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .arrays import freeze_fields
from .conventions import orient_axes, quaternion_from_matrix
from .eigen import jacobi_eigh
from .errors import InvalidParameterError
from .tolerances import DEFAULT_TOLERANCES

if TYPE_CHECKING:
    from .mass import MassProperties

__all__ = ["PrincipalFrame", "principal_frame", "equal_moment_pairs"]


@dataclass(frozen=True, slots=True)
class PrincipalFrame:
    """Principal moments and axes of a body about its centre of mass.

    moments : (3,) float [kg m^2], ascending.
    axes : (3, 3) float, rows are unit principal axes in the input frame,
        right-handed, signs by ``conventions.orient_axes``.
    quaternion : (4,) float, [w, x, y, z], rotates principal-frame vectors
        into the input frame (its matrix is ``axes.T``).
    unique_axes : False where two moments are equal within ``tolerance``.
    tolerance : the relative tolerance used for ``unique_axes``.
    """

    moments: NDArray[np.float64]
    axes: NDArray[np.float64]
    quaternion: NDArray[np.float64]
    unique_axes: bool
    tolerance: float

    def __post_init__(self) -> None:
        freeze_fields(self, {"moments": (3,), "axes": (3, 3), "quaternion": (4,)})

    @classmethod
    def from_eigen(
        cls,
        values: NDArray[np.float64],
        vectors: NDArray[np.float64],
        tolerance: float = DEFAULT_TOLERANCES.moment_rel,
    ) -> PrincipalFrame:
        """Sort eigenpairs ascending, orient the axes, derive the quaternion."""
        order = np.argsort(values, kind="stable")
        moments = np.asarray(values, dtype=np.float64)[order]
        axes = orient_axes(np.asarray(vectors, dtype=np.float64)[order])
        unique = not equal_moment_pairs(moments, tolerance)
        return cls(moments, axes, quaternion_from_matrix(axes.T), unique, tolerance)

    @classmethod
    def from_tensor(
        cls, tensor: NDArray[np.float64], tolerance: float = DEFAULT_TOLERANCES.moment_rel
    ) -> PrincipalFrame:
        """Principal frame of an inertia tensor about the centre of mass."""
        matrix = np.asarray(tensor, dtype=np.float64)
        if matrix.shape != (3, 3) or not np.all(np.isfinite(matrix)):
            raise InvalidParameterError("the inertia tensor must be a finite 3x3 matrix")
        if not np.allclose(matrix, matrix.T, rtol=1e-9, atol=1e-12 * np.abs(matrix).max()):
            raise InvalidParameterError("the inertia tensor must be symmetric")
        values, vectors = jacobi_eigh(matrix)
        _check_physical(np.sort(values), tolerance)
        return cls.from_eigen(values, vectors, tolerance)

    def as_rotation_matrix(self) -> NDArray[np.float64]:
        """Matrix carrying principal-frame components into the input frame."""
        return np.array(self.axes.T)


def _check_physical(moments: NDArray[np.float64], tolerance: float) -> None:
    scale = moments[2]
    if not scale > 0:
        raise InvalidParameterError("principal moments must be positive; got a zero or negative tensor")
    if moments[0] < -tolerance * scale:
        raise InvalidParameterError(
            f"the tensor has a negative principal moment ({moments[0]:.6g} kg m^2); it is not an inertia tensor"
        )
    if moments[0] + moments[1] < moments[2] * (1 - tolerance):
        raise InvalidParameterError(
            "principal moments break the triangle inequality I1 + I2 >= I3; no body has this tensor"
        )


def equal_moment_pairs(moments: NDArray[np.float64], tolerance: float) -> tuple[tuple[int, int], ...]:
    """Pairs of sorted moments equal within ``tolerance`` x largest moment.

    The decision looks at all gaps at once, so it cannot depend on the order of
    comparisons: all three are equal when the whole spread is within
    tolerance; otherwise only the smaller gap can be an equal pair.
    """
    i1, i2, i3 = (float(x) for x in moments)
    limit = tolerance * abs(i3)
    if i3 - i1 <= limit:
        return ((0, 1), (0, 2), (1, 2))
    gap12, gap23 = i2 - i1, i3 - i2
    if gap12 <= limit and gap12 <= gap23:
        return ((0, 1),)
    if gap23 <= limit and gap23 < gap12:
        return ((1, 2),)
    return ()


def principal_frame(props: MassProperties, tolerance: float = DEFAULT_TOLERANCES.moment_rel) -> PrincipalFrame:
    """Principal frame of the mass properties (moments refined in the body frame)."""
    return PrincipalFrame.from_eigen(props.principal_moments, props.principal_axes, tolerance)
