"""Seams merged within the documented tolerance, open parts closed together, shells oriented by nesting."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from benchmarks.cases import box, icosahedron, triangles_stl_bytes
from benchmarks.exact import exact_solid
from inertia.body import MeshBody, Part
from inertia.errors import InvalidMeshError, NotWatertightError, ZeroVolumeError
from inertia.mass import mass_properties
from inertia.pipeline import analyze
from inertia.seams import SEAM_STEPS, join_open_parts, merge_seams
from inertia.solid import closed_surface, winding_numbers
from inertia.tolerances import DEFAULT_TOLERANCES


def unshared_box(gap: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A box whose +x face has its own copies of its four vertices, written ``gap`` away (a CAD seam)."""
    v, f = box(1.0, 2.0, 3.0)
    on_face = np.flatnonzero(v[:, 0] == 1.0)
    copies = v[on_face].copy()
    copies[:, 1] -= gap * (copies[:, 1] == 0)  # 0.0 in one patch, -gap in the other
    remap = np.arange(len(v))
    remap[on_face] = len(v) + np.arange(len(on_face))
    face_normal_x = np.all(v[f][:, :, 0] == 1.0, axis=1)
    f2 = f.copy()
    f2[face_normal_x] = remap[f[face_normal_x]]
    v2 = np.vstack([v, copies])
    return v2, f2, v, f


def test_a_seam_of_a_few_ulps_is_merged_and_the_numbers_are_exact_for_the_merged_surface() -> None:
    v, f, _, _ = unshared_box(2.7e-16)
    body = MeshBody(v, f, name="part")
    props = mass_properties(body, density=1.0)
    merged_v, merged_f, _ = closed_surface(body)
    volume, _, tensor = exact_solid(merged_v, merged_f)
    assert props.mass == pytest.approx(float(volume), rel=1e-15)
    np.testing.assert_allclose(props.inertia.matrix, np.array(tensor, dtype=float), rtol=1e-14, atol=1e-15)
    assert any("seam vertices merged" in w and "largest gap 2.7e-16" in w for w in props.warnings)


def test_a_gap_above_the_tolerance_stays_open_and_names_the_part() -> None:
    diag = np.sqrt(1 + 4 + 9)
    v, f, _, _ = unshared_box(10 * DEFAULT_TOLERANCES.seam_rel * diag)
    with pytest.raises(NotWatertightError) as err:
        mass_properties(MeshBody(v, f, name="bracket"))
    assert "'bracket'" in err.value.message and err.value.details["part"] == "bracket"


@pytest.mark.parametrize("steps", [1, 4, 100])
def test_a_float32_files_seams_are_merged_within_a_few_of_its_steps(steps: int) -> None:
    # unitree_ros' waist_roll_link.STL and five more robot links: binary STL seams 3.7e-9 to 3e-8 apart, one or
    # two float32 steps of their coordinates and 1e4 times the float64 seam tolerance, were refused as open
    # (trimesh and MuJoCo read them closed). A float32 file's seams are merged within SEAM_STEPS of its steps
    step = 3.0 * 2.0**-24  # one float32 step at the largest coordinate (3)
    v, f, _, _ = unshared_box(steps * step)
    data = triangles_stl_bytes(v[f])
    if steps > SEAM_STEPS:
        with pytest.raises(NotWatertightError):
            analyze(data, filename="link.stl")
        return
    doc = analyze(data, filename="link.stl").as_dict()
    assert doc["mass"] == pytest.approx(6000.0, rel=steps * step)  # the box, one side moved by at most the gap
    assert any("steps of the file's float32 coordinates" in w for w in doc["warnings"])


def test_a_merge_that_would_collapse_a_triangle_is_not_made() -> None:
    # a sliver whose two close corners are both on open edges: merging them would collapse it
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1e-14, 0], [0, 1, 0]], dtype=float)
    f = np.array([[0, 1, 2], [0, 2, 3]])
    out = merge_seams(v, f)
    assert out.merged == 0 and out.refused == 1
    np.testing.assert_array_equal(out.faces, f)


def test_open_groups_that_close_together_are_one_body() -> None:
    v, f = box(1.0, 2.0, 3.0)
    half = len(f) // 2
    parts = [Part("lid", MeshBody(v, f[:half], name="lid")), Part("tray", MeshBody(v, f[half:], name="tray"))]
    joined, warnings = join_open_parts(parts)
    assert [p.name for p in joined] == ["lid+tray"] and "open each but close together" in warnings[0]


