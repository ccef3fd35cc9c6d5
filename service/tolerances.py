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

    seam_rel: float = 1e-12
    """Two vertices on open edges of a surface are one seam vertex when they are
    at most this times the diagonal of the part's bounding box apart.  CAD
    exporters write one point twice with different rounding (``0.0`` in one
    triangle, ``-2.7e-16`` in the next): gaps of a few ulps of the coordinates,
    ~1e-16 of the size; 1e-12 is far above that and far below any real
    feature or gap a part can have (a 1 m part: 1 pm)."""

    t_junction_rel: float = 1e-5
    """A vertex of an open edge lies on another open edge (a T-junction: a corner of one face in the middle of
    its neighbour's side) when its distance from that edge is at most this times the edge's length, and it is
    that far from both ends.  Such a surface is closed as drawn, only not along its edges; polyhedra written
    with six or seven digits (Geomview's samples) put their T-vertices 1e-6 to 3e-6 of the edge off it.  The
    surface is closed only where every open edge is matched, so this admits nothing but cracks of at most this
    width, which the closure fills (``seams.close_t_junctions``)."""

    jacobi_rel: float = 4 * EPS
    """Off-diagonal entries below this times the geometric mean of their
    diagonal pair are zero in the 3x3 Jacobi eigen-solver (relative accuracy,
    Demmel & Veselic 1992)."""

    jacobi_max_sweeps: int = 30
    """Cyclic Jacobi converges quadratically; 30 sweeps is far beyond need."""

    permanent_rotation_rel: float = 16 * EPS
    """Omega is along a principal axis when its other principal components are at
    most this times |Omega|: the rounding noise of ``axes @ omega``.  Anything
    larger is a real (if tiny) tilt whose motion, e.g. a flip, is predicted."""

    separatrix_rel: float = 16 * EPS
    """The asymmetric top is on the separatrix when |M^2 - 2 E I2| is at most this
    times I3 (I3 - I2) W3^2 + I1 (I2 - I1) W1^2, the two terms whose difference
    it is: below that the sign of the difference is rounding noise."""

    integrator_rtol: float = 1e-10
    """Default rtol of the dop853/rk45 methods: about the accuracy users expect
    of a cross-check, at a few thousand steps per hundred rotations."""

    integrator_atol_rel: float = 1e-14
    """atol of dop853/rk45, times |Omega| for Omega and times 1 for the
    quaternion: keeps the relative test meaningful when a component crosses 0."""

    splitting_step_angle: float = 1e-3
    """Default step of the splitting method, as the largest body rotation (rad)
    per step; its second-order error is then ~1e-7 per radian turned."""

    max_integration_steps: int = 2_000_000
    """Cap on steps of the numerical methods (a pure-Python loop for splitting):
    beyond it predict_motion refuses and points to method='exact'."""

    metres_plausible: float = 10.0
    """A part read in metres by default (the file declares no unit and none was
    given) that is more than this many metres across is most likely drawn in
    millimetres (a 10 m part is a building, a 10 mm part is common): warn."""

    shell_thickness_warn: float = 0.05
    """model=shell: a wall thicker than this fraction of the part's bounding-box
    diagonal is warned about; the thin-shell model's error grows like t/R."""

    shell_thickness_max: float = 0.5
    """model=shell: a wall at least half the part's diagonal is no wall (a box
    of side 1 with thickness 2 weighs 12 solids): refused as invalid_parameter."""


DEFAULT_TOLERANCES = Tolerances()
