"""Load + mass properties of binary STL files: ours against trimesh and numpy-stl.

    python -m benchmarks.mass            # 1e4, 1e5, 1e6, 4e6 triangles -> docs/performance.md
    python -m benchmarks.mass --quick    # 1e4, 1e5 only (a smoke run)

Test bodies are closed tori (R = 3, r = 1, a u-by-v grid, two triangles per
quad) written as binary STL into a temporary directory.  Three measurements
in the same run:

(a) whole processes, as a user meets them: ``inertia analyze FILE --json``
    (load, weld, watertight check, exact multi-pass integration, JSON)
    against a script that imports trimesh, loads the file and reads
    ``mass_properties`` and ``is_watertight``, and one that calls numpy-stl's
    ``Mesh.from_file`` + ``get_mass_properties``.  Wall time and peak RSS
    (GNU time's %M for the tool's own process, else ``os.wait4``) are the median of ``--repeat`` runs.
(b) our stages in process (read + weld of the STL, edge topology, outward
    orientation, each integration pass), timed by
    wrapping the stage functions around one ``pipeline.analyze`` call.
(c) accuracy: principal moments per unit density of each tool, their
    relative differences, and our own error estimate.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

SIZES = {"1e4": (100, 50), "1e5": (250, 200), "1e6": (1000, 500), "4e6": (2000, 1000)}
QUICK = ("1e4", "1e5")
SLOW_NUMPY_STL = 1_000_000  # numpy-stl's exact mass path takes ~36 s at 1e6: one run from here up

TRIMESH_SCRIPT = """
import json, sys, trimesh
m = trimesh.load(sys.argv[1])
p = m.mass_properties
print(json.dumps({"volume": float(p["volume"]), "inertia": p["inertia"].tolist(), "watertight": bool(m.is_watertight)}))
"""
NUMPY_STL_SCRIPT = """
import json, sys
from stl import mesh
m = mesh.Mesh.from_file(sys.argv[1])
volume, cog, inertia = m.get_mass_properties()
print(json.dumps({"volume": float(volume), "inertia": inertia.tolist()}))
"""


def torus_stl(path: Path, nu: int, nv: int, major: float = 3.0, minor: float = 1.0) -> int:
    """Write a closed torus of 2 nu nv triangles as binary STL; returns the triangle count."""
    u = 2 * np.pi * np.arange(nu) / nu
    v = 2 * np.pi * np.arange(nv) / nv
    uu, vv = np.meshgrid(u, v, indexing="ij")
    ring = major + minor * np.cos(vv)
    pts = np.stack([ring * np.cos(uu), ring * np.sin(uu), minor * np.sin(vv)], -1).reshape(-1, 3).astype("<f4")
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a, b = i * nv + j, (i + 1) % nu * nv + j
    c, d = (i + 1) % nu * nv + (j + 1) % nv, i * nv + (j + 1) % nv
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    rec = np.zeros(len(faces), dtype=[("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attr", "<u2")])
    rec["vertices"] = pts[faces]
    with open(path, "wb") as fh:
        fh.write(b"benchmarks.mass torus".ljust(80, b" "))
        fh.write(np.uint32(len(faces)).tobytes())
        fh.write(rec.tobytes())
    return len(faces)


GNU_TIME = "/usr/bin/time"


def run_process(cmd: list[str]) -> tuple[float, int, str]:
    """Wall time [s], peak RSS [bytes] and stdout of one child process.

    Linux carries a process's high-water RSS across fork and exec into the
    child's ``ru_maxrss``, so a child of this (large) benchmark process would
    report at least this process's own peak.  GNU time, itself tiny, forks the
    tool and reports the tool's own peak; without it we fall back to wait4.
    """
    wrapped = os.path.exists(GNU_TIME)
    with tempfile.TemporaryFile() as out, tempfile.NamedTemporaryFile("r") as rss_file:
        full = [GNU_TIME, "-f", "%M", "-o", rss_file.name, *cmd] if wrapped else cmd
        start = time.perf_counter()
        proc = subprocess.Popen(full, stdout=out, stderr=subprocess.PIPE)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - start
        proc.returncode = os.waitstatus_to_exitcode(status)
        err = proc.stderr.read().decode() if proc.stderr else ""
        if proc.returncode != 0:
            raise RuntimeError(f"{cmd[:3]} failed ({proc.returncode}): {err[-2000:]}")
        peak_kb = int(rss_file.read().split()[-1]) if wrapped else usage.ru_maxrss
        out.seek(0)
        return wall, peak_kb * 1024, out.read().decode()


def tool_commands(path: Path) -> dict[str, list[str]]:
    py = sys.executable
    inertia = Path(py).with_name("inertia")
    ours = [str(inertia)] if inertia.exists() else [py, "-m", "inertia"]
    return {
        "inertia": ours + ["analyze", str(path), "--json"],
        "trimesh": [py, "-c", TRIMESH_SCRIPT, str(path)],
        "numpy-stl": [py, "-c", NUMPY_STL_SCRIPT, str(path)],
    }


def principal_per_density(tool: str, stdout: str) -> tuple[np.ndarray, float | None]:
    """Sorted principal moments for unit density, and the tool's error estimate if any."""
    doc = json.loads(stdout)
    if tool == "inertia":
        moments = np.array(doc["principal"]["moments"]) / doc["density"]
        return np.sort(moments), float(doc["diagnostics"]["relative_error_estimate"])
    return np.sort(np.linalg.eigvalsh(np.array(doc["inertia"]))), None


