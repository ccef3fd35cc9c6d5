"""Free-form B-rep faces: OpenCASCADE's own rules against ``inertia.cad.green`` on solids with exact answers.

    python -m benchmarks.cad     # the table is a section of docs/cad.md

Each solid is bounded by a clamped, non-rational cubic B-spline profile (or is a NURBS conversion of
a primitive).  The reference evaluates the profile with scipy's ``BSpline`` from the same poles and
knots, without OpenCASCADE, and reduces every volume integral to a line integral over it by Green's
theorem in the profile's plane:

* prism of height h over the region A inside (x(s), y(s)):  ∫∫ x^a y^b dA = ∮ x^(a+1) y^b / (a+1) dy,
  and the z factors integrate in closed form (∫ z dz = h^2 / 2, ...);
* solid of revolution of the region inside (r(s), z(s)) about the z axis (Pappus):
  ∫ g dV = 2π ∫∫ g r dr dz = 2π ∮ G dz with ∂G/∂r = g r.

On each knot span the integrands are polynomials of degree at most 14, integrated exactly by a
12-point Gauss-Legendre rule.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = [
    "DEGREE",
    "prism_poles",
    "revolution_poles",
    "spline_profile",
    "spline_prism",
    "spline_revolution",
    "prism_reference",
    "revolution_reference",
    "comparison_rows",
    "relative_error",
]

DEGREE = 3


def _poles(centre: tuple[float, float], radius: float, wave: float, count: int, plane: str) -> list[tuple[float, float, float]]:
    """Poles around a wavy circle, closed by repeating the first."""
    out = []
    for i in range(count):
        a = 2 * math.pi * i / count
        r = radius + wave * math.sin(5 * a)
        p, q = centre[0] + r * math.cos(a), centre[1] + r * math.sin(a)
        out.append((p, q, 0.0) if plane == "xy" else (p, 0.0, q))
    return [*out, out[0]]


Samples = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _profile_samples(poles: list[tuple[float, float, float]], axes: tuple[int, int]) -> Samples:
    """Gauss points of the profile: p(s), q(s), dp/ds, dq/ds and weights, from scipy's BSpline."""
    from scipy.interpolate import BSpline

    spans = len(poles) - DEGREE
    knots = np.concatenate([[0.0] * DEGREE, np.arange(spans + 1, dtype=float), [float(spans)] * DEGREE])
    coefficients = np.array(poles, dtype=float)[:, list(axes)]
    curve = BSpline(knots, coefficients, DEGREE)
    x, w = np.polynomial.legendre.leggauss(12)
    s = np.concatenate([i + 0.5 + 0.5 * x for i in range(spans)])
    weights = np.tile(0.5 * w, spans)
    value, slope = curve(s), curve.derivative()(s)
    return value[:, 0], value[:, 1], slope[:, 0], slope[:, 1], weights


