"""Volume integrals of free-form B-rep faces by Green's theorem in each face's parameter plane.

OpenCASCADE's adaptive rule (``BRepGProp.VolumeProperties_s`` with an accuracy) checks its
convergence on the volume alone and chooses its Gauss order and its intervals from the
surface type.  On analytic faces (planes, cylinders, cones, spheres, tori bounded by lines
and circles) it integrates every moment to rounding.  Elsewhere it can stop far from the
answer while reporting convergence: measured on an extruded B-spline profile, 7 % off in
volume (its ``SurfaceOfExtrusion`` face gets neither the curve's knots nor enough points),
and 4.7e-7 off in the moments on the planar end faces, whose B-spline boundary is
integrated to the volume's degree only; the two-accuracy difference there is zero.  Its
Gauss-Kronrod variant converges, but takes seconds to minutes on symmetric or rational
faces (a component that is zero by symmetry never meets a relative tolerance).

So every other face is integrated here.  A closed surface bounds the volume; with
``r = P - L`` about a point ``L`` inside the part's box, the divergence theorem turns each
volume integral into a surface one (``div(r) = 3``, ``div(x r) = 4 x``, ``div(x y r) = 5 x y``):

    V = 1/3 ∮ r·n dA,   ∫ x dV = 1/4 ∮ x (r·n) dA,   ∫ x y dV = 1/5 ∮ x y (r·n) dA,

the same integrands as OpenCASCADE's ``BRepGProp_Gauss``.  On a face ``S(u, v)``,
``n dA = S_u × S_v du dv`` (reversed on a reversed face), and the trimmed parameter domain D
is bounded by the edges' curves on the face.  Green's theorem in the (u, v) plane makes
the area integral a boundary one,

    ∫∫_D f du dv = ∮_∂D F(u, v) dv,   F(u, v) = ∫_{u0}^{u} f(s, v) ds,

with ``u0`` the face's lower u bound: an outer integral along each edge's curve, and an
inner one along u at that point's v.  ``BRepGProp_Face`` and ``BRepGProp_Domain`` give
the face's points, oriented normals and edge curves, so the orientation conventions are
OpenCASCADE's own.

Both integrals are adaptive Gauss-Kronrod (15 points, with the embedded 7-point Gauss rule:
QUADPACK's ``qk15``, Piessens et al. 1983).  The integrand is piecewise smooth: it breaks
at the surface's knots (inner: u; outer: where the edge's curve crosses a knot line, found
exactly for straight edges) and at the edge curve's own knots, so the intervals start
there.  An interval is accepted when Kronrod and Gauss agree to ``tolerance`` in every
component; the sum of their differences, which exceeds the error of the Kronrod sums
returned, is the error estimate, with each inner error weighted as it enters the outer sum.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["SUMS", "is_analytic", "closed_shell_faces", "face_sums"]

SUMS = 14
"""Integrals per face, about L: V, ∫x, ∫y, ∫z, ∫x², ∫y², ∫z², ∫xy, ∫xz, ∫yz (dV); the face's
vector area ∫n dA, whose sum over a closed surface is zero (what is left measures how far the
faces of a file fail to close, on which the volume integrals depend); and its area ∫dA."""

# QUADPACK qk15: Kronrod nodes on [0, 1] (the odd ones, 1, 3, 5, 7, are the 7-point Gauss nodes) and weights
_XK = np.array(
    [
        0.991455371120812639206854697526329,
        0.949107912342758524526189684047851,
        0.864864423359769072789712788640926,
        0.741531185599394439863864773280788,
        0.586087235467691130294144845693013,
        0.405845151377397166906606412076961,
        0.207784955007898467600689403773245,
        0.000000000000000000000000000000000,
    ]
)
_WK = np.array(
    [
        0.022935322010529224963732008058970,
        0.063092092629978553290700663189204,
        0.104790010322250183839876322541518,
        0.140653259715525918745189590510238,
        0.169004726639267902826583426598550,
        0.190350578064785409913256402421014,
        0.204432940075298892414161999234649,
        0.209482141084727828012999174891714,
    ]
)
_WG = np.array(
    [
        0.129484966168869693270611432679082,
        0.279705391489276667901467771423780,
        0.381830050505118944950369775488975,
        0.417959183673469387755102040816327,
    ]
)
NODES = np.concatenate([-_XK[:-1], _XK[::-1]])  # 15 nodes on [-1, 1], ascending
KRONROD = np.concatenate([_WK[:-1], _WK[::-1]])
GAUSS = np.zeros(15)
GAUSS[[1, 3, 5, 13, 11, 9]] = np.concatenate([_WG[:-1], _WG[:-1]])
GAUSS[7] = _WG[-1]

MAX_DEPTH = 16  # bisections of one starting interval; past it the interval is taken with its error
# Intervals evaluated by one adaptive integration, per starting interval (plus a floor): a smooth integrand
# needs a few each, a singular corner a few dozen along one path; one that never converges (a degenerate
# surface) doubles them every round, 2^16 times its start by MAX_DEPTH.  Past the budget the open intervals
# are taken with their errors, as at MAX_DEPTH.
WORK_PER_START, WORK_FLOOR = 16, 2048


def is_analytic(face: Any) -> bool:
    """Whether OpenCASCADE's adaptive rule integrates the face's moments to rounding: an analytic
    surface bounded by straight lines and circles in its parameter plane (degenerate edges aside)."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve2d, BRepAdaptor_Surface
    from OCP.GeomAbs import (
        GeomAbs_Circle,
        GeomAbs_Cone,
        GeomAbs_Cylinder,
        GeomAbs_Line,
        GeomAbs_Plane,
        GeomAbs_Sphere,
        GeomAbs_Torus,
    )
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    if BRepAdaptor_Surface(face, False).GetType() not in (
        GeomAbs_Plane,
        GeomAbs_Cylinder,
        GeomAbs_Cone,
        GeomAbs_Sphere,
        GeomAbs_Torus,
    ):
        return False
    explorer = TopExp_Explorer(face, TopAbs_EDGE)
    while explorer.More():
        edge = TopoDS.Edge(explorer.Current())
        if not BRep_Tool.Degenerated_s(edge) and BRepAdaptor_Curve2d(edge, face).GetType() not in (GeomAbs_Line, GeomAbs_Circle):
            return False
        explorer.Next()
    return True


