"""Every pydantic model of the HTTP API: requests (strict) and responses (documented).

Requests forbid unknown fields and non-finite numbers. Responses mirror the
contract (API.md, "The analysis result"); they are built from the pipeline's
``as_dict`` and keep only the sections present (absent, never null).
"""

from __future__ import annotations

import json
import math
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from ..errors import InvalidParameterError
from ..pipeline import METHODS, AnalysisOptions

__all__ = [
    "MeshQuery", "PointIn", "PointsRequest", "PrecessionRequest",
    "AnalysisOut", "PrecessionOut", "PrecessionResponse", "ErrorOut", "HealthOut", "FormatsOut",
    "UnavailableFormatOut",
    "ERROR_RESPONSES",
]

Method = Literal["exact", "dop853", "rk45", "splitting"]
assert set(METHODS) == set(Method.__args__)  # type: ignore[attr-defined]

# a trajectory of this many samples is ~2.3 MB of JSON and under a second of compute;
# longer ones belong to the CLI or the library, not to one HTTP response
MAX_SAMPLES = 10_000

# request numbers beyond 1e100 in magnitude are refused: products of a few of them (m r^2,
# I omega^2) would leave float64, and no body in SI units comes near
MAX_MAGNITUDE = 1e100

Real = Annotated[float, Field(ge=-MAX_MAGNITUDE, le=MAX_MAGNITUDE)]
Vector = Annotated[list[float], Field(min_length=3, max_length=3)]
RealVector = Annotated[list[Real], Field(min_length=3, max_length=3)]
RealTensor = Annotated[list[RealVector], Field(min_length=3, max_length=3)]
Tensor = Annotated[list[Vector], Field(min_length=3, max_length=3)]
Quaternion = Annotated[list[float], Field(min_length=4, max_length=4)]
ExportFormat = Literal["urdf", "sdf", "mjcf"]
Isotopes = Literal["standard", "abundant"]


class _Request(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


def _triple(name: str, text: str | None) -> tuple[float, float, float] | None:
    if text is None:
        return None
    parts = text.replace(" ", "").split(",")
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        raise InvalidParameterError(f"{name} must be three numbers 'x,y,z', got {text!r}", parameter=name) from None
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise InvalidParameterError(f"{name} must be three finite numbers 'x,y,z', got {text!r}", parameter=name)
    return (values[0], values[1], values[2])


def _quaternion(text: str | None) -> tuple[float, float, float, float] | None:
    if text is None:
        return None
    try:
        values = tuple(float(p) for p in text.replace(" ", "").split(","))
    except ValueError:
        raise InvalidParameterError(f"frame must be four numbers 'w,x,y,z', got {text!r}", parameter="frame") from None
    if len(values) != 4 or not all(math.isfinite(v) for v in values):
        raise InvalidParameterError(f"frame must be four finite numbers 'w,x,y,z', got {text!r}", parameter="frame")
    return (values[0], values[1], values[2], values[3])


def _reject_constant(name: str) -> float:
    raise ValueError(f"{name} is not a finite number")


def _densities(text: str | None) -> dict[str, float] | None:
    if text is None:
        return None
    try:
        value = json.loads(text, parse_constant=_reject_constant)
    except ValueError as exc:
        raise InvalidParameterError(f"densities must be a JSON object of finite numbers: {exc}",
                                    parameter="densities") from None
    except RecursionError:
        raise InvalidParameterError('densities nests too deeply; send a flat JSON object {"part name": density}',
                                    parameter="densities") from None
    if not isinstance(value, dict) or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in value.values()):
        raise InvalidParameterError('densities must be a JSON object {"part name": density in kg/m^3}',
                                    parameter="densities")
    return {str(k): float(v) for k, v in value.items()}


