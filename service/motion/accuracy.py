"""How far a trajectory can be trusted: the phase of long horizons, and the numerical methods' error.

Both checks look at what the invariant drifts cannot see: a trajectory that keeps E and M to 1e-16
may still be at the wrong place on its orbit.

- Phase.  Every closed form advances a phase (the elliptic argument lambda t, the precession and
  spin angles) computed from rounded frequencies, so Omega(t) and the attitude are off by up to
  ``PHASE_ERROR_PER_RADIAN`` times the radians turned (measured: 0.1 to 0.5 eps per radian against
  L&L's closed form in mpmath at 60 digits, up to 1e16 rad; the bound allows 8 eps).  Beyond
  ``PHASE_WARN`` of |Omega| the result says so; beyond ``PHASE_REFUSE`` Omega(t) is no prediction
  at all and the request is refused (ask for a shorter duration).
- Numerical methods.  dop853, rk45 and splitting are compared with the exact solution at the same
  times (the closed forms cost a few vectorised operations per sample); a departure beyond
  ``NUMERICAL_WARN`` of |Omega| is reported with its size.  Near the separatrix or the
  intermediate axis their local errors (1e-10) grow like exp(rate t) into a flip at the wrong time
  while their invariant drifts stay at 1e-10.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..errors import MotionError
from ..tolerances import EPS
from .regime import Setup
from .result import FreeMotion, Regime

__all__ = [
    "PHASE_ERROR_PER_RADIAN",
    "PHASE_WARN",
    "PHASE_REFUSE",
    "NUMERICAL_WARN",
    "phase_warnings",
    "unstable_axis_warnings",
    "departure",
    "departure_warning",
    "phase_bound",
]

Array = NDArray[np.float64]

PHASE_ERROR_PER_RADIAN = 8 * EPS
"""Bound on the relative error of Omega(t) and the attitude per radian turned (rounded frequencies)."""

PHASE_WARN = 1e-6
"""Phase error bound (relative to |Omega|) above which the result carries a warning."""

PHASE_REFUSE = 0.1
"""Phase error bound above which Omega(t) is no prediction: the request is refused."""

NUMERICAL_WARN = 1e-6
"""Departure of a numerical method from the exact solution (relative to |Omega|) that is reported."""


def _phase_rate(setup: Setup, motion: FreeMotion) -> tuple[float, float]:
    """Fastest phase the closed forms advance [rad/s] (|Omega|, the elliptic rate, the precession
    rates), and the largest |Omega_i(t)| over the motion relative to |Omega(0)| (a phase error
    moves each component by up to its own amplitude)."""
    problem = setup.problem
    if setup.regime is Regime.REST:
        return 0.0, 1.0
    speed = float(np.linalg.norm(problem.omega_body))
    rates = [speed]
    amplitude = 1.0
    rates += [abs(r) for r in (motion.body_precession_rate, motion.space_precession_rate, motion.spin_rate) if r is not None]
    if setup.regime is Regime.ASYMMETRIC:
        from .jacobi import AsymmetricTop

        top = AsymmetricTop.from_initial(problem.moments, problem.omega_body, 0.0)
        # phi_dot = |M|/I_a + c / (1 + b sn^2) with |M|/I_a + c = |M|/I_other (jacobi.py): extremes at sn = 0, 1
        other = 0 if top.reference == 2 else 2
        at_zero = top.momentum / float(problem.moments[other])
        by_reference = top.momentum / float(problem.moments[top.reference])
        rates += [top.rate, abs(at_zero), abs(by_reference + (at_zero - by_reference) / (1.0 + top.b))]
        amplitude = max(1.0, float(np.max(top.amplitudes)) / speed)
    return max(rates), amplitude


def phase_bound(setup: Setup, motion: FreeMotion, duration: float) -> float:
    """Bound on the exact method's error of Omega(t) (relative to |Omega|) and of the attitude at ``duration``."""
    rate, amplitude = _phase_rate(setup, motion)
    return PHASE_ERROR_PER_RADIAN * (1.0 + rate * duration) * amplitude


