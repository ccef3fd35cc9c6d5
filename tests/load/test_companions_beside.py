"""A model on the caller's own disk is read with the files it names beside it; an upload never is.

A glTF's buffers live in ``.bin`` files next to it, and the model's own
tools (Blender, three.js, trimesh) read them from there.  ``analyze(path)``
and the command line do the same, for plain file names in the model's
folder; ``load_body(path)`` as the server calls it still refuses them.
"""

from __future__ import annotations

import io
import json
import re
import subprocess
import sys
import zipfile
from pathlib import Path
from urllib.parse import unquote

import pytest
import trimesh

from inertia.errors import ExternalReferenceError
from inertia.load import load_body
from inertia.pipeline import analyze
from tests.support.paths import ROOT

VOLUME = 1.0 * 2.0 * 3.0  # the box's extents


def write_gltf(folder: Path, rename: dict[str, str] | None = None, images: list[str] | None = None) -> Path:
    """A 1 x 2 x 3 box as a .gltf whose buffers are files beside it (``rename``: buffer file -> the uri written)."""
    files = trimesh.creation.box(extents=(1.0, 2.0, 3.0)).export(file_type="gltf")
    doc = json.loads(files.pop("model.gltf"))
    for buffer in doc["buffers"]:
        uri = (rename or {}).get(buffer["uri"], buffer["uri"])
        (folder / unquote(uri)).write_bytes(files[buffer["uri"]])  # where the uri points, "../" included
        buffer["uri"] = uri
    if images:
        doc["images"] = [{"uri": uri} for uri in images]
    path = folder / "box.gltf"
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


def test_analyze_reads_the_buffers_beside_a_gltf(tmp_path: Path) -> None:
    doc = analyze(write_gltf(tmp_path)).as_dict()
    assert doc["mass"] == pytest.approx(doc["density"] * VOLUME, rel=1e-14)
    assert doc["center_of_mass"] == pytest.approx([0.0, 0.0, 0.0], abs=1e-15)


def test_a_uri_written_from_the_folder_itself_names_the_file_beside(tmp_path: Path) -> None:
    # "./gltf_buffer_0.bin" is a relative reference (RFC 3986) to the file beside the model; it was refused as a
    # path, on disk and in an upload alike
    path = write_gltf(tmp_path, rename={"gltf_buffer_0.bin": "./gltf_buffer_0.bin"})
    assert "./gltf_buffer_0.bin" in path.read_text(encoding="utf-8")
    doc = analyze(path).as_dict()
    assert doc["mass"] == pytest.approx(doc["density"] * VOLUME, rel=1e-14)
    buffers = [(p.name, p.read_bytes()) for p in sorted(tmp_path.glob("*.bin"))]
    assert load_body([(path.name, path.read_bytes()), *buffers]).parts


