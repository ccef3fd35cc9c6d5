"""Atomic masses by element symbol, for molecules given as atoms.

Masses come from the ``periodictable`` package (imported here only), whose
tables are, for elements, the IUPAC standard atomic weights (Prohaska et
al., "Standard atomic weights of the elements 2021", Pure Appl. Chem. 94,
2022, as published by CIAAW; conventional values for the elements whose
weight is an interval), and for isotopes the AME2020 atomic masses (Wang et
al., Chinese Phys. C 45, 030003, 2021) with the CIAAW 2021 isotopic
abundances.  A bare symbol weighs the abridged value (API.md: "abridged
conventional values"): the standard atomic weight rounded to five
significant figures, as CIAAW abridges its table (sodium 22.990, not
22.98976928; fluorine 18.998), with halves rounded up as CIAAW writes
them (vanadium 50.9415 -> 50.942).

A symbol may carry a mass number in front (``13C``, ``2H``); ``D`` is ``2H``
and ``T`` is ``3H``.  With ``isotopes="abundant"`` a bare symbol means the
element's most abundant isotope.  Masses are returned in unified atomic mass
units (u, dalton); ``DALTON_KG`` converts them (CODATA, through scipy).
"""

from __future__ import annotations

import re
from functools import cache
from typing import Any

from .errors import InvalidParameterError
from .vocabulary import Isotopes, values

__all__ = ["ABRIDGED_DIGITS", "ISOTOPE_CHOICES", "abridged", "atomic_mass", "dalton_kg", "element_symbol"]

ISOTOPE_CHOICES = values(Isotopes)

# the abridged table's precision: five significant figures (CIAAW, "Abridged standard atomic weights")
ABRIDGED_DIGITS = 5

_SPEC = re.compile(r"^\s*(\d*)\s*([A-Za-z]{1,3})\s*$")
_HYDROGEN_ALIASES = {"D": 2, "T": 3}  # deuterium and tritium, IUPAC-recognised symbols
# elements with a standard atomic weight whose isotopic abundances the table lacks:
# uranium is 99.2742 % 238U in the CIAAW 2021 representative composition
_MOST_ABUNDANT_FALLBACK = {"U": 238}


def dalton_kg() -> float:
    """The unified atomic mass unit [kg] (CODATA value carried by scipy.constants)."""
    from scipy.constants import physical_constants

    return float(physical_constants["atomic mass constant"][0])


def _table() -> Any:
    try:
        import periodictable
    except ImportError as exc:  # pragma: no cover - a core dependency
        raise InvalidParameterError(
            "atoms by element need the 'periodictable' package; pip install periodictable", parameter="element"
        ) from exc
    return periodictable


def element_symbol(spec: str | int) -> str:
    """The element symbol of an atomic number (XYZ files may give numbers) or a symbol."""
    if isinstance(spec, int) or (isinstance(spec, str) and spec.strip().isdigit()):
        number = int(spec)
        table = _table()
        if not 1 <= number <= 118:
            raise InvalidParameterError(f"atomic number {number} is not an element", parameter="element")
        return str(table.elements[number].symbol)
    return spec


@cache
def atomic_mass(spec: str, isotopes: str = Isotopes.STANDARD) -> float:
    """Mass [u] of one atom named ``spec`` ("O", "13C", "D", "2H").

    isotopes : "standard" (standard atomic weight of a bare symbol) or
        "abundant" (its most abundant isotope).  A mass number always wins.
    """
    if isotopes not in ISOTOPE_CHOICES:
        raise InvalidParameterError(f"isotopes must be 'standard' or 'abundant', got {isotopes!r}", parameter="isotopes")
    match = _SPEC.match(spec) if isinstance(spec, str) else None
    if match is None:
        raise InvalidParameterError(f"element {spec!r} is not a symbol such as 'O', '13C' or 'D'", parameter="element")
    number_text, symbol = match.groups()
    mass_number = int(number_text) if number_text else None
    if symbol.upper() in _HYDROGEN_ALIASES:  # "d" as "D", as "o" is "O"
        symbol = symbol.upper()
        if mass_number is not None:
            raise InvalidParameterError(f"element {spec!r}: {symbol} already names an isotope of hydrogen", parameter="element")
        mass_number, symbol = _HYDROGEN_ALIASES[symbol], "H"
    element = _element(symbol, spec)
    if mass_number is not None:
        return _isotope_mass(element, mass_number, spec)
    if isotopes == "abundant":
        return _abundant_mass(element, spec)
    return _standard_weight(element, spec)


