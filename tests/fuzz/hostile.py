"""Hostile files of every kind, written here: includes, external references, bombs, header lies, deep JSON.

Each generator returns ``(filename, bytes)``. The honest counterparts (the same
layout without the attack) come from the same functions, so a test can check
that the guard refuses the attack and not the format.
"""

from __future__ import annotations

import base64
import io
import json
import struct
import zipfile
import zlib

import numpy as np

__all__ = [
    "TET_POINTS",
    "abaqus",
    "nastran",
    "xdmf",
    "vtu",
    "gltf",
    "glb",
    "threemf",
    "ply",
    "off",
    "zip_of",
    "deep_json",
    "obj_with_mtllib",
]

# a unit right tetrahedron: volume 1/6
TET_POINTS = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
TET_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
MIB = 1024 * 1024


def abaqus(include: str | None = None, keyword_input: str | None = None) -> tuple[str, bytes]:
    """An Abaqus deck of one C3D4 element, optionally with ``*INCLUDE, INPUT=`` or ``*NODE, INPUT=``."""
    lines = ["*HEADING", "one tetrahedron"]
    lines += (
        [f"*NODE, INPUT={keyword_input}"]
        if keyword_input
        else ["*NODE"] + [f"{i + 1}, {x}, {y}, {z}" for i, (x, y, z) in enumerate(TET_POINTS)]
    )
    lines += ["*ELEMENT, TYPE=C3D4, ELSET=EALL", "1, 1, 2, 3, 4"]
    if include:
        lines.append(f"*INCLUDE, INPUT={include}")
    return "deck.inp", ("\n".join(lines) + "\n").encode()


def nastran(include: str | None = None) -> tuple[str, bytes]:
    lines = ["BEGIN BULK"] + [f"GRID,{i + 1},,{x},{y},{z}" for i, (x, y, z) in enumerate(TET_POINTS)]
    lines.append("CTETRA,1,1,1,2,3,4")
    if include:
        lines.append(f"INCLUDE '{include}'")
    lines.append("ENDDATA")
    return "model.bdf", ("\n".join(lines) + "\n").encode()


def xdmf(data_format: str = "XML", reference: str = "mesh.h5:/points") -> tuple[str, bytes]:
    body = reference if data_format != "XML" else " ".join(map(str, TET_POINTS.ravel()))
    text = f"""<?xml version="1.0"?>
<Xdmf Version="3.0"><Domain><Grid Name="g"><Topology TopologyType="Tetrahedron" NumberOfElements="1">
<DataItem Dimensions="1 4" NumberType="Int" Format="XML">0 1 2 3</DataItem></Topology>
<Geometry GeometryType="XYZ"><DataItem Dimensions="4 3" NumberType="Float" Precision="8" Format="{data_format}">{body}</DataItem>
</Geometry></Grid></Domain></Xdmf>
"""
    return "mesh.xdmf", text.encode()


def _vtk_blocks(raw: bytes, *, declared: int | None = None, bomb: int = 0, lie_blocks: int | None = None) -> bytes:
    """VTK's compressed layout (UInt32 header): [nblocks, block size, last size, compressed sizes] + blocks.

    bomb: replace the content by this many zero bytes; declared: the uncompressed size the header claims.
    """
    content = b"\0" * bomb if bomb else raw
    block = zlib.compress(content, 9)
    size = len(content) if declared is None else declared
    nblocks = 1 if lie_blocks is None else lie_blocks
    return struct.pack("<4I", nblocks, size, size, len(block)) + block


