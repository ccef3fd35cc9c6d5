"""Bodies as loaded: frozen, validated once, coordinates in the file's length unit.

Coordinates stay exactly as read (float32 STL values widen exactly to
float64); ``length_scale`` (metres per file unit) is applied to the results,
not to the coordinates, so a unit conversion never perturbs the polyhedron.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .arrays import column_bounds
from .errors import EmptyGeometryError, InvalidParameterError

__all__ = ["MeshBody", "VolumeBody", "CellBlock", "PointBody", "BrepBody", "Part", "Body", "few_points_valid", "stored_eps"]


def _frozen(arr: ArrayLike, dtype: type[np.generic]) -> NDArray[Any]:
    out: NDArray[Any] = np.ascontiguousarray(arr, dtype=dtype)
    out.flags.writeable = False
    return out


def _check_finite(name: str, arr: NDArray[np.float64]) -> None:
    if not np.all(np.isfinite(arr)):
        bad = int(np.count_nonzero(~np.isfinite(arr)))
        raise InvalidParameterError(f"{name} contain {bad} non-finite value(s) (NaN or infinity); fix the input", field=name)


def stored_eps(vertices: NDArray[np.float64]) -> float:
    """Unit roundoff of a file's stored coordinates: float32 when every coordinate is a float32 value (binary
    STL, VTK's ``POINTS n float``, ASCII written from float32), else float64 (``MeshBody.coordinate_eps``)."""
    with np.errstate(over="ignore"):  # a value beyond float32's range is no float32: it casts to inf, unequal
        single = vertices.astype(np.float32)
    return 2.0**-24 if bool(np.array_equal(single, vertices)) else 2.0**-53


@dataclass(frozen=True, slots=True)
class MeshBody:
    """A triangle surface.

    vertices : (n, 3) float64, file units.  faces : (m, 3) int64 indices.
    welded : the reader already merged vertices with bit-identical coordinates
        (as ``topology.weld`` does), so the solid path need not weld again.
    coordinate_eps : unit roundoff of the file's coordinate storage: 2**-24 for
        float32 (binary STL), 2**-53 by default; each stored coordinate x may be
        |x| x this from the value the exporter had (``mass`` refuses a body whose
        volume or moments are within what that resolution can change).
    assumed_error : relative bound on how far the mass and moments may be from the
        file's body because of what the reader assumed and a warning names (3MF
        rotations written to few digits, taken as rotations; overlapping pieces
        weighed each in full); it enters the result's error estimate.
    """

    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    length_scale: float = 1.0
    name: str | None = None
    warnings: tuple[str, ...] = ()
    welded: bool = False
    coordinate_eps: float = 2.0**-53
    assumed_error: float = 0.0

    def __post_init__(self) -> None:
        v = _frozen(self.vertices, np.float64)
        f = _frozen(self.faces, np.int64)
        if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3:
            raise ValueError("vertices must be (n, 3) and faces (m, 3)")
        if len(f) == 0 or len(v) == 0:
            raise EmptyGeometryError("the mesh has no triangles; send a file that holds geometry")
        _check_finite("vertex coordinates", v)
        if f.min() < 0 or f.max() >= len(v):
            raise InvalidParameterError("a face refers to a vertex that does not exist; the file is corrupt")
        _check_extent(v)
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "faces", f)


@dataclass(frozen=True, slots=True)
class CellBlock:
    """Cells of one type other than the linear tetrahedron, integrated by ``cells``.

    type : a key of ``cells.CELL_NODES`` (meshio's name; VTK node order).
    nodes : (k, n) int64 point indices.  density : (k,) kg/m^3, or None (uniform).
    """

    type: str
    nodes: NDArray[np.int64]
    density: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        from .cells import CELL_NODES

        nodes = _frozen(self.nodes, np.int64)
        if self.type not in CELL_NODES or nodes.ndim != 2 or nodes.shape[1] != CELL_NODES[self.type]:
            raise ValueError(f"a {self.type} block needs (k, {CELL_NODES.get(self.type, '?')}) node indices")
        object.__setattr__(self, "nodes", nodes)
        if self.density is not None:
            object.__setattr__(self, "density", _densities(self.density, len(nodes)))


