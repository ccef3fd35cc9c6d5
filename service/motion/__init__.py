"""Torque-free motion of a rigid body: PrincipalFrame + Omega(0) -> FreeMotion.

``predict_motion`` decides the regime (rest, permanent rotation, spherical
top, regular precession of a symmetric top, asymmetric top, linear rotator),
checks that the chosen method supports the body (``CAPABILITIES``), computes
the quantities of the API's ``precession`` section and, given a duration and a
number of samples, the trajectory with its invariant drifts.

Capability table (method -> rotor classes it can propagate):

=========  =========================================================  =========================
method     rotor classes                                              how
=========  =========================================================  =========================
exact      all: spherical, symmetric (both), asymmetric, linear       closed forms (L&L §§33-37),
                                                                      Jacobi elliptic functions and
                                                                      Carlson R_J (Celledoni et al. 2008)
dop853     spherical, symmetric, asymmetric (not linear: I1 = 0)      scipy solve_ivp, order 8
rk45       spherical, symmetric, asymmetric (not linear)              scipy solve_ivp, order 5(4)
splitting  spherical, symmetric, asymmetric (not linear)              Lie-Poisson Strang splitting, order 2
=========  =========================================================  =========================

The numerical methods need 1/I1, which a linear rotator (I1 = 0) lacks.

Modelling decisions (stated once, here):

- The motion is that of the moments given.  The classification's
  ``tolerance`` labels the body (symmetric, spherical, linear); the closed
  forms of those tops are used only where the moments agree to rounding
  (``MOTION_ROUNDING`` x the largest moment, ``motion_rotor``), and then the
  moments that agree are replaced by their mean (a change at rounding level).
  Moments that differ by more, even if the classification calls them equal,
  move by the exact asymmetric (Jacobi elliptic) solution: a nearly
  symmetric top is not replaced by an ideal one whose motion departs from
  the true one over time.
- Linear rotator: the component of Omega along its axis carries neither
  angular momentum nor energy and moves no mass, so it is physically
  meaningless; it is dropped (with a warning when it is not negligible) and
  the rotator turns uniformly about M, perpendicular to its axis.
- Omega is along a principal axis (permanent rotation) when its other
  principal components are within rounding (``Tolerances.permanent_rotation_rel``);
  a larger tilt, even 1e-9, is predicted as the motion it is (a flip, say).
- ``stable`` follows the contract: an asymmetric top is unstable when Omega
  starts nearest its intermediate axis; permanent rotation about the
  intermediate axis is unstable; every other regime is stable (a symmetric
  top spun about a perpendicular axis is neutrally stable: no growth).

References: Landau & Lifshitz, Mechanics §§33-37; Celledoni, Fasso, Safstrom
& Zanna, SIAM J. Sci. Comput. 30 (2008) 2084; Carlson, Numer. Algorithms 10
(1995) 13; McLachlan, Phys. Rev. Lett. 71 (1993) 3043.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..classification import Classification, RotorClass
from ..errors import InvalidParameterError, MotionError
from ..principal import PrincipalFrame
from ..tolerances import DEFAULT_TOLERANCES, EPS, Tolerances
from . import quaternions as quat
from .invariants import RigidProblem, invariant_drifts
from .jacobi import AsymmetricTop
from .result import FreeMotion, MotionDiagnostics, MotionMethod, Regime, Trajectory
from .symmetric import SymmetricTop, uniform_rotation

__all__ = [
    "predict_motion",
    "ideal_moments",
    "motion_rotor",
    "MOTION_ROUNDING",
    "FreeMotion",
    "MotionMethod",
    "Regime",
    "Trajectory",
    "MotionDiagnostics",
    "CAPABILITIES",
    "MAX_SAMPLES",
]

MAX_MOMENTUM = 1e150  # bound on I3 |omega| and I3 |omega|^2: their squares (1e300) stay finite
MAX_SAMPLES = 1_000_000
"""Largest ``samples``: 1e6 samples are ~100 MB of JSON, beyond any client's use."""

_NUMERICAL = frozenset({RotorClass.SPHERICAL, RotorClass.SYMMETRIC_PROLATE, RotorClass.SYMMETRIC_OBLATE, RotorClass.ASYMMETRIC})
CAPABILITIES: Mapping[MotionMethod, frozenset[RotorClass]] = {
    MotionMethod.EXACT: frozenset(RotorClass),
    MotionMethod.DOP853: _NUMERICAL,
    MotionMethod.RK45: _NUMERICAL,
    MotionMethod.SPLITTING: _NUMERICAL,
}
"""Which rotor classes each method supports; ``predict_motion`` checks it first."""

MOTION_ROUNDING = 64 * EPS
"""Moments closer than this times the largest moment are equal to rounding: the
closed form of a symmetric, spherical or linear top is exact for them (their
spread is below the error of any computed moment)."""

