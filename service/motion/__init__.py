"""Torque-free motion of a rigid body: PrincipalFrame + Omega(0) -> FreeMotion.

``predict_motion`` validates its input, checks that the chosen method supports
the body (``CAPABILITIES``), and joins the stages, one module each:

    regime.py      frame + classification + Omega -> Setup (regime, stability, the problem solved)
    quantities.py  Setup -> the quantities of the API's ``precession`` section
    methods.py     Setup + times -> Omega(t), attitude: one class per method, with its capabilities
    integrators.py the numerical integrators (scipy imported only when one runs)
    symmetric.py, jacobi.py, elliptic.py  the closed forms
    accuracy.py    what the invariant drifts cannot show: the phase error of long horizons (warned
                   about, or refused where float64 cannot place the phase), and how far a numerical
                   method departs from the exact solution (warned about)
    scaling.py     the units of the computation: moments and Omega scaled by exact powers of two
                   so that nothing overflows at any scale, and the results taken back (or refused
                   when a reported number would leave float64's normal range)

and, given a duration and a number of samples, returns the trajectory with its
invariant drifts.

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
  Moments the caller declares exact (``exact_moments``: principal moments
  given as numbers) carry no rounding, so only exactly equal ones get a
  closed form of a degenerate top; an exactly zero smallest moment is a
  linear rotator in any case.
  Moments that differ by more, even if the classification calls them equal,
  move by the exact asymmetric (Jacobi elliptic) solution: a nearly
  symmetric top is not replaced by an ideal one whose motion departs from
  the true one over time.
- Linear rotator: the component of Omega along its axis carries neither
  angular momentum nor energy and moves no mass, but it turns the body's
  frame; it is kept, so the trajectory starts at the Omega given: the axis
  turns uniformly about M, perpendicular to it, while the body spins about
  the axis (the limit of a needle's regular precession as I1 -> 0).  Spun
  only about its axis, a rotator is a permanent rotation, not at rest.
- Omega is along a principal axis (permanent rotation) when its other
  principal components are within the rounding of ``axes @ Omega``
  (``Tolerances.permanent_rotation_rel``); a larger tilt, even 1e-9, is
  predicted as the motion it is (a flip, say).  Where the axes are an exact
  signed permutation (principal moments given, a diagonal tensor) there is no
  such rounding: only exact zeros are permanent rotation, and a tilt of 1e-17
  about the intermediate axis grows into the flip it is.
- Separatrix: the distance 2E I2 - M^2 is computed exactly.  Within
  ``Tolerances.separatrix_rel`` of zero the state is reported as on the
  separatrix (no period, a warning; API.md), but its trajectory is the
  motion of the numbers given; only an exact zero moves along the
  separatrix's hyperbolic limit (which the true motion leaves after its first
  approach to the intermediate axis).
- The regime names the body's class (API.md): where the classification's
  ``tolerance`` calls moments equal that differ by more than rounding, the
  section reports ``spherical``, or ``regular_precession`` with the symmetric
  top's rates of the equal pair's mean moment (``permanent_rotation`` for Omega
  across its axis), and a warning says so; the trajectory is still the exact
  motion of the moments as they are.  A rod within tolerance of a linear
  rotator is the ``rotator`` regime with its own prolate top's rates (a spin
  about its own axis stays a permanent rotation).
- ``stable`` follows the contract: an asymmetric top is unstable when Omega
  starts nearest its intermediate axis; permanent rotation about the
  intermediate axis is unstable; every other regime is stable (a symmetric
  top spun about a perpendicular axis is neutrally stable: no growth).  A
  body the classification calls symmetric is one: its middle axis, one of
  the pair equal within ``tolerance``, is stable whatever rounding ordered.

References: Landau & Lifshitz, Mechanics §§33-37; Celledoni, Fasso, Safstrom
& Zanna, SIAM J. Sci. Comput. 30 (2008) 2084; Carlson, Numer. Algorithms 10
(1995) 13; McLachlan, Phys. Rev. Lett. 71 (1993) 3043.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..classification import Classification
from ..errors import InvalidParameterError, MotionError
from ..principal import PrincipalFrame
from ..tolerances import DEFAULT_TOLERANCES, Tolerances
from . import quaternions as quat
from .accuracy import departure, departure_warning, phase_bound, phase_warnings, unstable_axis_warnings
from .invariants import RigidProblem, invariant_drifts
from .methods import CAPABILITIES, EXACT_REST, method_for
from .quantities import precession_quantities
from .regime import MOTION_ROUNDING, decide_regime, ideal_moments, motion_rotor
from .result import FreeMotion, MotionDiagnostics, MotionMethod, Regime, Trajectory
from .scaling import Units

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

MAX_SAMPLES = 1_000_000
"""Largest ``samples``: 1e6 samples are ~100 MB of JSON, beyond any client's use."""

