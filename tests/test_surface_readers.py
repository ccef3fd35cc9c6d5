"""Surface readers: OBJ and 3MF by the specification, glTF checks, multi-file uploads, no crash and no noise."""

from __future__ import annotations

import base64
import io
import json
import math
import re
import struct
import zipfile
from collections.abc import Callable
from fractions import Fraction
from pathlib import Path
from typing import Any, cast

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from benchmarks.cases import box, cube, obj_bytes
from inertia.errors import (
    EmptyGeometryError,
    InvalidParameterError,
    NotWatertightError,
    ServiceError,
    UnreadableFileError,
    UnsupportedFormatError,
    ZeroVolumeError,
)
from inertia.load import load_body
from inertia.load.ply import read_ascii_ply, uniform_face_rows
from inertia.load.safe import guarded_read
from inertia.pipeline import AnalysisOptions, analyze, analyze_loaded


def obj_text(v: np.ndarray, f: np.ndarray, extra: str = "") -> bytes:
    return extra.encode() + obj_bytes([(None, v, f)])


# --- OBJ -------------------------------------------------------------------------------------------


def test_an_obj_vertex_with_two_coordinates_is_refused_with_its_line() -> None:
    with pytest.raises(UnreadableFileError) as err:
        analyze(b"v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", filename="flat.obj")
    assert "line 1" in err.value.message and "2 numbers" in err.value.message