def measure_processes(path: Path, triangles: int, repeat: int) -> dict[str, dict[str, Any]]:
    out: dict[str, dict[str, Any]] = {}
    for tool, cmd in tool_commands(path).items():
        runs = 1 if tool == "numpy-stl" and triangles >= SLOW_NUMPY_STL else repeat
        walls, rss = [], []
        for _ in range(runs):
            wall, peak, stdout = run_process(cmd)
            walls.append(wall)
            rss.append(peak)
        moments, estimate = principal_per_density(tool, stdout)
        out[tool] = {"wall": statistics.median(walls), "rss": statistics.median(rss), "runs": runs,
                     "moments": moments, "estimate": estimate}
    return out


def stage_breakdown(path: Path) -> dict[str, float]:
    """Seconds per stage of one in-process ``pipeline.analyze`` (after a warm-up run)."""
    import inertia.load.stl as stl
    import inertia.mass as mass
    import inertia.solid as solid
    from inertia import pipeline

    times: dict[str, float] = defaultdict(float)
    passes = [0]

    def timed(name: str | Callable[[], str], fn: Callable[..., Any]) -> Callable[..., Any]:
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            start = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                times[name() if callable(name) else name] += time.perf_counter() - start
        return wrapper

    def pass_name() -> str:
        passes[0] += 1
        return f"integration pass {passes[0]}"

    patches = [(stl, "read_stl_file", "read STL + float32 weld"),
               (solid, "surface_topology", "edge topology (watertight check)"),
               (solid, "_orient_outward", "outward orientation"), (mass._Geometry, "sums", pass_name)]
    saved = [(obj, attr, getattr(obj, attr)) for obj, attr, _ in patches]
    try:
        for obj, attr, name in patches:
            setattr(obj, attr, timed(name, getattr(obj, attr)))
        pipeline.analyze(str(path))  # warm-up: lazy imports
        times.clear()
        passes[0] = 0
        start = time.perf_counter()
        pipeline.analyze(str(path))
        total = time.perf_counter() - start
    finally:
        for obj, attr, fn in saved:
            setattr(obj, attr, fn)
    staged = dict(times)
    staged["rest (file read, body checks, eigen, JSON)"] = total - sum(staged.values())
    staged["total analyze()"] = total
    return staged


def machine_info() -> dict[str, str]:
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    mem = ""
    try:
        kb = int(Path("/proc/meminfo").read_text().split()[1])
        mem = f"{kb / 2**20:.1f} GiB"
    except (OSError, ValueError, IndexError):
        pass
    versions = {name: importlib.metadata.version(name) for name in ("numpy", "trimesh", "numpy-stl")}
    return {"CPU": cpu, "cores (os.cpu_count)": str(os.cpu_count()), "memory": mem,
            "OS": platform.platform(), "Python": platform.python_version(),
            **{k: v for k, v in versions.items()},
            "OPENBLAS_CORETYPE": os.environ.get("OPENBLAS_CORETYPE", "(unset)"),
            "load average at the end (1, 5, 15 min)": ", ".join(f"{x:.2f}" for x in os.getloadavg())}


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b) / np.abs(b)))


