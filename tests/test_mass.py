"""Mass properties against closed forms and exact rational integration."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, cast

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from benchmarks import exact
from benchmarks.cases import box, box_inertia, l_bracket, prism
from benchmarks.exact import exact_solid
from inertia.body import MeshBody, PointBody, VolumeBody
from inertia.errors import InvalidParameterError, NotWatertightError, ZeroVolumeError
from inertia.mass import mass_properties
from tests.support.bodies import meshed

GENERIC = Rotation.from_euler("zyx", [0.3, 0.7, 1.1]).as_matrix()


def exact_moments(vertices: np.ndarray, faces: np.ndarray) -> list[float]:
    """Principal moments (unit density) of exactly this polyhedron: rational integration, 50-digit eigenvalues."""
    return [float(x) for x in exact.exact_moments(vertices, faces)]


def rel(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    return cast("np.ndarray", np.abs(np.asarray(a) - np.asarray(b)) / np.abs(np.asarray(b)))


def moments(props: Any) -> np.ndarray:
    return np.sort(props.principal_moments)


def test_box_moments_match_closed_form() -> None:
    a, b, c = 1.0, 2.0, 3.0
    props = mass_properties(MeshBody(*box(a, b, c)), density=7850.0)
    m = 7850.0 * a * b * c
    assert props.mass == pytest.approx(m, rel=1e-15)
    assert props.volume == pytest.approx(6.0, rel=1e-15)
    np.testing.assert_allclose(props.center_of_mass, [0.5, 1.0, 1.5], rtol=1e-15)
    expected = np.diag([m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12])
    np.testing.assert_allclose(props.inertia.matrix, expected, rtol=1e-14, atol=1e-14 * m)


@pytest.mark.parametrize("offset_sizes", [1e3, 1e6, 1e8])
def test_translated_box_keeps_every_moment(offset_sizes: float) -> None:
    v, f = box(1.0, 2.0, 3.0)
    shifted = v + offset_sizes * 3.0 * np.array([1.0, -0.6180339887, 0.4142135623])
    props = mass_properties(MeshBody(shifted, f), density=1.0)
    exact = exact_moments(shifted, f)
    assert np.all(rel(moments(props), exact) <= 1e-12)
    assert props.relative_error_estimate <= 1e-12
    assert np.all(rel(moments(props), exact) <= max(props.relative_error_estimate, 1e-15))


@pytest.mark.parametrize("thin", [1e-3, 1e-6])
def test_needle_under_generic_rotation_keeps_smallest_moment(thin: float) -> None:
    v, f = box(1.0, thin, thin, origin=(-0.5, -thin / 2, -thin / 2))
    rotated = v @ GENERIC.T + np.array([0.25, -1.5, 2.0])
    props = mass_properties(MeshBody(rotated, f), density=1.0)
    exact = exact_moments(rotated, f)
    errors = rel(moments(props), exact)
    assert errors[0] <= 1e-9
    assert np.all(errors <= props.relative_error_estimate)
    assert props.relative_error_estimate <= 1e-9


def test_plate_under_generic_rotation_keeps_every_moment() -> None:
    v, f = box(1.0, 1.0, 1e-6, origin=(-0.5, -0.5, -5e-7))
    rotated = v @ GENERIC.T
    props = mass_properties(MeshBody(rotated, f), density=1.0)
    errors = rel(moments(props), exact_moments(rotated, f))
    assert np.all(errors <= 1e-9)
    assert np.all(errors <= props.relative_error_estimate)


@pytest.mark.parametrize("scale", [1e-6, 1e6])
def test_scale_gives_same_relative_results(scale: float) -> None:
    v, f = l_bracket(2.0)
    base = mass_properties(MeshBody(v, f), density=1.0)
    scaled = mass_properties(MeshBody(v * scale, f), density=1.0)
    np.testing.assert_allclose(moments(scaled), moments(base) * scale**5, rtol=1e-14)
    np.testing.assert_allclose(scaled.mass, base.mass * scale**3, rtol=1e-14)


def test_l_bracket_matches_exact_integration() -> None:
    v, f = l_bracket(2.0)
    props = mass_properties(MeshBody(v, f), density=1.0)
    vol, com, _ = exact_solid(v, f)
    assert props.volume == float(vol)
    np.testing.assert_allclose(props.center_of_mass, [float(c) for c in com], rtol=1e-15)
    np.testing.assert_allclose(moments(props), exact_moments(v, f), rtol=1e-14)


def test_hexagonal_prism_matches_polygon_formula() -> None:
    n, radius, height = 6, 1.0, 2.0
    props = mass_properties(MeshBody(*prism(n, radius, height)), density=1.0)
    theta = 2 * np.pi / n
    area = n * radius**2 * np.sin(theta) / 2
    polar = n * radius**4 * np.sin(theta) * (2 + np.cos(theta)) / 12  # sum of centre triangles
    izz = height * polar
    ixx = height * (polar / 2 + area * height**2 / 12)
    np.testing.assert_allclose(moments(props), sorted([izz, ixx, ixx]), rtol=1e-13)


def test_units_scale_results_to_si() -> None:
    v, f = box(10.0, 20.0, 30.0)
    in_mm = mass_properties(MeshBody(v, f, length_scale=1e-3), density=1000.0)
    m = 1000.0 * 0.01 * 0.02 * 0.03
    assert in_mm.mass == pytest.approx(m, rel=1e-14)
    np.testing.assert_allclose(
        moments(in_mm), sorted([m * (4e-4 + 9e-4) / 12, m * (1e-4 + 9e-4) / 12, m * (1e-4 + 4e-4) / 12]), rtol=1e-13
    )


def test_total_mass_sets_density() -> None:
    props = mass_properties(MeshBody(*box(1.0, 2.0, 3.0)), mass=12.0)
    assert props.mass == pytest.approx(12.0, rel=1e-15)
    assert props.density == pytest.approx(2.0, rel=1e-15)


def test_inverted_winding_is_corrected_with_same_numbers() -> None:
    v, f = box(1.0, 2.0, 3.0)
    good = mass_properties(MeshBody(v, f))
    bad = mass_properties(MeshBody(v, f[:, [0, 2, 1]]))
    np.testing.assert_array_equal(bad.inertia.matrix, good.inertia.matrix)
    assert bad.mass == good.mass
    assert any("inverted" in w for w in bad.warnings)
    assert not good.warnings


def test_inconsistent_winding_is_repaired_with_a_warning() -> None:
    v, f = l_bracket(2.0)
    broken = f.copy()
    broken[[1, 5, 9]] = broken[[1, 5, 9]][:, [0, 2, 1]]
    good = mass_properties(MeshBody(v, f))
    repaired = mass_properties(MeshBody(v, broken))
    np.testing.assert_allclose(repaired.inertia.matrix, good.inertia.matrix, rtol=1e-14, atol=1e-12)
    assert any("inconsistent winding repaired (3 of" in w for w in repaired.warnings)


@pytest.mark.parametrize("reversed_face", [0, 7])
def test_repaired_winding_counts_the_faces_turned_from_the_files(reversed_face: int) -> None:
    # one facet of a box reversed: with it first, the consistent winding kept its way and flipped the other
    # eleven, then the whole was turned outward ("11 of 12 flipped" and "inverted"): one face was turned in all
    v, f = box(1.0, 2.0, 3.0)
    broken = f.copy()
    broken[reversed_face] = broken[reversed_face][[0, 2, 1]]
    repaired = mass_properties(MeshBody(v, broken))
    assert repaired.mass == pytest.approx(6000.0, rel=1e-15)
    assert [w for w in repaired.warnings if "winding" in w] == ["inconsistent winding repaired (1 of 12 faces flipped)"]


def test_open_mesh_is_refused_with_open_edge_count() -> None:
    v, f = box(1.0, 2.0, 3.0)
    with pytest.raises(NotWatertightError) as err:
        mass_properties(MeshBody(v, f[:-2]))
    assert err.value.details["open_edges"] == 4
    assert "model=shell" in err.value.message


def test_flat_closed_mesh_has_zero_volume() -> None:
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
    f = np.array([[0, 1, 2], [0, 2, 1]])
    with pytest.raises(ZeroVolumeError):
        mass_properties(MeshBody(v, f))


def test_non_finite_vertices_are_invalid() -> None:
    v, f = box(1.0, 1.0, 1.0)
    v[3, 1] = np.nan
    with pytest.raises(InvalidParameterError):
        MeshBody(v, f)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf")])
def test_non_positive_or_non_finite_masses_are_invalid(bad: float) -> None:
    with pytest.raises(InvalidParameterError):
        PointBody(np.array([1.0, bad]), np.zeros((2, 3)))


@pytest.mark.parametrize("bad", [0.0, -5.0, float("nan")])
def test_bad_density_is_invalid(bad: float) -> None:
    with pytest.raises(InvalidParameterError):
        mass_properties(MeshBody(*box(1, 1, 1)), density=bad)


def test_shell_box_matches_lamina_sum() -> None:
    a, b, c, t, rho = 1.0, 2.0, 3.0, 1e-3, 2700.0
    props = mass_properties(MeshBody(*box(a, b, c)), model="shell", thickness=t, density=rho)
    # six rectangular laminae (sides p x q, normal n, centre offset d): I_nn = m(p²+q²)/12, in-plane m p²/12
    total = np.zeros(3)
    mass = 0.0
    for normal, (p_ax, q_ax), half in ((0, (1, 2), a / 2), (1, (0, 2), b / 2), (2, (0, 1), c / 2)):
        sides = {0: a, 1: b, 2: c}
        p, q = sides[p_ax], sides[q_ax]
        m = rho * t * p * q
        diag = np.zeros(3)
        diag[normal] = m * (p * p + q * q) / 12
        diag[p_ax] = m * q * q / 12 + m * half**2
        diag[q_ax] = m * p * p / 12 + m * half**2
        total += 2 * diag
        mass += 2 * m
    assert props.mass == pytest.approx(mass, rel=1e-14)
    np.testing.assert_allclose(np.diag(props.inertia.matrix), total, rtol=1e-13)


def test_reference_tensor_follows_parallel_axis_theorem() -> None:
    a, b, c = 1.0, 2.0, 3.0
    props = mass_properties(MeshBody(*box(a, b, c)), density=1.0)
    ref = props.about(np.zeros(3))
    m = 6.0
    # about the corner: I_xx = m (b² + c²)/3, I_xy = -m a b / 4 (box integrals)
    expected = np.array(
        [
            [m * (b * b + c * c) / 3, -m * a * b / 4, -m * a * c / 4],
            [-m * a * b / 4, m * (a * a + c * c) / 3, -m * b * c / 4],
            [-m * a * c / 4, -m * b * c / 4, m * (a * a + b * b) / 3],
        ]
    )
    np.testing.assert_allclose(ref.matrix, expected, rtol=1e-14)
    assert ref.about == "reference"


def test_two_material_volume_mesh_matches_composite_box() -> None:
    from inertia.load import load_body
    from tests.support.paths import SAMPLES

    loaded = load_body(SAMPLES / "two_density.vtu")
    props = mass_properties(meshed(loaded.body))
    m1, m2 = 1000.0, 8000.0
    cx = (m1 * 0.5 + m2 * 1.5) / (m1 + m2)
    iyy = (m1 + m2) * 2 / 12 + m1 * (0.5 - cx) ** 2 + m2 * (1.5 - cx) ** 2
    assert props.mass == pytest.approx(m1 + m2, rel=1e-14)
    np.testing.assert_allclose(props.center_of_mass, [cx, 0.5, 0.5], rtol=1e-14)
    np.testing.assert_allclose(np.diag(props.inertia.matrix), [(m1 + m2) / 6, iyy, iyy], rtol=1e-13)
    assert props.density is None


def test_volume_mesh_density_ratio_of_a_million() -> None:
    _v, _f = box(2.0, 1.0, 1.0)
    pts = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1, 2)], dtype=float)
    split = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]
    left = [0, 1, 4, 3, 6, 7, 10, 9]
    right = [1, 2, 5, 4, 7, 8, 11, 10]
    tets = [[h[k] for k in t] for h in (left, right) for t in split]
    rho = np.array([1.0] * 6 + [1e6] * 6)
    props = mass_properties(VolumeBody(pts, np.array(tets), rho))
    m1, m2 = 1.0, 1e6
    cx = (m1 * 0.5 + m2 * 1.5) / (m1 + m2)
    iyy = (m1 + m2) / 6 + m1 * (0.5 - cx) ** 2 + m2 * (1.5 - cx) ** 2
    np.testing.assert_allclose(np.sort(props.principal_moments), sorted([(m1 + m2) / 6, iyy, iyy]), rtol=1e-12)


def test_diatomic_molecule_is_a_linear_rotator() -> None:
    from inertia.classification import RotorClass, classify
    from inertia.principal import principal_frame

    m1, m2, bond = 1.0, 16.0, 1.2e-10
    props = mass_properties(PointBody(np.array([m1, m2]), np.array([[0, 0, 0], [bond, 0, 0]], float)))
    expected = m1 * m2 * bond * bond / (m1 + m2)  # seed notes eq. (31)
    mom = moments(props)
    assert mom[0] == pytest.approx(0.0, abs=1e-15 * expected)
    np.testing.assert_allclose(mom[1:], [expected, expected], rtol=1e-14)
    assert classify(principal_frame(props)).rotor is RotorClass.LINEAR


def test_isosceles_triatomic_molecule() -> None:
    m1, m2, a, h = 1.0, 16.0, 2.0, 0.7
    x = np.array([[-a / 2, 0, 0], [a / 2, 0, 0], [0, h, 0]])
    props = mass_properties(PointBody(np.array([m1, m1, m2]), x))
    mu = 2 * m1 + m2
    i1, i2 = 2 * m1 * m2 * h * h / mu, m1 * a * a / 2  # seed notes, example 2b
    np.testing.assert_allclose(moments(props), sorted([i1, i2, i1 + i2]), rtol=1e-14)


def test_tetratomic_pyramid_molecule() -> None:
    m1, m2, a, h = 1.0, 3.0, 1.5, 0.9
    r = a / np.sqrt(3)  # circumradius of the equilateral base
    base = [[r * np.cos(t), r * np.sin(t), 0.0] for t in (0, 2 * np.pi / 3, 4 * np.pi / 3)]
    x = np.array([*base, [0.0, 0.0, h]])
    props = mass_properties(PointBody(np.array([m1, m1, m1, m2]), x))
    mu = 3 * m1 + m2
    i12 = 3 * m1 * m2 * h * h / mu + m1 * a * a / 2  # seed notes, example 2c
    i3 = m1 * a * a
    np.testing.assert_allclose(np.sort(moments(props)), sorted([i12, i12, i3]), rtol=1e-13)


def test_tetratomic_with_equal_masses_and_regular_shape_is_spherical() -> None:
    m, a = 2.0, 1.0
    h = np.sqrt(2 / 3) * a
    r = a / np.sqrt(3)
    x = np.array([[r * np.cos(t), r * np.sin(t), 0.0] for t in (0, 2 * np.pi / 3, 4 * np.pi / 3)] + [[0, 0, h]])
    props = mass_properties(PointBody(np.full(4, m), x))
    np.testing.assert_allclose(moments(props), [m * a * a] * 3, rtol=1e-13)


def test_results_are_bit_identical_across_processes(tmp_path: Path) -> None:
    import subprocess
    import sys

    code = (
        "from benchmarks.cases import l_bracket; import numpy as np;"
        "from scipy.spatial.transform import Rotation as R;"
        "from inertia.body import MeshBody; from inertia.mass import mass_properties;"
        "v, f = l_bracket(2.0); v = v @ R.from_euler('xyz', [.1, .2, .3]).as_matrix().T + 1e5;"
        "p = mass_properties(MeshBody(v, f)); print(p.inertia.matrix.tobytes().hex(), p.center_of_mass.tobytes().hex())"
    )
    from tests.support.paths import ROOT

    outs = {
        subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True).stdout for _ in range(2)
    }
    assert len(outs) == 1


def test_single_point_mass_has_zero_inertia() -> None:
    props = mass_properties(PointBody(np.array([2.0]), np.array([[1.0, 2.0, 3.0]])))
    assert props.mass == 2.0
    np.testing.assert_array_equal(props.center_of_mass, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(props.inertia.matrix, np.zeros((3, 3)))


def test_overflowing_coordinates_are_invalid_not_infinite() -> None:
    with pytest.raises(InvalidParameterError):
        mass_properties(PointBody(np.array([1.0, 1.0]), np.array([[1e254, 0, 0], [0, 1e254, 0]])))


@given(mass=st.floats(min_value=1e-9, max_value=1e9, allow_nan=False, allow_infinity=False))
@settings(max_examples=60, deadline=None)
def test_a_requested_mass_comes_back_as_sent(mass: float) -> None:
    # density = mass / volume, then density x volume, rounded the requested mass by an ulp (24 -> 23.999999999999996)
    bodies: list[MeshBody | PointBody] = [
        MeshBody(*l_bracket(1000.0), length_scale=1e-3),
        MeshBody(*prism(6, 1.0, 3.0)),
        PointBody(np.array([1.0, 2.0, 3.0]), np.eye(3)),
    ]
    for body in bodies:
        assert mass_properties(body, mass=mass).mass == mass


def test_the_parts_masses_add_up_to_the_whole() -> None:
    # the whole was integrated as one body and rounded on its own: two boxes of 1000 and 2000 kg made 2999.9999999999995
    from inertia.pipeline import analyze

    quads = [(1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)]
    lines = []
    for k, (a, b, c) in enumerate([(0.1, 0.7, 1.3), (0.3, 1.1, 0.9), (2.0, 0.2, 0.7)]):
        lines.append(f"o part{k}")
        lines += [f"v {x * a + 3 * k!r} {y * b!r} {z * c!r}" for x in (0, 1) for y in (0, 1) for z in (0, 1)]
        lines += ["f " + " ".join(str(8 * k + i) for i in quad) for quad in quads]
    doc = analyze("\n".join(lines).encode(), filename="three.obj").as_dict()
    assert len(doc["parts"]) == 3
    assert doc["mass"] == math.fsum(p["mass"] for p in doc["parts"])


@pytest.mark.parametrize("corners", [3, 4])
def test_corner_gather_in_steps_is_the_plain_gather(corners: int) -> None:
    """``gather_corners`` splits a block into steps; across and at their edges it must give ``points[cells]``."""
    from inertia.integrals import GATHER_STEP, gather_corners, point_records

    rng = np.random.default_rng(5)
    points = rng.normal(size=(1000, 3))
    for count in (1, GATHER_STEP - 1, GATHER_STEP, 2 * GATHER_STEP + 7):
        cells = rng.integers(0, len(points), size=(count, corners))
        got = gather_corners(point_records(points), cells)
        plain = points[cells]  # (count, corners, 3)
        for k in range(corners):
            for j in range(3):
                assert np.array_equal(got[k][j], plain[:, k, j])


@pytest.mark.parametrize("turn", [0, 1, 2])
def test_triangles_listed_twice_with_the_same_winding_are_weighed_once(turn: int) -> None:
    """An OBJ that lists every triangle again under a second material encloses the body twice over (winding number
    2 inside); the body is the one surface: each repeat is dropped, with a warning (it was weighed twice)."""
    v, f = box(2.0, 3.0, 4.0)
    again = np.roll(f, turn, axis=1)  # the same corners and winding, starting at another corner
    props = mass_properties(MeshBody(v, np.vstack([f, again[:5]])), density=1.0)  # five of them repeated
    assert props.volume == pytest.approx(24.0, rel=1e-14)
    expected = np.sort(np.diag(box_inertia(24.0, 2.0, 3.0, 4.0)))  # closed form, density 1
    assert np.sort(props.principal_moments).tolist() == pytest.approx(expected.tolist(), rel=1e-13)
    assert any("5 of 17 triangles repeat another" in w for w in props.warnings)