def _principal(volume: float, first: np.ndarray, second: dict[str, float]) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume, centre and principal moments [mm^5] from the integrals of 1, x_i and x_i x_j."""
    xx, yy, zz, xy, xz, yz = (second[k] for k in ("xx", "yy", "zz", "xy", "xz", "yz"))
    tensor = np.array([[yy + zz, -xy, -xz], [-xy, xx + zz, -yz], [-xz, -yz, xx + yy]])
    c = first / volume
    tensor -= volume * (float(c @ c) * np.eye(3) - np.outer(c, c))
    return volume, c, np.linalg.eigvalsh(tensor)


def prism_reference(poles: list[tuple[float, float, float]], h: float) -> tuple[float, np.ndarray, np.ndarray]:
    x, y, _, dy, w = _profile_samples(poles, (0, 1))

    def area_integral(a: int, b: int) -> float:  # ∫∫ x^a y^b dA = ∮ x^(a+1) y^b / (a+1) dy
        return float(np.sum(w * x ** (a + 1) * y**b / (a + 1) * dy))

    sign = 1.0 if area_integral(0, 0) > 0 else -1.0
    A, X, Y = (sign * area_integral(a, b) for a, b in ((0, 0), (1, 0), (0, 1)))
    XX, YY, XY = (sign * area_integral(a, b) for a, b in ((2, 0), (0, 2), (1, 1)))
    first = np.array([X * h, Y * h, A * h * h / 2])
    second = {"xx": XX * h, "yy": YY * h, "zz": A * h**3 / 3, "xy": XY * h, "xz": X * h * h / 2, "yz": Y * h * h / 2}
    return _principal(A * h, first, second)


def revolution_reference(poles: list[tuple[float, float, float]]) -> tuple[float, np.ndarray, np.ndarray]:
    r, z, _, dz, w = _profile_samples(poles, (0, 2))

    def turned(g: Any) -> float:  # 2π ∮ G dz, G = ∫ g(r, z) r dr from 0
        return float(2 * math.pi * np.sum(w * g(r, z) * dz))

    sign = 1.0 if turned(lambda r, z: r * r / 2) > 0 else -1.0
    V = sign * turned(lambda r, z: r * r / 2)
    Z = sign * turned(lambda r, z: r * r / 2 * z)
    R2 = sign * turned(lambda r, z: r**4 / 4)  # ∫ (x^2 + y^2) dV
    Z2 = sign * turned(lambda r, z: r * r / 2 * z * z)
    first = np.array([0.0, 0.0, Z])
    return _principal(V, first, {"xx": R2 / 2, "yy": R2 / 2, "zz": Z2, "xy": 0.0, "xz": 0.0, "yz": 0.0})


def prism_poles() -> list[tuple[float, float, float]]:
    return _poles((1.5, -0.5), 10.0, 3.0, 14, "xy")


def revolution_poles() -> list[tuple[float, float, float]]:
    return _poles((14.0, 2.0), 4.0, 0.8, 11, "xz")


PRISM_HEIGHT = 7.0


def spline_profile(poles: Sequence[tuple[float, float, float]], degree: int = 3) -> Any:
    """A clamped, uniform, non-rational B-spline through ``poles`` (the last pole repeats the first, so the
    curve closes), as a ``Geom_BSplineCurve``; knots 0, 1, ..., n - degree with end multiplicity degree + 1."""
    from OCP.collections import Array1_double, Array1_gp_Pnt, Array1_int
    from OCP.Geom import Geom_BSplineCurve
    from OCP.gp import gp_Pnt

    spans = len(poles) - degree
    points, knots, mults = Array1_gp_Pnt(1, len(poles)), Array1_double(1, spans + 1), Array1_int(1, spans + 1)
    for i, p in enumerate(poles):
        points.SetValue(i + 1, gp_Pnt(*p))
    for i in range(spans + 1):
        knots.SetValue(i + 1, float(i))
        mults.SetValue(i + 1, degree + 1 if i in (0, spans) else 1)
    return Geom_BSplineCurve(points, knots, mults, degree)


def _face(curve: Any) -> Any:
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeWire

    wire = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(curve).Edge()).Wire()
    return BRepBuilderAPI_MakeFace(wire, True).Face()


def spline_prism(curve: Any, height: float) -> Any:
    """The planar region inside ``curve`` (in z = 0) extruded by ``height`` along z: its side is a
    ``SurfaceOfExtrusion`` over the B-spline, its ends planes bounded by it."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Vec

    return BRepPrimAPI_MakePrism(_face(curve), gp_Vec(0.0, 0.0, height)).Shape()


def spline_revolution(curve: Any) -> Any:
    """The region inside ``curve`` (in the plane y = 0, at x > 0) turned once about the z axis: one
    ``SurfaceOfRevolution`` face."""
    import math

    from OCP.BRepPrimAPI import BRepPrimAPI_MakeRevol
    from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt

    return BRepPrimAPI_MakeRevol(_face(curve), gp_Ax1(gp_Pnt(0.0, 0.0, 0.0), gp_Dir(0.0, 0.0, 1.0)), 2 * math.pi).Shape()


