"""States at and within rounding of a degenerate regime move as the numbers given (L&L §37).

Expected values: L&L §37's closed form evaluated by mpmath at 90 digits from the exact float inputs
(``elliptic_reference``), where the distance to the separatrix, a difference of products of four
doubles, is exact.  Before, a state within 16 eps of the separatrix moved along the separatrix's
hyperbolic limit and one within 16 eps of a principal axis did not move at all: both part from the
true motion by O(1) after ~ln(1/gap)/rate, while the invariants (the only diagnostics) stayed at 1e-16.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np
import pytest

from benchmarks.cases import box
from inertia import analyze, analyze_points, precession
from inertia.motion import predict_motion
from inertia.options import AnalysisOptions
from tests.support.motion import body, elliptic_reference

EPS = float(np.finfo(float).eps)


def _omega_error(moments: Any, omega: Any, duration: float, samples: int = 9) -> tuple[Any, float]:
    res = precession(omega, principal_moments=moments, duration=duration, samples=samples)
    assert res.motion.trajectory is not None
    t = np.linspace(0.0, duration, samples)
    reference = elliptic_reference(moments, omega, t, dps=90)
    speed = float(np.linalg.norm(omega))
    return res, float(np.max(np.abs(res.motion.trajectory.omega_body - reference))) / speed


# I = (3, 4, 6): I3 (I3 - I2) = 12 = 4 I1 (I2 - I1), so Omega = (2, W2, 1) is exactly on the separatrix.
@pytest.mark.parametrize("ulps", [1, -1, 4, -8])
def test_within_rounding_of_the_separatrix_moves_as_given(ulps: int) -> None:
    w1 = 2.0 + ulps * math.ulp(2.0) if ulps > 0 else 2.0 + ulps * math.ulp(1.0)
    omega = (w1, 0.3, 1.0)
    res, error = _omega_error((3.0, 4.0, 6.0), omega, duration=300.0)
    assert res.motion.period is None  # API.md: within tolerance of the separatrix, no period
    assert any("within rounding of the separatrix" in w for w in res.warnings)
    # the true motion passes the intermediate axis every ~100 s; the separatrix's limit never does
    assert error <= 8 * EPS * (1 + np.linalg.norm(omega) * 300.0), error


def test_exactly_on_the_separatrix_still_follows_the_hyperbolic_limit() -> None:
    res, error = _omega_error((3.0, 4.0, 6.0), (2.0, 0.3, 1.0), duration=300.0)
    assert res.motion.period is None
    assert any("separatrix (2 E I2 = |M|^2 exactly)" in w for w in res.warnings)
    assert error <= 1e-13


@pytest.mark.parametrize("axis", [0, 1, 2])
@pytest.mark.parametrize("tilt", [1e-17, 1e-15])
def test_a_real_tilt_off_a_principal_axis_is_not_snapped(axis: int, tilt: float) -> None:
    """Principal moments given: the axes are exact, so a tilt of 1e-17 is the motion's, not rounding.

    About the intermediate axis it grows like exp(rate t) into a flip (the tennis-racket motion)."""
    omega = [tilt, tilt, tilt]
    omega[axis] = 1.0
    res, error = _omega_error((1.0, 2.0, 3.0), omega, duration=300.0)
    assert res.motion.regime.value == "asymmetric"
    assert res.motion.stable is (axis != 1)
    assert error <= 8 * EPS * (1 + 300.0), error
    if axis == 1:
        assert res.motion.flip_interval is not None and res.motion.flip_interval < 150.0


def test_an_exact_principal_axis_is_still_permanent_rotation() -> None:
    res = precession((0.0, 1.0, 0.0), principal_moments=(1.0, 2.0, 3.0))
    assert res.motion.regime.value == "permanent_rotation" and res.motion.stable is False


def _exact_motion(moments: Any, omega: Any, duration: float, samples: int) -> Any:
    """The motion of principal moments declared exact (``exact_moments``), axes the input axes."""
    frame, classification = body(moments)
    return predict_motion(frame, classification, np.asarray(omega), duration=duration, samples=samples, exact_moments=True)


@pytest.mark.parametrize("ulps", [1, 4, 32, 63])
@pytest.mark.parametrize("shape", ["oblate", "prolate", "spherical"])
def test_exact_moments_a_few_ulps_apart_move_as_given(ulps: int, shape: str) -> None:
    """Moments declared exact: a gap of one ulp is the body's, not rounding to be idealised.

    Replacing such moments by their mean (the symmetric or spherical closed form, what computed
    moments get) is off by up to 25 eps per radian turned, three times the 8 eps per radian the exact
    motion keeps."""
    gap = ulps * EPS
    moments = {
        "oblate": (1.0, 1.0 + gap, 2.0),
        "prolate": (1.0, 2.0 - 2 * gap, 2.0),
        "spherical": (1.0, 1.0 + gap, 1.0 + 3 * gap),
    }[shape]
    omega = (0.6, 0.5, 0.4)
    duration, samples = 1e4, 9
    motion = _exact_motion(moments, omega, duration, samples)
    reference = elliptic_reference(moments, omega, np.linspace(0.0, duration, samples), dps=90)
    speed = float(np.linalg.norm(omega))
    error = float(np.max(np.abs(motion.trajectory.omega_body - reference))) / speed
    assert error <= 8 * EPS * (1 + speed * duration), error
    # the section names the class the moments are given within the default tolerance (API.md: regular
    # precession for a symmetric top), while the trajectory above is the motion of the moments as given
    assert motion.regime.value == {"oblate": "regular_precession", "prolate": "regular_precession", "spherical": "spherical"}[shape]


def test_a_needle_whose_smallest_moment_is_exact_moves_as_the_prolate_top_it_is() -> None:
    """I = (1e-20, 1, 1) declared exact: the spin about the needle's axis turns Omega_perp in the body
    (L&L eq. 36.7) at omega = Omega_1 (I1 - I_perp) / I_perp; a linear rotator (I1 = 0) drops Omega_1."""
    import mpmath as mp

    moments, omega = (1e-20, 1.0, 1.0), (1.0, 0.5, 0.2)
    duration, samples = 10.0, 6
    motion = _exact_motion(moments, omega, duration, samples)
    with mp.workdps(40):
        rate = mp.mpf(omega[0]) * (mp.mpf(moments[0]) - 1) / 1
        expected = []
        for t in np.linspace(0.0, duration, samples):
            z = (mp.mpf(omega[1]) + 1j * mp.mpf(omega[2])) * mp.expj(rate * mp.mpf(float(t)))
            expected.append([omega[0], float(z.real), float(z.imag)])
    assert np.max(np.abs(motion.trajectory.omega_body - np.array(expected))) <= 1e-14
    # labelled with its class's regime (a linear rotator within the default tolerance, API.md), a warning
    # says the motion and its rates are the needle's own
    assert motion.regime.value == "rotator" and len(motion.warnings) == 1
    assert motion.body_precession_rate == pytest.approx(float(rate), rel=1e-15)


@pytest.mark.parametrize("offset", [0.0, 0.1])
def test_computed_moments_of_an_axis_aligned_cube_stay_a_spherical_top(offset: float) -> None:
    """A cube's computed moments differ by rounding even where its principal axes come out exact (axis
    aligned): they keep the spherical closed form (Omega constant), as computed moments always have."""
    vertices, faces = box(1.0, 1.0, 1.0)
    result = analyze((vertices + offset, faces), options=AnalysisOptions(omega=(0.3, 0.5, 0.7), duration=10.0, samples=3))
    assert result.motion is not None and result.motion.regime.value == "spherical"
    assert result.motion.trajectory is not None
    assert np.array_equal(result.motion.trajectory.omega_body, np.tile([0.3, 0.5, 0.7], (3, 1)))


@pytest.mark.parametrize("i2", [1.0 - 2.0**-53, 1.0 - 1e-7])
def test_a_zero_smallest_moment_is_a_linear_rotator_whatever_rounding_left(i2: float) -> None:
    """I1 = 0 puts all mass on a line, so I2 = I3 (L&L §32); the triangle inequality admits a gap of
    rounding (or of the tolerance).  Such moments divided by I1 = 0 (ZeroDivisionError, a 422 that
    said the numbers were too large or too small) before; the rotator turns uniformly about M."""
    omega = (0.0, 0.5, 0.2)
    res = precession(omega, principal_moments=(0.0, i2, 1.0), duration=5.0, samples=3)
    assert res.motion.regime.value == "rotator"
    assert res.motion.trajectory is not None
    assert np.array_equal(res.motion.trajectory.omega_body, np.tile([0.0, 0.5, 0.2], (3, 1)))
    assert any("their mean was used" in w for w in res.warnings) is (1.0 - i2 > 1e-12)


@pytest.mark.parametrize("spin", [0.3, -1.7])
def test_a_rotator_spun_about_its_axis_too_is_the_needles_limit(spin: float) -> None:
    """A spin about a linear rotator's own axis carries no M or E; it was dropped, so the trajectory's
    Omega(0) was not the one given.  Kept, the motion is a needle's regular precession as I1 -> 0: the
    same trajectory as the symmetric top (L&L §33, its own closed form) of I1 = 1e-12, to ~1e-12."""
    omega = (spin, 0.5, 0.2)
    rotator = precession(omega, principal_moments=(0.0, 1.0, 1.0), duration=7.0, samples=15).motion
    needle = precession(omega, principal_moments=(1e-12, 1.0, 1.0), tolerance=1e-15, duration=7.0, samples=15).motion
    assert rotator.regime.value == "rotator" and needle.regime.value == "regular_precession"
    assert rotator.trajectory is not None and needle.trajectory is not None
    assert np.array_equal(rotator.trajectory.omega_body[0], omega)
    np.testing.assert_allclose(rotator.trajectory.omega_body, needle.trajectory.omega_body, rtol=0, atol=1e-10)
    np.testing.assert_allclose(rotator.trajectory.quaternion, needle.trajectory.quaternion, rtol=0, atol=1e-10)
    np.testing.assert_allclose(rotator.trajectory.omega, needle.trajectory.omega, rtol=0, atol=1e-10)
    assert rotator.body_precession_rate == pytest.approx(needle.body_precession_rate, rel=1e-11)
    assert rotator.spin_rate == pytest.approx(needle.spin_rate, rel=1e-11)
    assert rotator.space_precession_rate == pytest.approx(needle.space_precession_rate, rel=1e-11)
    drifts = (rotator.diagnostics.energy_drift, rotator.diagnostics.momentum_drift)
    assert all(d is not None and d <= 1e-15 for d in drifts)


def test_a_rotator_spun_only_about_its_axis_is_a_permanent_rotation_not_rest() -> None:
    res = precession((2.0, 0.0, 0.0), principal_moments=(0.0, 1.0, 1.0), duration=1.0, samples=3).motion
    assert res.regime.value == "permanent_rotation" and res.stable is True
    assert res.trajectory is not None
    assert np.array_equal(res.trajectory.omega, np.tile([2.0, 0.0, 0.0], (3, 1)))
    half = np.array([np.cos(0.5), np.sin(0.5), 0.0, 0.0])  # turned by 1 rad about x after 0.5 s
    np.testing.assert_allclose(res.trajectory.quaternion[1], half, rtol=0, atol=1e-15)


def test_rounding_level_permanent_rotation_about_the_intermediate_axis_says_when_it_stops_holding() -> None:
    """A rotated tensor spun along its intermediate axis: axes @ omega carries ~1e-15 of noise, which the
    regime treats as zero (permanent rotation, unstable).  Over a long horizon the result says when such
    a tilt becomes a flip: a quarter of L&L's period (mpmath) of the state with that noise."""
    from tests.support.motion import ll_period

    rotation = np.array([[0.36, 0.48, -0.8], [-0.8, 0.6, 0.0], [0.48, 0.64, 0.6]])
    tensor = rotation.T @ np.diag([1.0, 2.0, 3.0]) @ rotation
    omega = list(2.0 * rotation[1])
    short = precession(omega, inertia_tensor=tensor, duration=10.0, samples=3)
    assert short.motion.regime.value == "permanent_rotation" and short.motion.stable is False
    assert not any("intermediate axis only to rounding" in w for w in short.warnings)
    long = precession(omega, inertia_tensor=tensor, duration=1000.0, samples=3)
    stated = [w for w in long.warnings if "intermediate axis only to rounding" in w]
    assert len(stated) == 1
    found = re.search(r"flip after about ([0-9.e+-]+) s", stated[0])
    assert found is not None
    noisy = np.asarray(long.frame.axes) @ np.asarray(omega)
    assert float(found.group(1)) == pytest.approx(ll_period(long.frame.moments, noisy) / 4, rel=0.1)


