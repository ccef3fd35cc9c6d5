"""Molecules (API.md 1.1, "Molecules"): atoms by element, XYZ files, rotational constants.

Expected values come from outside the code under test:

* atomic masses typed here from their sources: IUPAC/CIAAW abridged standard
  atomic weights 2021 (Prohaska et al., Pure Appl. Chem. 94, 573, 2022) and
  AME2020 isotope masses (Wang et al., Chinese Phys. C 45, 030003, 2021);
* the moments of inertia and constants recomputed here with numpy from those
  masses and the CODATA h and c (scipy.constants), A = h / (8 pi^2 I);
* the geometries and published constants of NIST CCCBDB (Computational
  Chemistry Comparison and Benchmark DataBase, release 22, "Listing of
  experimental geometry data", cccbdb.nist.gov/expgeom2x.asp?casno=...),
  each cited at its molecule.

The published ground-state constants (B0) are not those of a rigid
equilibrium geometry: vibration-rotation interaction and the inertial defect
separate them by up to a few per cent (water's re geometry gives A = 27.38
cm^-1 against A0 = 27.877).  The comparison with those tables is therefore a
consistency check at the size of that effect, stated per molecule; the
precision checks are against the independent recomputation.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.constants import c as SPEED_OF_LIGHT
from scipy.constants import h as PLANCK
from scipy.constants import physical_constants

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    from fastapi.testclient import TestClient

ROOT = Path(__file__).resolve().parents[1]
DALTON = physical_constants["atomic mass constant"][0]

# IUPAC 2021 abridged standard atomic weights [u]
STANDARD = {"H": 1.008, "C": 12.011, "N": 14.007, "O": 15.999}
# AME2020 atomic masses of the most abundant isotopes [u] (12C is 12 by definition)
ABUNDANT = {"H": 1.00782503224, "C": 12.0, "N": 14.00307400425, "O": 15.99491461926}
DEUTERIUM, CARBON13 = 2.01410177784, 13.00335483534  # AME2020 [u]
REL_MASS = 1e-9  # isotope masses as tabulated agree to this (rounding of the published digits)


@pytest.fixture(scope="module")
def client() -> Any:
    from inertia.app import app

    with TestClient(app) as c:
        yield c


def _deg(a: float) -> float:
    return math.radians(a)


def water(r: float = 0.958, angle: float = 104.4776) -> list[tuple[str, list[float]]]:
    """H2O, C2v, from rOH and aHOH (CCCBDB: re 0.958 A, 104.4776 deg, Hoy & Bunker 1979)."""
    y, z = r * math.sin(_deg(angle) / 2), r * math.cos(_deg(angle) / 2)
    return [("O", [0, 0, 0]), ("H", [0, y, z]), ("H", [0, -y, z])]


def ammonia(r: float = 1.012, angle: float = 106.67) -> list[tuple[str, list[float]]]:
    """NH3, C3v, from rNH and aHNH (CCCBDB: 1.012 A, 106.67 deg, Herzberg 1966)."""
    hh = 2 * r * math.sin(_deg(angle) / 2)
    rho = hh / math.sqrt(3)
    h = math.sqrt(r * r - rho * rho)
    nitrogen: list[tuple[str, list[float]]] = [("N", [0, 0, 0])]
    return nitrogen + [("H", [rho * math.cos(k * 2 * math.pi / 3), rho * math.sin(k * 2 * math.pi / 3), -h]) for k in range(3)]


def methane(r: float = 1.087) -> list[tuple[str, list[float]]]:
    """CH4, Td: hydrogens on alternate corners of a cube (rCH 1.087 A)."""
    s = r / math.sqrt(3)
    carbon: list[tuple[str, list[float]]] = [("C", [0, 0, 0])]
    return carbon + [("H", [s * a, s * b, s * a * b]) for a in (1, -1) for b in (1, -1)]


def formaldehyde(rch: float = 1.111, rco: float = 1.205, hch: float = 116.133) -> list[tuple[str, list[float]]]:
    """H2CO, C2v (CCCBDB: rCH 1.111, rCO 1.205 A, aHCH 116.133 deg, Gurvich)."""
    y, z = rch * math.sin(_deg(hch) / 2), -rch * math.cos(_deg(hch) / 2)
    return [("O", [0, 0, rco]), ("C", [0, 0, 0]), ("H", [0, y, z]), ("H", [0, -y, z])]


def carbon_dioxide(r: float = 1.162) -> list[tuple[str, list[float]]]:
    """CO2, linear, D-inf-h (rCO 1.162 A, the commonly quoted ground-state r0 distance)."""
    return [("O", [0, 0, -r]), ("C", [0, 0, 0]), ("O", [0, 0, r])]


def benzene(rcc: float = 1.3914, rch: float = 1.0802) -> list[tuple[str, list[float]]]:
    """C6H6, D6h (re(CC) 1.3914, re(CH) 1.0802 A: Gauss & Stanton, J. Phys. Chem. A 104, 2865, 2000)."""
    ring = [(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(6)]
    return [("C", [rcc * x, rcc * y, 0.0]) for x, y in ring] + [("H", [(rcc + rch) * x, (rcc + rch) * y, 0.0]) for x, y in ring]


def _points(atoms: list[tuple[str, list[float]]]) -> list[dict[str, Any]]:
    return [{"element": e, "position": p} for e, p in atoms]


def _constants(atoms: list[tuple[str, list[float]]], masses: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """Independent recomputation: principal moments [kg m^2] and A >= B >= C [MHz]."""
    m = np.array([masses[e] for e, _ in atoms]) * DALTON
    x = np.array([p for _, p in atoms], dtype=float) * 1e-10
    x = x - (m[:, None] * x).sum(axis=0) / m.sum()
    tensor = sum(mi * (np.dot(xi, xi) * np.eye(3) - np.outer(xi, xi)) for mi, xi in zip(m, x))
    moments = np.sort(np.linalg.eigvalsh(tensor))
    with np.errstate(divide="ignore"):
        mhz = PLANCK / (8 * math.pi**2 * moments) * 1e-6
    return moments, mhz


MOLECULES = {
    # name: (geometry, expected kind, shape, published ground-state constants [cm^-1], relative gap to them)
    # CCCBDB casno=7732185: A0 B0 C0 27.877 14.512 9.285; the re geometry differs from B0 by ~2.5 %
    "water": (water(), "asymmetric_top", None, [27.877, 14.512, 9.285], 0.03),
    # CCCBDB casno=50000 (Herzberg 1966): 9.4053 1.2953 1.1342; the inertial defect moves C by ~0.4 %
    "formaldehyde": (formaldehyde(), "asymmetric_top", None, [9.4053, 1.2953, 1.1342], 0.005),
    # CCCBDB casno=124389: B0 0.39021 (Herzberg 1966)
    "carbon dioxide": (carbon_dioxide(), "linear_rotator", None, [0.39021], 0.001),
    "ammonia": (ammonia(), "symmetric_top", "oblate", None, None),
    "methane": (methane(), "spherical_top", None, None, None),
    "benzene": (benzene(), "symmetric_top", "oblate", None, None),
}


@pytest.mark.parametrize("name", list(MOLECULES))
def test_molecule_rotor_type_and_constants(client: Any, name: str) -> None:
    atoms, kind, shape, published, gap = MOLECULES[name]
    r = client.post("/v1/analyze/points", json={"points": _points(atoms), "units": "angstrom", "isotopes": "abundant"})
    assert r.status_code == 200, r.text
    doc = r.json()
    assert doc["classification"]["kind"] == kind
    assert doc["classification"].get("shape") == shape
    moments, mhz = _constants(atoms, ABUNDANT)
    # REL_MASS: the package's isotope table rounds AME2020 masses at ~1e-10 relative (1H: 1.0078250319)
    np.testing.assert_allclose(doc["principal"]["moments"], moments, rtol=REL_MASS, atol=REL_MASS * moments[2])
    got = doc["rotational_constants"]
    if kind == "linear_rotator":
        expected_mhz = [PLANCK / (8 * math.pi**2 * moments[2]) * 1e-6]
    else:
        expected_mhz = list(mhz)
        assert got["MHz"] == sorted(got["MHz"], reverse=True)
    np.testing.assert_allclose(got["MHz"], expected_mhz, rtol=REL_MASS)
    np.testing.assert_allclose(got["cm-1"], np.array(expected_mhz) * 1e6 / SPEED_OF_LIGHT / 100, rtol=REL_MASS)
    if published is not None:
        assert gap is not None, "a published constant comes with its allowed gap"
        np.testing.assert_allclose(got["cm-1"], published, rtol=gap)


def test_symmetric_and_spherical_tops_have_their_equal_constants(client: Any) -> None:
    for atoms, equal in ((ammonia(), (0, 1)), (methane(), (0, 2)), (benzene(), (0, 1))):
        doc = client.post("/v1/analyze/points", json={"points": _points(atoms), "units": "angstrom"}).json()
        values = doc["rotational_constants"]["MHz"]
        assert values[equal[0]] == pytest.approx(values[equal[1]], rel=1e-12)


def test_standard_weights_are_the_default_and_abundant_isotopes_on_request(client: Any) -> None:
    atoms = water()
    for isotopes, table in (("standard", STANDARD), ("abundant", ABUNDANT)):
        body = {"points": _points(atoms), "units": "angstrom", "isotopes": isotopes}
        doc = client.post("/v1/analyze/points", json=body).json()
        expected = (table["O"] + 2 * table["H"]) * DALTON
        assert doc["mass"] == pytest.approx(expected, rel=1e-12 if isotopes == "standard" else REL_MASS, abs=0)
    default = client.post("/v1/analyze/points", json={"points": _points(atoms), "units": "angstrom"}).json()
    assert default["mass"] == pytest.approx((STANDARD["O"] + 2 * STANDARD["H"]) * DALTON, rel=1e-12, abs=0)


@pytest.mark.parametrize("symbol, mass", [("D", DEUTERIUM), ("2H", DEUTERIUM), ("13C", CARBON13), ("12C", 12.0)])
def test_mass_numbers_and_deuterium(client: Any, symbol: str, mass: float) -> None:
    body = {"points": [{"element": symbol, "position": [0, 0, 0]}, {"mass": 1.0, "position": [1, 0, 0]}], "mass_unit": "u"}
    doc = client.post("/v1/analyze/points", json=body).json()
    assert doc["mass"] == pytest.approx((mass + 1.0) * DALTON, rel=1e-9, abs=0)


def test_mass_wins_over_element_and_mass_unit_u(client: Any) -> None:
    body = {
        "points": [{"element": "O", "mass": 2.0, "position": [0, 0, 0]}, {"mass": 3.0, "position": [1, 0, 0]}],
        "mass_unit": "u",
    }
    doc = client.post("/v1/analyze/points", json=body).json()
    assert doc["mass"] == pytest.approx(5.0 * DALTON, rel=1e-12, abs=0)
    kg = client.post("/v1/analyze/points", json={**body, "mass_unit": "kg"}).json()
    assert kg["mass"] == 5.0


@pytest.mark.parametrize(
    "symbol, reason",
    [("Xx", "not an element"), ("99C", "mass numbers of C"), ("Tc", "no standard atomic weight"), ("14D", "already names")],
)
def test_unknown_elements_are_refused_with_advice(client: Any, symbol: str, reason: str) -> None:
    body = {"points": [{"element": symbol, "position": [0, 0, 0]}, {"element": "H", "position": [1, 0, 0]}]}
    r = client.post("/v1/analyze/points", json=body)
    assert r.status_code == 422
    assert r.json()["error"]["code"] == "invalid_parameter" and reason in r.json()["error"]["message"]


def test_a_point_needs_a_mass_or_an_element(client: Any) -> None:
    r = client.post("/v1/analyze/points", json={"points": [{"position": [0, 0, 0]}]})
    assert r.status_code == 422 and r.json()["error"]["code"] == "invalid_parameter"


def test_points_with_masses_only_have_no_rotational_constants(client: Any) -> None:
    doc = client.post(
        "/v1/analyze/points",
        json={
            "points": [{"mass": 1, "position": [0, 0, 0]}, {"mass": 1, "position": [1, 0, 0]}, {"mass": 1, "position": [0, 1, 0]}]
        },
    ).json()
    assert "rotational_constants" not in doc


def _xyz(atoms: list[tuple[str, list[float]]], comment: str = "from a test") -> str:
    lines = [str(len(atoms)), comment] + [f"{e} {p[0]!r} {p[1]!r} {p[2]!r}" for e, p in atoms]
    return "\n".join(lines) + "\n"


def test_xyz_upload_is_read_in_angstrom_with_the_isotopes_parameter(client: Any) -> None:
    atoms = formaldehyde()
    files = {"file": ("h2co.xyz", _xyz(atoms).encode(), "chemical/x-xyz")}
    doc = client.post("/v1/analyze/mesh", params={"isotopes": "abundant"}, files=files).json()
    assert doc["source"]["format"] == "xyz" and doc["source"]["units"] == "angstrom"
    _, mhz = _constants(atoms, ABUNDANT)
    np.testing.assert_allclose(doc["rotational_constants"]["MHz"], mhz, rtol=REL_MASS)
    nm = client.post("/v1/analyze/mesh", params={"units": "m"}, files=files).json()
    assert nm["source"]["units"] == "m"
    assert nm["principal"]["moments"][0] == pytest.approx(doc["principal"]["moments"][0] * 1e20, rel=1e-6)


def test_xyz_atomic_numbers_and_trajectories(client: Any) -> None:
    text = "3\nwater by atomic number\n8 0 0 0\n1 0 0.757 0.586\n1 0 -0.757 0.586\n3\nsecond frame\nO 0 0 0\nH 0 1 0\nH 0 -1 0\n"
    doc = client.post("/v1/analyze/mesh", files={"file": ("traj.xyz", text.encode())}).json()
    assert doc["source"]["points"] == 3
    assert any("first frame" in w for w in doc["warnings"])


@pytest.mark.parametrize(
    "text, message",
    [("x\n\nO 0 0 0\n", "number of atoms"), ("3\n\nO 0 0 0\n", "announces 3"), ("1\n\nO 0 zero 0\n", "element x y z")],
)
def test_broken_xyz_is_unreadable_file(client: Any, text: str, message: str) -> None:
    r = client.post("/v1/analyze/mesh", files={"file": ("bad.xyz", text.encode())})
    assert r.status_code == 422
    assert r.json()["error"]["code"] == "unreadable_file" and message in r.json()["error"]["message"]


def test_cli_analyze_water_xyz(tmp_path: Path) -> None:
    path = tmp_path / "water.xyz"
    path.write_text(_xyz(water()))
    table = subprocess.run(
        [sys.executable, "-m", "inertia", "analyze", str(path)], capture_output=True, text=True, check=True, cwd=ROOT
    ).stdout
    assert "rotational A, B, C" in table and "cm^-1" in table and "asymmetric_top" in table
    doc = json.loads(
        subprocess.run(
            [sys.executable, "-m", "inertia", "analyze", str(path), "--json", "--isotopes", "abundant"],
            capture_output=True,
            text=True,
            check=True,
            cwd=ROOT,
        ).stdout
    )
    _, mhz = _constants(water(), ABUNDANT)
    np.testing.assert_allclose(doc["rotational_constants"]["MHz"], mhz, rtol=REL_MASS)


@pytest.mark.parametrize("label", ["CA", "HG", "NE", "CD", "CL"])
def test_a_capitalised_label_that_may_name_another_element_is_refused(client: Any, label: str) -> None:
    # MDAnalysis's test.xyz labels alpha carbons 'CA': read as calcium, it weighed 40.078 u instead of 12.011
    text = f"2\nprotein atoms\n{label} 0 0 0\n{label} 1.5 0 0\n"
    r = client.post("/v1/analyze/mesh", files={"file": ("test.xyz", text.encode())})
    assert r.status_code == 422
    message = r.json()["error"]["message"]
    assert "ambiguous" in message and f"'{label[0]}'" in message


@pytest.mark.parametrize("label, mass", [("ZN", 65.38), ("ca", 40.078), ("o", 15.999)])
def test_a_label_in_another_case_that_names_one_element_is_read(client: Any, label: str, mass: float) -> None:
    body = {"points": [{"element": label, "position": [0, 0, 0]}], "mass_unit": "kg"}
    assert client.post("/v1/analyze/points", json=body).json()["mass"] == pytest.approx(mass * DALTON, rel=1e-12)


def _extended(properties: str, rows: list[str]) -> bytes:
    return (f'{len(rows)}\nLattice="20 0 0 0 20 0 0 0 20" Properties={properties} pbc="T T T"\n' + "\n".join(rows) + "\n").encode()


def test_extended_xyz_columns_are_read_where_properties_puts_them(client: Any) -> None:
    atoms = water()
    expected = client.post("/v1/analyze/mesh", files={"file": ("w.xyz", _xyz(atoms).encode())}).json()
    # an id column first and velocities after (as MD writers lay them out), species by atomic number
    numbers = {"O": 8, "H": 1}
    rows = [f"{k + 1} {numbers[e]} {p[0]!r} {p[1]!r} {p[2]!r} 0.1 0.2 0.3" for k, (e, p) in enumerate(atoms)]
    data = _extended("id:I:1:Z:I:1:pos:R:3:velo:R:3", rows)
    doc = client.post("/v1/analyze/mesh", files={"file": ("w.extxyz", data)}).json()
    assert doc["mass"] == expected["mass"]
    assert doc["center_of_mass"] == expected["center_of_mass"]
    assert doc["inertia_tensor"] == expected["inertia_tensor"]
    assert any("periodic cell (pbc='T T T')" in w for w in doc["warnings"])  # analysed without its images


def test_an_extended_xyz_masses_column_is_in_daltons(client: Any) -> None:
    # ASE writes masses:R:1 for atoms whose masses differ from the table's (here deuterated water)
    atoms = water()
    rows = [f"{e} {m!r} {p[0]!r} {p[1]!r} {p[2]!r}" for (e, p), m in zip(atoms, (15.999, DEUTERIUM, DEUTERIUM))]
    doc = client.post("/v1/analyze/mesh", files={"file": ("d2o.xyz", _extended("species:S:1:masses:R:1:pos:R:3", rows))}).json()
    assert doc["mass"] == pytest.approx((15.999 + 2 * DEUTERIUM) * DALTON, rel=1e-12)
    z = atoms[1][1][2] * 1e-10
    assert doc["center_of_mass"][2] == pytest.approx(2 * DEUTERIUM * z / (15.999 + 2 * DEUTERIUM), rel=1e-12)


def test_an_extended_xyz_without_species_or_positions_is_refused(client: Any) -> None:
    r = client.post("/v1/analyze/mesh", files={"file": ("a.xyz", _extended("id:I:1:pos:R:3", ["1 0 0 0"]))})
    assert r.status_code == 415
    assert "species:S:1" in r.json()["error"]["message"]


def test_a_form_feed_in_the_comment_line_ends_no_line(client: Any) -> None:
    # str.splitlines() split the comment at the form feed, and the first atom line became the comment
    atoms = water()
    plain = client.post("/v1/analyze/mesh", files={"file": ("w.xyz", _xyz(atoms).encode())}).json()
    doc = client.post("/v1/analyze/mesh", files={"file": ("w.xyz", _xyz(atoms, "page\x0cbreak\x0bhere").encode())}).json()
    assert doc["mass"] == plain["mass"] and doc["inertia_tensor"] == plain["inertia_tensor"]
    assert not doc["warnings"]


@pytest.mark.parametrize(
    "points",
    [
        [None, {"mass": 1, "position": [1, 0, 0]}],
        [1, 2],
        [[1, 0, 0, 0]],
        [{"mass": 1, "position": "123"}, {"mass": 1, "position": [1, 0, 0]}],
        [{"mass": True, "position": [0, 0, 0]}, {"mass": 1, "position": [1, 0, 0]}],
    ],
    ids=["null", "numbers", "list", "string-position", "boolean-mass"],
)
def test_a_points_file_entry_that_is_no_point_is_refused(client: Any, points: list[Any]) -> None:
    r = client.post("/v1/analyze/mesh", files={"file": ("p.json", json.dumps(points).encode())})
    assert r.status_code == 422
    assert r.json()["error"]["code"] == "invalid_parameter" and "point 0 must be an object" in r.json()["error"]["message"]


# --- extended XYZ comment lines as ASE reads them (ase.io.extxyz.key_val_str_to_dict), and counts ----------------
WATER_STANDARD = STANDARD["O"] + 2 * STANDARD["H"]  # u


def _water_rows(extra: list[str] | None = None) -> list[str]:
    return [f"{e} {p[0]!r} {p[1]!r} {p[2]!r}" + (f" {extra[k]}" if extra else "") for k, (e, p) in enumerate(water())]


@pytest.mark.parametrize(
    "comment, extra, mass",
    [
        # a quoted value that mentions a layout is not the layout: the occupancy column is no mass
        ('note="old Properties=species:S:1:pos:R:3:masses:R:1" Properties=species:S:1:pos:R:3:occupancy:R:1', "1.0", None),
        ("Computed properties = energy and dipole", None, None),  # plain XYZ: only the key Properties counts
        ("properties=species:S:1:pos:R:3:masses:R:1", "2.5", None),  # lower case: not the key, a plain comment
        ("Properties=species:S:1:pos:R:3:mass:R:1", "2.5", None),  # ASE's masses column is 'masses'
        ("Properties='species:S:1:pos:R:3:masses:R:1'", "2.5", 7.5),  # single quotes delimit a value too
        ("Properties=species:S:1:pos:R:3:masses:I:1", "2", 6.0),
        ('comment="" Properties=species:S:1:pos:R:3:masses:R:1', "2.5", 7.5),  # an empty value ends its pair
    ],
)
def test_extended_xyz_comment_lines_are_split_as_ase_splits_them(
    client: Any, comment: str, extra: str | None, mass: float | None
) -> None:
    rows = _water_rows([extra] * 3 if extra else None)
    text = "\n".join([str(len(rows)), comment, *rows]) + "\n"
    doc = client.post("/v1/analyze/mesh", files={"file": ("w.xyz", text.encode())}).json()
    assert doc["mass"] == pytest.approx((WATER_STANDARD if mass is None else mass) * DALTON, rel=1e-12)


def test_species_and_atomic_numbers_that_disagree_are_refused(client: Any) -> None:
    rows = _water_rows(["6", "1", "1"])
    text = "\n".join(["3", "Properties=species:S:1:pos:R:3:Z:I:1", *rows]) + "\n"
    r = client.post("/v1/analyze/mesh", files={"file": ("w.xyz", text.encode())})
    assert r.status_code == 422 and "species 'O' and atomic number '6'" in r.json()["error"]["message"]


@pytest.mark.parametrize(
    "count, message",
    [(5, "announces 5 atoms but holds 3 atom lines"), (2, "announces 2 atoms on its first line but holds more atom lines")],
)
def test_an_atom_count_that_does_not_match_is_refused(client: Any, count: int, message: str) -> None:
    text = "\n".join([str(count), "water", *_water_rows()]) + "\n\n"
    r = client.post("/v1/analyze/mesh", files={"file": ("w.xyz", text.encode())})
    assert r.status_code == 422 and message in r.json()["error"]["message"]


def test_a_word_after_the_atoms_is_not_an_atom_the_count_left_out(client: Any) -> None:
    text = "\n".join(["3", "water", *_water_rows(), "END"]) + "\n"
    doc = client.post("/v1/analyze/mesh", files={"file": ("w.xyz", text.encode())}).json()
    assert doc["mass"] == pytest.approx(WATER_STANDARD * DALTON, rel=1e-12)
    assert any("goes on after its first frame" in w for w in doc["warnings"])


def test_a_lattice_without_pbc_is_periodic_as_ase_reads_it(client: Any) -> None:
    text = "\n".join(["3", 'Lattice="20 0 0 0 20 0 0 0 20" Properties=species:S:1:pos:R:3', *_water_rows()]) + "\n"
    doc = client.post("/v1/analyze/mesh", files={"file": ("w.xyz", text.encode())}).json()
    assert any("periodic cell" in w for w in doc["warnings"])


def test_atoms_in_metres_without_a_unit_are_named_in_a_warning(client: Any) -> None:
    body = {"points": _points(water())}  # 0.958 apart: angstrom numbers, read as metres by default
    doc = client.post("/v1/analyze/points", json=body).json()
    assert any("read in metres" in w and "units=angstrom" in w for w in doc["warnings"])
    for fine in ({**body, "units": "angstrom"}, {**body, "units": "m"}):
        assert not client.post("/v1/analyze/points", json=fine).json()["warnings"]


def test_kilograms_beside_atoms_named_by_element_are_named_in_a_warning(client: Any) -> None:
    points = [
        {"element": "O", "position": [0, 0, 0]},
        {"element": "H", "position": [0, 0.757, 0.586]},
        {"mass": 2.014, "position": [0, -0.757, 0.586]},
    ]
    doc = client.post("/v1/analyze/points", json={"points": points, "units": "angstrom"}).json()
    assert any("mass_unit=u" in w for w in doc["warnings"])
    dalton = client.post("/v1/analyze/points", json={"points": points, "units": "angstrom", "mass_unit": "u"}).json()
    assert dalton["mass"] == pytest.approx((STANDARD["O"] + STANDARD["H"] + 2.014) * DALTON, rel=1e-12)
    assert not dalton["warnings"]


def test_a_single_atom_has_no_class_margin_to_doubt(client: Any) -> None:
    doc = client.post("/v1/analyze/points", json={"points": [{"element": "Ar", "position": [0, 0, 0]}]}).json()
    assert not any("classification uncertain" in w for w in doc["warnings"])


def test_a_requested_total_mass_says_the_constants_are_not_the_molecules() -> None:
    # the CLI's --mass (the points request has no total mass)
    from inertia.pipeline import AnalysisOptions, analyze_points

    plain = analyze_points(_points(water()), AnalysisOptions(units="angstrom")).as_dict()
    scaled = analyze_points(_points(water()), AnalysisOptions(units="angstrom", mass=1.0)).as_dict()
    assert not plain["warnings"]
    assert any("rotational constants are those of that scaled body" in w for w in scaled["warnings"])


def test_a_missing_comment_line_is_suggested_when_the_second_line_is_an_atom(client: Any) -> None:
    text = "\n".join(["3", *_water_rows()]) + "\n"
    r = client.post("/v1/analyze/mesh", files={"file": ("w.xyz", text.encode())})
    message = r.json()["error"]["message"]
    assert r.status_code == 422 and "holds 2 atom lines" in message and "is the comment line missing?" in message


@pytest.mark.parametrize(
    ("properties", "lacks"),
    [
        ("species:S:1:frc:R:3", "lack a position column ('pos:R:3')"),  # QUIP's force files: no positions at all
        ("species:S:1:pos:I:3", "lack positions as three real numbers ('pos:R:3'; it says 'pos:I:3')"),
        ("name:S:1:pos:R:3", "lack an element column ('species:S:1' or 'Z:I:1')"),
    ],
)
def test_an_extended_xyz_layout_is_refused_for_what_it_lacks_alone(client: Any, properties: str, lacks: str) -> None:
    text = "\n".join(["3", f"Properties={properties}", *_water_rows()]) + "\n"
    r = client.post("/v1/analyze/mesh", files={"file": ("w.xyz", text.encode())})
    message = r.json()["error"]["message"]
    assert r.status_code == 415 and lacks in message
    assert ("element column" in message) is properties.startswith("name")


def test_a_lattice_without_pbc_is_said_to_be_read_as_periodic_not_quoted(client: Any) -> None:
    text = "\n".join(["3", 'Lattice="20 0 0 0 20 0 0 0 20" Properties=species:S:1:pos:R:3', *_water_rows()]) + "\n"
    doc = client.post("/v1/analyze/mesh", files={"file": ("w.xyz", text.encode())}).json()
    assert any("a Lattice without pbc, periodic as ASE reads it" in w for w in doc["warnings"])
