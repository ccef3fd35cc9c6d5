"""Every pydantic model of the HTTP API: requests and responses, both strict.

Requests forbid unknown fields and non-finite numbers; their closed sets and
defaults come from ``vocabulary`` and ``AnalysisOptions``. Responses are the
result model's one serialisation (``inertia.results``, ``as_dict``): their
models are generated from the result model's sections (``inertia.sections``),
each forbidding keys it does not name, so a response the service sends is one
the OpenAPI schema describes, and a field added to a section is added to the
schema with it. Sections appear only when present (absent, never null).
Every error status is documented with the envelope and an example.
"""

from __future__ import annotations

import enum
import json
import math
import types
from dataclasses import MISSING, fields
from typing import TYPE_CHECKING, Annotated, Any, Literal, TypeAlias, Union, get_args, get_origin, get_type_hints

from pydantic import BaseModel, ConfigDict, Field, create_model, model_validator

from ..errors import InvalidParameterError, envelope
from ..options import DEFAULT_OPTIONS, AnalysisOptions
from ..sections import AnalysisDocument, PrecessionDocument, PrecessionSection, Section, Size
from ..vocabulary import ExportFormat, Geometry, Isotopes, MassUnit, Model, MotionMethod, values
from .settings import MIN_SAMPLES, max_samples

__all__ = [
    "MeshQuery",
    "PointIn",
    "PointsRequest",
    "PrecessionRequest",
    "AnalysisOut",
    "PrecessionOut",
    "PrecessionResponse",
    "ErrorOut",
    "HealthOut",
    "FormatsOut",
    "UnavailableFormatOut",
    "MAX_SAMPLES",
    "error_responses",
]


def _choice(members: type[enum.Enum]) -> Any:
    """A closed set of ``vocabulary`` as ``Literal`` of its strings: the schema lists them inline, and a value
    outside them is pydantic's ``literal_error`` naming them."""
    return Literal[values(members)]


def _default(name: str) -> Any:
    """The default of an option, from ``AnalysisOptions`` (where every default lives), as the schema shows it."""
    value = getattr(DEFAULT_OPTIONS, name)
    return value.value if isinstance(value, enum.Enum) else value


if TYPE_CHECKING:  # the request models hold the strings; AnalysisOptions validates them into the enums
    Method: TypeAlias = str
    ModelName: TypeAlias = str
    GeometryName: TypeAlias = str
    IsotopesName: TypeAlias = str
    MassUnitName: TypeAlias = str
    ExportName: TypeAlias = str
else:
    Method, ModelName, GeometryName = _choice(MotionMethod), _choice(Model), _choice(Geometry)
    IsotopesName, MassUnitName, ExportName = _choice(Isotopes), _choice(MassUnit), _choice(ExportFormat)

# the most trajectory samples one HTTP response carries (INERTIA_MAX_SAMPLES, default 10000: ~2.3 MB of
# JSON and under a second of compute); longer ones belong to the CLI or the library
MAX_SAMPLES = max_samples()
_SAMPLES = f"number of time samples, {MIN_SAMPLES} to {MAX_SAMPLES} (the server's INERTIA_MAX_SAMPLES)"

# request numbers beyond 1e100 in magnitude are refused: products of a few of them (m r^2,
# I omega^2) would leave float64, and no body in SI units comes near
MAX_MAGNITUDE = 1e100

Real = Annotated[float, Field(ge=-MAX_MAGNITUDE, le=MAX_MAGNITUDE)]
Vector = Annotated[list[float], Field(min_length=3, max_length=3)]
RealVector = Annotated[list[Real], Field(min_length=3, max_length=3)]
RealTensor = Annotated[list[RealVector], Field(min_length=3, max_length=3)]
Tensor = Annotated[list[Vector], Field(min_length=3, max_length=3)]
Quaternion = Annotated[list[float], Field(min_length=4, max_length=4)]


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
        raise InvalidParameterError(f"densities must be a JSON object of finite numbers: {exc}", parameter="densities") from None
    except RecursionError:
        raise InvalidParameterError(
            'densities nests too deeply; send a flat JSON object {"part name": density}', parameter="densities"
        ) from None
    if not isinstance(value, dict) or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value.values()):
        raise InvalidParameterError('densities must be a JSON object {"part name": density in kg/m^3}', parameter="densities")
    return {str(k): float(v) for k, v in value.items()}


