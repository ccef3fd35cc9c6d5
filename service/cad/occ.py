"""The OpenCASCADE adapter (``OCP``, the ``cadquery-ocp-novtk`` wheel): with ``green`` (its face
integrals), the only module that imports it.

Everything the binding can throw is caught here and translated into a
``ServiceError``; nothing above this module sees an OCP object's exception.

Reading.  STEP and IGES go through OpenCASCADE's XDE readers
(``STEPCAFControl_Reader``, ``IGESCAFControl_Reader``), which keep product
names and the assembly tree.  The document's length unit is set to the
millimetre, so the reader converts the file's own unit (STEP ``SI_UNIT`` /
``CONVERSION_BASED_UNIT``, IGES global section parameters 14-15) into
millimetres: OpenCASCADE's tolerances (``Precision::Confusion`` = 1e-7 model
units, the mesher's minimum size) assume parts of millimetres to metres in
model units, and a part read in metres meshes slowly and badly at fine
deflections.  The unit the file declared is read back for ``source.units``.

Integration.  ``BRepGProp.VolumeProperties_s(shape, props, eps)`` runs
OpenCASCADE's adaptive Gauss integration over the exact faces; its returned
error is the last relative change of each face's *volume* and says nothing
about the moments (measured: it reports 1e-16 where the moments of a NURBS
torus are still 8e-7 off).  On analytic faces (planes, cylinders, cones,
spheres, tori bounded by lines and circles) it integrates every moment to
rounding, so a solid of such faces only is integrated twice, at
``COARSE_EPS`` and ``FINE_EPS``, and the difference is the estimate.  On any
other face it can stop far off while both runs agree (9 % on a prism over a
B-spline profile, docs/cad.md): those faces are integrated by ``green``
(Green's theorem in the face's parameter plane, adaptive Gauss-Kronrod with its
own error bound), the analytic ones of the same solid face by face with
``BRepGProp_Vinert``, all as cones from one apex, and the sums added.
"""

from __future__ import annotations

import math
import os
import re
import tempfile
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import (
    EmptyGeometryError,
    ExternalReferenceError,
    NotWatertightError,
    ServiceError,
    UnreadableFileError,
    ZeroVolumeError,
)
from ..tolerances import DEFAULT_TOLERANCES

__all__ = [
    "CAD_EXTRA_HINT",
    "Solid",
    "BrepIntegral",
    "read_solids",
    "integrate",
    "tessellate",
    "triangles_only",
    "carried_triangles",
    "available",
]

CAD_EXTRA_HINT = "pip install 'inertia-service[cad]'"
VOLUME_REL = DEFAULT_TOLERANCES.volume_rel  # |V| below this x the bounding box's volume: no solid
MODEL_UNIT = 1e-3  # metres per model unit: OpenCASCADE works in millimetres

COARSE_EPS = 1e-12  # below ~1e-12 the moments, not only the volume, settle (API.md, accuracy of brep)
FINE_EPS = 1e-14  # a hundredfold tighter: its difference to COARSE_EPS is the error estimate
FREE_FORM_TOLERANCE = 1e-13  # green.py, per interval: relative to the box's volume times its diagonal's powers
ROUNDING_FLOOR = 64 * 2.220446049250313e-16  # Gauss sums of a few hundred terms per face, far from cancellation

# OpenCASCADE's own names of length units, as STEPControl_Reader.FileUnits and the IGES global section spell them
_UNIT_NAMES = {
    "m": "m",
    "metre": "m",
    "meter": "m",
    "mm": "mm",
    "millimetre": "mm",
    "millimeter": "mm",
    "cm": "cm",
    "centimetre": "cm",
    "centimeter": "cm",
    "um": "um",
    "micron": "um",
    "micrometre": "um",
    "micrometer": "um",
    "in": "in",
    "inch": "in",
    "ft": "ft",
    "foot": "ft",
    "feet": "ft",
}


def _quiet() -> None:
    """OpenCASCADE prints transfer statistics to stdout; a service's stdout is not its to write."""
    from OCP.Message import Message

    messenger = Message.DefaultMessenger_s()
    for printer in list(messenger.Printers()):
        messenger.RemovePrinter(printer)


def available() -> bool:
    """Whether the binding imports (the ``cad`` extra is installed)."""
    try:
        import OCP.BRepGProp  # noqa: F401
    except Exception:  # an ImportError, or a broken shared library
        return False
    return True


@dataclass(frozen=True, slots=True)
class Solid:
    """One solid of the file, placed in the file's frame, coordinates in millimetres.

    shape : the located ``TopoDS_Shape`` (a solid).  name : its product or shape name.
    """

    name: str
    shape: Any
    memo: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)  # _free_form's, once per solid


@dataclass(frozen=True, slots=True)
class BrepIntegral:
    """Volume integrals of one solid, coordinates in millimetres, unit density.

    volume [mm^3]; center [mm]; tensor [mm^5], about the centre, input axes
    (Landau & Lifshitz sign convention, as OpenCASCADE's MatrixOfInertia);
    estimate : relative error bound of volume, centre (in units of the radius
    of gyration) and each principal moment.
    """

    volume: float
    center: NDArray[np.float64]
    tensor: NDArray[np.float64]
    estimate: float
    faces: int
    warnings: tuple[str, ...] = ()


