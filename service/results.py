"""The result model: what one analysis computed, and its one serialiser to the API's JSON.

Every section the contract returns (API.md, "The analysis result" and
"Additions, version 1.1") is a field here, typed; ``as_dict()`` writes the
sections present and only those (absent means "not asked for", never null).
The HTTP response models (``api/schemas.py``), the CLI table and the batch
rows are all built from ``as_dict()``: there is no second description of the
JSON to drift from this one.

This module imports no stage that computes anything: results serialise
without knowing the pipeline that made them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, Any

import numpy as np

from .classification import Classification
from .mass import InertiaTensor, MassProperties
from .principal import PrincipalFrame
from .vocabulary import SourceKind, UnitsFrom

if TYPE_CHECKING:
    from .export import Snippet
    from .frames import NamedFrame
    from .motion import FreeMotion
    from .rotational import RotationalConstants

__all__ = [
    "Source",
    "Diagnostics",
    "PartResult",
    "AnalysisResult",
    "PrecessionResult",
    "analysis_dict",
    "precession_dict",
    "principal_dict",
    "classification_dict",
    "radii_of_gyration",
]


@dataclass(frozen=True, slots=True, kw_only=True)
class Source:
    """The ``source`` section: what was read, how, and how many elements it had.

    filename : the client's file name (absent for in-memory input without one).
    format : the reader's format name (``stl``, ``step``, ``points``, ...).
    kind : ``mesh``, ``volume``, ``points`` or ``cad``.
    units : the length unit applied to the file; units_from : ``request``, ``file`` or ``default``.
    geometry, solids, deflection : CAD files (``brep`` or ``mesh``; solids read; relative chordal deflection).
    vertices, triangles, watertight : surfaces (distinct vertices, triangles, closed) and tessellated CAD.
    points : point masses, or the nodes of a volume mesh; tetrahedra, cells : volume meshes.
    parts : the number of parts of a scene or assembly (absent for one body).
    """

    filename: str | None = None
    format: str
    kind: SourceKind
    units: str
    units_from: UnitsFrom
    vertices: int | None = None
    triangles: int | None = None
    watertight: bool | None = None
    points: int | None = None
    tetrahedra: int | None = None
    cells: int | None = None
    geometry: str | None = None
    solids: int | None = None
    deflection: float | None = None
    parts: int | None = None

    # the order of the keys in the JSON: the identity, then what the kind of input counts
    _ORDER = (
        "filename",
        "format",
        "kind",
        "units",
        "units_from",
        "vertices",
        "triangles",
        "watertight",
        "points",
        "tetrahedra",
        "cells",
        "parts",
    )
    _CAD_ORDER = (
        "filename",
        "format",
        "kind",
        "units",
        "units_from",
        "geometry",
        "solids",
        "watertight",
        "deflection",
        "vertices",
        "triangles",
        "parts",
    )

    def as_dict(self) -> dict[str, Any]:
        order = self._CAD_ORDER if self.kind == SourceKind.CAD else self._ORDER
        out = {key: getattr(self, key) for key in order if getattr(self, key) is not None}
        out["kind"], out["units_from"] = self.kind.value, self.units_from.value  # plain strings in the JSON
        return out


# the JSON keys of the source section, for the response schema
SOURCE_KEYS = tuple(f.name for f in fields(Source))


@dataclass(frozen=True, slots=True)
class Diagnostics:
    """The ``diagnostics`` section.

    elapsed_s : [s] wall time of the whole analysis.
    relative_error_estimate : [1] bound on the relative floating-point error of the principal moments.
    tessellation_error : [1] CAD with geometry=mesh: the largest relative difference of mass and principal
        moments between the tessellation and the exact B-rep (None otherwise).
    """

    elapsed_s: float
    relative_error_estimate: float
    tessellation_error: float | None = None

    def as_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"elapsed_s": float(self.elapsed_s), "relative_error_estimate": float(self.relative_error_estimate)}
        if self.tessellation_error is not None:
            out["tessellation_error"] = float(self.tessellation_error)
        return out


@dataclass(frozen=True, slots=True)
class PartResult:
    """One body of a scene or assembly, in the scene frame."""

    name: str
    props: MassProperties
    frame: PrincipalFrame
    classification: Classification
    surface_area: float | None = None
    export: Snippet | None = None

    def as_dict(self) -> dict[str, Any]:
        return _part_dict(self)


@dataclass(frozen=True, slots=True)
class AnalysisResult:
    """Everything one analysis computed; ``as_dict`` gives the API's JSON."""

    source: Source
    props: MassProperties
    frame: PrincipalFrame
    classification: Classification
    diagnostics: Diagnostics
    reference: InertiaTensor | None = None
    motion: FreeMotion | None = None
    parts: tuple[PartResult, ...] | None = None
    warnings: tuple[str, ...] = ()
    surface_area: float | None = None
    rotational_constants: RotationalConstants | None = None
    named_frame: NamedFrame | None = None
    export: Snippet | None = None

    @property
    def elapsed_s(self) -> float:
        return self.diagnostics.elapsed_s

    @property
    def tessellation_error(self) -> float | None:
        return self.diagnostics.tessellation_error

    def as_dict(self) -> dict[str, Any]:
        return analysis_dict(self)


