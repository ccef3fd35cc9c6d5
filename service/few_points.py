"""The whole analysis of a few point masses, straight to its JSON document.

A request of three point masses is a few hundred floating-point operations;
going through the general pipeline (bodies, geometries, sums, the result
model and its serialiser) cost several times the arithmetic in objects and
numpy calls on 3-vectors.  ``few_points_document`` computes the same document
on Python floats from the same kernels: ``refine.refine_few_points`` for the
passes, ``refine.moment_errors`` for the bound, ``conventions`` for the axes and
the quaternion, ``classification.classify_moments`` for the class, and the pipeline's
own warning rules.  Its answer is the general path's, byte for byte
(``tests/test_few_points.py`` compares them on generated point sets).

It answers only the plain case: up to ``SMALL_POINTS`` records that give
their masses, options that add no section (any length unit and tolerance),
and a body that needs no warning of its own (moments zero within rounding,
points on a line or at one place).  Everything else returns None, and the
caller takes the general path, which raises the input's errors as before.
"""

from __future__ import annotations

import math
import time
from dataclasses import fields
from operator import attrgetter
from typing import Any

from .body import few_points_valid
from .classification import classify_moments
from .conventions import LENGTH_UNITS, orient_axes, quaternion_from_matrix
from .mass.points import SMALL_POINTS, pairwise_sum
from .mass.refine import frame_tensor, moment_errors, refine_few_points, zero_point_moments
from .options import AnalysisOptions
from .pipeline import uncertain_class
from .principal import equal_moment_pairs
from .results import radii_of_gyration
from .tolerances import DEFAULT_TOLERANCES, EPS

__all__ = ["few_points_document"]

_FREE = ("units", "tolerance")
"""The options this path applies; every other must have its default (a new option is then never ignored)."""
_DEFAULTS = tuple((f.name, f.default) for f in fields(AnalysisOptions) if f.name not in _FREE)
_FIXED = attrgetter(*(name for name, _ in _DEFAULTS))
_FIXED_DEFAULTS = tuple(default for _, default in _DEFAULTS)


def _plain(options: AnalysisOptions) -> bool:
    return bool(_FIXED(options) == _FIXED_DEFAULTS)


def _number(value: Any) -> float | None:
    """A JSON number as ``load.points`` reads it (a float), or None for anything else."""
    return float(value) if type(value) is float or type(value) is int else None


def _records(records: list[dict[str, Any]]) -> tuple[list[float], list[list[float]]] | None:
    """Masses and positions of records ``{"mass": m, "position": [x, y, z]}`` that ``load.points`` and
    ``body.PointBody`` accept without a word; None for any other record (the general path decides)."""
    masses: list[float] = []
    points: list[list[float]] = []
    for rec in records:
        if type(rec) is not dict or len(rec) != 2:
            return None
        mass, position = _number(rec.get("mass")), rec.get("position")
        if mass is None or type(position) is not list or len(position) != 3:
            return None
        x, y, z = (_number(c) for c in position)
        if x is None or y is None or z is None:
            return None
        masses.append(mass)
        points.append([x, y, z])
    return masses, points


def few_points_document(records: list[dict[str, Any]], options: AnalysisOptions) -> dict[str, Any] | None:
    """``analyze_points(records, options).as_dict()`` for a few plain point masses; None where it does
    not apply (see the module's text)."""
    start = time.perf_counter()
    if not 0 < len(records) <= SMALL_POINTS or not _plain(options):
        return None
    found = _records(records)
    unit = options.units or "m"
    L = LENGTH_UNITS.get(unit)
    if found is None or L is None:
        return None
    masses, points = found
    if not few_points_valid(masses, points, L, pairwise_sum(masses)):
        return None
    tolerances = DEFAULT_TOLERANCES
    refined = refine_few_points(masses, points, tolerances)
    if refined is None:
        return None
    _, m2, diag, total = refined.moments
    values = refined.values
    estimate, errors = moment_errors([abs(m2[0][0]), abs(m2[1][1]), abs(m2[2][2])], diag, len(masses), 1, values)
    if refined.step is not None:
        estimate = max(estimate, refined.step)
    if any(zero_point_moments(values, errors)):
        return None  # a line or a single place: the general path reports those moments as 0, with a warning
    rotation = refined.rotation
    tensor = frame_tensor(rotation, values)
    # the material of point masses: their own masses; lengths scale by L, moments by L^2
    inertia_scale = 1.0 * L**2
    mass = total * (1.0 * L**0)
    com = [x * L for x in refined.com.tolist()]
    moments = [v * inertia_scale for v in values]
    matrix = (tensor * inertia_scale).tolist()
    if not (math.isfinite(mass) and all(map(math.isfinite, com)) and all(math.isfinite(x) for row in matrix for x in row)):
        return None
    estimate = max(float(estimate + 8 * EPS), 0.0)
    # the principal frame (``PrincipalFrame.from_eigen``): ascending moments in a stable order, oriented
    # axes, the quaternion; then the class
    order = sorted(range(3), key=moments.__getitem__)
    ascending = [moments[k] for k in order]
    columns = rotation.T.tolist()  # the axes, in the order of ``values``
    axes = orient_axes([columns[k] for k in order])
    tolerance = options.tolerance
    cls = classify_moments(ascending, axes, tolerance)
    warnings = uncertain_class(cls, estimate)
    classification: dict[str, Any] = {"kind": cls.kind}
    if cls.shape is not None:
        classification["shape"] = cls.shape
    if cls.symmetry_axis is not None:
        classification["symmetry_axis"] = cls.symmetry_axis.tolist()
    if cls.asymmetry is not None:
        classification["asymmetry"] = float(cls.asymmetry)
    classification["planar"] = bool(cls.planar)
    classification["tolerance"] = float(cls.tolerance)
    return {
        "source": {
            "format": "points",
            "kind": "points",
            "units": unit,
            "units_from": "request" if options.units else "default",
            "points": len(masses),
        },
        "mass": float(mass),
        "center_of_mass": com,
        "inertia_tensor": matrix,
        "principal": {
            "moments": ascending,
            "axes": axes.tolist(),
            "quaternion": quaternion_from_matrix(axes.T).tolist(),
            "unique_axes": not equal_moment_pairs(ascending, tolerance),
            **({"radii_of_gyration": radii_of_gyration(ascending, mass)} if mass > 0 else {}),
        },
        "classification": classification,
        "warnings": warnings,
        "diagnostics": {"elapsed_s": time.perf_counter() - start, "relative_error_estimate": estimate},
    }