def test_grouped_obj_is_analysed_as_one_closed_body() -> None:
    v, f = box(1.0, 2.0, 3.0)
    lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in v]
    lines.append("g top")
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f[:5]]
    lines.append("g rest")
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f[5:]]
    doc = analyze("\n".join(lines).encode(), filename="split.obj").as_dict()
    assert doc["mass"] == pytest.approx(6000, rel=1e-14)
    assert any("close together" in w for w in doc["warnings"])


def test_an_open_group_beside_a_closed_one_is_refused_by_name() -> None:
    v, f = box(1.0, 1.0, 1.0)
    lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in v]
    lines += [f"v {float(x) + 5!r} {float(y)!r} {float(z)!r}" for x, y, z in v]
    lines.append("g whole")
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]
    lines.append("g broken")
    lines += [f"f {a + 9} {b + 9} {c + 9}" for a, b, c in f[:-1]]
    with pytest.raises(NotWatertightError) as err:
        analyze("\n".join(lines).encode(), filename="two.obj")
    assert "broken" in err.value.message


def sphere_shell(radius: float, centre: tuple[float, float, float] = (0, 0, 0)) -> tuple[np.ndarray, np.ndarray]:
    v, f = icosahedron(1.0)
    v = v / np.linalg.norm(v[0]) * radius + np.asarray(centre)
    return v, f


def test_winding_number_is_one_inside_and_zero_outside() -> None:
    v, f = box(2.0, 2.0, 2.0, origin=(-1.0, -1.0, -1.0))
    w = winding_numbers(v, f, np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.5, 0.9, -0.2]]))
    np.testing.assert_allclose(np.abs(w), [1.0, 0.0, 1.0], atol=1e-12)


def test_a_cavity_wound_outward_beside_a_part_wound_inward_is_set_right_by_nesting() -> None:
    # outer box inverted, inner box (the cavity) outward, a separate small box beside them inverted:
    # the bounding-box rule would get the separate box wrong when it lies within the outer box's range
    ov, of = box(4.0, 4.0, 4.0)
    iv, i_f = box(1.0, 1.0, 1.0, origin=(1.5, 1.5, 1.5))
    # an L-shaped neighbour's box lies within the outer box's bounding box in two axes only
    sv, sf = box(1.0, 1.0, 1.0, origin=(5.0, 1.5, 1.5))
    v = np.vstack([ov, iv, sv])
    f = np.vstack([of[:, [0, 2, 1]], i_f + 8, sf[:, [0, 2, 1]] + 16])
    props = mass_properties(MeshBody(v, f), density=1.0)
    assert props.mass == pytest.approx(64 - 1 + 1, rel=1e-14)


def test_a_shell_inside_another_without_a_bounding_box_hint_is_a_cavity() -> None:
    # an icosahedral cavity in a box; the cavity's bounding box is inside, and so is a point of it
    bv, bf = box(4.0, 4.0, 4.0, origin=(-2.0, -2.0, -2.0))
    sv, sf = sphere_shell(1.0)
    v = np.vstack([bv, sv])
    f = np.vstack([bf, sf + 8])  # both outward: consistent, the file says two solids; keep
    both = mass_properties(MeshBody(v, f), density=1.0)
    f_bad = np.vstack([bf[:, [0, 2, 1]], sf + 8])  # outer inverted, inner outward
    fixed = mass_properties(MeshBody(v, f_bad), density=1.0)
    sphere_volume = float(exact_solid(sv, sf)[0])
    assert fixed.mass == pytest.approx(64 - sphere_volume, rel=1e-14)
    assert both.mass == pytest.approx(64 + sphere_volume, rel=1e-14)
    assert any("winding corrected" in w for w in fixed.warnings)


@pytest.mark.parametrize("shift", [(0.3, 0.2, 0.1), (1.0, 0.5, 0.25), (0.0, 0.0, 0.0)])
def test_an_inward_shell_that_crosses_its_outer_shell_is_refused(shift: tuple[float, float, float]) -> None:
    # admesh's conveyor/merge.stl: a closed shell and an inverted copy of it moved a little; the inverted one's
    # largest face is inside the other, so by one test point it is a cavity, and the two volumes all but cancel
    # (the refinement then divided by a volume of rounding size). A moved copy crosses the shell it is "in";
    # an unmoved one lies on it (every test point on the other shell): undecided, and left as the file winds it
    v, f = box(4.0, 3.0, 2.0)
    copy = v + np.asarray(shift)
    both = MeshBody(np.vstack([v, copy]), np.vstack([f, f[:, [0, 2, 1]] + len(v)]))
    if shift == (0.0, 0.0, 0.0):
        with pytest.raises(ZeroVolumeError):
            mass_properties(both, density=1.0)
        return
    with pytest.raises(InvalidMeshError, match="shells cross each other"):
        mass_properties(both, density=1.0)


