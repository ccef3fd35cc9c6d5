"""Principal frame: ascending principal moments, right-handed principal axes.

The eigen-decomposition is ``eigen.jacobi_eigh``, a cyclic Jacobi method with
high relative accuracy for every moment, the smallest of a needle included.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .arrays import freeze_fields
from .conventions import orient_axes, quaternion_from_matrix
from .eigen import jacobi_eigh
from .errors import InvalidParameterError
from .tolerances import DEFAULT_TOLERANCES, EPS

if TYPE_CHECKING:
    from .mass import MassProperties

__all__ = ["PrincipalFrame", "principal_frame", "equal_moment_pairs", "TensorFrame", "tensor_frame", "TENSOR_ERROR_FACTOR"]

TENSOR_ERROR_FACTOR = 17 * EPS
"""Absolute error of every eigenvalue of a given 3x3 tensor, times its Frobenius norm.

Jacobi's rotations are orthogonal to rounding, so the computed eigenvalues are
exact for a tensor within a few eps x ||T||_F of the one given (backward
error; Golub & Van Loan, Matrix Computations, §8.5), and Weyl's inequality
moves each eigenvalue by at most that perturbation's norm.  16 eps covers the
rotations of the sweeps; one more eps/2 x ||T||_F covers the rounding of the
input's own entries (each float64 entry is within half an ulp of the tensor
the user meant).  The Frobenius norm is at least the largest moment, so the
bound is ~17 eps I3 whatever the orientation: relative to moment i it is
~17 eps I3 / Ii, large for the smallest moment of a needle-like tensor."""


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
        cls, tensor: NDArray[np.float64], tolerance: float = DEFAULT_TOLERANCES.moment_rel, rounding: float = 0.0
    ) -> PrincipalFrame:
        """Principal frame of an inertia tensor about the centre of mass.

        rounding : [kg m^2] absolute error of the computed moments; a moment
            below ``-rounding`` is refused as negative (default: any negative one).
        """
        matrix = np.asarray(tensor, dtype=np.float64)
        if matrix.shape != (3, 3) or not np.all(np.isfinite(matrix)):
            raise InvalidParameterError("the inertia tensor must be a finite 3x3 matrix")
        if not np.allclose(matrix, matrix.T, rtol=1e-9, atol=1e-12 * np.abs(matrix).max()):
            raise InvalidParameterError("the inertia tensor must be symmetric")
        values, vectors = jacobi_eigh(matrix)
        _check_physical(np.sort(values), tolerance, rounding)
        return cls.from_eigen(values, vectors, tolerance)

    def as_rotation_matrix(self) -> NDArray[np.float64]:
        """Matrix carrying principal-frame components into the input frame."""
        return np.array(self.axes.T)


def _check_physical(moments: NDArray[np.float64], tolerance: float, rounding: float = 0.0) -> None:
    scale = moments[2]
    if not scale > 0:
        raise InvalidParameterError("principal moments must be positive; got a zero or negative tensor")
    if moments[0] < -rounding:
        raise InvalidParameterError(
            f"the tensor has a negative principal moment ({moments[0]:.6g} kg m^2); it is not an inertia tensor"
        )
    if 0.5 * float(moments[0]) + 0.5 * float(moments[1]) < 0.5 * float(moments[2]) * (1 - tolerance):  # halves: no overflow
        raise InvalidParameterError("principal moments break the triangle inequality I1 + I2 >= I3; no body has this tensor")


@dataclass(frozen=True, slots=True)
class TensorFrame:
    """The principal frame of a given tensor, with error bounds from the eigenproblem's conditioning.

    moment_errors : (3,) [kg m^2] absolute error bound of each moment (ascending order).
    relative_error_estimate : the largest moment error over its moment, among the
        moments larger than their own bound (those within it are reported as 0).
    axes_error : [rad] bound on the angle error of the unique axes, moment error
        over the smallest gap to another moment (Davis-Kahan); inf where two
        moments are equal within their errors (the axes are then any in their plane).
    warnings : what was assumed (a moment zero within rounding).
    """

    frame: PrincipalFrame
    moment_errors: NDArray[np.float64]
    relative_error_estimate: float
    axes_error: float
    warnings: tuple[str, ...]


def tensor_frame(tensor: NDArray[np.float64], tolerance: float = DEFAULT_TOLERANCES.moment_rel) -> TensorFrame:
    """Principal frame of a tensor given by a client, with an estimate from its conditioning.

    The absolute error of every eigenvalue is ``TENSOR_ERROR_FACTOR`` x ||T||_F,
    so moment i carries a relative error ~ 17 eps I3 / Ii.  A moment within its
    bound of zero is zero to rounding (a linear rotator's I1): it is reported as
    0 with a warning, never as a tiny negative number.  A moment below minus its
    bound is refused (no body has a negative moment).
    """
    matrix = np.asarray(tensor, dtype=np.float64)
    if matrix.shape != (3, 3) or not np.all(np.isfinite(matrix)):
        raise InvalidParameterError("the inertia tensor must be a finite 3x3 matrix")
    scale = float(np.sqrt(np.sum((matrix / max(float(np.abs(matrix).max()), 1e-300)) ** 2))) * float(np.abs(matrix).max())
    if not np.isfinite(scale):
        raise InvalidParameterError(
            "the inertia tensor's entries are too large to compute with in float64; express it in other units"
        )
    bound = TENSOR_ERROR_FACTOR * scale
    frame = PrincipalFrame.from_tensor(matrix, tolerance, rounding=bound)
    moments = frame.moments
    warnings: list[str] = []
    zero = moments <= bound
    if np.any(zero):
        warnings.append(
            f"{int(zero.sum())} principal moment(s) are zero within the rounding of the tensor "
            f"(|I| <= {bound:.3g} kg m^2) and are reported as 0"
        )
        clamped = np.where(zero, 0.0, moments)
        frame = PrincipalFrame(clamped, frame.axes, frame.quaternion, not equal_moment_pairs(clamped, tolerance), tolerance)
    errors = np.full(3, bound)
    live = ~zero
    relative = float(np.max(bound / frame.moments[live])) if np.any(live) else 1.0
    gaps = [min(abs(float(frame.moments[i] - frame.moments[j])) for j in range(3) if j != i) for i in range(3)]
    smallest_gap = min(gaps)
    axes_error = float(2 * bound / smallest_gap) if smallest_gap > 2 * bound else float("inf")
    return TensorFrame(frame, errors, relative, axes_error, tuple(warnings))


def equal_moment_pairs(moments: Sequence[float] | NDArray[np.float64], tolerance: float) -> tuple[tuple[int, int], ...]:
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
