"""Gmsh MSH files whose cells meshio hands on as another body: 18-node prisms, elements listed per group.

Expected values are closed forms: a right prism over the triangle (0,0), (1,0), (0,1) from z = 0 to 2 has
volume 1 and centroid (1/3, 1/3, 1); a tetrahedron on the unit corner has volume 1/6.  Node orders are
Gmsh's own (gmsh.info, "Node ordering"), typed here from that page.
"""

from __future__ import annotations

from collections.abc import Sequence

import pytest

from inertia.errors import EmptyGeometryError, UnreadableFileError, UnsupportedFormatError
from inertia.pipeline import AnalysisOptions, analyze
from tests.support.paths import ROOT

# the 18-node prism in Gmsh's order: corners, then edge midpoints 0-1, 0-2, 0-3, 1-2, 1-4, 2-5, 3-4, 3-5, 4-5,
# then the centres of the quadrilateral faces 0-1-4-3, 0-2-5-3, 1-2-5-4
_CORNERS = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 2), (1, 0, 2), (0, 1, 2)]
_EDGES = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 4), (2, 5), (3, 4), (3, 5), (4, 5)]
_FACES = [(0, 1, 4, 3), (0, 2, 5, 3), (1, 2, 5, 4)]


def _mean(indices: tuple[int, ...]) -> tuple[float, ...]:
    return tuple(sum(_CORNERS[i][k] for i in indices) / len(indices) for k in range(3))


def _msh22(nodes: Sequence[tuple[float, ...]], elements: list[tuple[int, list[int], list[int]]]) -> bytes:
    """An ASCII MSH 2.2 file: elements as (Gmsh type, physical tags, 1-based node numbers)."""
    lines = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$Nodes", str(len(nodes))]
    lines += [f"{i + 1} {x!r} {y!r} {z!r}" for i, (x, y, z) in enumerate(nodes)]
    lines += ["$EndNodes", "$Elements", str(len(elements))]
    for k, (etype, tags, numbers) in enumerate(elements):
        lines.append(" ".join(str(v) for v in [k + 1, etype, len(tags), *tags, *numbers]))
    lines.append("$EndElements")
    return ("\n".join(lines) + "\n").encode()


@pytest.mark.parametrize("lift", [0.0, 0.25])
def test_an_18_node_prism_is_read_in_gmshs_node_order(lift: float) -> None:
    # meshio passed Gmsh's order on as VTK's: 162 of 162 prisms of a meshed cylinder came back folded, the mass
    # 335 where 6283 is right. ``lift`` moves the centre of face 0-1-4-3 out of its plane (a curved face), which
    # a wrong order turns into another body altogether
    nodes = list(_CORNERS) + [_mean(e) for e in _EDGES] + [_mean(f) for f in _FACES]
    nodes[15] = (nodes[15][0], nodes[15][1] - lift, nodes[15][2])
    doc = analyze(_msh22(nodes, [(13, [1, 1], list(range(1, 19)))]), filename="prism.msh").as_dict()
    volume = doc["mass"] / doc["density"]
    if lift == 0.0:
        assert volume == pytest.approx(1.0, rel=1e-14)
        assert doc["center_of_mass"] == pytest.approx([1 / 3, 1 / 3, 1.0], rel=1e-14)
    else:
        # the face bulges outward (y < 0) by a biquadratic bump: volume 1 + lift * 2 * (4/9) (its integral
        # over the 1 x 2 face of the centre node's shape function, 16 u(1-u) v(1-v) -> 4/9 of the area)
        assert volume == pytest.approx(1.0 + lift * 2 * 4 / 9, rel=1e-13)
    assert not any("fold" in w for w in doc["warnings"])


def test_an_element_in_two_physical_groups_is_weighed_once() -> None:
    # MSH 2.2 writes it once per group: the 1 x 2 x 3 box of the report weighed 12000 for 6000
    corners = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
    data = _msh22(corners, [(4, [1, 1], [1, 2, 3, 4]), (4, [2, 1], [1, 2, 3, 4])])
    doc = analyze(data, filename="tet.msh").as_dict()
    assert doc["mass"] / doc["density"] == pytest.approx(1 / 6, rel=1e-14)
    assert any("more than once" in w for w in doc["warnings"])


