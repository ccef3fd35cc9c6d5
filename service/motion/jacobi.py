"""Exact torque-free motion of the asymmetric top (I1 < I2 < I3): Jacobi elliptic form.

Omega(t) (Landau & Lifshitz §37, eqs. 37.10-37.12).  With
D3 = 2E I3 - M^2, D1 = M^2 - 2E I1, D2 = M^2 - 2E I2, when D2 > 0 (Omega
circulates about x3):

    Omega1 = rho A1 cn u,   Omega2 = rho s A2 sn u,   Omega3 = s A3 dn u,
    A1^2 = D3 / (I1 (I3-I1)), A2^2 = D3 / (I2 (I3-I2)), A3^2 = D1 / (I3 (I3-I1)),
    u = lambda t + u0,  lambda^2 = (I3-I2) D1 / (I1 I2 I3),
    k^2 = (I2-I1) D3 / ((I3-I2) D1),  k'^2 = (I3-I1) D2 / ((I3-I2) D1),

with s = sign Omega3(0), rho = +-1 (a rotation by pi about x3 is a symmetry;
it keeps |u0| <= K) and u0 = F(amplitude of the initial point).  D2 < 0
(circulation about x1) swaps indices 1 and 3 in the amplitudes, the rate and
k, with s = sign Omega1(0) (substitution into Euler's equations fixes the
signs: Omega1 = s A1 dn, Omega2 = rho s A2 sn, Omega3 = rho A3 cn).  The D's are formed as sums of positive terms of the initial
Omega (D3 = I1(I3-I1)W1^2 + I2(I3-I2)W2^2, ...), and k'^2 from D2 directly,
so nothing cancels near the separatrix (k -> 1) beyond D2 itself.  On the
separatrix (D2 = 0) sn = tanh, cn = dn = sech (DLMF 22.5.iv) and the period
is infinite.

Attitude (Celledoni, Fasso, Safstrom & Zanna, "The exact computation of the
free rigid body motion and its use in splitting methods", SIAM J. Sci.
Comput. 30 (2008) 2084-2112; L&L §37 eq. 37.16).  With m = M_body/|M|, the
body-to-space rotation factors as R(t) = P Rz(phi(t)) E(m(t)), where E(m) is
the rotation taking m to e_z built from m alone (Euler angles theta, psi
about a reference body axis a, rows: m x e_a / |m x e_a|, m x row1, m), P is
fixed by R(0), and the precession angle about M obeys

    phi_dot = |M| (M_b^2/I_b + M_c^2/I_c) / (M_b^2 + M_c^2) = |M|/I_a + c / (1 + b sn^2 u).

Its integral is an incomplete elliptic integral of the third kind,
Pi(-b; am u | m) = u - (b/3) sn^3 R_J(cn^2, dn^2, 1, 1 + b sn^2) (DLMF
19.25.14, Carlson 1995), evaluated at u reduced to |u| <= K plus whole
half-periods times the complete integral: the cost per sample does not grow
with t.  Of the two extreme axes as reference a we take the one with b <= 1,
which keeps both Pi - u and |m x e_a| away from cancellation.  M in space is
|M| P e_z whatever phi is, so |M| is kept to rounding by construction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
from numpy.typing import NDArray

from ..errors import MotionError
from . import quaternions as quat
from .elliptic import (
    complete_third_kind_rj,
    incomplete_first_kind,
    jacobi_sncndn,
    quarter_period,
    reduce_argument,
    third_kind_rj,
)

__all__ = ["AsymmetricTop"]

Array = NDArray[np.float64]


def _sign(x: float) -> float:
    return -1.0 if x < 0 else 1.0


def _energy_gaps(moments: Array, omega_body: Array) -> tuple[float, float, float, float]:
    """D1 = M^2 - 2E I1, D2 = M^2 - 2E I2, D3 = 2E I3 - M^2, and the scale of D2, correctly rounded.

    D1 = I2(I2-I1)W2^2 + I3(I3-I1)W3^2 and D3 = I1(I3-I1)W1^2 + I2(I3-I2)W2^2
    are sums of non-negative terms, but D2 = I3(I3-I2)W3^2 - I1(I2-I1)W1^2, the
    distance to the separatrix, cancels: in floating point it would carry an
    absolute error ~EPS x its terms, i.e. 1e-4 relative at 1e-12 from the
    separatrix, and the period (~ln 1/|D2|) with it.  The inputs are floats, so
    all three are evaluated exactly in rational arithmetic and rounded once
    (a few scalar operations per prediction).
    """
    I1, I2, I3 = (Fraction(float(x)) for x in moments)
    W1, W2, W3 = (Fraction(float(x)) for x in omega_body)
    p3, p1 = I3 * (I3 - I2) * W3 * W3, I1 * (I2 - I1) * W1 * W1
    D1 = I2 * (I2 - I1) * W2 * W2 + I3 * (I3 - I1) * W3 * W3
    D3 = I1 * (I3 - I1) * W1 * W1 + I2 * (I3 - I2) * W2 * W2
    D2 = p3 - p1
    if D2 != 0 and abs(D2) < Fraction(_NORMAL_FLOOR) * max(D1, D3):
        # k'^2 = |D2| / D1 (or / D3) would leave float64's normal range: the period came out non-finite, or the
        # state was taken for one exactly on the separatrix, whose motion it leaves after its first approach
        raise MotionError(
            f"Omega starts about 1e{_log10(abs(D2) / max(D1, D3)):.0f} (relative) from the separatrix but not on it: float64 "
            "cannot represent so small a distance, which sets the period and the flips; tilt Omega further from "
            "the intermediate axis (more than ~1e-150 of its size), or put it on the separatrix exactly",
            parameter="omega",
        )
    return float(D1), float(D2), float(D3), float(p3 + p1)


def _log10(x: Fraction) -> float:
    """log10 of a positive fraction that may be far below float64's range."""
    return math.log10(x.numerator) - math.log10(x.denominator)