def _translated(exc: BaseException, what: str) -> ServiceError:
    """A binding's exception as an ``unreadable_file`` error with its first line."""
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    return UnreadableFileError(f"OpenCASCADE could not {what}: {text}", library="OpenCASCADE")


def read_solids(data: bytes, fmt: str) -> tuple[list[Solid], str | None, list[str]]:
    """The solids of a STEP or IGES file, the length unit it declares (None: not stated), and notes on what
    was left out."""
    try:
        return _read(data, fmt)
    except ServiceError:
        raise
    except (Exception, SystemExit) as exc:  # the binding raises its own Standard_Failure types
        raise _translated(exc, f"read the {fmt.upper()} file") from exc


# A STEP assembly may name its parts' files (DOCUMENT_FILE / EXTERNAL_SOURCE entities), which
# OpenCASCADE's XDE reader then opens from disk: the server never opens a file an upload names.
# a part kept in another file: a DOCUMENT_FILE or an EXTERNAL_SOURCE naming a STEP file (an EXTERNAL_SOURCE
# also names the program a text font comes from, IDENTIFIER('UG NX'), which is no file)
_STEP_EXTERNAL = re.compile(rb"(?:EXTERNAL_SOURCE|DOCUMENT_FILE)\s*\([^;]*?'[^']*\.(?:stp|step|p21|stpz)'", re.IGNORECASE)


def _refuse_external(data: bytes, fmt: str) -> None:
    match = _STEP_EXTERNAL.search(data) if fmt == "step" else None
    if match:
        raise ExternalReferenceError(
            "the STEP file refers to other files for its parts ("
            + match.group(0).decode("ascii", "replace")[:80]
            + "...); the server never opens files named by an upload: export the assembly as one self-contained STEP",
            format=fmt,
        )


def _read(data: bytes, fmt: str) -> tuple[list[Solid], str | None, list[str]]:
    _refuse_external(data, fmt)
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    _quiet()
    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    XCAFDoc_DocumentTool.SetLengthUnit_s(doc, MODEL_UNIT)  # the reader converts the file's unit to this
    reader = _reader(fmt)
    with tempfile.TemporaryDirectory(prefix="inertia-cad-") as tmp:
        path = os.path.join(tmp, "input." + ("stp" if fmt == "step" else "igs"))
        with open(path, "wb") as fh:
            fh.write(data)
        status = reader.ReadFile(path)
        if status != IFSelect_RetDone:
            raise UnreadableFileError(
                f"the file is not a readable {fmt.upper()} file (OpenCASCADE's reader status {int(status)}); "
                "export it again from the CAD tool",
                library="OpenCASCADE",
            )
        unit = _declared_unit(reader, fmt, data)
        if not reader.Transfer(doc):
            raise UnreadableFileError(
                f"OpenCASCADE read the {fmt.upper()} file but could not build its shapes", library="OpenCASCADE"
            )
    solids, notes = _solids(doc)
    return solids, unit, notes


def _reader(fmt: str) -> Any:
    if fmt == "step":
        from OCP.STEPCAFControl import STEPCAFControl_Reader

        reader: Any = STEPCAFControl_Reader()
    else:
        from OCP.IGESCAFControl import IGESCAFControl_Reader

        reader = IGESCAFControl_Reader()
    reader.SetNameMode(True)
    return reader


def _declared_unit(reader: Any, fmt: str, data: bytes) -> str | None:
    """The length unit the file states, in our names (an unknown one as the file spells it)."""
    if fmt == "step":
        from OCP.collections import Sequence_TCollection_AsciiString

        lengths, angles, solid_angles = (Sequence_TCollection_AsciiString() for _ in range(3))
        reader.ChangeReader().FileUnits(lengths, angles, solid_angles)
        names = {str(lengths.Value(i).ToCString()).strip().lower() for i in range(1, lengths.Length() + 1)}
        names.discard("")
        if not names:  # the reader converted the unit but gave it no name (NIST's CTC 05: an inch it leaves blank)
            names = _step_length_units(data)
    else:
        names = {_iges_unit(reader.WS().Model().GlobalSection())}
    names.discard("")
    if len(names) != 1:
        return None
    name: str = names.pop()
    return _UNIT_NAMES.get(name, name)


_STEP_COMPLEX = re.compile(rb"=\s*\(([^;]*)\)\s*;")
_STEP_CONVERSION = re.compile(rb"CONVERSION_BASED_UNIT\s*\(\s*'([^']*)'", re.IGNORECASE)
_STEP_SI_LENGTH = re.compile(rb"SI_UNIT\s*\(\s*(?:\.(\w+)\.|\$)\s*,\s*\.METRE\.", re.IGNORECASE)
_SI_PREFIX = {b"": "m", b"MILLI": "mm", b"CENTI": "cm", b"MICRO": "um", b"KILO": "km"}


def _step_length_units(data: bytes) -> set[str]:
    """The length units a STEP file's text declares (ISO 10303-41): the names of its conversion-based ones
    (an inch is 25.4 of a millimetre there, the millimetre then only its base), else its SI ones."""
    conversions: set[str] = set()
    si: set[str] = set()
    for m in _STEP_COMPLEX.finditer(data):
        entity = m.group(1)
        if b"LENGTH_UNIT" not in entity.upper():
            continue
        named = _STEP_CONVERSION.search(entity)
        if named:
            conversions.add(named.group(1).decode("latin-1").strip().lower())
            continue
        metre = _STEP_SI_LENGTH.search(entity)
        if metre:
            si.add(_SI_PREFIX.get((metre.group(1) or b"").upper(), ""))
    return conversions or si