Array = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class _Setup:
    """What the regime decision produced: the problem to solve and its labels."""

    problem: RigidProblem
    regime: Regime
    stable: bool | None
    warnings: tuple[str, ...]
    unique: int | None = None  # symmetry axis index of a symmetric top
    initial: RigidProblem | None = None  # the state as given: reported M, E and omega_body come from it


def predict_motion(
    frame: PrincipalFrame,
    classification: Classification,
    angular_velocity: ArrayLike,
    *,
    duration: float | None = None,
    samples: int | None = None,
    method: MotionMethod | str = "exact",
    tolerances: Tolerances = DEFAULT_TOLERANCES,
) -> FreeMotion:
    """Torque-free motion of the body from its initial angular velocity.

    angular_velocity : (3,) [rad/s], Omega at t = 0 in the input frame.
    duration : [s] > 0, and samples : 2 <= samples <= MAX_SAMPLES, together
        request the trajectory at ``samples`` equally spaced times in [0, duration].
    method : ``exact`` (default), ``dop853``, ``rk45`` or ``splitting``.
    tolerances : thresholds (``Tolerances``); the default is the service's.

    Raises ``InvalidParameterError`` for malformed input and ``MotionError``
    when the method cannot treat this body or this horizon.
    """
    started = time.perf_counter()
    chosen = _parse_method(method)
    omega = _parse_omega(angular_velocity)
    _check_scale(frame, omega)
    times = _parse_times(duration, samples)
    rotor = motion_rotor(frame, classification)
    if rotor not in CAPABILITIES[chosen]:
        raise MotionError(
            f"method={chosen.value!r} cannot propagate a {rotor.kind.replace('_', ' ')} "
            "(it needs 1/I1 and the smallest moment is zero); use method='exact'",
            parameter="method",
        )
    setup = _setup(frame, classification, omega, tolerances)
    motion = _quantities(setup, chosen, tolerances)
    if times is None:
        diagnostics = MotionDiagnostics(elapsed_s=time.perf_counter() - started)
        return replace(motion, diagnostics=diagnostics)
    omega_body, attitude = _propagate(setup, chosen, times, tolerances)
    trajectory = _trajectory(setup.problem, times, omega_body, attitude)
    energy_drift, momentum_drift = invariant_drifts(setup.problem, trajectory.omega_body, trajectory.quaternion)
    diagnostics = MotionDiagnostics(time.perf_counter() - started, energy_drift, momentum_drift)
    return replace(motion, trajectory=trajectory, diagnostics=diagnostics)


# -- input validation ---------------------------------------------------------------


def _parse_method(method: MotionMethod | str) -> MotionMethod:
    if isinstance(method, MotionMethod):
        return method
    try:
        return MotionMethod(str(method).lower())
    except ValueError:
        known = ", ".join(m.value for m in MotionMethod)
        raise InvalidParameterError(f"unknown method {method!r}; use one of {known}", parameter="method") from None


