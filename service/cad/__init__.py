"""CAD files (STEP, IGES): exact B-rep mass properties, or a tessellation of them.

    bytes -> occ.read_solids -> BrepBody parts -> brep_mass_properties       (geometry=brep)
                                               -> tessellated -> MeshBody parts  (geometry=mesh)

The OpenCASCADE binding (``OCP``, installed by the ``cad`` extra) is imported
only in ``occ``, and only when a CAD file is read; without it a CAD file gets
``unsupported_format`` naming the extra.

References: OpenCASCADE, ``BRepGProp`` (adaptive Gauss integration of the
volume integrals over the exact faces by the divergence theorem) and
``BRepMesh_IncrementalMesh`` (tessellation at a chordal deflection);
Landau & Lifshitz §32 for the tensor and its parallel-axis shift.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..body import BrepBody, MeshBody, Part
from ..conventions import DEFAULT_DENSITY
from ..errors import InvalidParameterError
from ..surface import SURFACE_AREA_KEY
from ..tolerances import EPS
from ..vocabulary import Model
from .read import CAD_FORMATS, DEFAULT_DEFLECTION, GEOMETRIES, read_cad_parts

if TYPE_CHECKING:
    from ..load import Loaded
    from ..mass import MassProperties

__all__ = [
    "CAD_FORMATS",
    "GEOMETRIES",
    "DEFAULT_DEFLECTION",
    "read_cad_parts",
    "brep_mass_properties",
    "combined_properties",
    "tessellated",
    "tessellation_error",
    "source_counts",
]


def brep_mass_properties(
    body: BrepBody, *, density: float | None = None, mass: float | None = None, model: str = Model.SOLID
) -> MassProperties:
    """Mass properties of one B-rep solid, SI units; density kg/m^3 (default 1000) or a total ``mass`` kg."""
    from ..eigen import jacobi_eigh
    from ..mass import InertiaTensor, MassProperties
    from . import occ

    if model != Model.SOLID:
        raise InvalidParameterError(
            "a CAD solid is integrated as a solid; model=shell applies to surface meshes", parameter="model"
        )
    integral = occ.integrate(body.solid)
    L = body.length_scale
    volume = integral.volume * L**3
    rho = density if density is not None else (DEFAULT_DENSITY if mass is None else mass / volume)
    tensor = integral.tensor * (rho * L**5)
    moments, axes = jacobi_eigh(tensor)
    com = integral.center * L
    return MassProperties(
        mass=float(rho * volume),
        center_of_mass=com,
        inertia=InertiaTensor(tensor, "centre_of_mass", com),
        principal_moments=moments,
        principal_axes=axes,
        relative_error_estimate=float(integral.estimate),
        volume=float(volume),
        density=float(rho),
        warnings=body.warnings + integral.warnings,
    )


def combined_properties(parts: Sequence[MassProperties]) -> MassProperties:
    """Several solids as one body: masses add, tensors move to the common centre (L&L eq. 32.12).

    Error estimate: each part's tensor is off by at most its estimate times
    its trace; the sum's eigenvalues move by at most the sum of those
    (Weyl), taken relative to the smallest principal moment of the whole.
    """
    from ..eigen import jacobi_eigh
    from ..mass import InertiaTensor, MassProperties, parallel_axis

    total = sum(p.mass for p in parts)
    com = sum((p.mass * p.center_of_mass for p in parts), np.zeros(3)) / total
    tensor = sum((parallel_axis(p.inertia.matrix, p.mass, p.center_of_mass - com) for p in parts), np.zeros((3, 3)))
    tensor = 0.5 * (tensor + tensor.T)
    moments, axes = jacobi_eigh(tensor)
    smallest = float(np.min(moments))
    spread = sum(p.relative_error_estimate * float(np.trace(p.inertia.matrix)) for p in parts)
    estimate = spread / smallest if smallest > 0 else math.inf
    volumes = [p.volume for p in parts]
    densities = {p.density for p in parts}
    return MassProperties(
        mass=float(total),
        center_of_mass=com,
        inertia=InertiaTensor(tensor, "centre_of_mass", com),
        principal_moments=moments,
        principal_axes=axes,
        relative_error_estimate=float(max(estimate, *(p.relative_error_estimate for p in parts)) + 8 * EPS),
        volume=None if None in volumes else float(sum(v for v in volumes if v is not None)),
        density=densities.pop() if len(densities) == 1 and None not in densities else None,
        warnings=tuple(w for p in parts for w in p.warnings),
    )


def tessellated(loaded: Loaded, deflection: float) -> Loaded:
    """The same CAD parts as closed triangle surfaces, chordal deflection ``deflection`` x each part's diagonal."""
    from dataclasses import replace

    from . import occ

    parts = []
    for part in loaded.parts:
        body = part.body
        if isinstance(body, MeshBody):  # a solid of triangles alone (read.py): already its tessellation
            parts.append(part)
            continue
        assert isinstance(body, BrepBody)
        vertices, faces = occ.tessellate(body.solid, deflection)
        # coordinates stay in the model unit as read; length_scale turns them into metres, as for the B-rep
        extras = {k: v for k, v in part.extras.items() if k != SURFACE_AREA_KEY}  # the triangles' own area
        parts.append(Part(part.name, MeshBody(vertices, faces, body.length_scale, part.name), extras))
    return replace(loaded, parts=tuple(parts))


def tessellation_error(exact: MassProperties, approx: MassProperties) -> float:
    """Largest relative difference of mass and principal moments (each sorted ascending)."""
    m = abs(approx.mass - exact.mass) / exact.mass
    a, b = np.sort(approx.principal_moments), np.sort(exact.principal_moments)
    return float(max(m, float(np.max(np.abs(a - b) / np.abs(b)))))


def source_counts(loaded: Loaded, geometry: str, deflection: float | None) -> dict[str, object]:
    """The CAD part of ``source``: solids, and triangles of a tessellation."""
    out: dict[str, object] = {"geometry": geometry, "solids": len(loaded.parts), "watertight": True}
    meshes = [p.body for p in loaded.parts if isinstance(p.body, MeshBody)]
    if meshes:
        out["deflection"] = deflection
        out["vertices"] = int(sum(len(b.vertices) for b in meshes))
        out["triangles"] = int(sum(len(b.faces) for b in meshes))
    return out
