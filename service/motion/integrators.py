"""Numerical methods beside the exact one: scipy's DOP853/RK45 and a Lie-Poisson splitting.

They are the cross-check of the exact solution and the baseline users would
otherwise reach for.  All return ``(omega_body, attitude)`` like the closed
forms: Omega(t) in the principal frame and the rotation since t = 0 in the
principal frame at t = 0.

- ``dop853``/``rk45``: Euler's equations (Landau & Lifshitz eq. 36.5)
  I1 dOmega1/dt = (I2 - I3) Omega2 Omega3 (and cyclic) with the attitude
  quaternion dq/dt = q (0, Omega) / 2, by ``scipy.integrate.solve_ivp``
  (Dormand & Prince 1980; Hairer, Norsett & Wanner, Solving ODEs I, §II.5).
  scipy.integrate is imported only when one of them runs.
- ``splitting``: the Hamiltonian H = sum M_i^2 / (2 I_i) split into its three
  terms, each of whose flows is an exact rotation about a body axis, composed
  symmetrically (Strang) with steps 1(h/2) 2(h/2) 3(h) 2(h/2) 1(h/2)
  (McLachlan, Phys. Rev. Lett. 71 (1993) 3043; Touma & Wisdom, Astron. J. 107
  (1994) 1189; Dullweber, Leimkuhler & McLachlan, J. Chem. Phys. 107 (1997)
  5840).  It is symplectic on the Lie-Poisson manifold, second order, keeps
  |M| (and M in space) exactly up to rounding and the energy within O(h^2)
  with no secular drift.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import MotionError
from . import quaternions as quat
from .invariants import RigidProblem

__all__ = ["integrate_scipy", "integrate_splitting", "SPLITTING_ORDER", "max_body_rate"]

Array = NDArray[np.float64]

SPLITTING_ORDER = 2  # Strang composition of exact sub-flows
_SCIPY_METHODS = {"dop853": ("DOP853", 8), "rk45": ("RK45", 5)}  # name -> (solve_ivp name, order)


def max_body_rate(problem: RigidProblem) -> float:
    """Upper bound of |Omega_i(t)| over the motion [rad/s]: min(|M|/I_i, sqrt(2E/I_i)) maximised over i."""
    m = float(np.linalg.norm(problem.momentum_body))
    e2 = 2.0 * problem.energy
    rates = [min(m / i, math.sqrt(e2 / i)) for i in problem.moments if i > 0]
    return max(rates) if rates else 0.0


def _euler_rhs(moments: Array) -> Any:
    I1, I2, I3 = (float(x) for x in moments)
    c1, c2, c3 = (I2 - I3) / I1, (I3 - I1) / I2, (I1 - I2) / I3

    def rhs(_t: float, y: Array) -> Array:
        w1, w2, w3, qw, qx, qy, qz = y
        return np.array(
            [
                c1 * w2 * w3,
                c2 * w3 * w1,
                c3 * w1 * w2,
                0.5 * (-qx * w1 - qy * w2 - qz * w3),
                0.5 * (qw * w1 + qy * w3 - qz * w2),
                0.5 * (qw * w2 - qx * w3 + qz * w1),
                0.5 * (qw * w3 + qx * w2 - qy * w1),
            ]
        )

    return rhs


def integrate_scipy(
    problem: RigidProblem,
    t: Array,
    method: str,
    rtol: float,
    atol_rel: float,
    max_steps: int,
) -> tuple[Array, Array]:
    """Euler's equations with the attitude by scipy's ``solve_ivp`` (``method`` dop853 or rk45).

    atol is ``atol_rel`` times |Omega(0)| for Omega and ``atol_rel`` for the
    quaternion.  Refuses (MotionError) when the estimated number of steps,
    rate x duration x rtol^(-1/order), exceeds ``max_steps``.
    """
    name, order = _SCIPY_METHODS[method]
    duration = float(t[-1])
    if duration == 0.0:  # the scaled time underflowed: the body turns by nothing a float64 holds, and scipy
        # returns no samples for an empty interval
        return np.tile(np.asarray(problem.omega_body, dtype=np.float64), (len(t), 1)), np.tile([1.0, 0.0, 0.0, 0.0], (len(t), 1))
    estimate = max_body_rate(problem) * duration * rtol ** (-1.0 / order)
    if estimate > max_steps:
        raise MotionError(
            f"method={method!r} would need about {estimate:.3g} steps for this duration "
            f"(limit {max_steps}); use method='exact' or a shorter duration",
            parameter="method",
        )
    from scipy.integrate import solve_ivp  # lazy: importing service.motion stays light

    scale = float(np.linalg.norm(problem.omega_body))
    atol = np.r_[np.full(3, atol_rel * scale), np.full(4, atol_rel)]
    y0 = np.r_[problem.omega_body, 1.0, 0.0, 0.0, 0.0]
    sol = solve_ivp(_euler_rhs(problem.moments), (0.0, duration), y0, method=name, t_eval=t, rtol=rtol, atol=atol)
    if not sol.success:
        raise MotionError(f"the {method} integrator failed: {sol.message}; use method='exact'", parameter="method")
    return np.ascontiguousarray(sol.y[:3].T), quat.canonical(sol.y[3:].T)


def _strang_step(m: list[float], q: list[float], inv_i: tuple[float, float, float], h: float) -> None:
    """One Strang step of the exact sub-flows, in place (plain floats: fastest in CPython)."""
    for axis, tau in ((0, 0.5 * h), (1, 0.5 * h), (2, h), (1, 0.5 * h), (0, 0.5 * h)):
        angle = m[axis] * inv_i[axis] * tau
        c, s = math.cos(angle), math.sin(angle)
        # body M turns by -angle about e_axis; the attitude by +angle (M in space fixed)
        j, k = (axis + 1) % 3, (axis + 2) % 3
        m[j], m[k] = c * m[j] + s * m[k], -s * m[j] + c * m[k]
        ch, sh = math.cos(0.5 * angle), math.sin(0.5 * angle)
        w, v = q[0], q[1:]
        vj, vk, va = v[j], v[k], v[axis]
        # q <- q (ch, sh e_axis)
        q[0] = w * ch - va * sh
        q[1 + axis] = va * ch + w * sh
        q[1 + j] = vj * ch + vk * sh
        q[1 + k] = vk * ch - vj * sh


def integrate_splitting(problem: RigidProblem, t: Array, step: float, max_steps: int) -> tuple[Array, Array]:
    """Lie-Poisson Strang splitting with steps of at most ``step`` [s] between samples."""
    gaps = np.diff(t)
    counts = np.maximum(np.ceil(gaps / step), 1).astype(np.int64) if gaps.size else np.zeros(0, np.int64)
    if counts.sum() > max_steps:
        raise MotionError(
            f"method='splitting' would need {int(counts.sum())} steps (limit {max_steps}); "
            "use method='exact' or a shorter duration",
            parameter="method",
        )
    inv_i = tuple(1.0 / float(i) for i in problem.moments)
    m = [float(x) for x in problem.momentum_body]
    q = [1.0, 0.0, 0.0, 0.0]
    ms = np.empty((t.size, 3))
    qs = np.empty((t.size, 4))
    ms[0], qs[0] = m, q
    for n, (gap, count) in enumerate(zip(gaps, counts), start=1):
        h = float(gap) / int(count)
        for _ in range(int(count)):
            _strang_step(m, q, inv_i, h)  # type: ignore[arg-type]
        norm = math.sqrt(sum(x * x for x in q))
        q = [x / norm for x in q]
        ms[n], qs[n] = m, q
    return ms / problem.moments, quat.canonical(qs)
