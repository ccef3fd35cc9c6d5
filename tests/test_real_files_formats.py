"""Real PLY, OFF, VTK, VTU, AVS UCD, STEP and IGES files (tests/data/real/<format>/): what their readers got wrong.

Every file of those folders is also run by ``tests/test_real_files.py`` against
its independent reference (``benchmarks/real_files.py``); these tests pin the
bugs the files found, with expectations read from the files themselves.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

from inertia.load import load_body

REAL = Path(__file__).resolve().parent / "data" / "real"


@pytest.mark.parametrize("name", ["cellsnd.ascii.inp", "cellsnd.bin.inp"])
def test_avs_ucd_inp_is_read_as_avs_ucd_not_taken_for_abaqus(name: str) -> None:
    """VTK's test data: an AVS UCD file of 8 triangles and 4 quads (13 nodes), ASCII and binary.

    Read as Abaqus, the ASCII file was said to hold "no points" and the binary one
    failed on UTF-8 decoding; the file's own reader (VTK's vtkAVSucdReader) finds
    its 12 surface cells, which are read as a surface (8 triangles and 4 quads split
    in two: 16 triangles) and refused as open.
    """
    from inertia.errors import NotWatertightError
    from inertia.pipeline import AnalysisOptions, analyze_loaded

    pytest.importorskip("vtkmodules")
    ascii_text = (REAL / "inp" / "cellsnd.ascii.inp").read_text()
    cell_lines = [ln.split() for ln in ascii_text.splitlines() if len(ln.split()) > 2 and ln.split()[2] in ("tri", "quad")]
    assert sum(f[2] == "tri" for f in cell_lines) == 8 and sum(f[2] == "quad" for f in cell_lines) == 4
    loaded = load_body((REAL / "inp" / name).read_bytes(), filename=name)
    note = loaded.parts[0].body.warnings[0]
    assert "AVS UCD" in note and "12 surface cells (16 triangles)" in note
    assert "Abaqus" not in note and "utf-8" not in note.lower()
    with pytest.raises(NotWatertightError):
        analyze_loaded(loaded, AnalysisOptions())


def test_avs_ucd_tetrahedron_is_weighed() -> None:
    """A 3-D UCD cell is read, not only refused: one unit right-corner tetrahedron, V = 1/6."""
    pytest.importorskip("vtkmodules")
    text = b"# AVS UCD\n4 1 0 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n0 1 tet 0 1 2 3\n"
    loaded = load_body(text, filename="tet.inp")
    from inertia.pipeline import AnalysisOptions, analyze_loaded

    doc = analyze_loaded(loaded, AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(1 / 6, rel=1e-14)


def test_abaqus_inp_is_not_taken_for_avs_ucd() -> None:
    from inertia.load.volume import is_avs_ucd

    assert not is_avs_ucd(b"*HEADING\n** comment\n*NODE\n1, 0.0, 0.0, 0.0\n")
    assert is_avs_ucd((REAL / "inp" / "cellsnd.bin.inp").read_bytes())
    assert is_avs_ucd((REAL / "inp" / "cellsnd.ascii.inp").read_bytes())


def test_rooms_sharing_a_wall_are_not_rewound_as_cavities() -> None:
    """trimesh's no_indices_3storybuilding.glb: each floor is two rooms that share a wall (four faces on its edges).

    The components joined across manifold edges were two open rooms and the wall's two
    sides; the nesting test re-wound one side of the wall as a "cavity" and the volume came
    out 0.36 % high.  Expected: trimesh's own reading of the file integrated exactly.
    """
    from benchmarks.real_files import reference
    from inertia.pipeline import AnalysisOptions, analyze_loaded

    rel = "trimesh_models/no_indices_3storybuilding.glb"
    volume, tensor = reference(REAL / rel, rel, ())
    loaded = load_body((REAL / rel).read_bytes(), filename="no_indices_3storybuilding.glb", units="m")
    doc = analyze_loaded(loaded, AnalysisOptions(units="m", density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(volume, rel=1e-12)
    assert max(abs(a - b) for ra, rb in zip(doc["inertia_tensor"], tensor, strict=True) for a, b in zip(ra, rb, strict=True)) <= (
        1e-12 * float(abs(tensor).max())
    )
    assert not any("winding corrected" in w for w in doc["warnings"])


@pytest.mark.parametrize(("name", "types"), [("MS.inp", ["DASHPOTA", "SPRINGA"]), ("MSM.inp", ["DASHPOTA", "MASS", "SPRINGA"])])
def test_abaqus_deck_of_springs_and_masses_is_refused_by_element_name(name: str, types: list[str]) -> None:
    """CalculiX's mass-spring examples: their element types (read from the deck) are named, not "is the file complete?"."""
    from inertia.errors import UnsupportedFormatError

    text = (REAL / "calculix" / name).read_text()
    declared = re.findall(r"^\*ELEMENT, *TYPE=(\w+)", text, re.IGNORECASE | re.MULTILINE)
    assert set(types) <= set(declared)
    with pytest.raises(UnsupportedFormatError) as info:
        load_body((REAL / "calculix" / name).read_bytes(), filename=name)
    assert all(t in info.value.message for t in types)
    assert "complete" not in info.value.message


