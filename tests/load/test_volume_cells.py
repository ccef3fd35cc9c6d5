"""Volume cells integrated as the elements they are (``inertia.cells``), against independent references."""

from __future__ import annotations

import itertools
from fractions import Fraction
from math import factorial
from typing import Any, cast

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from benchmarks.exact import exact_tetrahedra
from inertia.body import CellBlock, VolumeBody
from inertia.cells import CELL_NODES, cell_rule, shape_functions
from inertia.mass import assembly_properties, mass_properties

volref = pytest.importorskip("tests.load.volref")  # needs vtk (the 'vtk' extra, in 'test')

QUADRATIC = ("tetra10", "hexahedron20", "hexahedron27", "wedge15", "wedge18", "pyramid13")
ALL_TYPES = tuple(CELL_NODES)


def body_of(name: str, nodes: np.ndarray, density: np.ndarray | None = None) -> VolumeBody:
    return VolumeBody(nodes, np.empty((0, 4), np.int64), None, cells=(CellBlock(name, np.arange(len(nodes))[None, :], density),))


def curved(name: str, seed: int, amplitude: float = 0.08) -> np.ndarray:
    """A cell of type ``name``: VTK's reference nodes, stretched, sheared and moved (curving every edge)."""
    rng = np.random.default_rng(seed)
    base = volref.parametric_nodes(name)
    if name.startswith("pyramid"):  # VTK's apex node sits at (0, 0, 1); its geometric place is over the base
        base[4] = (0.5, 0.5, 1.0)
        if name == "pyramid13":
            base[9:13] = 0.5 * (base[[0, 1, 2, 3]] + base[4])
    a = np.array([[1.3, 0.2, 0.1], [0.1, 0.9, -0.2], [0.05, 0.1, 1.1]])
    return cast("np.ndarray", base @ a.T + amplitude * rng.uniform(-1, 1, base.shape) + np.array([0.3, -0.2, 0.5]))


def assert_matches_reference(props: Any, m0: float, m1: np.ndarray, m2: np.ndarray, rel: float) -> None:
    mass, com, tensor = volref.inertia_about_centre(m0, m1, m2, density=1000.0)
    scale = np.abs(tensor).max()
    size = np.sqrt(scale / mass)  # radius of gyration: the length scale of the centre's error
    actual = max(
        abs(props.mass - mass) / mass,
        np.abs(props.center_of_mass - com).max() / size,
        np.abs(props.inertia.matrix - tensor).max() / scale,
    )
    assert actual <= rel
    # the error estimate is honest: never below the error against the reference (whose own rounding,
    # ~1e-14 of the largest moment, is allowed for)
    moments_error = np.abs(np.sort(props.principal_moments) - np.linalg.eigvalsh(tensor)).max() / scale
    assert moments_error <= props.relative_error_estimate + 1e-14


# ---------------------------------------------------------------------------------------------
# the rules and the shape functions


def _exact_monomial(kind: str, a: int, b: int, c: int) -> Fraction:
    if kind == "cube":
        return Fraction(1, (a + 1) * (b + 1) * (c + 1))
    if kind == "tet":  # int r^a s^b t^c over the unit tetrahedron = a! b! c! / (a + b + c + 3)!
        return Fraction(factorial(a) * factorial(b) * factorial(c), factorial(a + b + c + 3))
    return Fraction(factorial(a) * factorial(b), factorial(a + b + 2)) / (c + 1)  # triangle x line


def _kind(name: str) -> str:
    return "tet" if name.startswith("tetra") else "wedge" if name.startswith("wedge") else "cube"


def _within_degree(name: str, e: tuple[int, int, int]) -> bool:
    degree = cell_rule(name).degree
    if _kind(name) in ("cube", "tet"):
        assert isinstance(degree, int)
        return (max(e) if _kind(name) == "cube" else sum(e)) <= degree
    assert isinstance(degree, tuple)
    return e[0] + e[1] <= degree[0] and e[2] <= degree[1]


