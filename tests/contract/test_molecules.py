"""Molecules (API.md 1.1): "Masses are IUPAC standard atomic weights (abridged conventional values)".

The abridged table of CIAAW gives each standard atomic weight to five significant figures
(conventional values for the elements whose weight is an interval). The weights below are
typed from it (CIAAW, "Abridged standard atomic weights", the table of Prohaska et al.,
Pure Appl. Chem. 94, 573, 2022); the unrounded standard weight is named beside each one
whose abridged value differs from it, since those are the ones an implementation reading
a full-precision table gets wrong. Deuterium: AME2020 (Wang et al., Chinese Phys. C 45,
030003, 2021). Constants: CODATA h, c and the dalton, through scipy.constants.
"""

from __future__ import annotations

import math
from typing import Any

import pytest
from fastapi.testclient import TestClient
from scipy.constants import c as SPEED_OF_LIGHT
from scipy.constants import h as PLANCK
from scipy.constants import physical_constants

from tests.contract.helpers import points_ok, post_mesh

DALTON = physical_constants["atomic mass constant"][0]

# abridged weights [u]; in the comment, the full standard atomic weight (CIAAW 2021) where it differs
ABRIDGED = {
    "H": 1.008,
    "He": 4.0026,  # 4.002602
    "C": 12.011,
    "F": 18.998,  # 18.998403162
    "Na": 22.990,  # 22.98976928
    "Al": 26.982,  # 26.9815384
    "P": 30.974,  # 30.973761998
    "Cl": 35.45,
    "V": 50.942,  # 50.9415: the half rounds up
    "Co": 58.933,  # 58.933194
    "I": 126.90,  # 126.90447
    "Yb": 173.05,  # 173.045: the half rounds up
    "Au": 196.97,  # 196.966570
}
DEUTERIUM = 2.01410177784  # AME2020 [u]


def _atom_mass(client: TestClient, element: str) -> float:
    res = points_ok(client, {"points": [{"element": element, "position": [0.0, 0.0, 0.0]}]})
    return float(res["mass"])


@pytest.mark.parametrize("element", sorted(ABRIDGED))
def test_an_element_weighs_its_abridged_standard_atomic_weight(client: TestClient, element: str) -> None:
    assert _atom_mass(client, element) == pytest.approx(ABRIDGED[element] * DALTON, rel=1e-14, abs=0)


def _diatomic_b(m1: float, m2: float, r_angstrom: float) -> tuple[float, float]:
    """B of a rigid diatomic [MHz, cm^-1]: I = mu r^2, B = h / (8 pi^2 I) (Gordy & Cook eq. 2.29)."""
    mu = m1 * m2 / (m1 + m2) * DALTON
    inertia = mu * (r_angstrom * 1e-10) ** 2
    hz = PLANCK / (8 * math.pi**2 * inertia)
    return hz * 1e-6, hz / SPEED_OF_LIGHT / 100


@pytest.mark.parametrize("pair,r", [(("H", "F"), 0.917), (("Na", "Cl"), 2.361), (("I", "Cl"), 2.321)])
def test_rotational_constant_of_a_diatomic_uses_the_abridged_weights(client: TestClient, pair: tuple[str, str], r: float) -> None:
    a, b = pair
    body = {"points": [{"element": a, "position": [0, 0, 0]}, {"element": b, "position": [0, 0, r]}], "units": "angstrom"}
    res = points_ok(client, body)
    mhz, wavenumber = _diatomic_b(ABRIDGED[a], ABRIDGED[b], r)
    assert res["classification"]["kind"] == "linear_rotator"
    assert res["rotational_constants"]["MHz"] == [pytest.approx(mhz, rel=1e-12, abs=0)]
    assert res["rotational_constants"]["cm-1"] == [pytest.approx(wavenumber, rel=1e-12, abs=0)]


def test_an_xyz_file_uses_the_abridged_weights(client: TestClient) -> None:
    r = post_mesh(client, "hf.xyz", b"2\nhydrogen fluoride\nH 0 0 0\nF 0 0 0.917\n")
    assert r.status_code == 200, r.text
    res: dict[str, Any] = r.json()
    assert res["mass"] == pytest.approx((ABRIDGED["H"] + ABRIDGED["F"]) * DALTON, rel=1e-14, abs=0)
    mhz, _ = _diatomic_b(ABRIDGED["H"], ABRIDGED["F"], 0.917)
    assert res["rotational_constants"]["MHz"] == [pytest.approx(mhz, rel=1e-12, abs=0)]


@pytest.mark.parametrize("spelling", ["D", "d", "2H", "2h"])
def test_deuterium_in_any_case_is_2h(client: TestClient, spelling: str) -> None:
    # '"D" is "2H"'; the symbols are read case-insensitively ("o" is O), so "d" is deuterium too
    assert _atom_mass(client, spelling) == pytest.approx(DEUTERIUM * DALTON, rel=1e-14, abs=0)
