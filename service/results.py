"""The result model: what one analysis computed, and its one serialiser to the API's JSON.

Every section the contract returns (API.md, "The analysis result" and
"Additions, version 1.1") is a field here, typed.  ``document()`` turns a
result into its typed JSON (``sections.AnalysisDocument``: one frozen
dataclass per JSON object, absent sections None) and ``as_dict()`` into the
JSON itself.  The HTTP response models (``api/schemas.py``) are generated from
those dataclasses, and the CLI table and the batch rows read the document:
there is no second description of the JSON to drift from this one.

This module imports no stage that computes anything: results serialise
without knowing the pipeline that made them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .classification import Classification
from .mass import InertiaTensor, MassProperties
from .principal import PrincipalFrame
from .sections import (
    AnalysisDocument,
    ClassificationSection,
    Diagnostics,
    ExportPartSection,
    ExportSection,
    FrameSection,
    PartSection,
    PrecessionDocument,
    PrincipalSection,
    ReferenceInertiaSection,
    RotationalConstantsSection,
    Source,
)
from .vocabulary import ExportFormat, RotorKind, RotorShape

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
    "analysis_document",
    "precession_document",
    "analysis_dict",
    "precession_dict",
    "principal_dict",
    "classification_dict",
    "radii_of_gyration",
]


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
        return _part_section(self).as_dict()


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

    def document(self) -> AnalysisDocument:
        """The typed JSON of this result."""
        return analysis_document(self)

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

    def document(self) -> PrecessionDocument:
        """The typed JSON of this result."""
        return precession_document(self)

    def as_dict(self) -> dict[str, Any]:
        return precession_dict(self)


# ---- the serialiser ---------------------------------------------------------------------------


def _list(arr: Any) -> Any:
    return np.asarray(arr, dtype=np.float64).tolist()


def radii_of_gyration(moments: Any, mass: float) -> list[float]:
    """k_i = sqrt(I_i / m) [m] (a zero moment within rounding, e.g. of a rotator, gives 0)."""
    return [math.sqrt(max(float(i), 0.0) / mass) for i in moments]


def principal_section(frame: PrincipalFrame, mass: float | None = None) -> PrincipalSection:
    return PrincipalSection(
        moments=_list(frame.moments),
        axes=_list(frame.axes),
        quaternion=_list(frame.quaternion),
        unique_axes=bool(frame.unique_axes),
        radii_of_gyration=radii_of_gyration(frame.moments, mass) if mass is not None and mass > 0 else None,
    )


def principal_dict(frame: PrincipalFrame, mass: float | None = None) -> dict[str, Any]:
    return principal_section(frame, mass).as_dict()


def classification_section(cls: Classification) -> ClassificationSection:
    return ClassificationSection(
        kind=RotorKind(cls.kind),
        shape=None if cls.shape is None else RotorShape(cls.shape),
        symmetry_axis=None if cls.symmetry_axis is None else _list(cls.symmetry_axis),
        asymmetry=None if cls.asymmetry is None else float(cls.asymmetry),
        planar=bool(cls.planar),
        tolerance=float(cls.tolerance),
    )


def classification_dict(cls: Classification) -> dict[str, Any]:
    return classification_section(cls).as_dict()


def _body(p: MassProperties) -> dict[str, Any]:
    """mass, volume, density (solids only, API.md), area (shells), centre of mass, tensor."""
    return {
        "mass": p.mass,
        "volume": p.volume,
        "density": p.density if p.volume is not None else None,
        "area": p.area,
        "center_of_mass": _list(p.center_of_mass),
        "inertia_tensor": _list(p.inertia.matrix),
    }


def _part_section(part: PartResult) -> PartSection:
    p = part.props
    return PartSection(
        name=part.name,
        **_body(p),
        surface_area=None if part.surface_area is None else float(part.surface_area),
        principal=principal_section(part.frame, p.mass),
        classification=classification_section(part.classification),
        warnings=list(p.warnings) if p.warnings else None,
    )


def analysis_document(result: AnalysisResult) -> AnalysisDocument:
    """The analysis result of the contract (API.md, "The analysis result"), typed."""
    p = result.props
    ref = result.reference
    parts = result.parts
    return AnalysisDocument(
        source=result.source,
        **_body(p),
        reference_inertia=None if ref is None else ReferenceInertiaSection(point=_list(ref.point), tensor=_list(ref.matrix)),
        surface_area=None if result.surface_area is None else float(result.surface_area),
        principal=principal_section(result.frame, p.mass),
        classification=classification_section(result.classification),
        rotational_constants=_rotational_section(result),
        frame=_frame_section(result),
        export=_export_section(result),
        precession=None if result.motion is None else result.motion.section(),
        parts=None if parts is None else [_part_section(part) for part in parts],
        warnings=list(result.warnings),
        diagnostics=result.diagnostics,
    )


def analysis_dict(result: AnalysisResult) -> dict[str, Any]:
    """The analysis result of the contract (API.md, "The analysis result")."""
    return analysis_document(result).as_dict()


def _rotational_section(result: AnalysisResult) -> RotationalConstantsSection | None:
    rc = result.rotational_constants
    return None if rc is None else RotationalConstantsSection(MHz=list(rc.mhz), cm_1=list(rc.wavenumber))


def _frame_section(result: AnalysisResult) -> FrameSection | None:
    nf = result.named_frame
    if nf is None:
        return None
    return FrameSection(
        quaternion=_list(nf.quaternion),
        center_of_mass=_list(nf.center_of_mass),
        inertia_tensor=_list(nf.inertia_tensor),
        reference_inertia=None if nf.reference_inertia is None else _list(nf.reference_inertia),
    )


def _export_section(result: AnalysisResult) -> ExportSection | None:
    """The robot export (API.md, "Additions, version 1.1"): the whole body's element, and each part's."""
    if result.export is None:
        return None
    parts = None
    if result.parts is not None:
        parts = [ExportPartSection(name=part.name, text=part.export.text) for part in result.parts if part.export is not None]
    return ExportSection(format=ExportFormat(result.export.format), text=result.export.text, parts=parts)


def precession_document(result: PrecessionResult) -> PrecessionDocument:
    """The response of POST /v1/precession, typed."""
    return PrecessionDocument(
        principal=principal_section(result.frame),
        classification=classification_section(result.classification),
        precession=result.motion.section(),
        warnings=list(result.warnings),
        diagnostics=result.diagnostics,
    )


def precession_dict(result: PrecessionResult) -> dict[str, Any]:
    """The response of POST /v1/precession."""
    return precession_document(result).as_dict()
