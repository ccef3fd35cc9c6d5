"""Abaqus decks that meshio reads as another body: nodes in several blocks, generated or placed geometry.

meshio 5.3.5 starts its node table afresh at each ``*NODE``, and ignores
the keywords that generate, copy or move nodes and elements.  The first is
repaired (node ids are the deck's own names); the others are refused by
name.  Expected values are closed forms: tetrahedra of volume |det|/6 and
centroid the mean of their corners.
"""

from __future__ import annotations

from fractions import Fraction

import pytest

from inertia.errors import UnsupportedFormatError
from inertia.pipeline import analyze

CORNER_TET = "1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n"  # volume 1/6, centroid (1/4, 1/4, 1/4)
FAR_TET = "5, 10, 0, 0\n6, 12, 0, 0\n7, 10, 2, 0\n8, 10, 0, 2\n"  # volume 8/6, centroid (10.5, 0.5, 0.5)


def expected() -> tuple[Fraction, list[Fraction]]:
    v1, v2 = Fraction(1, 6), Fraction(8, 6)
    c1, c2 = [Fraction(1, 4)] * 3, [Fraction(21, 2), Fraction(1, 2), Fraction(1, 2)]
    return v1 + v2, [(v1 * a + v2 * b) / (v1 + v2) for a, b in zip(c1, c2, strict=True)]


def weigh(deck: str) -> tuple[float, list[float]]:
    doc = analyze(deck.encode(), filename="deck.inp").as_dict()
    return doc["mass"] / doc["density"], doc["center_of_mass"]


@pytest.mark.parametrize(
    "deck",
    [
        # each element block after its own nodes: meshio pointed the first block into the second's nodes
        f"*HEADING\n*NODE\n{CORNER_TET}*ELEMENT, TYPE=C3D4, ELSET=A\n1, 1, 2, 3, 4\n"
        f"*NODE, NSET=FAR\n{FAR_TET}*ELEMENT, TYPE=C3D4, ELSET=B\n2, 5, 6, 7, 8\n",
        # both node blocks first: meshio failed on node id 1
        f"*HEADING\n*NODE\n{CORNER_TET}** a comment between\n*Node\n{FAR_TET}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n2, 5, 6, 7, 8\n",
        # Windows line ends, the last line without one
        (
            f"*HEADING\n*NODE\n{CORNER_TET}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n*NODE\n{FAR_TET}*ELEMENT, TYPE=C3D4\n2, 5, 6, 7, 8"
        ).replace("\n", "\r\n"),
    ],
    ids=["interleaved", "nodes-first", "crlf"],
)
def test_nodes_in_several_blocks_are_one_table(deck: str) -> None:
    volume, centre = weigh(deck)
    v, c = expected()
    assert volume == pytest.approx(float(v), rel=1e-14)
    assert centre == pytest.approx([float(x) for x in c], rel=1e-14)


def test_a_node_id_in_two_blocks_is_refused() -> None:
    deck = f"*NODE\n{CORNER_TET}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n*NODE\n{CORNER_TET.replace('0, 0, 1', '0, 0, 2')}"
    with pytest.raises(UnsupportedFormatError, match="node 1 in two \\*NODE blocks"):
        weigh(deck)


@pytest.mark.parametrize(
    ("extra", "said"),
    [
        ("*NGEN, NSET=LINE\n1, 4, 1\n", "generates nodes with \\*NGEN"),
        ("*ELGEN, ELSET=MORE\n1, 3, 4, 1\n", "generates elements with \\*ELGEN"),
        ("*NCOPY, OLD SET=A, NEW SET=B, CHANGE NUMBER=10, SHIFT\n1, 0, 0\n", "copies nodes with \\*NCOPY"),
        ("*NMAP, NSET=ALL, TYPE=SCALE\n0, 0, 0\n2, 2, 2\n", "maps node coordinates with \\*NMAP"),
    ],
)
def test_generated_or_moved_geometry_is_refused_by_name(extra: str, said: str) -> None:
    with pytest.raises(UnsupportedFormatError, match=said):
        weigh(f"*NODE\n{CORNER_TET}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n{extra}")


def test_cylindrical_node_coordinates_are_refused() -> None:
    with pytest.raises(UnsupportedFormatError, match="SYSTEM=C"):
        weigh(f"*NODE, SYSTEM=C\n{CORNER_TET}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n")


def test_a_placed_instance_is_refused_an_unplaced_one_read() -> None:
    part = f"*PART, NAME=P\n*NODE\n{CORNER_TET}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n*END PART\n*ASSEMBLY, NAME=A\n"
    with pytest.raises(UnsupportedFormatError, match="places a part instance"):
        weigh(part + "*INSTANCE, NAME=I, PART=P\n5., 0., 0.\n*END INSTANCE\n*END ASSEMBLY\n")
    with pytest.raises(UnsupportedFormatError, match="more than one part instance"):
        weigh(part + "*INSTANCE, NAME=I, PART=P\n*END INSTANCE\n*INSTANCE, NAME=J, PART=P\n*END INSTANCE\n*END ASSEMBLY\n")
    volume, centre = weigh(part + "*INSTANCE, NAME=I, PART=P\n0., 0., 0.\n*END INSTANCE\n*END ASSEMBLY\n")
    assert volume == pytest.approx(1 / 6, rel=1e-14) and centre == pytest.approx([0.25] * 3, rel=1e-14)