class MeshQuery(_Request):
    """Query parameters of /v1/analyze/mesh and /v1/batch."""

    format: str | None = Field(
        None,
        description="file format (stl, obj, ply, off, glb, gltf, 3mf, vtu, vtk, msh, ...); inferred from the file name when absent",
        examples=["stl"],
    )
    units: str | None = Field(
        None, description="length unit of the file: m, cm, mm, um, in, ft, angstrom (default m; angstrom for xyz)", examples=["m"]
    )
    density: float | None = Field(None, gt=0, le=MAX_MAGNITUDE, description="density [kg/m^3] (default 1000); exclusive with mass")
    mass: float | None = Field(None, gt=0, le=MAX_MAGNITUDE, description="total mass [kg]; the density is then derived")
    model: ModelName = Field(
        _default("model"), description="solid (closed surface or volume mesh) or shell (thin surface, needs thickness)"
    )
    thickness: float | None = Field(None, gt=0, le=MAX_MAGNITUDE, description="shell wall thickness [file units]")
    tolerance: float = Field(_default("tolerance"), gt=0, lt=1, description="relative tolerance for equal principal moments")
    reference: str | None = Field(
        None, description="'x,y,z' point [file units]: also report the tensor about it", examples=["0,0,0"]
    )
    omega: str | None = Field(
        None, description="'wx,wy,wz' initial angular velocity [rad/s], input frame: adds precession", examples=["0,0.1,1"]
    )
    duration: float | None = Field(None, gt=0, le=MAX_MAGNITUDE, description="with omega: seconds to predict [s]")
    samples: int | None = Field(None, ge=MIN_SAMPLES, le=MAX_SAMPLES, description=f"with omega: {_SAMPLES}")
    method: Method = Field(_default("method"), description="with omega: exact, dop853, rk45 or splitting")
    densities: str | None = Field(None, description="JSON object: part name -> density [kg/m^3]", examples=['{"bracket": 7850}'])
    geometry: GeometryName = Field(
        _default("geometry"), description="CAD files (STEP, IGES): integrate the exact B-rep (brep) or its tessellation (mesh)"
    )
    deflection: float | None = Field(
        None,
        gt=0,
        lt=1,
        description="with geometry=mesh: chordal deflection relative to the bounding-box diagonal [1] (default 1e-3)",
    )
    export: ExportName | None = Field(None, description="urdf, sdf or mjcf: adds the format's inertial element")
    frame: str | None = Field(
        None,
        description="'w,x,y,z' unit quaternion carrying a named frame's axes into the input frame: adds the frame section",
        examples=["1,0,0,0"],
    )
    isotopes: IsotopesName = Field(
        _default("isotopes"), description="atoms of an XYZ file: standard atomic weights or the most abundant isotope"
    )

    def as_options(self) -> AnalysisOptions:
        return AnalysisOptions(
            format=self.format,
            units=self.units,
            density=self.density,
            mass=self.mass,
            model=self.model,
            thickness=self.thickness,
            tolerance=self.tolerance,
            reference=_triple("reference", self.reference),
            omega=_triple("omega", self.omega),
            duration=self.duration,
            samples=self.samples,
            method=self.method,
            densities=_densities(self.densities),
            export=self.export,
            frame=_quaternion(self.frame),
            isotopes=self.isotopes,
            geometry=self.geometry,
            deflection=self.deflection,
        )