@pytest.mark.parametrize(
    "text, words",
    [
        (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "refers to vertex 9"),
        (b"v 0 0 0 2\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "weight"),
        (b"v 0 0 x\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "not a number"),
        (b"v 0 0 0\nf 1 a 3\n", "not an integer"),
        # tinyobjloader's issue-140-zero-face-idx.obj: 0 is no vertex number, whatever comes before it
        (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 0/0/0 1/1/1 2/2/2\n", "OBJ numbers vertices from 1"),
        (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "OBJ numbers vertices from 1"),
        (b"v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "gives 2 numbers;"),
        (b"v 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "gives 1 number;"),
    ],
)
def test_bad_obj_lines_are_named(text: bytes, words: str) -> None:
    with pytest.raises(UnreadableFileError) as err:
        analyze(text, filename="bad.obj")
    assert words in err.value.message


def test_msvc_spelling_of_nan_in_an_obj_file_is_named() -> None:
    # tinyobjloader's test-nan.obj: '#' began a comment, and "gives 1 numbers" hid the NaN behind it
    text = b"v 1.#IND -1.#IND 1.#IND\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
    with pytest.raises(InvalidParameterError, match=r"line 1 .* holds '1\.#IND', how Microsoft's C library writes"):
        analyze(text, filename="nan.obj")


def test_obj_quads_negative_indices_and_colours_read_exactly() -> None:
    v, _ = box(1.0, 2.0, 3.0)
    quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r} 0.5 0.5 0.5" for x, y, z in v]
    lines += ["f " + " ".join(f"{i - 8}/1/1" for i in q) for q in quads]  # relative indices, v/vt/vn
    doc = analyze("\n".join(lines).encode(), filename="quads.obj").as_dict()
    assert doc["mass"] == pytest.approx(6000, rel=1e-15)


def test_an_mni_object_file_is_named_for_what_it_is() -> None:
    # brain-imaging surfaces (MNI/BIC, read by VTK's vtkMNIObjectReader) are also called .obj: no "v" lines
    text = b"P 0.3 0.3 0.4 10 1 4\n 0 0 0\n 1 0 0\n 0 1 0\n 0 0 1\n"
    with pytest.raises(UnsupportedFormatError, match=r"MNI object file .* not a Wavefront OBJ"):
        analyze(text, filename="surface.obj")


def test_binary_bytes_named_obj_are_refused_in_words() -> None:
    with pytest.raises(ServiceError) as err:
        analyze(b"\x00\x01\x02binary", filename="x.obj")
    assert err.value.code in ("unreadable_file", "empty_geometry")


# --- OFF -------------------------------------------------------------------------------------------
# Every spelling below is the tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1) with outward faces: volume 1/6,
# centre (1/4, 1/4, 1/4).
TET_FACES = "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
TET_VERTICES = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"


@pytest.mark.parametrize(
    "text",
    [
        f"OFF\n4 4 6\n{TET_VERTICES}{TET_FACES}",
        f"OFF\n4 4 6\n# a comment\x0cwith a form feed\n{TET_VERTICES}{TET_FACES}",  # no line break in a comment
        f"4 4 6\n{TET_VERTICES}{TET_FACES}",  # the keyword is optional
        f"OFF 4 4 6\n{TET_VERTICES}{TET_FACES}",
        f"OFF4 4 6\n{TET_VERTICES}{TET_FACES}",  # counts written onto the keyword (trimesh's whitespace.off)
        f"nOFF\n3\n4 4 6\n{TET_VERTICES}{TET_FACES}",
        f"OFF\n4 4 6\n0 0 0 1 0\n0\n0 1 0 0\n0 1\n{TET_FACES}",  # vertices over line breaks
        f"OFF\n4 4 6\n0 0 0 1 0 0\n0 1 0\n0 0 1\n{TET_FACES}",  # two vertices on one line
        f"OFF\n4 4\n6\n{TET_VERTICES}{TET_FACES}",  # NEdges on a line of its own
        f"OFF\n4\n4\n6\n{TET_VERTICES}{TET_FACES}",  # every count on a line of its own
        f"OFF\n4 4 6\n{TET_VERTICES}3 0 2\n1 0.5 0.5 0.5\n3 0 1 3 7\n3\n0 3 2\n3 1 2 3\n",  # faces over lines
        f"NOFF\n4 4 6\n{TET_VERTICES.replace(chr(10), ' 0 0 1' + chr(10))}{TET_FACES}",
        f"appearance {{\n +texturing\n texture {{ file grid.pgm }}\n}}\nOFF\n4 4 6\n{TET_VERTICES}{TET_FACES}",
        # 4OFF: (x, y, z) / w
        f"4OFF\n4 4 6\n0 0 0 1\n2 0 0 2\n0 3 0 3\n0 0 0.5 0.5\n{TET_FACES}",
    ],
)
def test_off_is_read_as_geomview_specifies(text: str) -> None:
    doc = analyze(text.encode(), filename="tet.off", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(1 / 6, rel=1e-15)
    np.testing.assert_allclose(doc["center_of_mass"], [0.25, 0.25, 0.25], rtol=1e-15)


@pytest.mark.parametrize(
    ("text", "error", "words"),
    [
        ("OFF BINARY\n" + "x" * 40, UnsupportedFormatError, "binary OFF is not supported"),
        (f"nOFF\n4\n4 4 6\n{TET_VERTICES}{TET_FACES}", UnsupportedFormatError, "4 dimensions; a solid needs three"),
        ("\x01" * 10_000, UnreadableFileError, "binary data, not OFF text"),
        (f"OFF\nfour 4 6\n{TET_VERTICES}{TET_FACES}", UnreadableFileError, "'four' where its vertex count"),
        (f"OFF\n4 4 6\n{TET_VERTICES}3 0 2 1\n3 0 1 4\n3 0 3 2\n3 1 2 3\n", UnreadableFileError, "refers to vertex 4"),
        (f"OFF\n4 5 6\n{TET_VERTICES}{TET_FACES}", UnreadableFileError, "ends after 4 of its 5 faces"),
        (f"OFF\n5 4 6\n{TET_VERTICES}{TET_FACES}", UnreadableFileError, "OFF file"),
        (f"4OFF\n4 4 6\n0 0 0 0\n1 0 0 1\n0 1 0 1\n0 0 1 1\n{TET_FACES}", UnreadableFileError, "point at infinity"),
        (f"4OFF\n4 4 6\n0 0 0 1\n1 0 0 0\n0 1 0 1\n0 0 1 0\n{TET_FACES}", UnreadableFileError, "vertex 1 (counting from 0)"),
        ("OFF\n0 0 0\n", EmptyGeometryError, "declares 0 vertices and 0 faces"),
        (f"OFF\n4 4 6\n{TET_VERTICES}3 0 2 99999999999999999999\n{TET_FACES[8:]}", UnreadableFileError, "99999999999999999999"),
    ],
)
def test_off_faults_are_named(text: str, error: type[ServiceError], words: str) -> None:
    with pytest.raises(error, match=re.escape(words)) as caught:
        analyze(text.encode(), filename="bad.off")
    assert len(caught.value.message) < 400  # a binary "word" of megabytes is not quoted whole


# --- guarded reader calls ----------------------------------------------------------------------------


def test_system_exit_from_a_reader_becomes_an_error_and_chatter_is_silenced(capsys: pytest.CaptureFixture[str]) -> None:
    def reader() -> None:
        print("reader noise")
        raise SystemExit(1)

    with pytest.raises(UnreadableFileError) as err:
        guarded_read(reader, "ply")
    out = capsys.readouterr()
    assert out.out == "" and out.err == ""
    assert "PLY file could not be read" in err.value.message and "SystemExit" not in err.value.message


def test_keyboard_interrupt_is_not_swallowed() -> None:
    def reader() -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        guarded_read(reader, "ply")


def test_a_key_error_inside_a_reader_is_a_sentence() -> None:
    def reader() -> None:
        raise KeyError("vertex")

    with pytest.raises(UnreadableFileError) as err:
        guarded_read(reader, "ply")
    assert "missing" in err.value.message and err.value.details["reader_error"].startswith("KeyError")


# --- 3MF -----------------------------------------------------------------------------------------------

CT = (
    '<?xml version="1.0" encoding="UTF-8"?><Types xmlns="http://schemas.openxmlformats.org/package/2006/'
    'content-types"><Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>'
    '<Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/></Types>'
)
RELS = (
    '<?xml version="1.0" encoding="UTF-8"?><Relationships xmlns="http://schemas.openxmlformats.org/package/2006/'
    'relationships"><Relationship Target="/3D/3dmodel.model" Id="rel0" '
    'Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>{extra}</Relationships>'
)
CORE = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
PROD = "http://schemas.microsoft.com/3dmanufacturing/production/2015/06"


def mesh_xml(v: np.ndarray, f: np.ndarray) -> str:
    verts = "".join(f'<vertex x="{x!r}" y="{y!r}" z="{z!r}"/>' for x, y, z in v.tolist())
    tris = "".join(f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in f.tolist())
    return f"<mesh><vertices>{verts}</vertices><triangles>{tris}</triangles></mesh>"


def package(model: str, extra_rels: str = "", parts: dict[str, str] | None = None) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("[Content_Types].xml", CT)
        zf.writestr("_rels/.rels", RELS.format(extra=extra_rels))
        zf.writestr("3D/3dmodel.model", model)
        for name, text in (parts or {}).items():
            zf.writestr(name, text)
    return buf.getvalue()


def model(resources: str, build: str, unit: str = "millimeter", ns: str = "") -> str:
    return (
        f'<?xml version="1.0" encoding="UTF-8"?><model unit="{unit}" xmlns="{CORE}"{ns}>'
        f"<resources>{resources}</resources><build>{build}</build></model>"
    )


def test_3mf_support_objects_are_listed_not_weighed() -> None:
    part, support = mesh_xml(*cube(10.0)), mesh_xml(*cube(5.0, (20.0, 0.0, 0.0)))
    data = package(
        model(
            f'<object id="1" type="model" name="part">{part}</object><object id="2" type="support" name="prop">{support}</object>',
            '<item objectid="1"/><item objectid="2"/>',
        )
    )
    doc = analyze(data, filename="p.3mf", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(1000 * 1e-9, rel=1e-14)
    assert any("'prop'" in w and "not weighed" in w for w in doc["warnings"])


@pytest.mark.parametrize("closed", [True, False])
def test_3mf_a_support_that_is_a_component_of_the_part_is_not_weighed(closed: bool) -> None:
    # ch. 4.1 recommends attaching supports to a part as components (lib3mf's 3mfbase13_holed_cube_support.3mf):
    # a closed support was weighed silently, an open one refused the file as not watertight
    v, f = cube(5.0, (20.0, 0.0, 0.0))
    support = mesh_xml(v, f if closed else f[:-2])
    data = package(
        model(
            f'<object id="1" type="model" name="block">{mesh_xml(*cube(10.0))}</object>'
            f'<object id="2" type="support" name="prop">{support}</object>'
            '<object id="3" type="model" name="part"><components><component objectid="1"/><component objectid="2"/>'
            "</components></object>",
            '<item objectid="3"/>',
        )
    )
    doc = analyze(data, filename="p.3mf", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(1000 * 1e-9, rel=1e-14)
    assert doc["center_of_mass"] == pytest.approx([0.005, 0.005, 0.005], rel=1e-14)
    assert any("prop (support)" in w and "not weighed" in w for w in doc["warnings"])


def test_a_bare_3mf_model_part_is_named_for_what_it_is() -> None:
    # the XML of 3D/3dmodel.model alone: no 3MF tool reads it, and "not a zip" leaves the sender guessing
    xml = model(f'<object id="1" type="model">{mesh_xml(*cube(2.0))}</object>', '<item objectid="1"/>').encode()
    with pytest.raises(UnreadableFileError, match=r"bare XML model .* zip the model with its _rels/\.rels"):
        analyze(xml, filename="part.3mf")
    with pytest.raises(UnsupportedFormatError, match=r"\.model file is the XML part inside a 3MF package"):
        analyze(xml, filename="3dmodel.model")


def test_a_3mf_in_the_draft_093_namespace_is_named_as_such() -> None:
    # lib3mf's v093 test files: the 2013/01 namespace of the draft before 3MF 1.0 (object ids from 0); "invalid"
    # told the sender nothing about why
    xml = model(f'<object id="0" type="model">{mesh_xml(*cube(2.0))}</object>', '<item objectid="0"/>')
    xml = xml.replace(CORE, "http://schemas.microsoft.com/3dmanufacturing/2013/01")
    with pytest.raises(UnsupportedFormatError, match=r"3MF 0\.93 .* re-save it with a current 3MF exporter"):
        analyze(package(xml), filename="old.3mf")


def test_3mf_production_objects_in_another_model_part_are_read() -> None:
    other = (
        f'<?xml version="1.0" encoding="UTF-8"?><model unit="millimeter" xmlns="{CORE}"><resources>'
        f'<object id="7" type="model">{mesh_xml(*cube(2.0))}</object></resources><build/></model>'
    )
    root = model(
        '<object id="1" type="model"><components><component objectid="7" p:path="/3D/Objects/cube.model" '
        'transform="1 0 0 0 1 0 0 0 1 5 0 0"/></components></object>',
        '<item objectid="1"/>',
        ns=f' xmlns:p="{PROD}" requiredextensions="p"',
    )
    doc = analyze(
        package(root, parts={"3D/Objects/cube.model": other}), filename="prod.3mf", options=AnalysisOptions(units="m", density=1.0)
    ).as_dict()
    assert doc["mass"] == pytest.approx(8.0, rel=1e-15)
    np.testing.assert_allclose(doc["center_of_mass"], [6.0, 1.0, 1.0], rtol=1e-15)


def test_3mf_mirroring_transform_keeps_the_part_outward() -> None:
    data = package(
        model(
            f'<object id="1" type="model">{mesh_xml(*box(1.0, 2.0, 3.0))}</object>',
            '<item objectid="1" transform="-1 0 0 0 1 0 0 0 1 0 0 0"/>',
        )
    )
    doc = analyze(data, filename="m.3mf", options=AnalysisOptions(units="m", density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(6.0, rel=1e-15)
    assert not any("winding" in w for w in doc["warnings"])


@pytest.mark.parametrize("mirror", [False, True])
def test_3mf_rotation_written_to_six_digits_is_placed_as_that_rotation(mirror: bool) -> None:
    # a turn of 72 degrees about z as CAD exporters write it: cos 0.309017, sin 0.951057, so that the
    # determinant is +-(0.309017**2 + 0.951057**2) = +-1.000000923538 (exact in decimal); the box is 1 x 2 x 3
    c, s = 0.309017, 0.951057
    rows = f"{c} {s} 0 {s} -{c} 0" if mirror else f"{c} {s} 0 -{s} {c} 0"
    data = package(
        model(
            f'<object id="2" type="model">{mesh_xml(*box(1.0, 2.0, 3.0))}</object>'
            f'<object id="1" type="model"><components><component objectid="2" '
            f'transform="{rows} 0 0 1 10 0 0"/></components></object>',
            '<item objectid="1"/>',
        )
    )
    doc = analyze(data, filename="r.3mf", options=AnalysisOptions(units="m", density=1.0)).as_dict()
    # placed rigidly: the box's own volume and moments (as written it would be 6 x 1.000000923538)
    assert doc["mass"] == pytest.approx(6.0, rel=1e-14)
    moments = sorted(doc["principal"]["moments"])
    np.testing.assert_allclose(moments, [6 * (1 + 4) / 12, 6 * (1 + 9) / 12, 6 * (4 + 9) / 12], rtol=1e-13)
    # the centre (0.5, 1, 1.5) of the box, carried by the rotation c/r, s/r (r = sqrt(c^2 + s^2)) as a row vector
    r = math.hypot(c, s)
    x, y = 0.5, 1.0
    centre = [x * c / r + y * s / r, x * s / r - y * c / r] if mirror else [x * c / r - y * s / r, x * s / r + y * c / r]
    np.testing.assert_allclose(doc["center_of_mass"], [10 + centre[0], centre[1], 1.5], rtol=1e-14, atol=1e-14)
    notes = [w for w in doc["warnings"] if "rotations written to few digits" in w]
    assert len(notes) == 1 and "up to 9.2e-07 from orthonormal" in notes[0]
    assert "change a piece's volume by up to 9.2e-07 of it" in notes[0]  # 1.000000923538 - 1
    assert not any("winding" in w for w in doc["warnings"])
    # as written (lib3mf applies the matrix as it stands) the volume is 1.000000923538 times larger: the estimate
    # covers the difference between the two readings
    assert doc["diagnostics"]["relative_error_estimate"] >= 0.000000923538


def test_3mf_real_scale_is_applied_as_written() -> None:
    # a uniform scale of 1.001 is 2e-3 from orthonormal: a scale, not a rounded rotation
    data = package(
        model(
            f'<object id="1" type="model">{mesh_xml(*box(1.0, 2.0, 3.0))}</object>',
            '<item objectid="1" transform="1.001 0 0 0 1.001 0 0 0 1.001 0 0 0"/>',
        )
    )
    doc = analyze(data, filename="s.3mf", options=AnalysisOptions(units="m", density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(6.0 * 1.001**3, rel=1e-14)
    assert not any("rotations written" in w for w in doc["warnings"])


@pytest.mark.parametrize(
    "resources, build, words",
    [
        ('<object id="1" type="other">{m}</object>', '<item objectid="1"/>', "type 'other'"),
        ('<object id="1" type="model">{m}</object><object id="1" type="model">{m}</object>', '<item objectid="1"/>', "used twice"),
        ('<object id="1" type="model">{m}</object>', '<item objectid="2"/>', "does not define"),
        ('<object id="1" type="model">{m}</object>', '<item objectid="1" transform="1 0 0 0 1 0 0 0 0 0 0 0"/>', "singular"),
        ('<object id="1" type="model">{m}</object>', '<item objectid="1" transform="1 0 0"/>', "12"),
        ('<object id="1" type="shiny">{m}</object>', '<item objectid="1"/>', "type 'shiny'"),
        ('<object id="1" type="model" pindex="0">{m}</object>', '<item objectid="1"/>', "pindex but no pid"),
        ('<object id="1" type="model" pid="5" pindex="0">{m}</object>', '<item objectid="1"/>', "property group 5"),
        (
            '<object id="1" type="model"><components><component objectid="2"/></components></object>{o2}',
            '<item objectid="1"/>',
            "not defined before it",
        ),
    ],
)
def test_3mf_must_fail_rules(resources: str, build: str, words: str) -> None:
    m = mesh_xml(*cube(1.0))
    data = package(model(resources.format(m=m, o2=f'<object id="2" type="model">{m}</object>'), build))
    with pytest.raises(UnreadableFileError) as err:
        analyze(data, filename="bad.3mf")
    assert words in err.value.message and "3MF" in err.value.message


MAT = "http://schemas.microsoft.com/3dmanufacturing/material/2015/02"
BEAM = "http://schemas.microsoft.com/3dmanufacturing/beamlattice/2017/02"


def test_3mf_property_entries_without_their_prefix_are_named() -> None:
    # lib3mf's multiprop-opaque.3mf: <multi> written in the core namespace, so the group counts no entries
    m = mesh_xml(*cube(1.0))
    group = (
        '<m:colorgroup id="5"><m:color color="#FF0000"/></m:colorgroup>'
        '<m:multiproperties id="6" pids="5"><multi pindices="0"/></m:multiproperties>'
    )
    data = package(model(f'{group}<object id="1" type="model">{m}</object>', '<item objectid="1"/>', ns=f' xmlns:m="{MAT}"'))
    with pytest.raises(UnreadableFileError, match="<multi> elements of resource 6 are in the namespace"):
        analyze(data, filename="multi.3mf")


def test_3mf_beam_lattice_is_named_before_its_open_clipping_mesh() -> None:
    # lib3mf's Box_Attributes_Positive.3mf: an open mesh (the lattice's clipping mesh) before the lattice object
    v, f = cube(1.0)
    lattice = (
        f'<object id="2" type="model"><mesh>{mesh_xml(v, f)[6:-7]}<b:beamlattice minlength="0.1" radius="0.1" '
        'clippingmode="inside" clippingmesh="1"><b:beams/></b:beamlattice></mesh></object>'
    )
    data = package(
        model(
            f'<object id="1" type="model">{mesh_xml(v, f[:-1])}</object>{lattice}',
            '<item objectid="2"/>',
            ns=f' xmlns:b="{BEAM}"',
        )
    )
    with pytest.raises(UnsupportedFormatError, match="carries a beam lattice"):
        analyze(data, filename="lattice.3mf")


def test_3mf_open_model_object_is_refused_by_the_specification() -> None:
    v, f = cube(1.0)
    data = package(model(f'<object id="1" type="model" name="lid">{mesh_xml(v, f[:-1])}</object>', '<item objectid="1"/>'))
    with pytest.raises(NotWatertightError) as err:
        analyze(data, filename="open.3mf")
    assert "'lid'" in err.value.message and "chapter 4.1" in err.value.message


def test_3mf_relationship_to_an_outside_file_is_refused() -> None:
    m = model(f'<object id="1" type="model">{mesh_xml(*cube(1.0))}</object>', '<item objectid="1"/>')
    extra = (
        '<Relationship Target="C:/secret/thumb.png" Id="r9" '
        'Type="http://schemas.openxmlformats.org/package/2006/relationships/metadata/thumbnail"/>'
    )
    with pytest.raises(UnreadableFileError) as err:
        analyze(package(m, extra), filename="ext.3mf")
    assert "outside the package" in err.value.message


def test_3mf_with_only_supports_is_empty() -> None:
    data = package(model(f'<object id="1" type="support">{mesh_xml(*cube(1.0))}</object>', '<item objectid="1"/>'))
    with pytest.raises(EmptyGeometryError):
        analyze(data, filename="s.3mf")


def test_3mf_beam_lattice_required_is_unsupported() -> None:
    beam = "http://schemas.microsoft.com/3dmanufacturing/beamlattice/2017/02"
    data = package(
        model(
            f'<object id="1" type="model">{mesh_xml(*cube(1.0))}</object>',
            '<item objectid="1"/>',
            ns=f' xmlns:b="{beam}" requiredextensions="b"',
        )
    )
    with pytest.raises(UnsupportedFormatError):
        analyze(data, filename="b.3mf")


# --- glTF ----------------------------------------------------------------------------------------------


def gltf_box_doc() -> dict[str, Any]:
    data = trimesh.Scene(trimesh.Trimesh(*box(1.0, 2.0, 3.0), process=False)).export(file_type="gltf", embed_buffers=True)
    return cast("dict[str, Any]", json.loads(data["model.gltf"]))


_INSTANCES = (
    np.array([[10, 0, 0], [0, 5, 0]], dtype="<f4").tobytes()  # TRANSLATION
    + np.array([[0, 0, 0, 32767], [0, 0, 23170, 23170]], dtype="<i2").tobytes()  # ROTATION, normalized int16
    + np.array([[1, 1, 1], [2, 2, 2]], dtype="<f4").tobytes()  # SCALE
)


def _with_instances(doc: dict[str, Any], node_translation: list[float], buffer: int | None = None, at: int = 0) -> bytes:
    """The box drawn by EXT_mesh_gpu_instancing twice: at T (10, 0, 0); and turned 90 degrees about z (a quaternion
    in normalized int16, as glTF-Transform writes it), scaled by 2 and moved by (0, 5, 0); the node itself moved.
    The instance data in a new buffer (a data URI), or in ``buffer`` from byte ``at``."""
    if buffer is None:
        uri = "data:application/octet-stream;base64," + base64.b64encode(_INSTANCES).decode()
        doc["buffers"].append({"byteLength": len(_INSTANCES), "uri": uri})
        buffer = len(doc["buffers"]) - 1
    first_view = len(doc["bufferViews"])
    doc["bufferViews"] += [
        {"buffer": buffer, "byteOffset": at, "byteLength": 24},
        {"buffer": buffer, "byteOffset": at + 24, "byteLength": 16},
        {"buffer": buffer, "byteOffset": at + 40, "byteLength": 24},
    ]
    first = len(doc["accessors"])
    doc["accessors"] += [
        {"bufferView": first_view, "componentType": 5126, "count": 2, "type": "VEC3"},
        {"bufferView": first_view + 1, "componentType": 5122, "normalized": True, "count": 2, "type": "VEC4"},
        {"bufferView": first_view + 2, "componentType": 5126, "count": 2, "type": "VEC3"},
    ]
    doc["extensionsUsed"] = ["EXT_mesh_gpu_instancing"]
    node = next(n for n in doc["nodes"] if "mesh" in n)
    node["translation"] = node_translation
    node["extensions"] = {
        "EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": first, "ROTATION": first + 1, "SCALE": first + 2}}
    }
    return json.dumps(doc).encode()


def test_gltf_instances_are_each_weighed_where_they_are_drawn() -> None:
    # the 1 x 2 x 3 box (centre (0.5, 1, 1.5), volume 6) at (10, 0, 0): centre (10.5, 1, 1.5); scaled by 2 (volume
    # 48, centre (1, 2, 3)), turned by 90 degrees about z ((x, y) -> (-y, x): (-2, 1, 3)) and moved by (0, 5, 0):
    # (-2, 6, 3); then both by the node's (0, 0, 100). The instances alone are drawn, not the node's own mesh.
    data = _with_instances(gltf_box_doc(), [0.0, 0.0, 100.0])
    doc = analyze(data, filename="instanced.gltf", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(54.0, rel=1e-12)
    expected = (6 * np.array([10.5, 1, 101.5]) + 48 * np.array([-2, 6, 103])) / 54
    np.testing.assert_allclose(doc["center_of_mass"], expected, rtol=1e-12)
    assert any("2 instance(s) of 1 mesh node(s) placed by EXT_mesh_gpu_instancing" in w for w in doc["warnings"])


def test_an_open_instance_is_refused_by_its_node_and_number() -> None:
    doc = gltf_box_doc()
    primitive = doc["meshes"][0]["primitives"][0]
    doc["accessors"][primitive["indices"]]["count"] -= 3  # the box without its last triangle
    node = next(n for n in doc["nodes"] if "mesh" in n)
    node["name"] = "crate"
    data = _with_instances(doc, [0.0, 0.0, 100.0])
    with pytest.raises(NotWatertightError, match="part 'crate instance 0' is not watertight"):
        analyze(data, filename="instanced.gltf", options=AnalysisOptions(density=1.0))


def test_glb_instances_are_read_from_its_binary_chunk() -> None:
    glb = trimesh.Scene(trimesh.Trimesh(*box(1.0, 2.0, 3.0), process=False)).export(file_type="glb")
    json_length = int.from_bytes(glb[12:16], "little")
    doc = json.loads(glb[20 : 20 + json_length])
    binary = glb[20 + json_length + 8 :]
    binary += b"\0" * (-len(binary) % 4)
    doc["buffers"][0]["byteLength"] = len(binary) + len(_INSTANCES)
    text = _with_instances(doc, [0.0, 0.0, 100.0], buffer=0, at=len(binary))
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(binary) + len(_INSTANCES), 0x004E4942)
    data = struct.pack("<4sII", b"glTF", 2, 12 + len(chunks) + len(binary) + len(_INSTANCES)) + chunks + binary + _INSTANCES
    doc_out = analyze(data, filename="instanced.glb", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc_out["mass"] == pytest.approx(54.0, rel=1e-12)
    expected = (6 * np.array([10.5, 1, 101.5]) + 48 * np.array([-2, 6, 103])) / 54
    np.testing.assert_allclose(doc_out["center_of_mass"], expected, rtol=1e-12)


def test_gltf_positions_without_a_buffer_view_are_zeros_and_said_so() -> None:
    doc = gltf_box_doc()
    doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]].pop("bufferView")
    with pytest.raises(EmptyGeometryError, match="positions without a buffer view, which glTF reads as all zero"):
        analyze(json.dumps(doc).encode(), filename="zeros.gltf")


def test_gltf_without_a_scene_places_nothing() -> None:
    doc = gltf_box_doc()
    doc.pop("scenes")
    doc.pop("scene", None)
    with pytest.raises(EmptyGeometryError, match="has no scene, so its meshes are placed nowhere"):
        analyze(json.dumps(doc).encode(), filename="library.gltf")


def test_gltf_mirrored_node_is_read_outward() -> None:
    doc = gltf_box_doc()
    for node in doc["nodes"]:
        if "mesh" in node:
            node["scale"] = [-1.0, 1.0, 1.0]
            node.pop("matrix", None)
    res = analyze(json.dumps(doc).encode(), filename="mirror.gltf").as_dict()
    assert res["mass"] == pytest.approx(6000, rel=1e-14)
    assert not any("winding" in w for w in res["warnings"])


def _mesh_node(doc: dict[str, Any]) -> dict[str, Any]:
    node = next(n for n in doc["nodes"] if "mesh" in n)
    node.pop("matrix", None)
    return cast("dict[str, Any]", node)


@pytest.mark.parametrize("scale", [1.000004, 1 + 2e-9, 0.9999999])
def test_gltf_node_scale_near_one_is_applied(scale: float) -> None:
    # trimesh's scene graph snaps a world matrix within 1e-5 of a rotation to that rotation and drops one
    # within 1e-8 of the identity; glTF applies the scale: the 1 x 2 x 3 box's volume is 6 s^3
    doc = gltf_box_doc()
    _mesh_node(doc)["scale"] = [scale, scale, scale]
    res = analyze(json.dumps(doc).encode(), filename="scaled.gltf", options=AnalysisOptions(density=1.0)).as_dict()
    assert res["mass"] == pytest.approx(6 * scale**3, rel=1e-14)
    np.testing.assert_allclose(res["center_of_mass"], np.array([0.5, 1.0, 1.5]) * scale, rtol=1e-14)


def test_gltf_camera_nodes_keep_their_meshes_and_children() -> None:
    # a camera on the node that holds the box, and on a parent moving a second box by (10, 0, 0): glTF places
    # both (a node may hold a camera, a mesh and children); trimesh's reader skips a camera node and its subtree
    doc = gltf_box_doc()
    node = _mesh_node(doc)
    node["camera"] = 0
    doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}]
    doc["nodes"].append({"camera": 0, "translation": [10.0, 0.0, 0.0], "children": [len(doc["nodes"]) + 1]})
    doc["nodes"].append({"mesh": node["mesh"]})
    doc["scenes"][doc.get("scene", 0)]["nodes"].append(len(doc["nodes"]) - 2)
    res = analyze(json.dumps(doc).encode(), filename="cameras.gltf", options=AnalysisOptions(density=1.0)).as_dict()
    assert res["mass"] == pytest.approx(12.0, rel=1e-14)
    np.testing.assert_allclose(res["center_of_mass"], [5.5, 1.0, 1.5], rtol=1e-14)


def _with_morph_target(doc: dict[str, Any]) -> None:
    """A morph target on the box that moves every corner by (0, 0, 1): weighed, the box moves by w."""
    prim = doc["meshes"][0]["primitives"][0]
    count = doc["accessors"][prim["attributes"]["POSITION"]]["count"]
    moved = np.tile(np.array([0.0, 0.0, 1.0], dtype="<f4"), (count, 1)).tobytes()
    doc["buffers"].append(
        {"byteLength": len(moved), "uri": "data:application/octet-stream;base64," + base64.b64encode(moved).decode()}
    )
    doc["bufferViews"].append({"buffer": len(doc["buffers"]) - 1, "byteLength": len(moved)})
    doc["accessors"].append(
        {
            "bufferView": len(doc["bufferViews"]) - 1,
            "componentType": 5126,
            "count": count,
            "type": "VEC3",
            "min": [0.0, 0.0, 1.0],
            "max": [0.0, 0.0, 1.0],
        }
    )
    prim["targets"] = [{"POSITION": len(doc["accessors"]) - 1}]


def test_gltf_node_morph_weights_override_the_meshes() -> None:
    # glTF 2.0 section 3.7.2.2: a node's weights, where given, replace its mesh's
    doc = gltf_box_doc()
    _with_morph_target(doc)
    _mesh_node(doc)["weights"] = [1.0]
    with pytest.raises(UnsupportedFormatError, match="morph-target weights"):
        analyze(json.dumps(doc).encode(), filename="morphed.gltf")
    doc["meshes"][0]["weights"] = [1.0]
    _mesh_node(doc)["weights"] = [0.0]  # the node draws the stored positions
    res = analyze(json.dumps(doc).encode(), filename="rest.gltf", options=AnalysisOptions(density=1.0)).as_dict()
    assert res["mass"] == pytest.approx(6.0, rel=1e-14)
    np.testing.assert_allclose(res["center_of_mass"], [0.5, 1.0, 1.5], rtol=1e-14)


def _draco_without_fallback(doc: dict[str, Any]) -> None:
    """Draco used but not required, and no uncompressed positions: read without it, every corner is at 0."""
    doc["extensionsUsed"] = ["KHR_draco_mesh_compression"]
    prim = doc["meshes"][0]["primitives"][0]
    doc["meshes"][0]["name"] = "box"
    prim["extensions"] = {"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}}
    doc["accessors"][prim["attributes"]["POSITION"]].pop("bufferView")


@pytest.mark.parametrize(
    "change, words",
    [
        (lambda d: d["accessors"][d["meshes"][0]["primitives"][0]["attributes"]["POSITION"]].update(sparse={"count": 1}), "sparse"),
        (lambda d: d.update(extensionsRequired=["KHR_draco_mesh_compression"]), "(Draco mesh compression)"),
        (lambda d: d.update(extensionsRequired=["ACME_gizmo"]), "ACME_gizmo, which this service does not decode;"),
        (_draco_without_fallback, "mesh 'box' only with KHR_draco_mesh_compression"),
        (lambda d: d["meshes"][0].update(weights=[0.5]), "morph"),
        (lambda d: [n.update(skin=0) for n in d["nodes"] if "mesh" in n], "skinned"),
    ],
)
def test_gltf_geometry_trimesh_would_misread_is_refused(change: Callable[[dict[str, Any]], object], words: str) -> None:
    doc = gltf_box_doc()
    change(doc)
    with pytest.raises(UnsupportedFormatError) as err:
        analyze(json.dumps(doc).encode(), filename="x.gltf")
    assert words in err.value.message


def test_gltf_infinite_positions_are_counted_as_stored_under_a_placement() -> None:
    # assimp's BoxWithInfinites: infinite x coordinates under a node matrix, where inf x 0 made NaN (and numpy
    # warned on stderr, before the JSON error); the refusal counts what the file stores
    doc = gltf_box_doc()
    prim = doc["meshes"][0]["primitives"][0]
    acc = doc["accessors"][prim["attributes"]["POSITION"]]
    view = doc["bufferViews"][acc["bufferView"]]
    buf = doc["buffers"][view["buffer"]]
    raw = bytearray(base64.b64decode(buf["uri"].split(",", 1)[1]))
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    positions = np.frombuffer(raw, dtype="<f4", count=3 * acc["count"], offset=start).reshape(-1, 3).copy()
    positions[:2, 0] = np.inf
    raw[start : start + positions.nbytes] = positions.tobytes()
    buf["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bytes(raw)).decode()
    _mesh_node(doc)["matrix"] = [0, 0, -1, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1]  # a quarter turn about y
    with pytest.raises(InvalidParameterError, match="contain 2 non-finite value"):
        analyze(json.dumps(doc).encode(), filename="infinite.gltf")


def _two_parents(doc: dict[str, Any]) -> None:
    # the mesh node under the scene's root and under a second root moved 5 m: one of its places was dropped
    doc["nodes"] += [{"children": [0]}, {"children": [0], "translation": [5.0, 0.0, 0.0]}]
    doc["scenes"][0]["nodes"] = [1, 2]


def _root_and_child(doc: dict[str, Any]) -> None:
    doc["nodes"].append({"children": [0], "translation": [5.0, 0.0, 0.0]})
    doc["scenes"][0]["nodes"] = [0, 1]


def _cycle(doc: dict[str, Any]) -> None:
    doc["nodes"] += [{"children": [2]}, {"children": [1, 0]}, {}]  # 1 -> 2 -> 1, the mesh node under 2
    doc["scenes"][0]["nodes"] = [3]


@pytest.mark.parametrize(
    "change, words",
    [
        (_two_parents, "node 0 is a child of nodes 1 and 2"),
        (_root_and_child, "node 0 is a root of scene 0 and a child of node 1"),
        (_cycle, "has a cycle"),
    ],
)
def test_gltf_node_hierarchy_that_is_not_trees_is_refused(change: Callable[[dict[str, Any]], None], words: str) -> None:
    # glTF 2.0 section 3.5.2: the node hierarchy is a set of disjoint strict trees
    doc = gltf_box_doc()
    change(doc)
    with pytest.raises(UnreadableFileError, match=words):
        analyze(json.dumps(doc).encode(), filename="graph.gltf")


def _primitives_as_object(doc: dict[str, Any]) -> None:
    doc["meshes"][0]["primitives"] = doc["meshes"][0]["primitives"][0]  # assimp's wrongTypes/badArray.gltf


def _view_past_buffer(doc: dict[str, Any]) -> None:
    doc["bufferViews"][0]["byteLength"] = 5000  # assimp's IncorrectVertexArrays/Cube.gltf: views past the buffer


def _accessor_past_buffer(doc: dict[str, Any]) -> None:
    doc["accessors"][0]["count"] = 5000


def _view_before_buffer(doc: dict[str, Any]) -> None:
    doc["bufferViews"][0]["byteOffset"] = -1  # before the buffer's first byte: numpy's error was all one read


def _fractional_offset(doc: dict[str, Any]) -> None:
    doc["accessors"][0]["byteOffset"] = 0.5  # the schema's integer; int() made it 0


@pytest.mark.parametrize(
    "change, words",
    [
        (_primitives_as_object, r"mesh 0 has no array of primitives \(meshes\[0\]\.primitives"),
        (_view_past_buffer, r"buffer view 0 runs past the end of buffer 0 \(bytes 0 to 5000 of its 144\)"),
        (_accessor_past_buffer, r"accessor 0 runs past its buffer \(mesh 0\)"),
        (_view_before_buffer, r"bufferViews\[0\]\.byteOffset is not a whole number >= 0"),
        (_fractional_offset, r"accessors\[0\]\.byteOffset is not a whole number >= 0"),
    ],
)
def test_a_gltf_file_trimesh_cannot_read_has_its_fault_named(change: Callable[[dict[str, Any]], None], words: str) -> None:
    # these were all "a value of the wrong kind or count"
    doc = gltf_box_doc()
    change(doc)
    with pytest.raises(UnreadableFileError, match=words):
        analyze(json.dumps(doc).encode(), filename="broken.gltf")


@pytest.mark.parametrize(
    ("path", "value", "words"),
    [
        (("accessors",), True, "accessors is not an array of objects"),
        (("accessors", 0, "count"), True, r"accessors\[0\]\.count is not a whole number >= 0"),
        (("accessors", 0, "type"), ["VEC3"], r"accessors\[0\]\.type is not a string"),
        (("bufferViews", 0, "buffer"), {"0": 0}, r"bufferViews\[0\]\.buffer is not a whole number >= 0"),
        (("meshes", 0, "primitives", 0, "attributes"), True, r"primitives\[0\]\.attributes is not an object"),
        (("nodes",), [{"children": [-1]}], r"nodes\[0\]\.children is not an array of whole numbers >= 0"),
    ],
)
def test_a_gltf_document_of_the_wrong_shape_is_refused_by_its_path(path: tuple[Any, ...], value: Any, words: str) -> None:
    # each was one reader's own TypeError ("object of type 'bool' has no len()", "unhashable type: 'list'")
    doc = gltf_box_doc()
    target: Any = doc
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    with pytest.raises(UnreadableFileError, match=words + ", as the glTF 2.0 schema requires"):
        analyze(json.dumps(doc).encode(), filename="shape.gltf")


def _box_indices(doc: dict[str, Any]) -> tuple[dict[str, Any], np.ndarray]:
    """The box's index accessor and its values."""
    acc = doc["accessors"][doc["meshes"][0]["primitives"][0]["indices"]]
    view = doc["bufferViews"][acc["bufferView"]]
    raw = base64.b64decode(doc["buffers"][view["buffer"]]["uri"].split(",", 1)[1])
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    return acc, np.frombuffer(raw, dtype="<u4", count=acc["count"], offset=start).copy()


def _with_indices(doc: dict[str, Any], values: np.ndarray, component: int) -> None:
    """The box's triangles indexed by ``values`` of ``component`` type, in a new buffer."""
    acc, _ = _box_indices(doc)
    raw = values.astype({5121: "<u1", 5123: "<u2", 5125: "<u4"}[component]).tobytes()
    raw += b"\0" * (-len(raw) % 4)
    doc["buffers"].append({"byteLength": len(raw), "uri": "data:application/octet-stream;base64," + base64.b64encode(raw).decode()})
    doc["bufferViews"].append({"buffer": len(doc["buffers"]) - 1, "byteLength": len(raw)})
    acc.update(bufferView=len(doc["bufferViews"]) - 1, componentType=component, count=len(values), byteOffset=0)
    acc.pop("max", None)
    acc.pop("min", None)


def test_gltf_node_transforms_glTF_does_not_define_are_refused() -> None:
    # glTF 2.0 section 5.25: a node has a matrix or translation/rotation/scale, and its matrix is affine
    doc = gltf_box_doc()
    node = _mesh_node(doc)
    node["matrix"] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1]
    node["translation"] = [-5.0, 0.0, 0.0]
    with pytest.raises(UnreadableFileError, match="node 0 has both a matrix and translation"):
        analyze(json.dumps(doc).encode(), filename="both.gltf")
    node["matrix"] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.5, 0, 0, 0, 1]
    del node["translation"]
    with pytest.raises(UnreadableFileError, match=r"last row is \[0.0, 0.0, 0.5, 1.0\]"):
        analyze(json.dumps(doc).encode(), filename="projective.gltf")
    node["matrix"] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]  # the identity beside TRS: TRS alone places it
    node["translation"] = [-5.0, 0.0, 0.0]
    res = analyze(json.dumps(doc).encode(), filename="identity.gltf", options=AnalysisOptions(density=1.0)).as_dict()
    np.testing.assert_allclose(res["center_of_mass"], [-4.5, 1.0, 1.5], rtol=1e-14)


@pytest.mark.parametrize(
    "key, value", [("rotation", [10**400, 0, 0, 1]), ("matrix", [10**400] + [0] * 15), ("scale", [1, 1e999, 1])]
)
def test_gltf_node_transform_beyond_double_precision_is_refused(key: str, value: list[Any]) -> None:
    # an integer past 1e308 overflowed float() in the transform checks: a logged traceback and a vague message
    doc = gltf_box_doc()
    _mesh_node(doc)[key] = value
    with pytest.raises(InvalidParameterError, match=f"node 0 has a {key} holding a number that is not finite"):
        analyze(json.dumps(doc).encode(), filename="huge.gltf")


def test_gltf_rotation_that_is_not_a_unit_quaternion_is_named() -> None:
    doc = gltf_box_doc()
    _mesh_node(doc)["rotation"] = [0.0, 0.0, 2 * math.sin(math.pi / 4), 2 * math.cos(math.pi / 4)]  # 90 deg about z, x2
    res = analyze(json.dumps(doc).encode(), filename="q.gltf", options=AnalysisOptions(density=1.0)).as_dict()
    assert res["mass"] == pytest.approx(6.0, rel=1e-14)  # rotated, not scaled
    np.testing.assert_allclose(res["center_of_mass"], [-1.0, 0.5, 1.5], rtol=1e-14)
    assert any("rotation quaternion of length 2," in w for w in res["warnings"])


def test_gltf_node_scaled_to_zero_is_named() -> None:
    # glTF-Asset-Generator's case of a zero scale: it said "4 of its 4 triangles are stored twice" (a sheet)
    doc = gltf_box_doc()
    _mesh_node(doc)["scale"] = [1.0, 0.0, 1.0]
    with pytest.raises(ZeroVolumeError, match=r"node 0 has the scale \[1.0, 0.0, 1.0\], which flattens"):
        analyze(json.dumps(doc).encode(), filename="flat.gltf")
    doc = gltf_box_doc()
    doc["nodes"].append({"scale": [0.0, 0.0, 0.0], "camera": 0})  # a camera's node: nothing it places is weighed
    doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}]
    doc["scenes"][0]["nodes"].append(len(doc["nodes"]) - 1)
    assert analyze(json.dumps(doc).encode(), filename="cam.gltf", options=AnalysisOptions(density=1.0)).as_dict()[
        "mass"
    ] == pytest.approx(6.0)


@pytest.mark.parametrize("asset", [{"version": "3.0"}, {"version": "2.0", "minVersion": "2.1"}])
def test_gltf_of_another_version_than_2_is_refused(asset: dict[str, str]) -> None:
    doc = gltf_box_doc()
    doc["asset"] = asset
    with pytest.raises(UnsupportedFormatError, match=r"this service reads glTF 2\.0"):
        analyze(json.dumps(doc).encode(), filename="v.gltf")


def test_gltf_primitive_without_positions_is_left_out_with_a_note() -> None:
    # POSITION is optional (section 3.7.2.1): viewers skip such a primitive; trimesh refused the whole file
    doc = gltf_box_doc()
    doc["meshes"][0]["primitives"].append({"attributes": {}, "mode": 4})
    res = analyze(json.dumps(doc).encode(), filename="p.gltf", options=AnalysisOptions(density=1.0)).as_dict()
    assert res["mass"] == pytest.approx(6.0, rel=1e-14)
    assert any("1 primitive(s) of the glTF file have no positions" in w for w in res["warnings"])


@pytest.mark.parametrize("component, restart", [(5121, 255), (5123, 65535)])
def test_gltf_primitive_restart_index_is_refused(component: int, restart: int) -> None:
    # glTF-Asset-Generator's Negative/Mesh_PrimitiveRestart: WebGL 2 viewers drop the triangles using the value
    doc = gltf_box_doc()
    _, values = _box_indices(doc)
    values[-1] = restart
    _with_indices(doc, values, component)
    with pytest.raises(UnreadableFileError, match=f"has the index {restart}, the primitive restart value"):
        analyze(json.dumps(doc).encode(), filename="restart.gltf")


def test_gltf_triangle_list_with_a_partial_triangle_drops_it_with_a_note() -> None:
    doc = gltf_box_doc()
    _, values = _box_indices(doc)
    _with_indices(doc, np.concatenate([values, [0, 1]]), 5123)  # 38 indices
    res = analyze(json.dumps(doc).encode(), filename="partial.gltf", options=AnalysisOptions(density=1.0)).as_dict()
    assert res["mass"] == pytest.approx(6.0, rel=1e-14)
    assert any("lists 38 indices for its triangles" in w and "the last 2 were left out" in w for w in res["warnings"])


# glTF 2.0 section 3.7.2.1: a fan v0, v1, ..., vn is the triangles {v(i+1), v(i+2), v0}.  The unit right
# tetrahedron as one fan about the origin, [0, 2, 1, 3, 2], and the far face (1, 2, 3) as a triangle list.
_TETRA = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype="<f4")
_FAN = [0, 2, 1, 3, 2]


def _tetra_fan_doc(indexed: bool) -> tuple[dict[str, Any], bytes]:
    """The document and its one buffer's bytes: positions, then (indexed) the fan's and the triangle's indices."""
    if indexed:
        positions, fan_positions = _TETRA, _TETRA
        binary = _TETRA.tobytes() + np.array([*_FAN, 1, 2, 3], dtype="<u2").tobytes()
    else:  # the fan's own vertices in fan order, the triangle's after them
        fan_positions = _TETRA[_FAN]
        positions = _TETRA[[1, 2, 3]]
        binary = fan_positions.tobytes() + positions.tobytes()
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": fan_positions.nbytes}]
    accessors: list[dict[str, Any]] = [{"bufferView": 0, "componentType": 5126, "count": len(fan_positions), "type": "VEC3"}]
    if indexed:
        views.append({"buffer": 0, "byteOffset": 48, "byteLength": 16})
        accessors += [
            {"bufferView": 1, "componentType": 5123, "count": 5, "type": "SCALAR"},
            {"bufferView": 1, "byteOffset": 10, "componentType": 5123, "count": 3, "type": "SCALAR"},
        ]
        fan = {"attributes": {"POSITION": 0}, "indices": 1, "mode": 6}
        triangle = {"attributes": {"POSITION": 0}, "indices": 2}
    else:
        views.append({"buffer": 0, "byteOffset": fan_positions.nbytes, "byteLength": positions.nbytes})
        accessors.append({"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"})
        fan = {"attributes": {"POSITION": 0}, "mode": 6}
        triangle = {"attributes": {"POSITION": 1}}
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [fan, triangle]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(binary)}],
    }
    return doc, binary


