"""Bit-identity check for speed work: hashes of ``analyze()`` results before and after a change.

    python -m benchmarks.identity --sizes 2e5 1e6 --out before.json
    python -m benchmarks.identity --sizes 2e5 1e6 --compare before.json

Every case's result (``AnalysisResult.as_dict()``, elapsed times left out),
or the error it raised (class, message and details), is serialised as JSON
with sorted keys and hashed; ``--compare`` reports every case whose hash
differs from the stored one and exits 1 if any does.  A change that is only
faster must leave every hash unchanged.

Cases: the sample meshes (solid, and the STL ones as shells), and closed tori
(``benchmarks.mass.torus_stl``) at each size as binary STL with their faces in
grid order and shuffled, corners rotated within faces, inverted, mixed
winding, a few faces removed (open), float32 coordinates offset far from the
origin (100 to 1e7: exact, warned, refused), two disjoint tori, a torus with a
cavity (a thinner torus inside its tube, wound the same way: its orientation
is repaired by nesting), a shell analysis, and at the smallest size also ASCII STL,
OBJ (float64 text) and unwelded float64 arrays.  Meshes are written once into
``--cache`` and reused.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import tempfile
from collections.abc import Callable, Iterator
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.mass import torus_stl

SIZES = {"2e5": (500, 200), "1e6": (1000, 500), "5e6": (2500, 1000), "2e7": (5000, 2000)}
RECORD = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attr", "<u2")])
OFFSETS = (100.0, 2e4, 3e6, 1e7)
BIG = 3_000_000  # from this many triangles only the cases that exercise different code paths


def _write(path: Path, rec: np.ndarray) -> None:
    with open(path, "wb") as fh:
        fh.write(b"benchmarks.identity".ljust(80, b" "))
        fh.write(np.uint32(len(rec)).tobytes())
        fh.write(rec.tobytes())


def _records(path: Path) -> np.ndarray:
    return np.fromfile(path, dtype=RECORD, offset=84)


def _torus_records(cache: Path, label: str, scale: float = 1.0) -> np.ndarray:
    path = cache / f"torus_{label}.stl"
    if not path.exists():
        torus_stl(path, *SIZES[label])
    rec = _records(path)
    if scale != 1.0:
        rec = rec.copy()
        rec["vertices"] *= np.float32(scale)
    return rec


def _variants(cache: Path, label: str) -> Iterator[tuple[str, Path, dict[str, Any]]]:
    """(case name, file, analyze options) for the tori of one size."""
    base = _torus_records(cache, label)
    n = len(base)
    rng = np.random.default_rng(7)
    big = n >= BIG

    def make(name: str, build: Callable[[], np.ndarray], suffix: str = ".stl") -> Path:
        path = cache / f"{label}_{name}{suffix}"
        if not path.exists():
            _write(path, build())
        return path

    def shuffled() -> np.ndarray:
        return base[rng.permutation(n)]

    def rotated() -> np.ndarray:
        rec = base.copy()
        rec["vertices"] = np.roll(base["vertices"], 1, axis=1)
        return rec

    def inverted() -> np.ndarray:
        rec = base.copy()
        rec["vertices"][:, [1, 2]] = base["vertices"][:, [2, 1]]
        return rec

    def mixed() -> np.ndarray:
        rec = base.copy()
        flip = rng.random(n) < 0.3
        rec["vertices"][flip] = base["vertices"][flip][:, [0, 2, 1]]
        return rec

    def opened() -> np.ndarray:
        return np.delete(base, rng.choice(n, 5, replace=False))

    def offset(off: float) -> Callable[[], np.ndarray]:
        def build() -> np.ndarray:
            rec = base.copy()
            shifted = base["vertices"].astype(np.float64) + off * np.array([1.0, 0.7, 0.4])
            rec["vertices"] = shifted.astype("<f4")
            return rec

        return build

    def two() -> np.ndarray:
        other = base.copy()
        other["vertices"] += np.float32(10.0)
        return np.concatenate([base, other])

    def cavity() -> np.ndarray:
        inner = cache / f"torus_{label}_minor05.stl"  # the same ring, half the tube: inside the material
        if not inner.exists():
            torus_stl(inner, *SIZES[label], minor=0.5)
        return np.concatenate([base, _records(inner)])

    yield "ordered", make("ordered", lambda: base), {}
    yield "shuffled", make("shuffled", shuffled), {}
    yield "offset 2e4", make("off2e4", offset(2e4)), {}
    yield "mixed winding", make("mixed", mixed), {}
    if big:
        return
    yield "corners rotated", make("rotated", rotated), {}
    yield "inverted", make("inverted", inverted), {}
    yield "open", make("open", opened), {}
    for off in OFFSETS:
        if off != 2e4:
            yield f"offset {off:g}", make(f"off{off:g}", offset(off)), {}
    yield "two tori", make("two", two), {}
    yield "cavity", make("cavity", cavity), {}
    yield "shell", make("ordered", lambda: base), {"model": "shell", "thickness": 0.01}
    if n <= 300_000:
        yield "ascii stl", _ascii(cache, label, base), {}
        yield "obj", _obj(cache, label, base), {}


def _ascii(cache: Path, label: str, rec: np.ndarray) -> Path:
    path = cache / f"{label}_ascii.stl"
    if not path.exists():
        with open(path, "w") as fh:
            fh.write("solid t\n")
            for tri in rec["vertices"].astype(np.float64).tolist():
                fh.write(" facet normal 0 0 0\n  outer loop\n")
                fh.writelines(f"   vertex {x!r} {y!r} {z!r}\n" for x, y, z in tri)
                fh.write("  endloop\n endfacet\n")
            fh.write("endsolid t\n")
    return path


def _obj(cache: Path, label: str, rec: np.ndarray) -> Path:
    path = cache / f"{label}.obj"
    if not path.exists():
        corners = rec["vertices"].astype(np.float64).reshape(-1, 3) * 1.1  # float64 values no float32 can hold
        with open(path, "w") as fh:
            fh.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in corners.tolist())
            fh.writelines(f"f {3 * i + 1} {3 * i + 2} {3 * i + 3}\n" for i in range(len(rec)))
    return path


def _strip(o: Any) -> Any:
    if isinstance(o, dict):
        return {k: _strip(v) for k, v in o.items() if "elapsed" not in k}
    if isinstance(o, list):
        return [_strip(v) for v in o]
    return o


def _digest(run: Callable[[], Any]) -> tuple[str, str]:
    try:
        doc = run().as_dict()
    except Exception as exc:  # the refusal is part of the result
        doc = {"error": type(exc).__name__, "message": str(exc), "details": getattr(exc, "details", None)}
    text = json.dumps(_strip(doc), sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:16], text[:160]


def cases(cache: Path, sizes: list[str]) -> Iterator[tuple[str, Callable[[], Any]]]:
    from inertia.options import AnalysisOptions
    from inertia.pipeline import analyze

    samples = Path(__file__).resolve().parent.parent / "sample_meshes"
    for path in sorted(samples.iterdir()):
        if path.suffix in (".py", ".md"):
            continue
        yield f"sample {path.name}", partial(analyze, str(path))
        if path.suffix == ".stl":
            shell = AnalysisOptions(model="shell", thickness=0.001)
            yield f"sample {path.name} shell", partial(analyze, str(path), options=shell)
    for label in sizes:
        for name, path, opts in _variants(cache, label):
            yield f"{label} {name}", partial(analyze, str(path), options=AnalysisOptions(**opts))
        if SIZES[label][0] * SIZES[label][1] * 2 <= 300_000:
            rec = _torus_records(cache, label)
            corners = rec["vertices"].astype(np.float64).reshape(-1, 3)
            faces = np.arange(len(corners)).reshape(-1, 3)
            yield f"{label} unwelded arrays", partial(analyze, (corners, faces))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", nargs="*", default=["2e5"], choices=list(SIZES), help="torus sizes")
    parser.add_argument("--cache", default=None, help="folder for the generated meshes (default: a temporary one)")
    parser.add_argument("--out", default=None, help="write the hashes here (JSON)")
    parser.add_argument("--compare", default=None, help="compare with hashes written before by --out")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="inertia-identity-") as tmp:
        cache = Path(args.cache) if args.cache else Path(tmp)
        cache.mkdir(parents=True, exist_ok=True)
        found = {}
        for name, run in cases(cache, args.sizes):
            found[name] = _digest(run)
            print(f"{name}: {found[name][0]}", file=sys.stderr, flush=True)
    if args.out:
        Path(args.out).write_text(json.dumps({k: h for k, (h, _) in found.items()}, indent=1))
    if args.compare:
        before = json.loads(Path(args.compare).read_text())
        differ = [k for k, (h, _) in found.items() if k in before and before[k] != h]
        missing = [k for k in found if k not in before]
        for k in differ:
            print(f"DIFFERS {k}: {found[k][1]}")
        print(f"{len(found) - len(differ) - len(missing)} identical, {len(differ)} differ, {len(missing)} not in {args.compare}")
        return 1 if differ else 0
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
