"""Issue 12: the estimate of a tensor given to /v1/precession comes from its conditioning.

Reference: the eigenvalues of the float64 tensor exactly as given, computed by
mpmath (``mpmath.eigsy``) at 50 digits.  The estimate must never be below the
error of the returned moments, from I1/I3 = 1 down to 1e-12.
"""

from __future__ import annotations

import itertools

import mpmath as mp
import numpy as np
import pytest
from scipy.stats import special_ortho_group

from inertia import precession
from inertia.errors import InvalidParameterError

EPS = np.finfo(float).eps


def _reference(tensor: np.ndarray) -> list[mp.mpf]:
    with mp.workdps(50):
        values, _ = mp.eigsy(mp.matrix(tensor.tolist()))
        return sorted(values[i] for i in range(3))


@pytest.mark.parametrize("exponent", np.linspace(0.0, -12.0, 13))
def test_rotated_tensor_estimate_is_never_below_the_error(exponent: float) -> None:
    rng = np.random.default_rng(int(-exponent * 10) + 1)
    worst = 0.0
    for _ in range(20):
        i3 = 10 ** rng.uniform(-6, 6)
        i1 = i3 * 10**exponent
        i2 = rng.uniform(max(i1, i3 - i1), i3)  # a body: I1 + I2 >= I3
        r = special_ortho_group.rvs(3, random_state=rng)
        tensor = r @ np.diag([i1, i2, i3]) @ r.T
        tensor = 0.5 * (tensor + tensor.T)
        res = precession([0.1, 0.2, 0.3], inertia_tensor=tensor)
        est = res.relative_error_estimate
        assert np.isfinite(est) and est > 0
        ref = _reference(tensor)
        with mp.workdps(50):
            for got, want in zip(res.frame.moments, ref):
                if got == 0.0:  # zero within rounding, reported as such with a warning
                    assert abs(want) <= 17 * EPS * np.linalg.norm(tensor) and res.warnings
                    continue
                actual = float(abs((mp.mpf(float(got)) - want) / want))
                assert actual <= est, (exponent, actual, est)
                worst = max(worst, actual / est)
    # an estimate of the error, not of the worst case only: at I1/I3 = 1e-12 it is ~1e-3
    if exponent <= -6:
        assert res.relative_error_estimate > 1e3 * EPS
    assert worst < 1.0


def test_the_estimate_scales_with_the_conditioning() -> None:
    r = special_ortho_group.rvs(3, random_state=5)
    estimates = []
    for ratio in (1.0, 1e-4, 1e-8, 1e-12):
        tensor = r @ np.diag([ratio, 1.0, 1.0]) @ r.T
        estimates.append(precession([0, 0, 1.0], inertia_tensor=0.5 * (tensor + tensor.T)).relative_error_estimate)
    assert estimates[0] < 1e-13 and estimates[-1] > 1e-4
    assert all(a < b for a, b in itertools.pairwise(estimates))


def test_principal_moments_as_given_keep_a_rounding_estimate() -> None:
    res = precession([0.1, 0.2, 0.3], principal_moments=[1e-12, 1.0, 1.0])
    assert res.relative_error_estimate <= 1e-14


def test_a_rod_tensor_reports_zero_not_a_negative_moment() -> None:
    r = special_ortho_group.rvs(3, random_state=9)
    tensor = r @ np.diag([0.0, 1.0, 1.0]) @ r.T
    res = precession([0.3, -0.2, 1.0], inertia_tensor=0.5 * (tensor + tensor.T), duration=1.0, samples=3)
    assert res.frame.moments[0] == 0.0 and np.all(res.frame.moments >= 0)
    assert res.classification.kind == "linear_rotator" and res.motion.regime.value == "rotator"
    assert any("zero within the rounding" in w for w in res.warnings)
    assert np.isfinite(res.relative_error_estimate)


def test_a_negative_moment_beyond_rounding_is_refused() -> None:
    with pytest.raises(InvalidParameterError, match="negative principal moment"):
        precession([0, 0, 1.0], inertia_tensor=np.diag([-1e-9, 1.0, 1.0]))
