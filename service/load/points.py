"""Point masses from records, JSON or CSV."""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from ..body import PointBody
from ..errors import EmptyGeometryError, InvalidParameterError, UnreadableFileError

__all__ = ["points_from_records", "read_points_file"]


def points_from_records(records: Iterable[Mapping[str, Any]], length_scale: float = 1.0) -> PointBody:
    """``[{"mass": m, "position": [x, y, z]}, ...]`` as a ``PointBody``."""
    masses, positions = [], []
    for k, rec in enumerate(records):
        try:
            masses.append(float(rec["mass"]))
            pos = [float(x) for x in rec["position"]]
        except (KeyError, TypeError, ValueError) as exc:
            raise InvalidParameterError(
                f"point {k} needs a numeric 'mass' and a 3-component 'position'", index=k
            ) from exc
        if len(pos) != 3:
            raise InvalidParameterError(f"point {k} position must have 3 components, got {len(pos)}", index=k)
        positions.append(pos)
    if not masses:
        raise EmptyGeometryError("no points were given; send at least one point mass")
    return PointBody(np.array(masses), np.array(positions).reshape(-1, 3), length_scale)


def read_points_file(data: bytes, fmt: str, length_scale: float = 1.0) -> PointBody:
    """A JSON list of records (or ``{"points": [...]}``) or a CSV with columns mass,x,y,z."""
    text = data.decode("utf-8-sig", errors="replace")
    if fmt == "json":
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as exc:
            raise UnreadableFileError(f"the points file is not valid JSON ({exc.msg} at line {exc.lineno})") from exc
        records = doc.get("points") if isinstance(doc, dict) else doc
        if not isinstance(records, list):
            raise UnreadableFileError('the JSON must be a list of points or {"points": [...]}')
        return points_from_records(records, length_scale)
    rows = list(csv.DictReader(io.StringIO(text)))
    if not rows or not {"mass", "x", "y", "z"} <= set(rows[0]):
        raise UnreadableFileError("the CSV needs a header with columns mass,x,y,z and one row per point")
    return points_from_records(
        ({"mass": r["mass"], "position": [r["x"], r["y"], r["z"]]} for r in rows), length_scale
    )