def test_an_outward_shell_that_crosses_a_body_with_cavities_is_summed_with_a_warning() -> None:
    # Universal Robots' UR5 collision wrist3.stl: a body with three sealed cavities wound inward, and an outward
    # pin that runs from inside the body to outside it. The cavities sent the file into nesting, where the pin
    # was refused as crossing; without them the same pin was summed with a warning. The file winds every shell
    # as its nesting says but the pin, which is outward: its signed volumes (as trimesh and MuJoCo read it) are
    # body - cavity + pin, with the pin's part inside the body counted twice, and a warning says so
    bv, bf = box(2.0, 2.0, 2.0)
    cv, cf = box(0.5, 0.5, 0.5, origin=(0.25, 0.25, 0.25))
    pv, pf = box(0.25, 0.25, 1.5, origin=(1.5, 1.5, 1.5))
    v = np.vstack([bv, cv, pv])
    f = np.vstack([bf, cf[:, [0, 2, 1]] + 8, pf + 16])
    props = mass_properties(MeshBody(v, f), density=1.0)
    parts = [(Fraction(8), (1, 1, 1)), (Fraction(-1, 8), (0.5, 0.5, 0.5)), (Fraction(3, 32), (1.625, 1.625, 2.25))]
    volume = sum(m for m, _ in parts)
    com = [sum(m * Fraction(c[k]) for m, c in parts) / volume for k in range(3)]
    assert props.mass == float(volume)
    assert props.center_of_mass == pytest.approx([float(c) for c in com], rel=1e-15)
    assert any("lie partly inside another" in w and "counts once for each" in w for w in props.warnings)
    # wound inward, the same pin is no reading at all: refused as before
    f_in = np.vstack([bf, cf[:, [0, 2, 1]] + 8, pf[:, [0, 2, 1]] + 16])
    with pytest.raises(InvalidMeshError, match="shells cross each other"):
        mass_properties(MeshBody(v, f_in), density=1.0)


def test_an_inward_shell_that_crosses_from_outside_is_refused_too() -> None:
    # its largest face's centre is outside the box (depth 0: by one point a body of its own), but a corner is in
    bv, bf = box(1.0, 1.0, 1.0)
    cv, cf = box(1.1, 0.6, 0.6, origin=(0.6, 0.2, 0.2))
    body = MeshBody(np.vstack([bv, cv]), np.vstack([bf, cf[:, [0, 2, 1]] + len(bv)]))
    with pytest.raises(InvalidMeshError, match="shells cross each other"):
        mass_properties(body, density=1.0)


def test_a_cavity_within_its_shell_is_still_a_cavity_when_its_vertices_are_tested() -> None:
    # every vertex of the cavity is inside the box: the crossing test leaves it a cavity
    bv, bf = box(4.0, 4.0, 4.0, origin=(-2.0, -2.0, -2.0))
    sv, sf = sphere_shell(1.9)
    props = mass_properties(MeshBody(np.vstack([bv, sv]), np.vstack([bf[:, [0, 2, 1]], sf + 8])), density=1.0)
    assert props.mass == pytest.approx(64 - float(exact_solid(sv, sf)[0]), rel=1e-14)


@pytest.mark.parametrize("centre", [(0.0, 0.0, 0.0), (1.2, 0.9, -1.1)])
def test_shells_all_wound_outward_are_each_a_solid_wherever_they_lie(centre: tuple[float, float, float]) -> None:
    # the file says two solids (both wound outward); whether the box's middle lies inside the sphere or not (the
    # local origin, which once decided between keeping the winding and re-winding the sphere as a cavity) must
    # not change that: trimesh, VTK's vtkMassProperties and the stored winding all give box + sphere
    bv, bf = box(4.0, 4.0, 4.0, origin=(-2.0, -2.0, -2.0))
    sv, sf = sphere_shell(0.5, centre)
    props = mass_properties(MeshBody(np.vstack([bv, sv]), np.vstack([bf, sf + 8])), density=1.0)
    assert props.mass == pytest.approx(64 + float(exact_solid(sv, sf)[0]), rel=1e-14)
    assert not any("winding corrected" in w for w in props.warnings)
    # the volume they share counts twice, and the result says so
    assert any("all wind outward and overlap" in w for w in props.warnings)


