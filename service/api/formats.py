"""Which formats this installation can read: a reader whose package is missing is not offered."""

from __future__ import annotations

import importlib.util
from functools import cache

__all__ = ["unavailable_formats", "OPTIONAL_READERS"]

# format -> (module its reader imports, what to install)
OPTIONAL_READERS: dict[str, tuple[str, str]] = {
    "xdmf": ("h5py", "the 'hdf5' extra: pip install 'inertia-service[hdf5]'"),
    "med": ("h5py", "the 'hdf5' extra: pip install 'inertia-service[hdf5]'"),
    "vtk": ("vtkmodules", "the 'vtk' extra: pip install 'inertia-service[vtk]'"),
    "vtu": ("vtkmodules", "the 'vtk' extra: pip install 'inertia-service[vtk]'"),
    "step": ("OCP", "the 'cad' extra: pip install 'inertia-service[cad]'"),
    "iges": ("OCP", "the 'cad' extra: pip install 'inertia-service[cad]'"),
}


@cache
def unavailable_formats() -> dict[str, str]:
    """Formats whose reader cannot be imported here, with what enables each."""
    return {fmt: needs for fmt, (module, needs) in OPTIONAL_READERS.items() if importlib.util.find_spec(module) is None}