def _glb_bytes(doc: dict[str, Any], binary: bytes) -> bytes:
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(binary), 0x004E4942) + binary
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


@pytest.mark.parametrize("container", ["gltf", "glb"])
@pytest.mark.parametrize("indexed", [True, False])
def test_gltf_triangle_fans_are_read(container: str, indexed: bool) -> None:
    doc, binary = _tetra_fan_doc(indexed)
    if container == "glb":
        data = _glb_bytes(doc, binary)
    else:
        doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(binary).decode()
        data = json.dumps(doc).encode()
    res = analyze(data, filename=f"tetra.{container}", options=AnalysisOptions(density=1.0)).as_dict()
    # the unit right tetrahedron: volume 1/6, centre (1/4, 1/4, 1/4); about the centre I_xx = 1/30 - 1/48 = 1/80 and
    # I_xy = -(1/120 - 1/96) = 1/480 (integrals of x^2 and xy over it: 1/60 and 1/120)
    assert res["mass"] == pytest.approx(1 / 6, rel=1e-14)
    np.testing.assert_allclose(res["center_of_mass"], [0.25, 0.25, 0.25], rtol=1e-14)
    expected = np.full((3, 3), 1 / 480) + np.eye(3) * (1 / 80 - 1 / 480)
    np.testing.assert_allclose(res["inertia_tensor"], expected, rtol=1e-13, atol=1e-17)


