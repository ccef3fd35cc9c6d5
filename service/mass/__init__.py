"""Mass properties: mass, centre of mass and inertia tensor, exactly.

The stage is cut along its concepts:

- ``properties``: the result types, ``MassProperties`` and ``InertiaTensor``, and the
  parallel-axis theorem;
- ``geometry``: what is integrated, a body's points and cells as one of four kinds (closed
  surface, volume mesh, shell, point masses) with optional per-element weights;
- ``refine``: the multi-pass refinement engine (local origin, passes in the principal frame
  until it settles, the error bound, the refusal of what is not a body);
- ``material``: the material rule, one path for a single body and an assembly (a single body is
  a one-part assembly): ``mass_properties`` and ``assembly_properties``.
"""

from __future__ import annotations

from ..vocabulary import Model
from .material import assembly_properties, mass_properties
from .properties import InertiaTensor, MassProperties, parallel_axis

__all__ = ["InertiaTensor", "MassProperties", "mass_properties", "assembly_properties", "Model", "parallel_axis"]