def closed_shell_faces(shape: Any) -> Iterator[Any]:
    """The faces of the shape's closed shells, located and oriented as in the shape."""
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_FACE, TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    shells = TopExp_Explorer(shape, TopAbs_SHELL)
    while shells.More():
        shell = TopoDS.Shell(shells.Current())
        if BRep_Tool.IsClosed_s(shell):
            faces = TopExp_Explorer(shell, TopAbs_FACE)
            while faces.More():
                yield TopoDS.Face(faces.Current())
                faces.Next()
        shells.Next()


def _adaptive(
    values: Callable[[NDArray[np.float64], NDArray[np.intp]], NDArray[np.float64]],
    lo: NDArray[np.float64],
    hi: NDArray[np.float64],
    owner: NDArray[np.intp],
    count: int,
    tolerance: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``count`` integrals of a vector integrand, each over the intervals [lo, hi] that ``owner`` gives
    it, and their errors: (count, SUMS) each.  ``values(x, owner)`` is the integrand at the nodes x of
    intervals of those owners, (len(x), SUMS).  The intervals still open are evaluated together, one
    call of ``values`` per round of bisection."""
    total, error = np.zeros((count, SUMS)), np.zeros((count, SUMS))
    keep = hi > lo
    lo, hi, owner = lo[keep], hi[keep], owner[keep]
    budget = WORK_PER_START * lo.size + WORK_FLOOR
    for depth in range(MAX_DEPTH + 1):
        if lo.size == 0:
            break
        budget -= lo.size
        middle, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        nodes = (middle[:, None] + half[:, None] * NODES).ravel()
        f = values(nodes, np.repeat(owner, NODES.size)).reshape(lo.size, NODES.size, SUMS)
        if not np.all(np.isfinite(f)):
            raise ValueError("the surface gives a point or normal that is not a finite number (degenerate geometry)")
        kronrod = half[:, None] * np.einsum("k,ikj->ij", KRONROD, f)
        difference = np.abs(kronrod - half[:, None] * np.einsum("k,ikj->ij", GAUSS, f))
        done = np.all(difference <= tolerance, axis=1) | (depth == MAX_DEPTH) | (budget < 2 * lo.size)
        np.add.at(total, owner[done], kronrod[done])
        np.add.at(error, owner[done], difference[done])
        lo, middle, hi, owner = lo[~done], middle[~done], hi[~done], owner[~done]
        lo, hi, owner = np.concatenate([lo, middle]), np.concatenate([middle, hi]), np.concatenate([owner, owner])
    return total, error


def _adaptive_one(
    values: Callable[[NDArray[np.float64]], NDArray[np.float64]], breaks: list[float], tolerance: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """One integral over [breaks[0], breaks[-1]], its intervals starting at ``breaks``."""
    cuts = np.array(breaks, dtype=np.float64)
    total, error = _adaptive(lambda x, _: values(x), cuts[:-1], cuts[1:], np.zeros(len(breaks) - 1, dtype=np.intp), 1, tolerance)
    return total[0], error[0]


def _breaks(lo: float, hi: float, knots: list[float]) -> list[float]:
    return [lo, *(k for k in knots if lo < k < hi), hi]


def _intervals(count: int, fill: Callable[[Any], None]) -> list[float]:
    from OCP.collections import Array1_double

    array = Array1_double(1, count + 1)
    fill(array)
    return sorted(array.Value(i) for i in range(1, count + 2))


class _Face:
    """One face's integrals about ``origin`` with an absolute ``tolerance`` per component."""

    def __init__(self, face: Any, origin: NDArray[np.float64], tolerance: NDArray[np.float64]) -> None:
        from OCP.BRepAdaptor import BRepAdaptor_Surface
        from OCP.BRepGProp import BRepGProp_Face
        from OCP.GeomAbs import GeomAbs_CN
        from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec, gp_Vec2d

        self.face = face
        self.surface = BRepGProp_Face(face, False)
        self.u_lo, self.u_hi, self.v_lo, self.v_hi = self.surface.Bounds()
        adaptor = BRepAdaptor_Surface(face, True)
        self.u_knots = _intervals(adaptor.NbUIntervals(GeomAbs_CN), lambda a: adaptor.UIntervals(a, GeomAbs_CN))
        self.v_knots = _intervals(adaptor.NbVIntervals(GeomAbs_CN), lambda a: adaptor.VIntervals(a, GeomAbs_CN))
        self.origin = origin
        self.tolerance = tolerance
        self._point, self._normal, self._point2d, self._tangent2d = gp_Pnt(), gp_Vec(), gp_Pnt2d(), gp_Vec2d()

    def integrand(self, us: NDArray[np.float64], vs: NDArray[np.float64]) -> NDArray[np.float64]:
        """The integrands (``SUMS``) times |S_u × S_v| at each (u, v) (OpenCASCADE's oriented normal)."""
        point, normal, surface = self._point, self._normal, self.surface
        rows = []
        for u, v in zip(us.tolist(), vs.tolist()):
            surface.Normal(u, v, point, normal)
            rows.append(point.Coord() + normal.Coord())
        q = np.array(rows)
        r = q[:, :3] - self.origin
        dv = np.einsum("ij,ij->i", r, q[:, 3:])
        out = np.empty((len(rows), SUMS))
        out[:, 0] = dv / 3
        out[:, 1:4] = r * (dv / 4)[:, None]
        fifth = r * (dv / 5)[:, None]
        out[:, 4:7] = r * fifth
        out[:, 7] = r[:, 0] * fifth[:, 1]
        out[:, 8] = r[:, 0] * fifth[:, 2]
        out[:, 9] = r[:, 1] * fifth[:, 2]
        out[:, 10:13] = q[:, 3:]
        out[:, 13] = np.sqrt(np.einsum("ij,ij->i", q[:, 3:], q[:, 3:]))
        return out

    def along_u(self, vs: NDArray[np.float64], us: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """F(u, v) at each (u, v): the integrand integrated along u from the face's lower bound, with its
        error; all of them adaptively at once (the intervals still open are evaluated together)."""
        starts, ends, owners = [], [], []
        for i, u in enumerate(us.tolist()):
            cuts = _breaks(min(u, self.u_lo), max(u, self.u_lo), self.u_knots)
            starts += cuts[:-1]
            ends += cuts[1:]
            owners += [i] * (len(cuts) - 1)
        total, error = _adaptive(
            lambda x, owner: self.integrand(x, vs[owner]),
            np.array(starts, dtype=np.float64),
            np.array(ends, dtype=np.float64),
            np.array(owners, dtype=np.intp),
            len(us),
            self.tolerance,
        )
        sign = np.where(us >= self.u_lo, 1.0, -1.0)
        return total * sign[:, None], error

    def sums(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The face's integrals (``SUMS``) and their error."""
        if self.face.NbChildren() == 0:  # natural bounds: only the side u = u_hi has dv != 0
            return self._side()
        from OCP.BRepGProp import BRepGProp_Domain

        total, error = np.zeros(SUMS), np.zeros(SUMS)
        domain = BRepGProp_Domain(self.face)
        while domain.More():
            edge = domain.Value()
            if not self.surface.Load(edge):  # no curve on the face: the face cannot be integrated here
                raise ValueError("an edge has no curve on its face")
            s, e = self._edge(edge)
            total += s
            error += e
            domain.Next()
        return total, error

    def _side(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        inner: list[NDArray[np.float64]] = []

        def values(vs: NDArray[np.float64]) -> NDArray[np.float64]:
            out, e = self.along_u(vs, np.full(len(vs), self.u_hi))
            inner.append(e.max(axis=0))
            return out

        total, error = _adaptive_one(values, _breaks(self.v_lo, self.v_hi, self.v_knots), self.tolerance)
        return total, error + _weighted(inner, self.v_hi - self.v_lo)

    def _edge(self, edge: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        from OCP.BRepAdaptor import BRepAdaptor_Curve2d
        from OCP.GeomAbs import GeomAbs_CN, GeomAbs_Line
        from OCP.TopAbs import TopAbs_REVERSED

        surface, p, t = self.surface, self._point2d, self._tangent2d
        lo, hi = surface.FirstParameter(), surface.LastParameter()
        curve = BRepAdaptor_Curve2d(edge, self.face)
        breaks = [lo, hi]
        count = curve.NbIntervals(GeomAbs_CN)
        if count > 1:  # the curve's own knots; Load reversed a reversed edge's curve, t -> first + last - t
            knots = _intervals(count, lambda a: curve.Intervals(a, GeomAbs_CN))
            if edge.Orientation() == TopAbs_REVERSED:
                knots = [lo + (curve.LastParameter() - k) for k in knots]
            breaks += knots
        if curve.GetType() == GeomAbs_Line:  # a straight edge crosses the surface's knot lines at known parameters
            surface.D12d(lo, p, t)
            u1, v1 = p.X(), p.Y()
            surface.D12d(hi, p, t)
            u2, v2 = p.X(), p.Y()
            for a, b, knots in ((u1, u2, self.u_knots), (v1, v2, self.v_knots)):
                if a != b:
                    breaks += [lo + (k - a) / (b - a) * (hi - lo) for k in knots if min(a, b) < k < max(a, b)]
        breaks = sorted({x for x in breaks if lo <= x <= hi})
        inner: list[NDArray[np.float64]] = []

        def values(ls: NDArray[np.float64]) -> NDArray[np.float64]:
            uvd = np.empty((len(ls), 3))
            for i, parameter in enumerate(ls.tolist()):
                surface.D12d(parameter, p, t)
                uvd[i, :2] = p.Coord()
                uvd[i, 2] = t.Y()
            out = np.zeros((len(ls), SUMS))
            moving = uvd[:, 2] != 0.0  # along u, dv = 0: nothing to add
            if moving.any():
                u = np.clip(uvd[moving, 0], self.u_lo, self.u_hi)
                v = np.clip(uvd[moving, 1], self.v_lo, self.v_hi)
                dv = uvd[moving, 2]
                s, e = self.along_u(v, u)
                out[moving] = s * dv[:, None]
                inner.append((e * np.abs(dv)[:, None]).max(axis=0))
            return out

        total, error = _adaptive_one(values, breaks, self.tolerance)
        return total, error + _weighted(inner, hi - lo)


def _weighted(inner_errors: list[NDArray[np.float64]], length: float) -> NDArray[np.float64]:
    """A bound on what the inner integrals' errors add to an outer sum over ``length``: each node's error
    enters with its Kronrod weight times half its interval, and the accepted intervals' weights add up
    to their total length, at most ``length``."""
    if not inner_errors:
        return np.zeros(SUMS)
    return np.asarray(np.max(inner_errors, axis=0) * abs(length), dtype=np.float64)


def face_sums(
    face: Any, origin: NDArray[np.float64], tolerance: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The volume integrals and vector area (``SUMS``) contributed by one face, about ``origin`` [mm], and a bound
    on their error; ``tolerance`` is the absolute accuracy asked of each component per interval."""
    return _Face(face, origin, tolerance).sums()
