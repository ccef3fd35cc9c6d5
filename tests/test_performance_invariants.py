"""Correctness of the fast paths: float32 STL weld, packed sorts, union-find, SoA kernel.

No timings here; ``benchmarks/mass.py`` measures speed.  Each test pins a
property the optimisations could break: exact welding (-0.0 equals 0.0,
distinct points never merge, also when every hash collides), identical
topology on every sort path, scipy-equal components, and integration
results that do not depend on the block size beyond the error estimate.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import inertia.integrals as integrals
import inertia.mass as mass
import inertia.topology as topology
from benchmarks.cases import torus, triangles_stl_bytes
from benchmarks.exact import exact_moments, exact_solid, relative_error
from inertia.body import MeshBody
from inertia.load.stl import read_stl
from inertia.tolerances import EPS


def _torus(nu: int, nv: int) -> tuple[np.ndarray, np.ndarray]:
    """The 3/1 torus of ``benchmarks.cases`` with float32 vertices (as a binary STL stores them)."""
    v, f = torus(nu, nv, 3.0, 1.0)
    return v.astype(np.float32).astype(np.float64), f


TETRA = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
TETRA_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def test_stl_weld_merges_negative_zero_with_zero() -> None:
    tri = TETRA[TETRA_FACES].astype(np.float32)
    tri[0, 0] = [-0.0, -0.0, 0.0]  # the origin, written once with negative zeros
    tri[2, 0] = [0.0, -0.0, -0.0]
    vertices, faces, _ = read_stl(triangles_stl_bytes(tri))
    assert vertices.shape == (4, 3)
    np.testing.assert_array_equal(vertices[faces], TETRA[TETRA_FACES])
    assert not np.any(np.signbit(vertices))


def test_stl_weld_keeps_points_one_ulp_apart_and_numbers_by_first_appearance() -> None:
    tri = TETRA[TETRA_FACES].astype(np.float32)
    tri[3, 2, 2] = np.nextafter(np.float32(1.0), np.float32(2.0))  # a fifth, distinct point
    vertices, faces, _ = read_stl(triangles_stl_bytes(tri))
    assert len(vertices) == 5
    np.testing.assert_array_equal(vertices[faces], tri.astype(np.float64))
    first = [int(np.flatnonzero(faces.ravel() == k)[0]) for k in range(len(vertices))]
    assert first == sorted(first)


def test_ascii_stl_comes_back_welded_like_binary() -> None:
    tri = TETRA[TETRA_FACES]
    tri[1, 0] = [-0.0, 0.0, -0.0]  # the origin again, with negative zeros
    text = (
        "solid t\n"
        + "".join(
            " facet normal 0 0 0\n  outer loop\n"
            + "".join(f"   vertex {x!r} {y!r} {z!r}\n" for x, y, z in t.tolist())
            + "  endloop\n endfacet\n"
            for t in tri
        )
        + "endsolid t\n"
    )
    vertices, faces, _ = read_stl(text.encode())
    binary_vertices, binary_faces, _ = read_stl(triangles_stl_bytes(tri.astype(np.float32)))
    assert vertices.shape == (4, 3)
    np.testing.assert_array_equal(vertices, binary_vertices)
    np.testing.assert_array_equal(faces, binary_faces)
    assert not np.any(np.signbit(vertices))


@pytest.mark.parametrize(
    "degraded_hash", [lambda h: h & np.uint64(0), lambda h: h & np.uint64(3)], ids=["every-row-collides", "two-bit-hash"]
)
def test_row_ids_exact_when_hashes_collide(monkeypatch: pytest.MonkeyPatch, degraded_hash: Any) -> None:
    rng = np.random.default_rng(7)
    rows = rng.integers(0, 5, size=(3000, 3)).astype(np.uint32)  # ~125 distinct rows, many repeats
    cols = [rows[:, 0], rows[:, 1], rows[:, 2]]
    honest = topology.row_ids(cols)
    real_hash = topology._row_hash
    monkeypatch.setattr(topology, "_row_hash", lambda c: degraded_hash(real_hash(c)))
    ids, heads = topology.row_ids(cols)
    _, first, inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
    expected_heads = np.sort(first)
    renumber = np.argsort(np.argsort(first))  # groups numbered by first occurrence
    np.testing.assert_array_equal(heads, expected_heads)
    np.testing.assert_array_equal(ids, renumber[inverse.ravel()])
    np.testing.assert_array_equal(ids, honest[0])
    np.testing.assert_array_equal(rows[heads][ids], rows)


def test_weld_of_welded_mesh_returns_the_same_arrays() -> None:
    v, f = _torus(12, 8)
    welded_v, welded_f = topology.weld(v, f)
    assert welded_v is v and welded_f is f


def test_weld_float64_merges_bit_identical_rows_only() -> None:
    v, f = _torus(12, 8)
    corners = v[f].reshape(-1, 3).copy()
    corners[0] = -0.0 * corners[0] if not corners[0].any() else corners[0]
    corners[5, 0] = np.nextafter(corners[5, 0], np.inf)
    wv, wf = topology.weld(corners, np.arange(len(corners)).reshape(-1, 3))
    np.testing.assert_array_equal(wv[wf].reshape(-1, 3), corners)
    assert len(wv) == len(v) + 1


@pytest.mark.parametrize("key_bits", [30, 35, 45, 60, 64])
def test_edge_sort_paths_agree(key_bits: int) -> None:
    """Packed sort, bucketed packed sort (few and many buckets) and the argsort fallback order edges alike."""
    v, f = _torus(40, 25)
    key, _ = topology._edge_keys(f, len(v))
    reference = np.argsort(key, kind="stable")
    order, starts = topology._edge_order(key.copy(), key_bits + 20)
    np.testing.assert_array_equal(order, reference)
    ks = key[reference]
    np.testing.assert_array_equal(starts, np.flatnonzero(np.r_[True, ks[1:] != ks[:-1]]))


def test_surface_topology_counts_open_and_flipped_edges() -> None:
    v, f = _torus(10, 6)
    closed = topology.surface_topology(f, len(v))
    assert (closed.open_edges, closed.unbalanced_edges, closed.nonmanifold_edges) == (0, 0, 0)
    assert len(closed.edge_faces) == 3 * len(f) // 2 and not closed.edge_same_direction.any()
    flipped = f.copy()
    flipped[5] = flipped[5, [0, 2, 1]]  # face 0 keeps its winding, so only face 5 flips back
    topo = topology.surface_topology(flipped, len(v))
    assert (topo.open_edges, topo.unbalanced_edges, int(topo.edge_same_direction.sum())) == (0, 3, 3)
    repaired, count = topology.orient_consistently(flipped, topo)
    assert count == 1 and topology.surface_topology(repaired, len(v)).closed
    opened = topology.surface_topology(f[1:], len(v))
    assert opened.open_edges == 3


def test_components_match_scipy_labels() -> None:
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    rng = np.random.default_rng(3)
    n = 2000
    a, b = rng.integers(0, n, 1500), rng.integers(0, n, 1500)
    count, label = topology._components(n, a, b)
    graph = coo_matrix((np.ones(len(a), dtype=np.int8), (a, b)), shape=(n, n))
    ref_count, ref_label = connected_components(graph, directed=False)
    assert count == ref_count
    np.testing.assert_array_equal(label, ref_label)


@pytest.mark.parametrize("seed", range(4))
def test_components_of_edges_written_smaller_end_first_match_scipy(seed: int) -> None:
    """``ordered=True`` (every a < b, as surface_topology writes face pairs) skips sorting the first round's ends."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    rng = np.random.default_rng(seed)
    n = 3000
    a, b = rng.integers(0, n, 2500), rng.integers(0, n, 2500)
    keep = a != b
    lo, hi = np.minimum(a[keep], b[keep]).astype(np.int32), np.maximum(a[keep], b[keep]).astype(np.int32)
    count, label = topology._components(n, lo, hi, ordered=True)
    graph = coo_matrix((np.ones(len(lo), dtype=np.int8), (lo, hi)), shape=(n, n))
    ref_count, ref_label = connected_components(graph, directed=False)
    assert count == ref_count
    np.testing.assert_array_equal(label, ref_label)
    np.testing.assert_array_equal(topology._components(n, lo, hi)[1], label)  # the general first round agrees