@pytest.mark.parametrize("spelling", ["c3d4", "C3D4T", "c3d4h", "DC3D4"])
def test_abaqus_solid_variants_in_any_case_are_weighed(spelling: str) -> None:
    """Abaqus reads names in any case and has many variants of one node layout; V of the unit corner tetrahedron is 1/6."""
    from inertia.pipeline import AnalysisOptions, analyze_loaded

    deck = (
        f"*node, nset=nall\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n*element, type={spelling}, elset=eall\n1, 1, 2, 3, 4\n"
    )
    deck += "*element output, elset=eall\nS\n"  # a keyword that starts like *ELEMENT and is not one
    doc = analyze_loaded(load_body(deck.encode(), filename="t.inp"), AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(1 / 6, rel=1e-14)


def test_abaqus_shells_beside_solids_are_said_not_weighed() -> None:
    from inertia.pipeline import AnalysisOptions, analyze_loaded

    deck = b"*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n"
    deck += b"*ELEMENT, TYPE=S3\n2, 1, 2, 3\n"  # a shell: its mass needs a thickness, so it is said to be left out
    doc = analyze_loaded(load_body(deck, filename="t.inp"), AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(1 / 6, rel=1e-14)
    assert any("1 triangle elements" in w and "not weighed" in w for w in doc["warnings"])


def _vtk_ply_volume(path: Path) -> float:
    """The volume VTK's own PLY reader gives (its polygons cut by vtkTriangleFilter), by the divergence theorem."""
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkFiltersCore import vtkTriangleFilter
    from vtkmodules.vtkIOPLY import vtkPLYReader

    reader = vtkPLYReader()
    reader.SetFileName(str(path))
    split = vtkTriangleFilter()
    split.SetInputConnection(reader.GetOutputPort())
    split.Update()
    grid = split.GetOutput()
    to_numpy: Any = vtk_to_numpy  # untyped in VTK's wheel
    x = np.asarray(to_numpy(grid.GetPoints().GetData()), dtype=np.float64)
    t = x[np.asarray(to_numpy(grid.GetPolys().GetConnectivityArray())).reshape(-1, 3)]
    return abs(float(np.einsum("ij,ij->", t[:, 0], np.cross(t[:, 1], t[:, 2])))) / 6


def test_non_planar_polygons_say_how_they_were_split() -> None:
    """VTK's shark.ply: 2374 polygons of 4 to 10 corners, many not planar, so the volume depends on the split.

    VTK's reader cuts them otherwise than trimesh's fan and finds another volume; the number we
    return holds for the fan, and a warning must say so with a bound at least the difference.
    """
    pytest.importorskip("vtkmodules")
    import re as _re

    from inertia.pipeline import AnalysisOptions, analyze_loaded

    path = REAL / "ply" / "shark.ply"
    doc = analyze_loaded(load_body(path.read_bytes(), filename="shark.ply"), AnalysisOptions(density=1.0)).as_dict()
    vtk_volume = _vtk_ply_volume(path)
    differs = abs(doc["mass"] - vtk_volume) / vtk_volume
    assert differs > 1e-6  # the two readers' splits really disagree
    notes = [w for w in doc["warnings"] if "not planar" in w and "fan" in w]
    assert len(notes) == 1
    found = _re.search(r"up to about ([0-9.e+-]+) of it", notes[0])
    assert found is not None
    bound = float(found.group(1))
    assert bound >= differs


@pytest.mark.parametrize(
    "rel", ["ply/cube_blender_uv.ply", "ply/cube_blender_uv_meshlab.ply", "trimesh_models/cube_compressed.obj"]
)
def test_planar_polygons_are_split_without_a_word(rel: str) -> None:
    from inertia.pipeline import AnalysisOptions, analyze_loaded

    doc = analyze_loaded(load_body((REAL / rel).read_bytes(), filename=rel.split("/")[-1]), AnalysisOptions(density=1.0)).as_dict()
    assert not any("not planar" in w for w in doc["warnings"])


def test_binary_ply_quads_are_checked_too() -> None:
    """A unit cube whose top corner (1, 1, 1) is raised to z = 1.3: its top quad is bent.

    Volume of the fan split from corner 4: 1 + 0.3 / 3 = 1.1; the other diagonal gives 1.05 (the
    tetrahedron of the four top corners, 0.3 / 6 = 0.05, is left out): the warning must say about 0.05.
    """
    import struct

    from inertia.pipeline import AnalysisOptions, analyze_loaded

    corners = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1.3), (0, 1, 1)]
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    header = (
        "ply\nformat binary_little_endian 1.0\nelement vertex 8\nproperty double x\nproperty double y\n"
        "property double z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n"
    )
    data = header.encode() + b"".join(struct.pack("<3d", *c) for c in corners)
    data += b"".join(struct.pack("<B4i", 4, *q) for q in quads)
    doc = analyze_loaded(load_body(data, filename="bent.ply"), AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(1.1, rel=1e-14)
    notes = [w for w in doc["warnings"] if "not planar" in w]
    assert len(notes) == 1 and "1 of the 6 faces" in notes[0] and "about 0.05 of it" in notes[0]


def test_off_quads_are_checked_too() -> None:
    """The bent cube of the binary PLY test as an OFF file (header and counts on one line, as trimesh's whitespace.off)."""
    from inertia.pipeline import AnalysisOptions, analyze_loaded

    text = "OFF 8 6 12\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1.3\n0 1 1\n"
    text += "4 0 3 2 1\n4 4 5 6 7 0.5 0.5 0.5 1\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n"
    doc = analyze_loaded(load_body(text.encode(), filename="bent.off"), AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(1.1, rel=1e-14)
    notes = [w for w in doc["warnings"] if "not planar" in w]
    assert len(notes) == 1 and "OFF file" in notes[0] and "about 0.05 of it" in notes[0]


def test_polyhedron_cells_are_weighed() -> None:
    """VTK's polyhedron2pieces.vtu: two unit cubes written as polyhedra (VTK type 42), each under a pyramid of height 1.

    From the file's own coordinates: V = 2 (1 + 1/3) = 8/3.
    """
    pytest.importorskip("vtkmodules")
    from inertia.pipeline import AnalysisOptions, analyze_loaded

    doc = analyze_loaded(
        load_body((REAL / "vtu" / "polyhedron2pieces.vtu").read_bytes(), filename="polyhedron2pieces.vtu"),
        AnalysisOptions(density=1.0),
    ).as_dict()
    assert doc["mass"] == pytest.approx(8 / 3, rel=1e-14)
    assert doc["source"]["points"] == 18  # the file's own points: the split adds none
    assert doc["source"]["cells"] == 4  # the file's cells (2 polyhedra, 2 pyramids), not the tetrahedra of the split
    assert any("2 polyhedron cells were weighed as" in w for w in doc["warnings"])
    assert not any("not planar" in w for w in doc["warnings"])


def test_prism_cells_are_weighed_as_vtk_weighs_them() -> None:
    """VTK's PentaHexa.vtk: 60 pentagonal and 150 hexagonal prisms on a sphere, their faces bent.

    VTK's own cell sizes (vtkCellSizeFilter, signed: 150 cells are wound inward) sum in absolute
    value to the volume; the bent faces are said in a warning.
    """
    pytest.importorskip("vtkmodules")
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkFiltersVerdict import vtkCellSizeFilter
    from vtkmodules.vtkIOLegacy import vtkUnstructuredGridReader

    from inertia.pipeline import AnalysisOptions, analyze_loaded

    path = REAL / "vtk" / "PentaHexa.vtk"
    reader = vtkUnstructuredGridReader()
    reader.SetFileName(str(path))
    sizes = vtkCellSizeFilter()
    sizes.SetInputConnection(reader.GetOutputPort())
    sizes.Update()
    to_numpy: Any = vtk_to_numpy  # untyped in VTK's wheel
    volumes = np.asarray(to_numpy(sizes.GetOutput().GetCellData().GetArray("Volume")))
    doc = analyze_loaded(load_body(path.read_bytes(), filename="PentaHexa.vtk"), AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(float(np.abs(volumes).sum()), rel=1e-12)
    assert doc["source"]["cells"] == sizes.GetOutput().GetNumberOfCells() == 210  # the file's cells, as VTK counts them
    assert any("hexagonal prism cells" in w and "not planar" in w for w in doc["warnings"])


def test_polyhedron_that_is_not_star_shaped_is_refused() -> None:
    """An L-shaped polyhedron (VTK type 42): from its first corner (the L's outer corner) one arm's end is seen from behind."""
    pytest.importorskip("vtkmodules")
    from inertia.errors import UnsupportedFormatError

    # an L of two arms 4 long and 0.1 wide, 1 high
    pts = [(0, 0, 0), (4, 0, 0), (4, 0.1, 0), (0.1, 0.1, 0), (0.1, 4, 0), (0, 4, 0)]
    pts += [(x, y, 1) for x, y, _ in pts]
    bottom = [5, 4, 3, 2, 1, 0]
    top = [6, 7, 8, 9, 10, 11]
    sides = [[i, (i + 1) % 6, (i + 1) % 6 + 6, i + 6] for i in range(6)]
    faces = [bottom, top, *sides]
    stream = [len(faces)] + [v for f in faces for v in (len(f), *f)]
    points = "\n".join(f"{x} {y} {z}" for x, y, z in pts)
    text = (
        "# vtk DataFile Version 5.1\nL\nASCII\nDATASET UNSTRUCTURED_GRID\n"
        f"POINTS {len(pts)} double\n{points}\n"
        f"CELLS 2 {len(stream)}\nOFFSETS vtktypeint64\n0 {len(stream)}\nCONNECTIVITY vtktypeint64\n"
        + " ".join(map(str, stream))
        + "\nCELL_TYPES 1\n42\n"
    )
    with pytest.raises(UnsupportedFormatError) as info:
        load_body(text.encode(), filename="L.vtk")
    assert "star-shaped" in info.value.message


def test_gltf_primitives_have_the_same_part_names_on_every_read() -> None:
    """trimesh names a mesh's primitives with random hex digits; the parts, their names and order must not vary."""
    import random

    from inertia.pipeline import analyze

    path = REAL / "gltf_multi" / "rgb_cube_with_primitives.gltf"
    analyze(str(path))  # a module trimesh imports on first use draws from ``random`` as it is imported
    before = random.getstate()
    first = analyze(str(path)).as_dict()
    assert random.getstate() == before  # the caller's random numbers are left as they were
    random.random()  # whatever the state of ``random`` when the file is read
    second = analyze(str(path)).as_dict()
    assert first["warnings"] == second["warnings"]
    assert re.findall(r"Cube_\w+", " ".join(first["warnings"]))  # the primitives' parts are named in a warning


def test_a_gltf_with_a_byte_order_mark_is_read_as_without_it() -> None:
    # glTF 2.0 section 3.2 forbids the mark (the validator's json/bom.gltf); trimesh read such a file as the name of
    # another ("an entry the format requires is missing ('model.gltf')")
    from inertia.pipeline import analyze

    text = (REAL / "gltf_multi" / "rgb_cube_with_primitives.gltf").read_bytes()
    plain = analyze(text, filename="cube.gltf").as_dict()
    marked = analyze(b"\xef\xbb\xbf" + text, filename="cube.gltf").as_dict()
    for key in ("mass", "center_of_mass", "inertia_tensor", "warnings"):
        assert marked[key] == plain[key]


@pytest.mark.parametrize(
    "doc",
    [
        {"asset": {"version": "2.0"}},
        {"asset": {"version": "2.0"}, "buffers": [{"byteLength": 4}], "bufferViews": [{"buffer": 0, "byteLength": 4}]},
        {"asset": {"version": "2.0"}, "images": [{"uri": "data:image/png;base64,"}], "meshes": []},
    ],
    ids=["asset-only", "a-buffer-without-uri", "images-only"],
)
def test_a_gltf_without_meshes_holds_no_triangles(doc: dict[str, Any]) -> None:
    # the validator's valid files of buffers, views or images alone: trimesh's KeyError ('accessors', 'uri') had
    # been read as a missing entry of a broken file
    import json

    from inertia.errors import EmptyGeometryError
    from inertia.pipeline import analyze

    with pytest.raises(EmptyGeometryError, match="holds no meshes"):
        analyze(json.dumps(doc).encode(), filename="scene.gltf")


def test_a_glb_shorter_than_its_header_says_is_refused_as_truncated() -> None:
    import json
    import struct

    from inertia.errors import UnreadableFileError

    chunk = json.dumps({"asset": {"version": "2.0"}}).encode().ljust(32, b" ")  # 52 bytes in all
    glb = b"glTF" + struct.pack("<II", 2, 12 + 8 + len(chunk)) + struct.pack("<II", len(chunk), 0x4E4F534A) + chunk
    with pytest.raises(UnreadableFileError, match=r"declares 52 bytes but the file has 51; it is truncated or corrupt"):
        load_body(glb[:-1], filename="short.glb")
    with pytest.raises(UnreadableFileError, match=r"declares 8 bytes, too few for its 12-byte header and a chunk"):
        load_body(glb[:8] + struct.pack("<I", 8) + glb[12:], filename="tiny.glb")
    with pytest.raises(UnreadableFileError, match=r"the GLB header gives version 7; binary glTF 2.0 has version 2"):
        load_body(glb[:4] + struct.pack("<I", 7) + glb[8:], filename="seven.glb")


def test_bytes_after_a_glbs_declared_length_are_left_out_with_a_note() -> None:
    # glTF 2.0 section 4.4.2: the header's length is that of the whole GLB; the validator's GLB_EXTRA_DATA is a
    # warning, and trimesh and three.js read only that length. The 1 x 2 x 3 box weighs 6 at density 1.
    import trimesh

    from benchmarks.cases import box
    from inertia.pipeline import AnalysisOptions, analyze

    glb = trimesh.Trimesh(*box(1.0, 2.0, 3.0), process=False).export(file_type="glb")
    assert isinstance(glb, bytes)
    tail = b"glTF" + bytes(60)  # anything at all: here what looks like another GLB's header
    doc = analyze(glb + tail, filename="extra.glb", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(6.0, rel=1e-12)
    note = f"the GLB file has {len(tail)} byte(s) after the {len(glb)} its header declares"
    assert any(note in w for w in doc["warnings"])


def test_a_vtu_whose_points_are_fewer_than_its_cells_use_is_refused_by_name() -> None:
    # NumberOfPoints="1": VTK's reader keeps one point, and the tetra10 cells' nodes run past it; the warning
    # about 2-D cells apart from the volume indexed the points with those nodes first (an IndexError)
    from inertia.errors import UnreadableFileError

    data = (REAL / "vtu" / "tetra.vtu").read_bytes().replace(b'NumberOfPoints="22"', b'NumberOfPoints="1"')
    with pytest.raises(UnreadableFileError, match="refers to a point that does not exist"):
        load_body(data, filename="tetra.vtu")


@pytest.mark.parametrize(
    ("old", "new", "words"),
    [
        (b'NumberOfPoints="5"', b'NumberOfPoints="-1"', r"NumberOfPoints='-1', which is no count"),
        (b'NumberOfPoints="5"', b'NumberOfPoints="1e308"', r"NumberOfPoints='1e308', which is no count"),
        (b'NumberOfComponents="3"', b'NumberOfComponents="1000000000000"', r"NumberOfComponents=1000000000000, more values"),
    ],
    ids=["negative", "not-an-integer", "absurd-components"],
)
def test_vtk_xml_counts_no_file_can_hold_are_refused_before_vtk_reads_them(old: bytes, new: bytes, words: str) -> None:
    # VTK's XML readers trust these: -1 points crashed the process (SIGSEGV), 1e12 components looped for minutes
    from inertia.errors import UnreadableFileError

    data = (REAL / "vtu" / "cell_Pyramid.vtu").read_bytes()
    assert old in data
    with pytest.raises(UnreadableFileError, match=words):
        load_body(data.replace(old, new, 1), filename="pyramid.vtu")


@pytest.mark.parametrize(
    ("old", "new"), [(b"\n5 2.000000 0.000000", b"\n-2 2.000000 0.000000"), (b"\n1 1 tri 8 4 1", b"\n1 1 tri 8 -4 1")]
)
def test_an_avs_ucd_file_with_a_negative_number_is_refused_before_vtk_reads_it(old: bytes, new: bytes) -> None:
    # vtkAVSucdReader indexes its node map with the numbers as written: a node or a corner numbered -2 or -4
    # crashed the process (SIGSEGV)
    from inertia.errors import UnreadableFileError

    data = (REAL / "inp" / "cellsnd.ascii.inp").read_bytes()
    assert old in data
    with pytest.raises(UnreadableFileError, match="with a negative number"):
        load_body(data.replace(old, new, 1), filename="cells.inp")


@pytest.mark.parametrize(
    "new",
    [b"POINTS -1 float", b"POINTS 1e9 float", b"POINTS 99999999999 float"],
    ids=["negative", "not-an-integer", "more-than-the-file"],
)
def test_a_legacy_vtk_count_no_file_can_hold_is_refused_before_vtk_reads_it(new: bytes) -> None:
    # vtkDataSetReader trusts POINTS n: -1 crashed the process (SIGSEGV)
    from inertia.errors import UnreadableFileError

    data = (REAL / "vtk" / "AngularSector.vtk").read_bytes()
    assert b"POINTS 10141 float" in data
    with pytest.raises(UnreadableFileError, match="gives a count that is no count or more than the file holds"):
        load_body(data.replace(b"POINTS 10141 float", new, 1), filename="sector.vtk")


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        ("*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n2, 3, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n", "defines node 2 more than once"),
        ("*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n", "defines element 1 more than once"),
    ],
    ids=["node", "element"],
)
def test_an_abaqus_deck_that_numbers_two_nodes_or_elements_alike_is_refused(extra: str, words: str) -> None:
    # meshio kept a repeated node's last coordinates and counted a repeated element twice (volume 7/6 of 1)
    from inertia.errors import UnreadableFileError

    elements = "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n" + ("1, 1, 2, 3, 4\n" if "element" in words else "")
    with pytest.raises(UnreadableFileError, match=words):
        load_body((extra + elements).encode(), filename="tet.inp")
    single = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n"
    assert load_body(single.encode(), filename="tet.inp").parts  # one of each: read