# IGES 5.3, global section parameter 14 (units flag) -> unit; 3 means "the name in parameter 15"
_IGES_UNIT_FLAGS = {1: "in", 2: "mm", 4: "ft", 5: "mi", 6: "m", 7: "km", 8: "mil", 9: "um", 10: "cm", 11: "uin"}


def _iges_unit(section: Any) -> str:
    flag = int(section.UnitFlag())
    if flag in _IGES_UNIT_FLAGS:
        return _IGES_UNIT_FLAGS[flag]
    name = section.UnitName()
    return "" if name is None else str(name.ToCString()).strip().lower()


def _solids(doc: Any) -> tuple[list[Solid], list[str]]:
    """Every solid of the assembly tree, located, named after its product (or sub-shape) label; notes on the
    shells and faces left out.

    Shells and faces that bound no solid (surface bodies) hold no volume: beside solids they are left out
    with a warning that counts them, as CAD tools' mass properties weigh solid bodies only; a file of
    nothing else is refused as not watertight.
    """
    from OCP.collections import Sequence_TDF_Label
    from OCP.TopAbs import TopAbs_FACE, TopAbs_SHELL, TopAbs_SOLID
    from OCP.TopLoc import TopLoc_Location
    from OCP.XCAFDoc import XCAFDoc_DocumentTool, XCAFDoc_ShapeTool

    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    roots = Sequence_TDF_Label()
    tool.GetFreeShapes(roots)
    solids: list[Solid] = []
    for i in range(1, roots.Length() + 1):
        _walk(roots.Value(i), TopLoc_Location(), solids, depth=0)
    loose = 0
    for i in range(1, roots.Length() + 1):
        shape = XCAFDoc_ShapeTool.GetShape_s(roots.Value(i))
        # shells and faces that belong to no solid: surface bodies, or an open body
        loose += _count(shape, TopAbs_SHELL, TopAbs_SOLID) + _count(shape, TopAbs_FACE, TopAbs_SHELL)
    if loose and not solids:
        raise NotWatertightError(
            f"the CAD file holds {loose} shell(s) or face(s) that bound no solid, so it is not a closed body; "
            "export closed solids (sew the surfaces into a solid in the CAD tool)",
            open_shapes=loose,
        )
    if not solids:
        raise EmptyGeometryError("the CAD file holds no solid; export the part as a solid body")
    notes = (
        [
            f"the CAD file also holds {loose} shell(s) or face(s) that bound no solid (surface bodies, or a body "
            f"left open); they hold no volume and were left out, as CAD tools' mass properties leave them: the "
            f"result is its {len(solids)} solid(s); if one of those surfaces was meant as a solid, sew it closed"
        ]
        if loose
        else []
    )
    return _unique_names(solids), notes


MAX_DEPTH = 64  # assembly nesting deeper than this is a reference cycle, not a design


def _walk(label: Any, location: Any, out: list[Solid], depth: int, inherited: str | None = None) -> None:
    """Solids under one label: an assembly's components in turn, or a shape's own solids.

    ``inherited``: the nearest name above an unnamed shape. Some writers give a product's solid a
    label of its own without a name, under the product's named one (CAx-IF as1_pe_203: PLATE, BOLT);
    the solid then takes the product's name, or the name of the component that places it.
    """
    from OCP.collections import Sequence_TDF_Label
    from OCP.TDF import TDF_Label
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer
    from OCP.XCAFDoc import XCAFDoc_ShapeTool

    if depth > MAX_DEPTH:
        raise UnreadableFileError("the CAD file's assembly tree is nested too deeply (a reference cycle?)")
    if XCAFDoc_ShapeTool.IsAssembly_s(label):
        product = _label_name(label) or inherited
        components = Sequence_TDF_Label()
        XCAFDoc_ShapeTool.GetComponents_s(label, components, False)
        for i in range(1, components.Length() + 1):
            component = components.Value(i)
            referred = TDF_Label()
            if XCAFDoc_ShapeTool.GetReferredShape_s(component, referred):
                placed = location.Multiplied(XCAFDoc_ShapeTool.GetLocation_s(component))
                _walk(referred, placed, out, depth + 1, product or _label_name(component))
        return
    shape = XCAFDoc_ShapeTool.GetShape_s(label)
    own = _label_name(label) or inherited
    found = []
    explorer = TopExp_Explorer(shape, TopAbs_SOLID)
    while explorer.More():
        found.append(explorer.Current())
        explorer.Next()
    for k, solid in enumerate(found):
        # a product of one solid is named by its product; the solids of one product by their own names
        name = own if own and len(found) == 1 else _sub_shape_name(label, solid)
        name = name or (f"{own} {k + 1}" if own else f"solid {len(out) + 1}")
        out.append(Solid(name, solid.Moved(location)))


_PLACEHOLDER_NAMES = frozenset({"NONE", "SOLID", "COMPOUND", "COMPSOLID", "SHELL", "FACE", "SHAPE"})


