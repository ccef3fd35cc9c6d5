"""Helpers of the batch tests: a generated part library and row comparisons."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, cast

import numpy as np

from benchmarks import cases
from tests.support.motion import rotation

N_FILES = 50
BROKEN = {
    "broken/truncated.stl": "unreadable_file",
    "broken/open_box.stl": "not_watertight",
    "broken/garbage.stl": "unreadable_file",
}


def box(size: tuple[float, float, float], angle: float, offset: tuple[float, float, float]) -> np.ndarray:
    """Triangles (n, 3, 3) of a box rotated by ``angle`` about (1, 1, 1) and moved by ``offset``."""
    v, faces = cases.box(*size)
    rot = rotation(np.ones(3), angle)
    return cast("np.ndarray", (v @ rot.T + np.asarray(offset))[faces])


def stl_bytes(tri: np.ndarray) -> bytes:
    return cases.triangles_stl_bytes(tri, b"batch test".ljust(80, b" "))


def obj_text(tri: np.ndarray) -> str:
    """OBJ of a triangle soup: three vertices of its own per triangle."""
    return cases.obj_bytes([(None, tri.reshape(-1, 3), np.arange(3 * len(tri)).reshape(-1, 3))]).decode()


def make_library(root: Path) -> dict[str, str | None]:
    """Write 50 inputs under ``root``; returns name -> expected error code (None: fine)."""
    rng = np.random.default_rng(7)
    expected: dict[str, str | None] = {}
    folders = ["", "a/", "b/c/", "objs/"]
    for i in range(N_FILES - len(BROKEN)):
        folder = folders[i % len(folders)]
        sx, sy, sz = (float(x) for x in rng.uniform(0.01, 2.0, 3))
        angle = float(rng.uniform(0, np.pi))
        ox, oy, oz = (float(x) for x in rng.uniform(-50, 50, 3))
        tri = box((sx, sy, sz), angle, (ox, oy, oz))
        name = f"{folder}part_{i:02d}." + ("obj" if folder == "objs/" else "stl")
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if name.endswith(".obj"):
            path.write_text(obj_text(tri))
        else:
            path.write_bytes(stl_bytes(tri))
        expected[name] = None
    (root / "broken").mkdir()
    good = stl_bytes(box((1.0, 2.0, 3.0), 0.3, (0.0, 0.0, 0.0)))
    (root / "broken/truncated.stl").write_bytes(good[: 84 + 50 * 6 + 17])
    (root / "broken/open_box.stl").write_bytes(stl_bytes(box((1.0, 2.0, 3.0), 0.3, (0.0, 0.0, 0.0))[:10]))
    (root / "broken/garbage.stl").write_bytes(rng.bytes(777))
    expected.update(BROKEN)
    # not inputs: unknown extension, hidden file, hidden folder, macOS resource fork
    (root / "notes.txt").write_text("not a mesh")
    (root / ".hidden.stl").write_bytes(good)
    (root / ".cache").mkdir()
    (root / ".cache/x.stl").write_bytes(good)
    (root / "a/._part_01.stl").write_bytes(b"resource fork")
    return expected


def read_jsonl(path: Path) -> list[dict[str, Any]]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def without_timing(row: dict[str, Any]) -> dict[str, Any]:
    """A result row minus its run time, the one field that differs between runs."""
    out = json.loads(json.dumps(row))
    out.get("diagnostics", {}).pop("elapsed_s", None)
    return cast("dict[str, Any]", out)


def by_name(rows: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    out = {r["source"]["filename"]: without_timing(r) for r in rows}
    assert len(out) == len(rows), "duplicate names in the output"
    return out


def crashing_task(group: list[Any], options: Any, fmt: str) -> list[tuple[Any, bool]]:
    """The workers' task, except that a file named ``crash*`` kills its worker process (as the OOM killer would)."""
    import os

    from inertia.batch.tasks import render_sources

    if any(src.name.rsplit("/", 1)[-1].startswith("crash") for src in group):
        os._exit(9)
    return render_sources(group, options, fmt)


def cli_error(stderr: str) -> dict[str, str]:
    """The error the command printed on stderr: ``error: <message> (<code>)`` (or the JSON envelope)."""
    text = stderr.strip().splitlines()[-1]
    if text.startswith("{"):
        return dict(json.loads(text)["error"])
    assert text.startswith("error: ") and text.endswith(")"), text
    message, code = text[len("error: ") : -1].rsplit(" (", 1)
    return {"code": code, "message": message}