class MeshQuery(_Request):
    """Query parameters of /v1/analyze/mesh and /v1/batch."""

    format: str | None = Field(None, description="file format (stl, obj, ply, off, glb, gltf, 3mf, vtu, vtk, msh, "
                               "...); inferred from the file name when absent", examples=["stl"])
    units: str | None = Field(None, description="length unit of the file: m, cm, mm, um, in, ft, angstrom "
                              "(default m; angstrom for xyz)",
                              examples=["m"])
    density: float | None = Field(None, gt=0, le=MAX_MAGNITUDE,
                                  description="density [kg/m^3] (default 1000); exclusive with mass")
    mass: float | None = Field(None, gt=0, le=MAX_MAGNITUDE, description="total mass [kg]; the density is then derived")
    model: Literal["solid", "shell"] = Field("solid", description="solid (closed surface or volume mesh) or "
                                             "shell (thin surface, needs thickness)")
    thickness: float | None = Field(None, gt=0, le=MAX_MAGNITUDE, description="shell wall thickness [file units]")
    tolerance: float = Field(1e-6, gt=0, lt=1, description="relative tolerance for equal principal moments")
    reference: str | None = Field(None, description="'x,y,z' point [file units]: also report the tensor about it",
                                  examples=["0,0,0"])
    omega: str | None = Field(None, description="'wx,wy,wz' initial angular velocity [rad/s], input frame: "
                              "adds precession", examples=["0,0.1,1"])
    duration: float | None = Field(None, gt=0, le=MAX_MAGNITUDE, description="with omega: seconds to predict [s]")
    samples: int | None = Field(None, ge=1, le=MAX_SAMPLES,
                                description="with omega: number of time samples (at most 10000)")
    method: Method = Field("exact", description="with omega: exact, dop853, rk45 or splitting")
    densities: str | None = Field(None, description="JSON object: part name -> density [kg/m^3]",
                                  examples=['{"bracket": 7850}'])
    geometry: Literal["brep", "mesh"] = Field("brep", description="CAD files (STEP, IGES): integrate the exact "
                                              "B-rep (brep) or its tessellation (mesh)")
    deflection: float | None = Field(None, gt=0, lt=1, description="with geometry=mesh: chordal deflection "
                                     "relative to the bounding-box diagonal [1] (default 1e-3)")
    export: ExportFormat | None = Field(None, description="urdf, sdf or mjcf: adds the format's inertial element")
    frame: str | None = Field(None, description="'w,x,y,z' unit quaternion carrying a named frame's axes into the "
                              "input frame: adds the frame section", examples=["1,0,0,0"])
    isotopes: Isotopes = Field("standard", description="atoms of an XYZ file: standard atomic weights or the most "
                               "abundant isotope")

    def as_options(self) -> AnalysisOptions:
        return AnalysisOptions(
            format=self.format, units=self.units, density=self.density, mass=self.mass, model=self.model,
            thickness=self.thickness, tolerance=self.tolerance, reference=_triple("reference", self.reference),
            omega=_triple("omega", self.omega), duration=self.duration, samples=self.samples,
            method=self.method, densities=_densities(self.densities),
            export=self.export, frame=_quaternion(self.frame), isotopes=self.isotopes,
            geometry=self.geometry, deflection=self.deflection)


class PointIn(_Request):
    mass: float | None = Field(None, gt=0, le=MAX_MAGNITUDE, description="point mass [kg, or u with mass_unit=u]; "
                               "wins over element")
    element: str | None = Field(None, max_length=8, description="element symbol instead of a mass: 'O', '13C', 'D'",
                                examples=["O"])
    position: RealVector = Field(description="position [units of the request]")

    @model_validator(mode="after")
    def _mass_or_element(self) -> PointIn:
        if self.mass is None and self.element is None:
            raise ValueError("a point needs a mass or an element")
        return self


_POINTS_EXAMPLE: dict[str, Any] = {
    "points": [{"mass": 1.0, "position": [0, 0, 0]}, {"mass": 2.0, "position": [1, 0, 0]},
               {"mass": 1.0, "position": [0, 1, 0]}],
    "units": "m", "tolerance": 1e-6, "reference": [0, 0, 0],
}


class PointsRequest(_Request):
    """Body of /v1/analyze/points. Only ``points`` is required."""

    model_config = ConfigDict(json_schema_extra={"examples": [_POINTS_EXAMPLE]})

    points: list[PointIn] = Field(min_length=1, description="point masses")
    units: str | None = Field(None, description="length unit of the positions: m, cm, mm, um, in, ft, angstrom "
                              "(default m)")
    mass_unit: Literal["kg", "u"] = Field("kg", description="unit of given masses: kg, or u (dalton)")
    isotopes: Isotopes = Field("standard", description="masses of points given by element: standard atomic weights "
                               "or the most abundant isotope")
    export: ExportFormat | None = Field(None, description="urdf, sdf or mjcf: adds the format's inertial element")
    frame: Quaternion | None = Field(None, description="[w, x, y, z] unit quaternion carrying a named frame's axes "
                                     "into the input frame: adds the frame section")
    tolerance: float = Field(1e-6, gt=0, lt=1, description="relative tolerance for equal principal moments")
    reference: RealVector | None = Field(None, description="also report the tensor about this point [units]")
    omega: RealVector | None = Field(None, description="initial angular velocity [rad/s]: adds precession")
    duration: float | None = Field(None, gt=0, le=MAX_MAGNITUDE, description="with omega: seconds to predict [s]")
    samples: int | None = Field(None, ge=1, le=MAX_SAMPLES,
                                description="with omega: number of time samples (at most 10000)")
    method: Method = Field("exact", description="with omega: exact, dop853, rk45 or splitting")

    def records(self) -> list[dict[str, Any]]:
        return [p.model_dump(exclude_none=True) for p in self.points]

    def as_options(self) -> AnalysisOptions:
        return AnalysisOptions(
            units=self.units, tolerance=self.tolerance, method=self.method, duration=self.duration,
            samples=self.samples, mass_unit=self.mass_unit, isotopes=self.isotopes, export=self.export,
            frame=None if self.frame is None else tuple(self.frame),  # type: ignore[arg-type]
            reference=None if self.reference is None else tuple(self.reference),  # type: ignore[arg-type]
            omega=None if self.omega is None else tuple(self.omega))  # type: ignore[arg-type]


