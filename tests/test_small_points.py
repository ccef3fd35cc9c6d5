"""The small point-set path (``inertia.mass.points``) gives, bit for bit, what the numpy kernels give.

Expected values are the numpy kernels' own (``integrals.point_sums`` over ``ddouble.rotated``), the
path the small one replaces: the claim is identity, so nothing weaker than identical bytes passes.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import inertia.mass.points as small
from inertia.ddouble import rotated
from inertia.errors import ServiceError
from inertia.integrals import Sums, point_sums
from inertia.mass.points import SMALL_POINTS, pairwise_sum, small_point_sums
from inertia.options import AnalysisOptions
from inertia.pipeline import analyze_points

coordinates = st.one_of(
    st.floats(min_value=-1e3, max_value=1e3, allow_nan=False),
    st.sampled_from([0.0, -0.0, 1.0, -1.0, 0.5, 1e-300, -1e-300]),
    st.floats(min_value=-1e12, max_value=1e12, allow_nan=False),
)
masses = st.one_of(st.floats(min_value=1e-6, max_value=1e6), st.sampled_from([1.0, 2.0, 16.0, 1e-3]))
offsets = st.sampled_from([0.0, 1e-3, 1.0, 1e6, -1e9, 1e15])


@st.composite
def point_sets(draw: st.DrawFn, max_size: int = SMALL_POINTS) -> tuple[np.ndarray, np.ndarray]:
    n = draw(st.integers(min_value=1, max_value=max_size))
    m = np.array(draw(st.lists(masses, min_size=n, max_size=n)))
    x = np.array(draw(st.lists(st.lists(coordinates, min_size=3, max_size=3), min_size=n, max_size=n)))
    if draw(st.booleans()):  # collinear: every point on one line
        x = np.outer(x[:, 0], [1.0, -2.0, 0.5])
    if draw(st.booleans()):  # repeated points
        x[n // 2 :] = x[0]
    return m, x + draw(offsets)


def _same(a: Sums, b: Sums) -> None:
    for name in Sums.__slots__:
        left, right = np.asarray(getattr(a, name)), np.asarray(getattr(b, name))
        assert left.dtype == right.dtype and left.tobytes() == right.tobytes(), name


def _numpy_sums(m: np.ndarray, x: np.ndarray, origin: np.ndarray, rotation: np.ndarray | None) -> Sums | None:
    try:
        with np.errstate(over="raise", invalid="raise"):
            y = x - origin if rotation is None else rotated(x, origin, rotation)
            return point_sums(m, y)
    except FloatingPointError:
        return None


@settings(max_examples=400, deadline=None)
@given(point_sets(), st.integers(min_value=0, max_value=2**32 - 1), st.booleans())
def test_sums_equal_the_numpy_kernels_bit_for_bit(points: tuple[np.ndarray, np.ndarray], seed: int, turn: bool) -> None:
    m, x = points
    origin = x[len(x) // 2] + np.array([0.25, -0.5, 0.0])
    rotation = Rotation.random(random_state=seed).as_matrix() if turn else None
    want = _numpy_sums(m, x, origin, rotation)
    got = small_point_sums(m.tolist(), x.tolist(), origin, rotation)
    if want is None:
        assert got is None
    else:
        assert got is not None
        _same(got, want)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(min_value=-1e300, max_value=1e300, allow_nan=False), min_size=1, max_size=128))
def test_pairwise_sum_is_numpys(values: list[float]) -> None:
    assert np.float64(pairwise_sum(values)).tobytes() == np.array(values).sum().tobytes()


def _analysis(m: np.ndarray, x: np.ndarray, options: dict[str, Any]) -> str:
    records = [{"mass": float(mi), "position": [float(c) for c in xi]} for mi, xi in zip(m, x)]
    try:
        doc = analyze_points(records, AnalysisOptions(**options)).as_dict()
    except ServiceError as exc:
        return json.dumps(exc.as_dict())
    doc["diagnostics"].pop("elapsed_s")
    doc.get("precession", {}).get("diagnostics", {}).pop("elapsed_s", None)
    return json.dumps(doc, sort_keys=True)


def _both(m: np.ndarray, x: np.ndarray, options: dict[str, Any]) -> tuple[str, str]:
    """The analysis with the small path, and with every point set through numpy."""
    fast = _analysis(m, x, options)
    saved = small.SMALL_POINTS
    small.SMALL_POINTS = 0
    try:
        return fast, _analysis(m, x, options)
    finally:
        small.SMALL_POINTS = saved


@settings(max_examples=150, deadline=None)
@given(point_sets(), st.sampled_from([{}, {"omega": (0.3, -1.0, 2.0)}, {"reference": (1.0, 2.0, 3.0), "units": "mm"}]))
def test_analysis_json_is_the_same_with_and_without_the_small_path(
    points: tuple[np.ndarray, np.ndarray], options: dict[str, Any]
) -> None:
    fast, general = _both(*points, options)
    assert fast == general


def test_overflow_is_the_same_error_on_both_paths() -> None:
    fast, general = _both(np.array([1.0, 1.0]), np.array([[1e200, 0.0, 0.0], [-1e200, 3e200, 0.0]]), {})
    assert fast == general
    assert json.loads(fast)["error"]["code"] == "invalid_parameter"