def _label_name(label: Any) -> str | None:
    from OCP.TDataStd import TDataStd_Name

    attr = TDataStd_Name()
    # FindAttribute on a label without a name crashes the process in OCP 8.0.1 (a segfault on the face-colour
    # labels of SolidWorks exports); IsAttribute asks the same safely
    if label.IsNull() or not label.IsAttribute(TDataStd_Name.GetID_s()) or not label.FindAttribute(TDataStd_Name.GetID_s(), attr):
        return None
    text = str(attr.Get().ToExtString()).strip()
    # OpenCASCADE's writers fill unnamed products with such placeholders, and its readers name unnamed
    # shapes by their type
    # "=>[0:1:1:3]": the name XCAF gives a component label that the file left unnamed (the entry it refers to)
    if not text or text.lower().startswith("open cascade") or text.upper() in _PLACEHOLDER_NAMES or text.startswith("=>["):
        return None
    return text


def _sub_shape_name(label: Any, solid: Any) -> str | None:
    """The name of the sub-shape label that holds exactly this solid (IGES and multi-body STEP parts)."""
    from OCP.collections import Sequence_TDF_Label
    from OCP.XCAFDoc import XCAFDoc_ShapeTool

    subs = Sequence_TDF_Label()
    XCAFDoc_ShapeTool.GetSubShapes_s(label, subs)
    for i in range(1, subs.Length() + 1):
        if XCAFDoc_ShapeTool.GetShape_s(subs.Value(i)).IsSame(solid):
            return _label_name(subs.Value(i))
    return None


def _count(shape: Any, kind: Any, outside: Any) -> int:
    from OCP.TopExp import TopExp_Explorer

    explorer = TopExp_Explorer(shape, kind, outside)
    n = 0
    while explorer.More():
        n += 1
        explorer.Next()
    return n


def _unique_names(solids: list[Solid]) -> list[Solid]:
    """Repeated names (instances of one product) get " #2", " #3", ... so parts stay addressable."""
    seen: dict[str, int] = {}
    out = []
    for s in solids:
        seen[s.name] = seen.get(s.name, 0) + 1
        out.append(s if seen[s.name] == 1 else Solid(f"{s.name} #{seen[s.name]}", s.shape))
    return out


def integrate(solid: Solid) -> BrepIntegral:
    """Volume, centre and tensor of one solid by adaptive integration of its exact faces."""
    try:
        return _integrate(solid)
    except ServiceError:
        raise
    except (Exception, SystemExit) as exc:
        raise _translated(exc, f"integrate the solid {solid.name!r}") from exc


def _properties(shape: Any, reference: Any, eps: float) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps(reference)  # sums taken about a point inside the part, not the file's origin
    BRepGProp.VolumeProperties_s(shape, props, eps, True)  # OnlyClosed: faces of closed shells only
    c = props.CentreOfMass()
    m = props.MatrixOfInertia()  # about the centre of mass
    tensor = np.array([[m.Value(i, j) for j in (1, 2, 3)] for i in (1, 2, 3)], dtype=np.float64)
    return float(props.Mass()), np.array([c.X(), c.Y(), c.Z()], dtype=np.float64), tensor


def _integrate(solid: Solid) -> BrepIntegral:
    from OCP.gp import gp_Pnt

    _check_closed(solid)
    free_form = _free_form(solid)
    if free_form.free:
        return _integrate_free_form(solid, free_form)
    lo, hi = free_form.lo, free_form.hi
    centre = gp_Pnt(*((lo + hi) / 2).tolist())
    v1, c1, t1 = _properties(solid.shape, centre, COARSE_EPS)
    v2, c2, t2 = _properties(solid.shape, centre, FINE_EPS)
    if not all(math.isfinite(x) for x in (v1, v2)) or abs(v2) <= VOLUME_REL * free_form.box_volume:
        raise ZeroVolumeError(f"the solid {solid.name!r} encloses no volume; export it again as a closed solid")
    if v2 < 0:  # an inside-out solid: every integral changes sign
        v1, t1, v2, t2 = -v1, -t1, -v2, -t2
    estimate = max(_difference(v1, c1, t1, v2, c2, t2), ROUNDING_FLOOR)
    return BrepIntegral(v2, c2, 0.5 * (t2 + t2.T), estimate, _count_faces(solid.shape))


@dataclass(frozen=True, slots=True)
class _FreeForm:
    """A solid's faces split for integration, and ``green``'s sums over its free-form ones.

    lo, hi : the box [mm].  origin : apex and origin of every sum (``_rough_centre``).  faces : the
    faces of its closed shells.  free : those ``green`` integrates (indices into faces).  sums, error :
    their ``green.SUMS`` added, and the bound.
    """

    lo: NDArray[np.float64]
    hi: NDArray[np.float64]
    origin: NDArray[np.float64]
    faces: list[Any]
    free: list[int]
    sums: NDArray[np.float64]
    error: NDArray[np.float64]

    @property
    def size(self) -> float:
        return float(np.linalg.norm(self.hi - self.lo))

    @property
    def box_volume(self) -> float:
        return float(np.prod(np.maximum(self.hi - self.lo, 0.0)))

    @property
    def scale(self) -> NDArray[np.float64]:
        """Magnitudes of the ``green.SUMS`` over the box: the tolerances' unit."""
        v, d = self.box_volume, self.size
        return np.array([v] + [v * d] * 3 + [v * d * d] * 6 + [d * d] * 4)


