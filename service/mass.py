"""Mass properties: mass, centre of mass and inertia tensor, exactly.

Closed triangle surfaces are integrated exactly with the divergence theorem
as signed tetrahedra, volume meshes as their tetrahedra, shells as area
triangles and point sets directly (the integrals are in ``integrals``;
Mirtich 1996, Eberly 2002, Tonon 2004).

Precision.  Coordinates are first shifted to a local origin taken from the
body's own coordinates, so a part far from the file's origin loses nothing
(the difference of two nearby floats is exact, Sterbenz's lemma).  A first
pass gives the centre of mass and approximate principal axes; the body is
then re-integrated in that principal frame about its centre of mass, where
each diagonal entry is a sum of squares of coordinates of its own size, so
even the smallest moment of a needle keeps its relative precision.  Passes
repeat (at most ``MAX_PASSES``) until the frame no longer moves.  The tensor
in the input frame is then R diag(I) R^T.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .arrays import freeze_fields
from .body import Body, PointBody, VolumeBody
from .conventions import DEFAULT_DENSITY
from .ddouble import rotated
from .eigen import jacobi_eigh
from .errors import InsufficientPrecisionError, InvalidParameterError, ZeroVolumeError
from .integrals import Sums, local_origin, point_records, point_sums, simplex_sums
from .solid import closed_surface
from .tolerances import DEFAULT_TOLERANCES, EPS, Tolerances
from .vocabulary import MODELS, Model

__all__ = ["InertiaTensor", "MassProperties", "mass_properties", "assembly_properties", "Model", "parallel_axis"]

MAX_PASSES = 4  # one coarse pass plus refinements; the frame settles in 2-3
FRAME_SETTLED = 1e-7  # off-diagonal / sqrt(diag product) below this: the next pass moves moments < 1e-14


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


def _covariance(s: Sums) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Centre of mass (local) and int (x-c)(x-c)^T dm."""
    c = s.m1 / s.m0
    return c, s.m2 - s.m0 * np.outer(c, c)


def _inertia_from_covariance(cov: NDArray[np.float64]) -> NDArray[np.float64]:
    # I_ik = int (x_l^2 delta_ik - x_i x_k) dm   (Landau & Lifshitz eq. 32.2).
    # The diagonal is summed as C_yy + C_zz, never trace(C) - C_xx: for a
    # needle along x that difference would cancel all but a few digits.
    tensor = -cov
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        tensor[i, i] = cov[j, j] + cov[k, k]
    return tensor


class _Geometry:
    """Points + cells of one body in a form the passes can re-integrate."""

    def __init__(
        self,
        points: NDArray[np.float64],
        cells: NDArray[np.int64],
        kind: str,
        weight: NDArray[np.float64] | None,
        coordinate_eps: float = 2.0**-53,
        blocks: tuple[QuadBlock, ...] = (),
    ) -> None:
        self.points, self.cells, self.kind, self.weight = points, cells, kind, weight
        self.coordinate_eps = coordinate_eps  # unit roundoff of the stored coordinates (float32: 2**-24)
        self.blocks = blocks  # volume cells other than linear tetrahedra: (type, nodes, weight), by quadrature

    @property
    def referenced_points(self) -> int:
        return len(self.points)

    def sums(self, origin: NDArray[np.float64], rotation: NDArray[np.float64] | None) -> Sums:
        """The integrals about ``origin`` in the frame ``rotation`` (columns), or raise on overflow."""
        try:
            with np.errstate(over="raise", invalid="raise"):
                x = self.points - origin if rotation is None else rotated(self.points, origin, rotation)
                if self.kind == "points":
                    assert self.weight is not None
                    return point_sums(self.weight, x)
                if not self.blocks:
                    return simplex_sums(x, self.cells, self.kind, self.weight)
                return _volume_sums(x, self.cells, self.weight, self.blocks)
        except FloatingPointError as exc:
            raise InvalidParameterError(
                "the coordinates or masses are so large that the inertia integrals overflow floating point; "
                "express the input in other units"
            ) from exc


