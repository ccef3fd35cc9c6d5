"""The optional dependencies of batch runs, imported only when a run needs them."""

from __future__ import annotations

import importlib
import importlib.util
import sys
from types import ModuleType

from ..errors import InvalidParameterError

__all__ = ["ensure_installed", "require"]


def require(module: str, *, purpose: str, extra: str, parameter: str) -> ModuleType:
    """Import ``module`` (e.g. "pyarrow.parquet") and return its top-level package,
    or say which extra to install."""
    top = module.split(".")[0]
    ensure_installed(top, purpose=purpose, extra=extra, parameter=parameter)
    try:
        importlib.import_module(top)  # the package first: a blocked or missing package fails here
        importlib.import_module(module)
    except ImportError as exc:
        raise InvalidParameterError(f"{purpose} needs {top}: pip install 'inertia-service[{extra}]'", parameter=parameter) from exc
    return sys.modules[top]


def ensure_installed(package: str, *, purpose: str, extra: str, parameter: str) -> None:
    """Say which extra to install if ``package`` cannot be found, without importing it (that can wait)."""
    try:
        found = importlib.util.find_spec(package) is not None
    except (ImportError, ValueError):
        found = False
    if not found:
        raise InvalidParameterError(f"{purpose} needs {package}: pip install 'inertia-service[{extra}]'", parameter=parameter)