def departure(omega_body: Array, exact_omega_body: Array, quaternion: Array, exact_quaternion: Array, speed: float) -> float:
    """A numerical trajectory's largest departure from the exact one, relative to |Omega|: of Omega in the body
    frame and in space, and of the attitude (the distance of the unit quaternions, q and -q being one rotation).

    Omega in space is R(q) Omega_body; two rotations whose quaternions are d apart differ by an angle of up to
    about 2 d, so it departs by up to Omega_body's departure plus twice the quaternions' distance."""
    omega = float(np.max(np.abs(omega_body - exact_omega_body))) / speed if speed > 0 else 0.0
    apart = np.minimum(np.linalg.norm(quaternion - exact_quaternion, axis=1), np.linalg.norm(quaternion + exact_quaternion, axis=1))
    return omega + 2.0 * (float(np.max(apart)) if len(apart) else 0.0)


def phase_warnings(setup: Setup, motion: FreeMotion, duration: float) -> tuple[str, ...]:
    """Warn, or refuse (``MotionError``), when the phase error at ``duration`` (computation units) is large."""
    turned = _phase_rate(setup, motion)[0] * duration
    bound = phase_bound(setup, motion, duration)
    if bound >= PHASE_REFUSE:
        raise MotionError(
            f"over this duration the motion turns through about {turned:.2g} rad, and float64 cannot place "
            f"its phase that far (the error would reach {bound:.2g} of |omega|, {PHASE_ERROR_PER_RADIAN:.1e} "
            f"per radian); ask for a duration of at most {PHASE_REFUSE / bound:.2g} times this one",
            parameter="duration",
        )
    if bound > PHASE_WARN:
        return (
            f"the trajectory turns through about {turned:.2g} rad: Omega(t) and the attitude near its end are "
            f"accurate to about {bound:.1g} of |omega| only (the phase inherits the rounding of the frequencies, "
            f"{PHASE_ERROR_PER_RADIAN:.1e} per radian)",
        )
    return ()


def unstable_axis_warnings(setup: Setup, duration: float, omega_exponent: int) -> tuple[str, ...]:
    """Permanent rotation about the intermediate axis that holds only to rounding, over a long horizon.

    The given Omega had a tilt at rounding level (the noise of a rotated principal frame), which the
    regime treats as zero.  About the intermediate axis such a tilt grows like exp(sigma t),
    sigma = |Omega_2| sqrt((I2 - I1)(I3 - I2) / (I1 I3)) (L&L §37), into a flip after about
    ln(|Omega| / tilt) / sigma: beyond that the ideal permanent rotation is no prediction.
    ``duration`` is in computation units, 2^-omega_exponent s (``scaling.Units``).
    """
    if setup.regime is not Regime.PERMANENT_ROTATION or setup.stable is not False or setup.initial is None:
        return ()
    given = setup.initial.omega_body
    speed = float(np.max(np.abs(given)))
    tilt = float(max(abs(given[0]), abs(given[2])))
    if tilt == 0.0:
        return ()
    i1, i2, i3 = (float(x) for x in setup.problem.moments)
    sigma = abs(float(given[1])) * float(np.sqrt((i2 - i1) * (i3 - i2) / (i1 * i3)))
    flip = float(np.log(speed / tilt)) / sigma
    if duration <= flip:
        return ()
    return (
        f"Omega is along the intermediate axis only to rounding (a tilt of {tilt / speed:.1g} of |omega|, the "
        f"noise of the principal frame): rotation about that axis is unstable and such a tilt grows into a flip "
        f"after about {math.ldexp(flip, -omega_exponent):.3g} s of the {math.ldexp(duration, -omega_exponent):.3g} s "
        "asked for; beyond that the trajectory is the ideal permanent rotation, not a prediction",
    )


def departure_warning(method: str, omega_body: Array, exact_omega_body: Array, speed: float) -> tuple[str, ...]:
    """A warning with the numerical method's departure from the exact solution, when it is large."""
    departure = float(np.max(np.abs(omega_body - exact_omega_body))) / speed if speed > 0 else 0.0
    if departure <= NUMERICAL_WARN:
        return ()
    return (
        f"method={method!r} departs from the exact solution by up to {departure:.2g} of |omega| on this "
        "trajectory (its step errors, not shown by the energy and momentum drifts, grow along the motion, "
        "fastest near the separatrix and the intermediate axis); method='exact' is exact to rounding",
    )
