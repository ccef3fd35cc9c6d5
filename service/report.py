"""Results as the API's JSON: plain dicts of floats and lists, only the sections present."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .classify import Classification
    from .mass import MassProperties
    from .pipeline import AnalysisResult, PartResult, PrecessionResult
    from .principal import PrincipalFrame

__all__ = ["analysis_dict", "precession_dict", "principal_dict", "classification_dict"]


def _list(arr: Any) -> Any:
    return np.asarray(arr, dtype=np.float64).tolist()


def principal_dict(frame: PrincipalFrame) -> dict[str, Any]:
    return {
        "moments": _list(frame.moments),
        "axes": _list(frame.axes),
        "quaternion": _list(frame.quaternion),
        "unique_axes": bool(frame.unique_axes),
    }


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
    out["principal"] = principal_dict(part.frame)
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
    out["principal"] = principal_dict(result.frame)
    out["classification"] = classification_dict(result.classification)
    if result.motion is not None:
        out["precession"] = result.motion.as_dict()
    if result.parts is not None:
        out["parts"] = [_part_dict(part) for part in result.parts]
    out["warnings"] = list(result.warnings)
    out["diagnostics"] = {
        "elapsed_s": float(result.elapsed_s),
        "relative_error_estimate": float(p.relative_error_estimate),
    }
    if result.tessellation_error is not None:
        out["diagnostics"]["tessellation_error"] = float(result.tessellation_error)
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
