"""Reading a CAD file (STEP, IGES) into B-rep parts: the loader's side of ``cad``.

``load`` calls ``read_cad_parts``; the integration of the parts (``brep_mass_properties``)
and their tessellation live in the package, a stage above.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..body import BrepBody, MeshBody, Part
from ..conventions import LENGTH_UNITS
from ..errors import InvalidParameterError, UnsupportedFormatError
from ..surface import SURFACE_AREA_KEY
from ..vocabulary import UnitsFrom

if TYPE_CHECKING:
    from .occ import Solid

__all__ = ["CAD_FORMATS", "GEOMETRIES", "DEFAULT_DEFLECTION", "read_cad_parts"]

CAD_FORMATS = ("step", "iges")
GEOMETRIES = ("brep", "mesh")
DEFAULT_DEFLECTION = 1e-3  # of the bounding-box diagonal: about 1e-3 relative in mass (docs/cad.md)


def _binding() -> None:
    from . import occ

    if not occ.available():
        raise UnsupportedFormatError(
            f"reading STEP and IGES files needs the 'cad' extra (OpenCASCADE): {occ.CAD_EXTRA_HINT}", extra="cad"
        )


def read_cad_parts(data: bytes, fmt: str, units: str | None) -> tuple[list[Part], str, UnitsFrom, tuple[str, ...]]:
    """The solids of a CAD file as ``BrepBody`` parts, the unit applied, where it came from, warnings."""
    try:
        _binding()
    except ImportError as exc:  # pragma: no cover - occ itself imports nothing heavy
        raise UnsupportedFormatError(f"reading CAD files needs the 'cad' extra: {exc}", extra="cad") from exc
    from . import occ

    solids, declared, notes = occ.read_solids(data, fmt)
    warnings: list[str] = list(notes)
    file_scale = LENGTH_UNITS.get(declared) if declared else None
    if units is not None:
        if file_scale is None:
            raise InvalidParameterError(
                f"the file's length unit ({declared or 'several units'}) cannot be overridden; omit units", parameter="units"
            )
        scale, unit, units_from = occ.MODEL_UNIT * LENGTH_UNITS[units] / file_scale, units, UnitsFrom.REQUEST
    elif file_scale is None:
        scale, unit, units_from = occ.MODEL_UNIT, "m", UnitsFrom.FILE
        warnings.append(
            f"the file's length unit ({declared or 'several units'}) was converted to metres; reference points are read in metres"
        )
    else:
        assert declared is not None
        scale, unit, units_from = occ.MODEL_UNIT, declared, UnitsFrom.FILE
    triangles_only = [occ.triangles_only(s) for s in solids]
    if any(triangles_only):
        return _tessellated_solids(solids, triangles_only, scale), unit, units_from, tuple(warnings)
    parts = [Part(s.name, BrepBody(s, scale, s.name), {SURFACE_AREA_KEY: occ.surface_area(s) * scale**2}) for s in solids]
    return parts, unit, units_from, tuple(warnings)


def _tessellated_solids(solids: list[Solid], triangles_only: list[bool], scale: float) -> list[Part]:
    """Solids of triangles alone (AP242 tessellated geometry) as the meshes they are; refused beside exact ones."""
    from . import occ

    if not all(triangles_only):
        names = [s.name for s, t in zip(solids, triangles_only, strict=True) if t]
        raise UnsupportedFormatError(
            f"the file holds {len(names)} solid(s) of triangles alone ({', '.join(repr(n) for n in names[:4])}"
            f"{' ...' if len(names) > 4 else ''}) beside solids of exact geometry, which this service does not "
            "weigh together; export the parts alike (all exact, or all as meshes such as STL or 3MF)",
            format="step",
        )
    note = (
        "the file's solids are tessellated geometry (faces of triangles with no exact surface, as AP242 writes "
        "them): their triangles were weighed as the closed surface they form"
    )
    parts = []
    for s in solids:
        vertices, faces = occ.carried_triangles(s)
        parts.append(Part(s.name, MeshBody(vertices, faces, scale, s.name, (note,))))
    return parts
