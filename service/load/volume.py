"""Adapter to meshio for volume meshes (tetrahedra, hexahedra, wedges, pyramids).

Third-party exceptions are translated here; nothing above ``load/`` sees them.
"""

from __future__ import annotations

import os
import tempfile
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..body import Part, VolumeBody
from ..errors import EmptyGeometryError, UnreadableFileError
from .sniff import VOLUME_FORMATS

__all__ = ["read_volume_parts", "TET_SPLITS"]

# Each 3-D cell type split into tetrahedra by node index (VTK/meshio node order).
# Hexahedron: six tetrahedra around the diagonal 0-6; wedge: three; pyramid: two.
TET_SPLITS: dict[str, NDArray[np.int64]] = {
    "tetra": np.array([[0, 1, 2, 3]]),
    "hexahedron": np.array([[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]),
    "wedge": np.array([[0, 1, 2, 3], [1, 2, 3, 4], [2, 3, 4, 5]]),
    "pyramid": np.array([[0, 1, 2, 4], [0, 2, 3, 4]]),
}
_HIGHER_ORDER = {"tetra10": "tetra", "hexahedron20": "hexahedron", "hexahedron27": "hexahedron",
                 "wedge15": "wedge", "wedge18": "wedge", "pyramid13": "pyramid", "pyramid14": "pyramid"}


def read_volume_parts(data: bytes, fmt: str, length_scale: float) -> list[Part]:
    """Parts of a volume mesh: one per block of 3-D cells, split into tetrahedra."""
    import meshio

    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, f"upload.{fmt}")
        with open(path, "wb") as fh:
            fh.write(data)
        try:
            mesh = meshio.read(path, file_format=VOLUME_FORMATS[fmt])
        except Exception as exc:  # meshio raises ReadError, KeyError, ValueError, ...
            raise UnreadableFileError(f"could not read the {fmt.upper()} file: {_short(exc)}", format=fmt) from exc
    points = np.asarray(mesh.points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise UnreadableFileError("the volume mesh has no 3-D points")
    if points.shape[1] == 2:
        raise EmptyGeometryError("the mesh is two-dimensional; a volume needs 3-D cells")
    densities = mesh.cell_data.get("density")
    names = _block_names(mesh)
    parts: list[Part] = []
    for i, block in enumerate(mesh.cells):
        ctype = _HIGHER_ORDER.get(block.type, block.type)
        if ctype not in TET_SPLITS:
            continue
        split = TET_SPLITS[ctype]
        nodes = np.asarray(block.data, dtype=np.int64)[:, : split.max() + 1]
        tets = nodes[:, split].reshape(-1, 4)
        rho = None
        if densities is not None:
            rho = np.repeat(np.asarray(densities[i], dtype=np.float64).reshape(-1), len(split))
        parts.append(Part(names[i], VolumeBody(points, tets, rho, length_scale, names[i])))
    if not parts:
        kinds = ", ".join(sorted({b.type for b in mesh.cells})) or "none"
        raise EmptyGeometryError(
            f"the file has no 3-D cells (found: {kinds}); send tetrahedra, hexahedra, wedges or pyramids, "
            "or a closed surface mesh"
        )
    return parts


def _block_names(mesh: Any) -> list[str]:
    tags = mesh.cell_data.get("gmsh:physical")
    by_tag = {int(v[0]): k for k, v in (mesh.field_data or {}).items()}
    names = []
    for i, block in enumerate(mesh.cells):
        name = f"{block.type}_{i}"
        if tags is not None and len(tags[i]) and np.all(tags[i] == tags[i][0]):
            name = by_tag.get(int(tags[i][0]), name)
        names.append(name)
    return names


def _short(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    return text[:200]
