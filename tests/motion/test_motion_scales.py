"""Torque-free motion at any scale of the moments and of Omega (L&L §36: only the moments' ratios matter).

Euler's equations depend on the moments only through their ratios, and Omega(t) -> c Omega(c t) maps
solutions to solutions, while M and E scale as I Omega and I Omega^2.  Expected values come from the
closed form of L&L §37 in mpmath (``elliptic_reference``, at 60 digits and mpmath's unbounded exponent
range) and from M = I Omega, E = Omega.I Omega / 2 evaluated in mpmath, never from the code under test.
Before the motion was computed in power-of-two units, moments below ~1e-125 divided by zero, above
~1e125 gave a non-finite number (ValueError), and an Omega below ~1e-154 was reported as "rest" with
M = E = 0 (its squared norm underflowed).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import mpmath as mp
import numpy as np
import pytest
from fastapi.testclient import TestClient
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from inertia import precession
from inertia.errors import InvalidParameterError
from tests.support.motion import elliptic_reference, ll_period

EPS = float(np.finfo(float).eps)
MOMENTS = (1.0, 2.0, 3.0)
OMEGA = (1.0, 0.01, 0.5)


def _invariants(moments: Any, omega: Any) -> tuple[float, float]:
    """|M| and E of the state as given, in mpmath (exact inputs, 60 digits)."""
    with mp.workdps(60):
        inertia = [mp.mpf(float(x)) for x in moments]
        w = [mp.mpf(float(x)) for x in omega]
        m = mp.sqrt(sum((a * b) ** 2 for a, b in zip(inertia, w)))
        e = sum(a * b * b for a, b in zip(inertia, w)) / 2
        return float(m), float(e)


def _check_against_reference(res: Any, moments: Any, omega: Any, t: np.ndarray) -> None:
    motion = res.motion
    magnitude, energy = _invariants(moments, omega)
    assert motion.angular_momentum_magnitude == pytest.approx(magnitude, rel=4 * EPS, abs=0)
    assert motion.kinetic_energy == pytest.approx(energy, rel=4 * EPS, abs=0)
    assert motion.regime.value == "asymmetric"
    assert motion.trajectory is not None
    speed = max(abs(x) for x in omega)
    reference = elliptic_reference(moments, omega, t, dps=60)
    error = float(np.max(np.abs(motion.trajectory.omega_body - reference))) / speed
    turned = speed * float(t[-1])
    assert error <= 8 * EPS * (1 + turned), error


@pytest.mark.parametrize("scale", [1e-300, 1e-200, 1e-125, 1e125, 1e200, 1e300])
def test_moments_at_any_scale_move_as_their_ratios(scale: float) -> None:
    moments = tuple(scale * x for x in MOMENTS)
    t = np.linspace(0.0, 30.0, 7)
    res = precession(OMEGA, principal_moments=moments, duration=30.0, samples=7)
    _check_against_reference(res, moments, OMEGA, t)


@pytest.mark.parametrize("scale", [1e-150, 1e-100, 1e-160, 1e100, 1e150])
def test_tiny_and_huge_spins_scale_time_as_one_over_omega(scale: float) -> None:
    omega = tuple(scale * x for x in OMEGA)
    duration = 30.0 / scale
    t = np.linspace(0.0, duration, 7)
    moments = (1e-150, 2e-150, 3e-150) if scale > 1 else (1e150, 2e150, 3e150)
    res = precession(omega, principal_moments=moments, duration=duration, samples=7)
    _check_against_reference(res, moments, omega, t)
    assert res.motion.period is not None
    assert res.motion.period == pytest.approx(ll_period(moments, omega), rel=1e-14)  # L&L 4K/rate, mpmath


def test_http_precession_of_moments_of_1e_minus_200() -> None:
    """The reported gap: a 422 ZeroDivisionError before; the motion of the ratios now."""
    from inertia.api import create_app

    body = {"principal_moments": [1e-200, 2e-200, 3e-200], "omega": [1, 0.01, 0.5], "duration": 30.0, "samples": 4}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        response = TestClient(create_app()).post("/v1/precession", json=body)
    assert response.status_code == 200, response.text
    section = response.json()["precession"]
    magnitude, energy = _invariants(body["principal_moments"], body["omega"])
    assert section["angular_momentum_magnitude"] == pytest.approx(magnitude, rel=4 * EPS)
    assert section["kinetic_energy"] == pytest.approx(energy, rel=4 * EPS)
    reference = elliptic_reference(MOMENTS, OMEGA, np.linspace(0.0, 30.0, 4), dps=60)
    assert np.max(np.abs(np.asarray(section["trajectory"]["omega_body"]) - reference)) <= 1e-13


@pytest.mark.parametrize(
    ("moments", "omega", "what"),
    [
        (MOMENTS, (1e-300, 1e-302, 5e-301), "underflow"),  # E ~ 1e-600: was reported as "rest", M = E = 0
        ((1e-200, 2e-200, 3e-200), (1e-60, 1e-61, 1e-60), "underflow"),  # E ~ 1e-320, subnormal
        ((1e200, 2e200, 3e200), (1e60, 1e58, 1e60), "overflow"),  # E ~ 1e320
        (MOMENTS, (5e-324, 0.0, 0.0), "underflow"),  # a subnormal Omega keeps one bit
    ],
)
def test_numbers_beyond_float64_are_refused_not_reported(moments: Any, omega: Any, what: str) -> None:
    with pytest.raises(InvalidParameterError, match=what):
        precession(omega, principal_moments=moments)


_EXPONENTS = st.integers(-500, 500)
_POSITIVE = st.floats(1.0, 2.0)  # I1 + I2 >= I3 holds for any three
_COMPONENT = st.one_of(st.just(0.0), st.floats(0.001, 2.0), st.floats(-2.0, -0.001))


@settings(max_examples=40, deadline=None)
@given(
    st.tuples(_POSITIVE, _POSITIVE, _POSITIVE),
    st.tuples(_COMPONENT, _COMPONENT, _COMPONENT),
    _EXPONENTS,
    _EXPONENTS,
    st.sampled_from(["exact", "dop853", "splitting"]),
)
def test_power_of_two_units_change_the_motion_exactly(
    moments: tuple[float, float, float], omega: tuple[float, float, float], a: int, b: int, method: str
) -> None:
    """Moments x 2^a and Omega x 2^b: Omega, rates x 2^b, M x 2^(a+b), E x 2^(a+2b), times x 2^-b, to the bit."""
    moments = tuple(sorted(moments))  # type: ignore[assignment]
    assume(max(abs(x) for x in omega) > 0.01)
    duration = 3.0
    scaled_m = tuple(math.ldexp(x, a) for x in moments)
    scaled_w = tuple(math.ldexp(x, b) for x in omega)
    # stay where every input and output is a normal float64 (there a power of two is exact)
    assume(-900 < a + b < 900 and -900 < a + 2 * b < 900)
    base = precession(omega, principal_moments=moments, duration=duration, samples=5, method=method).motion
    scaled = precession(scaled_w, principal_moments=scaled_m, duration=math.ldexp(duration, -b), samples=5, method=method).motion
    assert scaled.regime is base.regime
    assert scaled.angular_momentum_magnitude == math.ldexp(base.angular_momentum_magnitude, a + b)
    assert scaled.kinetic_energy == math.ldexp(base.kinetic_energy, a + 2 * b)
    assert np.array_equal(scaled.angular_momentum, np.ldexp(base.angular_momentum, a + b))
    for name, power in (("body_precession_rate", b), ("spin_rate", b), ("period", -b), ("flip_interval", -b)):
        value = getattr(base, name)
        assert getattr(scaled, name) == (None if value is None else math.ldexp(value, power)), name
    assert base.trajectory is not None and scaled.trajectory is not None
    assert np.array_equal(scaled.trajectory.t, np.ldexp(base.trajectory.t, -b))
    assert np.array_equal(scaled.trajectory.omega_body, np.ldexp(base.trajectory.omega_body, b))
    assert np.array_equal(scaled.trajectory.omega, np.ldexp(base.trajectory.omega, b))
    assert np.array_equal(scaled.trajectory.quaternion, base.trajectory.quaternion)


@pytest.mark.parametrize("method", ["exact", "dop853", "rk45", "splitting"])
def test_a_duration_whose_turn_underflows_is_a_still_trajectory(method: str) -> None:
    # |omega| 1e-150 rad/s for 1e-200 s turns the body by 1e-350 rad, below float64: every sample is the start
    # (scipy's solvers return no samples for the empty interval the scaled time becomes)
    result = precession(principal_moments=[1, 2, 3], omega=[1e-150, 0, 1e-150], duration=1e-200, samples=5, method=method)
    doc = result.as_dict()["precession"]["trajectory"]
    assert doc["t"] == pytest.approx([0, 2.5e-201, 5e-201, 7.5e-201, 1e-200], rel=1e-15)
    assert all(q == [1.0, 0.0, 0.0, 0.0] for q in doc["quaternion"])
    assert all(w == [1e-150, 0.0, 1e-150] for w in doc["omega_body"])