@pytest.mark.parametrize("name", ALL_TYPES)
def test_rules_integrate_every_monomial_of_their_stated_degree_exactly(name: str) -> None:
    rule = cell_rule(name)
    worst = 0.0
    for i, j, k in itertools.product(range(11), repeat=3):
        e = (i, j, k)
        if _within_degree(name, e):
            value = float((rule.weights * np.prod(rule.points ** np.array(e), axis=1)).sum())
            exact = _exact_monomial(_kind(name), *e)
            worst = max(worst, abs(value - float(exact)) / float(exact))
    assert worst <= 32 * 2.2e-16  # the bound cells.py assumes for the rule's own rounding


@pytest.mark.parametrize("name", ["hexahedron", "hexahedron27", "tetra10", "wedge15"])
def test_stated_degree_is_not_exceeded_by_luck(name: str) -> None:
    """One degree more in some variable is not integrated exactly: the stated degree is the real one."""
    rule = cell_rule(name)
    degree = rule.degree
    e = (degree[0] + 2, 0, 0) if isinstance(degree, tuple) else (degree + 2, 0, 0)
    value = float((rule.weights * np.prod(rule.points ** np.array(e), axis=1)).sum())
    assert abs(value - float(_exact_monomial(_kind(name), *e))) > 1e-8


@pytest.mark.parametrize("name", ALL_TYPES)
def test_shape_functions_are_vtks(name: str) -> None:
    rng = np.random.default_rng(7)
    xi = rng.uniform(0.05, 0.45, (25, 3))
    ours, _ = shape_functions(name, xi)
    np.testing.assert_allclose(ours, volref.vtk_shape(name, xi), atol=1e-14)


# ---------------------------------------------------------------------------------------------
# closed forms


@pytest.mark.parametrize("name", QUADRATIC)
def test_quadratic_cell_with_straight_edges_equals_its_linear_cell(name: str) -> None:
    """Mid-edge (and face, centre) nodes where the linear cell's map puts them: the same body."""
    linear = {
        "tetra10": "tetra",
        "hexahedron20": "hexahedron",
        "hexahedron27": "hexahedron",
        "wedge15": "wedge",
        "wedge18": "wedge",
        "pyramid13": "pyramid",
    }[name]
    corners = curved(linear, seed=3, amplitude=0.15)
    xi = volref.parametric_nodes(name)
    if name == "pyramid13":  # VTK puts the apex at (0, 0, 1): any point of the cube's top face maps there
        xi[9:13] = [(0, 0, 0.5), (1, 0, 0.5), (1, 1, 0.5), (0, 1, 0.5)]
    nodes = volref.vtk_shape(linear, xi) @ corners
    quadratic = mass_properties(body_of(name, nodes))
    if linear == "tetra":
        straight = mass_properties(VolumeBody(corners, np.array([[0, 1, 2, 3]])))
    else:
        straight = mass_properties(body_of(linear, corners))
    assert quadratic.mass == pytest.approx(straight.mass, rel=1e-13)
    np.testing.assert_allclose(
        quadratic.inertia.matrix, straight.inertia.matrix, rtol=0, atol=1e-13 * np.abs(straight.inertia.matrix).max()
    )


def test_straight_tetra10_matches_the_exact_tetrahedron() -> None:
    corners = np.array([[0.0, 0.0, 0.0], [2.0, 0.25, 0.0], [0.5, 1.5, 0.125], [0.25, 0.5, 3.0]])
    mids = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]  # VTK's tetra10 edge order
    nodes = np.vstack([corners, [(corners[a] + corners[b]) / 2 for a, b in mids]])
    props = mass_properties(body_of("tetra10", nodes), density=1.0)
    vol, c, exact_tensor = exact_tetrahedra(corners, [[0, 1, 2, 3]])
    assert props.mass == pytest.approx(float(vol), rel=1e-14)
    np.testing.assert_allclose(props.center_of_mass, [float(v) for v in c], rtol=1e-14)
    np.testing.assert_allclose(props.inertia.matrix, np.array(exact_tensor, dtype=float), rtol=1e-13)


HEX = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)


