"""Work-precision of CAD tessellation: error and run time against the deflection, B-rep included.

    python -m benchmarks.cad                   # writes docs/cad.md
    python -m benchmarks.cad --doc /tmp/cad.md # elsewhere
    python -m benchmarks.cad --deflections 0.1 --doc /tmp/cad.md  # a smoke run

Each solid is built with OpenCASCADE (the binding of the ``cad`` extra), written
to a STEP file in millimetres, and analysed through ``inertia.pipeline.analyze``
from the file's bytes, as a user's upload would be: with ``geometry=brep``, and
with ``geometry=mesh`` at deflections 1e-1 ... 1e-5 of the bounding-box diagonal.
Errors are relative, against closed forms:

- cylinder r, h: V = pi r^2 h, I_z = m r^2 / 2, I_x = m (3 r^2 + h^2) / 12;
- sphere r: V = 4/3 pi r^3, I = 2/5 m r^2;
- torus R, r (ring about z): V = 2 pi^2 R r^2, I_z = m (R^2 + 3/4 r^2),
  I_x = m (R^2 / 2 + 5/8 r^2) (e.g. Weisstein, MathWorld "Torus", moment of inertia);
- the same cylinder with every face converted to NURBS (its geometry is still
  exact; only the integration is harder);
- a filleted plate with a hole: no closed form, so against its own B-rep result.

"mass" is the relative error of the mass; "moments" the largest relative error
of the three principal moments (sorted); "estimate" is what the result reports
(``relative_error_estimate`` for the B-rep, ``tessellation_error`` for a mesh).
Times are wall-clock of one ``analyze`` call (reading the STEP file included),
best of ``--repeat``, on whatever else the machine was running.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from benchmarks.harness import Report, best_of

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "cad.md"
DEFLECTIONS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5)
MM3 = 1e-9  # m^3 per mm^3
RHO = 1000.0  # the default density [kg/m^3]


def _quiet() -> None:
    from OCP.Message import Message

    messenger = Message.DefaultMessenger_s()
    for printer in list(messenger.Printers()):
        messenger.RemovePrinter(printer)


def cylinder(r: float = 10.0, h: float = 30.0) -> Any:
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder

    return BRepPrimAPI_MakeCylinder(r, h).Shape()


def sphere(r: float = 20.0) -> Any:
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeSphere

    return BRepPrimAPI_MakeSphere(r).Shape()


def torus(R: float = 30.0, r: float = 10.0) -> Any:
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeTorus

    return BRepPrimAPI_MakeTorus(R, r).Shape()


def nurbs(shape: Any) -> Any:
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert

    return BRepBuilderAPI_NurbsConvert(shape, True).Shape()


def bracket() -> Any:
    """A mounting plate 60 x 40 x 8 mm, every edge filleted at 2 mm, with a 10 mm through-hole."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    body = BRepPrimAPI_MakeBox(60.0, 40.0, 8.0).Shape()
    fillet = BRepFilletAPI_MakeFillet(body)
    explorer = TopExp_Explorer(body, TopAbs_EDGE)
    while explorer.More():
        fillet.Add(2.0, TopoDS.Edge(explorer.Current()))
        explorer.Next()
    hole = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(40.0, 20.0, -1.0), gp_Dir(0, 0, 1)), 5.0, 10.0).Shape()
    return BRepAlgoAPI_Cut(fillet.Shape(), hole).Shape()


def cylinder_reference(r: float = 10.0, h: float = 30.0) -> tuple[float, list[float]]:
    m = RHO * math.pi * r * r * h * MM3
    r, h = r * 1e-3, h * 1e-3
    ix, iz = m * (3 * r * r + h * h) / 12, m * r * r / 2
    return m, sorted([ix, ix, iz])


def sphere_reference(r: float = 20.0) -> tuple[float, list[float]]:
    m = RHO * 4 / 3 * math.pi * r**3 * MM3
    i = 0.4 * m * (r * 1e-3) ** 2
    return m, [i, i, i]


def torus_reference(R: float = 30.0, r: float = 10.0) -> tuple[float, list[float]]:
    m = RHO * 2 * math.pi**2 * R * r * r * MM3
    R, r = R * 1e-3, r * 1e-3
    iz, ix = m * (R * R + 0.75 * r * r), m * (R * R / 2 + 5 / 8 * r * r)
    return m, sorted([ix, ix, iz])


