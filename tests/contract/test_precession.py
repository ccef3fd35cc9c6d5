"""Torque-free precession (Landau & Lifshitz §§33-37): POST /v1/precession and the precession section."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient
from scipy.special import ellipk

from tests.contract.helpers import (
    RHO,
    TRIATOMIC,
    analyze,
    assert_error,
    box_inertia,
    check_classification,
    check_invariants,
    check_principal,
    check_symmetric_rates,
    check_trajectory,
    points_ok,
    post_precession,
    precession_ok,
    ray_kappa,
    reference_motion,
    rotation,
    thin_box_shell_inertia,
)
from tests.support.motion import unit_quaternion_matrix


def ll_asymmetric_period(I: Any, Omega: Any) -> float:
    """Landau & Lifshitz §37: period of Ω(t) in the body frame, I1 < I2 < I3."""
    I1, I2, I3 = I
    W = np.asarray(Omega, float)
    M2 = float(np.sum((np.asarray(I) * W) ** 2))
    E2 = float(np.sum(np.asarray(I) * W * W))  # 2E
    if M2 > E2 * I2:
        rate = math.sqrt((I3 - I2) * (M2 - E2 * I1) / (I1 * I2 * I3))
        k2 = (I2 - I1) * (E2 * I3 - M2) / ((I3 - I2) * (M2 - E2 * I1))
    else:
        rate = math.sqrt((I2 - I1) * (E2 * I3 - M2) / (I1 * I2 * I3))
        k2 = (I3 - I2) * (M2 - E2 * I1) / ((I2 - I1) * (E2 * I3 - M2))
    return 4 * float(ellipk(k2)) / rate


# file, mass, centre of mass, moments, kind, shape (sample_meshes/README.md; closed formulas)
PHI = (1 + 5**0.5) / 2

ICO_MASS = RHO * 5 * (3 + 5**0.5) / 12


def test_shell_model_integrates_a_thin_wall_of_given_thickness(client: TestClient) -> None:
    t = 1e-4  # file units (m): thin against the 1 x 2 x 3 box, so wall placement is second order
    res = analyze(client, "box.stl", model="shell", thickness=t)
    M, com, I = thin_box_shell_inertia(1, 2, 3, RHO * t)
    assert res["mass"] == pytest.approx(M, rel=1e-3, abs=0)
    np.testing.assert_allclose(res["center_of_mass"], com, atol=1e-3)
    np.testing.assert_allclose(res["inertia_tensor"], I, rtol=0, atol=1e-3 * np.trace(I))
    assert "volume" not in res and "density" not in res, "volume, density: solids only"


def test_precession_from_principal_moments_asymmetric_intermediate_start(client: TestClient) -> None:
    moments, omega = [1.0, 2.0, 3.0], [0.1, 1.0, 0.05]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": 10, "samples": 41})
    np.testing.assert_allclose(res["principal"]["moments"], moments, rtol=1e-15)
    # the input frame is the principal frame
    np.testing.assert_allclose(np.abs(res["principal"]["axes"]), np.eye(3), atol=1e-15)
    check_principal(res, np.diag(moments))
    check_classification(res, "asymmetric_top", planar=True)  # 1 + 2 = 3
    pre = res["precession"]
    assert pre["regime"] == "asymmetric"
    check_invariants(pre, np.diag(moments), omega)
    A = np.asarray(res["principal"]["axes"])
    np.testing.assert_allclose(pre["omega_body"], A @ omega, atol=1e-15)
    T = ll_asymmetric_period(moments, omega)
    assert pre["period"] == pytest.approx(T, rel=1e-10, abs=0)
    assert pre["stable"] is False
    assert pre["flip_interval"] == pytest.approx(T / 2, rel=1e-10, abs=0)
    check_trajectory(pre, moments, A, omega, 10.0, 41, np.diag(moments))


@pytest.mark.parametrize("omega,branch", [([0.05, 0.3, 1.0], "near I3"), ([1.0, 0.3, 0.05], "near I1")])
def test_asymmetric_period_both_branches_and_stable_starts(client: TestClient, omega: Any, branch: str) -> None:
    moments = [1.0, 2.0, 3.0]
    pre = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": 6, "samples": 13})["precession"]
    assert pre["regime"] == "asymmetric"
    T = ll_asymmetric_period(moments, omega)
    assert pre["period"] == pytest.approx(T, rel=1e-10, abs=0)
    assert pre["stable"] is True
    assert "flip_interval" not in pre
    check_trajectory(pre, moments, np.eye(3), omega, 6.0, 13, np.diag(moments))


def test_asymmetric_motion_returns_to_its_start_after_one_period(client: TestClient) -> None:
    moments, omega = [1.0, 2.0, 3.0], [0.2, 0.7, 0.4]
    T = ll_asymmetric_period(moments, omega)
    pre = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": T, "samples": 5})["precession"]
    W = np.asarray(pre["trajectory"]["omega_body"])
    np.testing.assert_allclose(W[-1], W[0], atol=1e-9)
    assert not np.allclose(W[2], W[0], atol=1e-3)  # but not after half of it


def test_separatrix_has_no_period_and_a_warning(client: TestClient) -> None:
    # 2E I2 = |M|²  <=>  I1(I1 − I2) Ω1² + I3(I3 − I2) Ω3² = 0; here Ω1 = √3 Ω3
    moments = [1.0, 2.0, 3.0]
    omega = [0.1 * math.sqrt(3), 1.0, 0.1]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega})
    pre = res["precession"]
    assert pre["regime"] == "asymmetric"
    assert "period" not in pre
    assert "flip_interval" not in pre
    warnings_ = list(res.get("warnings", [])) + list(pre.get("warnings", []))
    assert warnings_, "a warning must say why the period is absent"
    check_invariants(pre, np.diag(moments), omega)


def test_precession_from_a_rotated_inertia_tensor(client: TestClient) -> None:
    R = rotation([1, -1, 2], 0.9)
    moments = np.array([1.0, 2.0, 3.0])
    I = R @ np.diag(moments) @ R.T
    I = (I + I.T) / 2
    omega = [0.4, -0.3, 0.9]
    res = precession_ok(client, {"inertia_tensor": I.tolist(), "omega": omega, "duration": 5, "samples": 11, "tolerance": 1e-9})
    check_principal(res, I)
    check_classification(res, "asymmetric_top", tolerance=1e-9)
    np.testing.assert_allclose(res["principal"]["moments"], moments, rtol=1e-13)
    pre = res["precession"]
    check_invariants(pre, I, omega)
    A = np.asarray(res["principal"]["axes"])
    np.testing.assert_allclose(pre["omega_body"], A @ omega, atol=1e-13)
    Wb = R.T @ omega
    assert pre["period"] == pytest.approx(ll_asymmetric_period(moments, Wb), rel=1e-9, abs=0)
    check_trajectory(pre, moments, A, omega, 5.0, 11, I)


@pytest.mark.parametrize("moments,shape", [([2.0, 2.0, 3.0], "oblate"), ([1.0, 3.0, 3.0], "prolate")])
def test_symmetric_top_rates_follow_landau_lifshitz(client: TestClient, moments: Any, shape: str | None) -> None:
    omega = [0.3, -0.4, 1.2]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": 4, "samples": 9})
    check_classification(res, "symmetric_top", shape)
    n = np.asarray(res["classification"]["symmetry_axis"], float)
    unique = 2 if shape == "oblate" else 0
    assert abs(abs(n[unique]) - 1) < 1e-15
    I_sym, I_perp = moments[unique], moments[1]
    pre = res["precession"]
    check_invariants(pre, np.diag(moments), omega)
    check_symmetric_rates(pre, I_perp, I_sym, n, omega)
    check_trajectory(pre, moments, res["principal"]["axes"], omega, 4.0, 9, np.diag(moments))


def test_symmetric_mesh_regular_precession_in_the_input_frame(client: TestClient) -> None:
    # tetrahedron.stl: oblate, symmetry axis (1,1,1)/√3, I⊥ = 125/12, I3 = 50/3
    omega = [0.5, -0.2, 0.1]
    res = analyze(client, "tetrahedron.stl", omega=",".join(map(str, omega)), duration=5, samples=6)
    I = np.asarray(res["inertia_tensor"], float)
    n = np.asarray(res["classification"]["symmetry_axis"], float)
    assert abs(abs(n @ np.ones(3) / math.sqrt(3)) - 1) < 1e-12
    pre = res["precession"]
    check_invariants(pre, I, omega)
    I_perp = res["principal"]["moments"][0]
    I_sym = res["principal"]["moments"][2]
    assert I_perp == pytest.approx(125 / 12, rel=1e-12, abs=0) and I_sym == pytest.approx(50 / 3, rel=1e-12, abs=0)
    check_symmetric_rates(pre, I_perp, I_sym, n, omega)
    check_trajectory(pre, res["principal"]["moments"], res["principal"]["axes"], omega, 5.0, 6, I)


def test_asymmetric_mesh_precession_in_the_input_frame(client: TestClient) -> None:
    omega = [0.1, 2.0, 0.1]
    res = analyze(client, "box.stl", omega="0.1,2,0.1", duration=10, samples=21)
    pre = res["precession"]
    I = box_inertia(6000, 1, 2, 3)
    check_invariants(pre, I, omega)
    assert pre["regime"] == "asymmetric"
    # principal axes are ±z, ±y, ±x: the period depends only on the squares of Ω
    T = ll_asymmetric_period([2500, 5000, 6500], [0.1, 2.0, 0.1])
    assert pre["period"] == pytest.approx(T, rel=1e-10, abs=0)
    assert pre["stable"] is False
    assert pre["flip_interval"] == pytest.approx(T / 2, rel=1e-10, abs=0)
    check_trajectory(pre, [2500, 5000, 6500], res["principal"]["axes"], omega, 10.0, 21, I)


def test_flip_interval_is_the_time_between_reversals_of_omega2(client: TestClient) -> None:
    moments, omega = [1.0, 2.0, 3.0], [0.05, 1.0, 0.02]
    pre = precession_ok(client, {"principal_moments": moments, "omega": omega})["precession"]
    # independent: zero crossings of Ω2 in a reference integration
    T = ll_asymmetric_period(moments, omega)
    t = np.linspace(0, 2.2 * T, 4001)
    W, _, _ = reference_motion(moments, np.eye(3), omega, t)
    s = W[:, 1]
    idx = np.nonzero(np.sign(s[1:]) != np.sign(s[:-1]))[0]
    crossings = [t[i] - s[i] * (t[i + 1] - t[i]) / (s[i + 1] - s[i]) for i in idx]
    gaps = np.diff(crossings)
    assert len(gaps) >= 2
    np.testing.assert_allclose(gaps, pre["flip_interval"], rtol=1e-4)


@pytest.mark.parametrize("method", ["dop853", "rk45", "splitting"])
def test_numerical_methods_follow_the_same_motion(client: TestClient, method: str) -> None:
    moments, omega = [1.0, 2.0, 3.0], [0.3, 0.8, 0.5]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": 3, "samples": 7, "method": method})
    pre = res["precession"]
    assert pre["regime"] == "asymmetric"
    check_invariants(pre, np.diag(moments), omega)
    # the contract states no accuracy for the integrators: a loose 1e-4 is asked
    check_trajectory(pre, moments, res["principal"]["axes"], omega, 3.0, 7, np.diag(moments), tol=1e-4)


def test_rest(client: TestClient) -> None:
    res = precession_ok(client, {"principal_moments": [1, 2, 3], "omega": [0, 0, 0], "duration": 1, "samples": 3})
    pre = res["precession"]
    assert pre["regime"] == "rest"
    assert pre["angular_momentum_magnitude"] == 0 and pre["kinetic_energy"] == 0
    np.testing.assert_allclose(pre["angular_momentum"], [0, 0, 0], atol=0)
    for q in pre["trajectory"]["quaternion"]:
        np.testing.assert_allclose(unit_quaternion_matrix(q), np.eye(3), atol=1e-15)
    np.testing.assert_allclose(pre["trajectory"]["omega"], np.zeros((3, 3)), atol=0)


@pytest.mark.parametrize("axis,stable", [(0, True), (1, False), (2, True)])
def test_permanent_rotation_about_a_principal_axis(client: TestClient, axis: Any, stable: bool) -> None:
    omega = [0.0, 0.0, 0.0]
    omega[axis] = 1.5
    # box.stl: x has the largest moment (6500), y the intermediate, z the smallest
    res = analyze(client, "box.stl", omega=",".join(map(str, omega)), duration=2, samples=5)
    pre = res["precession"]
    assert pre["regime"] == "permanent_rotation"
    I = box_inertia(6000, 1, 2, 3)
    check_invariants(pre, I, omega)
    if "stable" in pre:
        assert pre["stable"] is stable
    for t, q, w in zip(pre["trajectory"]["t"], pre["trajectory"]["quaternion"], pre["trajectory"]["omega"]):
        np.testing.assert_allclose(unit_quaternion_matrix(q), rotation(omega, 1.5 * t), atol=1e-12)
        np.testing.assert_allclose(w, omega, atol=1e-12)


def test_spherical_top_keeps_omega_constant(client: TestClient) -> None:
    omega = [0.3, -0.2, 0.5]
    res = analyze(client, "icosahedron.stl", omega="0.3,-0.2,0.5", duration=4, samples=5)
    pre = res["precession"]
    assert pre["regime"] == "spherical"
    I0 = ICO_MASS * PHI**2 / 10  # ideal icosahedron; the float32 file is 4e-8 away
    np.testing.assert_allclose(res["inertia_tensor"], np.eye(3) * I0, rtol=0, atol=1e-7 * I0)
    check_invariants(pre, np.asarray(res["inertia_tensor"]), omega)
    w = np.linalg.norm(omega)
    for t, q, om, Wb in zip(*(pre["trajectory"][k] for k in ("t", "quaternion", "omega", "omega_body"))):
        np.testing.assert_allclose(om, omega, atol=1e-12)
        np.testing.assert_allclose(Wb, pre["omega_body"], atol=1e-12)
        np.testing.assert_allclose(unit_quaternion_matrix(q), rotation(omega, w * t), atol=1e-12)


def test_linear_rotator_precession(client: TestClient) -> None:
    body = {
        "points": [{"mass": 1.0, "position": [0, 0, 0]}, {"mass": 2.0, "position": [1, 0, 0]}],
        "omega": [0, 0, 2.0],
        "duration": 3.0,
        "samples": 4,
    }
    res = points_ok(client, body)
    pre = res["precession"]
    assert pre["regime"] == "rotator"
    I = 2 / 3
    np.testing.assert_allclose(pre["angular_momentum"], [0, 0, 2 * I], atol=1e-14)
    assert pre["angular_momentum_magnitude"] == pytest.approx(2 * I, rel=1e-14, abs=0)
    assert pre["kinetic_energy"] == pytest.approx(0.5 * I * 4, rel=1e-14, abs=0)
    tr = pre["trajectory"]
    np.testing.assert_allclose(tr["t"], [0, 1, 2, 3], atol=1e-15)
    for t, q, w in zip(tr["t"], tr["quaternion"], tr["omega"]):
        np.testing.assert_allclose(unit_quaternion_matrix(q), rotation([0, 0, 1], 2 * t), atol=1e-12)
        np.testing.assert_allclose(w, [0, 0, 2], atol=1e-12)


def test_points_precession_matches_the_mesh_contract(client: TestClient) -> None:
    body = {**TRIATOMIC, "omega": [0.2, 1.0, 0.3], "duration": 2.0, "samples": 5}
    res = points_ok(client, body)
    pre = res["precession"]
    I = np.asarray(res["inertia_tensor"], float)
    check_invariants(pre, I, body["omega"])
    check_trajectory(pre, res["principal"]["moments"], res["principal"]["axes"], body["omega"], 2.0, 5, I)


PRECESSION_ERRORS = [
    ("no omega", {"principal_moments": [1, 2, 3]}),
    ("no inertia", {"omega": [0, 0, 1]}),
    ("both inertia forms", {"principal_moments": [1, 2, 3], "inertia_tensor": np.eye(3).tolist(), "omega": [0, 0, 1]}),
    ("tensor not 3x3", {"inertia_tensor": [[1, 0], [0, 1]], "omega": [0, 0, 1]}),
    ("omega of two numbers", {"principal_moments": [1, 2, 3], "omega": [0, 1]}),
    ("unknown method", {"principal_moments": [1, 2, 3], "omega": [0, 0, 1], "method": "leapfrog"}),
    ("negative moment", {"principal_moments": [-1, 2, 3], "omega": [0, 0, 1]}),
    ("NaN moment", '{"principal_moments": [NaN, 2, 3], "omega": [0, 0, 1]}'),
    ("Infinity in tensor", '{"inertia_tensor": [[Infinity,0,0],[0,1,0],[0,0,1]], "omega": [0, 0, 1]}'),
    ("NaN omega", '{"principal_moments": [1, 2, 3], "omega": [0, NaN, 1]}'),
    ("Inf duration", '{"principal_moments": [1, 2, 3], "omega": [0, 0, 1], "duration": Infinity, "samples": 3}'),
    ("1e999 omega", '{"principal_moments": [1, 2, 3], "omega": [0, 1e999, 1]}'),
]


@pytest.mark.parametrize("label,body", PRECESSION_ERRORS, ids=[c[0] for c in PRECESSION_ERRORS])
def test_precession_errors_are_invalid_parameter(client: TestClient, label: str, body: Any) -> None:
    assert_error(post_precession(client, body), 422, "invalid_parameter")


def test_nearly_symmetric_mesh_reports_momentum_and_energy_of_its_own_tensor(client: TestClient) -> None:
    """hex_prism.stl is symmetric only within the tolerance (moments 1.4e-8 apart).  M = I Ω and
    E = ½ Ω·I Ω are properties of the initial state of the body whose tensor is reported; the
    moments are not to be rounded (cf. 'asymmetry ... is not rounded to ±1')."""
    omega = [0.3, 0.2, 1.0]
    res = analyze(client, "hex_prism.stl", omega="0.3,0.2,1", duration=20, samples=5)
    I = np.asarray(res["inertia_tensor"], float)
    pre = res["precession"]
    # labelled symmetric by the tolerance, and its regime with it (API.md: regular_precession for a
    # symmetric top), it moves as the asymmetric top its moments make (issue 12)
    assert res["classification"]["kind"] == "symmetric_top"
    assert pre["regime"] == "regular_precession"
    check_invariants(pre, I, omega)
    check_trajectory(pre, res["principal"]["moments"], res["principal"]["axes"], omega, 20.0, 5, I, tol=1e-9)


def test_exact_motion_over_many_periods(client: TestClient) -> None:
    moments, omega = [1.0, 2.0, 3.0], [0.3, 0.8, 0.5]
    T = ll_asymmetric_period(moments, omega)
    duration = 60 * T
    res = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": duration, "samples": 9})
    check_trajectory(res["precession"], moments, res["principal"]["axes"], omega, duration, 9, np.diag(moments), tol=1e-7)


@pytest.mark.parametrize("eps", [1e-3, -1e-3, 1e-5, -1e-5])
def test_period_near_the_separatrix(client: TestClient, eps: float) -> None:
    moments = [1.0, 2.0, 3.0]
    omega = [0.1 * math.sqrt(3) * (1 + eps), 1.0, 0.1]
    pre = precession_ok(client, {"principal_moments": moments, "omega": omega})["precession"]
    T = ll_asymmetric_period(moments, omega)
    assert pre["period"] == pytest.approx(T, rel=1e-9, abs=0)
    assert pre["stable"] is False
    assert pre["flip_interval"] == pytest.approx(T / 2, rel=1e-9, abs=0)


def test_separatrix_of_a_mesh_body(client: TestClient) -> None:
    # box.stl: I = 2500, 5000, 6500 (axes z, y, x); 2E I2 = |M|² when 2500² Ωz² = 6500·1500 Ωx²
    wx = 0.1
    wz = wx * math.sqrt(6500 * 1500) / 2500
    res = analyze(client, "box.stl", omega=f"{wx!r},1.0,{wz!r}")
    pre = res["precession"]
    assert pre["regime"] == "asymmetric" and "period" not in pre
    assert list(res.get("warnings", [])) + list(pre.get("warnings", []))


def test_unsorted_principal_moments_keep_the_given_frame_as_input_frame(client: TestClient) -> None:
    given = [3.0, 1.0, 2.0]
    omega = [0.2, 0.5, 1.0]
    res = precession_ok(client, {"principal_moments": given, "omega": omega, "duration": 3, "samples": 4})
    I = np.diag(given)
    np.testing.assert_allclose(res["principal"]["moments"], [1, 2, 3], rtol=1e-15)
    check_principal(res, I)
    A = np.abs(np.asarray(res["principal"]["axes"]))
    np.testing.assert_allclose(A, [[0, 1, 0], [0, 0, 1], [1, 0, 0]], atol=1e-15)
    pre = res["precession"]
    check_invariants(pre, I, omega)
    check_trajectory(pre, [1, 2, 3], res["principal"]["axes"], omega, 3.0, 4, I)


@pytest.mark.parametrize("method", ["exact", "dop853", "rk45", "splitting"])
def test_drift_diagnostics_are_honest(client: TestClient, method: str) -> None:
    """'diagnostics reports how well the trajectory keeps [M] and the energy': the reported drift
    is at least what the returned samples show (half of it, for definitions that differ)."""
    moments, omega = [1.0, 2.0, 3.0], [0.3, 0.8, 0.5]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": 50, "samples": 201, "method": method})
    pre = res["precession"]
    W = np.asarray(pre["trajectory"]["omega_body"])
    I = np.asarray(moments)
    E = 0.5 * (I * W * W).sum(axis=1)
    M = np.linalg.norm(I * W, axis=1)
    E0, M0 = 0.5 * I @ (np.asarray(omega) ** 2), np.linalg.norm(I * omega)
    seen_e = float(np.max(np.abs(E / E0 - 1)))
    seen_m = float(np.max(np.abs(M / M0 - 1)))
    d = pre["diagnostics"]
    assert d["energy_drift"] >= 0.5 * seen_e - 1e-15, (d, seen_e)
    assert d["momentum_drift"] >= 0.5 * seen_m - 1e-15, (d, seen_m)


def test_points_endpoint_accepts_the_method(client: TestClient) -> None:
    body = {**TRIATOMIC, "omega": [0.2, 1.0, 0.3], "duration": 2.0, "samples": 5, "method": "dop853"}
    res = points_ok(client, body)
    I = np.asarray(res["inertia_tensor"], float)
    check_trajectory(res["precession"], res["principal"]["moments"], res["principal"]["axes"], body["omega"], 2.0, 5, I, tol=1e-5)


def test_moments_equal_only_within_tolerance_are_not_rounded_in_momentum_and_energy(client: TestClient) -> None:
    """Same as the hex_prism case through /v1/precession: M = diag(I) Ω exactly for the given moments."""
    moments, omega = [1.0, 2.0, 2.0 + 1e-9], [0.3, 0.4, 0.5]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega})
    assert res["classification"]["kind"] == "symmetric_top"
    assert res["classification"]["asymmetry"] == pytest.approx(ray_kappa(moments), rel=1e-12, abs=0)
    check_invariants(res["precession"], np.diag(moments), omega)