@pytest.mark.parametrize(
    "nodes, tets",
    [
        ([0, 1, 2, 3, 4, 4, 4, 4], [[0, 1, 2, 4], [0, 2, 3, 4]]),  # top face to one apex: a pyramid
        ([0, 1, 2, 3, 4, 5, 5, 4], [[0, 3, 4, 1], [3, 4, 1, 2], [4, 1, 2, 5]]),  # top face to an edge: a wedge
        ([0, 1, 2, 2, 4, 4, 4, 4], [[0, 1, 2, 4]]),  # base to a triangle, top to a point: a tetrahedron
    ],
)
def test_collapsed_hexahedron_is_its_true_shape(nodes: list[int], tets: list[list[int]]) -> None:
    affine = np.array([[1.3, 0.2, 0.1], [0.1, 0.9, -0.2], [0.05, 0.1, 1.1]])
    points = HEX @ affine.T + (0.5, -1.0, 2.0)  # planar faces, so the true shape is the union of the tetrahedra
    props = mass_properties(
        VolumeBody(points, np.empty((0, 4), np.int64), cells=(CellBlock("hexahedron", np.array([nodes])),)), density=1.0
    )
    split = mass_properties(VolumeBody(points, np.array(tets)), density=1.0)
    assert props.mass == pytest.approx(split.mass, rel=1e-14)
    np.testing.assert_allclose(props.inertia.matrix, split.inertia.matrix, atol=1e-14 * np.abs(split.inertia.matrix).max())


def test_collapsed_hexahedron_is_not_twice_the_volume() -> None:
    """A wedge written as a hexahedron with repeated nodes, as meshers do: volume of the wedge."""
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [0, 1, 1]], dtype=float)
    nodes = np.array([[0, 1, 2, 2, 3, 4, 5, 5]])
    props = mass_properties(VolumeBody(points, np.empty((0, 4), np.int64), cells=(CellBlock("hexahedron", nodes),)), density=1.0)
    assert props.mass == pytest.approx(0.5, rel=1e-15)


# ---------------------------------------------------------------------------------------------
# curved and warped cells against VTK's shape functions and other rules


@pytest.mark.parametrize("name", ALL_TYPES)
@pytest.mark.parametrize("seed", [1, 2])
def test_curved_cell_matches_vtk_map_integrated_independently(name: str, seed: int) -> None:
    nodes = curved(name, seed)
    props = mass_properties(body_of(name, nodes))
    m0, m1, m2 = volref.reference_integrals(name, nodes)
    assert_matches_reference(props, m0, m1, m2, rel=1e-12)


def test_warped_hexahedron_is_the_trilinear_cell_not_a_tetrahedral_split() -> None:
    """One face warped: the two ways to split it along a diagonal give different answers; ours is neither."""
    points = HEX.copy()
    points[6] += (0.0, 0.0, 0.6)  # top face no longer planar
    props = mass_properties(body_of("hexahedron", points), density=1.0)
    m0, m1, m2 = volref.reference_integrals("hexahedron", points)
    assert_matches_reference(mass_properties(body_of("hexahedron", points)), m0, m1, m2, rel=1e-13)
    around_06 = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]
    around_17 = [[1, 2, 3, 7], [1, 3, 0, 7], [1, 0, 4, 7], [1, 4, 5, 7], [1, 5, 6, 7], [1, 6, 2, 7]]
    split_a = mass_properties(VolumeBody(points, np.array(around_06)), density=1.0).mass
    split_b = mass_properties(VolumeBody(points, np.array(around_17)), density=1.0).mass
    assert abs(split_a - split_b) > 1e-3  # the old answer depended on the numbering
    assert props.mass == pytest.approx(m0, rel=1e-14)
    # closed form: the top face is the bilinear height 1 + 0.6 r s over the unit square, mean 1 + 0.6/4
    assert props.mass == pytest.approx(1 + 0.6 / 4, rel=1e-14)


# ---------------------------------------------------------------------------------------------
# numbering, orientation, placement, densities


def _cube_symmetries() -> list[np.ndarray]:
    mats = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1, -1), repeat=3):
            m = np.zeros((3, 3))
            for i, (p, s) in enumerate(zip(perm, signs)):
                m[i, p] = s
            mats.append(m)
    return mats


