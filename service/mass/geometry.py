"""What the refinement engine integrates: a body's points and cells, with optional per-element weights.

``body_geometry`` turns a body and the model (solid or shell) into a ``Geometry`` of one of four
kinds, each with its own measure: ``"apex"`` (a closed surface as signed tetrahedra with the
origin, volume), ``"tet"`` (a volume mesh, volume), ``"tri"`` (a shell's triangles, area) and
``"points"`` (point masses, count).  The weights are the body's own (cell densities, point
masses) or None; the material rule (``material``) decides what multiplies them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..body import Body, PointBody, VolumeBody
from ..ddouble import rotated
from ..errors import InvalidParameterError
from ..integrals import Sums, point_sums, simplex_sums
from ..solid import FirstPass, oriented_surface
from ..vocabulary import Model
from . import points as small_points

__all__ = ["DIMENSION", "Geometry", "QuadBlock", "body_geometry"]

QuadBlock = tuple[str, NDArray[np.int64], NDArray[np.float64] | None]

DIMENSION = {"apex": 3, "tet": 3, "tri": 2, "points": 0}
"""The length power of each kind's measure: volume, volume, area, a count."""


_OVERFLOW = (
    "the coordinates or masses are so large that the inertia integrals overflow floating point; express the input in other units"
)


class Geometry:
    """Points + cells of one body in a form the passes can re-integrate."""

    def __init__(
        self,
        points: NDArray[np.float64],
        cells: NDArray[np.int64],
        kind: str,
        weight: NDArray[np.float64] | None,
        coordinate_eps: float = 2.0**-53,
        blocks: tuple[QuadBlock, ...] = (),
        first_pass: FirstPass | None = None,
    ) -> None:
        self.points, self.cells, self.kind, self.weight = points, cells, kind, weight
        self.coordinate_eps = coordinate_eps  # unit roundoff of the stored coordinates (float32: 2**-24)
        self.blocks = blocks  # volume cells other than linear tetrahedra: (type, nodes, weight), by quadrature
        self._first = first_pass  # the sums about an origin without rotation, already formed (``solid.oriented_surface``)
        self._small: tuple[list[float], list[list[float]]] | None = None  # a small point set as Python floats

    def small_lists(self) -> tuple[list[float], list[list[float]]]:
        """A point set's masses and points as Python floats (made once)."""
        if self._small is None:
            assert self.weight is not None
            self._small = (self.weight.tolist(), self.points.tolist())
        return self._small

    @property
    def referenced_points(self) -> int:
        return len(self.points)

    @property
    def weighted(self) -> bool:
        """The elements carry their own mass per measure (point masses, cell densities)."""
        return self.weight is not None or any(w is not None for _, _, w in self.blocks)

    def sums(self, origin: NDArray[np.float64], rotation: NDArray[np.float64] | None) -> Sums:
        """The integrals about ``origin`` in the frame ``rotation`` (columns), or raise on overflow."""
        first, self._first = self._first, None  # given once: the first pass
        if first is not None and rotation is None and np.array_equal(origin, first[0]):
            return first[1]
        if self.kind == "points" and len(self.points) <= small_points.SMALL_POINTS:  # the same sums without numpy's overheads
            found = small_points.small_point_sums(*self.small_lists(), origin, rotation)
            if found is None:
                raise InvalidParameterError(_OVERFLOW)
            return found
        try:
            with np.errstate(over="raise", invalid="raise"):
                x = self.points - origin if rotation is None else rotated(self.points, origin, rotation)
                if self.kind == "points":
                    assert self.weight is not None
                    return point_sums(self.weight, x)
                if not self.blocks:
                    return simplex_sums(x, self.cells, self.kind, self.weight)
                return _volume_sums(x, self.cells, self.weight, self.blocks)
        except FloatingPointError as exc:
            raise InvalidParameterError(_OVERFLOW) from exc


def _volume_sums(
    x: NDArray[np.float64], tets: NDArray[np.int64], weight: NDArray[np.float64] | None, blocks: tuple[QuadBlock, ...]
) -> Sums:
    """Linear tetrahedra in closed form plus every other cell by its exact quadrature (``cells``)."""
    from ..cells import cell_sums, combined

    total = simplex_sums(x, tets, "tet", weight) if len(tets) else None
    for name, nodes, w in blocks:
        part = cell_sums(x, name, nodes, w)
        total = part if total is None else combined(total, part)
    assert total is not None
    return total


def body_geometry(body: Body, model: str) -> tuple[Geometry, tuple[str, ...]]:
    """The geometry the passes integrate for ``body`` under ``model``, and warnings about it."""
    if isinstance(body, PointBody):
        return Geometry(body.positions, np.empty((0, 0), np.int64), "points", body.masses), ()
    if isinstance(body, VolumeBody):
        if model == Model.SHELL:
            raise InvalidParameterError("model=shell needs a surface mesh; a volume mesh is always a solid", parameter="model")
        blocks = tuple((b.type, b.nodes, b.density) for b in body.cells)
        return Geometry(body.points, body.tets, "tet", body.cell_density, blocks=blocks), _tangled_warning(body)
    if model == Model.SHELL:
        return Geometry(body.vertices, body.faces, "tri", None), ()
    vertices, faces, warnings, first = oriented_surface(body)
    return Geometry(vertices, faces, "apex", None, body.coordinate_eps, first_pass=first), warnings


def _tangled_warning(body: VolumeBody) -> tuple[str, ...]:
    if not body.cells:
        return ()
    from ..cells import tangled_cells

    count = sum(tangled_cells(body.points, b.type, b.nodes) for b in body.cells)
    if not count:
        return ()
    return (
        f"{count} of {body.cell_count} cells fold over themselves (their Jacobian changes sign); "
        "each was integrated with its signed Jacobian, so a folded region counts negatively: check the mesh",
    )
