"""Hypothesis invariants of the mass properties (Landau & Lifshitz §32)."""

from __future__ import annotations

from typing import Any

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia.body import MeshBody, PointBody
from inertia.mass import mass_properties, parallel_axis
from tests.support.strategies import boxes, convex_bodies, offsets, rotations

FAST = settings(max_examples=40, deadline=None)


def props_of(mesh: tuple[np.ndarray, np.ndarray], **kw: Any) -> Any:
    return mass_properties(MeshBody(*mesh), **kw)


def scale_of(props: Any) -> float:
    return float(np.max(np.abs(props.principal_moments)))


@FAST
@given(convex_bodies(), rotations)
def test_rotating_the_body_rotates_the_tensor(mesh: Any, rotation: Any) -> None:
    v, f = mesh
    base = props_of(mesh)
    turned = mass_properties(MeshBody(v @ rotation.T, f))
    expected = rotation @ base.inertia.matrix @ rotation.T
    np.testing.assert_allclose(turned.inertia.matrix, expected, atol=1e-12 * scale_of(base))
    np.testing.assert_allclose(turned.center_of_mass, rotation @ base.center_of_mass, atol=1e-12 * np.abs(v).max())


@FAST
@given(convex_bodies(), offsets)
def test_translation_leaves_the_centre_of_mass_tensor_alone(mesh: Any, offset: Any) -> None:
    v, f = mesh
    base = props_of(mesh)
    moved = mass_properties(MeshBody(v + offset, f))
    np.testing.assert_allclose(moved.inertia.matrix, base.inertia.matrix, atol=1e-12 * scale_of(base))
    np.testing.assert_allclose(
        moved.center_of_mass, base.center_of_mass + offset, atol=1e-12 * (np.abs(offset).max() + np.abs(v).max())
    )


@FAST
@given(convex_bodies(), st.floats(min_value=1e-3, max_value=1e3))
def test_scaling_by_s_scales_inertia_by_s_to_the_fifth(mesh: Any, s: Any) -> None:
    v, f = mesh
    base = props_of(mesh)
    scaled = mass_properties(MeshBody(v * s, f))
    np.testing.assert_allclose(np.sort(scaled.principal_moments), np.sort(base.principal_moments) * s**5, rtol=1e-12)
    np.testing.assert_allclose(scaled.mass, base.mass * s**3, rtol=1e-13)


@FAST
@given(boxes(), boxes())
def test_inertia_of_disjoint_parts_adds_up(first: Any, second: Any) -> None:
    (v1, f1), (v2, f2) = first, second
    v2 = v2 + np.array([v1[:, 0].max() + 1.0, 0.0, 0.0])  # beside the first, not touching
    a, b = props_of((v1, f1)), props_of((v2, f2))
    both = mass_properties(MeshBody(np.vstack([v1, v2]), np.vstack([f1, f2 + len(v1)])))
    total = a.mass + b.mass
    com = (a.mass * a.center_of_mass + b.mass * b.center_of_mass) / total
    expected = parallel_axis(a.inertia.matrix, a.mass, a.center_of_mass - com) + parallel_axis(
        b.inertia.matrix, b.mass, b.center_of_mass - com
    )
    np.testing.assert_allclose(both.mass, total, rtol=1e-13)
    np.testing.assert_allclose(both.inertia.matrix, expected, atol=1e-12 * np.abs(expected).max())


@FAST
@given(convex_bodies())
def test_principal_moments_obey_triangle_inequality_and_mass_is_positive(mesh: Any) -> None:
    props = props_of(mesh)
    i1, i2, i3 = np.sort(props.principal_moments)
    assert props.mass > 0
    assert i1 > 0
    assert i1 + i2 >= i3 * (1 - 1e-14)


@FAST
@given(convex_bodies(), st.permutations(list(range(20))))
def test_vertex_reindexing_changes_nothing(mesh: Any, perm: tuple[int, ...]) -> None:
    v, f = mesh
    n = len(v)
    order = np.array([p for p in perm if p < n] + list(range(20, n)))
    inverse = np.empty(n, dtype=int)
    inverse[order] = np.arange(n)
    base = props_of(mesh)
    shuffled = mass_properties(MeshBody(v[order], inverse[f]))
    np.testing.assert_allclose(shuffled.inertia.matrix, base.inertia.matrix, atol=1e-13 * scale_of(base))


@FAST
@given(st.integers(min_value=2, max_value=40), st.integers(min_value=0, max_value=2**32 - 1), rotations)
def test_point_sets_rotate_covariantly(n: int, seed: int, rotation: Any) -> None:
    rng = np.random.default_rng(seed)
    masses = rng.uniform(0.1, 10.0, n)
    x = rng.normal(size=(n, 3))
    base = mass_properties(PointBody(masses, x))
    turned = mass_properties(PointBody(masses, x @ rotation.T))
    scale = max(scale_of(base), 1e-300)
    np.testing.assert_allclose(turned.inertia.matrix, rotation @ base.inertia.matrix @ rotation.T, atol=1e-12 * scale)
    i1, i2, i3 = np.sort(base.principal_moments)
    assert i1 + i2 >= i3 * (1 - 1e-13)
