"""Test solids built and written with the same OpenCASCADE binding the reader uses (OCP)."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Sequence
from typing import Any

__all__ = [
    "box",
    "cylinder",
    "nurbs",
    "write_step",
    "write_iges",
    "open_shell",
]


def _quiet() -> None:
    from OCP.Message import Message

    messenger = Message.DefaultMessenger_s()
    for printer in list(messenger.Printers()):
        messenger.RemovePrinter(printer)


_quiet()


def box(dx: float, dy: float, dz: float, corner: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> Any:
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.gp import gp_Pnt

    return BRepPrimAPI_MakeBox(gp_Pnt(*corner), dx, dy, dz).Shape()


def cylinder(radius: float, height: float, base: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> Any:
    """Axis along z from ``base``."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(*base), gp_Dir(0, 0, 1)), radius, height).Shape()


def nurbs(shape: Any) -> Any:
    """The same solid with every face and edge converted to NURBS (exact rational B-splines)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert

    return BRepBuilderAPI_NurbsConvert(shape, True).Shape()


def open_shell() -> Any:
    """The box's faces less one, sewn into an open shell."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer

    sewing = BRepBuilderAPI_Sewing()
    explorer = TopExp_Explorer(box(1.0, 1.0, 1.0), TopAbs_FACE)
    n = 0
    while explorer.More():
        if n < 5:
            sewing.Add(explorer.Current())
        n += 1
        explorer.Next()
    sewing.Perform()
    return sewing.SewedShape()


def _document(parts: Sequence[tuple[str, Any]], assembly: str | None) -> Any:
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDocStd import TDocStd_Document
    from OCP.TopLoc import TopLoc_Location
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    if assembly is None and len(parts) == 1:
        label = tool.AddShape(parts[0][1], False)
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(parts[0][0]))
        return doc
    top = tool.NewShape()
    TDataStd_Name.Set_s(top, TCollection_ExtendedString(assembly or "assembly"))
    for name, shape in parts:
        label = tool.AddShape(shape, False)
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(name))
        tool.AddComponent(top, label, TopLoc_Location())
    tool.UpdateAssemblies()
    return doc


def _written(suffix: str, write: Any) -> bytes:
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "out" + suffix)
        write(path)
        with open(path, "rb") as fh:
            return fh.read()


def write_step(parts: Sequence[tuple[str, Any]], unit: str = "MM", assembly: str | None = None) -> bytes:
    """STEP AP214 text of named solids; ``unit``: the file's length unit (MM, M, INCH, ...).

    Shapes are in OpenCASCADE's session unit, millimetres: a 10 x 20 x 30 box is 10 mm by 20 mm by 30 mm
    in the file whatever ``unit`` is, and the writer converts the numbers to ``unit``.
    """
    from OCP.Interface import Interface_Static
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_AsIs

    doc = _document(parts, assembly)
    Interface_Static.SetCVal_s("write.step.unit", unit)
    writer = STEPCAFControl_Writer()
    writer.SetNameMode(True)
    writer.Transfer(doc, STEPControl_AsIs)
    return _written(".step", writer.Write)


def write_iges(shapes: Sequence[Any], unit: str = "MM") -> bytes:
    """IGES text of the solids as BRep entities (type 186), ``unit`` in the global section.

    OpenCASCADE's plain IGES writer keeps no product names (its XDE writer does, but writes
    trimmed faces instead of solids), so IGES parts are named by the reader.
    """
    from OCP.IGESControl import IGESControl_Writer

    writer = IGESControl_Writer(unit, 1)  # mode 1: solids as BRep entities
    for shape in shapes:
        writer.AddShape(shape)
    writer.ComputeModel()
    return _written(".igs", writer.Write)


def triangles_solid(corners: Sequence[tuple[float, float, float]], triangles: Sequence[tuple[int, int, int]]) -> Any:
    """A solid whose faces are triangles alone, with no surface (what AP242's tessellated geometry reads as):
    one face per triangle, each with its own three nodes, wound as given."""
    from OCP.BRep import BRep_Builder
    from OCP.gp import gp_Pnt
    from OCP.Poly import Poly_Triangle, Poly_Triangulation
    from OCP.TopoDS import TopoDS_Face, TopoDS_Shell, TopoDS_Solid

    builder = BRep_Builder()
    shell = TopoDS_Shell()
    builder.MakeShell(shell)
    for triangle in triangles:
        mesh = Poly_Triangulation(3, 1, False)
        for i, k in enumerate(triangle):
            mesh.SetNode(i + 1, gp_Pnt(*corners[k]))
        mesh.SetTriangle(1, Poly_Triangle(1, 2, 3))
        face = TopoDS_Face()
        builder.MakeFace(face, mesh)
        builder.Add(shell, face)
    solid = TopoDS_Solid()
    builder.MakeSolid(solid)
    builder.Add(solid, shell)
    return solid


def write_tessellated_step(parts: Sequence[tuple[str, Any]]) -> bytes:
    """``write_step`` with OpenCASCADE's writer of tessellated geometry on (``TRIANGULATED_FACE``)."""
    from OCP.Interface import Interface_Static

    before = Interface_Static.IVal_s("write.step.tessellated")
    Interface_Static.SetIVal_s("write.step.tessellated", 1)
    try:
        return write_step(parts)
    finally:
        Interface_Static.SetIVal_s("write.step.tessellated", before)