def _parse_omega(angular_velocity: ArrayLike) -> Array:
    try:
        omega = np.asarray(angular_velocity, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidParameterError("omega must be three numbers wx,wy,wz in rad/s", parameter="omega") from None
    if omega.shape != (3,):
        raise InvalidParameterError(f"omega must have 3 components, got shape {omega.shape}", parameter="omega")
    if not np.all(np.isfinite(omega)):
        raise InvalidParameterError("omega must be finite (no NaN or infinity)", parameter="omega")
    return omega


def _check_scale(frame: PrincipalFrame, omega: Array) -> None:
    """The body must have inertia, and |M| and E must stay well inside float64."""
    largest = float(frame.moments[-1])
    if not largest > 0:
        raise InvalidParameterError("the body has no rotational inertia (all its mass is at one point), "
                                    "so its free rotation is undefined; leave out omega", parameter="omega")
    # |M| <= I3 |omega| and 2E <= I3 |omega|^2; the motion squares and multiplies these
    speed2 = float(omega @ omega)
    if not (largest * np.sqrt(speed2) <= MAX_MOMENTUM and largest * speed2 <= MAX_MOMENTUM):
        raise InvalidParameterError("omega and the moments of inertia are so large that the angular momentum "
                                    "or energy would overflow float64; rescale them (other units)",
                                    parameter="omega")


def _parse_times(duration: float | None, samples: int | None) -> Array | None:
    if duration is None and samples is None:
        return None
    if duration is None or samples is None:
        missing = "duration" if duration is None else "samples"
        raise InvalidParameterError(f"a trajectory needs both duration and samples; give {missing} too", parameter=missing)
    number = isinstance(duration, (int, float, np.floating, np.integer)) and not isinstance(duration, bool)
    if not (number and np.isfinite(duration) and duration > 0):
        raise InvalidParameterError(f"duration must be a finite number of seconds > 0, got {duration!r}", parameter="duration")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or not 2 <= samples <= MAX_SAMPLES:
        raise InvalidParameterError(
            f"samples must be an integer from 2 to {MAX_SAMPLES}, got {samples!r}", parameter="samples"
        )
    return np.linspace(0.0, float(duration), int(samples))


# -- regime decision ----------------------------------------------------------------


def _setup(frame: PrincipalFrame, classification: Classification, omega: Array, tol: Tolerances) -> _Setup:
    """The regime, and the ideal problem that is solved; the state as given is kept beside it."""
    decided = _decide(frame, classification, omega, tol)
    axes = np.asarray(frame.axes, dtype=np.float64)
    given = RigidProblem(np.asarray(frame.moments, dtype=np.float64), axes @ omega, axes, frame.quaternion)
    return replace(decided, initial=given)


def _decide(frame: PrincipalFrame, classification: Classification, omega: Array, tol: Tolerances) -> _Setup:
    axes = np.asarray(frame.axes, dtype=np.float64)
    omega_body = axes @ omega
    rotor = motion_rotor(frame, classification)
    moments = ideal_moments(np.asarray(frame.moments, dtype=np.float64), rotor)
    warnings: list[str] = []
    if rotor is RotorClass.LINEAR and omega_body[0] != 0.0:
        along = abs(float(omega_body[0]))
        if along > tol.permanent_rotation_rel * float(np.linalg.norm(omega_body)):
            warnings.append(
                f"the component of omega along the rotator axis ({along:.3g} rad/s) has no physical effect "
                "on a linear rotator and was dropped"
            )
        omega_body = omega_body.copy()
        omega_body[0] = 0.0
    problem = RigidProblem(moments, omega_body, axes, frame.quaternion)
    rate = float(np.linalg.norm(omega_body))
    if rate == 0.0:
        return _Setup(problem, Regime.REST, None, tuple(warnings))
    if rotor is RotorClass.SPHERICAL:
        return _Setup(problem, Regime.SPHERICAL, True, tuple(warnings))
    if rotor is RotorClass.LINEAR:
        return _Setup(problem, Regime.ROTATOR, True, tuple(warnings))
    along_axis = _principal_axis_of(omega_body, tol.permanent_rotation_rel)
    if rotor.is_symmetric:
        unique = 0 if rotor is RotorClass.SYMMETRIC_PROLATE else 2
        perpendicular = abs(omega_body[unique]) <= tol.permanent_rotation_rel * rate
        if along_axis is not None or perpendicular:
            snapped = _snap(problem, along_axis, unique if perpendicular else None)
            return _Setup(snapped, Regime.PERMANENT_ROTATION, True, tuple(warnings))
        return _Setup(problem, Regime.REGULAR_PRECESSION, True, tuple(warnings), unique)
    if along_axis is not None:
        return _Setup(_snap(problem, along_axis, None), Regime.PERMANENT_ROTATION, along_axis != 1, tuple(warnings))
    nearest = int(np.argmax(np.abs(omega_body)))
    return _Setup(problem, Regime.ASYMMETRIC, nearest != 1, tuple(warnings))


def ideal_moments(moments: ArrayLike, rotor: RotorClass) -> Array:
    """Moments of the ideal top of class ``rotor``, the ones the motion is computed with.

    Moments of a pair the class makes equal become their mean; the smallest
    moment of a linear rotator becomes 0.  ``predict_motion`` passes the class
    of ``motion_rotor``, so this changes moments by rounding only.
    """
    given = np.asarray(moments, dtype=np.float64)
    ideal = given.copy()
    if rotor is RotorClass.SPHERICAL:
        ideal[:] = given.mean()
    elif rotor is RotorClass.SYMMETRIC_OBLATE:
        ideal[:2] = given[:2].mean()
    elif rotor in (RotorClass.SYMMETRIC_PROLATE, RotorClass.LINEAR):
        ideal[1:] = given[1:].mean()
    if rotor is RotorClass.LINEAR:
        ideal[0] = 0.0
    return ideal


def motion_rotor(frame: PrincipalFrame, classification: Classification) -> RotorClass:
    """The rotor class whose motion is computed: the classification's only where its moments agree to rounding.

    The classification labels the body with its own ``tolerance``; the motion
    uses a closed form (symmetric, spherical, linear) only for moments equal
    within ``MOTION_ROUNDING`` (or the classification's tolerance, if smaller).
    Otherwise the class is decided again at that level, so a nearly symmetric
    top moves as the asymmetric top it is.
    """
    from ..classification import classify

    level = min(MOTION_ROUNDING, classification.tolerance)
    if classification.tolerance <= level:
        return classification.rotor
    return classify(frame, level).rotor


def _principal_axis_of(omega_body: Array, rel: float) -> int | None:
    """Index of the principal axis Omega lies along (within ``rel`` |Omega|), else None."""
    limit = rel * float(np.linalg.norm(omega_body))
    big = np.abs(omega_body) > limit
    return int(np.argmax(big)) if int(big.sum()) == 1 else None


def _snap(problem: RigidProblem, axis: int | None, zero: int | None) -> RigidProblem:
    """Remove the rounding-level components that made the rotation permanent."""
    omega = problem.omega_body.copy()
    if axis is not None:
        kept = omega[axis]
        omega[:] = 0.0
        omega[axis] = kept
    if zero is not None:
        omega[zero] = 0.0
    return replace(problem, omega_body=omega)


# -- quantities of the precession section -----------------------------------------------


def _quantities(setup: _Setup, method: MotionMethod, tol: Tolerances) -> FreeMotion:
    problem = setup.problem
    # M = I Omega and E = Omega.I Omega/2 of the state as given, with the reported moments (API.md);
    # the ideal top's moments only shape the motion that follows
    given = setup.initial if setup.initial is not None else problem
    momentum = given.momentum_input
    base = FreeMotion(
        regime=setup.regime,
        method=method,
        angular_momentum=momentum,
        angular_momentum_magnitude=float(np.linalg.norm(momentum)),
        kinetic_energy=given.energy,
        omega_body=given.omega_body,
        diagnostics=MotionDiagnostics(elapsed_s=0.0),
        stable=setup.stable,
        warnings=setup.warnings,
    )
    if setup.regime is Regime.REGULAR_PRECESSION:
        assert setup.unique is not None
        top = SymmetricTop(problem.moments, problem.omega_body, setup.unique)
        return replace(
            base,
            body_precession_rate=top.body_precession_rate,
            space_precession_rate=top.space_precession_rate,
            spin_rate=top.spin_rate,
            nutation_angle=top.nutation_angle,
            period=2.0 * np.pi / abs(top.body_precession_rate),
        )
    if setup.regime is Regime.ROTATOR:
        return replace(
            base,
            space_precession_rate=float(np.linalg.norm(problem.omega_body)),
            nutation_angle=0.5 * np.pi,
        )
    if setup.regime is Regime.ASYMMETRIC:
        return _asymmetric_quantities(base, AsymmetricTop.from_initial(problem.moments, problem.omega_body, tol.separatrix_rel))
    return base


def _asymmetric_quantities(base: FreeMotion, top: AsymmetricTop) -> FreeMotion:
    if top.separatrix:
        warning = (
            "Omega starts on the separatrix (2 E I2 = |M|^2 within rounding): the motion approaches "
            "rotation about the intermediate axis forever, so it has no period"
        )
        return replace(base, warnings=(*base.warnings, warning))
    period = top.period
    flip = 0.5 * period if base.stable is False else None
    return replace(base, period=period, flip_interval=flip)


# -- propagation ------------------------------------------------------------------------


def _propagate(setup: _Setup, method: MotionMethod, t: Array, tol: Tolerances) -> tuple[Array, Array]:
    problem = setup.problem
    if setup.regime is Regime.REST or method is MotionMethod.EXACT:
        return _propagate_exact(setup, t, tol)
    from .integrators import integrate_scipy, integrate_splitting, max_body_rate

    if method is MotionMethod.SPLITTING:
        rate = max_body_rate(problem)
        step = tol.splitting_step_angle / rate
        return integrate_splitting(problem, t, step, tol.max_integration_steps)
    return integrate_scipy(problem, t, method.value, tol.integrator_rtol, tol.integrator_atol_rel, tol.max_integration_steps)


def _propagate_exact(setup: _Setup, t: Array, tol: Tolerances) -> tuple[Array, Array]:
    problem = setup.problem
    if setup.regime is Regime.REGULAR_PRECESSION:
        assert setup.unique is not None
        return SymmetricTop(problem.moments, problem.omega_body, setup.unique).propagate(t)
    if setup.regime is Regime.ASYMMETRIC:
        return AsymmetricTop.from_initial(problem.moments, problem.omega_body, tol.separatrix_rel).propagate(t)
    return uniform_rotation(problem.omega_body, t)


def _trajectory(problem: RigidProblem, t: Array, omega_body: Array, attitude: Array) -> Trajectory:
    """Express the principal-frame attitude in the input frame.

    q = q_A q~ q_A* with q_A the principal->input rotation: the same angle about
    the rotated axis, so the scalar part is kept and the vector part is taken
    through the axes (exactly the identity at t = 0).
    """
    q = np.concatenate([attitude[:, :1], attitude[:, 1:] @ problem.axes], axis=1)
    q = quat.canonical(q)
    omega = quat.rotate(q, omega_body @ problem.axes)
    return Trajectory(t=t, omega_body=omega_body, omega=omega, quaternion=q)
