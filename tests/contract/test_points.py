"""POST /v1/analyze/points: point masses."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from tests.contract.helpers import (
    TRIATOMIC,
    assert_error,
    check_classification,
    check_principal,
    parallel_axis,
    points_ok,
    post_points,
)


def test_triatomic_molecule_moments_match_closed_form(client: TestClient) -> None:
    res = points_ok(client, TRIATOMIC)
    m1, m2, a, h = 1.0, 16.0, 2.0, 1.0  # L&L §32 problem: isosceles triatomic molecule
    mu = 2 * m1 + m2
    I1, I2 = 2 * m1 * m2 * h * h / mu, m1 * a * a / 2
    assert res["mass"] == pytest.approx(mu, rel=1e-15, abs=0)
    np.testing.assert_allclose(res["center_of_mass"], [0, m2 * h / mu, 0], atol=1e-15)
    np.testing.assert_allclose(res["principal"]["moments"], sorted([I1, I2, I1 + I2]), rtol=1e-14)
    check_principal(res)
    check_classification(res, "asymmetric_top", planar=True)
    A = np.asarray(res["principal"]["axes"])
    assert abs(abs(A[2] @ [0, 0, 1]) - 1) < 1e-12  # I3 normal to the molecule's plane
    assert abs(abs(A[0] @ [1, 0, 0]) - 1) < 1e-12  # I1 = 2 m1 m2 h²/μ: about x, across the height
    assert abs(abs(A[1] @ [0, 1, 0]) - 1) < 1e-12  # I2 = m1 a²/2: about the symmetry axis y
    assert "volume" not in res and "density" not in res
    assert "parts" not in res and "precession" not in res and "reference_inertia" not in res


def test_points_units_tolerance_and_reference(client: TestClient) -> None:
    body = {**TRIATOMIC, "units": "mm", "tolerance": 1e-8, "reference": [0, 1000, 0]}
    res = points_ok(client, body)
    s = 1e-3
    mu = 18.0
    I = np.diag([2 * 16 * 1 / mu + 0.0, 0, 0])  # placeholder, rebuilt below
    pos = np.array([p["position"] for p in TRIATOMIC["points"]], float) * s
    ms = np.array([p["mass"] for p in TRIATOMIC["points"]], float)
    com = ms @ pos / ms.sum()
    I = sum(m * ((r - com) @ (r - com) * np.eye(3) - np.outer(r - com, r - com)) for m, r in zip(ms, pos))
    np.testing.assert_allclose(res["center_of_mass"], com, rtol=1e-14, atol=1e-18)
    np.testing.assert_allclose(res["inertia_tensor"], I, rtol=0, atol=1e-14 * np.trace(I))
    np.testing.assert_allclose(res["reference_inertia"]["point"], [0, 1.0, 0], rtol=1e-15)
    np.testing.assert_allclose(
        res["reference_inertia"]["tensor"], parallel_axis(I, mu, com - [0, 1.0, 0]), rtol=0, atol=1e-14 * np.trace(I)
    )
    assert res["classification"]["tolerance"] == 1e-8


def test_two_point_masses_are_a_linear_rotator(client: TestClient) -> None:
    res = points_ok(client, {"points": [{"mass": 1.0, "position": [0, 0, 0]}, {"mass": 2.0, "position": [1, 0, 0]}]})
    I = 1 * 2 * 1**2 / 3  # m1 m2 l² / (m1 + m2)
    moments = res["principal"]["moments"]
    assert abs(moments[0]) <= 1e-15 * I
    np.testing.assert_allclose(moments[1:], [I, I], rtol=1e-14)
    check_principal(res)
    check_classification(res, "linear_rotator", planar=True)
    assert abs(abs(res["classification"]["symmetry_axis"][0]) - 1) < 1e-14
    np.testing.assert_allclose(res["center_of_mass"], [2 / 3, 0, 0], rtol=1e-15)


def test_single_point_mass_is_accepted(client: TestClient) -> None:
    res = points_ok(client, {"points": [{"mass": 2.5, "position": [1, 2, 3]}]})
    assert res["mass"] == 2.5
    np.testing.assert_allclose(res["center_of_mass"], [1, 2, 3])
    np.testing.assert_allclose(res["inertia_tensor"], np.zeros((3, 3)), atol=0)


POINTS_ERRORS = [
    ("no points", {"points": []}),
    ("missing points", {"units": "m"}),
    ("zero mass", {"points": [{"mass": 0.0, "position": [0, 0, 0]}]}),
    ("negative mass", {"points": [{"mass": -1.0, "position": [0, 0, 0]}, {"mass": 1, "position": [1, 0, 0]}]}),
    ("position of two numbers", {"points": [{"mass": 1.0, "position": [0, 0]}]}),
    ("unknown unit", {"points": [{"mass": 1.0, "position": [0, 0, 0]}], "units": "parsec"}),
    ("bad method", {"points": TRIATOMIC["points"], "omega": [0, 0, 1], "method": "magic"}),
    ("not json", "{points: ["),
    ("NaN position", '{"points": [{"mass": 1.0, "position": [NaN, 0, 0]}]}'),
    ("Infinity mass", '{"points": [{"mass": Infinity, "position": [0, 0, 0]}]}'),
    ("overflowing literal", '{"points": [{"mass": 1e999, "position": [0, 0, 0]}]}'),
    (
        "-Infinity omega",
        '{"points": [{"mass": 1, "position": [0, 0, 0]}, {"mass": 1, "position": [1, 1, 0]}], "omega": [0, -Infinity, 0]}',
    ),
    ("NaN tolerance", '{"points": [{"mass": 1, "position": [0, 0, 0]}], "tolerance": NaN}'),
    ("NaN reference", '{"points": [{"mass": 1, "position": [0, 0, 0]}], "reference": [0, NaN, 0]}'),
]


@pytest.mark.parametrize("label,body", POINTS_ERRORS, ids=[c[0] for c in POINTS_ERRORS])
def test_points_errors_are_invalid_parameter(client: TestClient, label: str, body: Any) -> None:
    assert_error(post_points(client, body), 422, "invalid_parameter")


def test_collinear_points_along_a_diagonal_are_a_linear_rotator(client: TestClient) -> None:
    d = np.array([1.0, -2.0, 2.0]) / 3
    pts = [{"mass": m, "position": (s * d + [1, 1, 1]).tolist()} for m, s in ((1, 0), (2, 1.5), (3, -1))]
    res = points_ok(client, {"points": pts})
    ms = np.array([1.0, 2, 3])
    ss = np.array([0, 1.5, -1])
    sc = ms @ ss / ms.sum()
    I = float(ms @ (ss - sc) ** 2)
    np.testing.assert_allclose(res["principal"]["moments"][1:], [I, I], rtol=1e-13)
    assert abs(res["principal"]["moments"][0]) <= 1e-14 * I
    check_classification(res, "linear_rotator", planar=True)
    assert abs(abs(np.asarray(res["classification"]["symmetry_axis"]) @ d) - 1) < 1e-13


def test_point_masses_far_from_the_origin_keep_their_moments(client: TestClient) -> None:
    shift = np.array([1e8, -1e8, 3e7])
    pts = [{"mass": p["mass"], "position": (np.array(p["position"]) + shift).tolist()} for p in TRIATOMIC["points"]]
    res = points_ok(client, {"points": pts})
    est = res["diagnostics"]["relative_error_estimate"]
    want = [32 / 18, 2.0, 32 / 18 + 2]
    for got, w in zip(res["principal"]["moments"], want):
        assert abs(got - w) <= max(est, 4.5e-16) * w, (got, w, est)
    np.testing.assert_allclose(res["center_of_mass"], shift + np.array([0, 16 / 18, 0]), rtol=1e-16)
