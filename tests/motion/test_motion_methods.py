"""Numerical methods against the exact path; elliptic building blocks against mpmath; hypothesis invariants."""

from __future__ import annotations

from typing import Any

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia import precession
from inertia.motion import MotionMethod, Regime, predict_motion
from inertia.motion.elliptic import (
    complete_third_kind_rj,
    incomplete_first_kind,
    jacobi_sncndn,
    quarter_period,
    third_kind_rj,
)
from inertia.motion.integrators import SPLITTING_ORDER, integrate_splitting
from inertia.motion.invariants import RigidProblem
from inertia.motion.result import FreeMotion
from inertia.tolerances import Tolerances
from tests.support.motion import body, euler_reference, trajectory

MOMENTS, OMEGA = (1.0, 2.0, 3.0), (0.3, 0.2, 1.0)


def _exact(moments: Any, omega: Any, duration: float, samples: int, **kw: Any) -> FreeMotion:
    frame, cls = body(moments, **kw)
    return predict_motion(frame, cls, omega, duration=duration, samples=samples)


@pytest.mark.parametrize("method, tol", [("dop853", 1e-8), ("rk45", 1e-7), ("splitting", 1e-5)])
@pytest.mark.parametrize(
    "moments, omega", [(MOMENTS, OMEGA), ((1.0, 2.0, 3.0), (1.0, 0.4, 0.1)), ((2.0, 2.0, 3.0), (0.3, -0.4, 1.2))]
)
def test_numerical_methods_agree_with_exact(method: str, tol: float, moments: Any, omega: Any) -> None:
    frame, cls = body(moments)
    numeric = predict_motion(frame, cls, omega, duration=20.0, samples=41, method=method)
    exact = _exact(moments, omega, 20.0, 41)
    assert numeric.method is MotionMethod(method) and numeric.regime is exact.regime
    assert np.max(np.abs(trajectory(numeric).omega_body - trajectory(exact).omega_body)) <= tol
    dq = np.minimum(
        np.abs(trajectory(numeric).quaternion - trajectory(exact).quaternion).max(1),
        np.abs(trajectory(numeric).quaternion + trajectory(exact).quaternion).max(1),
    )
    assert np.max(dq) <= tol


def test_splitting_keeps_momentum_exactly_and_energy_without_drift() -> None:
    frame, cls = body(MOMENTS)
    motion = predict_motion(frame, cls, OMEGA, duration=100.0, samples=11, method="splitting")
    assert motion.diagnostics.momentum_drift is not None and motion.diagnostics.energy_drift is not None
    assert motion.diagnostics.momentum_drift <= 1e-12  # rounding only, over ~4e5 sub-rotations
    assert motion.diagnostics.energy_drift <= 1e-6  # O((h Omega)^2), bounded, not growing


def test_splitting_converges_at_its_declared_order() -> None:
    problem = RigidProblem(np.array(MOMENTS), np.array(OMEGA), np.eye(3), np.array([1.0, 0, 0, 0]))
    t = np.array([0.0, 5.0])
    exact = trajectory(_exact(MOMENTS, OMEGA, 5.0, 2)).omega_body[-1]
    steps = np.array([0.04, 0.02, 0.01, 0.005])
    errors = [np.linalg.norm(integrate_splitting(problem, t, h, 10**6)[0][-1] - exact) for h in steps]
    order = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert abs(order - SPLITTING_ORDER) <= 0.1


def test_integrator_tolerance_is_taken_from_tolerances() -> None:
    frame, cls = body(MOMENTS)
    loose = predict_motion(frame, cls, OMEGA, duration=20.0, samples=5, method="rk45", tolerances=Tolerances(integrator_rtol=1e-4))
    exact = _exact(MOMENTS, OMEGA, 20.0, 5)
    error = np.max(np.abs(trajectory(loose).omega_body - trajectory(exact).omega_body))
    assert 1e-7 < error < 1e-2


@pytest.mark.parametrize("m1", [0.9, 0.5, 1e-3, 1e-9, 2e-18])
def test_jacobi_functions_match_mpmath(m1: float) -> None:
    K = quarter_period(m1)
    u = np.linspace(-K, K, 17)
    sn, cn, dn = jacobi_sncndn(u, m1)
    with mp.workdps(40):
        m = 1 - mp.mpf(m1)
        assert abs(K - float(mp.ellipk(m))) <= 2e-16 * K
        for f, name in ((sn, "sn"), (cn, "cn"), (dn, "dn")):
            ref = np.array([float(mp.ellipfun(name, mp.mpf(x), m=m)) for x in u])
            assert np.max(np.abs(f - ref)) <= 4 * np.finfo(float).eps * K  # the argument carries ulp(K) itself
    assert np.max(np.abs(sn**2 + cn**2 - 1)) <= 2.3e-16
    assert np.max(np.abs(dn**2 + (1 - m1) * sn**2 - 1)) <= 4.5e-16