@pytest.mark.parametrize(("origin", "overlap"), [((0.5, 0.25, 0.25), True), ((1.5, 0.0, 0.0), False), ((1.0, 0.0, 0.0), False)])
def test_outward_shells_that_overlap_are_weighed_each_and_said_so(origin: tuple[float, float, float], overlap: bool) -> None:
    # two unit boxes wound outward: overlapping (a corner region of 0.5 x 0.75 x 0.75 shared), apart, or touching
    # along a face. Each is weighed as a solid, as trimesh and MuJoCo sum the signed volumes (2, whatever the
    # overlap); where they overlap the shared volume counted twice is named
    v, f = box(1.0, 1.0, 1.0)
    cv, cf = box(1.0, 1.0, 1.0, origin=origin)
    props = mass_properties(MeshBody(np.vstack([v, cv]), np.vstack([f, cf + len(v)])), density=1.0)
    assert props.mass == pytest.approx(2.0, rel=1e-14)
    assert any("all wind outward and overlap" in w for w in props.warnings) is overlap


@pytest.mark.parametrize(
    ("offset", "overlap"),
    [
        ((0.0, 0.0, 0.0), True),  # a plus sign: no vertex of either bar inside the other, their middles shared
        ((0.0, 0.0, 0.99), True),  # 1e-2 of the height shared
        ((0.0, 0.0, 0.9999), False),  # 1e-4 of it: as far as tessellated parts that touch cut into each other
        ((0.0, 0.0, 1.0), False),  # stacked: face on face
        ((0.0, 3.0, 0.0), False),  # apart
        ((2.5, 2.5, 0.0), False),  # touching along an edge (x = 2, y = 0.5)
        ((2.0, 2.0, 0.0), True),  # a corner region shared, no vertex clearly inside the other
    ],
)
def test_bars_laid_across_each_other_are_said_to_overlap(offset: tuple[float, float, float], overlap: bool) -> None:
    # two closed bars wound outward, 4 x 1 x 1 along x and 1 x 4 x 1 along y, centred together (plus offset):
    # trimesh and MuJoCo sum the two (8); crossing as a plus, they share a unit cube, which counts twice
    long_v, long_f = box(4.0, 1.0, 1.0, origin=(-2.0, -0.5, -0.5))
    wide_v, wide_f = box(1.0, 4.0, 1.0, origin=(-0.5 + offset[0], -2.0 + offset[1], -0.5 + offset[2]))
    props = mass_properties(MeshBody(np.vstack([long_v, wide_v]), np.vstack([long_f, wide_f + 8])), density=1.0)
    assert props.mass == pytest.approx(8.0, rel=1e-14)
    assert any("all wind outward and overlap" in w for w in props.warnings) is overlap


def test_zero_stored_volume_is_never_turned_into_a_body() -> None:
    # one box stored twice, the copy inverted and coincident: the stored polyhedron encloses nothing
    v, f = box(1.0, 2.0, 3.0)
    v2 = np.vstack([v, v])
    f2 = np.vstack([f, f[:, [0, 2, 1]] + 8])
    with pytest.raises(ZeroVolumeError):
        mass_properties(MeshBody(v2, f2, welded=True))


def test_a_separate_inverted_copy_is_turned_outward() -> None:
    v, f = box(1.0, 2.0, 3.0)
    v2 = np.vstack([v, v + np.array([5.0, 0.0, 0.0])])
    f2 = np.vstack([f, f[:, [0, 2, 1]] + 8])
    assert mass_properties(MeshBody(v2, f2), density=1.0).mass == pytest.approx(12.0, rel=1e-15)


def test_close_pairs_agree_with_brute_force() -> None:
    rng = np.random.default_rng(5)
    grid = rng.integers(0, 4, size=(300, 3)).astype(float)  # many equal projections on the axes
    pts = np.vstack([grid, grid[:40] + rng.normal(scale=1e-13, size=(40, 3))])
    from inertia.seams import close_pairs

    got = {tuple(p) for p in close_pairs(pts, 1e-12).tolist()}
    d = np.linalg.norm(pts[:, None] - pts[None], axis=2)
    i, j = np.nonzero(np.triu(d <= 1e-12, 1))
    assert got == set(zip(i.tolist(), j.tolist()))


