"""The guard at load_body refuses every reference to another file and every bomb, and only those.

Each attack is checked beside its honest twin (same generator, no attack), so a
test fails if the guard refuses the format rather than the attack. These fail
on a loader without the guard: the Abaqus reader follows INPUT= (and reads
/dev/zero without end), the 3MF and VTU readers inflate to gigabytes.
"""

from __future__ import annotations

import time

import pytest

from inertia.errors import ExternalReferenceError, ServiceError, UnreadableFileError
from inertia.errors import InputTooLargeError as PayloadTooLargeError
from inertia.load import load_body
from inertia.load.guard import check_upload, inflate_budget

from . import hostile as H

MIB = 1024 * 1024

ATTACKS = {
    "abaqus include": (H.abaqus(include="/etc/passwd"), ExternalReferenceError),
    "abaqus include device": (H.abaqus(include="/dev/zero"), ExternalReferenceError),
    "abaqus node input": (H.abaqus(keyword_input="/dev/zero"), ExternalReferenceError),
    "abaqus relative include": (H.abaqus(include="../../etc/passwd"), ExternalReferenceError),
    "xdmf hdf": (H.xdmf("HDF", "/etc/passwd:/x"), ExternalReferenceError),
    "xdmf binary": (H.xdmf("Binary", "/dev/zero"), ExternalReferenceError),
    "vtu piece source": (H.vtu(piece_source="/etc/passwd"), ExternalReferenceError),
    "vtu doctype": (H.vtu(doctype=True), ExternalReferenceError),
    "vtu bomb": (H.vtu(bomb=128 * MIB), PayloadTooLargeError),
    "vtu block lies": (H.vtu(bomb=8 * MIB, declared=96), PayloadTooLargeError),
    "vtu declares a gigabyte": (H.vtu(declared=10**9), PayloadTooLargeError),
    "vtu block count lies": (H.vtu(lie_blocks=10**6), UnreadableFileError),
    "gltf buffer uri": (H.gltf(uri="/etc/passwd"), ExternalReferenceError),
    "gltf buffer url": (H.gltf(uri="http://127.0.0.1:9/x.bin"), ExternalReferenceError),
    "gltf image uri": (H.gltf(image_uri="file:///etc/passwd"), ExternalReferenceError),
    "gltf nested json": (H.gltf(depth=100_000), UnreadableFileError),
    "glb length lies": (H.glb(length_lie=1000), UnreadableFileError),
    "glb chunk lies": (H.glb(chunk_lie=10**6), UnreadableFileError),
    "glb buffer uri": (H.glb(uri="/etc/passwd"), ExternalReferenceError),
    "3mf bomb": (H.threemf(bomb=256 * MIB), PayloadTooLargeError),
    "3mf doctype": (H.threemf(doctype=True), ExternalReferenceError),
    "3mf size lies": (H.threemf(size_lie=True), UnreadableFileError),
    "ply vertex count lies": (H.ply(vertices=10**9), UnreadableFileError),
    "ply ascii face count lies": (H.ply(faces=10**8, binary=False), UnreadableFileError),
    "off count lies": (H.off(vertices=10**9), UnreadableFileError),
}

HONEST = {
    "abaqus": H.abaqus(),
    "vtu": H.vtu(),
    "gltf": H.gltf(),
    "glb": H.glb(),
    "3mf": H.threemf(),
    "ply": H.ply(),
    "ply ascii": H.ply(binary=False),
    "off": H.off(),
}


@pytest.mark.parametrize("name", sorted(ATTACKS))
def test_attack_is_refused_with_its_class(name: str) -> None:
    (filename, data), expected = ATTACKS[name]
    with pytest.raises(expected) as info:
        load_body(data, filename=filename)
    assert "Traceback" not in info.value.message


@pytest.mark.parametrize("name", sorted(HONEST))
def test_honest_twin_of_each_attack_loads(name: str) -> None:
    filename, data = HONEST[name]
    loaded = load_body(data, filename=filename)
    assert loaded.parts


def test_refusal_names_the_reference_but_reads_nothing(tmp_path: object) -> None:
    # the message quotes what the file says, and says the same whether or not the path exists
    _, existing = H.abaqus(include="/etc/passwd")
    _, missing = H.abaqus(include="/no/such/file")
    messages = []
    for data in (existing, missing):
        with pytest.raises(ExternalReferenceError) as info:
            load_body(data, filename="deck.inp")
        messages.append(info.value.message.replace("/etc/passwd", "X").replace("/no/such/file", "X"))
    assert messages[0] == messages[1]


def test_include_of_a_companion_file_is_accepted_by_the_guard() -> None:
    _, data = H.abaqus(include="part.inp")
    check_upload(data, "inp", companions={"part.inp"})
    with pytest.raises(ExternalReferenceError):
        check_upload(data, "inp", companions={"other.inp"})
    _, sneaky = H.abaqus(include="sub/part.inp")
    with pytest.raises(ExternalReferenceError):  # a companion is a plain name, never a path
        check_upload(sneaky, "inp", companions={"sub/part.inp", "part.inp"})


def test_abaqus_comment_line_is_not_an_include() -> None:
    _, data = H.abaqus()
    check_upload(data.replace(b"*HEADING", b"** *INCLUDE, INPUT=/etc/passwd\n*HEADING"), "inp")


def test_bombs_are_refused_before_inflating() -> None:
    # a refusal costs a header read, not the inflation: well under the time to inflate even once
    for name in ("vtu bomb", "3mf bomb", "vtu declares a gigabyte"):
        (filename, data), expected = ATTACKS[name]
        start = time.process_time()
        with pytest.raises(expected):
            check_upload(data, filename.rsplit(".", 1)[1])
        assert time.process_time() - start < 0.5, name  # CPU seconds: inflating 128 MiB+ takes longer


def test_inflate_budget_is_floor_ratio_and_cap() -> None:
    from inertia.load import guard

    assert inflate_budget(10) == guard.INFLATE_FLOOR_BYTES
    assert inflate_budget(10 * MIB) == guard.INFLATE_RATIO * 10 * MIB
    assert inflate_budget(10**12) == guard.MAX_INFLATED_BYTES


def test_obj_mtllib_is_never_opened(tmp_path: object) -> None:
    # trimesh is given bytes with no resolver and materials are skipped: the named file is not read,
    # so a FIFO (which would block any reader) does not hold the load
    import os
    import pathlib

    fifo = pathlib.Path(str(tmp_path)) / "materials.mtl"
    os.mkfifo(fifo)
    filename, data = H.obj_with_mtllib(str(fifo))
    assert load_body(data, filename=filename).parts


def test_every_refusal_is_a_service_error() -> None:
    for (filename, data), _ in ATTACKS.values():
        with pytest.raises(ServiceError):
            load_body(data, filename=filename)