def _densities(values: ArrayLike, count: int) -> NDArray[np.float64]:
    rho = _frozen(values, np.float64)
    if rho.shape != (count,):
        raise ValueError("cell densities need one value per cell")
    _check_finite("cell densities", rho)
    if np.any(rho <= 0):
        raise InvalidParameterError("cell densities must be positive (kg/m^3)", field="density")
    return rho


@dataclass(frozen=True, slots=True)
class VolumeBody:
    """Volume cells: linear tetrahedra, and blocks of other cells.

    points : (n, 3) float64, file units.  tets : (k, 4) int64 linear tetrahedra.
    cell_density : (k,) float64 kg/m^3 per tetrahedron, or None (uniform).
    cells : blocks of hexahedra, wedges, pyramids and quadratic cells, each
        integrated as the element it is (``cells``), with its own densities.
    tet_cells : how many of the file's cells ``tets`` stand for, where they
        are polyhedral cells split into tetrahedra (None: one cell each).
    """

    points: NDArray[np.float64]
    tets: NDArray[np.int64]
    cell_density: NDArray[np.float64] | None = None
    length_scale: float = 1.0
    name: str | None = None
    warnings: tuple[str, ...] = ()
    cells: tuple[CellBlock, ...] = ()
    tet_cells: int | None = None

    def __post_init__(self) -> None:
        p = _frozen(self.points, np.float64)
        t = _frozen(self.tets, np.int64).reshape(-1, 4) if np.size(self.tets) == 0 else _frozen(self.tets, np.int64)
        if p.ndim != 2 or p.shape[1] != 3 or t.ndim != 2 or t.shape[1] != 4:
            raise ValueError("points must be (n, 3) and tets (k, 4)")
        if len(t) == 0 and not any(len(b.nodes) for b in self.cells):
            raise EmptyGeometryError("the volume mesh has no 3-D cells; send tetrahedra, hexahedra, wedges or pyramids")
        _check_finite("point coordinates", p)
        for nodes in [t, *(b.nodes for b in self.cells)]:
            if len(nodes) and (nodes.min() < 0 or nodes.max() >= len(p)):
                raise InvalidParameterError("a cell refers to a point that does not exist; the file is corrupt")
        _check_extent(p)
        object.__setattr__(self, "points", p)
        object.__setattr__(self, "tets", t)
        if self.cell_density is not None:
            object.__setattr__(self, "cell_density", _densities(self.cell_density, len(t)))
        weighted = {self.cell_density is not None for _ in t[:1]} | {b.density is not None for b in self.cells if len(b.nodes)}
        if len(weighted) > 1:
            raise ValueError("either every cell carries a density or none does")

    @property
    def weighted(self) -> bool:
        """The cells carry their own densities."""
        return self.cell_density is not None or any(b.density is not None for b in self.cells)

    @property
    def cell_count(self) -> int:
        """The file's 3-D cells this body holds (a polyhedron split into tetrahedra is one)."""
        tets = len(self.tets) if self.tet_cells is None else self.tet_cells
        return tets + sum(len(b.nodes) for b in self.cells)


