"""Issue 12: a nearly symmetric top moves as the body whose moments were given.

The classification's default tolerance (1e-6) labels these tops symmetric;
the motion must still be that of the moments as given, checked against
Euler's equations solved independently in mpmath (L&L §37's elliptic closed
form at 50 digits, itself checked against mpmath's Taylor-series ODE solver).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from inertia import precession
from tests.support.motion import elliptic_reference, euler_taylor_reference, trajectory

EPS = np.finfo(float).eps


def _tops(seed: int, count: int) -> Any:
    rng = np.random.default_rng(seed)
    for _ in range(count):
        gap = 10 ** rng.uniform(-13, -6.3)  # above rounding, below the default tolerance
        scale = 10 ** rng.uniform(-3, 3)
        if rng.random() < 0.5:
            moments = (1.0 * scale, (2.0 - gap) * scale, 2.0 * scale)  # nearly prolate
        else:
            moments = (1.0 * scale, (1.0 + gap) * scale, 2.0 * scale)  # nearly oblate
        yield moments, rng.normal(size=3)


def test_the_elliptic_reference_solves_eulers_equations() -> None:
    t = np.linspace(0.0, 10.0, 6)
    for moments, omega in _tops(7, 3):
        assert (
            np.max(np.abs(elliptic_reference(moments, omega, t) - euler_taylor_reference(moments, omega, t)))
            <= 1e-20 * np.linalg.norm(omega) + 1e-300
        )


@pytest.mark.parametrize("duration", [10.0, 1000.0])
def test_nearly_symmetric_tops_move_as_given_at_the_default_tolerance(duration: float) -> None:
    t = np.linspace(0.0, duration, 6)
    labelled_symmetric = 0
    for moments, omega in _tops(12, 60):
        res = precession(omega, principal_moments=moments, duration=duration, samples=len(t))
        labelled_symmetric += res.classification.kind == "symmetric_top"
        ref = elliptic_reference(moments, omega, t)
        speed = float(np.linalg.norm(omega))
        err = np.max(np.abs(trajectory(res.motion).omega_body - ref)) / speed
        # the exact motion: rounding per radian turned (measured worst 0.42 eps per radian)
        assert err <= 8 * EPS * (1 + speed * duration), (moments, omega, err)
        assert res.motion.regime.value == "regular_precession"  # the label of the class (API.md), not the motion's
    assert labelled_symmetric == 60


def test_tensor_input_of_a_nearly_symmetric_top_keeps_its_moments() -> None:
    moments, omega = (1.0, 1.0 + 3e-8, 2.0), (0.4, 0.9, 0.3)
    t = np.linspace(0.0, 10.0, 5)
    res = precession(omega, inertia_tensor=np.diag(moments), duration=10.0, samples=5)
    assert res.classification.kind == "symmetric_top"
    err = np.max(np.abs(trajectory(res.motion).omega_body - elliptic_reference(moments, omega, t)))
    assert err <= 1e-13