def write_step(shape: Any) -> bytes:
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    Interface_Static.SetCVal_s("write.step.unit", "MM")
    writer = STEPControl_Writer()
    writer.Transfer(shape, STEPControl_AsIs)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "part.step")
        writer.Write(path)
        return Path(path).read_bytes()


def _errors(doc: dict[str, Any], mass: float, moments: list[float]) -> tuple[float, float]:
    got = sorted(doc["principal"]["moments"])
    return abs(doc["mass"] - mass) / mass, max(abs(a - b) / b for a, b in zip(got, moments))


def _timed(call: Callable[[], dict[str, Any]], repeat: int) -> tuple[dict[str, Any], float]:
    out, timing = best_of(call, repeat)
    return out, timing.wall_s


def rows_for(
    name: str, shape: Any, reference: tuple[float, list[float]] | None, repeat: int, deflections: tuple[float, ...] = DEFLECTIONS
) -> list[str]:
    from inertia.pipeline import AnalysisOptions, analyze

    data = write_step(shape)
    brep, t_brep = _timed(lambda: analyze(data, filename=f"{name}.step").as_dict(), repeat)
    mass, moments = reference if reference else (brep["mass"], sorted(brep["principal"]["moments"]))
    em, ei = _errors(brep, mass, moments)
    est = brep["diagnostics"]["relative_error_estimate"]
    rows = [f"| {name} | B-rep | {brep['source']['solids']} solid | {em:.1e} | {ei:.1e} | {est:.1e} | {t_brep * 1e3:.0f} |"]
    for deflection in deflections:
        options = AnalysisOptions(geometry="mesh", deflection=deflection)

        def meshed(o: AnalysisOptions = options) -> dict[str, Any]:
            return analyze(data, filename=f"{name}.step", options=o).as_dict()

        doc, t = _timed(meshed, repeat)
        em, ei = _errors(doc, mass, moments)
        rows.append(
            f"| {name} | {deflection:g} | {doc['source']['triangles']:,} | {em:.1e} | {ei:.1e} | "
            f"{doc['diagnostics']['tessellation_error']:.1e} | {t * 1e3:.0f} |"
        )
        print(rows[-1], flush=True)
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--doc", type=Path, default=DOC)
    parser.add_argument("--repeat", type=int, default=1, help="runs per row, best kept (the 1e-5 rows take minutes)")
    parser.add_argument(
        "--deflections",
        type=lambda text: tuple(float(x) for x in text.split(",")),
        default=DEFLECTIONS,
        help="comma-separated mesh deflections (default 1e-1 .. 1e-5; e.g. 0.1 for a smoke run)",
    )
    args = parser.parse_args(argv)
    _quiet()
    from OCP import __file__ as ocp_file

    cases: list[tuple[str, Any, tuple[float, list[float]] | None]] = [
        ("cylinder r10 h30", cylinder(), cylinder_reference()),
        ("sphere r20", sphere(), sphere_reference()),
        ("torus R30 r10", torus(), torus_reference()),
        ("cylinder, NURBS faces", nurbs(cylinder()), cylinder_reference()),
        ("filleted plate with hole", bracket(), None),
    ]
    rows: list[str] = []
    for name, shape, ref in cases:
        rows.extend(rows_for(name, shape, ref, args.repeat, args.deflections))
    from benchmarks.free_form import comparison_rows

    _document(rows, comparison_rows(), Path(ocp_file).parent.name, args.repeat).write(args.doc)
    print(f"wrote {args.doc}")
    return 0