def test_a_stacked_inverted_cube_touching_another_is_turned_outward() -> None:
    # the second cube's largest faces include the shared one: its test point must move off it
    a_v, a_f = box(1.0, 1.0, 1.0)
    b_v, b_f = box(1.0, 1.0, 1.0, origin=(0.0, 0.0, 1.0))
    v = np.vstack([a_v, b_v])
    f = np.vstack([a_f, b_f[:, [0, 2, 1]] + 8])
    props = mass_properties(MeshBody(v, f, welded=True), density=1.0)
    assert props.mass == pytest.approx(2.0, rel=1e-15)


def test_winding_numbers_agree_point_by_point() -> None:
    v, f = sphere_shell(1.0)
    pts = np.array([[0.0, 0.0, 0.0], [0.5, 0.1, 0.0], [2.0, 0.0, 0.0], [0.0, -3.0, 1.0]])
    together = winding_numbers(v, f, pts)
    alone = [winding_numbers(v, f, p[None, :])[0] for p in pts]
    np.testing.assert_allclose(together, alone, atol=1e-12)
    np.testing.assert_allclose(np.abs(together), [1, 1, 0, 0], atol=1e-12)


def test_a_body_stored_twice_is_weighed_once_and_said_so() -> None:
    # the same closed box twice, both copies outward (an exporter that wrote a body twice, an OBJ that lists its
    # triangles again under a second material): once welded, every triangle repeats another, corners and winding
    # alike; the body is weighed once, as a Gmsh element listed twice is, and the warning says so
    v, f = box(1.0, 2.0, 3.0)
    props = mass_properties(MeshBody(np.vstack([v, v]), np.vstack([f, f + len(v)])), density=1.0)
    assert props.mass == pytest.approx(6.0, rel=1e-14)
    assert any("12 of 24 triangles repeat another" in w for w in props.warnings)


def test_many_disjoint_shells_get_no_overlap_warning() -> None:
    # 3,000 separate unit boxes in a row (the overlap check sweeps their boxes rather than testing every pair)
    v, f = box(1.0, 1.0, 1.0)
    shift = np.repeat(np.arange(3000) * 2.0, len(v))[:, None] * np.array([1.0, 0.0, 0.0])
    vertices = np.tile(v, (3000, 1)) + shift
    faces = np.vstack([f + k * len(v) for k in range(3000)])
    props = mass_properties(MeshBody(vertices, faces), density=1.0)
    assert props.mass == pytest.approx(3000.0, rel=props.relative_error_estimate)
    assert not any("overlap" in w for w in props.warnings)


def test_a_double_sided_sheet_is_refused_as_such() -> None:
    # trimesh's chair_model.obj: every triangle stored twice, once in each winding; closed as a 2-chain, it
    # encloses nothing, and the refusal says why rather than "flat or degenerate"
    v, f = box(1.0, 2.0, 3.0)
    sheet = f[:6]  # three faces of the box: an open sheet, made closed by its reverse copy
    with pytest.raises(ZeroVolumeError) as info:
        mass_properties(MeshBody(v, np.vstack([sheet, sheet[:, [0, 2, 1]]])), density=1.0)
    assert "12 of its 12 triangles" in info.value.message
    assert "double-sided" in info.value.message


def test_a_sheet_stored_twice_in_the_same_winding_is_refused_as_double_sided() -> None:
    # assimp's regr_3429812.obj: a quad and its two triangles, the same winding; the repair of the winding turns
    # one copy over, and the refusal must not say the file stored them "once in each winding"
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    sheet = np.array([[3, 2, 1], [3, 1, 0]])
    with pytest.raises(ZeroVolumeError) as info:
        mass_properties(MeshBody(v, np.vstack([sheet, sheet])), density=1.0)
    assert "4 of its 4 triangles are stored twice" in info.value.message
    assert "each winding" not in info.value.message


