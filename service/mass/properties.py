"""The public result of the mass stage: ``MassProperties`` and its ``InertiaTensor`` (SI units)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..arrays import freeze_fields

__all__ = ["InertiaTensor", "MassProperties", "parallel_axis"]


@dataclass(frozen=True, slots=True)
class InertiaTensor:
    """An inertia tensor that says where it lives.

    matrix : (3, 3) [kg m^2], symmetric.  about : "centre_of_mass" or
    "reference".  point : (3,) [m], the point it is taken about, input frame.
    """

    matrix: NDArray[np.float64]
    about: str
    point: NDArray[np.float64]
    frame: str = "input"

    def __post_init__(self) -> None:
        freeze_fields(self, {"matrix": (3, 3), "point": (3,)})


@dataclass(frozen=True, slots=True)
class MassProperties:
    """Mass properties about the centre of mass, in input-frame axes (SI).

    principal_moments, principal_axes : the eigen-decomposition refined in the
        body frame (rows are axes; unsorted, ``principal.principal_frame``
        orders and orients them).
    volume, density : solids only (None for shells and point sets).
    relative_error_estimate : floating-point error bound of the moments.
    """

    mass: float
    center_of_mass: NDArray[np.float64]
    inertia: InertiaTensor
    principal_moments: NDArray[np.float64]
    principal_axes: NDArray[np.float64]
    relative_error_estimate: float
    volume: float | None = None
    density: float | None = None
    area: float | None = None
    warnings: tuple[str, ...] = ()
    mesh_vertices: int | None = None
    """Distinct vertices of a surface after welding (solids), else None."""

    def about(self, point: NDArray[np.float64]) -> InertiaTensor:
        """Tensor about ``point`` [m] by the parallel-axis theorem."""
        p = np.asarray(point, dtype=np.float64)
        matrix = parallel_axis(self.inertia.matrix, self.mass, p - self.center_of_mass)
        return InertiaTensor(matrix, "reference", p)


def parallel_axis(tensor: NDArray[np.float64], mass: float, offset: NDArray[np.float64]) -> NDArray[np.float64]:
    """I' = I + mu (a^2 delta - a a^T) for a shift a from the centre of mass.

    Landau & Lifshitz §32, eq. (32.12); seed notes eq. (29).
    """
    a = np.asarray(offset, dtype=np.float64)
    shifted: NDArray[np.float64] = tensor + mass * (np.dot(a, a) * np.eye(3) - np.outer(a, a))
    return shifted