def _occ(shape: Any, gauss_kronrod: bool, eps: float) -> tuple[float, np.ndarray, np.ndarray, float]:
    """OpenCASCADE's own result: volume, centre, principal moments [mm], and the seconds it took."""
    from OCP.BRepGProp import BRepGProp
    from OCP.gp import gp_Pnt
    from OCP.GProp import GProp_GProps

    props = GProp_GProps(gp_Pnt(0.0, 0.0, 0.0))
    start = time.perf_counter()
    if gauss_kronrod:
        BRepGProp.VolumePropertiesGK_s(shape, props, eps, True, True, True, True)
    else:
        BRepGProp.VolumeProperties_s(shape, props, eps, True)
    seconds = time.perf_counter() - start
    m = props.MatrixOfInertia()
    c = props.CentreOfMass()
    tensor = np.array([[m.Value(i, j) for j in (1, 2, 3)] for i in (1, 2, 3)])
    return float(props.Mass()), np.array([c.X(), c.Y(), c.Z()]), np.linalg.eigvalsh(tensor), seconds


def relative_error(result: tuple[float, Any, Any], reference: tuple[float, np.ndarray, np.ndarray]) -> float:
    """Largest relative error of volume, centre (in radii of gyration) and principal moments (any order)."""
    (v, c, m), (v0, c0, m0) = result, reference
    gyration = math.sqrt(float(m0.max()) / v0)
    return max(
        abs(v - v0) / v0,
        float(np.max(np.abs(np.asarray(c) - c0))) / gyration,
        float(np.max(np.abs(np.sort(m) - m0) / m0)),
    )


def cases() -> list[tuple[str, Any, tuple[float, np.ndarray, np.ndarray]]]:
    """The free-form solids and their references (volume, centre, ascending principal moments; mm)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder

    r, h = 10.0, 30.0
    v = math.pi * r * r * h
    ix = v * (3 * r * r + h * h) / 12
    cylinder = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeCylinder(r, h).Shape(), True).Shape()
    prism, turned = prism_poles(), revolution_poles()
    return [
        ("prism over a B-spline profile", spline_prism(spline_profile(prism), PRISM_HEIGHT), prism_reference(prism, PRISM_HEIGHT)),
        ("revolved B-spline profile", spline_revolution(spline_profile(turned)), revolution_reference(turned)),
        ("cylinder r10 h30, NURBS faces", cylinder, (v, np.array([0.0, 0.0, h / 2]), np.sort([ix, ix, v * r * r / 2]))),
    ]


def comparison_rows(gauss_kronrod_eps: float = 1e-9) -> list[str]:
    """Markdown rows: each rule's largest relative error (volume, centre in radii of gyration, moments),
    its own estimate where it gives one, and its time, on the solids of ``cases``."""
    from inertia.cad import occ

    rows = []
    for name, shape, reference in cases():
        start = time.perf_counter()
        ours = occ.integrate(occ.Solid(name, shape))
        t_ours = time.perf_counter() - start
        ours_error = relative_error((ours.volume, ours.center, np.linalg.eigvalsh(ours.tensor)), reference)
        coarse, fine = _occ(shape, False, 1e-12), _occ(shape, False, 1e-14)
        adaptive_estimate = relative_error(coarse[:3], fine[:3])
        gk = _occ(shape, True, gauss_kronrod_eps)
        adaptive_ms, gk_ms, ours_ms = (coarse[3] + fine[3]) * 1e3, gk[3] * 1e3, t_ours * 1e3
        rows.append(
            f"| {name} | {relative_error(fine[:3], reference):.1e} | {adaptive_estimate:.1e} | {adaptive_ms:.0f} "
            f"| {relative_error(gk[:3], reference):.1e} | {gk_ms:.0f} | {ours_error:.1e} | {ours.estimate:.1e} | {ours_ms:.0f} |"
        )
        print(rows[-1], flush=True)
    return rows