def _sums(points: np.ndarray, faces: np.ndarray) -> integrals.Sums:
    return integrals.simplex_sums(points - integrals.local_origin(points), faces, "apex", None)


def test_integration_independent_of_block_size_within_estimate(monkeypatch: pytest.MonkeyPatch) -> None:
    v, f = _torus(60, 30)
    body = MeshBody(v, f)
    default = mass.mass_properties(body, density=1.0)
    assert np.array_equal(default.principal_moments, mass.mass_properties(body, density=1.0).principal_moments)
    for chunk in (1, 7, 1 << 10):
        monkeypatch.setattr(integrals, "CHUNK", chunk)
        other = mass.mass_properties(body, density=1.0)
        rel = np.abs(other.principal_moments - default.principal_moments) / default.principal_moments
        assert rel.max() <= default.relative_error_estimate + other.relative_error_estimate


def test_edge_form_determinants_match_exact_volumes() -> None:
    v, f = _torus(30, 20)
    x = v - integrals.local_origin(v)
    fast = _sums(v, f)
    exact_volume = float(exact_solid(x, f)[0])
    assert abs(fast.m0 - exact_volume) <= 16 * EPS * fast.abs_m0
    assert fast.noise <= 64 * abs(fast.m0)  # edge-form determinants are well conditioned on a torus