# --- several files in one upload -------------------------------------------------------------------------


def test_an_upload_of_two_models_is_refused_with_advice() -> None:
    v, f = box(1.0, 1.0, 1.0)
    with pytest.raises(UnsupportedFormatError) as err:
        load_body([("a.obj", obj_text(v, f)), ("b.obj", obj_text(v, f))])
    assert "2 model files" in err.value.message


def test_a_zip_holding_one_model_and_a_note_is_read() -> None:
    v, f = box(1.0, 2.0, 3.0)
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("part/box.obj", obj_text(v, f))
        zf.writestr("part/readme.txt", "hello")
    loaded = load_body(buf.getvalue(), filename="upload.zip")
    assert loaded.filename == "box.obj"
    assert analyze_loaded(loaded, AnalysisOptions()).as_dict()["mass"] == pytest.approx(6000, rel=1e-15)


def test_a_zip_slip_name_is_refused() -> None:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("../../evil.obj", b"v 0 0 0\n")
    with pytest.raises(UnreadableFileError):
        load_body(buf.getvalue(), filename="upload.zip")


def test_a_zip_needing_a_newer_extractor_is_unreadable_not_a_crash() -> None:
    data = bytearray((Path(__file__).parent / "data/real/3mf/box.3mf").read_bytes())
    at = data.index(b"PK\x01\x02")
    data[at + 6 : at + 8] = (999).to_bytes(2, "little")  # "version needed to extract" 99.9
    for name in ("box.3mf", "upload.zip"):
        with pytest.raises(UnreadableFileError):
            load_body(bytes(data), filename=name)


