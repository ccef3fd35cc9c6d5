"""Principal frame conventions and classification."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from inertia.classification import RotorClass, classify, ray_asymmetry
from inertia.conventions import matrix_from_quaternion
from inertia.eigen import jacobi_eigh
from inertia.errors import InvalidParameterError
from inertia.principal import PrincipalFrame


def frame_of(moments: list[float], rotation: np.ndarray | None = None, tol: float = 1e-6) -> PrincipalFrame:
    r = np.eye(3) if rotation is None else rotation
    return PrincipalFrame.from_tensor(r @ np.diag(moments) @ r.T, tol)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.lists(st.floats(0.1, 10.0), min_size=3, max_size=3))
def test_frame_is_right_handed_ascending_and_matches_its_quaternion(seed: int, raw: list[float]) -> None:
    a, b, c = sorted(raw)
    c = min(c, a + b)  # keep a physical tensor
    rot = Rotation.random(random_state=seed).as_matrix()
    frame = frame_of([a, b, c], rot)
    assert np.all(np.diff(frame.moments) >= 0)
    assert np.linalg.det(frame.axes) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(matrix_from_quaternion(frame.quaternion), frame.axes.T, atol=1e-12)
    assert frame.quaternion[0] >= 0
    tensor = rot @ np.diag([a, b, c]) @ rot.T
    np.testing.assert_allclose(frame.axes.T @ np.diag(frame.moments) @ frame.axes, tensor, atol=1e-12 * c)


def test_sign_rule_makes_largest_component_positive() -> None:
    frame = frame_of([1.0, 2.0, 3.0], -np.eye(3)[[1, 0, 2]] * np.array([1, 1, -1]))
    for axis in frame.axes[:2]:
        assert axis[np.argmax(np.abs(axis))] > 0


def test_jacobi_keeps_relative_accuracy_of_tiny_eigenvalue() -> None:
    rot = Rotation.from_euler("xyz", [0.2, 0.5, 0.9]).as_matrix()
    values, _ = jacobi_eigh(np.diag([1e-12, 1.0, 1.0 + 1e-3]))
    assert sorted(values)[0] == 1e-12
    values, vectors = jacobi_eigh(rot @ np.diag([3.0, 1.0, 2.0]) @ rot.T)
    np.testing.assert_allclose(sorted(values), [1.0, 2.0, 3.0], rtol=1e-14)
    np.testing.assert_allclose(vectors @ vectors.T, np.eye(3), atol=1e-14)


@pytest.mark.parametrize(
    "moments,rotor,shape",
    [
        ([2.0, 2.0, 2.0], RotorClass.SPHERICAL, None),
        ([1.0, 2.0, 2.0], RotorClass.SYMMETRIC_PROLATE, "prolate"),
        ([1.0, 1.0, 2.0], RotorClass.SYMMETRIC_OBLATE, "oblate"),
        ([1.0, 1.5, 2.0], RotorClass.ASYMMETRIC, None),
        ([0.0, 1.0, 1.0], RotorClass.LINEAR, None),
    ],
)
def test_classes(moments: list[float], rotor: RotorClass, shape: str | None) -> None:
    cls = classify(frame_of(moments))
    assert cls.rotor is rotor
    assert cls.shape == shape


def test_symmetry_axis_is_the_unique_axis() -> None:
    rot = Rotation.from_euler("xyz", [0.4, -0.3, 1.2]).as_matrix()
    cls = classify(frame_of([1.0, 3.0, 3.0], rot))
    unique = rot[:, 0]
    assert cls.symmetry_axis is not None
    assert abs(np.dot(cls.symmetry_axis, unique)) == pytest.approx(1.0, abs=1e-12)


def test_ray_kappa_from_rotational_constants() -> None:
    i1, i2, i3 = 1.0, 1.5, 2.0
    a, b, c = 1 / i1, 1 / i2, 1 / i3
    assert ray_asymmetry(np.array([i1, i2, i3])) == pytest.approx((2 * b - a - c) / (a - c), rel=1e-15)
    assert ray_asymmetry(np.array([1.0, 2.0, 2.0])) == -1.0
    assert ray_asymmetry(np.array([1.0, 1.0, 2.0])) == 1.0


def test_kappa_is_not_rounded_within_tolerance() -> None:
    cls = classify(frame_of([1.0, 2.0, 2.0 + 1e-9]))
    assert cls.rotor is RotorClass.SYMMETRIC_PROLATE
    assert cls.asymmetry != -1.0 and cls.asymmetry == pytest.approx(-1.0, abs=1e-8)


def test_planar_flag_for_lamina() -> None:
    assert classify(frame_of([1.0, 2.0, 3.0])).planar
    assert not classify(frame_of([1.5, 2.0, 3.0])).planar


def test_classification_does_not_depend_on_comparison_order() -> None:
    # gaps 0.6 tol and 0.7 tol: spread 1.3 tol > tol, so only the smaller gap is an equal pair
    tol = 1e-6
    i3 = 1.0
    frame = frame_of([i3 - 1.3e-6, i3 - 0.7e-6, i3], tol=tol)
    assert classify(frame).rotor is RotorClass.SYMMETRIC_OBLATE
    mirrored = frame_of([i3 - 1.3e-6, i3 - 0.6e-6, i3], tol=tol)
    assert classify(mirrored).rotor is RotorClass.SYMMETRIC_PROLATE


def test_tolerance_decides_near_symmetric_box() -> None:
    moments = [1.0, 1.0 + 1e-9 * 2, 2.0]
    assert classify(frame_of(moments, tol=1e-6)).rotor is RotorClass.SYMMETRIC_OBLATE
    assert classify(frame_of(moments, tol=1e-10)).rotor is RotorClass.ASYMMETRIC


@pytest.mark.parametrize(
    "tensor",
    [np.diag([1.0, 1.0, 3.0]), np.diag([-1.0, 2.0, 2.0]), np.zeros((3, 3)), np.array([[1.0, 0.5, 0], [0, 1, 0], [0, 0, 1]])],
)
def test_unphysical_tensors_are_rejected(tensor: np.ndarray) -> None:
    with pytest.raises(InvalidParameterError):
        PrincipalFrame.from_tensor(tensor)


@pytest.mark.parametrize("scale", [1e-300, 1.0, 1e300])
def test_kappa_does_not_depend_on_scale(scale: float) -> None:
    i1, i2, i3 = 1.0, 2.0, 3.0
    a, b, c = 1 / i1, 1 / i2, 1 / i3
    expected = (2 * b - a - c) / (a - c)
    assert ray_asymmetry(np.array([i1, i2, i3]) * scale) == pytest.approx(expected, rel=1e-14)


def test_a_class_decided_within_the_error_estimate_is_flagged() -> None:
    """I2 - I1 = 1.5e-6 I3 against the tolerance 1e-6: asymmetric, but with moments known only to 1e-3
    (a CAD file whose faces leave gaps) that gap says nothing, and the result must say so."""
    from inertia.pipeline import uncertain_class

    cls = classify(PrincipalFrame.from_eigen(np.array([1.0, 1.0 + 3e-6, 2.0]), np.eye(3), 1e-6))
    assert cls.rotor is RotorClass.ASYMMETRIC
    [warning] = uncertain_class(cls, 1e-3)
    assert "(I2 - I1) / I3 = 1.5e-06" in warning and "1e-06" in warning and "0.001" in warning
    assert uncertain_class(cls, 1e-12) == []
    exact = classify(PrincipalFrame.from_eigen(np.array([1.0, 1.0, 2.0]), np.eye(3), 1e-6))
    assert uncertain_class(exact, 1e-12) == []