def test_torus_moments_within_estimate_of_exact_polyhedron() -> None:
    v, f = _torus(16, 10)
    props = mass.mass_properties(MeshBody(v, f), density=1.0)
    exact = exact_moments(v, f)
    ours = np.sort(props.principal_moments)
    worst = max(relative_error(float(m), e) for m, e in zip(ours, exact))
    assert worst <= props.relative_error_estimate


def test_twice_areas_equal_numpy_cross_and_norm_to_the_bit() -> None:
    """The struct-of-arrays area kernel rounds exactly as ``np.cross`` + ``np.linalg.norm`` on rows."""
    from inertia.surface import twice_areas

    rng = np.random.default_rng(11)
    points = rng.normal(size=(500, 3)) * rng.choice([1e-8, 1.0, 3e5], size=(500, 1)) + 1e3
    faces = rng.integers(0, len(points), size=(4000, 3))
    origin = points[faces[0, 0]]
    tri = points[faces] - origin
    expected = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    np.testing.assert_array_equal(twice_areas(integrals.point_records(points), faces, origin), expected)
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    einsum = np.sqrt(np.einsum("ij,ij->i", cross, cross))  # sums x + z, then y
    np.testing.assert_array_equal(twice_areas(integrals.point_records(points), faces, origin, einsum_order=True), einsum)
    unshifted = points[faces]
    expected = np.linalg.norm(np.cross(unshifted[:, 1] - unshifted[:, 0], unshifted[:, 2] - unshifted[:, 0]), axis=1)
    np.testing.assert_array_equal(twice_areas(integrals.point_records(points), faces), expected)


def _bits(s: integrals.Sums) -> list[bytes]:
    return [
        np.asarray(getattr(s, f), dtype=np.float64).tobytes()
        for f in ("m0", "m1", "m2", "abs_m0", "abs_m2", "noise", "element_err", "measure")
    ]


@pytest.mark.parametrize("inverted", [False, True])
def test_first_pass_from_the_orientation_is_the_first_pass_or_none(inverted: bool) -> None:
    """The orientation's gather also yields refine's first pass: the same sums to the bit, kept only for faces
    the orientation left as they were."""
    from inertia.mass.geometry import Geometry, body_geometry
    from inertia.solid import oriented_surface

    v, f = _torus(300, 120)  # 72,000 faces: several blocks, on the threads
    if inverted:
        f = f[:, [0, 2, 1]]
    body = MeshBody(v, f, welded=True)
    surface = oriented_surface(body)
    if inverted:
        assert surface.first_pass is None and "inverted winding corrected" in surface.warnings
        return
    assert surface.first_pass is not None
    origin, first = surface.first_pass
    assert np.array_equal(origin, integrals.local_origin(surface.vertices))
    direct = integrals.simplex_sums(surface.vertices - origin, surface.faces, "apex", None)
    assert _bits(first) == _bits(direct)
    geometry, _ = body_geometry(body, "solid")
    given = geometry.sums(origin, None)  # the orientation's, once
    assert _bits(given) == _bits(direct)
    again = geometry.sums(origin, None)  # then formed afresh, alike
    assert again is not given and _bits(again) == _bits(direct)
    assert Geometry(surface.vertices, surface.faces, "apex", None, first_pass=surface.first_pass).sums(origin, None) is first
    other = Geometry(surface.vertices, surface.faces, "apex", None, first_pass=surface.first_pass)
    assert other.sums(origin + 1.0, None) is not first  # another origin: not the one the pass was formed about


def test_first_pass_that_overflows_is_left_to_the_pass_that_refuses_it() -> None:
    from inertia.errors import InvalidParameterError
    from inertia.mass import mass_properties
    from inertia.solid import oriented_surface

    v, f = _torus(12, 8)
    body = MeshBody(v * 1e200, f, welded=True)
    assert oriented_surface(body).first_pass is None
    with pytest.raises(InvalidParameterError, match="overflow"):
        mass_properties(body)