def test_a_surface_apart_from_the_volume_is_named_and_boundary_faces_are_not() -> None:
    # a closed skin beside a meshed box was left out without a word; Gmsh's physical surfaces (faces of the
    # volume itself) are no such thing
    nodes = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (5.0, 0.0, 0.0), (6.0, 0.0, 0.0), (5.0, 1.0, 0.0)]
    tet = (4, [1, 1], [1, 2, 3, 4])
    boundary = analyze(_msh22(nodes, [tet, (2, [2, 2], [1, 2, 3])]), filename="face.msh").as_dict()
    apart = analyze(_msh22(nodes, [tet, (2, [3, 3], [5, 6, 7])]), filename="skin.msh").as_dict()
    assert boundary["mass"] == apart["mass"] == pytest.approx(1000 / 6, rel=1e-14)
    assert not any("no 3-D cell uses" in w for w in boundary["warnings"])
    assert any("3 points that no 3-D cell uses" in w for w in apart["warnings"])


def _element_data(name: str, count: int) -> bytes:
    """An ASCII $ElementData section: one scalar per element, 1..count."""
    lines = ["$ElementData", "1", f'"{name}"', "1", "0.0", "3", "0", "1", str(count)]
    lines += [f"{k} {0.5 * k!r}" for k in range(1, count + 1)]
    return ("\n".join([*lines, "$EndElementData"]) + "\n").encode()


_TETRA = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
# the tetrahedron and its four faces as triangles, as Gmsh writes a volume with its boundary
_WITH_FACES: list[tuple[int, list[int], list[int]]] = [
    (2, [1, 1], [1, 3, 2]),
    (2, [1, 1], [1, 2, 4]),
    (2, [1, 1], [1, 4, 3]),
    (2, [1, 1], [2, 3, 4]),
    (4, [2, 1], [1, 2, 3, 4]),
]


def test_a_data_field_over_several_cell_blocks_does_not_stop_the_reading() -> None:
    # libigl's tutorial hand.msh: one $ElementData field "E" over its triangles and tetrahedra, which meshio
    # cannot split between its cell blocks ("Incompatible cell data"); the file was refused as unreadable
    data = _msh22(_TETRA, _WITH_FACES) + _element_data("E", 5)
    doc = analyze(data, filename="hand.msh").as_dict()
    assert doc["mass"] / doc["density"] == pytest.approx(1 / 6, rel=1e-15)
    assert doc["center_of_mass"] == pytest.approx([0.25, 0.25, 0.25], rel=1e-15)


def test_a_density_field_meshio_cannot_split_is_refused_not_dropped() -> None:
    # a field named density gives each cell its own (API.md): left out, the file would weigh as uniform
    data = _msh22(_TETRA, _WITH_FACES) + _element_data("density", 5)
    with pytest.raises(UnreadableFileError, match="field that its reader"):
        analyze(data, filename="weighted.msh")


def test_a_version_1_gmsh_file_is_refused_by_its_version() -> None:
    # gmsh's own benchmarks/extrude/surf.msh: meshio says only "Couldn't read file ... as gmsh"
    data = b"$NOD\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$ENDNOD\n$ELM\n1\n1 4 1 1 4 1 2 3 4\n$ENDELM\n"
    with pytest.raises(UnsupportedFormatError, match="version-1 format"):
        analyze(data, filename="surf.msh")


def test_a_readers_warning_is_not_given_as_the_reason_it_failed() -> None:
    # as MmgTools' init.mesh once did: meshio prints "Warning: ... doesn't know keyword RequiredVertices.
    # Skipping.", then fails on a keyword it does not know; the refusal named the harmless warning
    lines = ["MeshVersionFormatted 2", "Dimension 3", "Vertices", "1", "0 0 0 1", "RequiredVertices", "1", "1"]
    lines += ["NoSuchKeyword", "1", "1", "End"]
    with pytest.raises(UnreadableFileError) as caught:
        analyze(("\n".join(lines) + "\n").encode(), filename="init.mesh")
    assert "NoSuchKeyword" in caught.value.message and "Skipping" not in caught.value.message


