"""Hypothesis strategies and small mesh builders for the tests."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from benchmarks.cases import box


def convex_mesh(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closed, outward-wound triangle mesh of the convex hull of ``points``."""
    hull = ConvexHull(points)
    faces = hull.simplices.copy()
    centre = points[hull.vertices].mean(axis=0)
    for i, (a, b, c) in enumerate(faces):
        normal = np.cross(points[b] - points[a], points[c] - points[a])
        if np.dot(normal, points[a] - centre) < 0:
            faces[i] = [a, c, b]
    return points, faces


sizes = st.floats(min_value=0.05, max_value=20.0, allow_nan=False, allow_infinity=False)
rotations = st.integers(min_value=0, max_value=2**32 - 1).map(lambda seed: Rotation.random(random_state=seed).as_matrix())
offsets = st.lists(st.floats(min_value=-100, max_value=100, allow_nan=False), min_size=3, max_size=3).map(np.array)


@st.composite
def convex_bodies(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray]:
    """A random convex polyhedron (hull of 8-20 well-spread points)."""
    seed = draw(st.integers(min_value=0, max_value=2**32 - 1))
    n = draw(st.integers(min_value=8, max_value=20))
    rng = np.random.default_rng(seed)
    scale = np.array([draw(sizes), draw(sizes), draw(sizes)])
    pts = rng.normal(size=(n, 3)) * scale
    return convex_mesh(pts)


@st.composite
def boxes(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray]:
    return box(draw(sizes), draw(sizes), draw(sizes))