def vtu(
    *,
    bomb: int = 0,
    declared: int | None = None,
    piece_source: str | None = None,
    doctype: bool = False,
    lie_blocks: int | None = None,
) -> tuple[str, bytes]:
    """A one-tetrahedron VTU with zlib-compressed base64 arrays (as VTK writes them), or an attack on it."""

    def array(values: np.ndarray, vtk_type: str, components: int, attack: bool = False) -> str:
        raw = values.tobytes()
        packed = _vtk_blocks(raw, declared=declared, bomb=bomb, lie_blocks=lie_blocks) if attack else _vtk_blocks(raw)
        header, blocks = packed[:16], packed[16:]
        text = base64.b64encode(header).decode() + base64.b64encode(blocks).decode()
        return f'<DataArray type="{vtk_type}" NumberOfComponents="{components}" format="binary">{text}</DataArray>'

    attack = bool(bomb or declared is not None or lie_blocks is not None)
    piece = f'<Piece Source="{piece_source}"/>' if piece_source else ""
    dtd = '<!DOCTYPE VTKFile [<!ENTITY e SYSTEM "file:///etc/hostname">]>\n' if doctype else ""
    text = f"""<?xml version="1.0"?>
{dtd}<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian" header_type="UInt32"
 compressor="vtkZLibDataCompressor">
<UnstructuredGrid>{piece}<Piece NumberOfPoints="4" NumberOfCells="1">
<Points>{array(TET_POINTS.astype("<f8"), "Float64", 3, attack)}</Points>
<Cells>{array(np.arange(4, dtype="<i8"), "Int64", 1)}{array(np.array([4], dtype="<i8"), "Int64", 1)}
{array(np.array([10], dtype="u1"), "UInt8", 1)}</Cells>
</Piece></UnstructuredGrid></VTKFile>
"""
    text = text.replace("<Cells><DataArray", '<Cells><DataArray Name="connectivity"', 1)
    text = text.replace('</DataArray><DataArray type="Int64"', '</DataArray><DataArray Name="offsets" type="Int64"', 1)
    text = text.replace('<DataArray type="UInt8"', '<DataArray Name="types" type="UInt8"', 1)
    return "tet.vtu", text.encode()


def _gltf_doc(buffer_uri: str, image_uri: str | None = None) -> dict[str, object]:
    doc: dict[str, object] = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"uri": buffer_uri, "byteLength": 96 + 48}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 48}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5125, "count": 12, "type": "SCALAR"},
        ],
    }
    if image_uri:
        doc["images"] = [{"uri": image_uri}]
    return doc


def _tet_buffer() -> bytes:
    return TET_POINTS.astype("<f4").tobytes() + TET_FACES.astype("<u4").tobytes()


def gltf(uri: str | None = None, image_uri: str | None = None, depth: int = 0) -> tuple[str, bytes]:
    """A .gltf with its buffer embedded (data URI), or pointing at ``uri``; ``depth`` nests an extra."""
    data_uri = "data:application/octet-stream;base64," + base64.b64encode(_tet_buffer()).decode()
    doc = _gltf_doc(uri or data_uri, image_uri)
    text = json.dumps(doc)
    if depth:
        text = text[:-1] + ', "extras": ' + "[" * depth + "]" * depth + "}"
    return "tet.gltf", text.encode()


def glb(*, length_lie: int = 0, chunk_lie: int = 0, uri: str | None = None) -> tuple[str, bytes]:
    buffer = _tet_buffer()
    doc = _gltf_doc(uri or "")
    buffers = doc["buffers"]
    assert isinstance(buffers, list)
    if uri is None:
        buffers[0].pop("uri")
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text
    chunks += struct.pack("<II", len(buffer) + chunk_lie, 0x004E4942) + buffer
    total = 12 + len(chunks)
    return "tet.glb", struct.pack("<4sII", b"glTF", 2, total + length_lie) + chunks


_3MF_MODEL = """<?xml version="1.0" encoding="UTF-8"?>{dtd}
<model unit="millimeter" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">
<resources><object id="1" type="model"><mesh><vertices>{vertices}</vertices><triangles>{triangles}</triangles>
</mesh></object></resources><build><item objectid="1"/></build></model>"""
_3MF_RELS = """<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">
<Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>
</Relationships>"""
_3MF_TYPES = """<?xml version="1.0" encoding="UTF-8"?>
<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">
<Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>
<Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/></Types>"""


