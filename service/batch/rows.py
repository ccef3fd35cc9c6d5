"""One result row per input file, as a JSON line or as a flat table row.

A row is typed: the analysis result's document (``sections.AnalysisDocument``)
or an :class:`ErrorRow`.  Its JSON line (``as_dict()``) is exactly what
``POST /v1/batch`` streams: the analysis result of the contract, or
``{"source": {"filename": name}, "error": {...}}`` (the envelope) for a file
that failed.  ``source.filename`` is the input's name, the key ``--resume`` uses.

A flat row (CSV, Parquet) has the columns of :data:`COLUMNS`, all SI:
``mass`` kg, ``volume`` m^3 (empty for shells and points), ``com_*`` m, the six
components of the inertia tensor about the centre of mass in the input frame
and the principal moments ``I1 <= I2 <= I3`` in kg m^2, the principal axes
``axis{i}_{x,y,z}`` (unit vectors in the input frame, rows of
``principal.axes``) and the quaternion ``q_w, q_x, q_y, q_z`` that rotates
principal-frame vectors into the input frame.  ``Ixy`` is the (x, y)
element of the tensor, i.e. the product of inertia with its minus sign,
``-integral(x y dm)``.  ``class`` is ``classification.kind``, ``kappa`` Ray's
asymmetry (empty where the contract leaves it out), ``warnings`` joined by
``"; "``, ``error`` ``"<code>: <message>"`` (empty when the analysis worked).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, TypeAlias

from ..errors import ServiceError, envelope
from ..sections import AnalysisDocument

__all__ = ["COLUMNS", "FLOAT_COLUMNS", "ErrorRow", "Row", "error_row", "flat_row", "row_name"]

COLUMNS = (
    "name",
    "format",
    "mass",
    "volume",
    "com_x",
    "com_y",
    "com_z",
    "Ixx",
    "Iyy",
    "Izz",
    "Ixy",
    "Ixz",
    "Iyz",
    "I1",
    "I2",
    "I3",
    "axis1_x",
    "axis1_y",
    "axis1_z",
    "axis2_x",
    "axis2_y",
    "axis2_z",
    "axis3_x",
    "axis3_y",
    "axis3_z",
    "q_w",
    "q_x",
    "q_y",
    "q_z",
    "class",
    "kappa",
    "warnings",
    "error",
)
FLOAT_COLUMNS = frozenset(COLUMNS[2 : COLUMNS.index("class")]) | {"kappa"}
_AXES = tuple(f"axis{i}_{c}" for i in (1, 2, 3) for c in "xyz")

# (column, row, col) of the tensor components, in COLUMNS order
_TENSOR = (("Ixx", 0, 0), ("Iyy", 1, 1), ("Izz", 2, 2), ("Ixy", 0, 1), ("Ixz", 0, 2), ("Iyz", 1, 2))


@dataclass(frozen=True, slots=True)
class ErrorRow:
    """The row of a file that failed: its name and the error of the envelope."""

    name: str
    code: str
    message: str
    details: Mapping[str, Any]

    def as_dict(self) -> dict[str, Any]:
        """The JSON line: the API's error envelope plus the file's name."""
        return {"source": {"filename": self.name}, **envelope(self.code, self.message, self.details)}


Row: TypeAlias = AnalysisDocument | ErrorRow


def error_row(name: str, error: ServiceError) -> ErrorRow:
    """The row of a file that failed; details become plain JSON (they may hold numpy scalars or paths)."""
    details: dict[str, Any] = json.loads(json.dumps(error.details, default=str))
    return ErrorRow(name, error.code, error.message, details)


def row_name(row: dict[str, Any]) -> str:
    """The input name a JSON line belongs to."""
    return str(row["source"]["filename"])


def flat_row(row: Row) -> dict[str, Any]:
    """The CSV/Parquet row of a row; missing values are None."""
    out: dict[str, Any] = dict.fromkeys(COLUMNS)
    if isinstance(row, ErrorRow):
        out["name"] = row.name
        out["error"] = f"{row.code}: {row.message}"
        return out
    out["name"] = row.source.filename
    out["format"] = row.source.format
    out["mass"] = row.mass
    out["volume"] = row.volume
    out["com_x"], out["com_y"], out["com_z"] = row.center_of_mass
    tensor = row.inertia_tensor
    for column, i, j in _TENSOR:
        out[column] = tensor[i][j]
    principal = row.principal
    out["I1"], out["I2"], out["I3"] = principal.moments
    out.update(zip(_AXES, (x for axis in principal.axes for x in axis)))
    out["q_w"], out["q_x"], out["q_y"], out["q_z"] = principal.quaternion
    out["class"] = row.classification.kind.value
    out["kappa"] = row.classification.asymmetry
    out["warnings"] = "; ".join(row.warnings)
    out["error"] = ""
    return out
