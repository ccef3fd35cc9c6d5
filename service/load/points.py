"""Point masses from records, JSON, CSV or XYZ.

A record gives ``mass`` (in ``mass_unit``: kg, or u) or names its ``element``
(``"O"``, ``"13C"``, ``"D"``; masses from ``elements.atomic_mass``); ``mass``
wins when both are given.  XYZ files (atom count, comment line, then
``El x y z`` lines; the de-facto format of chemistry programs such as Open
Babel and ASE) name elements, by symbol or atomic number.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..body import PointBody
from ..errors import EmptyGeometryError, InvalidParameterError, UnreadableFileError, UnsupportedFormatError
from ..vocabulary import Isotopes, MassUnit, values

__all__ = ["MASS_UNITS", "names_elements", "points_from_records", "read_points", "read_points_document", "read_points_file"]

MASS_UNITS = values(MassUnit)


def names_elements(records: Iterable[Mapping[str, Any]]) -> bool:
    """Whether any record names its element (the input is then a molecule)."""
    return any(isinstance(rec, Mapping) and rec.get("element") is not None for rec in records)


def _number(value: Any) -> float:
    """A number, or its text (CSV fields are text); not a boolean, which JSON keeps apart from numbers."""
    if isinstance(value, bool):
        raise TypeError("a boolean is not a number")
    return float(value)


def _sequence(value: Any) -> Any:
    """The components of a position: a list, not a string (whose characters would each read as a number)."""
    if isinstance(value, (str, bytes, Mapping)):
        raise TypeError("a position is a list of numbers")
    return value


def _mass(rec: Mapping[str, Any], k: int, isotopes: str, dalton: float | None) -> float:
    """The record's mass [kg]: its ``mass`` (times ``dalton`` when in u), else its element's."""
    if rec.get("mass") is not None:
        return _number(rec["mass"]) * (dalton if dalton is not None else 1.0)
    if rec.get("element") is None:
        raise KeyError("mass")
    from ..elements import atomic_mass, dalton_kg

    try:
        return atomic_mass(str(rec["element"]), isotopes) * dalton_kg()
    except InvalidParameterError as exc:
        raise InvalidParameterError(f"point {k}: {exc.message}", index=k, **exc.details) from None


def points_from_records(
    records: Iterable[Mapping[str, Any]],
    length_scale: float = 1.0,
    *,
    isotopes: str = Isotopes.STANDARD,
    mass_unit: str = MassUnit.KG,
) -> PointBody:
    """``[{"mass": m, "position": [x, y, z]}, ...]`` (or ``"element"`` for ``mass``) as a ``PointBody``.

    mass_unit : "kg" or "u" for given masses; element masses are always right.
    """
    if mass_unit not in MASS_UNITS:
        raise InvalidParameterError(f"mass_unit must be 'kg' or 'u', got {mass_unit!r}", parameter="mass_unit")
    dalton = None
    if mass_unit == MassUnit.U:
        from ..elements import dalton_kg

        dalton = dalton_kg()
    masses, positions = [], []
    given: list[float] = []  # masses the records give themselves (not their element's)
    for k, rec in enumerate(records):
        try:
            if not isinstance(rec, Mapping):
                raise TypeError
            masses.append(_mass(rec, k, isotopes, dalton))
            if rec.get("mass") is not None:
                given.append(masses[-1])
            pos = [_number(x) for x in _sequence(rec["position"])]
        except OverflowError as exc:  # a JSON integer past a double's range (10^400)
            raise InvalidParameterError(f"point {k} has a number too large for a double (over 1.8e308)", index=k) from exc
        except (KeyError, TypeError, ValueError) as exc:
            raise InvalidParameterError(
                f"point {k} must be an object with a numeric 'mass' (or an 'element') and a 'position' of 3 numbers", index=k
            ) from exc
        if len(pos) != 3:
            raise InvalidParameterError(f"point {k} position must have 3 components, got {len(pos)}", index=k)
        positions.append(pos)
    if not masses:
        raise EmptyGeometryError("no points were given; send at least one point mass")
    body = PointBody(np.array(masses), np.array(positions).reshape(-1, 3), length_scale)
    if given and len(given) < len(masses) and dalton is None and max(given) > _ATOMIC_KG:
        # atoms named by element weigh ~1e-26 kg: a mass of grams or kilograms beside them was meant in dalton
        body = replace(
            body,
            warnings=(
                f"the points mix masses given in kg (the largest {max(given):.4g} kg) with atoms named by their element "
                f"(about 1e-26 kg each), so those atoms weigh next to nothing; if the masses are in dalton (u), pass "
                "mass_unit=u",
            ),
        )
    return body


_ATOMIC_KG = 1e-20
"""Heavier than any atom or molecule a points request describes atom by atom (a dalton is 1.66e-27 kg)."""


def read_points_file(data: bytes, fmt: str, length_scale: float = 1.0, *, isotopes: str = Isotopes.STANDARD) -> PointBody:
    """A JSON list of records (or ``{"points": [...]}``), a CSV with columns mass,x,y,z
    (or element,x,y,z), or an XYZ file."""
    return read_points(data, fmt, length_scale, isotopes=isotopes)[0]


def read_points(data: bytes, fmt: str, length_scale: float = 1.0, *, isotopes: str = Isotopes.STANDARD) -> tuple[PointBody, bool]:
    """The points of a file, and whether it names elements (a molecule: XYZ always does)."""
    body, molecule, _ = read_points_document(data, fmt, length_scale, isotopes=isotopes)
    return body, molecule


def read_points_document(
    data: bytes, fmt: str, length_scale: float = 1.0, *, isotopes: str = Isotopes.STANDARD
) -> tuple[PointBody, bool, str | None]:
    """``read_points``, and the length unit the file declares (a JSON document's ``units``), if any.

    A JSON file may hold the whole document of POST /v1/analyze/points: its ``mass_unit`` applies to
    the masses, its ``units`` is returned for the caller to apply when the request names none, and its
    other keys (options of a request: omega, tolerance, ...) are named in a warning, not applied.
    """
    records, warnings, declared, mass_unit = _file_records(data.decode("utf-8-sig", errors="replace"), fmt)
    body = points_from_records(records, length_scale, isotopes=isotopes, mass_unit=mass_unit)
    if warnings:
        body = replace(body, warnings=body.warnings + tuple(warnings))
    return body, fmt == "xyz" or names_elements(records), declared


# keys of the points document that describe the body itself; the others are options of a request
_BODY_KEYS = ("points", "units", "mass_unit")


def _file_records(text: str, fmt: str) -> tuple[list[Any], list[str], str | None, str]:
    if fmt == "xyz":  # an extended XYZ file's masses column is in u (element masses are always right)
        return (*_xyz_records(text), None, MassUnit.U)
    if fmt == "json":
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as exc:
            raise UnreadableFileError(f"the points file is not valid JSON ({exc.msg} at line {exc.lineno})") from exc
        records = doc.get("points") if isinstance(doc, dict) else doc
        if not isinstance(records, list):
            raise UnreadableFileError('the JSON must be a list of points or {"points": [...]}')
        if not isinstance(doc, dict):
            return records, [], None, MassUnit.KG
        return (records, *_document_keys(doc))
    reader = csv.DictReader(io.StringIO(text, newline=""))  # as the csv module reads files: \r, \n, \r\n end rows
    try:
        rows = list(reader)
        header = set(reader.fieldnames or ())
    except csv.Error as exc:
        raise UnreadableFileError(f"the CSV cannot be read as rows of comma-separated values ({exc})") from exc
    if not {"x", "y", "z"} <= header or not {"mass", "element"} & header:
        raise UnreadableFileError("the CSV needs a header with columns mass,x,y,z (or element,x,y,z) and one row per point")
    if not rows:
        raise EmptyGeometryError("the CSV has its header but no rows; send one row per point mass")
    return (
        [{"mass": r.get("mass") or None, "element": r.get("element") or None, "position": [r["x"], r["y"], r["z"]]} for r in rows],
        [],
        None,
        MassUnit.KG,
    )


def _document_keys(doc: Mapping[str, Any]) -> tuple[list[str], str | None, str]:
    """A points document's declared length unit and mass unit, and a warning naming its request options."""
    from ..conventions import LENGTH_UNITS

    units = doc.get("units")
    mass_unit = MassUnit.KG if doc.get("mass_unit") is None else doc["mass_unit"]
    if units is not None and (not isinstance(units, str) or units not in LENGTH_UNITS):
        known = ", ".join(LENGTH_UNITS)
        raise UnreadableFileError(f"the points file's units {units!r} is not a length unit; use one of {known}")
    if not isinstance(mass_unit, str) or mass_unit not in MASS_UNITS:
        raise UnreadableFileError(f"the points file's mass_unit {mass_unit!r} is not 'kg' or 'u'")
    options = [str(k) for k in doc if k not in _BODY_KEYS]
    warnings = []
    if options:
        warnings.append(
            f"the points file also holds {', '.join(options)}: options of a request, not of the body, and not "
            "applied; give them as options of the analysis"
        )
    return warnings, units, mass_unit


def _xyz_records(text: str) -> tuple[list[Any], list[str]]:
    """Atoms of the first frame of an XYZ file: count line, comment line, ``El x y z`` lines.

    An extended XYZ file (ASE, QUIP, OVITO) says in its comment line which columns hold what
    (``Properties=species:S:1:pos:R:3:...``); its species (or atomic numbers, ``Z``), positions and
    masses, if given, are read from those columns, and a layout without species or positions is refused.
    """
    from ..elements import element_symbol

    # lines end at \n, \r\n or \r only: str.splitlines also splits at form feeds and other
    # separators, which a comment line may hold
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    while lines and not lines[-1].strip():  # the end of the last line is not another line
        lines.pop()
    try:
        count = int(lines[0].split()[0])
    except (IndexError, ValueError):
        raise UnreadableFileError("an XYZ file starts with the number of atoms on its first line") from None
    if count < 1:
        raise EmptyGeometryError(f"the XYZ file's first line gives {count} atoms; send at least one")
    layout = _xyz_layout(lines[1] if len(lines) > 1 else "")
    atoms = lines[2 : 2 + count]
    if len(atoms) < count:
        hint = (
            " (its second line, always a comment in XYZ, holds what looks like an atom: is the comment line missing?)"
            if len(atoms) == count - 1 and len(lines) > 1 and _is_atom_line(lines[1], layout)
            else ""
        )
        raise UnreadableFileError(f"the XYZ file announces {count} atoms but holds {len(atoms)} atom lines{hint}")
    records = []
    for k, line in enumerate(atoms):
        fields = line.split()
        try:
            if len(fields) < layout.width:
                raise ValueError
            record: dict[str, Any] = {
                "element": element_symbol(fields[layout.species]),
                "position": [float(x) for x in fields[layout.pos : layout.pos + 3]],
            }
            if layout.number is not None and _bare(record["element"]) != element_symbol(fields[layout.number]):
                raise UnreadableFileError(
                    f"XYZ line {k + 3} names two elements: species {fields[layout.species]!r} and atomic number "
                    f"{fields[layout.number]!r} (Z); fix the file so that both columns agree",
                    line=k + 3,
                )
            if layout.mass is not None:
                record["mass"] = float(fields[layout.mass])
        except ValueError:
            raise UnreadableFileError(
                f"XYZ line {k + 3} must read {layout.reads}, got {line.strip()[:120]!r}", line=k + 3
            ) from None
        records.append(record)
    warnings = []
    after = [line for line in lines[2 + count :] if line.strip()]
    if after and _is_atom_line(after[0], layout):
        # the next frame would start with its atom count: this is an atom line the first count left out
        raise UnreadableFileError(
            f"the XYZ file announces {count} atoms on its first line but holds more atom lines (line "
            f"{lines.index(after[0], 2 + count) + 1}: {after[0].strip()[:80]!r}); fix the count",
            line=lines.index(after[0], 2 + count) + 1,
        )
    info = _key_values(lines[1]) if len(lines) > 1 else {}
    pbc = info.get("pbc", "T T T" if "Lattice" in info else "")  # ASE: a Lattice without pbc is periodic
    if any(flag in ("T", "t", "True", "true", "1") for flag in pbc.split()):
        said = f"pbc={pbc!r}" if "pbc" in info else "a Lattice without pbc, periodic as ASE reads it"
        warnings.append(
            f"the XYZ file describes a periodic cell ({said}); its {count} atoms were analysed as one isolated "
            "cluster, without their periodic images"
        )
    if after:
        warnings.append(
            f"the XYZ file goes on after its first frame of {count} atoms (a trajectory?); only the first frame was analysed"
        )
    return records, warnings


def _is_atom_line(line: str, layout: _XyzLayout) -> bool:
    """Whether a line reads as an atom of this layout (as many fields, numbers where the position is): not a
    next frame's count line, nor a trailing word such as END."""
    fields = line.split()
    if len(fields) < layout.width:
        return False
    try:
        [float(x) for x in fields[layout.pos : layout.pos + 3]]
    except ValueError:
        return False
    return True


def _bare(symbol: str) -> str:
    """The element of a symbol as an XYZ species column may write it ("13C" -> "C", "D" -> "H", "cl" -> "Cl")."""
    letters = symbol.strip().lstrip("0123456789")
    return "H" if letters.upper() in ("D", "T") else letters.capitalize()


@dataclass(frozen=True, slots=True)
class _XyzLayout:
    """Where an XYZ atom line holds the element, the position and (extended XYZ) the mass [u]."""

    species: int = 0
    pos: int = 1  # the first of three columns
    mass: int | None = None
    width: int = 4
    reads: str = "'element x y z'"
    number: int | None = None  # an atomic-number column (Z) beside the species, which must agree with it


_DELIMITERS = {'"': '"', "'": "'", "{": "}", "[": "]"}


def _key_values(comment: str) -> dict[str, str]:
    """The ``key=value`` pairs of an extended XYZ comment line, as ASE's ``key_val_str_to_dict`` splits them.

    Pairs are separated by white space; a value (or key) may be quoted with double or single quotes or
    bracketed with {} or [], inside which white space and ``=`` are text; a backslash escapes the next
    character; a key without ``=`` stands alone. So ``note="... Properties=..."`` is the key ``note``.
    """
    pairs: list[list[list[str]]] = [[[]]]
    closing: str | None = None
    escaped = False
    quoted = False  # the current key or value opened a quote: it has begun, even if empty ('comment=""')
    for char in comment.strip():
        if escaped:
            pairs[-1][-1].append(char)
            escaped = False
        elif char == "\\":
            escaped = True
        elif closing is not None:
            if char == closing:
                closing = None
            else:
                pairs[-1][-1].append(char)
        elif char in _DELIMITERS:
            closing = _DELIMITERS[char]
            quoted = True
        elif char.isspace():
            if pairs[-1][-1] or quoted:
                pairs.append([[]])
                quoted = False
        elif char == "=":
            if pairs[-1] == [[]] and len(pairs) > 1:  # "key = value": the '=' joins the key before it
                del pairs[-1]
            pairs[-1].append([])
            quoted = False
        else:
            pairs[-1][-1].append(char)
    out = {}
    for pair in pairs:
        if pair and pair[0]:
            out["".join(pair[0])] = "=".join("".join(part) for part in pair[1:]) if len(pair) > 1 else "T"
    return out


def _xyz_layout(comment: str) -> _XyzLayout:
    """The columns of an extended XYZ file's ``Properties`` (name:type:count triples); plain XYZ without one.

    As ASE reads it: the key is ``Properties`` exactly (a comment that merely says "properties = energy"
    is plain XYZ), the masses column is ``masses`` (another column is not a mass), and an atomic-number
    column ``Z`` beside ``species`` must name the same elements.
    """
    spec = _key_values(comment).get("Properties")
    if spec is None:
        return _XyzLayout()
    shown = spec[:120]
    fields = spec.split(":")
    if len(fields) % 3 or not fields[0]:
        raise UnreadableFileError(f"the extended XYZ Properties={shown!r} is not name:type:count triples")
    columns: dict[str, tuple[str, int, int]] = {}
    width = 0
    for name, kind, number in zip(fields[0::3], fields[1::3], fields[2::3]):
        if not number.isdigit() or kind.upper() not in ("S", "R", "I", "L"):
            raise UnreadableFileError(f"the extended XYZ Properties={shown!r} has a bad column {name!r}")
        columns[name] = (kind.upper(), width, int(number))
        width += int(number)
    species = columns.get("species") or columns.get("Z")
    numbers = columns.get("Z") if "species" in columns else None
    pos = columns.get("pos")
    mass = columns.get("masses")
    lacking = []
    if species is None or species[2] != 1:
        lacking.append("an element column ('species:S:1' or 'Z:I:1')")
    if pos is None:
        lacking.append("a position column ('pos:R:3')")
    elif pos[:3:2] != ("R", 3):
        lacking.append(f"positions as three real numbers ('pos:R:3'; it says 'pos:{pos[0]}:{pos[2]}')")
    if lacking:
        raise UnsupportedFormatError(
            f"the extended XYZ file's columns ({shown}) lack {' and '.join(lacking)}; write the file with them",
            format="xyz",
        )
    assert species is not None and pos is not None
    if mass is not None and (mass[0] not in ("R", "I") or mass[2] != 1):
        raise UnreadableFileError(f"the extended XYZ Properties={shown!r} has a masses column that is not one number per atom")
    names = {species[1]: "element", pos[1]: "x y z", **({} if mass is None else {mass[1]: "mass"})}
    if numbers is not None:
        names[numbers[1]] = "atomic number"
    return _XyzLayout(
        species[1],
        pos[1],
        None if mass is None else mass[1],
        width,
        f"{width} columns as its Properties= says ({', '.join(f'{names[c]} in column {c + 1}' for c in sorted(names))})",
        None if numbers is None or numbers[2] != 1 else numbers[1],
    )
