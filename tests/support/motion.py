"""Independent references for the motion tests (never the code under test).

- ``euler_reference``: Euler's equations (Landau & Lifshitz eq. 36.5) with the
  attitude as a rotation matrix, dR/dt = R [Omega]x, integrated by scipy's
  DOP853 at rtol 1e-12 (Hairer, Norsett & Wanner, Solving ODEs I, §II.5).
- ``ll_period``: the period 4K(k)/rate of L&L §37 in mpmath at 50 digits.
"""

from __future__ import annotations

import math
from typing import Any, cast

import mpmath as mp
import numpy as np
from scipy.integrate import solve_ivp

from benchmarks.exact import elliptic_omega
from inertia.classification import Classification, classify
from inertia.motion.result import FreeMotion, Trajectory
from inertia.principal import PrincipalFrame


def body(moments: Any, rotation: Any = None, tolerance: float = 1e-6) -> tuple[PrincipalFrame, Classification]:
    """Principal frame and classification of a body with these principal moments,
    its principal axes the rows of ``rotation`` (identity by default)."""
    axes = np.eye(3) if rotation is None else np.asarray(rotation, dtype=float)
    frame = PrincipalFrame.from_eigen(np.asarray(moments, dtype=float), axes, tolerance)
    assert np.allclose(frame.axes, axes, rtol=0, atol=1e-15), "choose test axes that already obey the sign rule"
    return frame, classify(frame)


def trajectory(motion: FreeMotion) -> Trajectory:
    """The sampled trajectory of a motion asked for with samples (a test fails here if it is missing)."""
    assert motion.trajectory is not None, "the motion was asked for with samples"
    return motion.trajectory


def euler_reference(moments: Any, omega_body: Any, t: Any, rtol: float = 1e-12) -> Any:
    """Omega(t) (N, 3) in the body and R(t) (N, 3, 3), the rotation since t = 0 in the body frame at 0."""
    I1, I2, I3 = (float(x) for x in moments)

    def rhs(_t: Any, y: Any) -> Any:
        w = y[:3]
        r = y[3:].reshape(3, 3)
        dw = [(I2 - I3) / I1 * w[1] * w[2], (I3 - I1) / I2 * w[2] * w[0], (I1 - I2) / I3 * w[0] * w[1]]
        hat = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        return np.r_[dw, (r @ hat).ravel()]

    scale = float(np.linalg.norm(omega_body))
    atol = np.r_[np.full(3, 1e-15 * scale), np.full(9, 1e-15)]
    y0 = np.r_[np.asarray(omega_body, dtype=float), np.eye(3).ravel()]
    sol = solve_ivp(rhs, (0.0, float(t[-1])), y0, method="DOP853", t_eval=t, rtol=rtol, atol=atol)
    assert sol.success
    return sol.y[:3].T, sol.y[3:].T.reshape(-1, 3, 3)


def ll_period(moments: Any, omega_body: Any) -> float:
    """4 K(k) / rate for the asymmetric top, L&L eqs. 37.10-37.12, at 50 digits."""
    with mp.workdps(50):
        I1, I2, I3 = (mp.mpf(float(x)) for x in moments)
        W = [mp.mpf(float(x)) for x in omega_body]
        E2 = I1 * W[0] ** 2 + I2 * W[1] ** 2 + I3 * W[2] ** 2
        M2 = (I1 * W[0]) ** 2 + (I2 * W[1]) ** 2 + (I3 * W[2]) ** 2
        if M2 < E2 * I2:  # swap the roles of 1 and 3
            I1, I3 = I3, I1
        rate = mp.sqrt((I3 - I2) * (M2 - E2 * I1) / (I1 * I2 * I3))
        k2 = (I2 - I1) * (E2 * I3 - M2) / ((I3 - I2) * (M2 - E2 * I1))
        return float(4 * mp.ellipk(k2) / rate)


def hat(w: Any) -> np.ndarray:
    """The cross-product matrix [w]x: hat(w) @ v = w x v."""
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]], dtype=float)


def rotation(axis: Any, angle: float) -> np.ndarray:
    """The rotation by ``angle`` about ``axis`` (Rodrigues' formula)."""
    u = np.asarray(axis, float)
    u = u / np.linalg.norm(u)
    K = hat(u)
    return cast("np.ndarray", np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K)


def unit_quaternion_matrix(q: Any) -> np.ndarray:
    """The rotation matrix of one quaternion [w, x, y, z], normalised first."""
    return cast("np.ndarray", quaternion_matrix(np.asarray(q, float) / np.linalg.norm(q)))


def quaternion_matrix(q: Any) -> Any:
    """Rotation matrices of quaternions [w, x, y, z] (written out, independent of the service)."""
    w, x, y, z = np.moveaxis(np.asarray(q, dtype=float), -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


def elliptic_reference(moments: Any, omega_body: Any, t: Any, dps: int = 50) -> Any:
    """Omega(t) of an asymmetric top from L&L §37's closed form (``benchmarks.exact.elliptic_omega``)."""
    return elliptic_omega(moments, omega_body, t, dps)


def euler_taylor_reference(moments: Any, omega_body: Any, t: Any, dps: int = 30) -> Any:
    """Omega(t) (N, 3) from Euler's equations integrated by mpmath's Taylor-series solver
    (``mpmath.odefun``) at ``dps`` digits: slow, for short horizons."""
    with mp.workdps(dps):
        I1, I2, I3 = (mp.mpf(float(x)) for x in moments)

        def rhs(_t: Any, w: Any) -> Any:
            return [(I2 - I3) / I1 * w[1] * w[2], (I3 - I1) / I2 * w[2] * w[0], (I1 - I2) / I3 * w[0] * w[1]]

        sol = mp.odefun(rhs, 0, [mp.mpf(float(x)) for x in omega_body])
        return np.array([[float(x) for x in sol(mp.mpf(float(tn)))] for tn in t])
