"""Jacobi elliptic functions and elliptic integrals, vectorised, stable near m = 1.

The torque-free asymmetric top needs sn, cn, dn at a parameter m = k^2 that may
lie within 1e-18 of 1 (a body started 1e-9 off its intermediate axis), where
``m`` itself rounds to 1.0.  Everything here therefore takes the parameter as
the pair ``(m, m1)`` with ``m1 = 1 - m`` computed by the caller from a
cancellation-free formula, never as ``1 - m``.

References
----------
- Abramowitz & Stegun, Handbook of Mathematical Functions (1964), §16.12
  (descending Landen transformation) and §16.8 (quarter-period shifts).
- B. C. Carlson, "Numerical computation of real or complex elliptic integrals",
  Numer. Algorithms 10 (1995) 13-26: R_F and R_J, here from ``scipy.special``.
- DLMF §19.25 (Legendre integrals in terms of Carlson's), §22.5 (limits m -> 1).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.special import elliprf, elliprj

from ..tolerances import EPS

__all__ = [
    "quarter_period",
    "jacobi_sncndn",
    "reduce_argument",
    "incomplete_first_kind",
    "complete_third_kind_rj",
    "third_kind_rj",
]

MAX_LANDEN_STEPS = 40
"""Descending Landen steps square the modulus each time (k_{j+1} ~ k_j'^2/4 ...);
from m1 = 1e-300 fewer than 15 steps reach k^2 < EPS, so 40 is never reached."""


def quarter_period(m1: float) -> float:
    """K(m) = R_F(0, m1, 1) (DLMF 19.25.1), accurate for m1 -> 0 (K ~ ln(4/sqrt(m1)))."""
    return float(elliprf(0.0, m1, 1.0))


def _landen_moduli(m1: float) -> tuple[list[float], list[float]]:
    """Moduli k_j and complementary parameters m1_j of the descending Landen chain.

    A&S 16.12: k_{j+1} = (1 - k'_j) / (1 + k'_j); its complement is computed
    without cancellation as k'_{j+1} = 2 sqrt(k'_j) / (1 + k'_j).
    """
    kp = float(np.sqrt(m1))
    ks: list[float] = []
    m1s: list[float] = [m1]
    for _ in range(MAX_LANDEN_STEPS):
        k_next = (1.0 - kp) / (1.0 + kp)
        kp = 2.0 * float(np.sqrt(kp)) / (1.0 + kp)
        ks.append(k_next)
        m1s.append(kp * kp)
        if k_next * k_next < EPS:
            break
    return ks, m1s


def jacobi_sncndn(u: NDArray[np.float64], m1: float) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """sn(u|m), cn(u|m), dn(u|m) for 0 < m1 = 1 - m <= 1, any real u (best |u| <= K).

    Descending Landen transformation (A&S 16.12.2-16.12.4) down to a modulus
    whose square is below EPS, where sn = sin and cn = cos to working precision,
    then back up.  dn is never formed as 1 - k sn^2 (which cancels near u = K
    when m -> 1) but as sqrt(cn^2 + m1 sn^2), a sum of non-negative terms, so
    cn, sn and dn keep full *relative* accuracy and sn^2 + cn^2 = 1,
    dn^2 + m sn^2 = 1 hold to rounding: the invariants of the top built from
    them are exact to rounding whatever the phase error.
    """
    u = np.asarray(u, dtype=np.float64)
    if m1 >= 1.0:  # m = 0: circular functions
        return np.sin(u), np.cos(u), np.ones_like(u)
    ks, m1s = _landen_moduli(m1)
    v = u.copy()
    for k in ks:
        v = v / (1.0 + k)
    sn, cn = np.sin(v), np.cos(v)
    # DLMF 22.10.4 (small m): sn = sin v to O(m); k_n^2 < EPS makes that exact.
    for level in range(len(ks) - 1, -1, -1):
        k = ks[level]
        dn = np.sqrt(cn * cn + m1s[level + 1] * sn * sn)
        denom = 1.0 + k * sn * sn
        sn, cn = (1.0 + k) * sn / denom, cn * dn / denom
    # Each level rounds sn and cn separately; renormalising restores
    # sn^2 + cn^2 = 1 to one rounding (it moves them by the accumulated error only).
    norm = np.hypot(sn, cn)
    sn, cn = sn / norm, cn / norm
    dn = np.sqrt(cn * cn + m1 * sn * sn)
    return sn, cn, dn


def reduce_argument(u: NDArray[np.float64], K: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Split u = 2K j + r with |r| <= K; returns (r, j) (j as float).

    sn and cn change sign and dn is unchanged under u -> u + 2K (A&S 16.8.1),
    so evaluating at the small r keeps the Landen chain in its accurate range
    and lets the caller add whole half-periods exactly.
    """
    j = np.rint(u / (2.0 * K))
    return u - j * (2.0 * K), j


def incomplete_first_kind(sin_phi: float, cos_phi: float, m1: float) -> float:
    """F(phi|m) for |phi| <= pi/2 from sin and cos of the amplitude.

    DLMF 19.25.5: F = sin(phi) R_F(cos^2, Delta^2, 1) with
    Delta^2 = 1 - m sin^2 = cos^2 + m1 sin^2 (no cancellation).
    """
    delta2 = cos_phi * cos_phi + m1 * sin_phi * sin_phi
    return float(sin_phi * elliprf(cos_phi * cos_phi, delta2, 1.0))


def third_kind_rj(sn: NDArray[np.float64], cn: NDArray[np.float64], dn: NDArray[np.float64], b: float) -> NDArray[np.float64]:
    """sn^3 R_J(cn^2, dn^2, 1, 1 + b sn^2) for the reduced argument (cn >= 0).

    With n = -b, DLMF 19.25.14 gives Pi(n; am u | m) = u + (n/3) times this.
    """
    value: NDArray[np.float64] = sn**3 * elliprj(cn * cn, dn * dn, 1.0, 1.0 + b * sn * sn)
    return value


def complete_third_kind_rj(m1: float, b: float) -> float:
    """R_J(0, m1, 1, 1 + b): Pi(n|m) = K(m) + (n/3) R_J(0, m1, 1, 1 - n) with n = -b (DLMF 19.25.2)."""
    return float(elliprj(0.0, m1, 1.0, 1.0 + b))
