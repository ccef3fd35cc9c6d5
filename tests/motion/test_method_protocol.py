"""The method protocol: every ``MotionMethod`` has its class, and the class states what it supports."""

from __future__ import annotations

from inertia.classification import RotorClass
from inertia.motion import CAPABILITIES, MotionMethod
from inertia.motion.methods import METHODS, PropagationMethod, method_for


def test_every_method_has_its_class() -> None:
    assert set(METHODS) == set(MotionMethod)
    for name in MotionMethod:
        method = method_for(name)
        assert isinstance(method, PropagationMethod)
        assert method.name is name
        assert CAPABILITIES[name] == method.capabilities


def test_only_the_exact_method_moves_a_linear_rotator() -> None:
    # the numerical methods divide by I1, which is zero for a linear rotator
    assert {name for name, caps in CAPABILITIES.items() if RotorClass.LINEAR in caps} == {MotionMethod.EXACT}
    assert CAPABILITIES[MotionMethod.EXACT] == frozenset(RotorClass)