@dataclass(frozen=True, slots=True)
class PrecessionResult:
    """Result of POST /v1/precession: principal frame, class, motion."""

    frame: PrincipalFrame
    classification: Classification
    motion: FreeMotion
    diagnostics: Diagnostics
    warnings: tuple[str, ...] = ()

    @property
    def relative_error_estimate(self) -> float:
        return self.diagnostics.relative_error_estimate

    @property
    def elapsed_s(self) -> float:
        return self.diagnostics.elapsed_s

    def as_dict(self) -> dict[str, Any]:
        return precession_dict(self)


# ---- the serialiser ---------------------------------------------------------------------------


def _list(arr: Any) -> Any:
    return np.asarray(arr, dtype=np.float64).tolist()


def radii_of_gyration(moments: Any, mass: float) -> list[float]:
    """k_i = sqrt(I_i / m) [m] (a zero moment within rounding, e.g. of a rotator, gives 0)."""
    return [math.sqrt(max(float(i), 0.0) / mass) for i in moments]


def principal_dict(frame: PrincipalFrame, mass: float | None = None) -> dict[str, Any]:
    out: dict[str, Any] = {
        "moments": _list(frame.moments),
        "axes": _list(frame.axes),
        "quaternion": _list(frame.quaternion),
        "unique_axes": bool(frame.unique_axes),
    }
    if mass is not None and mass > 0:
        out["radii_of_gyration"] = radii_of_gyration(frame.moments, mass)
    return out


def classification_dict(cls: Classification) -> dict[str, Any]:
    out: dict[str, Any] = {"kind": cls.kind}
    if cls.shape is not None:
        out["shape"] = cls.shape
    if cls.symmetry_axis is not None:
        out["symmetry_axis"] = _list(cls.symmetry_axis)
    if cls.asymmetry is not None:
        out["asymmetry"] = float(cls.asymmetry)
    out["planar"] = bool(cls.planar)
    out["tolerance"] = float(cls.tolerance)
    return out


def _body_dict(p: MassProperties) -> dict[str, Any]:
    """mass, volume, density (solids only, API.md), area (shells), centre of mass, tensor."""
    out: dict[str, Any] = {"mass": p.mass}
    if p.volume is not None:
        out["volume"] = p.volume
        if p.density is not None:
            out["density"] = p.density
    if p.area is not None:
        out["area"] = p.area
    out["center_of_mass"] = _list(p.center_of_mass)
    out["inertia_tensor"] = _list(p.inertia.matrix)
    return out


def _part_dict(part: PartResult) -> dict[str, Any]:
    p = part.props
    out: dict[str, Any] = {"name": part.name, **_body_dict(p)}
    if part.surface_area is not None:
        out["surface_area"] = float(part.surface_area)
    out["principal"] = principal_dict(part.frame, p.mass)
    out["classification"] = classification_dict(part.classification)
    if p.warnings:
        out["warnings"] = list(p.warnings)
    return out


def analysis_dict(result: AnalysisResult) -> dict[str, Any]:
    """The analysis result of the contract (API.md, "The analysis result")."""
    p = result.props
    out: dict[str, Any] = {"source": result.source.as_dict(), **_body_dict(p)}
    if result.reference is not None:
        out["reference_inertia"] = {"point": _list(result.reference.point), "tensor": _list(result.reference.matrix)}
    if result.surface_area is not None:
        out["surface_area"] = float(result.surface_area)
    out["principal"] = principal_dict(result.frame, p.mass)
    out["classification"] = classification_dict(result.classification)
    out.update(_v11_dict(result))
    if result.motion is not None:
        out["precession"] = result.motion.as_dict()
    if result.parts is not None:
        out["parts"] = [_part_dict(part) for part in result.parts]
        if result.export is not None:
            out["export"]["parts"] = [
                {"name": part.name, "text": part.export.text} for part in result.parts if part.export is not None
            ]
    out["warnings"] = list(result.warnings)
    out["diagnostics"] = result.diagnostics.as_dict()
    return out


def _v11_dict(result: AnalysisResult) -> dict[str, Any]:
    """rotational_constants, frame and export (API.md, "Additions, version 1.1")."""
    out: dict[str, Any] = {}
    rc = result.rotational_constants
    if rc is not None:
        out["rotational_constants"] = {"MHz": list(rc.mhz), "cm-1": list(rc.wavenumber)}
    nf = result.named_frame
    if nf is not None:
        out["frame"] = {
            "quaternion": _list(nf.quaternion),
            "center_of_mass": _list(nf.center_of_mass),
            "inertia_tensor": _list(nf.inertia_tensor),
        }
        if nf.reference_inertia is not None:
            out["frame"]["reference_inertia"] = _list(nf.reference_inertia)
    if result.export is not None:
        out["export"] = {"format": result.export.format, "text": result.export.text}
    return out


def precession_dict(result: PrecessionResult) -> dict[str, Any]:
    """The response of POST /v1/precession."""
    return {
        "principal": principal_dict(result.frame),
        "classification": classification_dict(result.classification),
        "precession": result.motion.as_dict(),
        "warnings": list(result.warnings),
        "diagnostics": result.diagnostics.as_dict(),
    }