QuadBlock = tuple[str, NDArray[np.int64], NDArray[np.float64] | None]


def _volume_sums(
    x: NDArray[np.float64], tets: NDArray[np.int64], weight: NDArray[np.float64] | None, blocks: tuple[QuadBlock, ...]
) -> Sums:
    """Linear tetrahedra in closed form plus every other cell by its exact quadrature (``cells``)."""
    from .cells import cell_sums, combined

    total = simplex_sums(x, tets, "tet", weight) if len(tets) else None
    for name, nodes, w in blocks:
        part = cell_sums(x, name, nodes, w)
        total = part if total is None else combined(total, part)
    assert total is not None
    return total


@dataclass(frozen=True, slots=True)
class _Refined:
    """What the passes found, in the file's units and the geometry's measure.

    sums : the final pass's integrals (principal frame, about the centre).
    com : (3,) centre, input frame.  tensor : (3, 3) about it, input frame.
    moments, axes : eigenvalues and axes (rows) from the final pass.
    estimate : relative error bound of the moments.
    """

    sums: Sums
    com: NDArray[np.float64]
    tensor: NDArray[np.float64]
    moments: NDArray[np.float64]
    axes: NDArray[np.float64]
    estimate: float
    warnings: tuple[str, ...] = ()


def _refine(geometry: _Geometry, tolerances: Tolerances) -> _Refined:
    """Multi-pass integration: a coarse pass, then passes in the principal frame until it settles."""
    origin = local_origin(geometry.points)
    s = geometry.sums(origin, None)
    _check_volume(s, geometry.kind)
    c, cov = _covariance(s)
    values, vectors = jacobi_eigh(_inertia_from_covariance(cov), tolerances)
    rotation = vectors.T  # columns: axes in the input frame
    com = origin + c
    previous = values
    for _ in range(MAX_PASSES - 1):
        s = geometry.sums(com, rotation)
        c_body, cov_body = _covariance(s)
        tensor_body = _inertia_from_covariance(cov_body)
        values, v_body = jacobi_eigh(tensor_body, tolerances)
        com = com + rotation @ c_body
        settled = _offdiagonal_ratio(tensor_body) <= FRAME_SETTLED
        top = float(np.abs(values).max())
        step = float(np.max(np.abs(values - previous)) / top) if top > 0 else 0.0
        rotation = rotation @ v_body.T
        previous = values
        if settled:
            break
    _check_volume(s, geometry.kind)
    estimate, errors = _error_estimate(s, values)
    if not settled:
        estimate = max(estimate, step)
    values, warnings = _physical_moments(geometry, values, errors)
    if geometry.kind == "apex":
        warnings += _check_resolution(geometry, s, com, rotation, values)
    tensor = rotation @ np.diag(values) @ rotation.T
    tensor = 0.5 * (tensor + tensor.T)
    return _Refined(s, com, tensor, values, rotation.T.copy(), estimate, warnings)


def _physical_moments(
    geometry: _Geometry, values: NDArray[np.float64], errors: NDArray[np.float64]
) -> tuple[NDArray[np.float64], tuple[str, ...]]:
    """No zero or negative moment of a solid, and no negative moment at all, comes back.

    Points on one line have a smallest moment that is zero up to rounding: it is
    reported as 0 (a linear rotator), with a warning.  A solid or a surface
    always has three positive moments (I1 + I2 >= I3 too); a stored polyhedron
    whose integration gives a moment within its rounding of zero, or below,
    is not a body (its faces cross or its shells are degenerate) and is refused.
    """
    low = values <= errors
    if geometry.kind == "points":
        # the second pass's rotation leaves a line's points off it by ~eps of their spread: a smallest
        # moment below 64 eps of the largest (the motion's rounding level) is that, not a size
        low |= values <= 64 * EPS * float(np.max(values))
        if not np.any(low):
            return values, ()
        if bool(np.all(low)):  # a single point, or all the mass at one place: every moment is zero
            return np.zeros(3), () if not np.any(values) else (
                "all principal moments are zero within rounding (the mass is at one point) and are reported as 0",
            )
        return np.where(low, 0.0, values), (
            "the smallest principal moment is zero within rounding (the points lie on a line) and is reported as 0",
        )
    order = np.sort(values)
    slack = float(errors.sum())
    if np.any(low) or order[0] + order[1] < order[2] - slack:
        raise InsufficientPrecisionError(
            "the stored polyhedron integrates to principal moments no body has (zero, negative, or "
            f"I1 + I2 < I3: {', '.join(f'{x:.6g}' for x in order)} in the file's units): its faces cross "
            "or its shells are degenerate; repair the mesh or export it nearer the origin in float64",
            moments=[float(x) for x in order],
        )
    return values, ()