@pytest.mark.parametrize("encoding", ["utf-16-be", "utf-16-le", "utf-32-le", "utf-32-be"])
def test_an_obj_written_as_utf16_or_utf32_text_is_read(encoding: str) -> None:
    # Windows editors save "Unicode" text as UTF-16 with a byte-order mark (assimp's box_UTF16BE.obj)
    v, f = box(1.0, 2.0, 3.0)
    text = obj_text(v, f).decode("ascii")
    bom = {"utf-16-be": b"\xfe\xff", "utf-16-le": b"\xff\xfe", "utf-32-le": b"\xff\xfe\x00\x00", "utf-32-be": b"\x00\x00\xfe\xff"}
    res = analyze(bom[encoding] + text.encode(encoding), filename="box.obj", options=AnalysisOptions(density=1.0)).as_dict()
    assert res["mass"] == pytest.approx(6.0, rel=1e-14)


def test_an_obj_with_a_byte_order_mark_that_lies_is_refused() -> None:
    with pytest.raises(UnreadableFileError, match="UTF-16-BE byte-order mark"):
        analyze(b"\xfe\xff" + b"v 0 0", filename="box.obj")  # an odd number of bytes: no UTF-16 text


def test_gltf_1_is_named_as_such() -> None:
    doc = {"asset": {"version": "1.0"}, "meshes": {"box": {"primitives": []}}}
    with pytest.raises(UnsupportedFormatError, match=r"is glTF 1\.0"):
        analyze(json.dumps(doc).encode(), filename="old.gltf")
    glb = b"glTF" + (1).to_bytes(4, "little") + (20).to_bytes(4, "little") + (0).to_bytes(4, "little") * 2
    with pytest.raises(UnsupportedFormatError, match=r"binary glTF 1\.0"):
        analyze(glb, filename="old.glb")


def test_a_required_material_extension_does_not_refuse_the_geometry() -> None:
    doc = gltf_box_doc()
    doc["extensionsRequired"] = doc["extensionsUsed"] = ["KHR_techniques_webgl"]
    res = analyze(json.dumps(doc).encode(), filename="shaded.gltf", options=AnalysisOptions(density=1.0)).as_dict()
    assert res["mass"] == pytest.approx(6.0, rel=1e-14)


def test_non_manifold_edges_are_named_when_the_winding_cannot_be_made_consistent() -> None:
    # three tetrahedral cells around one axis, their shared walls kept: no open edge, but edges with three faces
    a, b, c, d, e = range(5)
    v = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0.5], [-0.5, 0.87, 0.5], [-0.5, -0.87, 0.5]], dtype=float)
    f = np.array([[a, b, c], [a, b, d], [a, b, e], [a, c, d], [b, c, d], [a, d, e], [b, d, e], [a, e, c], [b, e, c]])
    with pytest.raises(NotWatertightError, match="shared by more than two faces") as err:
        analyze((v, f))
    assert err.value.details["nonmanifold_edges"] == 7


