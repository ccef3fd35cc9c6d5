"""Every numerical threshold of the service, with its default and reason.

Thresholds are relative to a scale of the problem (named next to each one),
never absolute.  Pass a modified copy (``dataclasses.replace``) to change one;
there is no mutable global.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Tolerances", "DEFAULT_TOLERANCES", "EPS"]

EPS = 2.220446049250313e-16  # float64 unit roundoff times two (numpy.finfo(float).eps)


@dataclass(frozen=True, slots=True)
class Tolerances:
    moment_rel: float = 1e-6
    """Two principal moments are equal when their gap is at most this times the
    largest moment.  The API's ``tolerance``; 1e-6 is above float noise of exact
    polyhedra (~1e-15) and below the asymmetry of any deliberately shaped part."""

    volume_rel: float = 1e-12
    """A solid has zero volume when |V| is at most this times the volume of its
    bounding box: flat or degenerate meshes land near 1e-16 (rounding only)."""

    jacobi_rel: float = 4 * EPS
    """Off-diagonal entries below this times the geometric mean of their
    diagonal pair are zero in the 3x3 Jacobi eigen-solver (relative accuracy,
    Demmel & Veselic 1992)."""

    jacobi_max_sweeps: int = 30
    """Cyclic Jacobi converges quadratically; 30 sweeps is far beyond need."""


DEFAULT_TOLERANCES = Tolerances()
