"""The multi-pass refinement engine: a body's centre of mass, inertia tensor and principal axes, exactly.

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

The engine works in the file's length unit and the geometry's own measure
(volume, area or point count, times the geometry's weights); what turns that
into kilograms is the material rule's (``material``).  It also returns the
honest error bound of the moments and refuses what is not a body.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..blocks import for_each_block
from ..eigen import jacobi_eigh, jacobi_lists
from ..errors import InsufficientPrecisionError, ZeroVolumeError
from ..integrals import Sums, local_origin
from ..surface import triangle_area
from ..tolerances import EPS, Tolerances
from . import points as small_points
from .geometry import Geometry

__all__ = [
    "FRAME_SETTLED",
    "MAX_PASSES",
    "FewPoints",
    "Refined",
    "moment_errors",
    "refine",
    "refine_few_points",
    "zero_point_moments",
]

MAX_PASSES = 4  # one coarse pass plus refinements; the frame settles in 2-3
FRAME_SETTLED = 1e-7  # off-diagonal / sqrt(diag product) below this: the next pass moves moments < 1e-14


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


@dataclass(frozen=True, slots=True)
class Refined:
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


def refine(geometry: Geometry, tolerances: Tolerances) -> Refined:
    """Multi-pass integration: a coarse pass, then passes in the principal frame until it settles."""
    if geometry.kind == "points" and len(geometry.points) <= small_points.SMALL_POINTS:
        found = _refine_few_points(geometry, tolerances)
        if found is not None:
            return found
    origin = local_origin(geometry.points)
    s = geometry.sums(origin, None)
    _check_volume(s, geometry.kind, geometry.cells)
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
        settled = _offdiagonal_ratio(tensor_body.tolist()) <= FRAME_SETTLED
        top = float(np.abs(values).max())
        step = float(np.max(np.abs(values - previous)) / top) if top > 0 else 0.0
        rotation = rotation @ v_body.T
        previous = values
        if settled:
            break
    _check_volume(s, geometry.kind, geometry.cells)
    return _finished(geometry, s, com, rotation, values, None if settled else step)


def _finished(
    geometry: Geometry,
    s: Sums,
    com: NDArray[np.float64],
    rotation: NDArray[np.float64],
    values: NDArray[np.float64],
    step: float | None,
) -> Refined:
    """The final pass's error bound (at least the last ``step`` where the frame did not settle), the
    moments' checks, and the tensor in the input frame."""
    estimate, errors = _error_estimate(s, values)
    if step is not None:
        estimate = max(estimate, step)
    values, warnings = _physical_moments(geometry, values, errors)
    if geometry.kind == "apex":
        warnings += _check_resolution(geometry, s, com, rotation, values)
    return Refined(s, com, frame_tensor(rotation, values.tolist()), values, rotation.T.copy(), estimate, warnings)


def frame_tensor(rotation: NDArray[np.float64], values: list[float]) -> NDArray[np.float64]:
    """The tensor in the input frame, ``rotation diag(values) rotation^T`` (the columns of ``rotation``
    are the axes), symmetrised."""
    v0, v1, v2 = values
    tensor: NDArray[np.float64] = rotation @ np.array([[v0, 0.0, 0.0], [0.0, v1, 0.0], [0.0, 0.0, v2]]) @ rotation.T
    return 0.5 * (tensor + tensor.T)


def _list_tensor(found: small_points.Moments) -> tuple[list[float], list[list[float]]]:
    """``_covariance`` then ``_inertia_from_covariance`` on Python floats, the same operations (m2 is
    symmetric, and so is every product c_i c_j: each entry is computed once for both sides)."""
    m1, (m2_0, m2_1, m2_2), _, total = found
    c0, c1, c2 = m1[0] / total, m1[1] / total, m1[2] / total
    v00 = m2_0[0] - total * (c0 * c0)
    v11 = m2_1[1] - total * (c1 * c1)
    v22 = m2_2[2] - total * (c2 * c2)
    t01 = -(m2_0[1] - total * (c0 * c1))
    t02 = -(m2_0[2] - total * (c0 * c2))
    t12 = -(m2_1[2] - total * (c1 * c2))
    return [c0, c1, c2], [[v11 + v22, t01, t02], [t01, v22 + v00, t12], [t02, t12, v00 + v11]]