@pytest.mark.parametrize("tail", [b"", b"o caf\xe9\n"], ids=["utf-8", "latin-1 name"])
def test_an_obj_with_a_utf8_byte_order_mark_keeps_its_first_vertex(tail: bytes) -> None:
    # with the mark left on the first line, "v 0 0 0" was not a vertex and every face pointed one vertex further
    text = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 0 0 3\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
    res = analyze(b"\xef\xbb\xbf" + text + tail, filename="tet.obj", options=AnalysisOptions(density=1.0)).as_dict()
    assert res["mass"] == pytest.approx(1 / 6, rel=1e-14)


@pytest.mark.parametrize("extensions", [5, True, [{}], "KHR_draco_mesh_compression"])
def test_gltf_primitive_extensions_of_the_wrong_type_are_not_a_crash(extensions: object) -> None:
    doc = gltf_box_doc()
    doc["meshes"][0]["primitives"][0]["extensions"] = extensions
    # trimesh's reader refuses such a file in its own words; our check before it must not fail first with a TypeError
    with pytest.raises(UnreadableFileError, match="does not follow the format"):
        analyze(json.dumps(doc).encode(), filename="odd.gltf")


def test_an_ascii_stl_with_a_utf8_byte_order_mark_is_read() -> None:
    data = trimesh.creation.box(extents=(1.0, 2.0, 3.0)).export(file_type="stl_ascii")
    text = data.encode() if isinstance(data, str) else data
    res = analyze(b"\xef\xbb\xbf" + text, filename="box.stl", options=AnalysisOptions(density=1.0)).as_dict()
    assert res["mass"] == pytest.approx(6.0, rel=1e-14)


# a 1 x 2 x 3 box, vertex x + 2y + 4z at (x, 2y, 3z), each face a quad wound outward
_BOX_CORNERS = [(x * 1.0, y * 2.0, z * 3.0) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
_BOX_QUADS = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]


@pytest.mark.parametrize("encoding", ["ascii", "binary_little_endian"])
def test_ply_triangle_strips_are_read(encoding: str) -> None:
    # Stanford's igea.ply keeps its 268,686 triangles as one tristrips element, which trimesh does not read: it
    # was refused as "only points or lines". Quad a b c d is the strip a b d c: (a, b, d), then (d, b, c) turned;
    # -1 starts the next strip; the second element joins two faces by a repeated vertex (a zero-area triangle)
    strips = [[v for q in _BOX_QUADS[:4] for v in (q[0], q[1], q[3], q[2], -1)]]
    q4, q5 = _BOX_QUADS[4], _BOX_QUADS[5]
    strips.append([q4[0], q4[1], q4[3], q4[2], q4[2], q5[0], q5[0], q5[1], q5[3], q5[2]])
    if encoding != "ascii":  # one element, as igea.ply has (trimesh reads binary lists of one length per element)
        strips = [strips[0] + strips[1]]
    head = ["ply", f"format {encoding} 1.0", "element vertex 8", "property double x", "property double y"]
    head += ["property double z", f"element tristrips {len(strips)}", "property list int int vertex_indices", "end_header"]
    text = ("\n".join(head) + "\n").encode()
    if encoding == "ascii":
        text += "".join(f"{x!r} {y!r} {z!r}\n" for x, y, z in _BOX_CORNERS).encode()
        text += "".join(" ".join(str(v) for v in [len(s), *s]) + "\n" for s in strips).encode()
    else:
        text += np.asarray(_BOX_CORNERS, dtype="<f8").tobytes()
        text += b"".join(np.asarray([len(s), *s], dtype="<i4").tobytes() for s in strips)
    doc = analyze(text, filename="strips.ply").as_dict()
    assert doc["mass"] / doc["density"] == pytest.approx(6.0, rel=1e-15)
    assert doc["center_of_mass"] == pytest.approx([0.5, 1.0, 1.5], rel=1e-15)
    assert doc["principal"]["moments"] == pytest.approx(sorted(6000 * (p + q) / 12 for p, q in ((4, 9), (1, 9), (1, 4))), rel=1e-14)
    assert not doc["warnings"]


@pytest.mark.parametrize(("encoding", "kind"), [("ascii", "float"), ("ascii", "double"), ("binary_little_endian", "float")])
def test_a_ply_files_coordinates_have_the_type_its_header_declares(encoding: str, kind: str) -> None:
    # the PLY specification's float is 4 bytes: its readers (trimesh, VCG/MeshLab, VTK) take a float property
    # as float32 in an ASCII file too, so "0.1" is the float32 0.100000001 there and 0.1 in a double property
    a = 0.1
    corners = [(0.0, 0.0, 0.0), (a, 0.0, 0.0), (0.0, a, 0.0), (0.0, 0.0, a)]
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    head = ["ply", f"format {encoding} 1.0", "element vertex 4", *(f"property {kind} {c}" for c in "xyz")]
    head += ["element face 4", "property list uchar int vertex_indices", "end_header"]
    text = ("\n".join(head) + "\n").encode()
    if encoding == "ascii":
        text += "".join(f"{x!r} {y!r} {z!r}\n" for x, y, z in corners).encode()
        text += "".join(f"3 {i} {j} {k}\n" for i, j, k in faces).encode()
    else:
        text += np.asarray(corners, dtype="<f4").tobytes()
        text += b"".join(struct.pack("<B3i", 3, *f) for f in faces)
    side = Fraction(a) if kind == "double" else Fraction(float(np.float32(a)))
    doc = analyze(text, filename="tetra.ply").as_dict()
    assert doc["mass"] == float(1000 * side**3 / 6)
    assert doc["center_of_mass"] == pytest.approx([float(side / 4)] * 3, rel=1e-15)


def test_a_flat_pillow_shell_far_from_the_origin_does_not_turn_a_body_into_a_cavity() -> None:
    # PrusaSlicer's extruder_idler_quads.obj: 92 pairs of back-to-back triangles (zero volume) whose determinants'
    # rounding, far from the local origin, exceeded eps x |det|; such a pair counted as a shell wound inward and
    # sent the file into nesting mode, where two small bodies inside the main one were subtracted as cavities
    outer, inner = cube(30.0, (50.0, 20.0, 15.0)), cube(5.0, (60.0, 30.0, 20.0))
    p = np.array([[72.92038, 25.986547, 27.487391], [72.940994, 25.984016, 27.524689], [72.865799, 25.99324, 27.388683]])
    pillow = (p, np.array([[0, 1, 2], [2, 1, 0]]))
    lines, n = [], 0
    for v, f in (outer, inner, pillow):
        lines += [f"v {x!r} {y!r} {z!r}" for x, y, z in np.asarray(v).tolist()]
        lines += [f"f {a + 1 + n} {b + 1 + n} {c + 1 + n}" for a, b, c in np.asarray(f).tolist()]
        n += len(v)
    doc = analyze("\n".join(lines).encode(), filename="nested.obj", options=AnalysisOptions(units="mm")).as_dict()
    assert doc["volume"] * 1e9 == pytest.approx(30.0**3 + 5.0**3, rel=1e-12)  # two bodies, both wound outward
    assert not any("winding corrected" in w for w in doc["warnings"])


def _prusa_config(kind: str) -> str:
    return (
        '<?xml version="1.0" encoding="UTF-8"?><config><object id="1" instances_count="1">'
        '<volume firstid="0" lastid="11"><metadata type="volume" key="volume_type" value="ModelPart"/></volume>'
        f'<volume firstid="12" lastid="23"><metadata type="volume" key="name" value="inner"/>{kind}</volume>'
        "</object></config>"
    )


