"""AnalysisOptions: the options of one analysis, validated once at the edge of the library.

They are the API's query parameters (API.md): lengths in ``units``, density
kg/m^3, mass kg, omega rad/s in the input frame, duration s.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from .conventions import length_scale
from .errors import InvalidParameterError
from .tolerances import DEFAULT_TOLERANCES
from .vocabulary import METHODS, MODELS, ExportFormat, Geometry, Isotopes, MassUnit, Model, MotionMethod, values

_EXPORT_FORMATS, _ISOTOPES, _MASS_UNITS, _GEOMETRIES = (values(e) for e in (ExportFormat, Isotopes, MassUnit, Geometry))

__all__ = ["AnalysisOptions", "METHODS", "DEFAULT_OPTIONS"]


def _vector(name: str, value: Sequence[float] | None) -> tuple[float, float, float] | None:
    if value is None:
        return None
    try:
        vec = tuple(float(x) for x in value)
    except (TypeError, ValueError) as exc:
        raise InvalidParameterError(f"{name} must be three numbers x,y,z", parameter=name) from exc
    if len(vec) != 3:
        raise InvalidParameterError(f"{name} must have 3 components, got {len(vec)}", parameter=name)
    if not all(math.isfinite(x) for x in vec):
        raise InvalidParameterError(f"{name} must be finite (no NaN or infinity)", parameter=name)
    return (vec[0], vec[1], vec[2])


def _positive(name: str, value: float | None) -> None:
    if value is not None and not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise InvalidParameterError(f"{name} must be a positive finite number, got {value!r}", parameter=name)


@dataclass(frozen=True, slots=True)
class AnalysisOptions:
    """Options of one analysis, as in the API's query parameters.

    Lengths (reference, thickness) are in ``units``; density kg/m^3; mass kg;
    omega rad/s in the input frame; duration s.  The closed sets (``vocabulary``)
    may be given as their strings: ``method`` becomes a ``MotionMethod`` and
    ``model`` a ``Model`` once validated.  The defaults here are the API's and the
    command line's (``DEFAULT_OPTIONS``); ``tolerance`` is ``Tolerances.moment_rel``.
    """

    format: str | None = None
    units: str | None = None
    density: float | None = None
    mass: float | None = None
    model: Model | str = Model.SOLID
    thickness: float | None = None
    tolerance: float = DEFAULT_TOLERANCES.moment_rel
    reference: tuple[float, float, float] | None = None
    omega: tuple[float, float, float] | None = None
    duration: float | None = None
    samples: int | None = None
    method: MotionMethod | str = MotionMethod.EXACT
    densities: Mapping[str, float] | None = None
    geometry: str = Geometry.BREP
    deflection: float | None = None
    export: str | None = None
    frame: tuple[float, float, float, float] | None = None
    isotopes: str = Isotopes.STANDARD
    mass_unit: str = MassUnit.KG

    def __post_init__(self) -> None:
        if self.units is not None:
            length_scale(self.units)
        for name in ("density", "mass", "thickness", "duration"):
            _positive(name, getattr(self, name))
        if self.density is not None and self.mass is not None:
            raise InvalidParameterError("give either density or mass, not both", parameter="density")
        if self.model not in MODELS:
            raise InvalidParameterError(f"model must be 'solid' or 'shell', got {self.model!r}", parameter="model")
        if type(self.model) is not Model:
            object.__setattr__(self, "model", Model(self.model))
        if not (isinstance(self.tolerance, (int, float)) and math.isfinite(self.tolerance) and 0 < self.tolerance < 1):
            raise InvalidParameterError("tolerance must be a number between 0 and 1 (relative)", parameter="tolerance")
        if self.reference is not None:
            object.__setattr__(self, "reference", _vector("reference", self.reference))
        if self.omega is not None:
            object.__setattr__(self, "omega", _vector("omega", self.omega))
        if self.samples is not None and (not isinstance(self.samples, int) or self.samples < 1):
            raise InvalidParameterError("samples must be a positive whole number", parameter="samples")
        if (self.duration is None) != (self.samples is None):
            raise InvalidParameterError("duration and samples go together; give both for a trajectory", parameter="samples")
        if self.duration is not None and self.omega is None:
            raise InvalidParameterError("duration and samples need omega", parameter="omega")
        method = self.method.value if isinstance(self.method, MotionMethod) else self.method
        if method not in METHODS:
            raise InvalidParameterError(f"method must be one of {', '.join(METHODS)}", parameter="method")
        if type(self.method) is not MotionMethod:
            object.__setattr__(self, "method", MotionMethod(method))
        if self.densities is not None:
            for name, rho in self.densities.items():
                _positive(f"densities[{name!r}]", rho)
        _check_v11(self)
        _check_geometry(self.geometry, self.deflection)


def _check_v11(options: AnalysisOptions) -> None:
    """The options of API 1.1: export, frame, isotopes, mass_unit."""
    formats = _EXPORT_FORMATS
    if options.export is not None and options.export not in formats:
        raise InvalidParameterError(f"export must be one of {', '.join(formats)}, got {options.export!r}", parameter="export")
    if options.frame is not None:
        from .frames import frame_rotation

        frame_rotation(options.frame)  # refused here if it is no unit quaternion; normalised in the section
        object.__setattr__(options, "frame", tuple(float(v) for v in options.frame))
    if options.isotopes not in _ISOTOPES:
        raise InvalidParameterError(f"isotopes must be 'standard' or 'abundant', got {options.isotopes!r}", parameter="isotopes")
    if options.mass_unit not in _MASS_UNITS:
        raise InvalidParameterError(f"mass_unit must be 'kg' or 'u', got {options.mass_unit!r}", parameter="mass_unit")


def _check_geometry(geometry: str, deflection: float | None) -> None:
    """CAD files: ``geometry`` brep or mesh; ``deflection`` (mesh only) relative to the bounding-box diagonal."""
    if geometry not in _GEOMETRIES:
        raise InvalidParameterError("geometry must be 'brep' or 'mesh'", parameter="geometry")
    if deflection is None:
        return
    _positive("deflection", deflection)
    if not deflection < 1:
        raise InvalidParameterError(
            "deflection is relative to the bounding-box diagonal: give a number below 1", parameter="deflection"
        )
    if geometry != "mesh":
        raise InvalidParameterError("deflection applies to geometry=mesh", parameter="deflection")


# the defaults of every analysis option, for the request schemas and the command line
DEFAULT_OPTIONS = AnalysisOptions()
