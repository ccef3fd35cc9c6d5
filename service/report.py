"""Results as the API's JSON: plain dicts of floats and lists, only the sections present."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .classification import Classification
    from .mass import MassProperties
    from .pipeline import AnalysisResult, PartResult, PrecessionResult
    from .principal import PrincipalFrame

__all__ = ["analysis_dict", "precession_dict", "principal_dict", "classification_dict"]


def _list(arr: Any) -> Any:
    return np.asarray(arr, dtype=np.float64).tolist()


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


def radii_of_gyration(moments: Any, mass: float) -> list[float]:
    """k_i = sqrt(I_i / m) [m] (a zero moment within rounding, e.g. of a rotator, gives 0)."""
    return [math.sqrt(max(float(i), 0.0) / mass) for i in moments]


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
    out["inertia_tensor"] = _list(p.inertia.matrix)
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
    out: dict[str, Any] = {"source": dict(result.source), **_body_dict(p)}
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
            out["export"]["parts"] = [{"name": part.name, "text": part.export.text}
                                      for part in result.parts if part.export is not None]
    out["warnings"] = list(result.warnings)
    out["diagnostics"] = {
        "elapsed_s": float(result.elapsed_s),
        "relative_error_estimate": float(p.relative_error_estimate),
    }
    if result.tessellation_error is not None:
        out["diagnostics"]["tessellation_error"] = float(result.tessellation_error)
    return out


def _v11_dict(result: AnalysisResult) -> dict[str, Any]:
    """rotational_constants, frame and export (API.md, "Additions, version 1.1")."""
    out: dict[str, Any] = {}
    rc = result.rotational_constants
    if rc is not None:
        out["rotational_constants"] = {"MHz": list(rc.mhz), "cm-1": list(rc.wavenumber)}
    nf = result.named_frame
    if nf is not None:
        out["frame"] = {"quaternion": _list(nf.quaternion), "center_of_mass": _list(nf.center_of_mass),
                        "inertia_tensor": _list(nf.inertia_tensor)}
        if nf.reference_inertia is not None:
            out["frame"]["reference_inertia"] = _list(nf.reference_inertia)
    if result.export is not None:
        out["export"] = {"format": result.export.format, "text": result.export.text}
    return out


def precession_dict(result: PrecessionResult) -> dict[str, Any]:
    """The response of POST /v1/precession."""
    out = {
        "principal": principal_dict(result.frame),
        "classification": classification_dict(result.classification),
        "precession": result.motion.as_dict(),
        "warnings": list(result.warnings),
        "diagnostics": {
            "elapsed_s": float(result.elapsed_s),
            "relative_error_estimate": float(result.relative_error_estimate),
        },
    }
    return out
