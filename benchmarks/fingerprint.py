"""Fingerprints of ``analyze()`` results, to show a refactoring changed no bit.

Every file in ``sample_meshes/`` and a set of generated bodies (point sets near and far from the
origin, multi-part assemblies with per-part densities, tori as solids and shells, a total mass, a
trajectory) is analysed in process; each result's JSON, minus its elapsed times, is hashed (floats
are written by ``repr``, so a hash changes with any bit).  An error is fingerprinted by its code and
message.

    python -m benchmarks.fingerprint --save before.json     # on the old code
    python -m benchmarks.fingerprint --check before.json    # on the new code: exit 1 on any change

Hashes depend on the numpy build and the machine's floating point, so compare runs on one machine.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.cases import box, obj_bytes, stl_bytes

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ROOT / "sample_meshes"


def _strip(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _strip(v) for k, v in value.items() if k != "elapsed_s"}
    if isinstance(value, list):
        return [_strip(v) for v in value]
    return value


def _torus(n: int, m: int, major: float, minor: float, offset: float) -> tuple[np.ndarray, np.ndarray]:
    u = np.linspace(0, 2 * np.pi, n, endpoint=False)[:, None]
    v = np.linspace(0, 2 * np.pi, m, endpoint=False)[None, :]
    ring = major + minor * np.cos(v)
    pts = np.stack([ring * np.cos(u), ring * np.sin(u), minor * np.sin(v) + 0 * u], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    a, b = i * m + j, ((i + 1) % n) * m + j
    c, d = ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return pts + offset, faces


def _vtu_box(offset: float, densities: bool) -> bytes:
    """A unit cube as 5 tetrahedra plus a hexahedron beside it, optionally with cell densities."""
    import tempfile

    import meshio

    cube = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    points = np.concatenate([cube, cube + np.array([1.0, 0.0, 0.0])]) + offset
    tets = np.array([[0, 1, 3, 4], [1, 2, 3, 6], [1, 4, 5, 6], [3, 4, 6, 7], [1, 3, 4, 6]])
    hexa = np.arange(8, 16)[None, :]
    data = {"density": [np.full(5, 1500.0), np.array([7800.0])]} if densities else {}
    mesh = meshio.Mesh(points, [("tetra", tets), ("hexahedron", hexa)], cell_data=data)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "cells.vtu"
        meshio.write(path, mesh, file_format="vtu")
        return path.read_bytes()


def _points(records: list[dict[str, Any]], opts: dict[str, Any]) -> Callable[[], dict[str, Any]]:
    from inertia.options import AnalysisOptions
    from inertia.pipeline import analyze_points

    return lambda: analyze_points(records, AnalysisOptions(**opts)).as_dict()


def _file(data: bytes | Path, filename: str, opts: dict[str, Any]) -> Callable[[], dict[str, Any]]:
    from inertia.options import AnalysisOptions
    from inertia.pipeline import analyze

    source = str(data) if isinstance(data, Path) else data
    return lambda: analyze(source, filename=filename, options=AnalysisOptions(**opts)).as_dict()


def cases() -> Iterator[tuple[str, Callable[[], dict[str, Any]]]]:
    """(name, a function returning the analysis's JSON) for every fingerprinted case."""

    motion = {"omega": (0.3, -1.2, 2.5), "duration": 2.0, "samples": 5}
    for path in sorted(SAMPLES.iterdir()):
        if path.suffix in (".md", ".py"):
            continue
        for label, opts in (
            ("default", {}),
            ("motion+reference", {**motion, "reference": (1.0, -2.0, 0.5)}),
            ("mass", {"mass": 3.25}),
            ("shell", {"model": "shell", "thickness": 0.01}),
        ):
            if path.suffix == ".json":
                records = json.loads(path.read_text())["points"]
                if label == "shell":
                    continue
                yield f"{path.name}:{label}", _points(records, opts)
            else:
                yield f"{path.name}:{label}", _file(path, path.name, opts)

    rng = np.random.default_rng(20261123)
    for n in (1, 2, 3, 4, 7, 40):
        for offset in (0.0, 1e-3, 1e6):
            x = rng.normal(size=(n, 3)) * rng.uniform(0.1, 10.0) + offset
            m = rng.uniform(0.1, 5.0, size=n)
            records = [{"mass": float(mi), "position": [float(c) for c in xi]} for mi, xi in zip(m, x)]
            for label, opts in (("default", {}), ("motion", motion), ("mass+mm", {"mass": 2.0, "units": "mm"})):
                yield f"points n={n} offset={offset}:{label}", _points(records, opts)
    line = [{"mass": 1.0 + i, "position": [0.5 * i, 1.0 * i, -0.25 * i]} for i in range(4)]
    yield "points collinear:motion", _points(line, motion)
    yield "points one:default", _points([{"mass": 2.0, "position": [1.0, 2.0, 3.0]}], {})
    yield (
        "points water:default",
        _points(
            [
                {"element": "O", "position": [0.0, 0.0, 0.1173]},
                {"element": "H", "position": [0.0, 0.7572, -0.4692]},
                {"element": "H", "position": [0.0, -0.7572, -0.4692]},
            ],
            {"units": "angstrom", "mass_unit": "u"},
        ),
    )

    for offset in (0.0, 1e4):
        v, f = _torus(24, 12, 2.0, 0.5, offset)
        data = stl_bytes(v, f)
        for label, opts in (
            ("solid", {}),
            ("solid rho", {"density": 2700.0}),
            ("solid mass", {"mass": 5.0}),
            ("shell", {"model": "shell", "thickness": 0.01}),
            ("shell mass", {"model": "shell", "thickness": 0.02, "mass": 1.5}),
            ("solid mm motion", {"units": "mm", **motion}),
        ):
            yield f"torus offset={offset}:{label}", _file(data, "torus.stl", opts)

    a = box(1.0, 1.0, 1.0)
    b = box(1.0, 2.0, 1.0, (3.0, 1.0, 0.0))
    t = _torus(16, 8, 1.0, 0.25, 0.0)
    t = (t[0] + [0.0, -4.0, 1.0], t[1])
    for offset in (0.0, 1e5):
        parts = [("left", a[0] + offset, a[1]), ("right", b[0] + offset, b[1]), ("ring", t[0] + offset, t[1])]
        data = obj_bytes(parts)
        assembly: tuple[tuple[str, dict[str, Any]], ...] = (
            ("default", {}),
            ("densities", {"densities": {"right": 2000.0, "ring": 8900.0}}),
            ("densities+density", {"density": 500.0, "densities": {"ring": 8900.0}}),
            ("mass", {"mass": 10.0}),
            ("densities+mass", {"mass": 10.0, "densities": {"right": 2000.0}}),
            ("shell", {"model": "shell", "thickness": 0.01}),
            ("shell densities", {"model": "shell", "thickness": 0.01, "densities": {"left": 3000.0}}),
            ("motion", motion),
        )
        for label, opts in assembly:
            yield f"assembly offset={offset}:{label}", _file(data, "asm.obj", opts)

    for offset in (0.0, 1e3):
        for dens in (False, True):
            data = _vtu_box(offset, dens)
            for label, opts in (("default", {}), ("mass", {"mass": 4.0}), ("density", {"density": 3.0})):
                yield f"volume offset={offset} densities={dens}:{label}", _file(data, "cells.vtu", opts)


def fingerprints() -> dict[str, str]:
    from inertia.errors import ServiceError

    out: dict[str, str] = {}
    for name, run in cases():
        try:
            doc: Any = _strip(run())
        except ServiceError as exc:
            doc = {"error": exc.code, "message": str(exc)}
        text = json.dumps(doc, sort_keys=True)
        out[name] = hashlib.sha256(text.encode()).hexdigest()
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--save", type=Path, help="write the fingerprints to this JSON file")
    group.add_argument("--check", type=Path, help="compare with fingerprints saved earlier")
    args = parser.parse_args(argv)
    found = fingerprints()
    if args.save:
        args.save.write_text(json.dumps(found, indent=1, sort_keys=True) + "\n")
        print(f"{len(found)} fingerprints written to {args.save}")
        return 0
    saved = json.loads(args.check.read_text())
    changed = sorted(k for k in saved.keys() | found.keys() if saved.get(k) != found.get(k))
    for name in changed:
        print(f"changed: {name}")
    print(f"{len(found) - len(changed)} of {len(found)} identical" + (f", {len(changed)} changed" if changed else ""))
    return 1 if changed else 0


if __name__ == "__main__":
    sys.exit(main())