CUBE_SYMMETRIES = _cube_symmetries()


def _renumbering(name: str, symmetry: np.ndarray) -> np.ndarray:
    """Node permutation p with node p[a] of the moved cell where node a was: the same body, renumbered."""
    xi = volref.parametric_nodes(name)
    moved = (xi - 0.5) @ symmetry.T + 0.5
    return np.array([int(np.argmin(np.abs(xi - m).sum(axis=1))) for m in moved])


@settings(max_examples=25, deadline=None)
@given(st.sampled_from(["hexahedron", "hexahedron20", "hexahedron27"]), st.sampled_from(range(48)), st.integers(0, 2**32 - 1))
def test_renumbering_a_cell_changes_nothing(name: str, which: int, seed: int) -> None:
    nodes = curved(name, seed % 1000)
    perm = _renumbering(name, CUBE_SYMMETRIES[which])
    rng = np.random.default_rng(seed)
    shuffle = rng.permutation(len(nodes))  # and the points stored in another order
    base = mass_properties(body_of(name, nodes))
    stored = np.empty_like(nodes)
    stored[shuffle] = nodes  # node i of the cell now lives at index shuffle[i]
    renumbered = mass_properties(VolumeBody(stored, np.empty((0, 4), np.int64), cells=(CellBlock(name, shuffle[perm][None, :]),)))
    assert renumbered.mass == pytest.approx(base.mass, rel=1e-14)
    np.testing.assert_allclose(
        renumbered.inertia.matrix,
        base.inertia.matrix,
        rtol=0,
        atol=4 * base.relative_error_estimate * np.abs(base.inertia.matrix).max(),
    )


def test_mirrored_cells_count_positive() -> None:
    nodes = curved("hexahedron27", 4)
    mirrored = _renumbering("hexahedron27", np.diag([-1.0, 1.0, 1.0]))
    a = mass_properties(body_of("hexahedron27", nodes))
    b = mass_properties(body_of("hexahedron27", nodes[mirrored]))
    assert b.mass == pytest.approx(a.mass, rel=1e-14) and a.mass > 0


def test_voxel_order_is_vtks() -> None:
    from inertia.cells import VOXEL_TO_HEXAHEDRON

    voxel = volref.parametric_nodes("voxel") * np.array([1.0, 2.0, 3.0])
    hexa = voxel[VOXEL_TO_HEXAHEDRON]
    np.testing.assert_array_equal(hexa, volref.parametric_nodes("hexahedron") * np.array([1.0, 2.0, 3.0]))


def test_cells_far_from_the_origin_keep_their_precision() -> None:
    nodes = np.round(curved("hexahedron20", 9) * 2**30) / 2**30  # so that the shift below is exact
    near = mass_properties(body_of("hexahedron20", nodes))
    far = mass_properties(body_of("hexahedron20", nodes + 2.0**20))
    assert far.mass == pytest.approx(near.mass, rel=1e-14)
    np.testing.assert_allclose(far.principal_moments, near.principal_moments, rtol=1e-13)
    np.testing.assert_allclose(far.center_of_mass - 2.0**20, near.center_of_mass, atol=1e-15 * 2**20)


def test_cell_densities_weight_each_cell() -> None:
    two = np.vstack([HEX, HEX[4:] + np.array([0.0, 0.0, 1.0])])
    cells = np.array([[0, 1, 2, 3, 4, 5, 6, 7], [4, 5, 6, 7, 8, 9, 10, 11]])
    props = mass_properties(
        VolumeBody(two, np.empty((0, 4), np.int64), cells=(CellBlock("hexahedron", cells, np.array([1000.0, 3000.0])),))
    )
    assert props.mass == pytest.approx(4000.0, rel=1e-14)
    assert props.center_of_mass[2] == pytest.approx((0.5 * 1000 + 1.5 * 3000) / 4000, rel=1e-14)


