"""The quantities of the API's ``precession`` section: M, E, rates, angles, periods of the regime."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..classification import RotorClass
from ..tolerances import Tolerances
from .jacobi import AsymmetricTop
from .regime import Setup, ideal_moments
from .result import FreeMotion, MotionDiagnostics, MotionMethod, Regime
from .symmetric import SymmetricTop

__all__ = ["precession_quantities"]


def precession_quantities(setup: Setup, method: MotionMethod, tol: Tolerances, tolerance: float = 0.0) -> FreeMotion:
    """The precession section's quantities; ``tolerance``: the request's relative tolerance, within which
    the state counts as on the separatrix (2 E I2 = |M|^2 within tolerance: no period, API.md)."""
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
    if setup.label is not None:
        return _labelled_quantities(base, setup)
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
        # M is perpendicular to the axis; a spin a about the axis adds the needle's limit rates (I1 -> 0):
        # Omega turns about the axis in the body at -a, the body spins about it at a (``rotator_motion``)
        spin = float(problem.omega_body[0])
        return replace(
            base,
            space_precession_rate=float(np.hypot(problem.omega_body[1], problem.omega_body[2])),
            nutation_angle=0.5 * np.pi,
            body_precession_rate=-spin if spin != 0.0 else None,
            spin_rate=spin if spin != 0.0 else None,
            period=2.0 * np.pi / abs(spin) if spin != 0.0 else None,
        )
    if setup.regime is Regime.ASYMMETRIC:
        near = max(tol.separatrix_rel, tolerance)
        return _asymmetric_quantities(base, AsymmetricTop.from_initial(problem.moments, problem.omega_body, near), tol)
    return base


def _labelled_quantities(base: FreeMotion, setup: Setup) -> FreeMotion:
    """The section of the regime the classification names (``Setup.label``): a symmetric top's rates are
    those of its ideal top, the equal pair's mean moment (L&L §§33-36), from the state as given; a needle
    labelled a rotator has the prolate top's rates of its own moments (the pair's mean)."""
    assert setup.label is not None
    labelled = replace(base, regime=setup.label, stable=True)
    if setup.label not in (Regime.REGULAR_PRECESSION, Regime.ROTATOR):
        return labelled
    assert setup.label_unique is not None
    unique = setup.label_unique
    rotor = RotorClass.SYMMETRIC_PROLATE if unique == 0 else RotorClass.SYMMETRIC_OBLATE
    top = SymmetricTop(ideal_moments(setup.problem.moments, rotor), setup.problem.omega_body, unique)
    rate = top.body_precession_rate
    return replace(
        labelled,
        body_precession_rate=rate if rate != 0.0 else None,
        space_precession_rate=top.space_precession_rate,
        spin_rate=top.spin_rate if rate != 0.0 else None,
        nutation_angle=top.nutation_angle,
        period=2.0 * np.pi / abs(rate) if rate != 0.0 else None,
    )


def _asymmetric_quantities(base: FreeMotion, top: AsymmetricTop, tol: Tolerances) -> FreeMotion:
    if top.separatrix and AsymmetricTop.from_initial(top.moments, top.omega_body, 0.0).separatrix:
        warning = (
            "Omega starts on the separatrix (2 E I2 = |M|^2 exactly): the motion approaches "
            "rotation about the intermediate axis forever, so it has no period"
        )
        return replace(base, warnings=(*base.warnings, warning))
    if top.separatrix:
        exact = AsymmetricTop.from_initial(top.moments, top.omega_body, tol.separatrix_rel)
        if exact.separatrix:
            warning = (
                "Omega starts within rounding of the separatrix (2 E I2 = |M|^2 to ~1e-15 relative), so no "
                "period is reported: it is finite, but it and the distance to the separatrix are set by the "
                "last digits of the input; the trajectory is the motion of the numbers as given"
            )
        else:
            warning = (
                "Omega starts within the tolerance of the separatrix (2 E I2 = |M|^2 within it), so no period is "
                "reported (API.md): the motion as given has a finite one, which grows without bound as the state "
                "nears the separatrix; the trajectory is the motion of the numbers as given"
            )
        return replace(base, warnings=(*base.warnings, warning))
    period = top.period
    flip = 0.5 * period if base.stable is False else None
    return replace(base, period=period, flip_interval=flip)