def _t_junction_box(lift: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The 2 x 1 x 1 box whose top is two unit squares: their shared corners (1, 0, 1) and (1, 1, 1), lifted by
    ``lift``, lie in the middle of the long top edges of the two long sides (T-junctions)."""
    v = np.array(
        [
            [0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0],  # bottom
            [0, 0, 1], [2, 0, 1], [2, 1, 1], [0, 1, 1],  # top corners
            [1, 0, 1 + lift], [1, 1, 1 + lift],  # the middle of the top's long edges
        ],
        dtype=np.float64,
    )  # fmt: skip
    f = np.array(
        [
            [0, 2, 1], [0, 3, 2],  # bottom, down
            [4, 8, 9], [4, 9, 7], [8, 5, 6], [8, 6, 9],  # top, two squares, up
            [0, 1, 5], [0, 5, 4],  # front y = 0: one rectangle, its top edge 4 -> 5 ... passes 8
            [3, 7, 6], [3, 6, 2],  # back y = 1: its top edge 6 -> 7 passes 9
            [0, 4, 7], [0, 7, 3],  # left
            [1, 2, 6], [1, 6, 5],  # right
        ]
    )  # fmt: skip
    return v, f


def _obj(v: np.ndarray, f: np.ndarray) -> bytes:
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in v.tolist()] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f.tolist()]
    return "\n".join(lines).encode()


@pytest.mark.parametrize("lift", [0.0, 3e-6])
def test_a_surface_closed_as_drawn_but_open_at_t_junctions_is_closed_with_slivers(lift: float) -> None:
    # Geomview's polyhedra (truncated_cube.off, cuboctahedron.off, ...): a corner of one face in the middle of its
    # neighbour's side, written with six digits; they were refused as not watertight
    v, f = _t_junction_box(lift)
    doc = analyze(_obj(v, f), filename="t.obj").as_dict()
    # exact reference: the same faces and the two slivers that fill the cracks under the lifted corners, in
    # Fractions (for lift 0 they are flat, and this is the 2 x 1 x 1 box)
    volume, com, tensor = exact_solid(v, np.concatenate([f, [[4, 5, 8], [6, 7, 9]]]))
    assert doc["volume"] == pytest.approx(float(volume), rel=1e-15)
    if lift == 0.0:
        assert volume == 2
    assert doc["center_of_mass"] == pytest.approx([float(c) for c in com], rel=1e-15, abs=1e-15)
    got = np.asarray(doc["inertia_tensor"]) / doc["density"]
    want = np.array([[float(x) for x in row] for row in tensor])
    np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-14 * float(np.abs(want).max()))
    [note] = [w for w in doc["warnings"] if "T-junction" in w]
    assert note.startswith("2 T-junction(s) closed")
    assert ("exactly on it" in note) is (lift == 0.0)


@pytest.mark.parametrize("lift", [3e-4, 0.1])
def test_a_crack_wider_than_the_t_junction_tolerance_stays_open(lift: float) -> None:
    v, f = _t_junction_box(lift)
    with pytest.raises(NotWatertightError, match=r"not watertight \(6 open edges\)"):
        analyze(_obj(v, f), filename="t.obj")


def test_t_junctions_are_not_closed_when_another_open_edge_has_no_partner() -> None:
    v, f = _t_junction_box()
    with pytest.raises(NotWatertightError, match=r"not watertight \(9 open edges\)"):
        analyze(_obj(v, f[[k for k in range(len(f)) if k != 0]]), filename="t.obj")  # a bottom triangle gone


def test_a_fine_top_meeting_single_quad_sides_is_closed_at_every_t_junction() -> None:
    # the unit cube whose top is an n x n grid and whose sides and bottom are one quad each: 4 (n - 1) corners of
    # the grid lie inside the sides' top edges
    n = 20
    xs = np.linspace(0.0, 1.0, n + 1)
    gx, gy = np.meshgrid(xs, xs, indexing="ij")
    top = np.stack([gx.ravel(), gy.ravel(), np.ones(gx.size)], axis=1)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    grid = np.concatenate([np.stack([a, b, c], axis=1), np.stack([a, c, d], axis=1)])
    o = len(top)  # the bottom's corners (0,0,0), (1,0,0), (1,1,0), (0,1,0) follow the grid
    t00, tn0, tnn, t0n = idx[0, 0], idx[n, 0], idx[n, n], idx[0, n]
    rest = [[o, o + 2, o + 1], [o, o + 3, o + 2], [o, o + 1, tn0], [o, tn0, t00], [o + 1, o + 2, tnn], [o + 1, tnn, tn0]]
    rest += [[o + 2, o + 3, t0n], [o + 2, t0n, tnn], [o + 3, o, t00], [o + 3, t00, t0n]]
    v = np.concatenate([top, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]])
    doc = analyze(triangles_stl_bytes(v[np.concatenate([grid, rest])]), filename="grid.stl").as_dict()
    assert doc["volume"] == pytest.approx(1.0, rel=1e-15)
    assert doc["center_of_mass"] == pytest.approx([0.5, 0.5, 0.5], rel=1e-15)
    assert any(w.startswith(f"{4 * (n - 1)} T-junction(s) closed") for w in doc["warnings"])
