"""glTF positions stored as integers (KHR_mesh_quantization): normalized ones stand for c / 127, c / 255,
c / 32767 or c / 65535 (glTF 2.0 section 3.6.2 and the extension's text); plain ones for themselves.

Expected values are exact rational sums over the box's triangles of the dequantized, placed corners.
"""

from __future__ import annotations

import base64
import json
import struct
from fractions import Fraction
from typing import Any

import numpy as np
import pytest

from inertia.errors import UnsupportedFormatError
from inertia.pipeline import AnalysisOptions, analyze

CORNERS = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
FACES = [(0, 2, 1), (1, 2, 3), (4, 5, 6), (5, 7, 6), (0, 1, 4), (1, 5, 4), (2, 6, 3), (3, 6, 7), (0, 4, 2), (2, 4, 6)]
FACES += [(1, 3, 5), (3, 7, 5)]
DTYPES = {5120: "<i1", 5121: "<u1", 5122: "<i2", 5123: "<u2"}
DIVISOR = {5120: 127, 5121: 255, 5122: 32767, 5123: 65535}


def quantized_box(component: int, normalized: bool, low: int, high: int, stride: int = 8) -> tuple[bytes, list[list[int]]]:
    """A box whose corners are the integers ``low`` / ``high`` per axis; a POSITION buffer padded to ``stride``."""
    dtype = np.dtype(DTYPES[component])
    ints = [[high if c else low for c in corner] for corner in CORNERS]
    positions = b"".join(np.asarray(v, dtype=dtype).tobytes().ljust(stride, b"\0") for v in ints)
    return positions, ints


def gltf(component: int, normalized: bool, low: int, high: int, nodes: list[dict[str, Any]], glb: bool = False) -> bytes:
    positions, _ = quantized_box(component, normalized, low, high)
    indices = np.asarray(FACES, dtype="<u2").tobytes()
    blob = positions + indices
    doc: dict[str, Any] = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_mesh_quantization"],
        "extensionsRequired": ["KHR_mesh_quantization"],
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(positions), "byteStride": 8},
            {"buffer": 0, "byteOffset": len(positions), "byteLength": len(indices)},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": component, "normalized": normalized, "count": 8, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5123, "count": 3 * len(FACES), "type": "SCALAR"},
        ],
    }
    if not glb:
        doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode()
        return json.dumps(doc).encode()
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    blob += b"\0" * (-len(blob) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(blob), 0x004E4942) + blob
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def exact_box(
    low: Fraction, high: Fraction, scale: tuple[float, float, float], shift: tuple[float, float, float]
) -> tuple[Fraction, list[Fraction]]:
    """Volume and centre of the box [low, high]^3 placed by diag(scale) and shift, exactly."""
    sides = [(high - low) * Fraction(s) for s in scale]
    centre = [Fraction(t) + Fraction(s) * (low + high) / 2 for s, t in zip(scale, shift, strict=True)]
    return sides[0] * sides[1] * sides[2], centre


@pytest.mark.parametrize(
    ("component", "low", "high"), [(5122, -10922, 21845), (5120, -40, 87), (5123, 1000, 60000), (5121, 3, 250)]
)
@pytest.mark.parametrize("glb", [False, True])
def test_normalized_positions_are_the_values_they_stand_for(component: int, low: int, high: int, glb: bool) -> None:
    scale, shift = (0.5, 0.25, 2.0), (1.0, 2.0, 3.0)
    data = gltf(component, True, low, high, [{"mesh": 0, "scale": list(scale), "translation": list(shift)}], glb=glb)
    doc = analyze(data, filename="box.glb" if glb else "box.gltf", options=AnalysisOptions(density=1.0)).as_dict()
    volume, centre = exact_box(Fraction(low, DIVISOR[component]), Fraction(high, DIVISOR[component]), scale, shift)
    assert doc["mass"] == pytest.approx(float(volume), rel=1e-14)
    assert doc["center_of_mass"] == pytest.approx([float(c) for c in centre], rel=1e-14)


def test_plain_integer_positions_are_scaled_by_their_node_as_gltfpack_writes_them() -> None:
    scale = (1 / 1024, 1 / 1024, 1 / 512)
    data = gltf(5122, False, -300, 700, [{"mesh": 0, "scale": list(scale)}])
    doc = analyze(data, filename="box.gltf", options=AnalysisOptions(density=1.0)).as_dict()
    volume, centre = exact_box(Fraction(-300), Fraction(700), scale, (0.0, 0.0, 0.0))
    assert doc["mass"] == pytest.approx(float(volume), rel=1e-14)
    assert doc["center_of_mass"] == pytest.approx([float(c) for c in centre], rel=1e-14)


def test_every_node_drawing_the_mesh_keeps_its_name() -> None:
    nodes = [{"mesh": 0, "name": "left"}, {"mesh": 0, "name": "right", "translation": [5.0, 0.0, 0.0]}]
    doc = analyze(gltf(5122, True, 0, 32767, nodes), filename="two.gltf", options=AnalysisOptions(density=1.0)).as_dict()
    assert sorted(p["name"] for p in doc["parts"]) == ["left", "right"]
    assert doc["mass"] == pytest.approx(2.0, rel=1e-14)
    assert doc["center_of_mass"] == pytest.approx([3.0, 0.5, 0.5], rel=1e-14)


def test_the_value_glTF_clamps_is_refused_by_name() -> None:
    # -32768 / 32767 is below -1, which glTF clamps: the integers no longer say where that corner is
    with pytest.raises(UnsupportedFormatError) as info:
        analyze(gltf(5122, True, -32768, 100, [{"mesh": 0}]), filename="box.gltf")
    assert "-32768" in info.value.message
