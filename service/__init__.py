"""Mass properties, principal frame, top classification and torque-free motion of rigid bodies.

The pipeline: bytes -> ``load_body`` -> ``mass_properties`` -> ``principal_frame``
-> ``classify`` [-> ``predict_motion``], joined by ``analyze``.
"""

from __future__ import annotations

from .classify import Classification, RotorClass, classify
from .errors import ServiceError
from .load import Loaded, load_body
from .mass import InertiaTensor, MassProperties, mass_properties
from .pipeline import AnalysisOptions, AnalysisResult, analyze, analyze_points, precession
from .principal import PrincipalFrame, principal_frame
from .tolerances import Tolerances

__all__ = [
    "AnalysisOptions",
    "AnalysisResult",
    "Classification",
    "InertiaTensor",
    "Loaded",
    "MassProperties",
    "PrincipalFrame",
    "RotorClass",
    "ServiceError",
    "Tolerances",
    "analyze",
    "analyze_points",
    "classify",
    "load_body",
    "mass_properties",
    "precession",
    "principal_frame",
]
