"""Mass properties: mass, centre of mass and inertia tensor, exactly.

Closed triangle surfaces are integrated with the divergence theorem as a sum
of signed tetrahedra spanned by each face and a local origin (Mirtich, J.
Graphics Tools 1(2), 1996; Eberly, "Polyhedral Mass Properties (Revisited)",
2002; Tonon, J. Math. Stat. 1(1), 2004).  For a tetrahedron with vertices p_k
and volume V, with S = sum p_k (Tonon eq. 7-8 in our notation):

    int x_i dV     = V S_i / 4
    int x_i x_j dV = V / 20 (sum_k p_ki p_kj + S_i S_j)

A triangle of area A (shell model) gives int x_i x_j dA = A/12 (sum_k p_ki p_kj
+ S_i S_j), int x_i dA = A S_i / 3.  Point masses are summed directly.

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
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .body import Body, MeshBody, PointBody, VolumeBody
from .errors import InvalidParameterError, NotWatertightError, ZeroVolumeError
from .principal import jacobi_eigh
from .tolerances import DEFAULT_TOLERANCES, EPS, Tolerances
from .topology import face_components, orient_consistently, surface_topology, weld

__all__ = ["InertiaTensor", "MassProperties", "mass_properties", "Model", "parallel_axis"]

CHUNK = 1 << 15  # elements per vectorised block: its (n,) temporaries (256 KB each) stay in cache
MAX_PASSES = 4  # one coarse pass plus refinements; the frame settles in 2-3
FRAME_SETTLED = 1e-7  # off-diagonal / sqrt(diag product) below this: the next pass moves moments < 1e-14


class Model:
    SOLID = "solid"
    SHELL = "shell"
    ALL = (SOLID, SHELL)


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
        for name in ("matrix", "point"):
            arr = np.array(getattr(self, name), dtype=np.float64)
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)


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
    return tensor + mass * (np.dot(a, a) * np.eye(3) - np.outer(a, a))


@dataclass(frozen=True, slots=True)
class _Sums:
    """Integrals over the body about the local origin (unit density or weights).

    m0 : int dm.  m1 : (3,) int x dm.  m2 : (3, 3) int x x^T dm.
    abs_m2 : (3, 3) sums of |contribution|, the scale of rounding errors.
    noise : rounding scale of m0 (sum of |a||b||c| / 6 for surfaces).
    terms : number of elements summed.
    """

    m0: float
    m1: NDArray[np.float64]
    m2: NDArray[np.float64]
    abs_m0: float
    abs_m2: NDArray[np.float64]
    noise: float
    terms: int
    element_err: NDArray[np.float64]  # (3,) per-element rounding scale of m2 diagonal


_IJ = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))
# rows of a block: m0, m1 x3, m2 x6 (xx yy zz xy xz yz), det noise, error scale of xx yy zz
ROWS = 14


def _block_terms(p: NDArray[np.float64], kind: str, weight: NDArray[np.float64] | None) -> NDArray[np.float64]:
    """Per-element [m0, m1 (3), m2 (6), noise] for one block of simplices."""
    if kind == "apex":  # tetrahedron (0, a, b, c) of a closed surface
        a, b, c = p[:, 0], p[:, 1], p[:, 2]
        cross = np.cross(b, c)
        dm = np.einsum("ij,ij->i", a, cross) / 6.0
        s = a + b + c
        f1, f2 = dm / 4.0, dm / 20.0
        noise = _det_condition(a, b, c) / 6.0
        verts = (a, b, c)
    elif kind == "tet":  # volume cell
        e1, e2, e3 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]
        cross = np.cross(e2, e3)
        dm = np.abs(np.einsum("ij,ij->i", e1, cross)) / 6.0
        s = p[:, 0] + p[:, 1] + p[:, 2] + p[:, 3]
        f1, f2 = dm / 4.0, dm / 20.0
        noise = _det_condition(e1, e2, e3) / 6.0
        verts = (p[:, 0], p[:, 1], p[:, 2], p[:, 3])
    else:  # "tri": thin shell, area measure
        a, b, c = p[:, 0], p[:, 1], p[:, 2]
        dm = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
        s = a + b + c
        f1, f2 = dm / 3.0, dm / 12.0
        noise = dm
        verts = (a, b, c)
    if weight is not None:
        dm, f1, f2 = dm * weight, f1 * weight, f2 * weight
    out = np.empty((ROWS, len(p)))
    out[0] = dm
    out[1:4] = (f1[:, None] * s).T
    for row, (i, j) in enumerate(_IJ, start=4):
        acc = s[:, i] * s[:, j]
        for v in verts:
            acc += v[:, i] * v[:, j]
        out[row] = f2 * acc
        if row < 7:  # diagonal: error of this element's term, |dm| + det noise
            out[row + 7] = acc * (np.abs(f2) + noise * (1.0 / 20.0 if weight is None else np.abs(weight) / 20.0))
    out[10] = noise if weight is None else noise * np.abs(weight)
    return out


def _det_condition(a: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64]) -> NDArray[np.float64]:
    """sum over permutations of |a_i b_j c_k|: rounding of a . (b x c) is a few eps times this."""
    i, j = [1, 2, 0], [2, 0, 1]
    abs_cross = np.abs(b[:, i] * c[:, j]) + np.abs(b[:, j] * c[:, i])
    return np.einsum("ij,ij->i", np.abs(a), abs_cross)


def _apex_block_sums(xyz: list[NDArray[np.float64]], cells: NDArray[np.int64],
                     total: NDArray[np.float64], total_abs: NDArray[np.float64]) -> None:
    """Add the row sums of ``_block_terms(points[cells], "apex", None)`` to total, total_abs.

    The same terms with the same arithmetic, element by element, on
    contiguous (n,) component arrays: no (n, 3) strided views, no np.cross or
    einsum dispatch, and each row is summed as soon as it is formed (numpy's
    pairwise sum over a contiguous row, as ``terms.sum(axis=1)`` does).
    """
    idx = [cells[:, k] for k in range(3)]
    a, b, c = ([x.take(i) for x in xyz] for i in idx)  # a[k]: component k of the first corners
    crx = b[1] * c[2] - b[2] * c[1]  # b x c, as np.cross forms it
    cry = b[2] * c[0] - b[0] * c[2]
    crz = b[0] * c[1] - b[1] * c[0]
    dm = (a[0] * crx + a[1] * cry + a[2] * crz) / 6.0
    del crx, cry, crz
    abs_a = [np.abs(v) for v in a]
    noise = (abs_a[0] * (np.abs(b[1] * c[2]) + np.abs(b[2] * c[1]))  # _det_condition
             + abs_a[1] * (np.abs(b[2] * c[0]) + np.abs(b[0] * c[2]))
             + abs_a[2] * (np.abs(b[0] * c[1]) + np.abs(b[1] * c[0]))) / 6.0
    del abs_a
    s = [a[k] + b[k] + c[k] for k in range(3)]
    f1, f2 = dm / 4.0, dm / 20.0
    err_factor = np.abs(f2) + noise * (1.0 / 20.0)
    _add_row(total, total_abs, 0, dm)
    for k in range(3):
        _add_row(total, total_abs, 1 + k, f1 * s[k])
    for row, (i, j) in enumerate(_IJ, start=4):
        acc = s[i] * s[j]
        for v in (a, b, c):
            acc += v[i] * v[j]
        _add_row(total, total_abs, row, f2 * acc)
        if row < 7:  # diagonal: error of this element's term (non-negative)
            acc *= err_factor
            total[row + 7] += acc.sum()
            total_abs[row + 7] += acc.sum()
    total[10] += noise.sum()
    total_abs[10] += noise.sum()


def _add_row(total: NDArray[np.float64], total_abs: NDArray[np.float64], row: int, terms: NDArray[np.float64]) -> None:
    total[row] += terms.sum()
    total_abs[row] += np.abs(terms).sum()


def _integrate(
    points: NDArray[np.float64],
    cells: NDArray[np.int64],
    kind: str,
    weight: NDArray[np.float64] | None,
) -> _Sums:
    total = np.zeros(ROWS)
    total_abs = np.zeros(ROWS)
    if kind == "apex" and weight is None:
        xyz = [np.ascontiguousarray(points[:, k]) for k in range(3)]  # struct of arrays
        for start in range(0, len(cells), CHUNK):
            _apex_block_sums(xyz, cells[start : start + CHUNK], total, total_abs)
        return _sums_from_rows(total, total_abs, len(cells))
    for start in range(0, len(cells), CHUNK):
        block = points[cells[start : start + CHUNK]]
        w = None if weight is None else weight[start : start + CHUNK]
        terms = _block_terms(block, kind, w)
        total += terms.sum(axis=1)
        total_abs += np.abs(terms).sum(axis=1)
    return _sums_from_rows(total, total_abs, len(cells))


def _sums_from_rows(total: NDArray[np.float64], total_abs: NDArray[np.float64], n: int) -> _Sums:
    m2 = np.empty((3, 3))
    a2 = np.empty((3, 3))
    for row, (i, j) in enumerate(_IJ, start=4):
        m2[i, j] = m2[j, i] = total[row]
        a2[i, j] = a2[j, i] = total_abs[row]
    return _Sums(float(total[0]), total[1:4].copy(), m2, float(total_abs[0]), a2, float(total[10]), n,
                 total[11:14].copy())


def _point_sums(masses: NDArray[np.float64], x: NDArray[np.float64]) -> _Sums:
    m1 = (masses[:, None] * x).sum(axis=0)
    m2 = np.empty((3, 3))
    for i, j in _IJ:
        m2[i, j] = m2[j, i] = float((masses * x[:, i] * x[:, j]).sum())
    diag_scale = np.array([float((masses * x[:, i] ** 2).sum()) for i in range(3)])
    return _Sums(float(masses.sum()), m1, m2, float(masses.sum()), np.abs(m2), 0.0, len(masses), diag_scale)


def _local_origin(points: NDArray[np.float64]) -> NDArray[np.float64]:
    """A point of the body's own float grid near its middle.

    The midpoint of the bounding box, rounded to float64, lies between the
    extreme coordinates, so for a body far from the origin every difference
    point - origin is exact (Sterbenz).
    """
    lo = points.min(axis=0)
    hi = points.max(axis=0)
    return lo + 0.5 * (hi - lo)


_SPLIT = 134217729.0  # 2^27 + 1, Dekker's splitting constant for float64


def _two_sum(a: NDArray[np.float64], b: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)  # Knuth, TAOCP vol. 2, 4.2.2


def _two_prod(a: NDArray[np.float64] | float, b: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    p = a * b
    ca = _SPLIT * a
    ah = ca - (ca - a)
    al = a - ah
    cb = _SPLIT * b
    bh = cb - (cb - b)
    bl = b - bh
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl  # Dekker 1971


def _rotated(points: NDArray[np.float64], origin: NDArray[np.float64], rotation: NDArray[np.float64]) -> NDArray[np.float64]:
    """(points - origin) @ rotation, each result rounded once from exact.

    The difference and the dot products are carried in double-double
    (Ogita, Rump & Oishi, SIAM J. Sci. Comput. 26, 2005), so a rotated
    coordinate is accurate to its own last bit, however small it is next to
    the body's size: the thin coordinates of a needle in its principal frame
    keep full relative precision.
    """
    n = len(points)
    d_hi = np.empty((n, 3))
    d_lo = np.empty((n, 3))
    for i in range(3):
        d_hi[:, i], d_lo[:, i] = _two_sum(points[:, i], np.full(n, -origin[i]))
    out = np.empty((n, 3))
    for j in range(3):
        hi, lo = _two_prod(rotation[0, j], d_hi[:, 0])
        lo = lo + rotation[0, j] * d_lo[:, 0]
        for i in (1, 2):
            p, e = _two_prod(rotation[i, j], d_hi[:, i])
            hi, e2 = _two_sum(hi, p)
            lo = lo + (e + e2 + rotation[i, j] * d_lo[:, i])
        out[:, j] = hi + lo
    return out


def _covariance(s: _Sums) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
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

    def __init__(self, points: NDArray[np.float64], cells: NDArray[np.int64], kind: str,
                 weight: NDArray[np.float64] | None) -> None:
        self.points, self.cells, self.kind, self.weight = points, cells, kind, weight

    @property
    def referenced_points(self) -> int:
        return len(self.points)

    def sums(self, origin: NDArray[np.float64], rotation: NDArray[np.float64] | None) -> _Sums:
        if rotation is None:
            x = self.points - origin
        else:
            x = _rotated(self.points, origin, rotation)
        if self.kind == "points":
            assert self.weight is not None
            return _point_sums(self.weight, x)
        return _integrate(x, self.cells, self.kind, self.weight)


def _refine(geometry: _Geometry, tolerances: Tolerances) -> tuple[_Sums, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], float]:
    """Multi-pass integration.  Returns final sums, COM, tensor (input frame),
    moments, axes (rows) and the relative error estimate of the moments."""
    origin = _local_origin(geometry.points)
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
    if not np.abs(values).max() > 0:
        raise InvalidParameterError(
            "the masses all sit at one point, so the body has no rotational inertia; "
            "send at least two distinct positions"
        )
    estimate = _error_estimate(s, values)
    if not settled:
        estimate = max(estimate, step)
    tensor = rotation @ np.diag(values) @ rotation.T
    tensor = 0.5 * (tensor + tensor.T)
    return s, com, tensor, values, rotation.T.copy(), estimate


def _offdiagonal_ratio(t: NDArray[np.float64]) -> float:
    worst = 0.0
    for i, j in ((0, 1), (0, 2), (1, 2)):
        scale = math.sqrt(abs(t[i, i] * t[j, j]))
        if t[i, j] != 0.0:
            worst = max(worst, abs(t[i, j]) / scale if scale > 0 else math.inf)
    return worst


def _error_estimate(s: _Sums, moments: NDArray[np.float64]) -> float:
    """Relative rounding-error bound of each principal moment, the worst one.

    In the final pass (principal frame, about the centre of mass) the
    coordinates are exact to their last bit, so the error comes from each
    element's own arithmetic (a few eps times its determinant's condition,
    ``element_err``) and from the summation, bounded by gamma * sum |terms|
    with gamma growing as the pairwise depth log2(CHUNK) plus the number of
    blocks (Higham, Accuracy and Stability of Numerical Algorithms, §4.2).
    """
    n_blocks = max(1, math.ceil(s.terms / CHUNK))
    gamma = (math.log2(min(max(s.terms, 2), CHUNK)) + n_blocks + 4) * EPS
    diag_err = gamma * np.diag(s.abs_m2) + 8 * EPS * s.element_err
    worst = 0.0
    for k in range(3):
        err = sum(diag_err[j] for j in range(3) if j != k)
        if moments[k] > 0:
            worst = max(worst, err / moments[k])
        elif err > 0:
            worst = math.inf
    return max(worst, 4 * EPS)


def _check_volume(s: _Sums, kind: str) -> None:
    if kind in ("apex", "tet") and abs(s.m0) <= 64 * EPS * s.noise:
        raise ZeroVolumeError(
            "the mesh encloses no volume (it is flat or degenerate); send a solid or use model=shell with a thickness",
            volume=s.m0,
        )
    if kind == "tri" and s.m0 <= 0:
        raise ZeroVolumeError("the surface has zero area; send a mesh with non-degenerate triangles")


def _solid_surface(body: MeshBody, tolerances: Tolerances) -> tuple[_Geometry, tuple[str, ...]]:
    """Weld, check closedness, repair winding; the geometry to integrate."""
    vertices, faces = weld(body.vertices, body.faces)
    degenerate = (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2])
    if np.any(degenerate):
        faces = faces[~degenerate]  # zero-area faces contribute nothing to any integral
    if len(faces) == 0:
        raise ZeroVolumeError("every triangle of the mesh is degenerate; the file holds no solid")
    topo = surface_topology(faces, len(vertices))
    warnings: list[str] = []
    if topo.open_edges:
        raise NotWatertightError(
            f"mesh is not watertight ({topo.open_edges} open edges), so it does not bound a solid; "
            "repair it, or analyse it as a thin surface with model=shell and a thickness",
            open_edges=topo.open_edges,
        )
    if not topo.closed:
        faces, flipped = orient_consistently(faces, topo)
        topo = surface_topology(faces, len(vertices))
        if not topo.closed:
            raise NotWatertightError(
                f"mesh winding cannot be made consistent ({topo.unbalanced_edges} edges disagree); "
                "repair the mesh or use model=shell",
                unbalanced_edges=topo.unbalanced_edges,
            )
        warnings.append(f"inconsistent winding repaired ({flipped} of {len(faces)} faces flipped)")
    faces, more = _orient_outward(vertices, faces, topo)
    warnings.extend(more)
    return _Geometry(vertices, faces, "apex", None), tuple(warnings)


def _orient_outward(vertices: NDArray[np.float64], faces: NDArray[np.int64], topo) -> tuple[NDArray[np.int64], list[str]]:  # type: ignore[no-untyped-def]
    """Make every shell bound positive volume, except cavities inside another shell."""
    origin = _local_origin(vertices)
    x = vertices - origin
    tri = x[faces]
    det = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))
    if np.all(det >= 0):
        return faces, []
    count, label = face_components(faces, topo)
    vol = np.bincount(label, weights=det, minlength=count)
    if count == 1 or np.all(vol < 0):
        if vol.sum() < 0:
            return faces[:, [0, 2, 1]], ["inverted winding corrected (all faces pointed inward)"]
        return faces, []
    lo = np.full((count, 3), np.inf)
    hi = np.full((count, 3), -np.inf)
    corners = x[faces].reshape(-1, 3)
    lab3 = np.repeat(label, 3)
    for k in range(3):
        np.minimum.at(lo[:, k], lab3, corners[:, k])
        np.maximum.at(hi[:, k], lab3, corners[:, k])
    flip_shell = np.zeros(count, dtype=bool)
    for shell in np.flatnonzero(vol < 0):
        inside = (vol > 0) & np.all(lo <= lo[shell], axis=1) & np.all(hi >= hi[shell], axis=1)
        flip_shell[shell] = not np.any(inside)
    if not np.any(flip_shell):
        return faces, []
    out = faces.copy()
    sel = flip_shell[label]
    out[sel] = out[sel][:, [0, 2, 1]]
    return out, [f"inverted winding corrected on {int(flip_shell.sum())} of {count} shells"]


def _geometry(body: Body, model: str, thickness: float | None, tolerances: Tolerances) -> tuple[_Geometry, tuple[str, ...]]:
    if isinstance(body, PointBody):
        return _Geometry(body.positions, np.empty((0, 0), np.int64), "points", body.masses), ()
    if isinstance(body, VolumeBody):
        if model == Model.SHELL:
            raise InvalidParameterError("model=shell needs a surface mesh; a volume mesh is always a solid", parameter="model")
        return _Geometry(body.points, body.tets, "tet", body.cell_density), ()
    if model == Model.SHELL:
        return _Geometry(body.vertices, body.faces, "tri", None), ()
    return _solid_surface(body, tolerances)


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
    s, com, tensor, moments, axes, estimate = _refine(geometry, tolerances)
    L = body.length_scale
    if isinstance(body, PointBody):
        measure_to_mass = 1.0 if mass is None else mass / s.m0
        length_power = 2
        volume = uniform_density = area = None
    elif model == Model.SHELL:
        area = s.m0 * L**2
        assert thickness is not None
        shell_volume = area * thickness * L
        rho = density if density is not None else (1000.0 if mass is None else mass / shell_volume)
        measure_to_mass = rho * thickness * L
        length_power = 4
        volume, uniform_density = None, rho
    else:
        area = None
        volume = s.m0 * L**3
        weighted = isinstance(body, VolumeBody) and body.cell_density is not None
        if weighted:
            volume = _unweighted_volume(geometry) * L**3
            measure_to_mass = 1.0 if mass is None else mass / (s.m0 * L**3)
            uniform_density = None
        else:
            rho = density if density is not None else (1000.0 if mass is None else mass / volume)
            measure_to_mass = rho
            uniform_density = rho
        length_power = 5
    # measure-space integrals are in file units; scale lengths then multiply by density
    to_mass = measure_to_mass * (L**3 if length_power == 5 else L**2 if length_power == 4 else 1.0)
    total_mass = s.m0 * to_mass
    inertia_scale = measure_to_mass * L**length_power
    moments_si = moments * inertia_scale
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
        warnings=body.warnings + warnings,
        mesh_vertices=geometry.referenced_points if geometry.kind == "apex" else None,
    )


def _unweighted_volume(geometry: _Geometry) -> float:
    return _Geometry(geometry.points, geometry.cells, geometry.kind, None).sums(
        _local_origin(geometry.points), None
    ).m0


def _check_material(body: Body, density: float | None, mass: float | None, model: str, thickness: float | None) -> None:
    if model not in Model.ALL:
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