@pytest.mark.parametrize("m1, b", [(0.5, 0.3), (1e-12, 0.9), (0.99, 1e-3)])
def test_elliptic_integrals_match_mpmath(m1: float, b: float) -> None:
    phi = 1.1
    s, c = np.sin(phi), np.cos(phi)
    d = np.sqrt(c * c + m1 * s * s)
    with mp.workdps(40):
        m = 1 - mp.mpf(m1)
        F = mp.ellipf(phi, m)
        Pi = mp.ellippi(-b, phi, m)  # Pi(n; phi | m), n = -b
        Pic = mp.ellippi(-b, m)
    assert incomplete_first_kind(s, c, m1) == pytest.approx(float(F), rel=1e-15)
    pi_value = float(F) - b / 3 * third_kind_rj(np.array([s]), np.array([c]), np.array([d]), b)[0]
    assert pi_value == pytest.approx(float(Pi), rel=1e-14)
    assert quarter_period(m1) - b / 3 * complete_third_kind_rj(m1, b) == pytest.approx(float(Pic), rel=1e-14)


moments_st = (
    st.tuples(st.floats(0.1, 10.0), st.floats(0.1, 10.0), st.floats(0.1, 10.0))
    .map(sorted)
    .filter(lambda m: m[1] - m[0] > 1e-3 * m[2] and m[2] - m[1] > 1e-3 * m[2] and m[0] + m[1] >= m[2])
)
omega_st = st.tuples(st.floats(-5.0, 5.0), st.floats(-5.0, 5.0), st.floats(-5.0, 5.0)).filter(
    lambda w: sorted(abs(x) for x in w)[1] > 1e-3
)


@settings(max_examples=40, deadline=None)
@given(moments_st, omega_st, st.floats(1.0, 1e5))
def test_exact_path_keeps_energy_and_momentum(moments: Any, omega: Any, duration: float) -> None:
    motion = _exact(moments, omega, duration, 257)
    assert motion.regime is Regime.ASYMMETRIC
    assert motion.diagnostics.momentum_drift is not None and motion.diagnostics.energy_drift is not None
    assert motion.diagnostics.energy_drift <= 1e-12
    assert motion.diagnostics.momentum_drift <= 1e-12
    assert np.all(np.isfinite(trajectory(motion).quaternion))


@settings(max_examples=15, deadline=None)
@given(moments_st, omega_st)
def test_exact_path_agrees_with_dop853(moments: Any, omega: Any) -> None:
    rate = float(np.linalg.norm(omega))
    duration = 10.0 / rate  # ~10 radians: beyond, DOP853's own error grows near separatrices
    motion = _exact(moments, omega, duration, 21)
    w_ref, _r_ref = euler_reference(moments, omega, trajectory(motion).t)
    assert np.max(np.abs(trajectory(motion).omega_body - w_ref)) <= 1e-8 * rate


def _turned(axis: np.ndarray, angle: float, v: np.ndarray) -> np.ndarray:
    """v turned by ``angle`` about ``axis`` (Rodrigues)."""
    k = axis / np.linalg.norm(axis)
    turned: np.ndarray = v * np.cos(angle) + np.cross(k, v) * np.sin(angle) + k * np.dot(k, v) * (1 - np.cos(angle))
    return turned


@pytest.mark.parametrize("omega", [[0.3, 0.4, 1.0], [1.0, 0.4, 0.3], [0.2, -1.0, 0.5]])
@pytest.mark.parametrize("method", ["dop853", "rk45"])
def test_numerical_methods_estimate_covers_omega_in_space(method: str, omega: list[float]) -> None:
    # a symmetric top (transverse moment 4.5): Omega in space precesses about M at |M| / 4.5 (L&L §33); the
    # space-frame Omega carries the attitude's error twice over (a rotation angle is twice the quaternions'
    # distance), which an estimate from Omega_body and the quaternion distance alone missed by up to 1.9x
    moments, w0 = np.array([1.0, 4.5, 4.5]), np.array(omega)
    doc = precession(principal_moments=moments.tolist(), omega=omega, duration=30.0, samples=201, method=method).as_dict()
    motion = doc["precession"]
    momentum = moments * w0
    rate = float(np.linalg.norm(momentum)) / 4.5
    want = np.array([_turned(momentum, rate * t, w0) for t in motion["trajectory"]["t"]])
    error = float(np.max(np.abs(np.array(motion["trajectory"]["omega"]) - want))) / float(np.linalg.norm(w0))
    assert error <= motion["diagnostics"]["relative_error_estimate"]


@pytest.mark.parametrize("method", ["exact", "dop853", "rk45", "splitting"])
def test_the_first_sample_is_the_state_given_exactly(method: str) -> None:
    # API.md: the quaternion is the identity at t = 0; Omega there is the Omega given, not the closed forms'
    # value at their start (an elliptic function's rounding left 1e-16 in the quaternion)
    doc = precession(principal_moments=[1.0, 2.0, 3.0], omega=[0.3, 1.0, 0.2], duration=10.0, samples=3, method=method)
    trajectory = doc.as_dict()["precession"]["trajectory"]
    assert trajectory["quaternion"][0] == [1.0, 0.0, 0.0, 0.0]
    assert trajectory["omega"][0] == [0.3, 1.0, 0.2] and trajectory["omega_body"][0] == [0.3, 1.0, 0.2]
