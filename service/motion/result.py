"""Result types of the torque-free motion: FreeMotion, Trajectory, MotionDiagnostics.

``FreeMotion.as_dict()`` is exactly the ``precession`` section of the API
contract (``shared/API.md``): only the keys that apply to the regime, SI units,
vectors in the input frame unless the name says ``_body``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..arrays import frozen_array
from ..sections import MotionDiagnosticsSection, PrecessionSection, TrajectorySection
from ..vocabulary import MotionMethod, Regime

__all__ = ["Regime", "MotionMethod", "Trajectory", "MotionDiagnostics", "FreeMotion"]

Array = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class Trajectory:
    """Sampled motion.

    t : (N,) [s], from 0 to the duration.
    omega_body : (N, 3) [rad/s], Omega(t) in the principal frame.
    omega : (N, 3) [rad/s], Omega(t) in the fixed input frame.
    quaternion : (N, 4) [w, x, y, z], w >= 0: the rotation carrying a body
        point's position (about the centre of mass, input frame) at t = 0 to
        its position at t; the identity at t = 0.
    """

    t: Array
    omega_body: Array
    omega: Array
    quaternion: Array

    def __post_init__(self) -> None:
        object.__setattr__(self, "t", frozen_array(self.t))
        for name, shape in (("omega_body", (3,)), ("omega", (3,)), ("quaternion", (4,))):
            arr = frozen_array(getattr(self, name), shape)
            if arr.shape[0] != self.t.shape[0]:
                raise ValueError(f"{name} has {arr.shape[0]} rows for {self.t.shape[0]} times")
            object.__setattr__(self, name, arr)

    def section(self) -> TrajectorySection:
        return TrajectorySection(
            t=self.t.tolist(), omega_body=self.omega_body.tolist(), omega=self.omega.tolist(), quaternion=self.quaternion.tolist()
        )

    def as_dict(self) -> dict[str, Any]:
        return self.section().as_dict()


@dataclass(frozen=True, slots=True)
class MotionDiagnostics:
    """How long the prediction took and how well the trajectory keeps the invariants.

    energy_drift : max over samples of |E(t) - E(0)| / E(0) (None without a trajectory).
    momentum_drift : max over samples of |M(t) - M(0)| / |M(0)|, M in the input
        frame reconstructed from the reported quaternion and omega_body.
    relative_error_estimate : bound on the trajectory's error, of Omega(t) relative
        to |Omega| and of the attitude quaternion: the closed forms' phase rounding,
        plus a numerical method's measured departure from them (None without a
        trajectory). The drifts cannot see a trajectory at the wrong place on its orbit.
    """

    elapsed_s: float
    energy_drift: float | None = None
    momentum_drift: float | None = None
    relative_error_estimate: float | None = None

    def section(self) -> MotionDiagnosticsSection:
        return MotionDiagnosticsSection(
            elapsed_s=self.elapsed_s,
            energy_drift=self.energy_drift,
            momentum_drift=self.momentum_drift,
            relative_error_estimate=self.relative_error_estimate,
        )

    def as_dict(self) -> dict[str, Any]:
        return self.section().as_dict()


_OPTIONAL_SCALARS = (
    "body_precession_rate",
    "space_precession_rate",
    "spin_rate",
    "nutation_angle",
    "period",
)


@dataclass(frozen=True, slots=True)
class FreeMotion:
    """Torque-free motion of a rigid body (Landau & Lifshitz §§33-37).

    angular_momentum : (3,) [kg m^2/s], M = I Omega in the input frame.
    angular_momentum_magnitude : [kg m^2/s].
    kinetic_energy : [J], E = Omega . I Omega / 2.
    omega_body : (3,) [rad/s], initial Omega in the principal frame.
    body_precession_rate, space_precession_rate, spin_rate : [rad/s] or None.
    nutation_angle : [rad] or None.
    period : [s] of Omega(t) in the body frame, or None (no period, or infinite).
    stable : whether the motion stays near its initial axis (None for rest).
    flip_interval : [s] between reversals of Omega_2, unstable asymmetric tops only.
    """

    regime: Regime
    method: MotionMethod
    angular_momentum: Array
    angular_momentum_magnitude: float
    kinetic_energy: float
    omega_body: Array
    diagnostics: MotionDiagnostics
    body_precession_rate: float | None = None
    space_precession_rate: float | None = None
    spin_rate: float | None = None
    nutation_angle: float | None = None
    period: float | None = None
    stable: bool | None = None
    flip_interval: float | None = None
    trajectory: Trajectory | None = None
    warnings: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "angular_momentum", frozen_array(self.angular_momentum, (3,)))
        object.__setattr__(self, "omega_body", frozen_array(self.omega_body, (3,)))
        numbers = [self.angular_momentum_magnitude, self.kinetic_energy]
        numbers += [getattr(self, k) for k in (*_OPTIONAL_SCALARS, "flip_interval")]
        finite = all(np.isfinite(x) for x in numbers if x is not None)
        if not finite or not np.all(np.isfinite(self.angular_momentum)):
            raise ValueError("FreeMotion holds a non-finite number")  # a bug, never an input error

    def section(self) -> PrecessionSection:
        """The API's ``precession`` section: only the keys that apply."""
        return PrecessionSection(
            regime=self.regime,
            angular_momentum=self.angular_momentum.tolist(),
            angular_momentum_magnitude=self.angular_momentum_magnitude,
            kinetic_energy=self.kinetic_energy,
            omega_body=self.omega_body.tolist(),
            body_precession_rate=self.body_precession_rate,
            space_precession_rate=self.space_precession_rate,
            spin_rate=self.spin_rate,
            nutation_angle=self.nutation_angle,
            period=self.period,
            stable=self.stable,
            flip_interval=self.flip_interval,
            trajectory=None if self.trajectory is None else self.trajectory.section(),
            diagnostics=self.diagnostics.section(),
        )

    def as_dict(self) -> dict[str, Any]:
        """The API's ``precession`` section as JSON."""
        return self.section().as_dict()