class PointIn(_Request):
    mass: float | None = Field(
        None, gt=0, le=MAX_MAGNITUDE, description="point mass [kg, or u with mass_unit=u]; wins over element"
    )
    element: str | None = Field(None, max_length=8, description="element symbol instead of a mass: 'O', '13C', 'D'", examples=["O"])
    position: RealVector = Field(description="position [units of the request]")

    @model_validator(mode="after")
    def _mass_or_element(self) -> PointIn:
        if self.mass is None and self.element is None:
            raise ValueError("a point needs a mass or an element")
        return self


_POINTS_EXAMPLE: dict[str, Any] = {
    "points": [{"mass": 1.0, "position": [0, 0, 0]}, {"mass": 2.0, "position": [1, 0, 0]}, {"mass": 1.0, "position": [0, 1, 0]}],
    "units": "m",
    "tolerance": _default("tolerance"),
    "reference": [0, 0, 0],
}


class PointsRequest(_Request):
    """Body of /v1/analyze/points. Only ``points`` is required."""

    model_config = ConfigDict(json_schema_extra={"examples": [_POINTS_EXAMPLE]})

    points: list[PointIn] = Field(min_length=1, description="point masses")
    units: str | None = Field(None, description="length unit of the positions: m, cm, mm, um, in, ft, angstrom (default m)")
    mass_unit: MassUnitName = Field(_default("mass_unit"), description="unit of given masses: kg, or u (dalton)")
    isotopes: IsotopesName = Field(
        _default("isotopes"), description="masses of points given by element: standard atomic weights or the most abundant isotope"
    )
    export: ExportName | None = Field(None, description="urdf, sdf or mjcf: adds the format's inertial element")
    frame: Quaternion | None = Field(
        None, description="[w, x, y, z] unit quaternion carrying a named frame's axes into the input frame: adds the frame section"
    )
    tolerance: float = Field(_default("tolerance"), gt=0, lt=1, description="relative tolerance for equal principal moments")
    reference: RealVector | None = Field(None, description="also report the tensor about this point [units]")
    omega: RealVector | None = Field(None, description="initial angular velocity [rad/s]: adds precession")
    duration: float | None = Field(None, gt=0, le=MAX_MAGNITUDE, description="with omega: seconds to predict [s]")
    samples: int | None = Field(None, ge=MIN_SAMPLES, le=MAX_SAMPLES, description=f"with omega: {_SAMPLES}")
    method: Method = Field(_default("method"), description="with omega: exact, dop853, rk45 or splitting")

    def records(self) -> list[dict[str, Any]]:
        return [p.model_dump(exclude_none=True) for p in self.points]

    def as_options(self) -> AnalysisOptions:
        return AnalysisOptions(
            units=self.units,
            tolerance=self.tolerance,
            method=self.method,
            duration=self.duration,
            samples=self.samples,
            mass_unit=self.mass_unit,
            isotopes=self.isotopes,
            export=self.export,
            frame=None if self.frame is None else tuple(self.frame),  # type: ignore[arg-type]
            reference=None if self.reference is None else tuple(self.reference),  # type: ignore[arg-type]
            omega=None if self.omega is None else tuple(self.omega),  # type: ignore[arg-type]
        )