def test_medit_required_entities_weigh_nothing_and_are_read_past() -> None:
    # libMeshb's Required* blocks (elements a remesher keeps; MmgTools' test meshes): meshio refused every one
    # but RequiredVertices ("Unknown keyword 'RequiredEdges'")
    lines = ["MeshVersionFormatted 2", "Dimension 3", "Vertices", "4", "0 0 0 1", "2 0 0 1", "0 2 0 1", "0 0 2 1"]
    lines += ["RequiredVertices", "1", "1", "Edges", "1", "1 2 0", "RequiredEdges", "1", "1"]
    lines += ["Tetrahedra", "1", "1 2 3 4 0", "RequiredTetrahedra 1", "1", "RequiredTriangles", "0", "End"]
    doc = analyze(("\n".join(lines) + "\n").encode(), filename="init.mesh").as_dict()
    assert doc["mass"] / doc["density"] == pytest.approx(8 / 6, rel=1e-15)


_MSH41_SAVE_ALL = """$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
1
3 7 "solid"
$EndPhysicalNames
$Entities
0 0 1 1
1 0 0 0 1 1 1 0 0
1 0 0 0 1 1 1 1 7 1 1
$EndEntities
$Nodes
1 4 1 4
3 1 0 4
1
2
3
4
0 0 0
1 0 0
0 1 0
0 0 1
$EndNodes
$Elements
2 5 1 5
2 1 2 4
1 1 3 2
2 1 2 4
3 1 4 3
4 2 3 4
3 1 4 1
5 1 2 3 4
$EndElements
"""


def test_an_msh4_file_with_untagged_surfaces_beside_a_physical_volume_is_read() -> None:
    # Gmsh's Mesh.SaveAll writes every entity, physical or not (gmsh's own benchmarks/3d/discrete.msh): meshio
    # 5.3 could not split the physical tags of some entities between all cell blocks and the file was refused
    doc = analyze(_MSH41_SAVE_ALL.encode(), filename="discrete.msh").as_dict()
    assert doc["mass"] / doc["density"] == pytest.approx(1 / 6, rel=1e-15)
    assert doc["center_of_mass"] == pytest.approx([0.25, 0.25, 0.25], rel=1e-15)


_MSH41_TWO_MATERIALS = """$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
3 1 "steel"
3 2 "alu"
$EndPhysicalNames
$Entities
0 0 1 2
1 0 0 0 1 1 1 0 0
1 0 0 0 1 1 1 1 1 0
2 2 0 0 4 2 2 1 2 0
$EndEntities
$Nodes
1 8 1 8
3 1 0 8
1
2
3
4
5
6
7
8
0 0 0
1 0 0
0 1 0
0 0 1
2 0 0
4 0 0
2 2 0
2 0 2
$EndNodes
$Elements
3 3 1 3
2 1 2 1
1 1 2 3
3 1 4 1
2 1 2 3 4
3 2 4 1
3 5 6 7 8
$EndElements
"""


def test_an_msh4_file_read_without_its_entities_keeps_its_physical_names() -> None:
    # Mesh.SaveAll beside two physical volumes: the file is read without $Entities (meshio cannot split the
    # tags of the untagged surface), and the volumes keep the names their entities' tags give them, so that
    # densities by name still apply
    options = AnalysisOptions(densities={"steel": 7850.0, "alu": 2700.0})
    doc = analyze(_MSH41_TWO_MATERIALS.encode(), filename="two.msh", options=options).as_dict()
    assert sorted(p["name"] for p in doc["parts"]) == ["alu", "steel"]
    assert doc["mass"] == pytest.approx(7850.0 / 6 + 2700.0 * 8 / 6, rel=1e-14)


_MSH22_MIXED_TAG_COUNTS = """$MeshFormat
2.2 0 8
$EndMeshFormat
$Nodes
8
1 0 0 0
2 1 0 0
3 1 1 0
4 0 1 0
5 0 0 1
6 1 0 1
7 1 1 1
8 0 1 1
$EndNodes
$Elements
7
1 2 1 7 1 2 3
2 4 2 1 1 1 2 3 7
3 4 2 1 1 1 3 4 7
4 4 2 1 1 1 5 2 7
5 4 2 1 1 2 5 6 7
6 4 2 1 1 1 4 8 7
7 4 2 1 1 1 8 5 7
$EndElements
"""