_RESOLUTION_REFUSE = 1.0
"""Refuse a surface whose volume or a moment could change by this fraction of itself when every
stored coordinate moves by its resolution: the file does not determine the body."""
_RESOLUTION_WARN = 1e-3
"""Warn (naming the resolution) above this fraction: the stored polyhedron is computed exactly,
but it may differ that much from the part it was exported from."""


def _check_resolution(
    geometry: _Geometry, s: Sums, com: NDArray[np.float64], rotation: NDArray[np.float64], values: NDArray[np.float64]
) -> tuple[str, ...]:
    """Refuse a closed surface its stored coordinates cannot represent; warn when they barely do.

    Each stored coordinate x is the exporter's value to within delta = u |x|max
    (u: the storage's unit roundoff, 2**-24 for float32).  Moving every surface
    point by up to sqrt(3) delta changes the volume by at most sqrt(3) delta A
    (A the surface area) and moment k by at most that volume times the largest
    squared distance of the surface from axis k.  When either change reaches
    the quantity itself, the numbers describe the rounding, not a part.
    """
    x = geometry.points
    delta = geometry.coordinate_eps * float(np.abs(x).max())
    y = x - com
    records = point_records(y)  # one gather of 24 bytes per corner, not numpy's slower 2-D fancy indexing
    area = 0.0
    for start in range(0, len(geometry.cells), 1 << 16):
        tri = records.take(geometry.cells[start : start + (1 << 16)]).view(np.float64).reshape(-1, 3, 3)
        area += 0.5 * float(np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum())
    weight = 1.0 if geometry.weight is None else float(np.max(geometry.weight))
    moved = math.sqrt(3.0) * delta * area  # volume the resolution can move
    volume = abs(s.measure)
    along = y @ rotation  # principal-frame coordinates (columns of rotation are the axes)
    sq = along * along
    reach = np.array([float(np.max(sq.sum(axis=1) - sq[:, k])) for k in range(3)])
    ratio_v = moved / volume if volume > 0 else math.inf
    ratio_i = float(np.max(moved * weight * reach / values))
    ratio = max(ratio_v, ratio_i)
    if not ratio >= _RESOLUTION_WARN:
        return ()
    float32 = geometry.coordinate_eps >= 2.0**-24
    cause = (
        f"the file's float32 coordinates, {float(np.abs(x).max()):.3g} units from the origin, are resolved "
        f"only to {delta:.3g} units"
        if float32
        else f"its coordinates are resolved only to {delta:.3g} units (degenerate shells, or a body thinner "
        "than the rounding of its coordinates)"
    )
    if ratio >= _RESOLUTION_REFUSE:
        raise InsufficientPrecisionError(
            f"the stored coordinates cannot represent this body: {cause}, which can change its volume or a "
            f"principal moment by {ratio:.3g} times its own value; "
            + (
                "export it in float64 (e.g. OBJ, or ASCII STL with 9 digits) or nearer the origin"
                if float32
                else "repair the degenerate shells or export the part nearer the origin"
            ),
            resolution=delta,
            ratio=min(ratio, 1e300),
        )
    return (
        f"{cause}: the stored polyhedron is integrated exactly, but it may differ from the exported part by up "
        f"to {ratio:.2g} of its volume or a principal moment; export in float64 or nearer the origin to avoid it",
    )