@dataclass(frozen=True, slots=True)
class PointBody:
    """Point masses.  masses : (n,) kg.  positions : (n, 3), file units."""

    masses: NDArray[np.float64]
    positions: NDArray[np.float64]
    length_scale: float = 1.0
    name: str | None = None
    warnings: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        m = _frozen(self.masses, np.float64)
        x = _frozen(self.positions, np.float64)
        if m.ndim != 1 or x.shape != (len(m), 3):
            raise InvalidParameterError("each point needs a mass and a 3-component position")
        if len(m) == 0:
            raise EmptyGeometryError("no points were given; send at least one point mass")
        if not (len(m) <= _FEW_POINTS and few_points_valid(m.tolist(), x.tolist(), self.length_scale, float(m.sum()))):
            _check_finite("masses", m)
            _check_finite("positions", x)
            if np.any(m <= 0):
                raise InvalidParameterError(
                    f"masses must be positive; {int(np.count_nonzero(m <= 0))} are zero or negative", field="mass"
                )
            _check_span(m, x, self.length_scale)
        object.__setattr__(self, "masses", m)
        object.__setattr__(self, "positions", x)


# Moments of a point set are ~ mass x span^2 [kg m^2]; below float64's smallest normal number over eps they
# lose digits to underflow (subnormals, then 0), so no number with the promised precision can come back.
_MIN_MOMENT_SCALE = float(np.finfo(np.float64).tiny) / float(np.finfo(np.float64).eps)


_FEW_POINTS = 64  # up to this many points the checks run on Python floats (numpy's per-call cost dominates)


def few_points_valid(masses: list[float], positions: list[list[float]], length_scale: float, mass_sum: float) -> bool:
    """True when the checks below would all pass; False sends the body through them (to raise their errors).

    The same comparisons on the same floats: max, min and their difference are exact in both, and
    ``mass_sum`` is numpy's sum of the masses, as in ``_check_span``."""
    if not all(math.isfinite(v) and v > 0 for v in masses) or not all(math.isfinite(c) for p in positions for c in p):
        return False
    span = max(max(column) - min(column) for column in zip(*positions)) * length_scale
    return not (span > 0.0 and mass_sum * span * span < _MIN_MOMENT_SCALE)


def _check_span(masses: NDArray[np.float64], positions: NDArray[np.float64], length_scale: float) -> None:
    """Refuse a point set so small that its moments underflow float64 (a single point is fine: its moments are 0)."""
    lo, hi = column_bounds(positions)
    span = float(np.max(hi - lo)) * length_scale
    if span > 0.0 and float(masses.sum()) * span * span < _MIN_MOMENT_SCALE:
        raise InvalidParameterError(
            f"the points span only {span:.3g} m, so their moments (~ mass x span^2) would underflow float64; "
            "give the positions in a smaller length unit (units) or scale them up",
            field="position",
        )


# A solid's integrals are taken in the file's units and grow as size^5 (the second moments); a part so small
# that size^5 falls below float64's smallest normal number over eps loses its moments to underflow.
_MIN_EXTENT = _MIN_MOMENT_SCALE ** (1 / 5)


def _check_extent(coordinates: NDArray[np.float64]) -> None:
    """Refuse a mesh so small, in its own units, that its moments underflow float64."""
    lo, hi = column_bounds(coordinates)
    extent = float(np.max(hi - lo))
    if 0.0 < extent < _MIN_EXTENT:
        raise InvalidParameterError(
            f"the part is only {extent:.3g} file units across, so its moments (~ size^5) would underflow float64; "
            "export it in a smaller length unit (scaled up) and pass that unit (units)",
            field="coordinates",
        )


Body = MeshBody | VolumeBody | PointBody


@dataclass(frozen=True, slots=True)
class BrepBody:
    """A solid of a CAD file, kept as its exact boundary representation.

    solid : the CAD binding's solid (``inertia.cad.occ.Solid``; opaque here),
        coordinates in the binding's model unit (millimetres), converted from
        the file's own unit.
    length_scale : metres per model unit: 1e-3, times (requested unit) /
        (file unit) when the request overrides the file's unit.
    """

    solid: Any
    length_scale: float = 1.0
    name: str | None = None
    warnings: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class Part:
    """One named body of a scene or assembly, already placed in the scene frame."""

    name: str
    body: Body | BrepBody
    extras: dict[str, object] = field(default_factory=dict)
