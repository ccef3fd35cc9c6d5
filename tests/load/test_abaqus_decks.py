"""Abaqus decks that meshio reads as another body: nodes in several blocks, generated or placed geometry.

meshio 5.3.5 starts its node table afresh at each ``*NODE``, and ignores
the keywords that generate, copy or move nodes and elements.  The first is
repaired (node ids are the deck's own names); the others are refused by
name.  Expected values are closed forms: tetrahedra of volume |det|/6 and
centroid the mean of their corners.
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import pytest

from inertia.errors import (
    ExternalReferenceError,
    InputTooLargeError,
    UnreadableFileError,
    UnsupportedFormatError,
    ZeroVolumeError,
)
from inertia.load import load_body
from inertia.pipeline import AnalysisOptions, analyze, analyze_loaded

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


BIG_TET = "1, 0, 0, 0\n2, 3, 0, 0\n3, 0, 3, 0\n4, 0, 0, 3\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n"  # volume 27/6


def upload(main: str, **files: str) -> tuple[float, list[float]]:
    """The deck and its companions as one upload, read as the server reads it."""
    parts = [("deck.inp", main.encode()), *((name.replace("_", "."), text.encode()) for name, text in files.items())]
    doc = analyze_loaded(load_body(parts), AnalysisOptions()).as_dict()
    return doc["mass"] / doc["density"], doc["center_of_mass"]


def test_an_include_is_read_in_its_place_before_the_decks_own_nodes() -> None:
    # meshio merged the included tetrahedron, then replaced the node table at the deck's own *NODE: the deck's
    # tetrahedron came back twice (1/3 for 27/6 + 1/6)
    volume, centre = upload(
        f"*HEADING\n*INCLUDE, INPUT=part.inc\n*NODE\n{FAR_TET}*ELEMENT, TYPE=C3D4\n9, 5, 6, 7, 8\n", part_inc=f"*NODE\n{BIG_TET}"
    )
    assert volume == pytest.approx(27 / 6 + 8 / 6, rel=1e-14)
    assert centre[0] == pytest.approx((27 / 6 * 0.75 + 8 / 6 * 10.5) / (35 / 6), rel=1e-14)


def test_included_node_data_and_nested_includes_of_any_name() -> None:
    # *NODE, INPUT= reads the block's data lines from the file; an include may include others; names need not end in .inp
    volume, _ = upload(
        "*NODE, INPUT=nodes.txt\n*INCLUDE, INPUT=more.inc\n",
        nodes_txt=CORNER_TET,
        more_inc="*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n*INCLUDE, INPUT=far.inc\n",
        far_inc=f"*NODE\n{FAR_TET}*ELEMENT, TYPE=C3D4\n2, 5, 6, 7, 8\n",
    )
    assert volume == pytest.approx(9 / 6, rel=1e-14)


def test_a_path_named_in_an_included_file_is_refused(tmp_path: Path) -> None:
    secret = tmp_path / "secret.inp"
    secret.write_text(f"*NODE\n{BIG_TET}", encoding="utf-8")
    with pytest.raises(ExternalReferenceError, match="never opens files named by an upload"):
        upload("*HEADING\n*INCLUDE, INPUT=a_inc\n", a_inc=f"*INCLUDE, INPUT={secret}\n")


def test_the_working_directory_does_not_shadow_an_uploaded_include(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "a.inc").write_text(f"*NODE\n{BIG_TET}", encoding="utf-8")  # meshio looked here first
    monkeypatch.chdir(tmp_path)
    volume, _ = upload("*HEADING\n*INCLUDE, INPUT=a.inc\n", a_inc=f"*NODE\n{CORNER_TET}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n")
    assert volume == pytest.approx(1 / 6, rel=1e-14)


def test_an_include_that_includes_itself_is_refused() -> None:
    with pytest.raises((UnreadableFileError, InputTooLargeError)):
        upload("*INCLUDE, INPUT=loop_inc\n", loop_inc="*INCLUDE, INPUT=loop_inc\n*INCLUDE, INPUT=loop_inc\n")


def test_a_local_system_for_the_nodes_is_refused() -> None:
    with pytest.raises(UnsupportedFormatError, match="\\*SYSTEM"):
        weigh(f"*SYSTEM\n100., 0., 0.\n*NODE\n{CORNER_TET}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n")


def test_node_ids_are_compared_as_numbers() -> None:
    deck = f"*NODE\n{CORNER_TET}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n*NODE\n01, 5, 5, 5\n"
    with pytest.raises(UnsupportedFormatError, match="node 1 in two"):
        weigh(deck)


def test_the_caller_reads_nested_includes_beside_the_deck(tmp_path: Path) -> None:
    (tmp_path / "a.inp").write_text("*INCLUDE, INPUT=b.inp\n", encoding="utf-8")
    (tmp_path / "b.inp").write_text(f"*NODE\n{CORNER_TET}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n", encoding="utf-8")
    (tmp_path / "deck.inp").write_text("*HEADING\n*INCLUDE, INPUT=a.inp\n", encoding="utf-8")
    doc = analyze(tmp_path / "deck.inp").as_dict()
    assert doc["mass"] / doc["density"] == pytest.approx(1 / 6, rel=1e-14)
    with pytest.raises(ExternalReferenceError):
        analyze(tmp_path / "deck.inp", companions_beside=False)


def test_an_upload_of_a_deck_with_inp_includes_reads_the_deck_that_includes_them() -> None:
    # every file ends in .inp: the one no other file includes is the model, wherever it comes in the upload
    # (a zip's folders included: a companion is offered under its base name)
    deck = "*HEADING\n*INCLUDE, INPUT=nodes.inp\n*INCLUDE, INPUT=elements.inp\n"
    files = [
        ("mesh/nodes.inp", f"*NODE\n{CORNER_TET}{FAR_TET}".encode()),
        ("elements.inp", b"*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n2, 5, 6, 7, 8\n"),
        ("job.inp", deck.encode()),
    ]
    doc = analyze_loaded(load_body(files), AnalysisOptions()).as_dict()
    volume, centre = expected()
    assert doc["mass"] / doc["density"] == pytest.approx(float(volume), rel=1e-14)
    assert doc["center_of_mass"] == pytest.approx([float(c) for c in centre], rel=1e-14)
    assert doc["source"]["filename"] == "job.inp"


def test_an_include_named_from_the_folder_itself_is_the_file_beside(tmp_path: Path) -> None:
    # CalculiX decks include their generated mesh as INPUT=./all.msh: refused as a path, and all.msh (a readable
    # format's name) counted as a second model of the upload
    deck, mesh = b"*HEADING\n*INCLUDE, INPUT=./all.msh\n", f"*NODE\n{CORNER_TET}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n".encode()
    doc = analyze_loaded(load_body([("beam.inp", deck), ("all.msh", mesh)]), AnalysisOptions()).as_dict()
    assert doc["mass"] / doc["density"] == pytest.approx(1 / 6, rel=1e-14)
    (tmp_path / "beam.inp").write_bytes(deck)
    (tmp_path / "all.msh").write_bytes(mesh)
    doc = analyze(tmp_path / "beam.inp").as_dict()
    assert doc["mass"] / doc["density"] == pytest.approx(1 / 6, rel=1e-14)


def test_two_decks_that_include_neither_are_still_two_models() -> None:
    one = f"*NODE\n{CORNER_TET}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n".encode()
    with pytest.raises(UnsupportedFormatError, match="2 model files"):
        load_body([("a.inp", one), ("b.inp", one)])


def test_the_assemblys_reference_point_is_no_node_of_the_part() -> None:
    # as Abaqus/CAE writes a one-part model: the assembly's reference point is numbered 1 in its own namespace
    deck = (
        f"*Heading\n*Part, name=P\n*Node\n{CORNER_TET}*Element, type=C3D4\n1, 1, 2, 3, 4\n*End Part\n"
        "*Assembly, name=A\n*Instance, name=P-1, part=P\n*End Instance\n"
        "*Node\n      1,   5.,   5.,   5.\n*Nset, nset=RP, internal\n1,\n*End Assembly\n"
    )
    volume, centre = weigh(deck)
    assert volume == pytest.approx(1 / 6, rel=1e-14) and centre == pytest.approx([0.25] * 3, rel=1e-14)


def test_a_flat_element_set_is_named_in_the_refusal() -> None:
    # an element block whose only element is flat: the deck's other block has volume, so the message names the
    # part (each element block is one, named by its cell type and position)
    flat = "9, 10, 0, 0\n10, 11, 0, 0\n11, 10, 1, 0\n12, 11, 1, 0\n"
    deck = (
        f"*NODE\n{CORNER_TET}{flat}*ELEMENT, TYPE=C3D4, ELSET=SOLID\n1, 1, 2, 3, 4\n"
        "*ELEMENT, TYPE=C3D4, ELSET=FLAT\n2, 9, 10, 11, 12\n"
    )
    with pytest.raises(ZeroVolumeError, match="part 'tetra_1': the mesh encloses no volume") as err:
        weigh(deck)
    assert err.value.details["part"] == "tetra_1"


TWO_TETS = f"*NODE\n{CORNER_TET}{FAR_TET}"


@pytest.mark.parametrize(
    "deck",
    [
        # a comment line between the elements: meshio ended the block there and dropped the second element
        f"{TWO_TETS}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n**   2, 5, 6, 7, 8 (a note)\n2, 5, 6, 7, 8\n",
        # a node set by GENERATE without its increment (Abaqus: 1), and one naming a node the deck lacks
        f"{TWO_TETS}*NSET, NSET=ALL, GENERATE\n1, 8\n*NSET, NSET=GONE\n82\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n2, 5, 6, 7, 8\n"
        "*ELSET, ELSET=E, GENERATE\n1, 2\n",
        # node lines that end with a comma, omit z (0), leave a field empty (0), or go on with a normal's cosines
        "*NODE\n1, 0, 0, 0,\n2, 1, 0\n3, 0, 1, \n4, 0,, 1\n5, 10, 0, 0, 0.0, 0.0, 1.0\n6, 12, 0, 0\n7, 10, 2\n8, 10, 0, 2\n"
        "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n2, 5, 6, 7, 8\n",
        # keywords indented, as CalculiX's refined decks write them
        f" *NODE\n{CORNER_TET}{FAR_TET}  *ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n\t*ELEMENT, TYPE=C3D4\n2, 5, 6, 7, 8\n",
    ],
    ids=["comment-in-elements", "sets-meshio-failed-on", "node-lines-abaqus-defaults", "indented-keywords"],
)
def test_what_abaqus_ignores_or_defaults_keeps_every_element(deck: str) -> None:
    volume, centre = weigh(deck)
    v, c = expected()
    assert volume == pytest.approx(float(v), rel=1e-14)
    assert centre == pytest.approx([float(x) for x in c], rel=1e-14)


@pytest.mark.parametrize(("element", "nodes"), [("S8", "2, 3, 4, 2, 3, 4, 2, 3"), ("s4", "2, 3, 4, 2"), ("B32R", "2, 3, 4")])
def test_shells_and_beams_meshio_lacks_are_left_out_with_the_solids_weighed(element: str, nodes: str) -> None:
    deck = f"{TWO_TETS}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n2, 5, 6, 7, 8\n*ELEMENT, TYPE={element}\n3, {nodes}\n"
    doc = analyze(deck.encode(), filename="deck.inp").as_dict()
    v, c = expected()
    assert doc["mass"] / doc["density"] == pytest.approx(float(v), rel=1e-14)
    assert doc["center_of_mass"] == pytest.approx([float(x) for x in c], rel=1e-14)
    assert any("whose mass depends on section properties; they were not weighed" in w for w in doc["warnings"])


@pytest.mark.parametrize(
    "elements",
    [
        "1, 1, 2, 3, 4, 17\n2, 5, 6, 7, 8, 17, 18\n",  # numbers past the type's nodes (CalculiX's transition.inp)
        "1, 1, 2,\n3, 4\n2, 5, 6, 7,\n8, 19\n",  # continuation lines, the last with one number too many
        "1, 1, 2, 3, 4, 9, 9, 9, 9, 9\n2, 5, 6, 7, 8, 9, 9, 9, 9, 9\n",  # ten numbers a line: two rows of five to meshio
    ],
    ids=["extra-numbers", "continued", "a-multiple-of-the-row"],
)
def test_element_lines_are_read_as_calculix_reads_them(elements: str) -> None:
    # CalculiX (elements.f) takes an element's nodes from its first line and the lines after it until it
    # has as many as its type needs; numbers past those on a line are not nodes
    volume, centre = weigh(f"{TWO_TETS}*ELEMENT, TYPE=C3D4\n{elements}")
    v, c = expected()
    assert volume == pytest.approx(float(v), rel=1e-14)
    assert centre == pytest.approx([float(x) for x in c], rel=1e-14)


@pytest.mark.parametrize("newline", ["\n", "\r\n", "\r"], ids=["lf", "crlf", "cr"])
def test_a_comment_in_a_deck_of_any_line_ends_removes_only_its_line(newline: str) -> None:
    deck = f"** made by a tool\n{TWO_TETS}*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n** between\n2, 5, 6, 7, 8\n"
    volume, centre = weigh(deck.replace("\n", newline))
    v, c = expected()
    assert volume == pytest.approx(float(v), rel=1e-14)
    assert centre == pytest.approx([float(x) for x in c], rel=1e-14)