class PrecessionRequest(_Request):
    """Body of /v1/precession: exactly one of inertia_tensor or principal_moments, and omega."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {"principal_moments": [1.0, 1.0, 2.0], "omega": [0.1, 0.0, 1.0], "duration": 10.0, "samples": 5},
                {"inertia_tensor": [[2.0, 0, 0], [0, 3.0, 0], [0, 0, 4.0]], "omega": [1.0, 0.01, 0.0]},
            ]
        }
    )

    inertia_tensor: RealTensor | None = Field(None, description="inertia about the centre of mass [kg m^2]")
    principal_moments: RealVector | None = Field(
        None, description="principal moments [kg m^2]; the input frame is then the principal frame"
    )
    omega: RealVector = Field(description="initial angular velocity [rad/s], input frame")
    tolerance: float = Field(_default("tolerance"), gt=0, lt=1, description="relative tolerance for equal principal moments")
    duration: float | None = Field(None, gt=0, le=MAX_MAGNITUDE, description="seconds to predict [s]")
    samples: int | None = Field(None, ge=MIN_SAMPLES, le=MAX_SAMPLES, description=_SAMPLES)
    method: Method = Field(_default("method"), description="exact, dop853, rk45 or splitting")

    def arguments(self) -> dict[str, Any]:
        return self.model_dump()


# ---- responses ----------------------------------------------------------------------------


class _Out(BaseModel):
    # a key the result model writes and this model does not name is an error, not a silent pass-through
    model_config = ConfigDict(extra="forbid")


# the response models of the result model's sections (``inertia.sections``), generated from their fields:
# the same names, types, descriptions and optional keys; a model per section, named after it
_NAMES: dict[type, str] = {PrecessionDocument: "PrecessionResponse"}
_GENERATED: dict[type, type[BaseModel]] = {}


def response_model(section: type[Section]) -> type[BaseModel]:
    """The pydantic model of a section of the result model: a field per dataclass field (optional where the
    dataclass defaults it to None, since the serialiser leaves such a key out), keyed as the JSON is."""
    model = _GENERATED.get(section)
    if model is None:
        hints = get_type_hints(section, include_extras=True)
        spec: dict[str, Any] = {}
        for f in fields(section):  # type: ignore[arg-type]  # every Section is a dataclass
            required = f.default is MISSING and f.default_factory is MISSING
            description, key = f.metadata.get("description") or None, f.metadata.get("key")
            info = Field(description=description, alias=key) if required else Field(None, description=description, alias=key)
            spec[f.name] = (_pydantic_type(hints[f.name]), info)
        name = _NAMES.get(section) or section.__name__.removesuffix("Section").removesuffix("Document") + "Out"
        summary = (section.__doc__ or "").split("\n\n")[0].strip().replace("``", "") or None
        model = _GENERATED[section] = create_model(name, __base__=_Out, __doc__=summary, **spec)
    return model


def _pydantic_type(hint: Any) -> Any:
    """A section field's type for pydantic: arrays of a ``Size`` get that length, closed sets their strings,
    nested sections their generated models."""
    origin = get_origin(hint)
    if origin is Annotated:
        base, *extras = get_args(hint)
        sizes = [m.n for m in extras if isinstance(m, Size)]
        inner = _pydantic_type(base)
        return Annotated[inner, Field(min_length=sizes[0], max_length=sizes[0])] if sizes else inner
    if origin is Union or origin is types.UnionType:
        return Union[tuple(_pydantic_type(a) for a in get_args(hint))]  # noqa: UP007  (built at run time)
    if origin is list:
        (item,) = get_args(hint)
        return list[_pydantic_type(item)]  # type: ignore[misc]
    if isinstance(hint, type) and issubclass(hint, enum.Enum):
        return _choice(hint)
    if isinstance(hint, type) and issubclass(hint, Section):
        return response_model(hint)
    return hint


AnalysisOut = response_model(AnalysisDocument)
PrecessionResponse = response_model(PrecessionDocument)
PrecessionOut = response_model(PrecessionSection)


class ErrorBody(_Out):
    code: str = Field(description="snake_case error code (API.md)", examples=["invalid_parameter"])
    message: str = Field(description="what went wrong and what to do, one sentence")
    details: dict[str, Any] = Field(description="machine-readable particulars (the parameter, the limit, ...)")


class ErrorOut(_Out):
    """The one error envelope of every status >= 400."""

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
        default_factory=list, description="formats known to the service that this installation cannot read"
    )


# ---- error statuses: the envelope, with what each status means and a real example -----------------


def _example(code: str, message: str, **details: Any) -> dict[str, Any]:
    return envelope(code, message, details)


_ERRORS: dict[int, tuple[str, dict[str, dict[str, Any]]]] = {
    401: (
        "unauthorized: the server requires an API key (INERTIA_API_KEY) and the X-API-Key header is missing or wrong",
        {
            "unauthorized": _example("unauthorized", "missing or wrong API key; send it in the X-API-Key header"),
        },
    ),
    413: (
        "payload_too_large: the request body is larger than INERTIA_MAX_UPLOAD_BYTES, or a file would inflate "
        "past what can be read",
        {
            "payload_too_large": _example(
                "payload_too_large",
                "the request body is larger than the limit of 536870912 bytes; send a "
                "smaller file or raise INERTIA_MAX_UPLOAD_BYTES",
                limit_bytes=536870912,
                content_length=600000000,
            ),
        },
    ),
    415: (
        "unsupported_format: the file's format is not one this service reads (GET /v1/formats), or its reader "
        "needs an extra that is not installed",
        {
            "unsupported_format": _example(
                "unsupported_format",
                "cannot read files ending in .dwg; readable formats are stl, obj, ply, off, "
                "glb, gltf, 3mf, ... (or pass format=... if the name is misleading)",
                format="dwg",
            ),
        },
    ),
    422: (
        "the request or its file cannot be analysed: invalid_parameter (also every schema validation failure), "
        "unreadable_file, empty_geometry, not_watertight, zero_volume, invalid_inertia, ...",
        {
            "invalid_parameter": _example(
                "invalid_parameter",
                "query field 'density': Input should be greater than 0; fix it and send the request again",
                parameter="density",
                errors=[{"loc": ["query", "density"], "msg": "Input should be greater than 0", "type": "greater_than"}],
            ),
            "not_watertight": _example(
                "not_watertight",
                "part 'bracket' is not watertight (4 open edges), so it does not bound a "
                "solid; repair it, or analyse it as a thin surface with model=shell and a thickness",
                open_edges=4,
                part="bracket",
            ),
            "invalid_inertia": _example(
                "invalid_inertia",
                "the body is a linear rotator or a single point (smallest principal moment "
                "0 kg m^2 is zero); a simulator needs three positive moments: give the body some thickness",
                reason="zero_moment",
                format="urdf",
                moments=[0.0, 0.0, 0.0],
            ),
        },
    ),
    500: (
        "internal_error: a bug; the error was logged",
        {
            "internal_error": _example(
                "internal_error",
                "the server failed unexpectedly; the error was logged, please report it with the input that caused it",
            ),
        },
    ),
    503: (
        "timeout (the compute limit INERTIA_TIMEOUT_S passed) or server_busy (every compute process is busy "
        "and the queue is full; see Retry-After)",
        {
            "timeout": _example(
                "timeout",
                "the computation took too long and was stopped (limit 120 s); send a smaller input or raise INERTIA_TIMEOUT_S",
                timeout_s=120.0,
            ),
            "server_busy": _example(
                "server_busy",
                "the server is busy: 4 analyses are running and 64 are waiting; retry after the time in the Retry-After header",
                retry_after_s=5,
                waiting=64,
            ),
        },
    ),
}


def error_responses(*statuses: int) -> dict[int | str, dict[str, Any]]:
    """The OpenAPI ``responses`` of these error statuses: the envelope, a description and real examples."""
    out: dict[int | str, dict[str, Any]] = {}
    for status in statuses:
        description, examples = _ERRORS[status]
        out[status] = {
            "model": ErrorOut,
            "description": description,
            "content": {
                "application/json": {"examples": {name: {"summary": name, "value": value} for name, value in examples.items()}}
            },
        }
        if status == 503:
            out[status]["headers"] = {
                "Retry-After": {"description": "server_busy: seconds to wait before retrying", "schema": {"type": "integer"}}
            }
        if status == 401:
            out[status]["headers"] = {
                "WWW-Authenticate": {"description": "the key goes in the X-API-Key header", "schema": {"type": "string"}}
            }
    return out