class PrecessionRequest(_Request):
    """Body of /v1/precession: exactly one of inertia_tensor or principal_moments, and omega."""

    model_config = ConfigDict(json_schema_extra={"examples": [
        {"principal_moments": [1.0, 1.0, 2.0], "omega": [0.1, 0.0, 1.0], "duration": 10.0, "samples": 5},
        {"inertia_tensor": [[2.0, 0, 0], [0, 3.0, 0], [0, 0, 4.0]], "omega": [1.0, 0.01, 0.0]},
    ]})

    inertia_tensor: RealTensor | None = Field(None, description="inertia about the centre of mass [kg m^2]")
    principal_moments: RealVector | None = Field(None, description="principal moments [kg m^2]; the input frame "
                                             "is then the principal frame")
    omega: RealVector = Field(description="initial angular velocity [rad/s], input frame")
    tolerance: float = Field(1e-6, gt=0, lt=1, description="relative tolerance for equal principal moments")
    duration: float | None = Field(None, gt=0, le=MAX_MAGNITUDE, description="seconds to predict [s]")
    samples: int | None = Field(None, ge=1, le=MAX_SAMPLES,
                                description="number of time samples (at most 10000)")
    method: Method = Field("exact", description="exact, dop853, rk45 or splitting")

    def arguments(self) -> dict[str, Any]:
        return self.model_dump()


# ---- responses ----------------------------------------------------------------------------


class _Out(BaseModel):
    # the pipeline may add fields (e.g. source.units_from, area); they pass through
    model_config = ConfigDict(extra="allow")

    @classmethod
    def from_result(cls, doc: dict[str, Any]) -> Any:
        return cls.model_validate(doc)


class SourceOut(_Out):
    filename: str | None = None
    format: str
    kind: str = Field(description="mesh, volume, points or cad")
    units: str
    vertices: int | None = None
    triangles: int | None = None
    watertight: bool | None = None


class ReferenceInertiaOut(_Out):
    point: Vector = Field(description="reference point [m], input frame")
    tensor: Tensor = Field(description="inertia about the point [kg m^2]")


class PrincipalOut(_Out):
    moments: Vector = Field(description="ascending principal moments [kg m^2]")
    axes: Tensor = Field(description="rows: unit principal axes in the input frame")
    quaternion: Quaternion = Field(description="[w, x, y, z]: principal frame -> input frame")
    unique_axes: bool
    radii_of_gyration: Vector | None = Field(None, description="k_i = sqrt(I_i / m) [m]")


class ClassificationOut(_Out):
    kind: Literal["spherical_top", "symmetric_top", "asymmetric_top", "linear_rotator"]
    shape: Literal["prolate", "oblate"] | None = None
    symmetry_axis: Vector | None = None
    asymmetry: float | None = Field(None, description="Ray's kappa")
    planar: bool
    tolerance: float


class TrajectoryOut(_Out):
    t: list[float] = Field(description="times [s]")
    omega_body: list[Vector] = Field(description="angular velocity in the principal frame [rad/s]")
    omega: list[Vector] = Field(description="angular velocity in the input frame [rad/s]")
    quaternion: list[Quaternion] = Field(description="attitude relative to t = 0, [w, x, y, z]")


class PrecessionOut(_Out):
    regime: str = Field(description="rest, permanent_rotation, spherical, regular_precession, asymmetric, rotator")
    angular_momentum: Vector | None = Field(None, description="[kg m^2/s], input frame")
    angular_momentum_magnitude: float | None = None
    kinetic_energy: float | None = Field(None, description="[J]")
    omega_body: Vector | None = Field(None, description="initial angular velocity, principal frame [rad/s]")
    body_precession_rate: float | None = Field(None, description="[rad/s]")
    space_precession_rate: float | None = Field(None, description="[rad/s]")
    spin_rate: float | None = Field(None, description="[rad/s]")
    nutation_angle: float | None = Field(None, description="[rad]")
    period: float | None = Field(None, description="[s]")
    stable: bool | None = None
    flip_interval: float | None = Field(None, description="[s]")
    trajectory: TrajectoryOut | None = None
    diagnostics: dict[str, Any] | None = None