def _document(rows: list[str], free_form: list[str], binding: str, repeat: int) -> Report:
    import importlib.metadata as md

    version = md.version("cadquery-ocp-novtk")
    report = Report("CAD files: tessellation work-precision", "python -m benchmarks.cad")
    report.add(f"""Generated by `{report.regenerate}` (cadquery-ocp-novtk {version}, Python
{platform.python_version()}, {platform.machine()}; best of {repeat} runs of one
`analyze` call on the STEP file's bytes, reading included; the machine was shared
with other work, so times are indicative).

`geometry=brep` (the default) integrates the exact faces; `geometry=mesh`
tessellates them with a chordal deflection of `deflection` times the part's
bounding-box diagonal (angular deflection 0.5 rad, OpenCASCADE's default, which
governs the coarsest setting) and integrates the polyhedron exactly. Errors are
relative, against closed forms (cylinder, sphere, torus) or, for the filleted plate,
against its B-rep result. *estimate* is what the result itself reports:
`relative_error_estimate` on the B-rep rows, `tessellation_error` (difference to the
B-rep) on the mesh rows.

| solid | deflection | triangles | mass error | moments error | estimate | time [ms] |
|---|---|---:|---:|---:|---:|---:|
{chr(10).join(rows)}

The first mesh row of the first solid includes loading the tessellator's libraries once.
The filleted plate's B-rep row is its own reference (zero error by construction): its
estimate is the information there. Its blends are B-spline faces, integrated by
`inertia.cad.green` (below).

Reading the table: the tessellation's error falls in proportion to the deflection
once the linear deflection governs (below about 1e-2), roughly 5 x deflection in the
moments for these curved solids; planar faces cost nothing. To reach 1e-6 a mesh
needs a deflection near 1e-7 and millions of triangles, where the B-rep gives
1e-8 or better in milliseconds: use `geometry=mesh` only to see what a tessellated
export (STL, a simulator's collision mesh) of the part would weigh.

How the B-rep rows are integrated: faces on analytic surfaces (planes, cylinders,
cones, spheres, tori) bounded by lines and circles go through OpenCASCADE's adaptive
Gauss rule (`BRepGProp_Vinert` with eps 1e-12 and 1e-14), which integrates them to
rounding; the difference of the two runs is their estimate. Every other face (B-spline
and Bezier surfaces, extrusions and revolutions of curves, offsets, and analytic
surfaces with a free-form boundary) is integrated by `inertia.cad.green`: Green's
theorem in the face's parameter plane, adaptive 15-point Gauss-Kronrod in both
directions with the intervals starting at the knots, and the Kronrod-Gauss differences
as its error bound. All faces are summed as cones from one apex, the one
`BRepGProp.VolumeProperties_s` takes (the mean of the vertices). Where a file's faces
do not quite close (gaps within its tolerance), the volume depends on that apex: the
faces' leftover vector area (zero for a closed surface) bounds by how much, that bound
enters the estimate, and past 1e-6 a warning names the solid.

## Free-form faces: OpenCASCADE's own rules against ours

Errors are relative (volume, centre in radii of gyration, principal moments; the
largest), against references computed without OpenCASCADE: Green's theorem and
Pappus's rule over scipy's `BSpline` of the same poles (`benchmarks/free_form.py`), the
closed form for the cylinder. *adaptive*: `BRepGProp.VolumeProperties_s` at eps 1e-14,
with the difference to eps 1e-12 as its estimate (what this service reported before);
*Gauss-Kronrod*: `BRepGProp.VolumePropertiesGK_s` at eps 1e-9; *ours*: `geometry=brep`
as it runs now. Times in milliseconds, one run each, integration only.

| solid | adaptive: error | estimate | ms | Gauss-Kronrod: error | ms | ours: error | estimate | ms |
|---|---:|---:|---:|---:|---:|---:|---:|---:|
{chr(10).join(free_form)}

The adaptive rule checks its convergence on the volume alone and takes its Gauss
order and intervals from the surface type: on the extruded B-spline it stops several
percent off while its two runs agree about as badly, and on the revolution its
estimate does not say that the moments are off. The Gauss-Kronrod rule converges but
takes seconds on the symmetric and rational faces (a component that is zero by
symmetry never meets its relative tolerance). The default, non-adaptive rule (what
gmsh's `getMass` calls) is off by about 1 % on the NURBS cylinder.

On a real part, pythonocc-demos' `Ventilator.stp` (305 faces, 290 of them free-form,
from CATIA V5), the adaptive rule's volume is 6e-6 from the Gauss-Kronrod rule's and
ours 3.5e-8 from it; ours takes 13 s against the adaptive rule's 11 s (its two
runs, on a quiet machine) and Gauss-Kronrod's 59 s. That file's faces leave 0.66 mm^2
of vector area open, which leaves its volume open by up to 4e-4 (its estimate, with a
warning). On 189 solids of public STEP and IGES files (CadQuery, build123d, pythonocc,
OCCT's and CAx-IF's samples via occt-import-js, KiCad models, gmsh's tutorials), ours and the Gauss-Kronrod rule agreed within our
estimate on 184 and within 3e-12 on the other 5 (small parts far from the file's origin,
where the reference, taken about that origin, rounds at that level); 9 of them carry the
warning about faces that do not close. On gmsh's `wing_fuselage.step` (B-spline,
extrusion and revolution faces) the adaptive rule alone was 2.7e-4 off while its two
runs agreed to 1e-14; ours is 1.2e-7 from the Gauss-Kronrod rule, within its estimate.""")
    return report


if __name__ == "__main__":
    sys.exit(main())