def _refine_few_points(geometry: Geometry, tolerances: Tolerances) -> Refined | None:
    """``refine`` for a few point masses, bit for bit, on Python floats (``refine_few_points``)."""
    masses, points = geometry.small_lists()
    found = refine_few_points(masses, points, tolerances)
    if found is None:
        return None
    return _finished(
        geometry, small_points.as_sums(found.moments, len(masses)), found.com, found.rotation, np.array(found.values), found.step
    )


class FewPoints(NamedTuple):
    """The last pass of ``refine_few_points``: its sums about ``com`` in the frame ``rotation`` (whose
    columns are the axes in the input frame), the moments it found, and the last step where the frame
    did not settle (None where it did)."""

    moments: small_points.Moments
    com: NDArray[np.float64]
    rotation: NDArray[np.float64]
    values: list[float]
    step: float | None


def refine_few_points(masses: list[float], points: list[list[float]], tolerances: Tolerances) -> FewPoints | None:
    """``refine``'s passes for a few point masses, bit for bit, on Python floats.

    A handful of points is a few dozen flops per pass; numpy's fixed cost per call (and the ``Sums``
    of every pass) was most of the time.  The operations and their order are ``refine``'s: the
    sums are ``points.point_moments``, the eigen-kernel ``jacobi_lists``; the 3 x 3 products stay
    numpy's (its BLAS may fuse their multiply-adds).  None where a number is not finite: ``refine``
    then decides, with its own errors.
    """
    xs, ys, zs = zip(*points)
    x0, y0, z0, x1, y1, z1 = min(xs), min(ys), min(zs), max(xs), max(ys), max(zs)
    origin = [x0 + 0.5 * (x1 - x0), y0 + 0.5 * (y1 - y0), z0 + 0.5 * (z1 - z0)]
    found = small_points.point_moments(masses, points, origin, None)
    if found is None:
        return None
    c, tensor = _list_tensor(found)
    values, v = jacobi_lists(tensor, tolerances)
    rotation = np.asfortranarray(v)  # columns: axes in the input frame, laid out as ``refine``'s vectors.T
    com = np.array([o + x for o, x in zip(origin, c)])
    previous = values
    step = None
    for _ in range(MAX_PASSES - 1):
        found = small_points.point_moments(masses, points, com.tolist(), v)
        if found is None:
            return None
        c_body, tensor_body = _list_tensor(found)
        values, v_body = jacobi_lists(tensor_body, tolerances)
        if not all(map(math.isfinite, values)):
            return None
        com = com + rotation @ np.array(c_body)
        settled = _offdiagonal_ratio(tensor_body) <= FRAME_SETTLED
        top = max(map(abs, values))
        moved = max(abs(a - b) for a, b in zip(values, previous))
        step = moved / top if top > 0 else 0.0
        rotation = rotation @ np.asfortranarray(v_body)  # the strides of ``refine``'s v_body.T: the same BLAS kernel
        v = rotation.tolist()
        previous = values
        if settled:
            step = None
            break
    return FewPoints(found, com, rotation, values, step)


def _physical_moments(
    geometry: Geometry, values: NDArray[np.float64], errors: NDArray[np.float64]
) -> tuple[NDArray[np.float64], tuple[str, ...]]:
    """No zero or negative moment of a solid, and no negative moment at all, comes back.

    Points on one line have a smallest moment that is zero up to rounding: it is
    reported as 0 (a linear rotator), with a warning.  A solid or a surface
    always has three positive moments (I1 + I2 >= I3 too); a stored polyhedron
    whose integration gives a moment within its rounding of zero, or below,
    is not a body (its faces cross or its shells are degenerate) and is refused.
    """
    if geometry.kind == "points":
        low = np.array(zero_point_moments(values.tolist(), errors.tolist()))
        if not np.any(low):
            return values, ()
        if bool(np.all(low)):  # a single point, or all the mass at one place: every moment is zero
            return np.zeros(3), () if not np.any(values) else (
                "all principal moments are zero within rounding (the mass is at one point) and are reported as 0",
            )
        return np.where(low, 0.0, values), (
            "the smallest principal moment is zero within rounding (the points lie on a line) and is reported as 0",
        )
    low = values <= errors
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