def _free_form(solid: Solid) -> _FreeForm:
    """The solid's ``_FreeForm``, integrated once and kept with the solid (its area and its volume
    integrals come from the same pass)."""
    from . import green

    memo = solid.memo.get("free_form")
    if isinstance(memo, _FreeForm):
        return memo
    lo, hi = bounding_box(solid.shape)
    faces = list(green.closed_shell_faces(solid.shape))
    free = [i for i, f in enumerate(faces) if not green.is_analytic(f)]
    origin = _rough_centre(solid.shape, lo, hi) if free else (lo + hi) / 2
    out = _FreeForm(lo, hi, origin, faces, free, np.zeros(green.SUMS), np.zeros(green.SUMS))
    for i in free:
        s, e = green.face_sums(faces[i], origin, FREE_FORM_TOLERANCE * out.scale)
        out.sums[:] += s
        out.error[:] += e
    solid.memo["free_form"] = out
    return out


def _difference(
    v1: float, c1: NDArray[np.float64], t1: NDArray[np.float64], v2: float, c2: NDArray[np.float64], t2: NDArray[np.float64]
) -> float:
    """Relative difference of two results: volume, centre (in radii of gyration), each principal moment."""
    m1, m2 = np.linalg.eigvalsh(t1), np.linalg.eigvalsh(t2)
    gyration = math.sqrt(max(float(m2.max()), 0.0) / v2)
    return max(
        abs(v1 - v2) / v2,
        float(np.max(np.abs(c1 - c2))) / gyration if gyration > 0 else 0.0,
        float(np.max(np.abs(m1 - m2) / np.maximum(np.abs(m2), 1e-300))),
    )


def _integrate_free_form(solid: Solid, free_form: _FreeForm) -> BrepIntegral:
    """Analytic faces by OpenCASCADE's adaptive rule (twice, as above), the others by ``green``.

    All sums are taken about the same origin and added before the centre of mass is formed.  The
    estimate is the largest of the two-accuracy difference, the free-form faces' own error bound
    carried to volume, centre and principal moments component by component (first order), and the
    volume the faces' gaps leave open (``_unclosed``, with a warning where that matters).
    """
    from . import green

    origin, lo, hi = free_form.origin, free_form.lo, free_form.hi
    own, own_error = free_form.sums.copy(), free_form.error.copy()
    runs = [np.zeros(green.SUMS), np.zeros(green.SUMS)]
    free = set(free_form.free)
    for i, face in enumerate(free_form.faces):
        if i in free:
            continue
        coarse = _face_sums(face, origin, COARSE_EPS, free_form.size, vector_area=False)
        fine = _face_sums(face, origin, FINE_EPS, free_form.size, vector_area=True)
        if coarse is None or fine is None:  # its first moment is lost: integrated here as well
            s, e = green.face_sums(face, origin, FREE_FORM_TOLERANCE * free_form.scale)
            own += s
            own_error += e
            continue
        runs[0] += coarse
        runs[1] += fine
    runs = [run + own for run in runs]
    if not all(math.isfinite(float(x)) for run in runs for x in run) or abs(runs[1][0]) <= VOLUME_REL * free_form.box_volume:
        raise ZeroVolumeError(f"the solid {solid.name!r} encloses no volume; export it again as a closed solid")
    sign = 1.0 if runs[1][0] > 0 else -1.0  # an inside-out solid: every integral changes sign
    v1, c1, t1 = _from_sums(sign * runs[0], origin)
    v2, c2, t2 = _from_sums(sign * runs[1], origin)
    reach = float(np.linalg.norm(np.maximum(np.abs(lo - origin), np.abs(hi - origin))))
    unclosed, warnings = _unclosed(solid.name, runs[1], v2, reach)
    estimate = max(_difference(v1, c1, t1, v2, c2, t2), _propagated(sign * runs[1], own_error, origin), unclosed, ROUNDING_FLOOR)
    return BrepIntegral(v2, c2, t2, estimate, _count_faces(solid.shape), warnings)


UNCLOSED_WARNING = 1e-6  # relative volume the faces' gaps may move, API.md's accuracy of brep


def _unclosed(name: str, sums: NDArray[np.float64], volume: float, reach: float) -> tuple[float, tuple[str, ...]]:
    """How much the faces' failure to close leaves the volume open (relative), and a warning where
    that exceeds ``UNCLOSED_WARNING``.

    Over a closed surface the vector area ∮n dA is zero and the cone integrals do not depend on their
    apex.  Where the faces leave a vector area ``delta`` (gaps and overlaps within the file's
    tolerance), the volume depends on the apex, that is on how the gaps would be closed: by up to
    |delta| ``reach`` / 3 for an apex anywhere in the box.  The apex taken is the one of OpenCASCADE's
    ``BRepGProp.VolumeProperties_s`` (which gmsh's ``getMass`` calls), so the result is
    theirs; its Gauss-Kronrod variant takes another apex and differs by up to this much (7.5e-6 on
    CAx-IF's s1-c5-214 MAINBODY_FRONT, where this is 3e-4).  It enters the estimate.
    """
    delta = float(np.linalg.norm(sums[10:13]))
    moved = delta * reach / 3 / abs(volume)
    if moved <= UNCLOSED_WARNING:
        return moved, ()
    return (
        moved,
        (
            f"the faces of the solid {name!r} do not quite close (they leave {delta:.2g} mm^2 of vector area open, "
            f"gaps within the file's tolerance): its volume depends on how they are closed, by up to {moved:.1g} "
            "relative; the result takes OpenCASCADE's convention",
        ),
    )