def threemf(*, bomb: int = 0, doctype: bool = False, size_lie: bool = False) -> tuple[str, bytes]:
    """A 3MF package of one tetrahedron; ``bomb`` adds a member of that many inflated bytes."""
    vertices = "".join(f'<vertex x="{x}" y="{y}" z="{z}"/>' for x, y, z in TET_POINTS)
    triangles = "".join(f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in TET_FACES)
    dtd = '\n<!DOCTYPE model [<!ENTITY e SYSTEM "file:///etc/hostname">]>' if doctype else ""
    model = _3MF_MODEL.format(dtd=dtd, vertices=vertices, triangles=triangles)
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("[Content_Types].xml", _3MF_TYPES)
        z.writestr("_rels/.rels", _3MF_RELS)
        z.writestr("3D/3dmodel.model", model)
        if bomb:
            z.writestr("3D/padding.model", b" " * bomb)
    data = out.getvalue()
    if size_lie:  # the member's declared size says 10 bytes: the reader must stop there (CRC error)
        data = _lie_about_sizes(data, b"3D/3dmodel.model", 10)
    return "tet.3mf", data


def _lie_about_sizes(data: bytes, name: str | bytes, size: int) -> bytes:
    buf = bytearray(data)
    target = name.encode() if isinstance(name, str) else name
    for sig, field in ((b"PK\x03\x04", 22), (b"PK\x01\x02", 24)):
        start = 0
        while (pos := buf.find(sig, start)) >= 0:
            name_len_at = pos + (26 if sig == b"PK\x03\x04" else 28)
            name_len = struct.unpack_from("<H", buf, name_len_at)[0]
            name_at = pos + (30 if sig == b"PK\x03\x04" else 46)
            if bytes(buf[name_at : name_at + name_len]) == target:
                struct.pack_into("<I", buf, pos + field, size)
            start = pos + 4
    return bytes(buf)


def ply(vertices: int = 4, faces: int = 4, binary: bool = True) -> tuple[str, bytes]:
    """A PLY tetrahedron whose header declares ``vertices`` and ``faces`` (a lie when not 4)."""
    fmt = "binary_little_endian" if binary else "ascii"
    header = (
        f"ply\nformat {fmt} 1.0\nelement vertex {vertices}\nproperty float x\nproperty float y\n"
        f"property float z\nelement face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
    ).encode()
    if binary:
        body = TET_POINTS.astype("<f4").tobytes() + b"".join(struct.pack("<B3i", 3, *map(int, f)) for f in TET_FACES)
    else:
        body = (
            "".join(f"{x} {y} {z}\n" for x, y, z in TET_POINTS).encode()
            + "".join(f"3 {a} {b} {c}\n" for a, b, c in TET_FACES).encode()
        )
    return "tet.ply", header + body


def off(vertices: int = 4, faces: int = 4) -> tuple[str, bytes]:
    text = f"OFF\n{vertices} {faces} 0\n" + "".join(f"{x} {y} {z}\n" for x, y, z in TET_POINTS)
    text += "".join(f"3 {a} {b} {c}\n" for a, b, c in TET_FACES)
    return "tet.off", text.encode()


def obj_with_mtllib(path: str) -> tuple[str, bytes]:
    text = f"mtllib {path}\n" + "".join(f"v {x} {y} {z}\n" for x, y, z in TET_POINTS)
    text += "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in TET_FACES)
    return "tet.obj", text.encode()


def zip_of(members: list[tuple[str, bytes]], corrupt: str | None = None) -> bytes:
    """A .zip of the members; the one named ``corrupt`` has its compressed bytes damaged."""
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        for name, data in members:
            z.writestr(name, data)
    raw = bytearray(out.getvalue())
    if corrupt is not None:
        with zipfile.ZipFile(io.BytesIO(bytes(raw))) as z:
            info = z.getinfo(corrupt)
        start = info.header_offset + 30 + len(info.filename.encode()) + len(info.extra)
        for k in range(start, start + min(info.compress_size, 64)):
            raw[k] ^= 0x5A
    return bytes(raw)


def deep_json(depth: int) -> str:
    """A JSON text nested ``depth`` levels deep."""
    return "[" * depth + "]" * depth
