"""The JSON of a result, typed: one frozen dataclass per JSON object of the contract, its fields its keys.

``results.py`` (and ``motion.FreeMotion`` for the ``precession`` section) build
these from what an analysis computed; everything that shows a result reads them:

- ``as_dict()`` is the API's JSON (a field that is None is absent, never null;
  the keys in field order; closed sets as their strings),
- the HTTP response models (``api/schemas.py``) are generated from the fields,
  their types and descriptions, and forbid any key not named here,
- the command line's table and the batch rows read the typed fields.

So a new result field is added here once, with its type and description, and
in the function that fills it.  Field metadata: ``description`` for the
schema, ``key`` where the JSON key is not a Python name (``cm-1``).  Lengths of
fixed-size arrays are ``Annotated[..., Size(n)]``.

This module imports nothing heavy (no numpy): the sections hold plain lists.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field, fields
from typing import Annotated, Any

from .vocabulary import ExportFormat, Regime, RotorKind, RotorShape, SourceKind, UnitsFrom

__all__ = [
    "Size",
    "Vector",
    "Tensor",
    "Quaternion",
    "Section",
    "Source",
    "Diagnostics",
    "ReferenceInertiaSection",
    "PrincipalSection",
    "ClassificationSection",
    "TrajectorySection",
    "MotionDiagnosticsSection",
    "PrecessionSection",
    "PartSection",
    "RotationalConstantsSection",
    "FrameSection",
    "ExportPartSection",
    "ExportSection",
    "AnalysisDocument",
    "PrecessionDocument",
]


@dataclass(frozen=True, slots=True)
class Size:
    """The fixed length of a JSON array (3 for a vector, 4 for a quaternion)."""

    n: int


Vector = Annotated[list[float], Size(3)]
Tensor = Annotated[list[Vector], Size(3)]
Quaternion = Annotated[list[float], Size(4)]


def doc(description: str = "", *, key: str | None = None) -> dict[str, str | None]:
    """A field's metadata: its schema description (and JSON key, where it is not the field's name)."""
    return {"description": description, "key": key}


_KEYS: dict[type, tuple[tuple[str, str], ...]] = {}


def _keys(cls: type) -> tuple[tuple[str, str], ...]:
    keys = _KEYS.get(cls)
    if keys is None:
        keys = _KEYS[cls] = tuple((f.name, f.metadata.get("key") or f.name) for f in fields(cls))
    return keys


def _plain(value: Any) -> Any:
    if isinstance(value, Section):
        return value.as_dict()
    if isinstance(value, enum.Enum):
        return value.value
    if isinstance(value, list) and value and isinstance(value[0], Section):
        return [v.as_dict() for v in value]
    return value


class Section:
    """Base of the sections: ``as_dict()`` writes the fields that are not None, in order."""

    __slots__ = ()

    def as_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for name, key in _keys(type(self)):
            value = getattr(self, name)
            if value is not None:
                out[key] = _plain(value)
        return out


@dataclass(frozen=True, slots=True, kw_only=True)
class Source(Section):
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


@dataclass(frozen=True, slots=True)
class Diagnostics(Section):
    """The ``diagnostics`` section: elapsed time [s] and the relative error estimate of the principal moments [1].

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


@dataclass(frozen=True, slots=True, kw_only=True)
class ReferenceInertiaSection(Section):
    """``reference_inertia``: the tensor about the requested point."""

    point: Vector = field(metadata=doc("reference point [m], input frame"))
    tensor: Tensor = field(metadata=doc("inertia about the point [kg m^2]"))


@dataclass(frozen=True, slots=True, kw_only=True)
class PrincipalSection(Section):
    """``principal``: the principal frame."""

    moments: Vector = field(metadata=doc("ascending principal moments [kg m^2]"))
    axes: Tensor = field(metadata=doc("rows: unit principal axes in the input frame"))
    quaternion: Quaternion = field(metadata=doc("[w, x, y, z]: principal frame -> input frame"))
    unique_axes: bool = field(metadata=doc())
    radii_of_gyration: Vector | None = field(default=None, metadata=doc("k_i = sqrt(I_i / m) [m]"))


@dataclass(frozen=True, slots=True, kw_only=True)
class ClassificationSection(Section):
    """``classification``: the rotor class of the principal moments."""

    kind: RotorKind = field(metadata=doc())
    shape: RotorShape | None = field(default=None, metadata=doc())
    symmetry_axis: Vector | None = field(default=None, metadata=doc())
    asymmetry: float | None = field(default=None, metadata=doc("Ray's kappa"))
    planar: bool = field(metadata=doc())
    tolerance: float = field(metadata=doc())


@dataclass(frozen=True, slots=True, kw_only=True)
class TrajectorySection(Section):
    """``precession.trajectory``: the sampled motion."""

    t: list[float] = field(metadata=doc("times [s]"))
    omega_body: list[Vector] = field(metadata=doc("angular velocity in the principal frame [rad/s]"))
    omega: list[Vector] = field(metadata=doc("angular velocity in the input frame [rad/s]"))
    quaternion: list[Quaternion] = field(metadata=doc("attitude relative to t = 0, [w, x, y, z]"))


