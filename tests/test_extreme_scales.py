"""Huge and tiny scales: a power-of-two change of scale changes the results by exactly that power.

Scaling a body's tensor by 2**k is exact in floating point, so every eigenvalue must scale by exactly 2**k
and the eigenvectors must not change at all, until the values themselves leave float64's range.  Before the
eigen-kernel rescaled such matrices, the product of two diagonal entries overflowed above ~2**512: every
off-diagonal then looked negligible and a rotated tensor came back unrotated, its "principal moments" the
diagonal of the rotated matrix (43 % off for a box 1e40 m across).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from benchmarks.cases import box, write_obj
from inertia import analyze
from inertia.eigen import jacobi_eigh
from inertia.errors import InvalidParameterError

_ROTATION_ANGLES = st.tuples(*(st.floats(-math.pi, math.pi) for _ in range(3)))
_MOMENTS = st.tuples(*(st.floats(0.01, 100.0) for _ in range(3)))


def _rotation(angles: tuple[float, float, float]) -> np.ndarray:
    ax, ay, az = angles
    rx = np.array([[1, 0, 0], [0, math.cos(ax), -math.sin(ax)], [0, math.sin(ax), math.cos(ax)]])
    ry = np.array([[math.cos(ay), 0, math.sin(ay)], [0, 1, 0], [-math.sin(ay), 0, math.cos(ay)]])
    rz = np.array([[math.cos(az), -math.sin(az), 0], [math.sin(az), math.cos(az), 0], [0, 0, 1]])
    rotation: np.ndarray = rz @ ry @ rx
    return rotation


@settings(max_examples=60, deadline=None)
@given(_ROTATION_ANGLES, _MOMENTS, st.integers(-1000, 1000))
def test_eigen_kernel_is_exactly_scale_invariant(
    angles: tuple[float, float, float], moments: tuple[float, float, float], exponent: int
) -> None:
    rotation = _rotation(angles)
    tensor = rotation @ np.diag(moments) @ rotation.T
    tensor = 0.5 * (tensor + tensor.T)
    scaled = np.ldexp(tensor, exponent)
    assume(np.array_equal(np.ldexp(scaled, -exponent), tensor))  # no entry fell into the subnormals on the way
    values, vectors = jacobi_eigh(tensor)
    scaled_values, scaled_vectors = jacobi_eigh(scaled)
    assert np.array_equal(scaled_values, np.ldexp(values, exponent))
    assert np.array_equal(scaled_vectors, vectors)


def test_rotated_tensor_of_1e200_is_diagonalised() -> None:
    rotation = _rotation((0.3, 0.5, 0.7))
    moments = np.array([1.0, 2.0, 3.0])
    tensor = rotation @ np.diag(moments) @ rotation.T * 1e200
    values, vectors = jacobi_eigh(tensor)
    order = np.argsort(values)
    assert np.allclose(values[order] / 1e200, moments, rtol=1e-14, atol=0)
    # each eigenvector is (up to sign) a column of the rotation
    alignment = np.abs(vectors[order] @ rotation)
    assert np.allclose(alignment, np.eye(3), atol=1e-14)


def _rotated_box_file(tmp_path: Path, size: float) -> tuple[Path, np.ndarray, tuple[float, float, float]]:
    sides = (size, 2.0 * size, 3.0 * size)
    vertices, faces = box(*sides)
    rotation = _rotation((0.3, 0.5, 0.7))
    path = tmp_path / "box.obj"
    write_obj(path, (vertices - vertices.mean(axis=0)) @ rotation.T, faces)
    return path, rotation, sides


@pytest.mark.parametrize("size", [1e-50, 1e-20, 1e20, 1e40, 1e58])
def test_rotated_box_at_extreme_sizes_matches_the_closed_form(tmp_path: Path, size: float) -> None:
    """Principal moments M (b^2 + c^2) / 12 ... and the box's own axes, with no overflow warning (an error here)."""
    path, rotation, (a, b, c) = _rotated_box_file(tmp_path, size)
    result = analyze(str(path)).as_dict()
    mass = result["mass"]
    assert mass == pytest.approx(1000.0 * a * b * c, rel=1e-14)
    expected = sorted(mass / 12.0 * x for x in (b * b + c * c, a * a + c * c, a * a + b * b))
    assert np.allclose(result["principal"]["moments"], expected, rtol=1e-14, atol=0)
    alignment = np.abs(np.asarray(result["principal"]["axes"]) @ rotation).max(axis=1)
    assert np.allclose(alignment, 1.0, rtol=0, atol=1e-14)


@pytest.mark.parametrize("size", [1e-60, 1e-75, 1e-110])
def test_mesh_whose_moments_underflow_is_refused_with_its_size(tmp_path: Path, size: float) -> None:
    path, _, _ = _rotated_box_file(tmp_path, size)
    with pytest.raises(InvalidParameterError, match="underflow float64") as caught:
        analyze(str(path))
    assert f"{3.5 * size:.2g}"[:3] in str(caught.value)  # the part's size, in the message


def test_a_tensor_near_the_top_of_float64_is_diagonalised_without_overflow() -> None:
    # symmetrising (x + y) / 2 and the triangle inequality I1 + I2 >= I3 both summed entries near 1e308;
    # the eigenvalues of a diagonal tensor are its diagonal, exactly, and no step may overflow on the way
    import warnings

    from inertia.principal import PrincipalFrame

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        frame = PrincipalFrame.from_tensor(np.diag([1e308, 1.5e308, 1.7e308]))
    assert frame.moments.tolist() == [1e308, 1.5e308, 1.7e308]


@pytest.mark.parametrize(
    ("offset", "scale", "blamed"),
    [(1e5, 1e-3, True), (0.0, 1.0, False)],
    ids=["a-millimetre-part-100-km-out", "a-shape-squashed-onto-itself-at-the-origin"],
)
def test_a_mesh_of_collapsed_triangles_blames_float32_only_where_its_steps_explain_it(
    offset: float, scale: float, blamed: bool
) -> None:
    from benchmarks.cases import stl_bytes
    from inertia.errors import ZeroVolumeError
    from inertia.pipeline import analyze

    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]) * scale + offset
    if not blamed:  # corners written onto each other in pairs: every face collapses in the file itself
        v[1], v[3] = v[0], v[2]
    f = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    with pytest.raises(ZeroVolumeError, match="every triangle of the mesh is degenerate") as err:
        analyze(stl_bytes(v, f), filename="tet.stl")
    assert ("float32 coordinates are too coarse" in str(err.value)) is blamed
