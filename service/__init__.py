"""Mass properties, principal frame, top classification and torque-free motion of rigid bodies.

The pipeline: bytes -> ``load_body`` -> ``mass_properties`` -> ``principal_frame``
-> ``classify`` [-> ``predict_motion``], joined by ``analyze``.
"""

from __future__ import annotations

import importlib
import logging
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .classification import Classification, RotorClass, classify
    from .errors import ServiceError
    from .load import Loaded, load_body
    from .mass import InertiaTensor, MassProperties, mass_properties
    from .pipeline import AnalysisOptions, AnalysisResult, analyze, analyze_points, precession
    from .principal import PrincipalFrame, principal_frame
    from .tolerances import Tolerances

# A library's logging goes where its user's configuration sends it (the HTTP service's: uvicorn's); with none,
# Python's last-resort handler would print warnings and their tracebacks on stderr, beside the command's own
# error envelope (logging HOWTO, "Configuring Logging for a Library").
logging.getLogger(__name__).addHandler(logging.NullHandler())

# Names are imported on first use (PEP 562), so ``import inertia`` and the CLI
# start without numpy: ``inertia batch`` starts its workers' forkserver first.
_HOME = {
    "Classification": "classification",
    "RotorClass": "classification",
    "classify": "classification",
    "ServiceError": "errors",
    "Loaded": "load",
    "load_body": "load",
    "InertiaTensor": "mass",
    "MassProperties": "mass",
    "mass_properties": "mass",
    "AnalysisOptions": "pipeline",
    "AnalysisResult": "pipeline",
    "analyze": "pipeline",
    "analyze_points": "pipeline",
    "precession": "pipeline",
    "PrincipalFrame": "principal",
    "principal_frame": "principal",
    "Tolerances": "tolerances",
}


def __getattr__(name: str) -> Any:
    if name == "__version__":  # one source: the distribution's metadata, from pyproject.toml
        from importlib.metadata import PackageNotFoundError, version

        try:
            return version("inertia-service")
        except PackageNotFoundError:  # a checkout that was never installed
            return "0+unknown"
    home = _HOME.get(name)
    if home is None:
        raise AttributeError(f"module 'inertia' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{home}", __name__), name)
    globals()[name] = value
    return value


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
