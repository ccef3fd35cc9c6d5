"""POST /v1/analyze/mesh: mass, centre of mass, inertia tensor, principal frame and classification of meshes,
and the options that shape them (units, density, mass, shell, tolerance, reference, sections)."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from benchmarks.cases import stl_bytes
from tests.contract.helpers import (
    BOX_FACES,
    RHO,
    SAMPLES,
    UNIT_SCALE,
    analyze,
    assert_error,
    assert_no_nulls,
    box_corners,
    box_inertia,
    check_classification,
    check_invariants,
    check_principal,
    check_symmetric_rates,
    check_trajectory,
    exact_mass_properties,
    exact_moments,
    exact_of,
    obj_bytes,
    parallel_axis,
    post_mesh,
    precession_ok,
    ray_kappa,
    rotation,
    strip_elapsed,
    thin_box_shell_inertia,
    two_box_scene,
    two_cube_obj,
)

SAMPLE_TABLE = [
    ("box.stl", 6000.0, (0.5, 1, 1.5), box_inertia(6000, 1, 2, 3).diagonal()[::-1], "asymmetric_top", None),
    ("l_bracket.stl", 12000.0, (1.5, 1, 1), (9000, 24000, 25000), "asymmetric_top", None),
    ("tetrahedron.stl", 1000 / 6, (0.25, 0.25, 0.25), (125 / 12, 125 / 12, 50 / 3), "symmetric_top", "oblate"),
    ("hex_prism.stl", 5196.15232944, (0, 0, 1), (2165.06343174, 2814.58247292, 2814.58251178), "symmetric_top", "prolate"),
    # float32 vertices: 2.2e-8 away from the ideal icosahedron, so the published exact values
    ("icosahedron.stl", 2181.69503867, (0, 0, 0), (571.175184819,) * 3, "spherical_top", None),
    ("needle.obj", 1e-3, (0, 0, 0), (1e-3 * 2e-6 / 12, 1e-3 * (1 + 1e-6) / 12, 1e-3 * (1 + 1e-6) / 12), "symmetric_top", "prolate"),
    ("plate.obj", 1.0, (0, 0, 0), ((1 + 1e-6) / 12, (1 + 1e-6) / 12, 2 / 12), "symmetric_top", "oblate"),
    ("inverted_box.stl", 6000.0, (0.5, 1, 1.5), (2500, 5000, 6500), "asymmetric_top", None),
    ("two_density.vtu", 9000.0, (1.38888888889, 0.5, 0.5), (1500, 2388.88888889, 2388.88888889), "symmetric_top", "prolate"),
]


@pytest.mark.parametrize("filename,mass,com,moments,kind,shape", SAMPLE_TABLE, ids=[row[0] for row in SAMPLE_TABLE])
def test_sample_mesh_matches_published_values(
    client: TestClient, filename: str, mass: float, com: Any, moments: Any, kind: str, shape: str | None
) -> None:
    res = analyze(client, filename)
    assert res["mass"] == pytest.approx(mass, rel=1e-10, abs=0)
    size = max(1.0, float(np.max(np.abs(com))))
    np.testing.assert_allclose(res["center_of_mass"], com, rtol=0, atol=1e-10 * size)
    np.testing.assert_allclose(res["principal"]["moments"], moments, rtol=1e-10)
    check_principal(res)
    check_classification(res, kind, shape)
    assert "parts" not in res or filename.endswith(".vtu")
    assert res["source"]["filename"] == filename
    assert res["source"]["format"] == filename.rsplit(".", 1)[1]
    assert res["source"]["units"] == "m"
    assert isinstance(res["warnings"], list) if "warnings" in res else True
    d = res["diagnostics"]
    assert d["elapsed_s"] >= 0 and d["relative_error_estimate"] >= 0


def test_source_describes_the_uploaded_mesh(client: TestClient) -> None:
    res = analyze(client, "box.stl", units="mm")
    src = res["source"]
    assert src["filename"] == "box.stl" and src["format"] == "stl" and src["kind"] == "mesh"
    assert src["units"] == "mm"
    assert src["vertices"] == 8 and src["triangles"] == 12 and src["watertight"] is True


def test_box_tensor_in_input_frame_and_reference_by_parallel_axis_theorem(client: TestClient) -> None:
    res = analyze(client, "box.stl", reference="0,0,0")
    I_com = box_inertia(6000, 1, 2, 3)
    np.testing.assert_allclose(res["inertia_tensor"], I_com, rtol=0, atol=1e-12 * 6500)
    ref = res["reference_inertia"]
    np.testing.assert_allclose(ref["point"], [0, 0, 0], atol=0)
    np.testing.assert_allclose(
        ref["tensor"],
        parallel_axis(I_com, 6000, [0.5, 1, 1.5]),
        rtol=0,
        atol=1e-12 * 26000,
    )
    assert res["volume"] == pytest.approx(6.0, rel=1e-15, abs=0)
    assert res["density"] == RHO


def test_inverted_winding_is_corrected_with_a_warning(client: TestClient) -> None:
    good = analyze(client, "box.stl")
    bad = analyze(client, "inverted_box.stl")
    assert bad["mass"] == pytest.approx(good["mass"], rel=1e-15, abs=0)
    np.testing.assert_allclose(bad["inertia_tensor"], good["inertia_tensor"], rtol=0, atol=1e-12 * 6500)
    np.testing.assert_allclose(bad["principal"]["moments"], good["principal"]["moments"], rtol=1e-14)
    assert bad["warnings"] == ["inverted winding corrected"], "API.md's words, as its example shows them"


def rotated_box(a: float, b: float, c: float, R: Any, offset: Any) -> Any:
    v = (box_corners(a, b, c) - np.array([a, b, c]) / 2) @ R.T + np.asarray(offset, float)
    return v, BOX_FACES


def test_rotated_box_tensor_axes_and_quaternion_are_in_the_input_frame(client: TestClient) -> None:
    R = rotation([1, 2, 3], 0.7)
    v, f = rotated_box(1.0, 2.0, 3.0, R, [0.3, -0.2, 0.1])
    data = obj_bytes([(None, v, f)])
    res = analyze(client, "rotated.obj", data)
    _mass, _com, inertia, _ = exact_mass_properties(v[f])
    want = np.array([[float(x) for x in r] for r in inertia])
    np.testing.assert_allclose(res["inertia_tensor"], want, rtol=0, atol=1e-12 * 6500)
    np.testing.assert_allclose(want, R @ box_inertia(6000, 1, 2, 3) @ R.T, rtol=0, atol=1e-9)
    np.testing.assert_allclose(res["center_of_mass"], [0.3, -0.2, 0.1], atol=1e-14)
    check_principal(res)
    A = np.asarray(res["principal"]["axes"])
    # principal axes: the box's own axes, mapped by R (moments 2500: z, 5000: y, 6500: x)
    for k, body_axis in enumerate([[0, 0, 1], [0, 1, 0], [1, 0, 0]]):
        assert abs(abs(A[k] @ (R @ body_axis)) - 1) < 1e-12
    check_classification(res, "asymmetric_top")


def test_far_from_origin_rotated_box_keeps_every_moment_within_the_estimate(client: TestClient) -> None:
    """Accuracy: estimate <= 1e-12 for bodies up to 1e8 of their own sizes from the origin."""
    R = rotation([0.3, -1, 0.4], 1.1)
    v, f = rotated_box(1.0, 2.0, 3.0, R, [1e8, 5e7, -7e7])
    data = obj_bytes([(None, v, f)])
    res = analyze(client, "far.obj", data)
    _mass, com, inertia, _ = exact_mass_properties(v[f])
    est = res["diagnostics"]["relative_error_estimate"]
    assert est <= 1e-12
    for got, want in zip(res["principal"]["moments"], exact_moments(inertia)):
        assert abs(got - want) <= max(est, 2.3e-16) * want, (got, want, est)
    np.testing.assert_allclose(res["center_of_mass"], [float(x) for x in com], rtol=1e-15)


def test_far_from_origin_binary_stl_uses_its_float32_coordinates(client: TestClient) -> None:
    R = rotation([1, 1, 0], 0.4)
    v, f = rotated_box(1.0, 2.0, 3.0, R, [1e4, -2e4, 3e3])
    data = stl_bytes(v, f)
    res = analyze(client, "far32.stl", data)
    mass, _com, inertia, _ = exact_of("far32.stl", data)
    est = res["diagnostics"]["relative_error_estimate"]
    assert est <= 1e-12
    assert res["mass"] == pytest.approx(float(mass), rel=1e-13, abs=0)
    for got, want in zip(res["principal"]["moments"], exact_moments(inertia)):
        assert abs(got - want) <= max(est, 2.3e-16) * want, (got, want, est)


@pytest.mark.parametrize("dims", [(1.0, 1e-6, 1e-6), (1.0, 1.0, 1e-6)], ids=["needle", "plate"])
def test_needle_and_plate_of_aspect_1e6_at_an_angle_keep_the_smallest_moment(
    client: TestClient, dims: tuple[float, float, float]
) -> None:
    """Accuracy: estimate <= 1e-9 for the smallest moment of needles and plates of aspect
    ratio up to 1e6, at any orientation."""
    R = rotation([0.2, 0.9, -0.4], 0.83)
    v, f = rotated_box(*dims, R, [0.25, 0.5, -0.75])
    data = obj_bytes([(None, v, f)])
    res = analyze(client, "thin.obj", data)
    _, _, inertia, _ = exact_mass_properties(v[f])
    want = exact_moments(inertia)
    est = res["diagnostics"]["relative_error_estimate"]
    assert est <= 1e-9
    for got, w in zip(res["principal"]["moments"], want):
        assert abs(got - w) <= max(est, 2.3e-16) * w, (got, w, est)


def test_same_input_gives_bit_identical_numbers(client: TestClient) -> None:
    data = (SAMPLES / "l_bracket.stl").read_bytes()
    params = dict(omega="0.3,1,-0.2", duration="3", samples="7", reference="1,2,3")
    a = strip_elapsed(analyze(client, "l_bracket.stl", data, **params))
    b = strip_elapsed(analyze(client, "l_bracket.stl", data, **params))
    assert json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


@pytest.mark.parametrize("unit", list(UNIT_SCALE))
def test_units_convert_file_lengths_to_si(client: TestClient, unit: str) -> None:
    s = UNIT_SCALE[unit]
    res = analyze(client, "box.stl", units=unit, reference="1,0,0")
    m = 6 * s**3 * RHO
    assert res["source"]["units"] == unit
    assert res["mass"] == pytest.approx(m, rel=1e-13, abs=0)
    assert res["volume"] == pytest.approx(6 * s**3, rel=1e-13, abs=0)
    assert res["density"] == pytest.approx(RHO, rel=1e-15, abs=0)
    np.testing.assert_allclose(res["center_of_mass"], np.array([0.5, 1, 1.5]) * s, rtol=1e-14)
    I_com = box_inertia(m, s, 2 * s, 3 * s)
    np.testing.assert_allclose(res["inertia_tensor"], I_com, rtol=0, atol=1e-12 * np.trace(I_com))
    np.testing.assert_allclose(res["principal"]["moments"], sorted(I_com.diagonal()), rtol=1e-12)
    # the reference point is given in file units and reported in metres
    np.testing.assert_allclose(res["reference_inertia"]["point"], [s, 0, 0], rtol=1e-15)
    want = parallel_axis(I_com, m, np.array([0.5 - 1, 1, 1.5]) * s)
    np.testing.assert_allclose(res["reference_inertia"]["tensor"], want, rtol=0, atol=1e-12 * np.trace(want))


def test_reference_at_the_centre_of_mass_in_millimetres_gives_the_central_tensor(client: TestClient) -> None:
    res = analyze(client, "box.stl", units="mm", reference="0.5,1,1.5")
    np.testing.assert_allclose(res["reference_inertia"]["point"], [5e-4, 1e-3, 1.5e-3], rtol=1e-15)
    I = np.asarray(res["inertia_tensor"])
    np.testing.assert_allclose(res["reference_inertia"]["tensor"], I, rtol=0, atol=1e-12 * np.trace(I))


def test_density_option_scales_mass_and_inertia(client: TestClient) -> None:
    res = analyze(client, "box.stl", density=7850)
    assert res["mass"] == pytest.approx(6 * 7850, rel=1e-14, abs=0)
    assert res["density"] == 7850
    np.testing.assert_allclose(res["principal"]["moments"], np.array([2500, 5000, 6500]) * 7.85, rtol=1e-13)


def test_mass_option_derives_the_density(client: TestClient) -> None:
    res = analyze(client, "box.stl", mass=12)
    assert res["mass"] == pytest.approx(12, rel=1e-14, abs=0)
    assert res["density"] == pytest.approx(2.0, rel=1e-14, abs=0)
    assert res["volume"] == pytest.approx(6.0, rel=1e-14, abs=0)
    np.testing.assert_allclose(res["principal"]["moments"], np.array([2500, 5000, 6500]) * 12 / 6000, rtol=1e-13)


def test_density_and_mass_are_exclusive(client: TestClient) -> None:
    r = post_mesh(client, "box.stl", (SAMPLES / "box.stl").read_bytes(), density=1000, mass=2)
    assert_error(r, 422, "invalid_parameter")


def test_shell_thickness_is_in_file_units(client: TestClient) -> None:
    res = analyze(client, "box.stl", model="shell", thickness=0.1, units="mm")
    M, _com, I = thin_box_shell_inertia(1e-3, 2e-3, 3e-3, RHO * 1e-4)
    assert res["mass"] == pytest.approx(M, rel=1e-3, abs=0)
    np.testing.assert_allclose(res["inertia_tensor"], I, rtol=0, atol=1e-3 * np.trace(I))


def test_shell_model_accepts_an_open_surface(client: TestClient) -> None:
    t = 1e-4
    res = analyze(client, "open_box.stl", model="shell", thickness=t)
    M, com, I = thin_box_shell_inertia(1, 2, 3, RHO * t, faces=("x0", "y0", "y1", "z0", "z1"))
    assert res["mass"] == pytest.approx(M, rel=1e-3, abs=0)
    np.testing.assert_allclose(res["center_of_mass"], com, atol=1e-3)
    np.testing.assert_allclose(res["inertia_tensor"], I, rtol=0, atol=1e-3 * np.trace(I))


def test_shell_model_needs_a_thickness(client: TestClient) -> None:
    r = post_mesh(client, "box.stl", (SAMPLES / "box.stl").read_bytes(), model="shell")
    assert_error(r, 422, "invalid_parameter")


def test_tolerance_decides_which_moments_are_equal(client: TestClient) -> None:
    # hex_prism.stl (float32): the two large moments differ by ~1.4e-8 relative
    loose = analyze(client, "hex_prism.stl")
    check_classification(loose, "symmetric_top", "prolate")
    kappa = loose["classification"]["asymmetry"]
    assert kappa == pytest.approx(ray_kappa(loose["principal"]["moments"]), rel=1e-12, abs=0)
    assert kappa != -1.0, "asymmetry is computed from the reported moments, not rounded to -1"
    assert kappa == pytest.approx(-1, abs=1e-6)
    strict = analyze(client, "hex_prism.stl", tolerance="1e-10")
    check_classification(strict, "asymmetric_top", tolerance=1e-10)


def test_planar_uses_the_tolerance(client: TestClient) -> None:
    # plate.obj 1 x 1 x 1e-3: (I1 + I2 - I3)/I3 = 1e-6 exactly
    assert analyze(client, "plate.obj", tolerance="1e-5")["classification"]["planar"] is True
    assert analyze(client, "plate.obj", tolerance="1e-7")["classification"]["planar"] is False
    assert analyze(client, "box.stl")["classification"]["planar"] is False


def test_spherical_top_has_no_asymmetry_or_shape(client: TestClient) -> None:
    res = analyze(client, "icosahedron.stl")
    check_classification(res, "spherical_top")
    assert res["principal"]["unique_axes"] is False


def test_parts_of_a_scene_with_densities_per_part(client: TestClient) -> None:
    res = analyze(client, "pair.obj", two_cube_obj(), densities=json.dumps({"left": 1000, "right": 3000}))
    parts = {p["name"]: p for p in res["parts"]}
    assert set(parts) == {"left", "right"}
    for name, m, c in (("left", 1000, [0.5, 0.5, 0.5]), ("right", 3000, [2.5, 0.5, 0.5])):
        p = parts[name]
        assert p["mass"] == pytest.approx(m, rel=1e-13, abs=0)
        np.testing.assert_allclose(p["center_of_mass"], c, rtol=1e-13)
        np.testing.assert_allclose(p["inertia_tensor"], np.eye(3) * m / 6, rtol=0, atol=1e-12 * m)
    assert res["mass"] == pytest.approx(4000, rel=1e-13, abs=0)
    com = np.array([2.0, 0.5, 0.5])
    np.testing.assert_allclose(res["center_of_mass"], com, rtol=1e-13)
    want = parallel_axis(np.eye(3) * 1000 / 6, 1000, np.array([0.5, 0.5, 0.5]) - com) + parallel_axis(
        np.eye(3) * 3000 / 6, 3000, np.array([2.5, 0.5, 0.5]) - com
    )
    np.testing.assert_allclose(res["inertia_tensor"], want, rtol=0, atol=1e-12 * np.trace(want))
    check_principal(res)


def test_parts_without_densities_use_the_density_option(client: TestClient) -> None:
    res = analyze(client, "pair.obj", two_cube_obj(), density=2000)
    assert {p["name"] for p in res["parts"]} == {"left", "right"}
    assert res["mass"] == pytest.approx(4000, rel=1e-13, abs=0)
    for p in res["parts"]:
        assert p["mass"] == pytest.approx(2000, rel=1e-13, abs=0)


def test_single_body_has_no_parts(client: TestClient) -> None:
    assert "parts" not in analyze(client, "box.stl")
    assert "parts" not in analyze(client, "needle.obj")


def test_only_requested_sections_are_present(client: TestClient) -> None:
    res = analyze(client, "box.stl")
    for key in ("precession", "reference_inertia", "parts"):
        assert key not in res
    res = analyze(client, "box.stl", omega="0,1,0.1")  # no samples: no trajectory
    assert "trajectory" not in res["precession"]
    # duration without samples: API.md does not say whether this is an error; either reading
    # (no trajectory, or invalid_parameter) is accepted
    r = post_mesh(client, "box.stl", (SAMPLES / "box.stl").read_bytes(), omega="0,1,0.1", duration=2)
    if r.status_code == 200:
        assert "trajectory" not in r.json()["precession"]
    else:
        assert_error(r, 422, "invalid_parameter")
    res = analyze(client, "box.stl", omega="0,1,0.1", duration=2, samples=5)
    assert len(res["precession"]["trajectory"]["t"]) == 5


def test_symmetric_top_in_a_rotated_frame(client: TestClient) -> None:
    R = rotation([2, 1, -1], 1.3)
    I = R @ np.diag([1.5, 1.5, 2.5]) @ R.T
    I = (I + I.T) / 2
    omega = [1.0, 0.2, -0.5]
    res = precession_ok(client, {"inertia_tensor": I.tolist(), "omega": omega, "duration": 3, "samples": 7})
    check_classification(res, "symmetric_top", "oblate")
    n = np.asarray(res["classification"]["symmetry_axis"], float)
    assert abs(abs(n @ (R @ [0, 0, 1])) - 1) < 1e-12
    pre = res["precession"]
    check_invariants(pre, I, omega)
    check_symmetric_rates(pre, 1.5, 2.5, n, omega)
    check_trajectory(pre, [1.5, 1.5, 2.5], res["principal"]["axes"], omega, 3.0, 7, I)


def test_needle_of_aspect_1e6_is_a_linear_rotator_within_the_default_tolerance(client: TestClient) -> None:
    """I1/I3 = 2e-12: 'smallest moment zero within tolerance, the other two equal: ... a thin rod'."""
    R = rotation([1, 2, 2], 0.6)
    v, f = rotated_box(1.0, 1e-6, 1e-6, R, [0, 0, 0])
    data = obj_bytes([(None, v, f)])
    res = analyze(client, "rod.obj", data)
    check_classification(res, "linear_rotator", planar=True)
    n = np.asarray(res["classification"]["symmetry_axis"])
    assert abs(abs(n @ (R @ [1, 0, 0])) - 1) < 1e-9
    strict = analyze(client, "rod.obj", data, tolerance="1e-14")
    check_classification(strict, "symmetric_top", "prolate", planar=False, tolerance=1e-14)
    spin = analyze(client, "rod.obj", data, omega=",".join(repr(float(x)) for x in R @ [0, 0, 1.0]))
    # labelled a rotator, and its regime with it (API.md: rotator for a linear rotator), it moves as the
    # thin prolate top its moments make (issue 12): spun perpendicular to its axis, Omega stays put
    assert spin["precession"]["regime"] == "rotator"
    assert spin["precession"]["nutation_angle"] == pytest.approx(np.pi / 2, rel=1e-12)


def test_random_convex_body_far_from_the_origin_within_the_estimate(client: TestClient) -> None:
    from scipy.spatial import ConvexHull

    rng = np.random.default_rng(7)
    local = rng.normal(size=(40, 3)) * [1.0, 0.6, 0.3]
    hull = ConvexHull(local)
    faces = hull.simplices.copy()
    centre = local[hull.vertices].mean(axis=0)
    for t in faces:  # outward winding
        a, b, c = local[t]
        if np.cross(b - a, c - a) @ (a - centre) < 0:
            t[1], t[2] = t[2], t[1]
    v = local @ rotation([3, 1, -2], 2.0).T + [3e7, -4e7, 5e7]
    data = obj_bytes([(None, v, faces)])
    res = analyze(client, "hull.obj", data)
    mass, _com, inertia, _ = exact_mass_properties(v[faces])
    est = res["diagnostics"]["relative_error_estimate"]
    assert est <= 1e-12
    assert res["mass"] == pytest.approx(float(mass), rel=1e-13, abs=0)
    for got, want in zip(res["principal"]["moments"], exact_moments(inertia)):
        assert abs(got - want) <= max(est, 2.3e-16) * want, (got, want, est)
    check_principal(res)


@pytest.mark.parametrize("omega", [[0.3, -0.4, -1.2], [-0.7, 0.1, 0.05], [0.0, 0.5, -2.0]])
def test_symmetric_top_signs_follow_the_reported_symmetry_axis(client: TestClient, omega: Any) -> None:
    moments = [2.0, 2.0, 3.0]
    res = precession_ok(client, {"principal_moments": moments, "omega": omega, "duration": 2, "samples": 5})
    n = res["classification"]["symmetry_axis"]
    check_symmetric_rates(res["precession"], 2.0, 3.0, n, omega)
    check_trajectory(res["precession"], moments, res["principal"]["axes"], omega, 2.0, 5, np.diag(moments))


def test_parts_carry_their_own_frames_consistently(client: TestClient) -> None:
    scene, _ = two_box_scene()
    res = analyze(client, "scene.glb", scene.export(file_type="glb"))
    for p in res["parts"]:
        assert_no_nulls(p)
        if "principal" in p:
            check_principal(p, np.asarray(p["inertia_tensor"], float))


def test_mass_option_scales_parts_with_their_own_densities(client: TestClient) -> None:
    res = analyze(client, "pair.obj", two_cube_obj(), densities=json.dumps({"left": 1000, "right": 3000}), mass=8)
    assert res["mass"] == pytest.approx(8, rel=1e-13, abs=0)
    parts = {p["name"]: p for p in res["parts"]}
    assert parts["left"]["mass"] == pytest.approx(2, rel=1e-13, abs=0)
    assert parts["right"]["mass"] == pytest.approx(6, rel=1e-13, abs=0)
    np.testing.assert_allclose(res["center_of_mass"], [2.0, 0.5, 0.5], rtol=1e-13)


def test_cavity_is_subtracted_not_mistaken_for_inverted_winding(client: TestClient) -> None:
    outer, inner = box_corners(4, 4, 4) - 2, box_corners(2, 2, 2) - 1
    v = np.vstack([outer, inner])
    f = np.vstack([BOX_FACES, BOX_FACES[:, ::-1] + 8])  # the cavity's faces point into the hole
    res = analyze(client, "hollow.stl", stl_bytes(v, f))
    assert res["mass"] == pytest.approx(RHO * (64 - 8), rel=1e-14, abs=0)
    assert res["volume"] == pytest.approx(56, rel=1e-14, abs=0)
    I = box_inertia(64000, 4, 4, 4) - box_inertia(8000, 2, 2, 2)
    np.testing.assert_allclose(res["inertia_tensor"], I, rtol=0, atol=1e-13 * np.trace(I))
    check_classification(res, "spherical_top")


def test_a_separate_inverted_shell_is_corrected_with_a_warning(client: TestClient) -> None:
    v = np.vstack([box_corners(1, 1, 1), box_corners(1, 1, 1) + np.array([3, 0, 0])])
    f = np.vstack([BOX_FACES, BOX_FACES[:, ::-1] + 8])
    res = analyze(client, "two.stl", stl_bytes(v, f))
    assert res["mass"] == pytest.approx(2000, rel=1e-14, abs=0)
    np.testing.assert_allclose(res["center_of_mass"], [2, 0.5, 0.5], rtol=1e-14)
    assert res["warnings"]


def test_inconsistent_winding_is_repaired_with_a_warning(client: TestClient) -> None:
    f = BOX_FACES.copy()
    f[[0, 5, 9]] = f[[0, 5, 9]][:, ::-1]
    res = analyze(client, "mixed.stl", stl_bytes(box_corners(1, 2, 3), f))
    assert res["mass"] == pytest.approx(6000, rel=1e-14, abs=0)
    np.testing.assert_allclose(res["inertia_tensor"], box_inertia(6000, 1, 2, 3), rtol=0, atol=1e-12 * 6500)
    assert res["warnings"]


def test_v11_sections_absent_unless_asked(client: TestClient) -> None:
    """A plain request carries none of export, frame, rotational_constants; a surface mesh carries surface_area."""
    res = client.post("/v1/analyze/mesh", files={"file": ("box.stl", (SAMPLES / "box.stl").read_bytes())})
    assert res.status_code == 200
    doc = res.json()
    assert not {"export", "frame", "rotational_constants"} & set(doc)
    assert doc["surface_area"] == pytest.approx(2 * (1 * 2 + 2 * 3 + 3 * 1), rel=1e-12, abs=0)  # the 1 x 2 x 3 m box
    m, moments = doc["mass"], doc["principal"]["moments"]
    assert doc["principal"]["radii_of_gyration"] == pytest.approx([math.sqrt(i / m) for i in moments], rel=1e-12, abs=0)