class PartOut(_Out):
    name: str
    mass: float
    center_of_mass: Vector
    inertia_tensor: Tensor
    surface_area: float | None = Field(None, description="[m^2]")
    principal: PrincipalOut | None = None
    classification: ClassificationOut | None = None


class RotationalConstantsOut(_Out):
    MHz: list[float] = Field(description="A >= B >= C [MHz]; B alone for a linear molecule")
    cm_1: list[float] = Field(alias="cm-1", description="A >= B >= C [cm^-1]; B alone for a linear molecule")


class FrameOut(_Out):
    quaternion: Quaternion = Field(description="[w, x, y, z]: the named frame's axes -> input frame")
    center_of_mass: Vector = Field(description="[m], along the named axes, from the input origin or the reference")
    inertia_tensor: Tensor = Field(description="about the centre of mass [kg m^2], named-frame axes")
    reference_inertia: Tensor | None = Field(None, description="about the reference point [kg m^2], named-frame axes")


class ExportPartOut(_Out):
    name: str
    text: str


class ExportOut(_Out):
    format: ExportFormat
    text: str = Field(description="the format's inertial element, SI units, 17 significant digits")
    parts: list[ExportPartOut] | None = None


class DiagnosticsOut(_Out):
    elapsed_s: float
    relative_error_estimate: float
    tessellation_error: float | None = Field(None, description="geometry=mesh: largest relative difference of "
                                             "mass and principal moments to the exact B-rep [1]")


class AnalysisOut(_Out):
    """One analysis result (API.md); sections appear only when asked for."""

    source: SourceOut
    mass: float = Field(description="[kg]")
    volume: float | None = Field(None, description="[m^3], solids only")
    density: float | None = Field(None, description="[kg/m^3], solids only")
    center_of_mass: Vector = Field(description="[m], input frame")
    inertia_tensor: Tensor = Field(description="about the centre of mass [kg m^2], input frame")
    reference_inertia: ReferenceInertiaOut | None = None
    surface_area: float | None = Field(None, description="[m^2], surface meshes and CAD solids")
    principal: PrincipalOut
    classification: ClassificationOut
    rotational_constants: RotationalConstantsOut | None = None
    frame: FrameOut | None = None
    export: ExportOut | None = None
    precession: PrecessionOut | None = None
    parts: list[PartOut] | None = None
    warnings: list[str] = []
    diagnostics: DiagnosticsOut


class PrecessionResponse(_Out):
    principal: PrincipalOut
    classification: ClassificationOut
    precession: PrecessionOut
    warnings: list[str] = []
    diagnostics: DiagnosticsOut


class ErrorBody(BaseModel):
    code: str = Field(description="snake_case error code", examples=["not_watertight"])
    message: str = Field(description="what went wrong and what to do")
    details: dict[str, Any] = {}


class ErrorOut(BaseModel):
    error: ErrorBody


class HealthOut(BaseModel):
    status: Literal["ok"]


class FormatOut(BaseModel):
    format: str
    kind: Literal["surface", "volume", "points", "cad"] = Field(description="what the file holds")
    parts: bool = Field(description="whether a file can hold several bodies (scene or assembly)")


class UnavailableFormatOut(BaseModel):
    format: str
    needs: str = Field(description="what to install to read it (an extra of this package, or a package)")


class FormatsOut(BaseModel):
    formats: list[FormatOut]
    surface: list[str] = Field(description="formats of surface meshes")
    volume: list[str] = Field(description="formats of volume meshes (tetrahedra, hexahedra, ...)")
    scene: list[str] = Field(description="formats that can hold several parts")
    points: list[str] = Field(description="formats of point-mass tables")
    cad: list[str] = Field(default_factory=list, description="CAD formats (B-rep solids; the 'cad' extra)")
    unavailable: list[UnavailableFormatOut] = Field(
        default_factory=list, description="formats known to the service that this installation cannot read")


def _error(description: str) -> dict[str, Any]:
    return {"model": ErrorOut, "description": description}


# the error statuses every /v1 endpoint may answer
ERROR_RESPONSES: dict[int | str, dict[str, Any]] = {
    401: _error("unauthorized: the API key is missing or wrong"),
    413: _error("payload_too_large"),
    422: _error("invalid_parameter, invalid_inertia (export of a body a simulator would refuse), "
                "or a file that cannot be analysed"),
    500: _error("internal_error"),
    503: _error("timeout"),
}