_NORMAL_FLOOR = 1e-300
"""Smallest distance to the separatrix, relative to M^2 - 2 E I1 or 2 E I3 - M^2, whose k'^2 is a normal float64."""


@dataclass(frozen=True, slots=True)
class AsymmetricTop:
    """Constants of the Jacobi solution for one initial condition.

    Build with :meth:`from_initial`.  ``order`` maps (cn, sn, dn) to principal
    indices; ``signs`` are the signs multiplying (A cn, A sn, A dn).
    """

    moments: Array
    omega_body: Array
    momentum: float
    rate: float  # lambda [1/s]
    m: float
    m1: float
    K: float
    u0: float
    order: tuple[int, int, int]
    amplitudes: Array
    signs: Array
    separatrix: bool
    reference: int  # a, index of the reference body axis for the Euler angles
    b: float  # phi_dot = |M|/I_a + c / (1 + b sn^2)

    @classmethod
    def from_initial(cls, moments: Array, omega_body: Array, separatrix_rel: float) -> AsymmetricTop:
        I1, I2, I3 = (float(x) for x in moments)
        W1, W3 = float(omega_body[0]), float(omega_body[2])
        g21, g32, g31 = I2 - I1, I3 - I2, I3 - I1
        D1, D2, D3, scale2 = _energy_gaps(moments, omega_body)
        separatrix = abs(D2) <= separatrix_rel * scale2
        momentum = float(np.linalg.norm(np.asarray(moments) * np.asarray(omega_body)))
        inv_i123 = 1.0 / I1 / I2 / I3
        if D2 >= 0.0 or separatrix:  # circulation about x3 (L&L 37.10)
            order = (0, 1, 2)
            amps = [np.sqrt(D3 / (I1 * g31)), np.sqrt(D3 / (I2 * g32)), np.sqrt(D1 / (I3 * g31))]
            s = _sign(W3)
            sn_sign = s
            rate = np.sqrt(g32 * D1 * inv_i123)
            m, m1 = g21 * D3 / (g32 * D1), g31 * D2 / (g32 * D1)
        else:  # circulation about x1: indices 1 <-> 3 and t -> -t
            order = (2, 1, 0)
            amps = [np.sqrt(D1 / (I3 * g31)), np.sqrt(D1 / (I2 * g21)), np.sqrt(D3 / (I1 * g31))]
            s = _sign(W1)
            sn_sign = s
            rate = np.sqrt(g21 * D3 * inv_i123)
            m, m1 = g32 * D1 / (g21 * D3), -g31 * D2 / (g21 * D3)
        if separatrix:
            m, m1 = 1.0, 0.0
        w = np.asarray(omega_body, dtype=np.float64)
        rho = _sign(w[order[0]])
        sn0 = w[order[1]] / (rho * sn_sign * amps[1])
        cn0 = abs(w[order[0]]) / amps[0]
        h = np.hypot(sn0, cn0)
        sn0, cn0 = sn0 / h, cn0 / h
        if separatrix:
            K = np.inf
            u0 = float(np.arcsinh(sn0 / cn0))  # am(u|1) = gd(u): tan(am) = sinh u
        else:
            K = quarter_period(m1)
            u0 = incomplete_first_kind(sn0, cn0, m1)
        # Reference axis: b for each choice (the four cases worked out from
        # M^2 - I_a^2 Omega_a^2 = alpha + beta sn^2, b = beta/alpha).
        if order == (0, 1, 2):
            b_by_axis = {2: I3 * g21 / (I1 * g32), 0: I1 * D3 / (I3 * D1)}
        else:
            b_by_axis = {0: I1 * g32 / (I3 * g21), 2: I3 * D1 / (I1 * D3)}
        reference = min(b_by_axis, key=lambda a: b_by_axis[a])
        return cls(
            moments=np.array(moments, dtype=np.float64),
            omega_body=w.copy(),
            momentum=momentum,
            rate=float(rate),
            m=float(m),
            m1=float(m1),
            K=float(K),
            u0=u0,
            order=order,
            amplitudes=np.array(amps, dtype=np.float64),
            signs=np.array([rho, rho * sn_sign, s]),
            separatrix=bool(separatrix),
            reference=reference,
            b=float(b_by_axis[reference]),
        )

    @property
    def period(self) -> float:
        """Period of Omega(t) in the body frame, 4K(k)/lambda (infinite on the separatrix)."""
        return 4.0 * self.K / self.rate

    def _elliptic(self, t: Array) -> tuple[Array, Array, Array, Array, Array]:
        """sn, cn, dn at the reduced argument r (u = lambda t + u0 = 2K j + r), the parity (-1)^j, and j.

        sn and cn flip sign every half period, dn does not (A&S 16.8.1).  On the
        separatrix there is no period: the values are at u itself, j = 0.
        """
        u = self.rate * t + self.u0
        if self.separatrix:
            e = np.exp(-np.abs(u))
            sech = 2.0 * e / (1.0 + e * e)  # 1/cosh without overflow
            return np.tanh(u), sech, sech, np.ones_like(u), np.zeros_like(u)
        r, j = reduce_argument(u, self.K)
        sn, cn, dn = jacobi_sncndn(r, self.m1)
        return sn, cn, dn, 1.0 - 2.0 * np.mod(j, 2.0), j

    def _omega_from(self, sn: Array, cn: Array, dn: Array, parity: Array) -> Array:
        out = np.empty((sn.size, 3))
        values = (parity * cn, parity * sn, dn)
        for col, fn, amp, sign in zip(self.order, values, self.amplitudes, self.signs):
            out[:, col] = sign * amp * fn
        return out

    def omega(self, t: Array) -> Array:
        """Omega(t) in the principal frame, (N, 3) [rad/s]."""
        sn, cn, dn, parity, _ = self._elliptic(np.asarray(t, dtype=np.float64))
        return self._omega_from(sn, cn, dn, parity)

    def _precession_angle(self, t: Array, reduced: tuple[Array, Array, Array], j: Array) -> Array:
        """phi(t) - phi(0), the rotation angle about M (Celledoni et al. 2008, §3)."""
        I1, _, I3 = (float(x) for x in self.moments)
        a = self.reference
        coef = (1.0 if a == 2 else -1.0) * self.momentum * (I3 - I1) / (I1 * I3) / self.rate
        b = self.b
        if self.separatrix:  # int du / (1 + b tanh^2 u) = [u + sqrt(b) atan(sqrt(b) tanh u)] / (1 + b)
            u = self.rate * t + self.u0
            rb = np.sqrt(b)
            bounded = rb * (np.arctan(rb * np.tanh(u)) - np.arctan(rb * np.tanh(self.u0)))
            angle: Array = (self.momentum / self.moments[a] + coef * self.rate / (1 + b)) * t + coef * bounded / (1 + b)
            return angle
        # Pi(-b; am u) = u - (b/3) [2 j R_J(0, m1, 1, 1+b) + sn_r^3 R_J(cn_r^2, dn_r^2, 1, 1 + b sn_r^2)]
        sn_r, cn_r, dn_r = reduced
        sn0, cn0, dn0 = jacobi_sncndn(np.array([self.u0]), self.m1)
        tail = 2.0 * j * complete_third_kind_rj(self.m1, b) + third_kind_rj(sn_r, cn_r, dn_r, b)
        tail = tail - third_kind_rj(sn0, cn0, dn0, b)
        other = 0 if a == 2 else 2  # |M|/I_a + c = |M|/I_other (see module doc)
        precession: Array = (self.momentum / self.moments[other]) * t - coef * (b / 3.0) * tail
        return precession

    def _euler_frame(self, omega: Array) -> Array:
        """E(m): rows m x e_a / |m x e_a|, m x row1, m, for m = M_body/|M| (N, 3, 3)."""
        m = omega * self.moments / self.momentum
        m = m / np.linalg.norm(m, axis=-1, keepdims=True)
        e_a = np.zeros(3)
        e_a[self.reference] = 1.0
        row1 = np.cross(m, e_a)
        row1 /= np.linalg.norm(row1, axis=-1, keepdims=True)
        row2 = np.cross(m, row1)
        return np.stack([row1, row2, m], axis=-2)

    def propagate(self, t: Array) -> tuple[Array, Array]:
        """Omega(t) in the body and the attitude since t = 0 (principal frame at t = 0)."""
        sn, cn, dn, parity, j = self._elliptic(t)
        omega = self._omega_from(sn, cn, dn, parity)
        phi = self._precession_angle(t, (sn, cn, dn), j)
        frames = self._euler_frame(omega)
        e0 = self._euler_frame(self.omega_body[None, :])[0]
        c, s = np.cos(phi)[:, None], np.sin(phi)[:, None]
        rotated = np.stack([c * frames[:, 0] - s * frames[:, 1], s * frames[:, 0] + c * frames[:, 1], frames[:, 2]], 1)
        # R~(t) = E0^T Rz(phi) E(t): position at t of a body point, t = 0 principal coordinates
        attitude = np.einsum("ki,nkj->nij", e0, rotated)
        return omega, quat.from_matrices(attitude)
