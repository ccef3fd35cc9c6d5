"""The problem a motion method solves, and the invariants it must keep.

Torque-free motion conserves the kinetic energy E = sum I_i Omega_i^2 / 2 and
the angular momentum M (fixed in space, Landau & Lifshitz §36).  Every method
is judged by how well its trajectory keeps both.

``RigidProblem`` holds the *effective* moments the motion is computed with:
moments equal to rounding (``motion.MOTION_ROUNDING``) are replaced by their
mean, and the smallest moment of a linear rotator by 0, so that a closed form
applies (a spherical top's Omega is then exactly constant); moments that
differ by more are kept as given.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..arrays import freeze_fields
from . import quaternions as quat

__all__ = ["RigidProblem", "kinetic_energy", "invariant_drifts"]

Array = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class RigidProblem:
    """Initial value problem of the torque-free rigid body in its principal frame.

    moments : (3,) [kg m^2], ascending, the effective moments (see module doc).
    omega_body : (3,) [rad/s], initial Omega in the principal frame.
    axes : (3, 3), rows are the principal axes in the input frame.
    to_input : (4,) quaternion carrying principal components to input components.
    """

    moments: Array
    omega_body: Array
    axes: Array
    to_input: Array

    def __post_init__(self) -> None:
        freeze_fields(self, {"moments": (3,), "omega_body": (3,), "axes": (3, 3), "to_input": (4,)})

    @property
    def momentum_body(self) -> Array:
        """M = I Omega in the principal frame [kg m^2/s] (L&L eq. 32.8)."""
        return self.moments * self.omega_body

    @property
    def momentum_input(self) -> Array:
        """M in the input frame (axes.T maps principal to input components)."""
        return np.asarray(self.axes.T @ self.momentum_body)

    @property
    def energy(self) -> float:
        return kinetic_energy(self.moments, self.omega_body)


def kinetic_energy(moments: Array, omega_body: Array) -> float:
    """E = sum I_i Omega_i^2 / 2 [J] (L&L eq. 32.9)."""
    return float(0.5 * np.sum(moments * omega_body * omega_body))


def invariant_drifts(problem: RigidProblem, omega_body: Array, quaternion: Array) -> tuple[float, float]:
    """Max relative drift of the energy and of M in the input frame along a trajectory.

    M(t) is rebuilt as the client would: the attitude ``quaternion`` (t=0 ->
    t, input frame) applied to M_body(t) taken to the input frame through the
    axes at t = 0.  A zero initial value gives an absolute drift instead.
    """
    energies = 0.5 * np.sum(problem.moments * omega_body * omega_body, axis=-1)
    e0 = problem.energy
    energy_drift = float(np.max(np.abs(energies - e0)) / (e0 if e0 > 0 else 1.0))
    m_input = quat.rotate(quaternion, (problem.moments * omega_body) @ problem.axes)
    m0 = problem.momentum_input
    scale = float(np.linalg.norm(m0))
    momentum_drift = float(np.max(np.linalg.norm(m_input - m0, axis=-1)) / (scale if scale > 0 else 1.0))
    return energy_drift, momentum_drift
