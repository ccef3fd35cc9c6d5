"""Load + mass properties of binary STL files: ours against trimesh and numpy-stl.

    python -m benchmarks.mass            # 1e4, 1e5, 1e6, 5e6, 2e7 triangles -> docs/performance.md
    python -m benchmarks.mass --quick    # 1e4, 1e5 only (a smoke run)
    python -m benchmarks.mass --sizes 2e7 --repeat 1 --out docs/performance-2e7.md   # the 1 GB file alone

2e7 triangles (a 1 GB file) runs a tool only where the machine has the
memory it needs free (trimesh needs ~12x the file size); otherwise the cell
says it was skipped and why.

Test bodies are closed tori (R = 3, r = 1, a u-by-v grid, two triangles per
quad) written as binary STL into a temporary directory.  Three measurements
in the same run:

(a) whole processes, as a user meets them: ``inertia analyze FILE --json``
    (load, weld, watertight check, exact multi-pass integration, JSON)
    against a script that imports trimesh, loads the file and reads
    ``mass_properties`` and ``is_watertight``, and one that calls numpy-stl's
    ``Mesh.from_file`` + ``get_mass_properties``.  Wall time and peak RSS
    (GNU time's %M for the tool's own process, else ``os.wait4``) and CPU time are
    the best of ``--repeat`` interleaved rounds (the tools' order alternates),
    with the spread of the wall times shown: the machine may be shared.
(b) our stages in process (read + weld of the STL, edge topology, the signed
    volumes with the first integration pass, outward orientation, each further
    integration pass), timed by
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
import sys
import tempfile
from collections import defaultdict
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.cases import torus, triangles_stl_bytes
from benchmarks.harness import Report, Stopwatch, available_memory, cpu_model, run_tool

SIZES = {"1e4": (100, 50), "1e5": (250, 200), "1e6": (1000, 500), "5e6": (2500, 1000), "2e7": (5000, 2000)}
QUICK = ("1e4", "1e5")
SLOW_NUMPY_STL = 1_000_000  # numpy-stl's exact mass path takes ~36 s at 1e6: one run there
NO_NUMPY_STL = 1_000_000  # ... and minutes from 1e6 up (36 s quiet, minutes on a busy machine): not run
# peak memory of each tool as a multiple of the file size (measured at 1e6-5e6), to decide whether a run fits
MEMORY_FACTOR = {"inertia": 3.5, "trimesh": 13.0, "numpy-stl": 36.0}
MEMORY_MARGIN = 8 << 30  # left free for everyone else on the machine (shared)

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
    v, faces = torus(nu, nv, major, minor)
    path.write_bytes(triangles_stl_bytes(v.astype("<f4")[faces], b"benchmarks.mass torus".ljust(80, b" ")))
    return len(faces)


def tool_commands(path: Path) -> dict[str, list[str]]:
    py = sys.executable
    inertia = Path(py).with_name("inertia")
    ours = [str(inertia)] if inertia.exists() else [py, "-m", "inertia"]
    return {
        "inertia": [*ours, "analyze", str(path), "--json"],
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


def compile_bytecode() -> list[str]:
    """Compile every contender's modules to bytecode, as ``pip install`` does, where it is missing or stale.

    An installed wheel (trimesh, numpy-stl) has its bytecode from the install.  Our package run from
    an editable checkout under ``PYTHONDONTWRITEBYTECODE`` would instead compile its modules on every
    run (~0.05-0.1 s of each process); compiling them here measures what an installed user runs.
    Returns the packages whose bytecode could not be written (read-only), which then run as they are.
    """
    import compileall
    import importlib.util

    unwritten = []
    for name in ("inertia", "trimesh", "stl"):
        spec = importlib.util.find_spec(name)
        if spec is None or not spec.submodule_search_locations:
            continue
        for folder in spec.submodule_search_locations:
            if not compileall.compile_dir(folder, quiet=2):
                unwritten.append(name)
    return unwritten


def measure_processes(path: Path, triangles: int, repeat: int) -> dict[str, dict[str, Any]]:
    """Every tool on ``path``, ``repeat`` interleaved rounds (the order alternates); the best of each."""
    out: dict[str, dict[str, Any]] = {}
    commands = tool_commands(path)
    size = path.stat().st_size
    for tool in commands:
        need = MEMORY_FACTOR[tool] * size
        if tool == "numpy-stl" and triangles >= NO_NUMPY_STL:
            out[tool] = {"skipped": "not run (its exact mass path takes minutes from 1e6 triangles)"}
        elif available_memory() < need + MEMORY_MARGIN:
            out[tool] = {"skipped": f"not run: needs ~{need / 2**30:.1f} GiB, {available_memory() / 2**30:.1f} GiB available"}
        else:
            out[tool] = {"walls": [], "rss": [], "cpu": []}
    for r in range(repeat):
        order = [t for t in commands if "skipped" not in out[t]]
        for tool in order if r % 2 == 0 else order[::-1]:
            if tool == "numpy-stl" and triangles >= SLOW_NUMPY_STL and out[tool]["walls"]:
                continue
            run = run_tool(commands[tool])
            wall, peak, stdout, cpu = run.wall_s, run.peak_rss_bytes, run.stdout, run.cpu_s
            out[tool]["walls"].append(wall)
            out[tool]["rss"].append(peak)
            out[tool]["cpu"].append(cpu)
            out[tool]["stdout"] = stdout
    for res in out.values():
        if "skipped" in res:
            continue
        res["wall"], res["rss"], res["cpu_s"], res["runs"] = min(res["walls"]), min(res["rss"]), min(res["cpu"]), len(res["walls"])
    for tool, res in out.items():
        if "skipped" not in res:
            res["moments"], res["estimate"] = principal_per_density(tool, res.pop("stdout"))
    return out


def stage_breakdown(path: Path, warmup: Path) -> dict[str, float]:
    """Seconds per stage of one in-process ``pipeline.analyze`` (after a warm-up run on a small file)."""
    import inertia.load.stl as stl
    import inertia.mass.geometry as mass_geometry
    import inertia.solid as solid
    from inertia import pipeline

    times: dict[str, float] = defaultdict(float)
    passes = [0]

    def timed(name: str | Callable[[], str], fn: Callable[..., Any]) -> Callable[..., Any]:
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            clock = Stopwatch()
            try:
                return fn(*args, **kwargs)
            finally:
                times[name() if callable(name) else name] += clock.wall_s

        return wrapper

    def pass_name() -> str:
        passes[0] += 1
        if passes[0] == 1:  # a closed surface's first pass is formed with its signed volumes, and only handed over here
            return "integration pass 1, where not formed with the volumes"
        return f"integration pass {passes[0]}"

    patches: list[tuple[Any, str, str | Callable[[], str]]] = [
        (stl, "read_stl_file", "read STL + float32 weld"),
        (solid, "surface_topology", "edge topology (watertight check)"),
        (solid, "_volumes_and_first_pass", "signed volumes + integration pass 1 (one gather)"),
        (solid, "_orient_outward", "outward orientation"),
        (mass_geometry.Geometry, "sums", pass_name),
    ]
    saved = [(obj, attr, getattr(obj, attr)) for obj, attr, _ in patches]
    try:
        for obj, attr, name in patches:
            setattr(obj, attr, timed(name, getattr(obj, attr)))
        pipeline.analyze(str(warmup))  # warm-up: lazy imports
        times.clear()
        passes[0] = 0
        clock = Stopwatch()
        pipeline.analyze(str(path))
        total = clock.wall_s
    finally:
        for obj, attr, fn in saved:
            setattr(obj, attr, fn)
    staged = dict(times)
    staged["rest (file read, body checks, eigen, JSON)"] = total - sum(staged.values())
    staged["total analyze()"] = total
    return staged


def machine_info() -> dict[str, str]:
    cpu = cpu_model()
    mem = ""
    try:
        kb = int(Path("/proc/meminfo").read_text().split()[1])
        mem = f"{kb / 2**20:.1f} GiB"
    except (OSError, ValueError, IndexError):
        pass
    versions = {}
    for name in ("numpy", "trimesh", "numpy-stl"):
        try:
            versions[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:  # numpy-stl is only needed below 1e6 triangles
            versions[name] = "not installed"
    return {
        "CPU": cpu,
        "cores (os.cpu_count)": str(os.cpu_count()),
        "memory": mem,
        "OS": platform.platform(),
        "Python": platform.python_version(),
        **{k: v for k, v in versions.items()},
        "OPENBLAS_CORETYPE": os.environ.get("OPENBLAS_CORETYPE", "(unset)"),
        "load average at the end (1, 5, 15 min)": ", ".join(f"{x:.2f}" for x in os.getloadavg()),
    }


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b) / np.abs(b)))


def _cell(r: dict[str, Any], key: str, fmt: str, scale: float = 1.0) -> str:
    return "skipped" if "skipped" in r else format(r[key] / scale, fmt)


def report(results: dict[str, dict[str, Any]], stages: dict[str, dict[str, float]], command: str) -> Report:
    mb = 1e6
    tools = ("inertia", "trimesh", "numpy-stl")
    out = Report("Performance: load + mass properties of binary STL", command)
    lines = [
        f"Regenerate with `{command}` from the repository root (written by `benchmarks/mass.py`).",
        "",
        "Bodies: closed tori (R = 3, r = 1) as binary STL, two triangles per grid quad.  Whole processes:",
        "`inertia analyze FILE --json` (load, float32 weld, watertight and winding checks, exact",
        "multi-pass integration, JSON) against a script that imports trimesh, loads the file and reads",
        "`mass_properties` and `is_watertight`, and one that runs numpy-stl's `Mesh.from_file` +",
        "`get_mass_properties`.  Rounds are interleaved (the tools' order alternates); wall time, CPU time",
        "(user + system) and peak RSS (GNU time's maximum resident set of the tool's own process) are the",
        "best of the runs shown, and *spread* is the slowest run over the fastest, a measure of how much",
        "the shared machine disturbed the run. numpy-stl runs only up to 1e5 triangles",
        "(its exact mass path takes minutes). Every tool runs from compiled bytecode, as after `pip install`",
        "(the benchmark compiles any module whose bytecode is missing or stale first).",
        "",
        "## Whole process",
        "",
        "| triangles | file MB | inertia s | inertia CPU s | trimesh s | trimesh CPU s | numpy-stl s "
        "| trimesh / inertia (wall) | trimesh / inertia (CPU) | numpy-stl / inertia "
        "| inertia peak MB | x file | trimesh peak MB | x file | numpy-stl peak MB | runs (ours, trimesh, numpy-stl) "
        "| spread (ours, trimesh) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    skipped: list[str] = []
    for r in results.values():
        size = r["file_bytes"]
        ours, tm, ns = (r[k] for k in tools)
        runs = ", ".join(str(r[k].get("runs", 0)) for k in tools)
        ratio = f"{tm['wall'] / ours['wall']:.2f}x" if "skipped" not in tm and "skipped" not in ours else "skipped"
        cpu_ratio = f"{tm['cpu_s'] / ours['cpu_s']:.2f}x" if "skipped" not in tm and "skipped" not in ours else "skipped"
        ns_ratio = f"{ns['wall'] / ours['wall']:.1f}x" if "skipped" not in ns and "skipped" not in ours else "skipped"
        spread = ", ".join(f"{max(x['walls']) / min(x['walls']):.2f}" if "skipped" not in x else "-" for x in (ours, tm))
        lines.append(
            f"| {r['triangles']:,} | {size / mb:.1f} | {_cell(ours, 'wall', '.3f')} | {_cell(ours, 'cpu_s', '.2f')} "
            f"| {_cell(tm, 'wall', '.3f')} | {_cell(tm, 'cpu_s', '.2f')} | {_cell(ns, 'wall', '.2f')} "
            f"| {ratio} | {cpu_ratio} | {ns_ratio} "
            f"| {_cell(ours, 'rss', '.0f', mb)} | {_cell(ours, 'rss', '.2f', size)} | {_cell(tm, 'rss', '.0f', mb)} "
            f"| {_cell(tm, 'rss', '.2f', size)} | {_cell(ns, 'rss', '.0f', mb)} | {runs} | {spread} |"
        )
        skipped += [f"- {r['triangles']:,} triangles, {k}: {r[k]['skipped']}" for k in tools if "skipped" in r[k]]
    lines += [""]
    if skipped:
        lines += ["Not run:", "", *skipped, ""]
    lines += [
        "Targets: at least 5x faster than trimesh at 1e6 triangles and 4x at 5e6, whole processes; peak memory "
        "at most 3x the file size.",
        "",
    ]
    lines += ["## Where our time goes (in process, one `pipeline.analyze`, seconds)", ""]
    names: list[str] = []
    for st in stages.values():
        names += [n for n in st if n not in names]
    lines += ["| stage | " + " | ".join(stages) + " |", "|---|" + "---|" * len(stages)]
    for n in names:
        lines.append(f"| {n} | " + " | ".join(f"{st.get(n, 0.0):.4f}" for st in stages.values()) + " |")
    lines += [
        "",
        "The whole-process time also holds interpreter start-up and imports (0.15-0.2 s: Python, numpy, our modules).",
        "",
    ]
    lines += [
        "## Accuracy (principal moments per unit density)",
        "",
        "No closed form exists for the tessellated torus, so the tools are compared with each other;",
        "`inertia` also reports its own rounding-error bound.",
        "",
        "| triangles | inertia moments | max rel. diff trimesh | max rel. diff numpy-stl | inertia error estimate |",
        "|---|---|---|---|---|",
    ]
    for r in results.values():
        if "skipped" in r["inertia"]:
            continue
        ours = r["inertia"]["moments"]
        diffs = [f"{_rel(r[k]['moments'], ours):.1e}" if "skipped" not in r[k] else "not run" for k in ("trimesh", "numpy-stl")]
        lines.append(
            f"| {r['triangles']:,} | {', '.join(f'{x:.12g}' for x in ours)} "
            f"| {diffs[0]} | {diffs[1]} | {r['inertia']['estimate']:.1e} |"
        )
    lines += [
        "",
        "## Machine",
        "",
        "Wall times are only comparable within one run: a load average above the core count means",
        "other work shared the CPUs, which slows every tool (peak memory is unaffected).",
        "",
        *[f"- {k}: {v}" for k, v in machine_info().items()],
    ]
    out.add(*lines)
    return out


def main(argv: list[str] | None = None) -> int:
    global MEMORY_MARGIN
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="only 1e4 and 1e5 triangles")
    parser.add_argument("--sizes", nargs="+", choices=list(SIZES), help="triangle counts to run")
    parser.add_argument("--repeat", type=int, default=3, help="runs per tool and size (median reported)")
    parser.add_argument("--out", default="docs/performance.md", help="report to write ('-' for stdout)")
    parser.add_argument(
        "--memory-margin",
        type=float,
        default=8.0,
        help="GiB of memory to leave free for the rest of the machine; a tool that would leave less is not run",
    )
    args = parser.parse_args(argv)
    MEMORY_MARGIN = int(args.memory_margin * 2**30)
    sizes = args.sizes or (list(QUICK) if args.quick else list(SIZES))
    results: dict[str, dict[str, Any]] = {}
    stages: dict[str, dict[str, float]] = {}
    for name in compile_bytecode():
        print(f"{name}: its bytecode could not be written; it runs as installed", file=sys.stderr)
    with tempfile.TemporaryDirectory(prefix="inertia-bench-") as tmp:
        warmup = Path(tmp) / "warmup.stl"
        torus_stl(warmup, *SIZES["1e4"])
        for label in sizes:
            path = Path(tmp) / f"torus_{label}.stl"
            triangles = torus_stl(path, *SIZES[label])
            print(f"{label}: {triangles:,} triangles, {path.stat().st_size / 1e6:.1f} MB", file=sys.stderr, flush=True)
            r: dict[str, Any] = dict(measure_processes(path, triangles, args.repeat))
            r["triangles"], r["file_bytes"] = triangles, path.stat().st_size
            results[label] = r
            if "skipped" not in r["inertia"]:
                stages[label] = stage_breakdown(path, warmup)
            print(
                "  "
                + ", ".join(
                    f"{k} {r[k]['wall']:.3f} s {r[k]['rss'] / 1e6:.0f} MB" if "skipped" not in r[k] else f"{k} skipped"
                    for k in ("inertia", "trimesh", "numpy-stl")
                ),
                file=sys.stderr,
                flush=True,
            )
            path.unlink()
    command = (
        "python -m benchmarks.mass"
        + (" --quick" if args.quick and not args.sizes else "")
        + (f" --sizes {' '.join(args.sizes)}" if args.sizes else "")
        + (f" --repeat {args.repeat}" if args.repeat != 3 else "")
        + (f" --out {args.out}" if args.out not in ("docs/performance.md", "-") else "")
        + (f" --memory-margin {args.memory_margin:g}" if args.memory_margin != 8 else "")
    )
    doc = report(results, stages, command)
    if args.out == "-":
        print(doc.text())
    else:
        doc.write(Path(args.out))
        print(f"wrote {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