def test_the_command_line_reads_them_too(tmp_path: Path) -> None:
    out = subprocess.run(
        [sys.executable, "-m", "inertia", "analyze", str(write_gltf(tmp_path)), "--json"],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    assert doc["mass"] == pytest.approx(doc["density"] * VOLUME, rel=1e-14)


def test_a_path_loaded_as_the_server_loads_it_names_nothing_outside_itself(tmp_path: Path) -> None:
    with pytest.raises(ExternalReferenceError, match="never opens files named by an upload"):
        load_body(write_gltf(tmp_path))


def test_a_buffer_missing_from_the_folder_is_named(tmp_path: Path) -> None:
    path = write_gltf(tmp_path)
    (tmp_path / "gltf_buffer_1.bin").unlink()
    said = re.escape("(buffer uri 'gltf_buffer_1.bin'), which is not in the file's folder")
    with pytest.raises(ExternalReferenceError, match=said) as err:
        analyze(path)
    assert err.value.details["reference"] == "gltf_buffer_1.bin"


def test_a_buffer_named_by_a_path_is_not_read_even_where_it_exists(tmp_path: Path) -> None:
    inner = tmp_path / "model"
    inner.mkdir()
    path = write_gltf(inner, rename={"gltf_buffer_0.bin": "../gltf_buffer_0.bin"})
    assert (tmp_path / "gltf_buffer_0.bin").exists()
    with pytest.raises(ExternalReferenceError, match="a path or URL") as info:
        analyze(path)
    # a .zip follows no paths either (three.js's DamagedHelmetGpuInstancing names ../glTF/DamagedHelmet.bin):
    # the advice is the one that works
    assert "one .zip" not in info.value.message and "plain file name" in info.value.message
    zipped = io.BytesIO()
    with zipfile.ZipFile(zipped, "w") as archive:
        archive.write(path, "model/" + path.name)
        archive.write(tmp_path / "gltf_buffer_0.bin", "gltf_buffer_0.bin")
    with pytest.raises(ExternalReferenceError) as info:
        load_body(zipped.getvalue(), filename="model.zip")
    assert "not even within a .zip" in info.value.message


def test_a_uri_encoded_name_finds_its_file(tmp_path: Path) -> None:
    path = write_gltf(tmp_path, rename={"gltf_buffer_0.bin": "gltf%20buffer_0.bin"})
    assert (tmp_path / "gltf buffer_0.bin").exists()
    doc = analyze(path).as_dict()
    assert doc["mass"] == pytest.approx(doc["density"] * VOLUME, rel=1e-14)


def test_a_texture_left_out_of_an_upload_does_not_refuse_the_geometry(tmp_path: Path) -> None:
    path = write_gltf(tmp_path, images=["box_basecolor.png"])
    upload = io.BytesIO()
    with zipfile.ZipFile(upload, "w") as zf:  # the model and its buffers, not its texture
        for file in (path, tmp_path / "gltf_buffer_0.bin", tmp_path / "gltf_buffer_1.bin"):
            zf.writestr(file.name, file.read_bytes())
    doc = analyze(upload.getvalue(), filename="box.zip").as_dict()
    assert doc["mass"] == pytest.approx(doc["density"] * VOLUME, rel=1e-14)


def test_a_texture_named_by_a_path_or_url_is_still_refused(tmp_path: Path) -> None:
    path = write_gltf(tmp_path, images=["file:///etc/passwd"])
    with pytest.raises(ExternalReferenceError, match="image uri"):
        analyze(path)


def test_an_abaqus_deck_reads_the_include_beside_it(tmp_path: Path) -> None:
    # meshio merges an included file that is a mesh of its own (nodes and elements), as Abaqus decks split them
    (tmp_path / "bulk.inp").write_text(
        "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n*ELEMENT, TYPE=C3D4, ELSET=ALL\n1, 1, 2, 3, 4\n",
        encoding="utf-8",
    )
    deck = tmp_path / "deck.inp"
    deck.write_text("*HEADING\nunit tetrahedron\n*INCLUDE, INPUT=bulk.inp\n", encoding="utf-8")
    doc = analyze(deck).as_dict()
    assert doc["mass"] == pytest.approx(doc["density"] / 6, rel=1e-14)  # the unit corner tetrahedron
    assert doc["center_of_mass"] == pytest.approx([0.25, 0.25, 0.25], rel=1e-14)
    with pytest.raises(ExternalReferenceError):
        load_body(deck)  # as the server reads an upload


def test_a_tetgen_ele_reads_its_node_file_beside_it(tmp_path: Path) -> None:
    # TetGen's .ele names no file: its points are in the .node of the same stem (sfepy's octahedron.ele)
    (tmp_path / "tet.node").write_text("4 3 0 0\n1 0 0 0\n2 2 0 0\n3 0 2 0\n4 0 0 2\n", encoding="utf-8")
    (tmp_path / "tet.ele").write_text("1 4 0\n1 1 2 3 4\n", encoding="utf-8")
    doc = analyze(tmp_path / "tet.ele").as_dict()
    assert doc["mass"] == pytest.approx(doc["density"] * 8 / 6, rel=1e-14)
    with pytest.raises(ExternalReferenceError, match=r"tet\.node"):
        load_body(tmp_path / "tet.ele")  # as the server reads an upload


def test_a_texture_in_a_subfolder_is_skipped_one_climbing_out_refused(tmp_path: Path) -> None:
    doc = analyze(write_gltf(tmp_path, images=["textures/box%20wood.png"])).as_dict()
    assert doc["mass"] == pytest.approx(doc["density"] * VOLUME, rel=1e-14)
    with pytest.raises(ExternalReferenceError, match="image uri"):
        analyze(write_gltf(tmp_path, images=["textures/../../box.png"]))


def test_a_refusal_that_names_no_file_keeps_its_own_message(tmp_path: Path) -> None:
    path = tmp_path / "mesh.vtu"
    path.write_bytes(b'<?xml version="1.0"?>\n<!DOCTYPE x [<!ENTITY e SYSTEM "file:///etc/passwd">]>\n<VTKFile/>\n')
    with pytest.raises(ExternalReferenceError, match="document type"):
        analyze(path)