def _rough_centre(shape: Any, lo: NDArray[np.float64], hi: NDArray[np.float64]) -> NDArray[np.float64]:
    """The mean of the shape's vertices, as each visit of the explorer finds them: the apex that
    ``BRepGProp.VolumeProperties_s`` takes for its cones, so that a file whose faces do not quite
    close gets the same volume by both routes.  The box's centre where there are no vertices."""
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_VERTEX
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    total, count = np.zeros(3), 0
    explorer = TopExp_Explorer(shape, TopAbs_VERTEX)
    while explorer.More():
        p = BRep_Tool.Pnt_s(TopoDS.Vertex(explorer.Current()))
        total += (p.X(), p.Y(), p.Z())
        count += 1
        explorer.Next()
    return total / count if count else (lo + hi) / 2


def _face_sums(face: Any, origin: NDArray[np.float64], eps: float, size: float, vector_area: bool) -> NDArray[np.float64] | None:
    """``green.SUMS`` of one face by OpenCASCADE's adaptive rule, the cone from ``origin`` over the face
    (``BRepGProp_Vinert`` with ``origin`` as its apex and location); its vector area only if asked
    (zeros otherwise).  None where the cone's volume is too small to carry the face's first moment
    back (OpenCASCADE keeps the centre, not the moment)."""
    from OCP.BRepGProp import BRepGProp_Domain, BRepGProp_Face, BRepGProp_Vinert
    from OCP.gp import gp_Pnt

    apex = gp_Pnt(*origin.tolist())
    props = BRepGProp_Vinert(BRepGProp_Face(face, False), BRepGProp_Domain(face), apex, apex, eps)
    volume = float(props.Mass())
    c = props.CentreOfMass()
    d = np.array([c.X(), c.Y(), c.Z()], dtype=np.float64) - origin
    if volume == 0.0 or float(np.max(np.abs(d))) > 1e3 * size:
        return None
    area = np.zeros(3)  # the vector area: the cone's volume moves by -a·area/3 with its apex
    for k in range(3 if vector_area else 0):
        moved = origin.copy()
        moved[k] += size
        point = gp_Pnt(*moved.tolist())  # the rule's apex is its location
        cone = BRepGProp_Vinert(BRepGProp_Face(face, False), BRepGProp_Domain(face), point, point, eps)
        area[k] = 3 * (volume - float(cone.Mass())) / size
    m = props.MatrixOfInertia()  # about the centre of mass; back to the origin (L&L eq. 32.12)
    tensor = np.array([[m.Value(i, j) for j in (1, 2, 3)] for i in (1, 2, 3)], dtype=np.float64)
    tensor += volume * (float(d @ d) * np.eye(3) - np.outer(d, d))
    half_trace = 0.5 * float(np.trace(tensor))  # x^2 + y^2 + z^2 integrated
    return np.array(
        [
            volume,
            *(volume * d),
            half_trace - tensor[0, 0],
            half_trace - tensor[1, 1],
            half_trace - tensor[2, 2],
            -tensor[0, 1],
            -tensor[0, 2],
            -tensor[1, 2],
            *area,
            0.0,  # its area is not needed here; surface_area takes the analytic faces' from OpenCASCADE
        ],
        dtype=np.float64,
    )


def _from_sums(sums: NDArray[np.float64], origin: NDArray[np.float64]) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """Volume, centre of mass and the tensor about it (L&L sign convention) from ``green.SUMS`` about ``origin``."""
    volume = float(sums[0])
    d = sums[1:4] / volume
    xx, yy, zz, xy, xz, yz = sums[4:10]
    tensor = np.array([[yy + zz, -xy, -xz], [-xy, xx + zz, -yz], [-xz, -yz, xx + yy]], dtype=np.float64)
    tensor -= volume * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return volume, origin + d, 0.5 * (tensor + tensor.T)


def _propagated(sums: NDArray[np.float64], error: NDArray[np.float64], origin: NDArray[np.float64]) -> float:
    """The sums' error bound carried to the relative errors of volume, centre and principal moments:
    each sum moved by its bound in turn, the changes added (first order)."""
    v, c, t = _from_sums(sums, origin)
    m = np.linalg.eigvalsh(t)
    gyration = math.sqrt(max(float(m.max()), 0.0) / v)
    dv, dc, dm = 0.0, np.zeros(3), np.zeros(3)
    for i in np.flatnonzero(error[:10]):
        moved = sums.copy()
        moved[i] += error[i]
        v_i, c_i, t_i = _from_sums(moved, origin)
        dv += abs(v_i - v)
        dc += np.abs(c_i - c)
        dm += np.abs(np.linalg.eigvalsh(t_i) - m)
    return max(
        dv / v,
        float(np.max(dc)) / gyration if gyration > 0 else 0.0,
        float(np.max(dm / np.maximum(np.abs(m), 1e-300))),
    )


