"""The regime decision: which motion the body makes, and the ideal problem that is solved.

``decide_regime`` maps a principal frame, its classification and Omega(0) to a
``Setup``: the regime (rest, permanent rotation, spherical top, regular
precession, asymmetric top, linear rotator), its stability, the warnings, and
the ``RigidProblem`` whose motion the methods compute.  The modelling decisions
are stated in the package's docstring.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..classification import Classification, RotorClass
from ..principal import PrincipalFrame
from ..tolerances import EPS, Tolerances
from .invariants import RigidProblem
from .result import Regime

__all__ = ["Setup", "decide_regime", "ideal_moments", "motion_rotor", "MOTION_ROUNDING"]

MOTION_ROUNDING = 64 * EPS
"""Moments closer than this times the largest moment are equal to rounding: the
closed form of a symmetric, spherical or linear top is exact for them (their
spread is below the error of any computed moment)."""

Array = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class Setup:
    """What the regime decision produced: the problem to solve and its labels."""

    problem: RigidProblem
    regime: Regime
    stable: bool | None
    warnings: tuple[str, ...]
    unique: int | None = None  # symmetry axis index of a symmetric top
    initial: RigidProblem | None = None  # the state as given: reported M, E and omega_body come from it
    # the regime of the body's class where the motion is that of a finer class (moments equal within the
    # classification's tolerance, apart by more than rounding): the precession section names it and gives
    # its quantities (API.md), the trajectory stays the motion of ``problem``; ``label_unique`` is the
    # symmetry axis index of a symmetric top's label
    label: Regime | None = None
    label_unique: int | None = None


def decide_regime(
    frame: PrincipalFrame,
    classification: Classification,
    omega: Array,
    tol: Tolerances,
    exact_moments: bool = False,
) -> Setup:
    """The regime, and the ideal problem that is solved; the state as given is kept beside it.

    ``omega`` is in the computation's units (``scaling.Units``); the regime does not depend on them.
    ``exact_moments``: the moments are numbers given, not computed (see ``motion_rotor``).
    """
    decided = _decide(frame, classification, omega, tol, exact_moments)
    axes = np.asarray(frame.axes, dtype=np.float64)
    given = RigidProblem(np.asarray(frame.moments, dtype=np.float64), axes @ omega, axes, frame.quaternion)
    return _labelled(replace(decided, initial=given), classification)


def _labelled(setup: Setup, classification: Classification) -> Setup:
    """The regime the classification names (API.md: spherical for a spherical top, regular_precession or
    permanent_rotation for a symmetric top), where the motion is computed as a finer class's."""
    rotor, regime = classification.rotor, setup.regime
    if rotor is RotorClass.SPHERICAL and regime not in (Regime.REST, Regime.SPHERICAL):
        label, unique = Regime.SPHERICAL, None
    elif rotor is RotorClass.LINEAR and _needle_moves(setup):
        # a body of I1 > 0 within tolerance of zero: the rotator's label, the needle's own rates
        label, unique = Regime.ROTATOR, 0
    elif rotor.is_symmetric and regime is Regime.ASYMMETRIC:
        unique = 0 if rotor is RotorClass.SYMMETRIC_PROLATE else 2
        label = Regime.REGULAR_PRECESSION if setup.problem.omega_body[unique] != 0.0 else Regime.PERMANENT_ROTATION
    elif rotor.is_symmetric and regime is Regime.PERMANENT_ROTATION and setup.stable is False:
        # about the intermediate axis of moments the class calls equal (always one of the equal pair): the
        # symmetric top's permanent rotation across its axis, which is stable (API.md: only an asymmetric
        # top's intermediate axis is unstable); the trajectory is still the motion of the moments as they are
        label, unique = Regime.PERMANENT_ROTATION, None
    else:
        return setup
    moments = np.asarray(setup.problem.moments, dtype=np.float64)
    if label is Regime.ROTATOR:
        note = (
            f"the smallest principal moment is {float(moments[0] / moments[-1]):.2g} of the largest, within the "
            f"tolerance {classification.tolerance:g} of zero: the precession section names the rotator regime of "
            "that linear_rotator, with the rates of the body's own moments; the trajectory is its motion"
        )
        return replace(setup, label=label, label_unique=unique, warnings=(*setup.warnings, note))
    spread = float(moments[-1] - moments[0]) if label is Regime.SPHERICAL else _pair_gap(moments, rotor)
    note = (
        f"the principal moments the classification calls equal differ by {spread / float(moments[-1]):.2g} of the "
        f"largest, within its tolerance {classification.tolerance:g}: the precession section reports the "
        f"{label.value} regime of that {rotor.kind} (its rates from the equal moments' mean); the trajectory is the "
        "motion of the moments as they are"
    )
    return replace(setup, label=label, label_unique=unique, warnings=(*setup.warnings, note))


def _needle_moves(setup: Setup) -> bool:
    """A linear rotator's class on a body whose smallest moment is not 0: the motion is that of a prolate
    or asymmetric top, unless it is a spin about the needle's own axis (a permanent rotation it is)."""
    if setup.regime in (Regime.REGULAR_PRECESSION, Regime.ASYMMETRIC):
        return True
    return setup.regime is Regime.PERMANENT_ROTATION and setup.problem.omega_body[0] == 0.0


