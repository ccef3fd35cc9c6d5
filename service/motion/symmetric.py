"""Closed forms of uniform motions: permanent rotation, spherical top, rotator, symmetric top.

Each propagator returns ``(omega_body, attitude)`` at times t: Omega(t) in the
principal frame (N, 3) and the attitude (N, 4), the rotation from t = 0 to t
expressed in the principal frame *at t = 0*.

References
----------
- Landau & Lifshitz, Mechanics, 3rd ed., §33 (free symmetric top: regular
  precession, |M|/I1 about M), §36 (Euler's equations, eqs. 36.5-36.7 for a
  symmetric top: Omega_perp turns at omega = Omega_3 (I3 - I1)/I1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from . import quaternions as quat

__all__ = ["uniform_rotation", "SymmetricTop"]

Array = NDArray[np.float64]


def uniform_rotation(omega_body: Array, t: Array) -> tuple[Array, Array]:
    """Omega constant in body and space: a rotation by |Omega| t about Omega.

    Exact for rest, permanent rotation about a principal axis, every motion of
    a spherical top, and a linear rotator spun across its axis (``rotator_motion``).
    """
    rate = float(np.linalg.norm(omega_body))
    omega = np.broadcast_to(omega_body, (t.size, 3)).copy()
    if rate == 0.0:
        attitude = np.zeros((t.size, 4))
        attitude[:, 0] = 1.0
        return omega, attitude
    return omega, quat.from_axis_angle(omega_body / rate, rate * t)


def rotator_motion(omega_body: Array, t: Array) -> tuple[Array, Array]:
    """A linear rotator (axis x1, I1 = 0) with Omega_body = (a, w2, w3): M = I_perp (0, w2, w3) is fixed in
    space, the axis turns about it at |w|, and the body spins about its axis at a.

    The attitude is A(t) B(t): A a rotation by |w| t about w (a fixed direction in space, since the axis stays
    perpendicular to it), B one by a t about x1; then Omega = w + a x1(t) in space, and in the body
    Omega_body(t) = (a, w turned by -a t about x1).  This is the needle's regular precession as I1 -> 0
    (L&L §33: body precession rate -a, spin a); with a = 0 it is the uniform rotation about w.
    """
    a = float(omega_body[0])
    across = np.array([0.0, omega_body[1], omega_body[2]])
    if a == 0.0:
        return uniform_rotation(across, t)
    c, s = np.cos(a * t), np.sin(a * t)
    omega = np.empty((t.size, 3))
    omega[:, 0] = a
    omega[:, 1] = c * across[1] + s * across[2]
    omega[:, 2] = c * across[2] - s * across[1]
    _, turn = uniform_rotation(across, t)
    spin = quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), a * t)
    return omega, quat.multiply(turn, spin)


_CYCLIC = {0: (1, 2), 2: (0, 1)}  # unique index s -> (p, q) with (p, q, s) right-handed


@dataclass(frozen=True, slots=True)
class SymmetricTop:
    """Regular precession of a symmetric top, L&L §33 and §36.

    unique : index (0 prolate, 2 oblate) of the symmetry axis among the
        ascending principal axes; the other two moments are equal (I_perp).
    """

    moments: Array
    omega_body: Array
    unique: int

    @property
    def perpendicular_moment(self) -> float:
        p, _ = _CYCLIC[self.unique]
        return float(self.moments[p])

    @property
    def body_precession_rate(self) -> float:
        """omega = Omega_3 (I3 - I1) / I1 (L&L eq. 36.6), signed.

        The gap I3 - I1 is taken from the moments directly (exact when they
        are within a factor 2, Sterbenz), never as M cos(theta)(1/I3 - 1/I1),
        which cancels when I3 - I1 is tiny.
        """
        i_perp = self.perpendicular_moment
        i_s = float(self.moments[self.unique])
        return float(self.omega_body[self.unique] * (i_s - i_perp) / i_perp)

    @property
    def momentum_magnitude(self) -> float:
        return float(np.linalg.norm(self.moments * self.omega_body))

    @property
    def space_precession_rate(self) -> float:
        """|M| / I1: the symmetry axis turns about M at this rate (L&L eq. 33.2)."""
        return self.momentum_magnitude / self.perpendicular_moment

    @property
    def spin_rate(self) -> float:
        """psi_dot = |M| cos(theta) (1/I3 - 1/I1) = -omega (L&L §36, eqs. 33.3 and 36.6).

        Computed as -omega, which needs no difference of reciprocals.
        """
        return -self.body_precession_rate

    @property
    def nutation_angle(self) -> float:
        """theta between the symmetry axis and M, cos(theta) = I3 Omega_3 / |M| (L&L eq. 33.3).

        atan2(|M_perp|, M_3) keeps full accuracy near 0 and pi, where acos does not.
        """
        m = self.moments * self.omega_body
        p, q = _CYCLIC[self.unique]
        return float(np.arctan2(np.hypot(m[p], m[q]), m[self.unique]))

    def propagate(self, t: Array) -> tuple[Array, Array]:
        """Omega(t) in the body and the attitude since t = 0.

        Body frame: Omega_p + i Omega_q = (Omega_p + i Omega_q)(0) exp(i omega t)
        (L&L eq. 36.7).  Attitude: R(t) = Rot(M, |M| t / I1) R(0) Rot(x3, psi_dot t);
        differentiating gives Omega = (|M|/I1) m + psi_dot x3, i.e. L&L eq. 33.1.
        """
        p, q = _CYCLIC[self.unique]
        omega_rate = self.body_precession_rate
        angle = omega_rate * t
        c, s = np.cos(angle), np.sin(angle)
        w = self.omega_body
        omega = np.empty((t.size, 3))
        omega[:, p] = w[p] * c - w[q] * s
        omega[:, q] = w[p] * s + w[q] * c
        omega[:, self.unique] = w[self.unique]
        m = self.moments * w
        m_hat = m / np.linalg.norm(m)
        axis = np.zeros(3)
        axis[self.unique] = 1.0
        about_m = quat.from_axis_angle(m_hat, self.space_precession_rate * t)
        about_axis = quat.from_axis_angle(axis, self.spin_rate * t)
        return omega, quat.multiply(about_m, about_axis)
