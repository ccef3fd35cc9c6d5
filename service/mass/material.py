"""The material rule: what turns the engine's integrals into kilograms, with one path for bodies and assemblies.

A single body is a one-part assembly.  Every request goes the same way: the parts' geometries are
integrated as one body by the refinement engine (``refine``), in the file's length unit and the
geometry's measure, and then multiplied by one number per SI unit of measure, ``per_measure``:

    mass = m0 * per_measure * L^d          I = I_measure * per_measure * L^(d+2)

with L the length unit in metres and d the measure's length power (3 for a volume, 2 for a shell's
area, 0 for point masses: ``geometry.DIMENSION``).

Where the material sits:
- one part: its uniform material is factored out of the integral (``per_measure`` is the density,
  density x wall for a shell, or the ratio a requested total mass fixes), and elements weigh
  only with their own masses (point masses, cell densities).  Fewer roundings, and a requested
  mass scales the integrals exactly;
- several parts: each element carries its part's density as a weight, so one integration sees
  the whole assembly (an assembly far from the origin keeps the precision a single part has;
  adding part tensors by the parallel-axis theorem would not: their offsets cancel), and
  ``per_measure`` is 1.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..body import Body, MeshBody, PointBody
from ..conventions import DEFAULT_DENSITY
from ..errors import InvalidParameterError
from ..integrals import Sums
from ..tolerances import DEFAULT_TOLERANCES, EPS, Tolerances
from ..vocabulary import MODELS, Model
from .geometry import DIMENSION, Geometry, body_geometry
from .properties import InertiaTensor, MassProperties
from .refine import refine

__all__ = ["Material", "assembly_properties", "mass_properties"]


@dataclass(frozen=True, slots=True)
class Material:
    """What multiplies the integrals of the measure, and what a single body reports about it.

    per_measure : mass per SI unit of the integrated measure (kg/m^3, kg/m^2 for a shell), or a
        pure factor when the elements' weights already carry the mass.
    volume [m^3], density [kg/m^3], area [m^2] : a single part's, where they apply, else None.
    """

    per_measure: float
    volume: float | None = None
    density: float | None = None
    area: float | None = None


def mass_properties(
    body: Body,
    *,
    density: float | None = None,
    mass: float | None = None,
    model: str = Model.SOLID,
    thickness: float | None = None,
    tolerances: Tolerances = DEFAULT_TOLERANCES,
) -> MassProperties:
    """Mass properties of ``body`` about its centre of mass, SI units.

    density : kg/m^3 (solids; default 1000), exclusive with ``mass`` [kg].
    model : "solid" (closed surface or volume mesh) or "shell" (surface of
        wall ``thickness``, in the file's length unit).
    Point bodies carry their own masses; ``mass`` rescales them.
    """
    _check_material(body, density, mass, model, thickness)
    return _properties([(body, density)], model=model, thickness=thickness, mass=mass, tolerances=tolerances)


def assembly_properties(
    parts: Sequence[tuple[Body, float | None]],
    *,
    model: str = Model.SOLID,
    thickness: float | None = None,
    factor: float = 1.0,
    tolerances: Tolerances = DEFAULT_TOLERANCES,
) -> MassProperties:
    """Several bodies of one file integrated as one, each with its own material.

    parts : (body, density) pairs; density in kg/m^3 for a uniform body, None
        for a body that carries its own masses (cell densities, point masses).
    factor : multiplies every density and mass (a requested total mass).

    The whole assembly goes through the same multi-pass integration as one
    body, with per-element weights, so an assembly far from the origin keeps
    the precision a single part has; adding part tensors by the parallel-axis
    theorem would not (their offsets cancel).
    """
    return _properties(parts, model=model, thickness=thickness, factor=factor, tolerances=tolerances)


def _properties(
    parts: Sequence[tuple[Body, float | None]],
    *,
    model: str,
    thickness: float | None,
    tolerances: Tolerances,
    mass: float | None = None,
    factor: float = 1.0,
) -> MassProperties:
    """The one path: integrate the parts as one body, then apply the material rule."""
    scales = {body.length_scale for body, _ in parts}
    if len(scales) != 1:
        raise InvalidParameterError("the parts of one assembly must share a length unit")
    L = scales.pop()
    geometries: list[Geometry] = []
    warnings: list[str] = [w for body, _ in parts for w in body.warnings]
    for body, _ in parts:
        geometry, more = body_geometry(body, model)
        geometries.append(geometry)
        warnings.extend(more)
    single = len(parts) == 1
    densities = [density for _, density in parts]
    whole = geometries[0] if single else _weighted_whole(geometries, densities, model, thickness, L, factor)
    refined = refine(whole, tolerances)
    s, com, tensor = refined.sums, refined.com, refined.tensor
    # several parts: the weights carry every part's density
    material = _one_part(whole, s, L, densities[0], mass, thickness, factor) if single else Material(1.0)
    d = DIMENSION[whole.kind]
    to_mass = material.per_measure * L**d
    inertia_scale = material.per_measure * L ** (d + 2)
    # a requested mass is the body's mass by definition (density x volume would round it by an ulp)
    total_mass = float(mass) if mass is not None and single else s.m0 * to_mass
    _check_finite_results(total_mass, com * L, tensor * inertia_scale)
    return MassProperties(
        mass=float(total_mass),
        center_of_mass=com * L,
        inertia=InertiaTensor(tensor * inertia_scale, "centre_of_mass", com * L),
        principal_moments=refined.moments * inertia_scale,
        principal_axes=refined.axes,
        # what a reader assumed (and a warning names) bounds the error too
        relative_error_estimate=max(float(refined.estimate + 8 * EPS), *(_assumed(body) for body, _ in parts)),
        volume=material.volume,
        density=material.density,
        area=material.area,
        warnings=tuple(warnings) + refined.warnings,
        mesh_vertices=whole.referenced_points if single and whole.kind == "apex" else None,
    )


def _assumed(body: Body) -> float:
    return body.assumed_error if isinstance(body, MeshBody) else 0.0


def _one_part(
    geometry: Geometry,
    s: Sums,
    L: float,
    density: float | None,
    mass: float | None,
    thickness: float | None,
    factor: float,
) -> Material:
    """The material of a single part, factored out of its integrals.

    Elements with their own weights (point masses, cell densities) need only the
    requested total mass's ratio; a uniform body's density is the one given, the
    default, or the one the requested mass fixes over the body's volume (a
    shell's: area x wall).
    """
    d = DIMENSION[geometry.kind]
    if geometry.weighted:
        volume = None if geometry.kind == "points" else float(s.measure * L**d)
        return Material(factor if mass is None else mass / (s.m0 * L**d) * factor, volume=volume)
    if geometry.kind == "tri":
        assert thickness is not None
        area = s.m0 * L**2
        shell_volume = area * thickness * L
        rho = density if density is not None else (DEFAULT_DENSITY if mass is None else mass / shell_volume)
        rho = rho * factor
        return Material(rho * thickness * L, density=float(rho), area=float(area))
    volume = s.m0 * L**3
    rho = density if density is not None else (DEFAULT_DENSITY if mass is None else mass / volume)
    rho = rho * factor
    return Material(rho, volume=float(volume), density=float(rho))


def _weighted_whole(
    geometries: Sequence[Geometry],
    densities: Sequence[float | None],
    model: str,
    thickness: float | None,
    L: float,
    factor: float,
) -> Geometry:
    """Several parts as one geometry whose every element weighs with its part's density (times ``factor``)."""
    weights: list[NDArray[np.float64]] = []
    for geometry, density in zip(geometries, densities):
        weights.append(_element_weights(geometry, density, model, thickness, L) * factor)
        geometry.blocks = tuple(
            (name, nodes, _block_weights(w, len(nodes), density) * factor) for name, nodes, w in geometry.blocks
        )
    kinds = {g.kind for g in geometries}
    if len(kinds) != 1:
        raise InvalidParameterError("an assembly must hold bodies of one kind (all surfaces, all volumes or all points)")
    kind = kinds.pop()
    offsets = np.cumsum([0] + [len(g.points) for g in geometries[:-1]])
    return Geometry(
        np.concatenate([g.points for g in geometries]),
        np.concatenate([g.cells + off for g, off in zip(geometries, offsets)]) if kind != "points" else np.empty((0, 0), np.int64),
        kind,
        np.concatenate(weights),
        max(g.coordinate_eps for g in geometries),
        tuple((name, nodes + off, w) for g, off in zip(geometries, offsets) for name, nodes, w in g.blocks),
    )


def _element_weights(
    geometry: Geometry, density: float | None, model: str, thickness: float | None, L: float
) -> NDArray[np.float64]:
    """Mass per unit of each element's measure (file units): density, density x wall, or the masses."""
    n = len(geometry.points) if geometry.kind == "points" else len(geometry.cells)
    if geometry.weight is not None:  # cell densities or point masses
        return np.asarray(geometry.weight, dtype=np.float64)
    rho = DEFAULT_DENSITY if density is None else density
    if model == Model.SHELL:
        assert thickness is not None
        rho = rho * thickness * L
    return np.full(n, rho)


def _block_weights(weight: NDArray[np.float64] | None, count: int, density: float | None) -> NDArray[np.float64]:
    """Density of each cell of a block: its own, or the part's uniform density."""
    if weight is not None:
        return np.asarray(weight, dtype=np.float64)
    return np.full(count, DEFAULT_DENSITY if density is None else density)


def _check_finite_results(mass: float, com: NDArray[np.float64], tensor: NDArray[np.float64]) -> None:
    """Coordinates or masses near the float64 limits overflow the squares of the integrals."""
    if not (math.isfinite(mass) and np.all(np.isfinite(com)) and np.all(np.isfinite(tensor))):
        raise InvalidParameterError(
            "the coordinates or masses are so large (or so small) that the inertia overflows floating point; "
            "express the input in other units"
        )


def _check_material(body: Body, density: float | None, mass: float | None, model: str, thickness: float | None) -> None:
    if model not in MODELS:
        raise InvalidParameterError(f"unknown model {model!r}; use 'solid' or 'shell'", parameter="model")
    if density is not None and mass is not None:
        raise InvalidParameterError("give either density or mass, not both", parameter="density")
    for name, value in (("density", density), ("mass", mass), ("thickness", thickness)):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise InvalidParameterError(f"{name} must be a positive finite number, got {value!r}", parameter=name)
    if model == Model.SHELL and thickness is None:
        raise InvalidParameterError("model=shell needs a wall thickness (in the file's length unit)", parameter="thickness")
    if model == Model.SOLID and thickness is not None and not isinstance(body, PointBody):
        raise InvalidParameterError("thickness applies only to model=shell", parameter="thickness")
    if isinstance(body, PointBody) and density is not None:
        raise InvalidParameterError("point masses carry their own masses; density does not apply", parameter="density")