def _offdiagonal_ratio(t: NDArray[np.float64]) -> float:
    worst = 0.0
    for i, j in ((0, 1), (0, 2), (1, 2)):
        scale = math.sqrt(abs(t[i, i] * t[j, j]))
        if t[i, j] != 0.0:
            worst = max(worst, abs(t[i, j]) / scale if scale > 0 else math.inf)
    return worst


def _error_estimate(s: Sums, moments: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
    """Relative rounding-error bound of each principal moment, the worst one, and each one's absolute bound.

    A moment within its absolute bound of zero is left out of the relative
    estimate (``_physical_moments`` reports it as 0, or refuses the body).

    In the final pass (principal frame, about the centre of mass) the
    coordinates are exact to their last bit, so the error comes from each
    element's own arithmetic (a few eps times its determinant's condition,
    ``element_err``) and from the summation, pairwise within and across
    blocks, bounded by gamma * sum |terms| with gamma growing as the depth of
    the two trees (Higham, Accuracy and Stability of Numerical Algorithms, §4.2).
    """
    per_block = max(2, math.ceil(s.terms / max(s.blocks, 1)))
    gamma = (math.log2(per_block) + math.log2(max(s.blocks, 1)) + 4) * EPS
    diag_err = gamma * np.diag(s.abs_m2) + 8 * EPS * s.element_err
    errors = np.array([sum(diag_err[j] for j in range(3) if j != k) for k in range(3)], dtype=np.float64)
    live = moments > errors
    worst = float(np.max(errors[live] / moments[live])) if np.any(live) else 1.0
    return max(worst, 4 * EPS), errors


def _check_volume(s: Sums, kind: str) -> None:
    if kind in ("apex", "tet") and abs(s.m0) <= 64 * EPS * s.noise:
        raise ZeroVolumeError(
            "the mesh encloses no volume (it is flat or degenerate); send a solid or use model=shell with a thickness",
            volume=s.m0,
        )
    if kind == "tri" and s.m0 <= 0:
        raise ZeroVolumeError("the surface has zero area; send a mesh with non-degenerate triangles")


def _geometry(body: Body, model: str, thickness: float | None, tolerances: Tolerances) -> tuple[_Geometry, tuple[str, ...]]:
    if isinstance(body, PointBody):
        return _Geometry(body.positions, np.empty((0, 0), np.int64), "points", body.masses), ()
    if isinstance(body, VolumeBody):
        if model == Model.SHELL:
            raise InvalidParameterError("model=shell needs a surface mesh; a volume mesh is always a solid", parameter="model")
        blocks = tuple((b.type, b.nodes, b.density) for b in body.cells)
        return _Geometry(body.points, body.tets, "tet", body.cell_density, blocks=blocks), _tangled_warning(body)
    if model == Model.SHELL:
        return _Geometry(body.vertices, body.faces, "tri", None), ()
    vertices, faces, warnings = closed_surface(body)
    return _Geometry(vertices, faces, "apex", None, body.coordinate_eps), warnings


def _tangled_warning(body: VolumeBody) -> tuple[str, ...]:
    if not body.cells:
        return ()
    from .cells import tangled_cells

    count = sum(tangled_cells(body.points, b.type, b.nodes) for b in body.cells)
    if not count:
        return ()
    return (
        f"{count} of {body.cell_count} cells fold over themselves (their Jacobian changes sign); "
        "each was integrated with its signed Jacobian, so a folded region counts negatively: check the mesh",
    )


def mass_properties(
    body: Body,
    *,
    density: float | None = None,
    mass: float | None = None,
    model: str = Model.SOLID,
    thickness: float | None = None,
    tolerances: Tolerances = DEFAULT_TOLERANCES,
) -> MassProperties:
    """Mass properties of ``body`` about its centre of mass, SI units.

    density : kg/m^3 (solids; default 1000), exclusive with ``mass`` [kg].
    model : "solid" (closed surface or volume mesh) or "shell" (surface of
        wall ``thickness``, in the file's length unit).
    Point bodies carry their own masses; ``mass`` rescales them.
    """
    _check_material(body, density, mass, model, thickness)
    geometry, warnings = _geometry(body, model, thickness, tolerances)
    refined = _refine(geometry, tolerances)
    s, com, tensor, moments, axes, estimate = (
        refined.sums,
        refined.com,
        refined.tensor,
        refined.moments,
        refined.axes,
        refined.estimate,
    )
    L = body.length_scale
    if isinstance(body, PointBody):
        measure_to_mass = 1.0 if mass is None else mass / s.m0
        length_power = 2
        volume = uniform_density = area = None
    elif model == Model.SHELL:
        area = s.m0 * L**2
        assert thickness is not None
        shell_volume = area * thickness * L
        rho = density if density is not None else (DEFAULT_DENSITY if mass is None else mass / shell_volume)
        measure_to_mass = rho * thickness * L
        length_power = 4
        volume, uniform_density = None, rho
    else:
        area = None
        volume = s.m0 * L**3
        weighted = isinstance(body, VolumeBody) and body.weighted
        if weighted:
            volume = s.measure * L**3
            measure_to_mass = 1.0 if mass is None else mass / (s.m0 * L**3)
            uniform_density = None
        else:
            rho = density if density is not None else (DEFAULT_DENSITY if mass is None else mass / volume)
            measure_to_mass = rho
            uniform_density = rho
        length_power = 5
    # measure-space integrals are in file units; scale lengths then multiply by density
    to_mass = measure_to_mass * (L**3 if length_power == 5 else L**2 if length_power == 4 else 1.0)
    total_mass = s.m0 * to_mass
    inertia_scale = measure_to_mass * L**length_power
    moments_si = moments * inertia_scale
    _check_finite_results(total_mass, com * L, tensor * inertia_scale)
    return MassProperties(
        mass=float(total_mass),
        center_of_mass=com * L,
        inertia=InertiaTensor(tensor * inertia_scale, "centre_of_mass", com * L),
        principal_moments=moments_si,
        principal_axes=axes,
        relative_error_estimate=float(estimate + 8 * EPS),
        volume=None if volume is None else float(volume),
        density=None if uniform_density is None else float(uniform_density),
        area=None if area is None else float(area),
        warnings=body.warnings + warnings + refined.warnings,
        mesh_vertices=geometry.referenced_points if geometry.kind == "apex" else None,
    )


def assembly_properties(
    parts: Sequence[tuple[Body, float | None]],
    *,
    model: str = Model.SOLID,
    thickness: float | None = None,
    factor: float = 1.0,
    tolerances: Tolerances = DEFAULT_TOLERANCES,
) -> MassProperties:
    """Several bodies of one file integrated as one, each with its own material.

    parts : (body, density) pairs; density in kg/m^3 for a uniform body, None
        for a body that carries its own masses (cell densities, point masses).
    factor : multiplies every density and mass (a requested total mass).

    The whole assembly goes through the same multi-pass integration as one
    body, with per-element weights, so an assembly far from the origin keeps
    the precision a single part has; adding part tensors by the parallel-axis
    theorem would not (their offsets cancel).
    """
    bodies = [b for b, _ in parts]
    scales = {b.length_scale for b in bodies}
    if len(scales) != 1:
        raise InvalidParameterError("the parts of one assembly must share a length unit")
    L = scales.pop()
    geoms: list[tuple[_Geometry, NDArray[np.float64]]] = []
    warnings: list[str] = []
    for body, density in parts:
        geometry, more = _geometry(body, model, thickness, tolerances)
        weights = _element_weights(geometry, density, model, thickness, L) * factor
        geometry.blocks = tuple(
            (name, nodes, _block_weights(w, len(nodes), density) * factor) for name, nodes, w in geometry.blocks
        )
        geoms.append((geometry, weights))
        warnings.extend(more)
    kinds = {g.kind for g, _ in geoms}
    if len(kinds) != 1:
        raise InvalidParameterError("an assembly must hold bodies of one kind (all surfaces, all volumes or all points)")
    kind = kinds.pop()
    offsets = np.cumsum([0] + [len(g.points) for g, _ in geoms[:-1]])
    whole = _Geometry(
        np.concatenate([g.points for g, _ in geoms]),
        np.concatenate([g.cells + off for (g, _), off in zip(geoms, offsets)]) if kind != "points" else np.empty((0, 0), np.int64),
        kind,
        np.concatenate([w for _, w in geoms]),
        max(g.coordinate_eps for g, _ in geoms),
        tuple((name, nodes + off, w) for (g, _), off in zip(geoms, offsets) for name, nodes, w in g.blocks),
    )
    refined = _refine(whole, tolerances)
    s, com, tensor, moments, axes, estimate = (
        refined.sums,
        refined.com,
        refined.tensor,
        refined.moments,
        refined.axes,
        refined.estimate,
    )
    length_power = {"apex": 5, "tet": 5, "tri": 4, "points": 2}[kind]
    to_mass = L ** (length_power - 2)
    inertia_scale = L**length_power
    _check_finite_results(s.m0 * to_mass, com * L, tensor * inertia_scale)
    return MassProperties(
        mass=float(s.m0 * to_mass),
        center_of_mass=com * L,
        inertia=InertiaTensor(tensor * inertia_scale, "centre_of_mass", com * L),
        principal_moments=moments * inertia_scale,
        principal_axes=axes,
        relative_error_estimate=float(estimate + 8 * EPS),
        warnings=tuple(warnings) + refined.warnings,
    )


def _element_weights(
    geometry: _Geometry, density: float | None, model: str, thickness: float | None, L: float
) -> NDArray[np.float64]:
    """Mass per unit of each element's measure (file units): density, density x wall, or the masses."""
    n = len(geometry.points) if geometry.kind == "points" else len(geometry.cells)
    if geometry.weight is not None:  # cell densities or point masses
        return np.asarray(geometry.weight, dtype=np.float64)
    rho = DEFAULT_DENSITY if density is None else density
    if model == Model.SHELL:
        assert thickness is not None
        rho = rho * thickness * L
    return np.full(n, rho)


def _block_weights(weight: NDArray[np.float64] | None, count: int, density: float | None) -> NDArray[np.float64]:
    """Density of each cell of a block: its own, or the part's uniform density."""
    if weight is not None:
        return np.asarray(weight, dtype=np.float64)
    return np.full(count, DEFAULT_DENSITY if density is None else density)


def _check_finite_results(mass: float, com: NDArray[np.float64], tensor: NDArray[np.float64]) -> None:
    """Coordinates or masses near the float64 limits overflow the squares of the integrals."""
    if not (math.isfinite(mass) and np.all(np.isfinite(com)) and np.all(np.isfinite(tensor))):
        raise InvalidParameterError(
            "the coordinates or masses are so large (or so small) that the inertia overflows floating point; "
            "express the input in other units"
        )


def _check_material(body: Body, density: float | None, mass: float | None, model: str, thickness: float | None) -> None:
    if model not in MODELS:
        raise InvalidParameterError(f"unknown model {model!r}; use 'solid' or 'shell'", parameter="model")
    if density is not None and mass is not None:
        raise InvalidParameterError("give either density or mass, not both", parameter="density")
    for name, value in (("density", density), ("mass", mass), ("thickness", thickness)):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise InvalidParameterError(f"{name} must be a positive finite number, got {value!r}", parameter=name)
    if model == Model.SHELL and thickness is None:
        raise InvalidParameterError("model=shell needs a wall thickness (in the file's length unit)", parameter="thickness")
    if model == Model.SOLID and thickness is not None and not isinstance(body, PointBody):
        raise InvalidParameterError("thickness applies only to model=shell", parameter="thickness")
    if isinstance(body, PointBody) and density is not None:
        raise InvalidParameterError("point masses carry their own masses; density does not apply", parameter="density")