Array = NDArray[np.float64]


def predict_motion(
    frame: PrincipalFrame,
    classification: Classification,
    angular_velocity: ArrayLike,
    *,
    duration: float | None = None,
    samples: int | None = None,
    method: MotionMethod | str = MotionMethod.EXACT,
    tolerances: Tolerances = DEFAULT_TOLERANCES,
    exact_moments: bool = False,
    moment_error: float = 0.0,
) -> FreeMotion:
    """Torque-free motion of the body from its initial angular velocity.

    angular_velocity : (3,) [rad/s], Omega at t = 0 in the input frame.
    duration : [s] > 0, and samples : 2 <= samples <= MAX_SAMPLES, together
        request the trajectory at ``samples`` equally spaced times in [0, duration].
    method : ``exact`` (default), ``dop853``, ``rk45`` or ``splitting``.
    tolerances : thresholds (``Tolerances``); the default is the service's.
    exact_moments : the frame's moments are exact numbers (principal moments given by the
        caller), not computed ones: moments then get a degenerate top's closed form only where
        they are equal, not merely within rounding (``MOTION_ROUNDING``) of each other.
    moment_error : relative error bound of the frame's moments (the mass stage's or the tensor's
        estimate; 0 for exact moments): the trajectory's estimate includes how far the motion moves
        when a moment moves by it (``_moment_departure``).

    Raises ``InvalidParameterError`` for malformed input and ``MotionError``
    when the method cannot treat this body or this horizon.
    """
    started = time.perf_counter()
    chosen = method_for(_parse_method(method))
    omega = _parse_omega(angular_velocity)
    _check_inertia(frame)
    given_times = _parse_times(duration, samples)
    # the motion is computed in units where the largest moment and |Omega_i| are ~1 (exact powers of two)
    units = Units.of(np.asarray(frame.moments, dtype=np.float64), omega)
    frame = units.frame(frame)
    times = None if given_times is None else units.times(given_times)
    chosen.check(motion_rotor(frame, classification, exact_moments))
    setup = decide_regime(frame, classification, units.angular_velocity(omega), tolerances, exact_moments)
    motion = precession_quantities(setup, chosen.name, tolerances, classification.tolerance)
    if times is None:
        motion = units.restore(motion, None)
        return replace(motion, diagnostics=MotionDiagnostics(elapsed_s=time.perf_counter() - started))
    notes = phase_warnings(setup, motion, float(times[-1]))  # refuses a horizon whose phase float64 cannot place
    unstable = unstable_axis_warnings(setup, float(times[-1]), units.omega)
    notes += unstable
    # a body at rest stays at rest: no method needs to integrate that
    propagator = EXACT_REST if setup.regime is Regime.REST else chosen
    omega_body, attitude = propagator.propagate(setup, times, tolerances)
    # the trajectory's error bound: the closed forms' phase rounding, and a numerical method's measured departure
    # from them (of Omega and of the attitude, which the invariant drifts do not see)
    error = phase_bound(setup, motion, float(times[-1]))
    exact_omega, exact_attitude = omega_body, attitude
    speed = float(np.linalg.norm(setup.problem.omega_body))
    if propagator is not EXACT_REST:
        exact_omega, exact_attitude = EXACT_REST.propagate(setup, times, tolerances)
        notes += departure_warning(chosen.name.value, omega_body, exact_omega, speed)
        error += departure(omega_body, exact_omega, attitude, exact_attitude, speed)
    if moment_error > 0.0 and setup.regime is not Regime.REST:
        # at most ~2,000 of the samples, the last among them: six more propagations stay a fraction of the first
        at = np.unique(np.r_[np.arange(0, len(times), max(1, len(times) // 2000)), len(times) - 1])
        moved = (frame, classification, units.angular_velocity(omega), times[at], tolerances, moment_error)
        error += _moment_departure(*moved, exact_omega[at], exact_attitude[at], speed)
        i1, i3 = float(frame.moments[0]), float(frame.moments[2])
        if error > LOST and i1 > 0.0:  # no prediction: Omega(t) may be anywhere its energy allows, |Omega(t)|
            error = max(error, 2.0 * math.sqrt(i3 / i1))  # <= sqrt(2E / I1) <= sqrt(I3 / I1) |Omega(0)|
    if unstable:  # the rounding's tilt turns Omega over within the duration: it may be anywhere, even -Omega
        error = max(error, 2.0)
    motion = replace(motion, warnings=(*motion.warnings, *notes))
    trajectory = _trajectory(setup.problem, times, omega_body, attitude, units.angular_velocity(omega))
    energy_drift, momentum_drift = invariant_drifts(setup.problem, trajectory.omega_body, trajectory.quaternion)
    motion = units.restore(replace(motion, trajectory=trajectory), given_times)
    diagnostics = MotionDiagnostics(time.perf_counter() - started, energy_drift, momentum_drift, error)
    return replace(motion, diagnostics=diagnostics)


LOST = 0.1
"""A departure (relative to |Omega|) beyond which the trajectory is no prediction of the body's motion."""


def _moment_departure(
    frame: PrincipalFrame,
    classification: Classification,
    omega: Array,
    times: Array,
    tolerances: Tolerances,
    relative: float,
    omega_body: Array,
    attitude: Array,
    speed: float,
) -> float:
    """How far the exact motion moves when one moment moves by its error bound, either way (the largest).

    The trajectory is the motion of the moments computed, and the body's own moments may differ from
    them by ``relative``.  Mostly that moves the phase by about as much; but near the separatrix it can
    put the state on its other side (the body then circulates about the other axis), and for a pair of
    moments equal to rounding it decides whether Omega turns over at all, so the trajectory may be no
    prediction of the body's motion at all: the departure, measured, says so.
    """
    worst = 0.0
    moments = np.asarray(frame.moments, dtype=np.float64)
    for k in range(3):
        for sign in (1.0, -1.0):
            moved = moments.copy()
            moved[k] *= 1.0 + sign * relative
            if not moved[0] <= moved[1] <= moved[2]:
                continue  # a pair that would swap: the other pair's moves cover that side
            try:
                setup = decide_regime(replace(frame, moments=moved), classification, omega, tolerances, exact_moments=True)
                other_omega, other_attitude = EXACT_REST.propagate(setup, times, tolerances)
            except MotionError:
                continue  # a moved state float64 cannot place (within ~1e-150 of the separatrix)
            worst = max(worst, departure(other_omega, omega_body, other_attitude, attitude, speed))
    return worst


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


def _check_inertia(frame: PrincipalFrame) -> None:
    """The body must have inertia (the scale of the motion is otherwise free: see ``scaling``)."""
    largest = float(frame.moments[-1])
    if not (largest > 0 and np.isfinite(largest)):
        raise InvalidParameterError(
            "the body has no rotational inertia (all its mass is at one point), so its free rotation is undefined; leave out omega",
            parameter="omega",
        )


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
        raise InvalidParameterError(f"samples must be an integer from 2 to {MAX_SAMPLES}, got {samples!r}", parameter="samples")
    return np.linspace(0.0, float(duration), int(samples))


# -- the trajectory in the input frame ------------------------------------------------


def _trajectory(problem: RigidProblem, t: Array, omega_body: Array, attitude: Array, omega: Array) -> Trajectory:
    """Express the principal-frame attitude in the input frame.

    q = q_A q~ q_A* with q_A the principal->input rotation: the same angle about
    the rotated axis, so the scalar part is kept and the vector part is taken
    through the axes.  At t = 0 the state is the one given, exactly (API.md: the
    quaternion is the identity there): Omega as given (``omega``, computation
    units), Omega_body as the problem has it, whatever rounding the closed forms
    leave at their start.
    """
    q = np.concatenate([attitude[:, :1], attitude[:, 1:] @ problem.axes], axis=1)
    q = quat.canonical(q)
    omega_t = quat.rotate(q, omega_body @ problem.axes)
    start = t == 0.0
    if np.any(start):
        q[start] = (1.0, 0.0, 0.0, 0.0)
        omega_body = np.array(omega_body, dtype=np.float64)
        omega_body[start] = problem.omega_body
        omega_t[start] = omega
    return Trajectory(t=t, omega_body=omega_body, omega=omega_t, quaternion=q)
