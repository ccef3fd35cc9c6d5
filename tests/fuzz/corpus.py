"""Seed files of every readable format, and the mutations the fuzz loop applies to them.

Seeds: the repository's ``sample_meshes/``, a tetrahedron written by meshio in each of its volume
formats and by trimesh in each surface format, point tables, and every file of ``hostile.py``
(honest and attacking). Mutations: byte flips, truncation, duplicated and spliced slices, numbers
replaced by extreme ones, header lies (STL count, GLB length, zip sizes), inserted includes and
document types, and deep JSON nesting.
"""

from __future__ import annotations

import io
import random
import re
import struct
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

from . import hostile as H

__all__ = ["seeds", "mutate", "MUTATIONS"]

ROOT = Path(__file__).resolve().parents[2]
MESHIO_FORMATS = {
    "vtu": "vtu",
    "vtk": "vtk",
    "msh": "gmsh",
    "mesh": "medit",
    "inp": "abaqus",
    "f3grid": "flac3d",
    "dat": "tecplot",
    "ugrid": "ugrid",
}


def _meshio_seeds() -> list[tuple[str, bytes]]:
    import meshio

    mesh = meshio.Mesh(H.TET_POINTS, [("tetra", np.array([[0, 1, 2, 3]]))])
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for ext, fmt in MESHIO_FORMATS.items():
            path = Path(tmp) / f"tet.{ext}"
            try:
                meshio.write(str(path), mesh, file_format=fmt)
            except Exception:
                continue
            out.append((path.name, path.read_bytes()))
        binary = Path(tmp) / "tet_binary.msh"
        meshio.write(str(binary), mesh, file_format="gmsh", binary=True)
        out.append((binary.name, binary.read_bytes()))
    return out


def _trimesh_seeds() -> list[tuple[str, bytes]]:
    import trimesh

    mesh = trimesh.Trimesh(H.TET_POINTS, H.TET_FACES, process=False)
    out = []
    for ext in ("stl", "obj", "ply", "off", "glb", "gltf"):
        data = mesh.export(file_type=ext) if ext != "gltf" else mesh.export(file_type="gltf", embed_buffers=True)
        if isinstance(data, dict):  # gltf with embed_buffers gives {name: bytes}
            data = data["model.gltf"]
        out.append((f"tet.{ext}", data if isinstance(data, bytes) else data.encode()))
    ascii_stl = mesh.export(file_type="stl_ascii")
    assert isinstance(ascii_stl, str), type(ascii_stl)  # trimesh writes text formats as str
    out.append(("tet_ascii.stl", ascii_stl.encode()))
    return out


def seeds() -> list[tuple[str, bytes]]:
    """Every seed file as (name, bytes)."""
    files = [(p.name, p.read_bytes()) for p in sorted((ROOT / "sample_meshes").iterdir()) if p.suffix not in (".py", ".md")]
    files += _meshio_seeds() + _trimesh_seeds()
    files += [("points.csv", b"mass,x,y,z\n1,0,0,0\n2,1,0,0\n1,0,1,0\n")]
    files += [
        H.abaqus(),
        H.nastran(),
        H.xdmf(),
        H.vtu(),
        H.gltf(),
        H.glb(),
        H.threemf(),
        H.ply(),
        H.ply(binary=False),
        H.off(),
        H.obj_with_mtllib("/etc/passwd"),
        H.abaqus(include="/etc/passwd"),
        H.vtu(piece_source="/etc/passwd"),
        H.gltf(uri="/etc/passwd"),
        H.xdmf("Binary", "/dev/zero"),
        H.vtu(bomb=16 * 1024 * 1024),
        H.threemf(bomb=32 * 1024 * 1024),
        H.vtu(bomb=4 << 20, declared=96),
    ]
    return files


def _flip(data: bytes, rng: random.Random) -> bytes:
    buf = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        if buf:
            buf[rng.randrange(len(buf))] = rng.randrange(256)
    return bytes(buf)


def _truncate(data: bytes, rng: random.Random) -> bytes:
    return data[: rng.randrange(len(data) + 1)]


def _duplicate(data: bytes, rng: random.Random) -> bytes:
    if not data:
        return data
    a = rng.randrange(len(data))
    b = min(len(data), a + rng.randint(1, 4096))
    return data[:b] + data[a:b] * rng.randint(1, 50) + data[b:]


_NUMBER = re.compile(rb"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")
_EXTREMES = [
    b"1e308",
    b"-1e308",
    b"1e-320",
    b"nan",
    b"inf",
    b"-1",
    b"0",
    b"4294967295",
    b"18446744073709551615",
    b"99999999999",
    b"2147483648",
    b"-2147483649",
    b"1" * 400,
]


def _extreme_number(data: bytes, rng: random.Random) -> bytes:
    matches = list(_NUMBER.finditer(data[:200_000]))
    if not matches:
        return _flip(data, rng)
    for m in rng.sample(matches, min(len(matches), rng.randint(1, 4))):
        data = data[: m.start()] + rng.choice(_EXTREMES) + data[m.end() :]
        break  # offsets shift after one replacement
    return data


_INSERTS = [
    b"\n*INCLUDE, INPUT=/etc/passwd\n",
    b"\nmtllib /etc/passwd\n",
    b"\nINCLUDE '/etc/passwd'\n",
    b'<!DOCTYPE x [<!ENTITY e SYSTEM "file:///etc/passwd">]>',
    b'<Piece Source="/etc/passwd"/>',
    b'"uri": "/etc/passwd", ',
    b"\x00" * 64,
    b"\xff\xfe",
    b"[" * 3000,
]


def _insert(data: bytes, rng: random.Random) -> bytes:
    at = rng.randrange(len(data) + 1)
    return data[:at] + rng.choice(_INSERTS) + data[at:]


def _header_lie(data: bytes, rng: random.Random) -> bytes:
    buf = bytearray(data)
    if data[:4] == b"glTF" and len(buf) >= 20:  # file length, first chunk length
        struct.pack_into("<I", buf, rng.choice((8, 12)), rng.choice((0, 1, 2**31, 2**32 - 1)))
    elif data[:2] == b"PK":
        import zipfile

        try:
            with zipfile.ZipFile(io.BytesIO(data)) as z:
                name = rng.choice(z.namelist())
        except Exception:
            return _flip(data, rng)
        return H._lie_about_sizes(data, name, rng.choice((0, 10, 2**31, 2**32 - 1)))
    elif len(buf) >= 84:  # binary STL triangle count
        struct.pack_into("<I", buf, 80, rng.choice((0, 1, 2**31, 2**32 - 1)))
    return bytes(buf)


def _splice(data: bytes, rng: random.Random, other: bytes = b"") -> bytes:
    a, b = rng.randrange(len(data) + 1), rng.randrange(len(other) + 1)
    return data[:a] + other[b:]


def _nest(data: bytes, rng: random.Random) -> bytes:
    depth = rng.choice((100, 1000, 20_000))
    return b"[" * depth + data + b"]" * depth


MUTATIONS: list[Callable[[bytes, random.Random], bytes]] = [
    _flip,
    _truncate,
    _duplicate,
    _extreme_number,
    _insert,
    _header_lie,
    _nest,
]


def mutate(data: bytes, rng: random.Random, corpus: list[tuple[str, bytes]]) -> bytes:
    """One to three mutations of ``data`` (a splice with another seed now and then)."""
    for _ in range(rng.randint(1, 3)):
        splice = rng.random() < 0.1
        data = _splice(data, rng, rng.choice(corpus)[1]) if splice else rng.choice(MUTATIONS)(data, rng)
    return data