def surface_area(solid: Solid) -> float:
    """Area of the solid's faces [mm^2]: analytic ones by OpenCASCADE's adaptive rule (eps ``FINE_EPS``),
    free-form ones by ``green`` (the adaptive rule is 1.5 % off on a prism over a B-spline profile)."""
    try:
        from OCP.BRep import BRep_Builder
        from OCP.BRepGProp import BRepGProp
        from OCP.GProp import GProp_GProps
        from OCP.TopoDS import TopoDS_Compound

        free_form = _free_form(solid)
        if not free_form.free:
            props = GProp_GProps()
            BRepGProp.SurfaceProperties_s(solid.shape, props, FINE_EPS)
            return float(props.Mass())
        builder, analytic = BRep_Builder(), TopoDS_Compound()
        builder.MakeCompound(analytic)
        free = set(free_form.free)
        for i, face in enumerate(free_form.faces):
            if i not in free:
                builder.Add(analytic, face)
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(analytic, props, FINE_EPS)
        return float(props.Mass()) + float(free_form.sums[13])
    except ServiceError:
        raise
    except (Exception, SystemExit) as exc:
        raise _translated(exc, f"measure the surface of the solid {solid.name!r}") from exc


def _check_closed(solid: Solid) -> None:
    """Every shell of the solid must be closed; an open one bounds no volume."""
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    explorer = TopExp_Explorer(solid.shape, TopAbs_SHELL)
    shells = 0
    while explorer.More():
        shells += 1
        if not BRep_Tool.IsClosed_s(TopoDS.Shell(explorer.Current())):
            raise NotWatertightError(
                f"the solid {solid.name!r} has an open shell (a face is missing or not sewn), so it does not "
                "bound a volume; repair it in the CAD tool",
                part=solid.name,
            )
        explorer.Next()
    if shells == 0:
        raise EmptyGeometryError(f"the solid {solid.name!r} has no faces", part=solid.name)


def _count_faces(shape: Any) -> int:
    from OCP.TopAbs import TopAbs_FACE, TopAbs_SHAPE

    return _count(shape, TopAbs_FACE, TopAbs_SHAPE)