def zero_point_moments(values: list[float], errors: list[float]) -> list[bool]:
    """Which moments of a point set are zero within rounding: within their error bound, or (the second
    pass's rotation leaves a line's points off it by ~eps of their spread) below 64 eps of the largest
    moment, the motion's rounding level."""
    line = 64 * EPS * max(values)
    return [v <= e or v <= line for v, e in zip(values, errors)]


_RESOLUTION_REFUSE = 1.0
"""Refuse a surface whose volume or a moment could change by this fraction of itself when every
stored coordinate moves by its resolution: the file does not determine the body."""
_BLOCK = 1 << 16  # points (the reach) or triangles (the area) per block of the resolution check
_RESOLUTION_WARN = 1e-3
"""Warn (naming the resolution) above this fraction: the stored polyhedron is computed exactly,
but it may differ that much from the part it was exported from."""


def _check_resolution(
    geometry: Geometry, s: Sums, com: NDArray[np.float64], rotation: NDArray[np.float64], values: NDArray[np.float64]
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
    rows = range(0, len(x), _BLOCK)
    reach_rows = np.empty((len(rows), 3))

    def reach_block(start: int) -> None:
        # row by row, as on the whole array: x - com, its principal-frame coordinates (columns of rotation are
        # the axes), and each point's largest squared distance from each axis
        along = (x[start : start + _BLOCK] - com) @ rotation
        sq = along * along
        total = sq[:, 0] + sq[:, 1] + sq[:, 2]  # once, not once per axis; as sum(axis=1) adds three, ~7x faster
        reach_rows[start // _BLOCK] = [np.max(total - sq[:, k]) for k in range(3)]

    for_each_block(reach_block, rows)
    reach = reach_rows.max(axis=0)
    # the surface's area as the surface_area section computes it, which then takes it from here (surface.py)
    area = triangle_area(x, geometry.cells)
    weight = 1.0 if geometry.weight is None else float(np.max(geometry.weight))
    moved = math.sqrt(3.0) * delta * area  # volume the resolution can move
    volume = abs(s.measure)
    ratio_v = moved / volume if volume > 0 else math.inf
    ratio_i = float(np.max(moved * weight * reach / values))
    ratio = max(ratio_v, ratio_i)
    if not ratio >= _RESOLUTION_WARN:
        return ()
    float32 = geometry.coordinate_eps >= 2.0**-24
    if float32 and _on_coarse_grid(x, geometry.coordinate_eps):
        return ()  # the stored values are the exporter's own: the polyhedron read is the part
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


_GRID_EVIDENCE_BITS = 12
"""Bits of chance (one in 4,096) against rounded coordinates all falling on ``_on_coarse_grid``'s grid."""


def _on_coarse_grid(x: NDArray[np.float64], eps: float) -> bool:
    """The coordinates evidently were not rounded to their storage: they lie on a grid coarser than it.

    The resolution check assumes each stored coordinate was rounded from the exporter's value.  A
    part drawn on whole units (a box from 1,000,000 to 1,000,003 in float32, whose step there is
    1/16) uses fewer bits than its storage has: those values were stored exactly, the polyhedron
    read is the part, and its numbers are exact (API.md: "exactly the polyhedron that was read").
    A rounded value falls on a grid of 2**j storage steps once in 2**j, so each distinct value of
    a coordinate on it is j bits of evidence; ``_GRID_EVIDENCE_BITS`` of them decide.  Dividing by a
    power of two is exact, so the test is too.
    """
    largest = float(np.abs(x).max())
    if largest == 0.0:
        return False
    step = math.ldexp(eps, math.frexp(largest)[1])  # largest < 2^e, where a stored step is eps 2^e
    scaled = x / step
    if not np.all(scaled == np.floor(scaled)):
        return False  # a value finer than the largest one's step: nothing coarser to go by
    whole = scaled.astype(np.int64)  # |scaled| <= 1 / eps: exact
    nonzero = whole[whole != 0]
    if len(nonzero) == 0:
        return False
    j = int(np.min(nonzero & -nonzero)).bit_length() - 1  # trailing zero bits common to every value
    distinct = sum(len(np.unique(column[column != 0])) for column in whole.T)
    return j * distinct >= _GRID_EVIDENCE_BITS


_TINY = float(np.finfo(np.float64).tiny)


def _offdiagonal_ratio(t: list[list[float]]) -> float:
    worst = 0.0
    for i, j in ((0, 1), (0, 2), (1, 2)):
        product = abs(t[i][i] * t[j][j])  # Python floats: an overflow is inf, without a warning
        if math.isfinite(product) and product >= _TINY:
            scale = math.sqrt(product)
        else:  # beyond ~1e154 or below ~1e-154 the product leaves float64's range; the root of each does not
            scale = math.sqrt(abs(t[i][i])) * math.sqrt(abs(t[j][j]))
        if t[i][j] != 0.0:
            worst = max(worst, abs(t[i][j]) / scale if scale > 0 else math.inf)
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
    estimate, errors = moment_errors(s.abs_m2.diagonal().tolist(), s.element_err.tolist(), s.terms, s.blocks, moments.tolist())
    return estimate, np.array(errors)


def moment_errors(
    abs_diagonal: list[float], element_err: list[float], terms: int, blocks: int, moments: list[float]
) -> tuple[float, list[float]]:
    """``_error_estimate`` on Python floats: the sums' ``abs_m2`` diagonal and ``element_err``, the
    count of terms and blocks, and the moments (a 3-vector costs numpy more per call than the work)."""
    per_block = max(2, math.ceil(terms / max(blocks, 1)))
    gamma = (math.log2(per_block) + math.log2(max(blocks, 1)) + 4) * EPS
    d = [gamma * a + 8 * EPS * e for a, e in zip(abs_diagonal, element_err)]
    errors = [d[1] + d[2], d[0] + d[2], d[0] + d[1]]
    live = [err / m for err, m in zip(errors, moments) if m > err]
    worst = max(live) if live else 1.0
    return max(worst, 4 * EPS), errors


def _check_volume(s: Sums, kind: str, cells: NDArray[np.int64] | None = None) -> None:
    if kind in ("apex", "tet") and abs(s.m0) <= 64 * EPS * s.noise:
        twins = _reverse_twins(cells) if kind == "apex" and cells is not None else 0
        if twins:
            raise ZeroVolumeError(
                f"the mesh encloses no volume: {twins} of its {len(cells) if cells is not None else 0} triangles are "
                "stored twice, as the two sides of one sheet (a double-sided surface, not a solid; copies stored "
                "with the same winding are read so too); send the solid's closed outer surface, or use model=shell "
                "with a thickness",
                volume=s.m0,
                double_sided_triangles=twins,
            )
        raise ZeroVolumeError(
            "the mesh encloses no volume (it is flat or degenerate); send a solid or use model=shell with a thickness",
            volume=s.m0,
        )
    if kind == "tri" and s.m0 <= 0:
        raise ZeroVolumeError("the surface has zero area; send a mesh with non-degenerate triangles")


def _reverse_twins(cells: NDArray[np.int64]) -> int:
    """How many triangles have a twin of the same three corners wound the other way (double-sided sheets)."""
    if len(cells) < 2:
        return 0
    order = np.argsort(cells, axis=1)
    corners = np.take_along_axis(cells, order, axis=1)
    # the winding of each triangle as written: whether sorting its corners took an odd permutation
    odd = (order[:, 0] > order[:, 1]) ^ (order[:, 1] > order[:, 2]) ^ (order[:, 0] > order[:, 2])
    unique, inverse = np.unique(corners, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    # a set of corners stored with both windings: its triangles are twins of each other
    wound_odd, wound_even = np.zeros(len(unique), dtype=bool), np.zeros(len(unique), dtype=bool)
    wound_odd[inverse[odd]] = True
    wound_even[inverse[~odd]] = True
    return int(np.count_nonzero((wound_odd & wound_even)[inverse]))
