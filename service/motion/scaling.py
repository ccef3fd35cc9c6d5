"""Units of the motion: moments and Omega rescaled by exact powers of two, and back.

Euler's equations I dOmega/dt = (I Omega) x Omega depend on the moments only
through their ratios, and if Omega(t) solves them so does c Omega(c t)
(Landau & Lifshitz §36, eq. 36.5).  So the motion is computed for moments
2^-a I and angular velocity 2^-b Omega, with a and b chosen (``math.frexp``)
so that the largest moment and the largest component of Omega lie in
[1/2, 1), at times 2^b t; the results are then taken back:

    Omega, rates  x 2^b        M  x 2^(a+b)       E  x 2^(a+2b)
    period, flip interval  x 2^-b                 angles, attitude unchanged

Multiplying by a power of two is exact in floating point (no rounding, as
long as nothing leaves float64's normal range), so the prediction is exactly
invariant under power-of-two changes of units, and nothing inside the motion
(M^2, E I, 1/(I1 I2 I3), ...) can overflow or underflow, whatever the scale of
the input.  Only the reported numbers themselves can fall outside float64; a
quantity that would overflow, or underflow into the subnormal range (where
it keeps fewer than 53 bits), is refused with a message that says which,
rather than reported as infinity, zero or a number with lost digits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidParameterError
from ..principal import PrincipalFrame
from .result import FreeMotion, Trajectory

__all__ = ["Units"]

Array = NDArray[np.float64]

TINY = float(np.finfo(np.float64).tiny)
"""Smallest normal float64 (2.2e-308): below it a number keeps fewer than 53 bits."""


def _exponent(x: float) -> int:
    """e with x = f 2^e, 1/2 <= f < 1 (x > 0, finite)."""
    return math.frexp(x)[1]


@dataclass(frozen=True, slots=True)
class Units:
    """The power-of-two exponents a (moments) and b (Omega) of one prediction."""

    moment: int
    omega: int

    @classmethod
    def of(cls, moments: Array, omega: Array) -> Units:
        """Exponents that bring the largest moment and the largest |Omega_i| to [1/2, 1) (0 for a zero Omega)."""
        speed = float(np.max(np.abs(omega)))
        return cls(_exponent(float(np.max(moments))), _exponent(speed) if speed > 0 else 0)

    # -- into the units of the computation ------------------------------------------

    def frame(self, frame: PrincipalFrame) -> PrincipalFrame:
        return replace(frame, moments=np.ldexp(frame.moments, -self.moment))

    def angular_velocity(self, omega: Array) -> Array:
        return np.ldexp(omega, -self.omega)

    def times(self, t: Array) -> Array:
        scaled = np.ldexp(t, self.omega)
        if not np.all(np.isfinite(scaled)):
            raise InvalidParameterError(
                "duration x |omega| is beyond float64's range (the body would turn by more than 1e308 rad); "
                "ask for a shorter duration",
                parameter="duration",
            )
        return scaled

    # -- back to the units of the input -------------------------------------------------

    def restore(self, motion: FreeMotion, t: Array | None) -> FreeMotion:
        """The motion in the input's units; refuses numbers outside float64's normal range."""
        b, m, e = self.omega, self.moment + self.omega, self.moment + 2 * self.omega
        _check("the angular velocity |omega|", float(np.max(np.abs(motion.omega_body))), b, "rad/s")
        _check("the angular momentum |M|", motion.angular_momentum_magnitude, m, "kg m^2/s")
        _check("the kinetic energy E", motion.kinetic_energy, e, "J")

        def rate(value: float | None, name: str) -> float | None:
            return None if value is None else _check(name, value, b, "rad/s")

        def interval(value: float | None, name: str) -> float | None:
            return None if value is None else _check(name, value, -b, "s")

        trajectory = motion.trajectory
        if trajectory is not None:
            assert t is not None
            _check("the angular velocity |Omega(t)|", float(np.max(np.abs(trajectory.omega_body))), b, "rad/s")
            trajectory = Trajectory(
                t=t,
                omega_body=np.ldexp(trajectory.omega_body, b),
                omega=np.ldexp(trajectory.omega, b),
                quaternion=trajectory.quaternion,
            )
        return replace(
            motion,
            angular_momentum=np.ldexp(motion.angular_momentum, m),
            angular_momentum_magnitude=math.ldexp(motion.angular_momentum_magnitude, m),
            kinetic_energy=math.ldexp(motion.kinetic_energy, e),
            omega_body=np.ldexp(motion.omega_body, b),
            body_precession_rate=rate(motion.body_precession_rate, "the body precession rate"),
            space_precession_rate=rate(motion.space_precession_rate, "the space precession rate"),
            spin_rate=rate(motion.spin_rate, "the spin rate"),
            period=interval(motion.period, "the period"),
            flip_interval=interval(motion.flip_interval, "the flip interval"),
            trajectory=trajectory,
        )


def _check(name: str, value: float, exponent: int, unit: str) -> float:
    """value 2^exponent, refused when it is non-zero but outside float64's normal range."""
    if value == 0.0:
        return 0.0
    try:
        scaled = math.ldexp(value, exponent)
    except OverflowError:
        scaled = math.inf
    if math.isfinite(scaled) and abs(scaled) >= TINY:
        return scaled
    decimal = math.log10(abs(value)) + exponent * math.log10(2.0)
    side = "overflow" if decimal > 0 else "underflow"
    raise InvalidParameterError(
        f"{name} of this motion is about 1e{decimal:.0f} {unit}, which would {side} float64; "
        "rescale omega or the moments of inertia (other units)",
        parameter="omega",
    )