@pytest.mark.parametrize("ulps", [(32, 64), (1, 2)])
def test_principal_moments_given_within_rounding_of_equal_move_as_the_numbers_given(ulps: tuple[int, int]) -> None:
    # moments a client sends are its own numbers, not rounded results: (1, 1 + 32 eps, 1 + 64 eps) is an
    # asymmetric top whose Omega turns slowly, not a spherical top whose Omega stays put
    moments = (1.0, 1.0 + ulps[0] * EPS, 1.0 + ulps[1] * EPS)
    _, error = _omega_error(moments, (0.6, 0.5, 0.4), duration=1e4)
    assert error <= 64 * EPS, error  # the ideal top's closed form was 1e-12..4e-11 off by t = 1e4


def test_a_rotators_spin_of_rounding_is_no_spin() -> None:
    # three collinear points turned off the axes, Omega across the line: the axial component of Omega_body is the
    # rounding of the turned axes (~1e-16), not a spin with a period of 4e16 s
    from scipy.spatial.transform import Rotation

    line = Rotation.from_euler("zyx", [0.3, 0.7, 1.1]).as_matrix()[:, 0]
    across = np.cross(line, [0.0, 0.0, 1.0])
    points = [{"mass": m, "position": (t * line).tolist()} for m, t in ((1.0, -1.0), (2.0, 0.5), (1.0, 1.5))]
    result = analyze_points(points, AnalysisOptions(omega=tuple(across / np.linalg.norm(across))))
    assert result.motion is not None and result.motion.regime.value == "rotator"
    assert result.motion.period is None and result.motion.spin_rate is None and result.motion.body_precession_rate is None
