"""The propagation methods: one class per ``MotionMethod``, each with the rotor classes it supports.

A method turns the ``Setup`` of the regime decision into Omega(t) in the
principal frame and the principal-frame attitude at the sample times.  As in
scipy's ``OdeSolver`` family, a method is a class that states its capability
(``capabilities``: the rotor classes it can propagate) and implements one
operation (``propagate``); ``predict_motion`` looks the class up by name
(``method_for``) and never dispatches on the name itself.  Adding a method is
adding a class here and a member to ``MotionMethod``.
"""

from __future__ import annotations

import abc
from collections.abc import Mapping
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from ..classification import RotorClass
from ..errors import MotionError
from ..tolerances import Tolerances
from .jacobi import AsymmetricTop
from .regime import Setup
from .result import MotionMethod, Regime
from .symmetric import SymmetricTop, rotator_motion, uniform_rotation

__all__ = ["PropagationMethod", "Exact", "Dop853", "Rk45", "Splitting", "METHODS", "CAPABILITIES", "EXACT_REST", "method_for"]

Array = NDArray[np.float64]

_NUMERICAL = frozenset({RotorClass.SPHERICAL, RotorClass.SYMMETRIC_PROLATE, RotorClass.SYMMETRIC_OBLATE, RotorClass.ASYMMETRIC})
"""The numerical methods need 1/I1, which a linear rotator (I1 = 0) lacks."""


class PropagationMethod(abc.ABC):
    """How Omega(t) and the attitude are computed, and for which rotor classes."""

    name: ClassVar[MotionMethod]
    capabilities: ClassVar[frozenset[RotorClass]]

    def check(self, rotor: RotorClass) -> None:
        """Raise ``MotionError`` when this method cannot propagate a body of class ``rotor``."""
        if rotor not in self.capabilities:
            raise MotionError(
                f"method={self.name.value!r} cannot propagate a {rotor.kind.replace('_', ' ')} "
                "(it needs 1/I1 and the smallest moment is zero); use method='exact'",
                parameter="method",
            )

    @abc.abstractmethod
    def propagate(self, setup: Setup, t: Array, tol: Tolerances) -> tuple[Array, Array]:
        """(omega_body (N, 3), attitude (N, 4)) of the setup's problem at the times ``t``."""


class Exact(PropagationMethod):
    """Closed forms (L&L §§33-37), Jacobi elliptic functions and Carlson R_J (Celledoni et al. 2008)."""

    name = MotionMethod.EXACT
    capabilities = frozenset(RotorClass)

    def propagate(self, setup: Setup, t: Array, tol: Tolerances) -> tuple[Array, Array]:
        problem = setup.problem
        if setup.regime is Regime.REGULAR_PRECESSION:
            assert setup.unique is not None
            return SymmetricTop(problem.moments, problem.omega_body, setup.unique).propagate(t)
        if setup.regime is Regime.ASYMMETRIC:
            # the motion of the state as given: only an exactly zero distance to the separatrix (computed
            # exactly) is the separatrix's own motion; within tol.separatrix_rel the quantities call it
            # separatrix (no period), but the hyperbolic limit would part from the true motion by O(1)
            # after ~ln(1/gap)/rate (the first approach to the intermediate axis)
            return AsymmetricTop.from_initial(problem.moments, problem.omega_body, 0.0).propagate(t)
        if setup.regime is Regime.ROTATOR:
            return rotator_motion(problem.omega_body, t)
        return uniform_rotation(problem.omega_body, t)


class _Scipy(PropagationMethod):
    """Euler's equations and the attitude by scipy's ``solve_ivp`` (imported when one runs)."""

    capabilities = _NUMERICAL

    def propagate(self, setup: Setup, t: Array, tol: Tolerances) -> tuple[Array, Array]:
        from .integrators import integrate_scipy

        return integrate_scipy(
            setup.problem, t, self.name.value, tol.integrator_rtol, tol.integrator_atol_rel, tol.max_integration_steps
        )


class Dop853(_Scipy):
    """Dormand-Prince, order 8."""

    name = MotionMethod.DOP853


class Rk45(_Scipy):
    """Dormand-Prince, order 5(4)."""

    name = MotionMethod.RK45


class Splitting(PropagationMethod):
    """Lie-Poisson Strang splitting of the exact sub-flows, order 2 (McLachlan 1993)."""

    name = MotionMethod.SPLITTING
    capabilities = _NUMERICAL

    def propagate(self, setup: Setup, t: Array, tol: Tolerances) -> tuple[Array, Array]:
        from .integrators import integrate_splitting, max_body_rate

        step = tol.splitting_step_angle / max_body_rate(setup.problem)
        return integrate_splitting(setup.problem, t, step, tol.max_integration_steps)


METHODS: Mapping[MotionMethod, PropagationMethod] = {m.name: m for m in (Exact(), Dop853(), Rk45(), Splitting())}
"""Every ``MotionMethod`` and its class (a test checks that none is missing)."""

CAPABILITIES: Mapping[MotionMethod, frozenset[RotorClass]] = {name: m.capabilities for name, m in METHODS.items()}
"""Which rotor classes each method supports; ``predict_motion`` checks it first."""


EXACT_REST = METHODS[MotionMethod.EXACT]
"""What propagates a body at rest, whatever the method asked for."""


def method_for(name: MotionMethod) -> PropagationMethod:
    """The method of that name."""
    return METHODS[name]