def test_an_msh2_file_whose_elements_carry_different_numbers_of_tags_is_read() -> None:
    # legal in MSH 2 (FreeFem writes lines with one tag, triangles with two); meshio refused it ("Incompatible
    # cell data"): the six tetrahedra of the unit cube around its diagonal 1-7
    doc = analyze(_MSH22_MIXED_TAG_COUNTS.encode(), filename="cube.msh", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(1.0, rel=1e-15)
    assert doc["center_of_mass"] == pytest.approx([0.5, 0.5, 0.5], rel=1e-15)


def test_freefems_own_msh_format_is_named_as_such() -> None:
    # FreeFem++ writes .msh files of its own: "vertices triangles boundary-edges", then the lists
    text = "4 2 4\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n1 2 3 0\n1 3 4 0\n1 2 1\n2 3 1\n3 4 1\n4 1 1\n"
    with pytest.raises(UnsupportedFormatError) as info:
        analyze(text.encode(), filename="aile.msh")
    assert "FreeFem" in info.value.message and "'aile.msh' is not a Gmsh file" in info.value.message


@pytest.mark.parametrize(
    "text",
    [
        b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n0\n$EndNodes\n$Elements\n0\n$EndElements\n",
        b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n0 0 0 0\n$EndNodes\n$Elements\n0 0 0 0\n$EndElements\n",
    ],
    ids=["msh2", "msh4"],
)
def test_an_msh_file_without_nodes_is_empty_geometry(text: bytes) -> None:
    # PyMesh's tests/data/empty.msh: meshio answered "zero-size array to reduction operation maximum ..."
    with pytest.raises(EmptyGeometryError, match="holds no nodes"):
        analyze(text, filename="empty.msh")


def test_an_msh2_element_line_with_another_node_count_than_its_type_is_refused() -> None:
    """gmshparser's physical_v2_1.msh: a hexahedron written with the type number of a tetrahedron (4). Gmsh refuses
    the line; meshio took its last four nodes, four corners of one face, and the file read as a flat tetrahedron."""
    cube = [(x, y, z) for z in (0.0, 1.0) for y in (0.0, 1.0) for x in (0.0, 1.0)]
    hexahedron = [1, 2, 4, 3, 5, 6, 8, 7]
    with pytest.raises(UnreadableFileError, match=r"element 1 of .* has type 4 \(a 4-node tetra\) but lists 8 nodes"):
        analyze(_msh22(cube, [(4, [1, 1], hexahedron)]), filename="bad.msh")
    doc = analyze(_msh22(cube, [(5, [1, 1], hexahedron)]), filename="cube.msh").as_dict()  # its own type number, 5
    assert doc["mass"] / doc["density"] == pytest.approx(1.0, rel=1e-14)


def test_an_msh_4_0_file_as_gmsh_writes_it_is_read() -> None:
    """Gmsh 4.0 writes its version as "4", which meshio took for 4.1 and failed on ("unmatched data"); the box is
    1 x 2 x 3, meshed by Gmsh itself (tests/data/gmsh/README.md)."""
    path = ROOT / "tests" / "data" / "gmsh" / "box_v40.msh"
    assert path.read_bytes().startswith(b"$MeshFormat\n4 0 8\n")
    doc = analyze(str(path)).as_dict()
    assert doc["mass"] / doc["density"] == pytest.approx(6.0, rel=1e-14)
    assert doc["center_of_mass"] == pytest.approx([0.5, 1.0, 1.5], rel=1e-14)


def test_a_binary_msh_that_starts_with_a_dollar_sign_is_named_no_gmsh_file() -> None:
    # MuJoCo's own binary .msh (its test cube.msh): four int32 counts, the first 36 = b"$\x00\x00\x00"
    data = b"$\x00\x00\x00" + bytes(4) * 3 + bytes(range(200))
    with pytest.raises(UnreadableFileError, match=r"is not a Gmsh file: it does not start with a \$ section"):
        analyze(data, filename="cube.msh")


def test_a_partitioned_msh_file_is_refused_by_name() -> None:
    # Gmsh's partitioned output ($PartitionedEntities, $GhostElements): meshio read its partition entities' tags as
    # undefined numbers ("refers to 7 ... without defining it")
    data = b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PartitionedEntities\n2\n0\n0 0 0 0\n$EndPartitionedEntities\n"
    with pytest.raises(UnsupportedFormatError, match=r"is partitioned \(\$PartitionedEntities"):
        analyze(data, filename="box.msh")


def test_an_msh_file_without_elements_is_empty_geometry() -> None:
    # gmsh-parser's t9.msh: a format line and four empty entity lists, no $Nodes, no $Elements
    data = b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 0\n$EndEntities\n"
    with pytest.raises(EmptyGeometryError, match=r"holds no elements \(it has no \$Elements section\)"):
        analyze(data, filename="t9.msh")