def _pair_gap(moments: Array, rotor: RotorClass) -> float:
    return float(moments[2] - moments[1]) if rotor is RotorClass.SYMMETRIC_PROLATE else float(moments[1] - moments[0])


def _decide(frame: PrincipalFrame, classification: Classification, omega: Array, tol: Tolerances, exact_moments: bool) -> Setup:
    axes = np.asarray(frame.axes, dtype=np.float64)
    omega_body = axes @ omega
    rotor = motion_rotor(frame, classification, exact_moments)
    moments = ideal_moments(np.asarray(frame.moments, dtype=np.float64), rotor)
    warnings: list[str] = []
    given = np.asarray(frame.moments, dtype=np.float64)
    if rotor is RotorClass.LINEAR and given[2] - given[1] > MOTION_ROUNDING * given[2]:
        warnings.append(
            f"the smallest moment is zero, so all mass is on a line and the other two moments are equal; the "
            f"given ones differ by {(given[2] - given[1]) / given[2]:.2g} of the largest, and their mean was used"
        )
    problem = RigidProblem(moments, omega_body, axes, frame.quaternion)
    rate = float(np.linalg.norm(omega_body))
    if rate == 0.0:
        return Setup(problem, Regime.REST, None, tuple(warnings))
    if rotor is RotorClass.SPHERICAL:
        return Setup(problem, Regime.SPHERICAL, True, tuple(warnings))
    # Omega_body = axes @ Omega carries rounding (and the axes their own error) unless the axes are an
    # exact signed permutation (principal moments given, a diagonal tensor): then a tilt is real, even
    # 1e-17, and moves as it does (about the intermediate axis it grows to a flip after ~40 / rate)
    noise = 0.0 if exact_axes(axes) else tol.permanent_rotation_rel
    if rotor is RotorClass.LINEAR:
        # the spin about the rotator's own axis carries no M or E and moves no mass, but it turns the body's
        # frame: it is kept, so that Omega(t) starts as given (the limit of a needle as I1 -> 0)
        if float(np.hypot(omega_body[1], omega_body[2])) <= noise * rate:
            return Setup(_snap(problem, 0, None), Regime.PERMANENT_ROTATION, True, tuple(warnings))
        if abs(float(omega_body[0])) <= noise * rate:  # a spin of rounding only: no spin, no period of it
            return Setup(_snap(problem, None, 0), Regime.ROTATOR, True, tuple(warnings))
        return Setup(problem, Regime.ROTATOR, True, tuple(warnings))
    along_axis = _principal_axis_of(omega_body, noise)
    if rotor.is_symmetric:
        unique = 0 if rotor is RotorClass.SYMMETRIC_PROLATE else 2
        perpendicular = abs(omega_body[unique]) <= noise * rate
        if along_axis is not None or perpendicular:
            snapped = _snap(problem, along_axis, unique if perpendicular else None)
            return Setup(snapped, Regime.PERMANENT_ROTATION, True, tuple(warnings))
        return Setup(problem, Regime.REGULAR_PRECESSION, True, tuple(warnings), unique)
    if along_axis is not None:
        return Setup(_snap(problem, along_axis, None), Regime.PERMANENT_ROTATION, along_axis != 1, tuple(warnings))
    nearest = int(np.argmax(np.abs(omega_body)))
    return Setup(problem, Regime.ASYMMETRIC, nearest != 1, tuple(warnings))


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


def motion_rotor(frame: PrincipalFrame, classification: Classification, exact_moments: bool = False) -> RotorClass:
    """The rotor class whose motion is computed: the classification's only where its moments agree to rounding.

    The classification labels the body with its own ``tolerance``; the motion
    uses a closed form (symmetric, spherical, linear) only for moments equal
    within ``MOTION_ROUNDING`` (or the classification's tolerance, if smaller),
    and for moments the caller knows to be exact (``exact_moments``: principal
    moments given as numbers) only for equal ones.  A smallest moment of
    exactly 0 is a linear rotator in any case.
    Otherwise the class is decided again at that level, so a nearly symmetric
    top moves as the asymmetric top it is.
    """
    from ..classification import classify

    if float(frame.moments[0]) == 0.0 < float(frame.moments[-1]):
        # all mass on a line: I2 = I3 whatever rounding (within the triangle inequality's allowance) left
        return RotorClass.LINEAR
    # exact moments carry no rounding to forgive; computed ones (a mesh's, a tensor's eigenvalues) do,
    # even where their axes came out exact (an axis-aligned part)
    level = 0.0 if exact_moments else min(MOTION_ROUNDING, classification.tolerance)
    if classification.tolerance <= level:
        return classification.rotor
    return classify(frame, level).rotor


def exact_axes(axes: ArrayLike) -> bool:
    """Whether the principal axes are a signed permutation of the input axes, exactly.

    Then the moments and ``axes @ Omega`` are the numbers given (principal moments, a diagonal
    tensor) with no rounding of a rotation in them.
    """
    a = np.asarray(axes, dtype=np.float64)
    return bool(np.all((a == 0.0) | (np.abs(a) == 1.0)))


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