@dataclass(frozen=True, slots=True, kw_only=True)
class MotionDiagnosticsSection(Section):
    """``precession.diagnostics``."""

    elapsed_s: float = field(metadata=doc("[s]"))
    energy_drift: float | None = field(default=None, metadata=doc("max |E(t) - E(0)| / E(0) over the trajectory [1]"))
    momentum_drift: float | None = field(default=None, metadata=doc("max |M(t) - M(0)| / |M(0)| over the trajectory [1]"))
    relative_error_estimate: float | None = field(
        default=None,
        metadata=doc("bound on the trajectory's error: omega(t) relative to |omega|, and the attitude quaternion [1]"),
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class PrecessionSection(Section):
    """``precession``: the torque-free motion, only the keys that apply to the regime."""

    regime: Regime = field(metadata=doc())
    angular_momentum: Vector = field(metadata=doc("[kg m^2/s], input frame"))
    angular_momentum_magnitude: float = field(metadata=doc("[kg m^2/s]"))
    kinetic_energy: float = field(metadata=doc("[J]"))
    omega_body: Vector = field(metadata=doc("initial angular velocity, principal frame [rad/s]"))
    body_precession_rate: float | None = field(default=None, metadata=doc("[rad/s]"))
    space_precession_rate: float | None = field(default=None, metadata=doc("[rad/s]"))
    spin_rate: float | None = field(default=None, metadata=doc("[rad/s]"))
    nutation_angle: float | None = field(default=None, metadata=doc("[rad]"))
    period: float | None = field(default=None, metadata=doc("[s]"))
    stable: bool | None = field(default=None, metadata=doc())
    flip_interval: float | None = field(default=None, metadata=doc("[s]"))
    trajectory: TrajectorySection | None = field(default=None, metadata=doc())
    diagnostics: MotionDiagnosticsSection = field(metadata=doc())


@dataclass(frozen=True, slots=True, kw_only=True)
class PartSection(Section):
    """One element of ``parts``: a body of a scene or assembly, in the scene frame."""

    name: str = field(metadata=doc())
    mass: float = field(metadata=doc("[kg]"))
    volume: float | None = field(default=None, metadata=doc("[m^3], solids only"))
    density: float | None = field(default=None, metadata=doc("[kg/m^3], solids of one density"))
    area: float | None = field(default=None, metadata=doc("[m^2], thin shells: the area that carries the mass"))
    center_of_mass: Vector = field(metadata=doc("[m], scene frame"))
    inertia_tensor: Tensor = field(metadata=doc("about the part's own centre of mass [kg m^2]"))
    surface_area: float | None = field(default=None, metadata=doc("[m^2]"))
    principal: PrincipalSection = field(metadata=doc())
    classification: ClassificationSection = field(metadata=doc())
    warnings: list[str] | None = field(default=None, metadata=doc())


@dataclass(frozen=True, slots=True, kw_only=True)
class RotationalConstantsSection(Section):
    """``rotational_constants``: of a molecule, from its principal moments."""

    MHz: list[float] = field(metadata=doc("A >= B >= C [MHz]; B alone for a linear molecule"))
    cm_1: list[float] = field(metadata=doc("A >= B >= C [cm^-1]; B alone for a linear molecule", key="cm-1"))


@dataclass(frozen=True, slots=True, kw_only=True)
class FrameSection(Section):
    """``frame``: the centre of mass and tensors along a named frame's axes."""

    quaternion: Quaternion = field(metadata=doc("[w, x, y, z]: the named frame's axes -> input frame"))
    center_of_mass: Vector = field(metadata=doc("[m], along the named axes, from the input origin or the reference"))
    inertia_tensor: Tensor = field(metadata=doc("about the centre of mass [kg m^2], named-frame axes"))
    reference_inertia: Tensor | None = field(default=None, metadata=doc("about the reference point [kg m^2], named-frame axes"))


@dataclass(frozen=True, slots=True, kw_only=True)
class ExportPartSection(Section):
    """One part's inertial element."""

    name: str = field(metadata=doc())
    text: str = field(metadata=doc())


@dataclass(frozen=True, slots=True, kw_only=True)
class ExportSection(Section):
    """``export``: the inertial element of a robot description format."""

    format: ExportFormat = field(metadata=doc())
    text: str = field(metadata=doc("the format's inertial element, SI units, 17 significant digits"))
    parts: list[ExportPartSection] | None = field(default=None, metadata=doc())


@dataclass(frozen=True, slots=True, kw_only=True)
class AnalysisDocument(Section):
    """One analysis result (API.md); sections appear only when asked for."""

    source: Source = field(metadata=doc())
    mass: float = field(metadata=doc("[kg]"))
    volume: float | None = field(default=None, metadata=doc("[m^3], solids only"))
    density: float | None = field(default=None, metadata=doc("[kg/m^3], solids only"))
    area: float | None = field(default=None, metadata=doc("[m^2], thin shells: the area that carries the mass"))
    center_of_mass: Vector = field(metadata=doc("[m], input frame"))
    inertia_tensor: Tensor = field(metadata=doc("about the centre of mass [kg m^2], input frame"))
    reference_inertia: ReferenceInertiaSection | None = field(default=None, metadata=doc())
    surface_area: float | None = field(default=None, metadata=doc("[m^2], surface meshes and CAD solids"))
    principal: PrincipalSection = field(metadata=doc())
    classification: ClassificationSection = field(metadata=doc())
    rotational_constants: RotationalConstantsSection | None = field(default=None, metadata=doc())
    frame: FrameSection | None = field(default=None, metadata=doc())
    export: ExportSection | None = field(default=None, metadata=doc())
    precession: PrecessionSection | None = field(default=None, metadata=doc())
    parts: list[PartSection] | None = field(default=None, metadata=doc())
    warnings: list[str] = field(metadata=doc())
    diagnostics: Diagnostics = field(metadata=doc())


@dataclass(frozen=True, slots=True, kw_only=True)
class PrecessionDocument(Section):
    """The response of POST /v1/precession."""

    principal: PrincipalSection = field(metadata=doc())
    classification: ClassificationSection = field(metadata=doc())
    precession: PrecessionSection = field(metadata=doc())
    warnings: list[str] = field(metadata=doc())
    diagnostics: Diagnostics = field(metadata=doc())
