"""Points files (.json) uploaded or given to the CLI: the document of POST /v1/analyze/points, read as it says.

A client that writes the points request of API.md to a file gets the body that request describes: its
``units`` and ``mass_unit`` apply (the request's own ``units``, when given, wins, as for a CAD file's unit),
and keys that are options of a request, not of the body, are named in a warning instead of being dropped
without a word.
"""

from __future__ import annotations

import json
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from tests.contract.helpers import analyze

# two masses 1 and 3 kg, 4 length units apart on x: I2 = I3 = m1 m2 / (m1 + m2) d^2 = 3/4 * 16 = 12 (units^2 kg)
DOC = {"points": [{"mass": 1.0, "position": [0, 0, 0]}, {"mass": 3.0, "position": [4, 0, 0]}]}
I_PERP = Fraction(1 * 3, 1 + 3) * 16


def _doc(**extra: object) -> bytes:
    return json.dumps({**DOC, **extra}).encode()


def test_json_points_file_units_apply(client: TestClient) -> None:
    res = analyze(client, "rod.json", _doc(units="cm"))
    assert res["source"]["units"] == "cm"
    assert res["source"]["units_from"] == "file"
    assert res["center_of_mass"] == pytest.approx([0.03, 0.0, 0.0], rel=1e-15)
    assert res["principal"]["moments"][1:] == pytest.approx([float(I_PERP * Fraction(1, 10**4))] * 2, rel=1e-15)


def test_request_units_win_over_the_files(client: TestClient) -> None:
    res = analyze(client, "rod.json", _doc(units="cm"), units="mm")
    assert res["source"]["units"] == "mm" and res["source"]["units_from"] == "request"
    assert res["principal"]["moments"][1:] == pytest.approx([float(I_PERP * Fraction(1, 10**6))] * 2, rel=1e-15)


def test_json_points_file_mass_unit_applies(client: TestClient) -> None:
    from scipy.constants import physical_constants

    dalton = physical_constants["atomic mass constant"][0]
    res = analyze(client, "rod.json", _doc(mass_unit="u"))
    assert res["mass"] == pytest.approx(4 * dalton, rel=1e-15)


def test_json_points_file_request_options_are_named_not_dropped(client: TestClient) -> None:
    res = analyze(client, "rod.json", _doc(omega=[0, 1, 0], tolerance=1e-3))
    assert "precession" not in res
    said = " ".join(res["warnings"])
    assert "omega" in said and "tolerance" in said


def test_json_points_file_with_an_unknown_unit_is_refused(client: TestClient) -> None:
    r = client.post("/v1/analyze/mesh", files={"file": ("rod.json", _doc(units="furlong"), "application/json")})
    assert r.status_code == 422, r.text
    err = r.json()["error"]
    assert err["code"] == "unreadable_file" and "furlong" in err["message"]


def test_cli_reads_a_points_file_in_its_units(tmp_path: Path) -> None:
    path = tmp_path / "co.json"
    path.write_bytes(_doc(units="angstrom"))
    out = subprocess.run(
        [sys.executable, "-m", "inertia", "analyze", str(path), "--json"], capture_output=True, text=True, check=True
    ).stdout
    res = json.loads(out)
    assert res["source"]["units"] == "angstrom"
    assert res["principal"]["moments"][2] == pytest.approx(float(I_PERP) * 1e-20, rel=1e-15)


@pytest.mark.parametrize("extra", [{"units": ["m"]}, {"units": {"a": 1}}, {"mass_unit": ["u"]}, {"mass_unit": "g"}])
def test_json_points_file_with_units_of_the_wrong_kind_is_refused(client: TestClient, extra: dict[str, object]) -> None:
    r = client.post("/v1/analyze/mesh", files={"file": ("rod.json", _doc(**extra), "application/json")})
    assert r.status_code == 422, r.text
    assert r.json()["error"]["code"] == "unreadable_file"


def test_a_points_csv_with_a_header_and_no_rows_is_empty_geometry(client: TestClient) -> None:
    r = client.post("/v1/analyze/mesh", files={"file": ("p.csv", b"mass,x,y,z\n", "text/csv")})
    assert r.status_code == 422, r.text
    assert r.json()["error"]["code"] == "empty_geometry"
    r = client.post("/v1/analyze/mesh", files={"file": ("p.csv", b"a,b\n1,2\n", "text/csv")})
    assert r.json()["error"]["code"] == "unreadable_file"


def test_json_points_file_with_null_units_reads_as_the_defaults(client: TestClient) -> None:
    res = analyze(client, "rod.json", _doc(units=None, mass_unit=None))
    assert res["source"]["units"] == "m" and res["mass"] == 4.0