def _element(symbol: str, spec: str) -> Any:
    table = _table()
    # symbols are case-sensitive in chemistry ("Co" vs "CO"); "o" or "cl" are read by normalising, but a label
    # in capitals whose first letter is an element itself is ambiguous: PDB's "CA" is an alpha carbon, not
    # calcium, and "NE", "HG", "CD" name nitrogen, hydrogen and carbon atoms of amino acids
    canonical = symbol[0].upper() + symbol[1:].lower()
    element = _lookup(table, canonical)
    if element is None:
        raise InvalidParameterError(f"element {spec!r} is not an element symbol", parameter="element")
    if len(symbol) > 1 and symbol.isupper() and _lookup(table, symbol[0]) is not None:
        raise InvalidParameterError(
            f"element {spec!r} is ambiguous: element symbols are written with one capital ({canonical!r} is "
            f"{element.name}), and labels in capitals often name an atom of element {symbol[0]!r} (PDB's 'CA' is an "
            f"alpha carbon); write {canonical!r} or {symbol[0]!r}",
            parameter="element",
        )
    return element


def _lookup(table: Any, symbol: str) -> Any:
    element = getattr(table, symbol, None)
    return element if element is not None and hasattr(element, "isotopes") and element.number != 0 else None


def _abundances(element: Any) -> dict[int, float]:
    return {int(a): float(element[a].abundance) for a in element.isotopes if float(element[a].abundance) > 0}


def _standard_weight(element: Any, spec: str) -> float:
    # an element with no stable isotope (Tc, Pm, Po, ...) has no standard atomic weight; the
    # table then holds a representative isotope's mass, which would be a silent guess here
    if not _abundances(element) and float(element.mass).is_integer():
        raise InvalidParameterError(
            f"element {spec!r} has no standard atomic weight (no stable isotope); give a mass number such as "
            f"'{int(element.mass)}{element.symbol}' or the mass",
            parameter="element",
        )
    return abridged(float(element.mass))


def abridged(weight: float) -> float:
    """A standard atomic weight abridged to ``ABRIDGED_DIGITS`` significant figures, halves up as CIAAW rounds.

    A weight already written with fewer digits (a conventional value such as 1.008 or 6.94) is unchanged.
    """
    from decimal import ROUND_HALF_UP, Decimal

    exact = Decimal(repr(weight))  # the decimal digits as tabulated, not the binary float's expansion
    step = Decimal(1).scaleb(exact.adjusted() - ABRIDGED_DIGITS + 1)
    rounded = exact.quantize(step, rounding=ROUND_HALF_UP)  # 1.008 -> 1.0080: the same number
    return weight if rounded == exact else float(rounded)


def _abundant_mass(element: Any, spec: str) -> float:
    abundances = _abundances(element)
    if not abundances and element.symbol in _MOST_ABUNDANT_FALLBACK:
        return float(element[_MOST_ABUNDANT_FALLBACK[element.symbol]].mass)
    if not abundances:
        raise InvalidParameterError(
            f"element {spec!r} has no naturally abundant isotope; give a mass number or the mass", parameter="element"
        )
    mass_number = max(abundances, key=lambda a: abundances[a])
    return float(element[mass_number].mass)


def _isotope_mass(element: Any, mass_number: int, spec: str) -> float:
    if mass_number not in element.isotopes:
        known = ", ".join(str(a) for a in element.isotopes)
        raise InvalidParameterError(
            f"isotope {spec!r} is not in the AME2020 table; mass numbers of {element.symbol} are {known}",
            parameter="element",
        )
    return float(element[mass_number].mass)