@pytest.mark.parametrize(
    "kind",
    [
        '<metadata type="volume" key="volume_type" value="ParameterModifier"/>',
        '<metadata type="volume" key="volume_type" value="SupportBlocker"/>',
        '<metadata type="volume" key="modifier" value="1"/>',  # PrusaSlicer before volume_type
    ],
    ids=["modifier", "blocker", "old-modifier"],
)
def test_a_prusaslicer_modifier_volume_is_not_weighed(kind: str) -> None:
    # a 4 mm modifier cube inside a 10 mm part, in one mesh: PrusaSlicer prints 1000 mm^3; it weighed 1064
    v1, f1 = cube(10.0)
    v2, f2 = cube(4.0, (3.0, 3.0, 3.0))
    mesh = mesh_xml(np.concatenate([v1, v2]), np.concatenate([f1, f2 + len(v1)]))
    data = package(
        model(f'<object id="1" type="model" name="cube">{mesh}</object>', '<item objectid="1"/>'),
        parts={"Metadata/Slic3r_PE_model.config": _prusa_config(kind)},
    )
    doc = analyze(data, filename="p.3mf", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(1000 * 1e-9, rel=1e-14)
    assert any("inner (" in w and "not weighed" in w for w in doc["warnings"])


def test_a_prusaslicer_negative_volume_is_refused_not_weighed_as_material() -> None:
    v1, f1 = cube(10.0)
    v2, f2 = cube(4.0, (3.0, 3.0, 3.0))
    mesh = mesh_xml(np.concatenate([v1, v2]), np.concatenate([f1, f2 + len(v1)]))
    negative = '<metadata type="volume" key="volume_type" value="NegativeVolume"/>'
    data = package(
        model(f'<object id="1" type="model" name="cube">{mesh}</object>', '<item objectid="1"/>'),
        parts={"Metadata/Slic3r_PE_model.config": _prusa_config(negative)},
    )
    with pytest.raises(UnsupportedFormatError, match="negative volume"):
        analyze(data, filename="p.3mf")


def test_a_bambu_modifier_part_is_not_weighed() -> None:
    # Bambu Studio and OrcaSlicer make each volume a component and name its subtype in model_settings.config
    settings = (
        '<?xml version="1.0" encoding="UTF-8"?><config><object id="3"><metadata key="name" value="cube"/>'
        '<part id="1" subtype="normal_part"/><part id="2" subtype="modifier_part"><metadata key="name" value="inner"/>'
        "</part></object></config>"
    )
    data = package(
        model(
            f'<object id="1" type="model">{mesh_xml(*cube(10.0))}</object>'
            f'<object id="2" type="model">{mesh_xml(*cube(4.0, (3.0, 3.0, 3.0)))}</object>'
            '<object id="3" type="model" name="cube"><components><component objectid="1"/><component objectid="2"/>'
            "</components></object>",
            '<item objectid="3"/>',
        ),
        parts={"Metadata/model_settings.config": settings},
    )
    doc = analyze(data, filename="b.3mf", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(1000 * 1e-9, rel=1e-14)
    assert any("inner (modifier)" in w for w in doc["warnings"])


@pytest.mark.parametrize(
    "offset, overlaps",
    [
        ((5.0, 0.0, 0.0), True),
        ((10.0, 0.0, 0.0), False),
        ((0.0, 0.0, 0.0), True),
        ((4.0, 3.0, 2.0), True),
        ((0.0, 10.0, 10.0), False),
    ],
    ids=["half", "touching", "same-place", "corner", "edge"],
)
def test_3mf_overlapping_components_are_named(offset: tuple[float, float, float], overlaps: bool) -> None:
    # the specification unites overlapping components (ch. 4.2); they are weighed each in full, so the overlap
    # (500 mm^3 of two 10 mm cubes half over each other) counted twice without a word
    data = package(
        model(
            f'<object id="1" type="model">{mesh_xml(*cube(10.0))}</object>'
            f'<object id="2" type="model">{mesh_xml(*cube(10.0, offset))}</object>'
            '<object id="3" type="model" name="pair"><components><component objectid="1"/><component objectid="2"/>'
            "</components></object>",
            '<item objectid="3"/>',
        )
    )
    doc = analyze(data, filename="o.3mf").as_dict()
    assert any("overlap" in w for w in doc["warnings"]) is overlaps
    # the overlap is not measured: the estimate does not claim the sum's rounding for the united solid
    assert (doc["diagnostics"]["relative_error_estimate"] == 1.0) is overlaps


@pytest.mark.parametrize(("order", "newline"), [("<", "\r"), (">", "\n"), ("<", "\r\n")])
def test_a_binary_ply_with_quads_and_triangles_is_read(order: str, newline: str) -> None:
    # draco's testdata/Box.ply (a Rhino export): binary faces of 4 and 3 corners, header lines ending in a bare
    # \r, and a material element after the faces; trimesh reads a binary list as if every row had the first
    # row's length ("PLY is unexpected length!") and the file was refused as unreadable
    encoding = "binary_little_endian" if order == "<" else "binary_big_endian"
    quads = [q for q in _BOX_QUADS if q != _BOX_QUADS[5]]
    last = _BOX_QUADS[5]
    faces: list[tuple[int, ...]] = [*quads, (last[0], last[1], last[2]), (last[0], last[2], last[3])]
    head = ["ply", f"format {encoding} 1.0", "comment Rhino-like", "element vertex 8", "property float x", "property float y"]
    head += ["property float z", f"element face {len(faces)}", "property list uchar int vertex_indices", "element material 1"]
    head += ["property uchar red", "property float shine", "end_header"]
    text = (newline.join(head) + newline).encode()
    text += np.asarray(_BOX_CORNERS, dtype=order + "f4").tobytes()
    text += b"".join(struct.pack(f"{order}B{len(f)}i", len(f), *f) for f in faces)
    text += struct.pack(f"{order}Bf", 200, 0.5)
    doc = analyze(text, filename="Box.ply").as_dict()
    assert doc["mass"] / doc["density"] == 6.0  # the 1 x 2 x 3 box, exact
    assert doc["center_of_mass"] == pytest.approx([0.5, 1.0, 1.5], rel=1e-15)
    assert doc["principal"]["moments"] == pytest.approx(sorted(6000 * (p + q) / 12 for p, q in ((4, 9), (1, 9), (1, 4))), rel=1e-14)


# the 1 x 2 x 3 box with a vertex (8) in the middle of its front top edge: the top and front faces are
# pentagons, the bottom two triangles; written quad first, the corner counts 4, 3, 5, 4, 4, 5, 3 fill exactly
# seven quads
_EDGE_BOX = [(0, 0, 0), (1, 0, 0), (1, 2, 0), (0, 2, 0), (0, 0, 3), (1, 0, 3), (1, 2, 3), (0, 2, 3), (0.5, 0, 3)]
_EDGE_BOX_FACES = [(3, 7, 6, 2), (0, 3, 2), (4, 8, 5, 6, 7), (0, 4, 7, 3), (1, 2, 6, 5), (0, 1, 5, 8, 4), (0, 2, 1)]


def _edge_box_ply(order: str, head: tuple[str, ...] = ()) -> bytes:
    encoding = "binary_little_endian" if order == "<" else "binary_big_endian"
    lines = ["ply", *head, f"format {encoding} 1.0", "element vertex 9", "property float x", "property float y"]
    lines += ["property float z", "element face 7", "property list uchar int vertex_indices", "end_header"]
    text = ("\n".join(lines) + "\n").encode() + np.asarray(_EDGE_BOX, dtype=order + "f4").tobytes()
    return text + b"".join(struct.pack(f"{order}B{len(f)}i", len(f), *f) for f in _EDGE_BOX_FACES)


@pytest.mark.parametrize("order", ["<", ">"])
@pytest.mark.parametrize(
    "head",
    [(), ("comment made by hand",), ("obj_info drawn by hand", "comment two lines"), ("comment end_header is near",)],
    ids=["plain", "comment-first", "obj-info-first", "end-header-in-comment"],
)
def test_a_binary_ply_trimesh_would_misread_is_read_as_written(order: str, head: tuple[str, ...]) -> None:
    # trimesh reads a binary face list as if every row had the first's length (these faces fill seven quads
    # exactly: the box came back open, or pointing at vertex 83886080), takes the byte order from the header's
    # second line (after a comment, a big-endian file was read byte-swapped: another closed box, another mass,
    # no word) and ends the header at any line naming end_header
    doc = analyze(_edge_box_ply(order, head), filename="edge.ply", options=AnalysisOptions(density=1.0)).as_dict()
    assert doc["mass"] == pytest.approx(6.0, rel=1e-15)
    assert doc["center_of_mass"] == pytest.approx([0.5, 1.0, 1.5], rel=1e-15)
    assert not [w for w in doc["warnings"] if "winding" in w]


def _ascii_box_ply(joins: Callable[[int], str], newline: str = "\n", kind: str = "float") -> bytes:
    """The 1 x 2 x 3 box as an ASCII PLY file whose numbers are joined by ``joins(k)`` (k: the gap's index)
    after the header: a space, a line break, or a blank line."""
    head = ["ply", "format ascii 1.0", "element vertex 8", *(f"property {kind} {c}" for c in "xyz")]
    head += [f"element face {len(_BOX_QUADS)}", "property list uchar int vertex_indices", "end_header"]
    words = [repr(v) for corner in _BOX_CORNERS for v in corner]
    words += [str(w) for quad in _BOX_QUADS for w in (len(quad), *quad)]
    body = words[0] + "".join(joins(k) + word for k, word in enumerate(words[1:]))
    return (newline.join(head) + newline + body.replace("\n", newline) + newline).encode()


def _row_ends() -> set[int]:
    """The gaps of ``_ascii_box_ply``'s numbers that end a row: a line break in a file of one row per line."""
    ends, at = set(), 0
    for width in [3] * len(_BOX_CORNERS) + [1 + len(q) for q in _BOX_QUADS]:
        at += width
        ends.add(at - 1)
    return ends


_ONE_ROW_PER_LINE = _ascii_box_ply(lambda k: "\n" if k in _row_ends() else " ")


@pytest.mark.parametrize(
    ("joins", "newline"),
    [
        (lambda k: "\n" if k in _row_ends() or k == 4 else " ", "\n"),  # a vertex row wrapped onto a second line
        (lambda k: "\n" if k in _row_ends() and k % 2 else " ", "\n"),  # rows two by two on one line
        (lambda k: "\n\n" if k == 40 else "\n" if k in _row_ends() else " ", "\n"),  # a blank line among the faces
        (lambda k: " ", "\r\n"),  # every number on one line
        (lambda k: "\n" if k % 5 == 0 else " ", "\r\n"),  # a line break every five numbers
    ],
    ids=["wrapped-row", "two-rows-a-line", "blank-line", "one-line", "every-five"],
)
def test_an_ascii_ply_is_read_as_numbers_whatever_its_lines(joins: Callable[[int], str], newline: str) -> None:
    # the format's ASCII data is numbers separated by white space (rply and VCG read words, not lines); trimesh
    # reads one row per line, so a wrapped row or a blank line shifted every row after it: the closed box was
    # refused as "not watertight (8 open edges)"
    data = _ascii_box_ply(joins, newline)
    doc = analyze(data, filename="box.ply").as_dict()
    assert doc["mass"] / doc["density"] == 6.0  # the 1 x 2 x 3 box, exact
    assert doc["center_of_mass"] == pytest.approx([0.5, 1.0, 1.5], rel=1e-15)
    assert doc["principal"]["moments"] == pytest.approx(sorted(6000 * (p + q) / 12 for p, q in ((4, 9), (1, 9), (1, 4))), rel=1e-14)
    # the same numbers a row per line: the same result, bit for bit
    regular = analyze(_ONE_ROW_PER_LINE, filename="box.ply").as_dict()
    for key in ("mass", "center_of_mass", "inertia_tensor", "principal", "warnings"):
        assert doc[key] == regular[key]


def _with_vertex_lists(data: bytes) -> bytes:
    """``data`` with a list of two texture coordinates after each vertex's z, and its first face row wrapped."""
    head, body = data.split(b"end_header\n")
    rows = body.decode().splitlines()
    rows = [r + " 2 0.25 0.75" for r in rows[:8]] + [rows[8].replace(" ", "\n", 2), *rows[9:]]
    head = head.replace(b"property float z\n", b"property float z\nproperty list uchar float uv\n")
    return head + b"end_header\n" + "\n".join(rows).encode() + b"\n"


@pytest.mark.parametrize(
    "variant",
    [
        lambda d: d.replace(b"end_header\n", b"end_header\n\n"),  # a blank line before the first row
        lambda d: d.replace(b"end_header\n", b"end_header\n \t \n"),  # a line of blanks there
        lambda d: d.replace(b"\n", b"\r"),  # every line ended by a bare CR, the header's too
        _with_vertex_lists,  # a list property among the vertices' scalars
        lambda d: d.replace(b"element vertex", b"element note 0\nelement vertex"),  # an empty element, no properties
    ],
    ids=["blank-first-line", "blanks-first-line", "cr-only", "vertex-lists", "empty-element"],
)
def test_ascii_ply_layouts_trimesh_misread_are_read(variant: Callable[[bytes], bytes]) -> None:
    doc = analyze(variant(_ONE_ROW_PER_LINE), filename="box.ply").as_dict()
    assert doc["mass"] / doc["density"] == 6.0  # the 1 x 2 x 3 box, exact
    assert doc["center_of_mass"] == pytest.approx([0.5, 1.0, 1.5], rel=1e-15)


def test_an_ascii_ply_face_corner_that_is_no_whole_number_is_refused() -> None:
    data = _ONE_ROW_PER_LINE[:-2] + b".5\n"  # the last corner of the last face: 7.5
    with pytest.raises(UnreadableFileError, match=r"has a face corner \d\.5, which is no vertex number"):
        analyze(data, filename="box.ply")


@settings(max_examples=25, deadline=None)
@given(st.lists(st.sampled_from([" ", "\n", " \n ", "\t", "\n\n"]), min_size=53, max_size=53))
def test_an_ascii_ply_gives_one_result_however_its_numbers_are_split(gaps: list[str]) -> None:
    data = _ascii_box_ply(lambda k: gaps[k])
    doc = analyze(data, filename="box.ply").as_dict()
    regular = analyze(_ONE_ROW_PER_LINE, filename="box.ply").as_dict()
    for key in ("mass", "center_of_mass", "inertia_tensor", "principal", "warnings"):
        assert doc[key] == regular[key]


def test_an_ascii_ply_integer_coordinate_with_a_fraction_is_refused_not_truncated() -> None:
    # rply (the reader of the PLY format's author's tools) refuses "2.5" in an int property; cast to the
    # declared int it would move the vertex to 2 and weigh another body, without a word
    data = _ascii_box_ply(lambda k: "\n" if k in _row_ends() else " ", kind="int")
    doc = analyze(data, filename="box.ply").as_dict()  # whole numbers in int properties: the 1 x 2 x 3 box
    assert doc["mass"] / doc["density"] == pytest.approx(6.0, rel=1e-15)
    with pytest.raises(UnreadableFileError, match=r"declares vertex property 'y' as an integer but has the value 2\.5"):
        analyze(data.replace(b" 2.0 ", b" 2.5 ", 1), filename="box.ply")


def test_an_ascii_ply_read_by_words_keeps_the_declared_float_type() -> None:
    # "0.1" in a float property is the float32 0.100000001 for every PLY reader, wrapped or not
    a = repr(0.1)
    data = _ascii_box_ply(lambda k: " ").replace(b" 2.0 ", f" {a} ".encode(), 1)
    vertices, _, _ = cast(Any, read_ascii_ply(data))
    assert vertices[2, 1] == float(np.float32(0.1)) != 0.1
    vertices, _, _ = cast(Any, read_ascii_ply(data.replace(b"property float", b"property double")))
    assert vertices[2, 1] == 0.1


@pytest.mark.parametrize("tail", [b" 7", b" x"], ids=["a-number-over", "a-word"])
def test_an_ascii_ply_whose_numbers_do_not_fill_its_elements_is_left_to_trimesh(tail: bytes) -> None:
    data = _ascii_box_ply(lambda k: " ").rstrip() + tail + b"\n"
    assert read_ascii_ply(data) is None
    with pytest.raises(ServiceError):  # trimesh's reading of it, as before: not a body
        analyze(data, filename="box.ply")


def test_an_ascii_ply_whose_rows_hold_more_than_declared_is_read_by_lines_with_a_note() -> None:
    # trimesh's fuze_ascii.ply (MIT): each face row has ten numbers after its colour where the header declares
    # four; its binary twin fuze.ply, with the same geometry, is the reference
    real = Path(__file__).parent / "data" / "real" / "ply"
    ascii_doc = analyze((real / "fuze_ascii.ply").read_bytes(), filename="fuze_ascii.ply").as_dict()
    binary_doc = analyze((real / "fuze.ply").read_bytes(), filename="fuze.ply").as_dict()
    assert ascii_doc["volume"] == binary_doc["volume"]
    assert ascii_doc["center_of_mass"] == binary_doc["center_of_mass"]
    assert any("its rows hold more values than declared); it was read one row per line" in w for w in ascii_doc["warnings"])
    assert not any("one row per line" in w for w in binary_doc["warnings"])


@pytest.mark.parametrize("cut", [1, 3, 25], ids=["last-number", "last-row-but-one-number", "five-rows"])
def test_a_truncated_ascii_ply_is_refused_not_weighed_as_far_as_it_goes(cut: int) -> None:
    # assimp's test/models-nonbsd/PLY/ant-half.ply declares 912 faces and ends after 259; read row by row, a
    # closed body cut after some faces gave the faces before the cut as the whole mesh (happly's
    # platonic_shelf cut after 26 of 50 faces: 6.71 instead of 9.76, no warning)
    ends = _row_ends()
    data = _ascii_box_ply(lambda k: "\n" if k in ends else " ")
    head, body = data.split(b"end_header\n")
    kept = body.split()[:-cut]  # the numbers before the cut, each row on its line as before
    lines, at = [], 0
    for width in [3] * 8 + [5] * 6:
        if at < len(kept):
            lines.append(b" ".join(kept[at : at + width]))
        at += width
    data = head + b"end_header\n" + b"\n".join(lines) + b"\n"
    whole = 6 - (cut + 4) // 5
    with pytest.raises(UnreadableFileError, match=rf"ends after {whole} of the 6 'face' rows its header declares: it is truncated"):
        analyze(data, filename="box.ply")


def test_an_ascii_ply_without_the_rows_of_an_element_after_its_faces_is_still_read() -> None:
    # an element the geometry does not need, declared after the faces but not written: trimesh's reading, as before
    data = _ONE_ROW_PER_LINE.replace(b"end_header", b"element material 1\nproperty uchar red\nend_header")
    doc = analyze(data, filename="box.ply").as_dict()
    assert doc["mass"] / doc["density"] == 6.0


def test_a_ply_header_with_a_type_no_reader_knows_is_refused_by_its_line() -> None:
    # pyntcloud's tests/data/diamond_with_bool.ply: "property bool is_green"; trimesh's KeyError had been
    # read as "an entry the format requires is missing ('bool')"
    data = _ONE_ROW_PER_LINE.replace(b"end_header", b"element flag 0\nproperty bool is_green\nend_header")
    with pytest.raises(
        UnreadableFileError, match=r"header line 'property bool is_green' gives the type 'bool', which is no PLY type"
    ):
        analyze(data, filename="diamond.ply")
    # the 64-bit types trimesh reads are no fault
    data = _ONE_ROW_PER_LINE.replace(b"end_header", b"element flag 0\nproperty int64 id\nend_header")
    assert analyze(data, filename="box.ply").as_dict()["mass"] == 6000.0


def test_a_ply_header_without_its_end_is_refused_in_a_sentence() -> None:
    # assimp's test/models/invalid/crash-30d6...ply: binary bytes inside a property line and no end_header; the
    # message had shown the bytes, "an entry the format requires is missing ('\\x00\\x00\\x00')"
    data = _ONE_ROW_PER_LINE.split(b"property float y")[0] + b"property \x00\x00\x00\x07\x00\x00\x00\x03"
    with pytest.raises(UnreadableFileError, match=r"^the PLY file's header has no 'end_header' line: the file is cut short"):
        analyze(data, filename="crash.ply")


def test_binary_ply_face_rows_are_checked_list_by_list() -> None:
    # a texture-coordinate list after the corners: rows of one length go to trimesh, rows of several to our walker
    head = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    head += b"element face 2\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\nend_header\n"
    body = np.zeros((4, 3), dtype="<f4").tobytes()
    row = struct.pack("<B3iB6f", 3, 0, 1, 2, 6, *range(6))
    assert uniform_face_rows(head + body + row + struct.pack("<B3iB6f", 3, 0, 2, 3, 6, *range(6)))
    assert not uniform_face_rows(head + body + row + struct.pack("<B3iB4f", 3, 0, 2, 3, 4, *range(4)) + b"\0" * 8)
    assert uniform_face_rows(b"ply\nformat ascii 1.0\nelement vertex 0\nend_header\n")


def test_a_signalling_nan_in_a_binary_ply_is_refused_without_a_word_on_stderr() -> None:
    # a corrupted copy of three.js's dolphins_le.ply: widening a float32 signalling NaN printed numpy's
    # "invalid value encountered in cast" before the error (warnings are errors in this suite)
    faces = [(0, 1, 2), (0, 2, 3, 1)]  # a triangle and a quad: trimesh fails, our own reader walks the rows
    head = ["ply", "format binary_little_endian 1.0", "element vertex 4", "property float x", "property float y"]
    head += ["property float z", f"element face {len(faces)}", "property list uchar int vertex_indices", "end_header"]
    corners = np.zeros((4, 3), dtype="<f4")
    corners.view("<u4")[1, 0] = 0x7FA00000  # a signalling NaN
    text = ("\n".join(head) + "\n").encode() + corners.tobytes()
    text += b"".join(struct.pack(f"<B{len(f)}i", len(f), *f) for f in faces)
    with pytest.raises(ServiceError) as info:
        analyze(text, filename="dolphins.ply")
    assert info.value.code == "invalid_parameter" and "non-finite" in info.value.message


@pytest.mark.parametrize(
    "head",
    [
        ["element vertex 1", "property float x", "property float x", "property float z"],  # a name twice
        ["element vertex 3"],  # no properties
        [
            "element vertex 1",
            "property float x",
            "property float y",
            "property float z",
            "element face 1",
            "property list uchar int vertex_indices",
        ],
    ],
    ids=["repeated-name", "no-properties", "truncated"],
)
def test_a_binary_ply_no_reader_can_walk_is_refused_in_a_sentence(head: list[str]) -> None:
    # the fallback reader gives up (None) and trimesh's own classified error stands, not a numpy ValueError
    from inertia.load.ply import read_binary_ply

    text = ("\n".join(["ply", "format binary_little_endian 1.0", *head, "end_header"]) + "\n").encode() + b"\x00" * 5
    assert read_binary_ply(text) is None
    with pytest.raises(ServiceError):
        analyze(text, filename="broken.ply")


def test_a_binary_stl_whose_size_disagrees_with_its_count_says_by_how_much() -> None:
    # a record's worth of bytes or more beyond the count, or fewer bytes than it: refused, with the sizes, so
    # that the extra bytes (or the missing ones) can be seen (trimesh refuses any difference)
    from tests.support.meshes import box_stl

    data = box_stl(1.0, 2.0, 3.0)
    with pytest.raises(UnreadableFileError, match=r"declares 12 triangles \(684 bytes\) but holds 734, 50 more"):
        load_body(data + b"\n" * 50, filename="box.stl")
    with pytest.raises(UnreadableFileError, match=r"declares 12 triangles \(684 bytes\) but holds 634: it is truncated"):
        load_body(data[:-50], filename="box.stl")
    # PyMesh's tests/data/empty.stl: a count of 0 and one stray newline, no triangle to read
    with pytest.raises(UnreadableFileError, match=r"declares 0 triangles \(84 bytes\) but holds 85, 1 more"):
        load_body(data[:80] + bytes(4) + b"\n", filename="empty.stl")


@pytest.mark.parametrize("header", [b"", b"solid test.stl, written as binary"], ids=["plain", "solid-header"])
@pytest.mark.parametrize("tail", [b"\n", b"\0" * 49], ids=["a-newline", "49-bytes"])
@pytest.mark.parametrize("source", ["bytes", "file"])
def test_a_binary_stl_with_fewer_bytes_than_a_record_after_its_triangles_is_read_with_a_warning(
    header: bytes, tail: bytes, source: str, tmp_path: Path
) -> None:
    # numpy-stl's own tests/stl_binary/HalfDonut.stl: a header beginning with "solid", 288 triangles and one byte
    # more; it was taken for ASCII and refused as "no triangles". numpy-stl reads it; fewer bytes than a record
    # cannot hold a triangle the count left out, so the triangles are read and the extra bytes named
    from tests.support.meshes import box_stl

    data = box_stl(1.0, 2.0, 3.0)
    data = header.ljust(80, b" ")[:80] + data[80:] + tail
    if source == "file":
        path = tmp_path / "box.stl"
        path.write_bytes(data)
        doc = analyze(str(path)).as_dict()
    else:
        doc = analyze(data, filename="box.stl").as_dict()
    assert doc["mass"] / doc["density"] == 6.0  # the 1 x 2 x 3 box, exact
    assert doc["center_of_mass"] == pytest.approx([0.5, 1.0, 1.5], rel=1e-15)
    assert [w for w in doc["warnings"] if "after its last triangle" in w] == [
        f"the binary STL file holds {len(tail)} byte(s) after its last triangle (its header declares 12 triangles, "
        "684 bytes), too few for another one; they were ignored"
    ]


def test_a_binary_stl_under_a_solid_header_that_its_size_refuses_says_it_is_binary() -> None:
    from tests.support.meshes import box_stl

    for header in (b"solid part", b"solid facets by a CAD exporter"):  # "facet" in the header: still binary
        data = header.ljust(80, b" ") + box_stl(1.0, 2.0, 3.0)[80:]
        with pytest.raises(UnreadableFileError, match=r"begins with 'solid' but it holds binary data.*holds 734, 50 more"):
            load_body(data + b"\0" * 50, filename="part.stl")