def test_assembly_of_cell_blocks_equals_one_body() -> None:
    a = body_of("hexahedron27", curved("hexahedron27", 1))
    b = body_of("wedge15", curved("wedge15", 2) + np.array([3.0, 0.0, 0.0]))
    whole = assembly_properties([(a, 1000.0), (b, 2000.0)])
    pa, pb = mass_properties(a, density=1000.0), mass_properties(b, density=2000.0)
    assert whole.mass == pytest.approx(pa.mass + pb.mass, rel=1e-14)
    com = (pa.mass * pa.center_of_mass + pb.mass * pb.center_of_mass) / (pa.mass + pb.mass)
    np.testing.assert_allclose(whole.center_of_mass, com, rtol=1e-13)


# tetra10 nodes as VTK numbers them: corners, then the edges 01, 12, 02, 03, 13, 23
_TET10_EDGES = ((0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3))


def _tetra10_signed_volume(nodes: list[tuple[Fraction, ...]]) -> Fraction:
    """The integral of det J over the reference tetrahedron, exactly: det J of a quadratic tetrahedron is a cubic,
    and Stroud's T3:3-1 rule (Approximate Calculation of Multiple Integrals, 1971: the centroid with weight -4/5
    and the four points (1/2, 1/6, 1/6, 1/6) with 9/20 each) integrates cubics exactly, with rational points."""

    def det_j(r: Fraction, s: Fraction, t: Fraction) -> Fraction:
        lam = [1 - r - s - t, r, s, t]
        d_lam = [(-1, -1, -1), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
        grad = [tuple((4 * lam[i] - 1) * d_lam[i][k] for k in range(3)) for i in range(4)]
        grad += [tuple(4 * (d_lam[a][k] * lam[b] + lam[a] * d_lam[b][k]) for k in range(3)) for a, b in _TET10_EDGES]
        j = [[sum((nodes[n][i] * grad[n][k] for n in range(10)), Fraction(0)) for k in range(3)] for i in range(3)]
        return (
            j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
            - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
            + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0])
        )

    quarter, half, sixth = Fraction(1, 4), Fraction(1, 2), Fraction(1, 6)
    points: list[tuple[tuple[Fraction, ...], Fraction]] = [((quarter, quarter, quarter), Fraction(-4, 5))]
    points += [(p[1:], Fraction(9, 20)) for p in set(itertools.permutations((half, sixth, sixth, sixth)))]
    return sum((w * det_j(*p) for p, w in points), Fraction(0)) / 6


@pytest.mark.parametrize("mirrored", [False, True])
def test_folded_curved_cell_counts_its_folded_region_negatively(mirrored: bool) -> None:
    """A tetra10 whose corners span a positive tetrahedron but whose det J changes sign (one edge node pulled far
    out) integrates to -7/24: the warning says such a cell is integrated with its signed Jacobian, as Gmsh's
    signed Jacobians count it, whatever the order of its nodes; it used to be negated whole (+7/24)."""
    corners = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
    straight = [tuple(Fraction(c) for c in p) for p in corners]
    straight += [tuple((straight[a][k] + straight[b][k]) / 2 for k in range(3)) for a, b in _TET10_EDGES]
    folded = list(straight)
    folded[7] = (Fraction(3, 4), Fraction(2), Fraction(1, 2))  # edge 03's node
    big = [tuple(6 * c - 1 for c in p) for p in straight]  # a straight cell holding the folded one: a physical body
    assert _tetra10_signed_volume(folded) == Fraction(-7, 24)
    exact = _tetra10_signed_volume(folded) + _tetra10_signed_volume(big)
    order = [0, 2, 1, 3, 6, 5, 4, 7, 9, 8] if mirrored else list(range(10))  # corners 1 and 2 swapped, with their edges
    nodes = np.array([[float(c) for c in folded[i]] for i in order] + [[float(c) for c in p] for p in big])
    cells = np.array([list(range(10)), list(range(10, 20))])
    body = VolumeBody(nodes, np.empty((0, 4), np.int64), None, cells=(CellBlock("tetra10", cells, None),))
    assert mass_properties(body, density=1.0).volume == pytest.approx(float(exact), rel=1e-13)
