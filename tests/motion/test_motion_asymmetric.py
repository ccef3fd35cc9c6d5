"""Asymmetric top, exact path: against L&L closed forms, mpmath and DOP853 at rtol 1e-12."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from inertia.conventions import orient_axes
from inertia.errors import MotionError
from inertia.motion import Regime, predict_motion
from tests.support.motion import body, euler_reference, ll_period, quaternion_matrix

# principal axes as rows in the input frame, signs already by the convention's rule
ROT = orient_axes(Rotation.from_euler("zyx", [0.3, 0.5, -0.7]).as_matrix())

GENERIC = [
    ((1.0, 2.0, 3.0), (0.3, 0.2, 1.0)),  # about x3
    ((1.0, 2.0, 3.0), (1.0, 0.4, 0.1)),  # about x1
    ((1.0, 2.0, 3.0), (-0.3, 0.5, -1.0)),  # signs
    ((1.0, 2.0, 3.0), (-0.05, 1.0, 0.2)),  # near the intermediate axis, about x3
    ((1.0, 1.1, 3.0), (0.9, -0.2, 0.5)),  # reference axis x3 for the attitude
    ((1.0, 1.2, 3.0), (-1.0, -0.05, 0.05)),  # about x1, reference axis x3
    ((0.4, 1.5, 1.7), (0.7, -0.5, 0.3)),
]


def _predict(moments: Any, omega_body: Any, rotation: Any = ROT, tolerance: float = 1e-6, **kw: Any) -> Any:
    frame, cls = body(moments, rotation, tolerance)
    return predict_motion(frame, cls, np.asarray(rotation).T @ np.asarray(omega_body, dtype=float), **kw)


@pytest.mark.parametrize("moments, omega", GENERIC)
def test_period_is_4K_over_rate(moments: Any, omega: Any) -> None:
    motion = _predict(moments, omega)
    assert motion.regime is Regime.ASYMMETRIC
    expected = ll_period(moments, omega)
    assert abs(motion.period - expected) <= 1e-13 * expected


@pytest.mark.parametrize("moments, omega", GENERIC)
def test_omega_and_attitude_match_dop853(moments: Any, omega: Any) -> None:
    t = np.linspace(0.0, 25.0, 201)
    motion = _predict(moments, omega, duration=25.0, samples=201)
    w_ref, r_ref = euler_reference(moments, omega, t)
    traj = motion.trajectory
    scale = np.linalg.norm(omega)
    assert np.max(np.abs(traj.omega_body - w_ref)) <= 1e-9 * scale
    # reported attitude in the input frame -> body frame at t = 0: R~ = A q A^T
    r_body = ROT @ quaternion_matrix(traj.quaternion) @ ROT.T
    assert np.max(np.abs(r_body - r_ref)) <= 1e-9
    # Omega in the input frame is the attitude applied to Omega_body taken through the axes at t = 0
    omega_in = np.einsum("nij,nj->ni", quaternion_matrix(traj.quaternion), traj.omega_body @ ROT)
    assert np.max(np.abs(traj.omega - omega_in)) <= 1e-14 * scale


@pytest.mark.parametrize("moments, omega", GENERIC[:3])
def test_momentum_in_input_frame_is_constant(moments: Any, omega: Any) -> None:
    motion = _predict(moments, omega, duration=1e3, samples=2001)
    traj = motion.trajectory
    m_body = traj.omega_body * np.asarray(moments)
    m_in = np.einsum("nij,nj->ni", quaternion_matrix(traj.quaternion), m_body @ ROT)
    m0 = np.asarray(motion.angular_momentum)
    assert np.max(np.linalg.norm(m_in - m0, axis=1)) <= 1e-10 * np.linalg.norm(m0)
    assert motion.diagnostics.momentum_drift <= 1e-13
    assert motion.diagnostics.energy_drift <= 1e-13


def test_quaternions_are_unit_and_identity_at_zero() -> None:
    motion = _predict((1.0, 2.0, 3.0), (0.3, 0.2, 1.0), duration=50.0, samples=501)
    q = motion.trajectory.quaternion
    assert np.max(np.abs(np.linalg.norm(q, axis=1) - 1.0)) <= 4e-16
    assert np.max(np.abs(q[0] - [1.0, 0.0, 0.0, 0.0])) <= 1e-15
    assert np.all(q[:, 0] >= 0.0)


def test_flip_near_intermediate_axis() -> None:
    """Started 1e-3 off x2, Omega2 reverses every half period (the tennis-racket flip)."""
    moments, omega = (1.0, 2.0, 3.0), (1e-3, 1.0, 1e-3)
    motion = _predict(moments, omega, duration=300.0, samples=30001)
    assert motion.stable is False
    assert motion.flip_interval == pytest.approx(0.5 * ll_period(moments, omega), rel=1e-13)
    w2 = motion.trajectory.omega_body[:, 1]
    t = motion.trajectory.t
    crossings = t[:-1][np.sign(w2[:-1]) != np.sign(w2[1:])]
    assert len(crossings) >= 3
    assert np.allclose(np.diff(crossings), motion.flip_interval, atol=2 * (t[1] - t[0]))
    # between flips Omega stays near the intermediate axis, +-|Omega|
    assert np.max(np.abs(w2)) == pytest.approx(1.0, rel=1e-5)


def test_stable_when_nearest_an_extreme_axis() -> None:
    motion = _predict((1.0, 2.0, 3.0), (0.3, 0.2, 1.0))
    assert motion.stable is True and motion.flip_interval is None


def test_separatrix_has_no_period_and_follows_the_hyperbolic_limit() -> None:
    # I = (3, 5, 6), Omega = (1, W2, 1): I3 (I3 - I2) W3^2 = I1 (I2 - I1) W1^2 = 6 exactly, so 2 E I2 = M^2.
    moments, omega = (3.0, 5.0, 6.0), (1.0, 0.3, 1.0)
    motion = _predict(moments, omega, rotation=np.eye(3), duration=40.0, samples=401)
    assert motion.period is None and motion.flip_interval is None
    assert any("separatrix" in w for w in motion.warnings)
    # L&L §37 at k = 1: Omega2 = A2 tanh(rate t + u0), A2^2 = D3 / (I2 (I3 - I2)), rate^2 = (I3 - I2) D1 / (I1 I2 I3)
    I1, I2, I3 = moments
    W1, W2, W3 = omega
    D3 = I1 * (I3 - I1) * W1**2 + I2 * (I3 - I2) * W2**2
    D1 = I2 * (I2 - I1) * W2**2 + I3 * (I3 - I1) * W3**2
    a2, rate = np.sqrt(D3 / (I2 * (I3 - I2))), np.sqrt((I3 - I2) * D1 / (I1 * I2 * I3))
    t = motion.trajectory.t
    expected = a2 * np.tanh(rate * t + np.arctanh(W2 / a2))
    assert np.max(np.abs(motion.trajectory.omega_body[:, 1] - expected)) <= 1e-13
    w_ref, _ = euler_reference(moments, omega, t[:101])
    assert np.max(np.abs(motion.trajectory.omega_body[:101] - w_ref)) <= 1e-8


@pytest.mark.parametrize("side", [+1.0, -1.0])
def test_within_1e_12_of_the_separatrix(side: Any) -> None:
    """2E I2 / M^2 - 1 ~ 1e-12 on either side: k'^2 ~ 1e-12, m rounds to 1 if formed as 1 - k'^2."""
    moments = (1.0, 2.0, 3.0)
    omega = (1.0, 0.4, np.sqrt((1.0 + side * 1e-12) / 3.0))  # I3 (I3 - I2) W3^2 - I1 (I2 - I1) W1^2 = +-1e-12
    # principal = input frame: a rotated input would perturb omega_body by ~1e-16, i.e. the
    # 1e-12 distance to the separatrix by ~1e-4 and the period with it (conditioning of the problem)
    # a tolerance below the distance: with the default 1e-6 the state is on the separatrix (API.md), no period
    assert _predict(moments, omega, rotation=np.eye(3)).period is None
    motion = _predict(moments, omega, rotation=np.eye(3), tolerance=1e-13, duration=1e5, samples=20001)
    expected = ll_period(moments, omega)
    assert abs(motion.period - expected) <= 1e-12 * expected
    assert motion.diagnostics.energy_drift <= 1e-12 and motion.diagnostics.momentum_drift <= 1e-12
    # up to the first approach to x2: beyond, any 1e-16 difference grows like exp(rate t)
    t = np.linspace(0.0, 20.0, 41)
    short = _predict(moments, omega, rotation=np.eye(3), tolerance=1e-13, duration=20.0, samples=41)
    w_ref, _ = euler_reference(moments, omega, t)
    assert np.max(np.abs(short.trajectory.omega_body - w_ref)) <= 1e-8


@pytest.mark.parametrize("eps, on", [(1e-8, True), (1e-7, True), (3e-7, True), (3e-6, False), (1e-5, False)])
def test_within_the_requested_tolerance_of_the_separatrix_there_is_no_period(eps: float, on: bool) -> None:
    # API.md: "On the separatrix itself (2E I2 = |M|^2 within tolerance) ... period is absent and a warning says
    # why". I = (1, 2, 3), Omega = (sqrt 3 (1 + eps), 0.1, 1): the relative distance |2E I2 - M^2| / M^2 is about
    # eps / 2, within the default tolerance 1e-6 up to eps = 2e-6
    moments = (1.0, 2.0, 3.0)
    omega = (np.sqrt(3.0) * (1 + eps), 0.1, 1.0)
    W1, W2, W3 = omega
    m2 = (1 * W1) ** 2 + (2 * W2) ** 2 + (3 * W3) ** 2
    two_e_i2 = 2 * (1 * W1**2 + 2 * W2**2 + 3 * W3**2)
    assert bool(abs(two_e_i2 - m2) / m2 <= 1e-6) is on
    motion = _predict(moments, omega, rotation=np.eye(3))
    assert (motion.period is None) is on
    assert any("within the tolerance of the separatrix" in w for w in motion.warnings) is on


@pytest.mark.parametrize("tilt", [1e-155, 1e-170, 1e-300])
def test_a_distance_to_the_separatrix_float64_cannot_hold_is_refused(tilt: float) -> None:
    # I = (3, 4, 6), Omega = (0, 1, tilt): 2E I2 - M^2 = -I3 (I3 - I2) tilt^2, ~1e-310 and below, exactly; k'^2 left
    # float64's normal range (a non-finite period: a 500), or rounded to 0 (taken for the separatrix: a trajectory
    # that never flipped, where the body flips every ~2400 s)
    with pytest.raises(MotionError, match="from the separatrix but not on it"):
        _predict((3.0, 4.0, 6.0), (0.0, 1.0, tilt), rotation=np.eye(3))
    assert _predict((3.0, 4.0, 6.0), (0.0, 1.0, 1e-150), rotation=np.eye(3)).period > 0


def test_started_1e_9_off_the_intermediate_axis() -> None:
    moments, omega = (1.0, 2.0, 3.0), (1e-9, 1.0, 1e-9)
    motion = _predict(moments, omega, rotation=np.eye(3), duration=1e5, samples=20001)  # see above: conditioning
    assert motion.regime is Regime.ASYMMETRIC and motion.stable is False
    assert motion.period == pytest.approx(ll_period(moments, omega), rel=1e-13)
    assert motion.diagnostics.energy_drift <= 1e-12 and motion.diagnostics.momentum_drift <= 1e-12
    assert np.min(motion.trajectory.omega_body[:, 1]) < -0.99  # it does flip
    t = np.linspace(0.0, 40.0, 41)
    w_ref, _ = euler_reference(moments, omega, t)
    short = _predict(moments, omega, rotation=np.eye(3), duration=40.0, samples=41)
    assert np.max(np.abs(short.trajectory.omega_body - w_ref)) <= 1e-9


def test_fast_spin_with_slow_asymmetry() -> None:
    """|Omega| = 1e6 rad/s, I2 - I1 = 1e-3 I1: the Jacobi phase stays accurate over ~1e4 periods."""
    moments = (1.0, 1.001, 2.0)
    omega = (6e5, 3e5, 7e5)
    period = ll_period(moments, omega)
    motion = _predict(moments, omega, duration=1e5, samples=10001)
    assert motion.period == pytest.approx(period, rel=1e-12)
    assert motion.diagnostics.energy_drift <= 1e-12 and motion.diagnostics.momentum_drift <= 1e-12
    horizon = 5 * period
    t = np.linspace(0.0, horizon, 51)
    w_ref, r_ref = euler_reference(moments, omega, t)
    short = _predict(moments, omega, rotation=np.eye(3), duration=horizon, samples=51)
    assert np.max(np.abs(short.trajectory.omega_body - w_ref)) <= 1e-9 * np.linalg.norm(omega)
    assert np.max(np.abs(quaternion_matrix(short.trajectory.quaternion) - r_ref)) <= 1e-8


@pytest.mark.parametrize("scale", [1e-30, 1e30])
def test_extreme_moment_scales_give_the_same_omega(scale: Any) -> None:
    moments, omega = np.array([1.0, 2.0, 3.0]), (0.3, 0.2, 1.0)
    unit = _predict(moments, omega, duration=1e5, samples=2001)
    scaled = _predict(moments * scale, omega, duration=1e5, samples=2001)
    assert scaled.period == pytest.approx(unit.period, rel=1e-14)
    # same to rounding of the phase: ~EPS x rate x t ~ 1e-11 rad at t = 1e5
    assert np.max(np.abs(scaled.trajectory.omega_body - unit.trajectory.omega_body)) <= 1e-10
    assert scaled.angular_momentum_magnitude == pytest.approx(scale * unit.angular_momentum_magnitude, rel=1e-14)
    assert scaled.diagnostics.energy_drift <= 1e-12 and scaled.diagnostics.momentum_drift <= 1e-12


def test_nearly_linear_asymmetric_body_matches_dop853() -> None:
    """I1 = 1e-9 I3: Omega1 swings at ~1e3 rad/s while the rest turns at ~1 rad/s."""
    moments, omega = (1e-9, 1.0, 1.001), (0.3, 0.2, 1.0)
    t = np.linspace(0.0, 0.05, 101)
    motion = _predict(moments, omega, tolerance=1e-12, duration=0.05, samples=101)
    assert motion.regime is Regime.ASYMMETRIC
    w_ref, _r_ref = euler_reference(moments, omega, t)
    assert np.max(np.abs(motion.trajectory.omega_body - w_ref)) <= 1e-8
    long = _predict(moments, omega, tolerance=1e-12, duration=1e5, samples=2001)
    assert long.diagnostics.energy_drift <= 1e-12 and long.diagnostics.momentum_drift <= 1e-12