def bounding_box(shape: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Lower and upper corners [mm] of the shape's exact bounding box."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.AddOptimal_s(shape, box, False, False)
    lo, hi = box.CornerMin(), box.CornerMax()
    return (np.array([lo.X(), lo.Y(), lo.Z()], dtype=np.float64), np.array([hi.X(), hi.Y(), hi.Z()], dtype=np.float64))


ANGULAR_DEFLECTION = 0.5  # rad, OpenCASCADE's default; the linear deflection governs below ~1e-2 of the diagonal


def tessellate(solid: Solid, deflection: float) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Triangles of the solid's surface, chordal deflection ``deflection`` x its bounding-box diagonal.

    Vertices on an edge shared by two faces are merged through the edge's
    polygon on each face's triangulation, so the surface is closed exactly.
    """
    try:
        return _tessellate(solid, deflection)
    except ServiceError:
        raise
    except (Exception, SystemExit) as exc:
        raise _translated(exc, f"tessellate the solid {solid.name!r}") from exc


def _tessellate(solid: Solid, deflection: float) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.BRepTools import BRepTools

    lo, hi = bounding_box(solid.shape)
    diagonal = float(np.linalg.norm(hi - lo))
    shape = solid.shape
    # Delabella first (fast); the default Watson triangulator where Delabella leaves a face out or the
    # surface open (filleted blends); then Watson on a ShapeFix'ed copy (blend faces read back from STEP
    # can carry p-curves the mesher rejects; ShapeFix rebuilds them, the surfaces stay the same).
    for fast, fix in ((True, False), (False, False), (False, True)):
        if fix:
            shape = _fixed(shape)
        BRepTools.Clean_s(shape)  # drop any triangulation the file (or the last attempt) carried
        mesher = BRepMesh_IncrementalMesh(shape, _mesh_parameters(deflection * diagonal, fast))
        if mesher.IsDone() and _all_faces_meshed(shape):
            vertices, faces = _welded(*_triangles(shape, solid.name), MERGE_FRACTION * deflection * diagonal)
            if _closed(faces):
                return vertices, faces
    raise UnreadableFileError(
        f"OpenCASCADE could not tessellate the solid {solid.name!r} into a closed surface; use geometry=brep", part=solid.name
    )


MERGE_FRACTION = 1e-3  # nodes closer than this x the chordal deflection are one point (seams, poles)


def _welded(
    vertices: NDArray[np.float64], faces: NDArray[np.int64], radius: float
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Nodes within ``radius`` merged (a seam's two sides, a degenerate edge's nodes); collapsed triangles dropped."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    pairs = cKDTree(vertices).query_pairs(radius, output_type="ndarray")
    if len(pairs):
        n = len(vertices)
        graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        _, label = connected_components(graph, directed=False)
        first = np.full(label.max() + 1, -1, dtype=np.int64)
        first[label[::-1]] = np.arange(n)[::-1]  # the lowest index of each group
        faces = first[label][faces]
    keep = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    faces = faces[keep]
    used, compact = np.unique(faces, return_inverse=True)
    return vertices[used], compact.reshape(faces.shape).astype(np.int64)


def _closed(faces: NDArray[np.int64]) -> bool:
    """Every undirected edge used by exactly two triangles."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return bool(np.all(counts == 2))


def _mesh_parameters(deflection: float, fast: bool) -> Any:
    """Absolute chordal deflection [mm], OpenCASCADE's default angle; ``fast``: the Delabella triangulator,
    about 6x faster than the default (Watson) on a sphere at 1e-4 of its diagonal, the same triangles' count."""
    from OCP.IMeshTools import IMeshTools_MeshAlgoType, IMeshTools_Parameters

    params = IMeshTools_Parameters()
    params.Deflection = deflection
    params.Angle = ANGULAR_DEFLECTION
    params.Relative = False
    params.InParallel = False  # one core per job: the compute pool runs jobs side by side
    if fast:
        params.MeshAlgo = IMeshTools_MeshAlgoType.IMeshTools_MeshAlgoType_Delabella
    return params


def _all_faces_meshed(shape: Any) -> bool:
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS

    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        if BRep_Tool.Triangulation_s(TopoDS.Face(explorer.Current()), TopLoc_Location()) is None:
            return False
        explorer.Next()
    return True


def triangles_only(solid: Solid) -> bool:
    """Whether the solid's faces are triangles with no exact surface (AP242's tessellated geometry,
    ``COMPLEX_TRIANGULATED_FACE``): nothing to integrate exactly, the triangles are the body."""
    try:
        from OCP.BRep import BRep_Tool
        from OCP.TopAbs import TopAbs_FACE
        from OCP.TopExp import TopExp_Explorer
        from OCP.TopoDS import TopoDS

        explorer = TopExp_Explorer(solid.shape, TopAbs_FACE)
        found = False
        while explorer.More():
            if BRep_Tool.Surface_s(TopoDS.Face(explorer.Current())) is not None:
                return False
            found = True
            explorer.Next()
        return found
    except (Exception, SystemExit) as exc:
        raise _translated(exc, f"read the faces of the solid {solid.name!r}") from exc


def carried_triangles(solid: Solid) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The triangles a tessellated solid carries [mm] (``_triangles``), and points given twice (each face
    lists its own) joined where their coordinates are equal."""
    try:
        vertices, faces = _triangles(solid.shape, solid.name)
    except ServiceError:
        raise
    except (Exception, SystemExit) as exc:
        raise _translated(exc, f"read the triangles of the solid {solid.name!r}") from exc
    unique, inverse = np.unique(vertices, axis=0, return_inverse=True)
    return unique, inverse.reshape(-1)[faces].astype(np.int64)


def _fixed(shape: Any) -> Any:
    from OCP.ShapeFix import ShapeFix_Shape

    fixer = ShapeFix_Shape(shape)
    fixer.Perform()
    return fixer.Shape()


def _triangles(shape: Any, name: str) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    from OCP.BRep import BRep_Tool
    from OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as TopTools_IndexedMapOfShape
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_REVERSED
    from OCP.TopExp import TopExp, TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS

    points: list[NDArray[np.float64]] = []
    faces: list[NDArray[np.int64]] = []
    remap: dict[int, int] = {}  # global node index -> the index it is merged into
    edge_nodes: dict[int, list[int]] = {}
    edge_map = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_EDGE, edge_map)
    offset = 0
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        face = TopoDS.Face(explorer.Current())
        loc = TopLoc_Location()
        tri = BRep_Tool.Triangulation_s(face, loc)
        if tri is None:
            raise UnreadableFileError(f"a face of the solid {name!r} could not be tessellated", part=name)
        trsf = loc.Transformation()
        n = tri.NbNodes()
        xyz = np.empty((n, 3), dtype=np.float64)
        for i in range(1, n + 1):
            p = tri.Node(i).Transformed(trsf)
            xyz[i - 1] = (p.X(), p.Y(), p.Z())
        t = np.empty((tri.NbTriangles(), 3), dtype=np.int64)
        for k in range(1, tri.NbTriangles() + 1):
            t[k - 1] = tri.Triangle(k).Get()
        t -= 1
        if face.Orientation() == TopAbs_REVERSED:
            t = t[:, ::-1]
        edges = TopExp_Explorer(face, TopAbs_EDGE)
        while edges.More():
            edge = TopoDS.Edge(edges.Current())
            poly = BRep_Tool.PolygonOnTriangulation_s(edge, tri, loc)
            if poly is not None:
                nodes = [offset + poly.Node(j) - 1 for j in range(1, poly.NbNodes() + 1)]
                first = edge_nodes.setdefault(edge_map.FindIndex(edge), nodes)
                if first is not nodes and len(first) == len(nodes):
                    for a, b in zip(nodes, first):
                        remap[a] = remap.get(b, b)
            edges.Next()
        points.append(xyz)
        faces.append(t + offset)
        offset += n
        explorer.Next()
    if not faces:
        raise EmptyGeometryError(f"the solid {name!r} gave no triangles", part=name)
    index = np.arange(offset, dtype=np.int64)
    for a, b in remap.items():
        index[a] = b
    triangles = index[np.concatenate(faces)]
    used, compact = np.unique(triangles, return_inverse=True)  # drop the nodes merged into others
    return np.concatenate(points)[used], compact.reshape(triangles.shape).astype(np.int64)