def report(results: dict[str, dict[str, Any]], stages: dict[str, dict[str, float]], command: str) -> str:
    mb = 1e6
    lines = ["# Performance: load + mass properties of binary STL", "",
             f"Regenerate with `{command}` from the repository root (written by `benchmarks/mass.py`).", "",
             "Bodies: closed tori (R = 3, r = 1) as binary STL, two triangles per grid quad.  Whole processes:",
             "`inertia analyze FILE --json` (load, float32 weld, watertight and winding checks, exact",
             "multi-pass integration, JSON) against a script that imports trimesh, loads the file and reads",
             "`mass_properties` and `is_watertight`, and one that runs numpy-stl's `Mesh.from_file` +",
             "`get_mass_properties`.  Times and peak RSS (GNU time's maximum resident set of the tool's own process) are medians of the",
             "runs shown; numpy-stl runs once from 1e6 triangles up (its exact mass path takes minutes).", "",
             "## Whole process", "",
             "| triangles | file MB | inertia s | trimesh s | numpy-stl s | trimesh / inertia | numpy-stl / inertia "
             "| inertia peak MB | x file | trimesh peak MB | x file | numpy-stl peak MB | runs (ours, trimesh, numpy-stl) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for label, r in results.items():
        size = r["file_bytes"]
        t = {k: r[k]["wall"] for k in ("inertia", "trimesh", "numpy-stl")}
        m = {k: r[k]["rss"] for k in ("inertia", "trimesh", "numpy-stl")}
        runs = ", ".join(str(r[k]["runs"]) for k in ("inertia", "trimesh", "numpy-stl"))
        lines.append(
            f"| {r['triangles']:,} | {size / mb:.1f} | {t['inertia']:.3f} | {t['trimesh']:.3f} | {t['numpy-stl']:.2f} "
            f"| {t['trimesh'] / t['inertia']:.2f}x | {t['numpy-stl'] / t['inertia']:.1f}x "
            f"| {m['inertia'] / mb:.0f} | {m['inertia'] / size:.2f} | {m['trimesh'] / mb:.0f} | {m['trimesh'] / size:.2f} "
            f"| {m['numpy-stl'] / mb:.0f} | {runs} |")
    lines += ["", "Targets at 1e6 triangles: at least 3x faster than trimesh, peak memory at most 4x the file size.", ""]
    lines += ["## Where our time goes (in process, one `pipeline.analyze`, seconds)", ""]
    names: list[str] = []
    for st in stages.values():
        names += [n for n in st if n not in names]
    lines += ["| stage | " + " | ".join(stages) + " |", "|---|" + "---|" * len(stages)]
    for n in names:
        lines.append(f"| {n} | " + " | ".join(f"{st.get(n, 0.0):.4f}" for st in stages.values()) + " |")
    lines += ["", "The whole-process time also holds interpreter start-up and imports (~0.1 s).", ""]
    lines += ["## Accuracy (principal moments per unit density)", "",
              "No closed form exists for the tessellated torus, so the tools are compared with each other;",
              "`inertia` also reports its own rounding-error bound.", "",
              "| triangles | inertia moments | max rel. diff trimesh | max rel. diff numpy-stl | inertia error estimate |",
              "|---|---|---|---|---|"]
    for r in results.values():
        ours = r["inertia"]["moments"]
        lines.append(f"| {r['triangles']:,} | {', '.join(f'{x:.12g}' for x in ours)} "
                     f"| {_rel(r['trimesh']['moments'], ours):.1e} | {_rel(r['numpy-stl']['moments'], ours):.1e} "
                     f"| {r['inertia']['estimate']:.1e} |")
    lines += ["", "## Machine", "",
              "Wall times are only comparable within one run: a load average above the core count means",
              "other work shared the CPUs, which slows every tool (peak memory is unaffected).", ""] + [f"- {k}: {v}" for k, v in machine_info().items()] + [""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="only 1e4 and 1e5 triangles")
    parser.add_argument("--sizes", nargs="+", choices=list(SIZES), help="triangle counts to run")
    parser.add_argument("--repeat", type=int, default=3, help="runs per tool and size (median reported)")
    parser.add_argument("--out", default="docs/performance.md", help="report to write ('-' for stdout)")
    args = parser.parse_args(argv)
    sizes = args.sizes or (list(QUICK) if args.quick else list(SIZES))
    results: dict[str, dict[str, Any]] = {}
    stages: dict[str, dict[str, float]] = {}
    with tempfile.TemporaryDirectory(prefix="inertia-bench-") as tmp:
        for label in sizes:
            path = Path(tmp) / f"torus_{label}.stl"
            triangles = torus_stl(path, *SIZES[label])
            print(f"{label}: {triangles:,} triangles, {path.stat().st_size / 1e6:.1f} MB", file=sys.stderr, flush=True)
            r = measure_processes(path, triangles, args.repeat)
            r["triangles"], r["file_bytes"] = triangles, path.stat().st_size
            results[label] = r
            stages[label] = stage_breakdown(path)
            print("  " + ", ".join(f"{k} {r[k]['wall']:.3f} s {r[k]['rss'] / 1e6:.0f} MB"
                                   for k in ("inertia", "trimesh", "numpy-stl")), file=sys.stderr, flush=True)
            path.unlink()
    command = "python -m benchmarks.mass" + (" --quick" if args.quick and not args.sizes else "") \
        + (f" --sizes {' '.join(args.sizes)}" if args.sizes else "") \
        + (f" --repeat {args.repeat}" if args.repeat != 3 else "")
    text = report(results, stages, command)
    if args.out == "-":
        print(text)
    else:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(text)
        print(f"wrote {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
