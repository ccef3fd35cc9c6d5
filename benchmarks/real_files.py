"""Real files from public repositories: read right, refused with a reason, wrong, or crashed.

    python -m benchmarks.real_files            # every file under tests/data/real -> docs/real-files.md
    python -m benchmarks.real_files --check    # the same, exit 1 if any file is wrong or crashed

Each folder under ``tests/data/real/`` is a category; its README names each
file's source repository, path, commit and licence.  What each file must give
is in ``EXPECTED`` below: ``read`` (a solid whose numbers are compared with a
reference), or ``refuse`` (the file is broken, or one of the 3MF Consortium's
MUSTFAIL samples) with the error codes that are acceptable.

References, independent of the service's own readers and integrator:

- ``exact``: the file read by trimesh (its own readers, ``process=False``; a
  glTF scene flattened with its node transforms; a 3MF without the objects
  the 3MF specification does not weigh), vertices within 1e-11 of the part's
  diagonal merged by trimesh's own ``merge_vertices`` (the seams), then
  integrated exactly in rational arithmetic (``benchmarks/exact.py``): volume,
  centre and inertia tensor of the polyhedron for unit density.
- ``closed-form``: a cube of edge a: V = a^3, I = V a^2 / 6 about its centre.

Counted as **read right** when the mass agrees with the reference to 1e-9
relative and the tensor to 1e-9 of its norm (the seam merge moves vertices by
~1e-16 of the size, and trimesh rounds coordinates to merge them);
**refused** when the file is expected to be refused and the service answers
one of the expected error codes with a sentence; **wrong** when a number comes
back that disagrees with the reference, when a file that must be refused is
read, or when a readable file is refused; **crashed** when anything but the
service's own error escapes.
"""

from __future__ import annotations

import argparse
import functools
import io
import itertools
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.harness import Report, timed

ROOT = Path(__file__).resolve().parents[1]
REAL = ROOT / "tests" / "data" / "real"
OUT = ROOT / "docs" / "real-files.md"
TOL = 1e-9

READ = "read"
REFUSE = "refuse"
INVALID = ("unreadable_file",)
OPEN = ("not_watertight",)

# file (relative to tests/data/real) -> (expectation, reference or acceptable codes, companions, note)
EXPECTED: dict[str, tuple[str, Any, tuple[str, ...], str]] = {
    "seams/angle_block.STL": (READ, "exact", (), "SolidWorks export: seams a rounding apart"),
    "seams/featuretype.STL": (READ, "exact", (), "SolidWorks export: seams a rounding apart"),
    "seams/idler_riser.STL": (READ, "exact", (), "SolidWorks export: seams a rounding apart"),
    "seams/octagonal_pocket.stl": (READ, "exact", (), "CAD export: seams a rounding apart"),
    "grouped_obj/groups.obj": (READ, "exact", (), "one closed surface split into open g groups"),
    "grouped_obj/two_objects.obj": (READ, "exact", (), "two closed o objects"),
    "grouped_obj/joined_tetrahedra.obj": (READ, "exact", (), "two tetrahedra"),
    "grouped_obj/negative_indices.obj": (READ, "exact", (), "relative (negative) face indices"),
    "gltf_multi/rgb_cube_with_primitives.gltf": (READ, "exact", (), "one cube split into three open primitives"),
    "gltf_multi/nested.glb": (READ, "exact", (), "node hierarchy with scales"),
    "gltf_multi/TestScene.gltf": (
        REFUSE,
        OPEN,
        ("TestScene.bin",),
        ".gltf with its .bin in one upload; its scene holds an open plane",
    ),
    "3mf/box.3mf": (READ, "exact", (), "core"),
    "3mf/cylinder.3mf": (READ, "exact", (), "core"),
    "3mf/multiple_cylinders.3mf": (READ, "exact", (), "core, several build items"),
    "3mf/torus.3mf": (READ, "exact", (), "core"),
    "3mf/box_prod.3mf": (READ, "exact", (), "Production extension: objects in separate model parts"),
    "3mf/sphere_prod.3mf": (READ, "exact", (), "Production extension: objects in separate model parts"),
    "3mf/sphere.3mf": (READ, "exact", (), "core"),
    "3mf/cube_gears.3mf": (READ, "exact", (), "core, 17 objects: gears that touch without overlapping"),
    "3mf/heartgears.3mf": (READ, "exact", (), "core, several objects"),
    "3mf/dodeca_chain_loop.3mf": (READ, "exact", (), "core, a loop of interlinked chain links"),
    "broken/featuretype.3MF": (REFUSE, OPEN, (), "T-junctions: 18 open edges that no merge closes"),
    "broken/teapot.stl": (REFUSE, OPEN, (), "open surface"),
    "broken/soup.stl": (REFUSE, OPEN, (), "triangle soup"),
    "broken/notenoughindices.obj": (REFUSE, INVALID, (), "a face with two corners"),
    "broken/empty_nodes.glb": (REFUSE, ("empty_geometry",), (), "nodes without meshes"),
}
# the 3MF Consortium's conformance samples: MUSTPASS read, MUSTFAIL refused
for _p in sorted((REAL / "3mf" / "mustpass").glob("*.3mf")):
    EXPECTED[f"3mf/mustpass/{_p.name}"] = (READ, "exact", (), "3MF Consortium MUSTPASS")
for _p in sorted((REAL / "3mf" / "mustfail").glob("*.3mf")):
    EXPECTED[f"3mf/mustfail/{_p.name}"] = (
        REFUSE,
        ("unreadable_file", "external_reference", "not_watertight", "unsupported_format"),
        (),
        "3MF Consortium MUSTFAIL",
    )
# MUSTFAIL 3.4.1a (an unprefixed metadata name outside the well-known list) contradicts MUSTPASS 3.4.1c
# (which must ignore such a name): metadata never changes the solid, so both are read, and this is said
EXPECTED["3mf/mustfail/MUSTFAIL_Chapter3.4.1a_MissingMetadataName.3mf"] = (
    READ,
    "exact",
    (),
    "MUSTFAIL contradicted by MUSTPASS 3.4.1c: read, metadata ignored",
)
# other folders may state their own expectations in an expected.json beside their files:
#   {"file": {"expect": "read" | "refuse", "codes": [...], "volume": V, "rtol": r, "companions": [...], "note": "..."}}
# ("reference": "exact" instead of "volume": the exact reference below, from trimesh's reading)
# ("volume" in file units for unit density: a reference computed elsewhere, e.g. by VTK, named in the README)
# an entry may also say "known": why the service still answers it wrong (listed in the report, and the test
# expects "wrong" so that it notices the day it is fixed)
KNOWN: dict[str, str] = {}
for _manifest in sorted(REAL.glob("*/expected.json")):
    for _name, _entry in json.loads(_manifest.read_text()).items():
        _rel = f"{_manifest.parent.name}/{_name}"
        if _entry.get("known"):
            KNOWN[_rel] = str(_entry["known"])
        if _entry.get("expect") == REFUSE:
            EXPECTED[_rel] = (
                REFUSE,
                tuple(_entry.get("codes", INVALID)),
                tuple(_entry.get("companions", ())),
                _entry.get("note", ""),
            )
        elif _entry.get("reference") == "exact":  # a surface file: trimesh's reading integrated exactly
            EXPECTED[_rel] = (READ, "exact", tuple(_entry.get("companions", ())), _entry.get("note", ""))
        else:
            EXPECTED[_rel] = (
                READ,
                {"volume": float(_entry["volume"]), "rtol": float(_entry.get("rtol", TOL))},
                tuple(_entry.get("companions", ())),
                _entry.get("note", ""),
            )
# references computed by another program, beside the files: {"file": {"volume": V, "inertia_unit_density": 3x3, ...}}
# (e.g. quadratic/gmsh_reference.json, Gmsh's own integration; vtk/vtk_reference.json, VTK's own cells, written by
# benchmarks/real_references.py), compared to REFERENCE_TOL or to the entry's own "rtol" where it states a coarser one
REFERENCE_TOL = 1e-10
for _refs in sorted(REAL.glob("*/*reference*.json")):
    for _name, _entry in json.loads(_refs.read_text()).items():
        _rel = f"{_refs.parent.name}/{_name}"
        if _rel not in EXPECTED and isinstance(_entry, dict) and "volume" in _entry:
            EXPECTED[_rel] = (
                READ,
                {
                    "volume": float(_entry["volume"]),
                    "rtol": float(_entry.get("rtol", REFERENCE_TOL)),
                    "tensor": _entry.get("inertia_unit_density"),
                    "source": _refs.name,
                },
                (),
                "",
            )
# any other model file is still read and counted ("no reference") so that nothing in the folder goes unrun
_COMPANION = {".bin", ".node", ".json", ".md", ".png", ".txt"}
for _path in sorted(REAL.glob("*/*")):
    _rel = f"{_path.parent.name}/{_path.name}"
    if _path.is_file() and _path.suffix.lower() not in _COMPANION and _rel not in EXPECTED:
        EXPECTED[_rel] = (READ, None, (), "no reference")
# objects that the 3MF specification does not weigh, by trimesh's geometry name, for the reference
_NOT_WEIGHED = {"3mf/mustpass/MUSTPASS_Chapter4.1_ExplicitSupport.3mf": ("2",)}


@dataclass
class Row:
    path: str
    fmt: str
    outcome: str  # "read right", "refused", "wrong", "crashed"
    detail: str
    reference: str


def reference(path: Path, rel: str, companions: tuple[str, ...]) -> tuple[float, np.ndarray]:
    """Volume and inertia tensor about the centre (unit density) of the file as trimesh reads it, exactly."""
    import trimesh

    from benchmarks.exact import exact_solid

    kwargs: dict[str, Any] = {}
    if companions:
        kwargs["resolver"] = trimesh.resolvers.ZipResolver({c: (path.parent / c).read_bytes() for c in companions})
    ext = path.suffix.lower().lstrip(".")
    scene = trimesh.load_scene(io.BytesIO(path.read_bytes()), file_type=ext, process=False, **kwargs)
    skip = _NOT_WEIGHED.get(rel, ())
    verts, faces, offset = [], [], 0
    edges, root = scene.graph.transforms, scene.graph.base_frame
    for node in scene.graph.nodes_geometry:
        if ext in ("gltf", "glb"):
            # the edges' matrices multiplied from the root, as glTF composes nodes: trimesh's graph[node] snaps a
            # world matrix within 1e-5 of a rotation to it and drops edges within 1e-8 of the identity (a 3MF
            # rotation written to few digits is snapped by our reader too, with a warning)
            chain: list[Any] = edges.shortest_path(root, node)
            transform = functools.reduce(
                np.matmul, (edges.edge_data[pair].get("matrix", np.eye(4)) for pair in itertools.pairwise(chain)), np.eye(4)
            )
            name = edges.node_data[node]["geometry"]
        else:
            transform, name = scene.graph[node]
        geom = scene.geometry[name]
        if not isinstance(geom, trimesh.Trimesh) or any(str(name).endswith(s) or str(node) == s for s in skip):
            continue
        v = np.asarray(geom.vertices, dtype=np.float64) @ np.asarray(transform)[:3, :3].T + np.asarray(transform)[:3, 3]
        f = np.asarray(geom.faces, dtype=np.int64)
        if np.linalg.det(np.asarray(transform)[:3, :3]) < 0:
            f = f[:, [0, 2, 1]]
        verts.append(v)
        faces.append(f + offset)
        offset += len(v)
    mesh = trimesh.Trimesh(np.concatenate(verts), np.concatenate(faces), process=False)
    diag = float(np.linalg.norm(np.ptp(mesh.vertices, axis=0)))
    mesh.merge_vertices(digits_vertex=max(0, int(-np.floor(np.log10(1e-11 * diag)))))
    if not mesh.is_winding_consistent:
        trimesh.repair.fix_winding(mesh)
    volume, _, tensor = exact_solid(mesh.vertices, mesh.faces)
    sign = 1.0 if volume > 0 else -1.0
    return sign * float(volume), sign * np.array([[float(x) for x in row] for row in tensor])


def run_one(rel: str) -> Row:
    from inertia.errors import ServiceError
    from inertia.load import load_body
    from inertia.pipeline import AnalysisOptions, analyze_loaded

    expect, ref_kind, companions, _note = EXPECTED[rel]
    path = REAL / rel
    fmt = path.suffix.lower().lstrip(".")
    source: Any = path.read_bytes()
    if companions:
        source = [(path.name, source), *((c, (path.parent / c).read_bytes()) for c in companions)]
    try:
        loaded = load_body(source, filename=path.name, units="m")  # file units: compared as written
        doc = analyze_loaded(loaded, AnalysisOptions(units="m", density=1.0)).as_dict()
    except ServiceError as exc:
        if expect == REFUSE and exc.code in ref_kind:
            return Row(rel, fmt, "refused", f"`{exc.code}`: {exc.message}", "expected refusal")
        return Row(rel, fmt, "wrong", f"refused a readable file: `{exc.code}`: {exc.message}", "-")
    except BaseException as exc:
        return Row(rel, fmt, "crashed", f"{type(exc).__name__}: {str(exc)[:200]}", "-")
    if expect == REFUSE:
        return Row(rel, fmt, "wrong", f"read (mass {doc['mass']:.6g}) though it must be refused", "expected refusal")
    if ref_kind is None:
        return Row(rel, fmt, "read, no reference", f"volume {doc['mass']:.10g}", "-")
    if isinstance(ref_kind, dict):  # computed by another program (a *reference*.json or expected.json)
        err = abs(doc["mass"] - ref_kind["volume"]) / abs(ref_kind["volume"])
        detail = f"volume {doc['mass']:.10g}, rel. error {err:.1e}"
        ok = err <= ref_kind["rtol"]
        if ref_kind.get("tensor") is not None:
            ref_t = np.asarray(ref_kind["tensor"], dtype=np.float64)
            t_err = float(np.max(np.abs(np.asarray(doc["inertia_tensor"]) - ref_t)) / np.linalg.norm(ref_t))
            detail += f", tensor {t_err:.1e}"
            ok = ok and t_err <= ref_kind["rtol"]
        return Row(rel, fmt, "read right" if ok else "wrong", detail, ref_kind.get("source", "expected.json"))
    volume, tensor = reference(path, rel, companions)
    mass_err = abs(doc["mass"] - volume) / abs(volume)
    t_err = float(np.max(np.abs(np.asarray(doc["inertia_tensor"]) - tensor)) / np.linalg.norm(tensor))
    warnings = "; ".join(w for w in doc["warnings"] if "length unit" not in w and "declares no length unit" not in w)
    detail = f"volume {volume:.10g}, rel. error {mass_err:.1e}, tensor {t_err:.1e}" + (f"; {warnings[:160]}" if warnings else "")
    outcome = "read right" if mass_err <= TOL and t_err <= TOL else "wrong"
    return Row(rel, fmt, outcome, detail, "exact rational integration of trimesh's reading")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if any file is wrong or crashed")
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args(argv)
    rows, timing = timed(lambda: [run_one(rel) for rel in sorted(EXPECTED)])
    render(rows, timing.wall_s).write(args.out)
    bad = [r for r in rows if r.outcome in ("wrong", "crashed")]
    for r in bad:
        print(f"{r.outcome}: {r.path}: {r.detail}")
    print(f"{len(rows)} files, {len(bad)} wrong or crashed -> {args.out}")
    return 1 if (args.check and bad) else 0


def render(rows: list[Row], elapsed: float) -> Report:
    outcomes = ("read right", "read, no reference", "refused", "wrong", "crashed")
    by_fmt: dict[str, dict[str, int]] = {}
    for r in rows:
        by_fmt.setdefault(r.fmt, dict.fromkeys(outcomes, 0))[r.outcome] += 1
    report = Report("Real files", "python -m benchmarks.real_files")
    lines = [
        f"Generated by `{report.regenerate}` over `tests/data/real/` (each folder's README gives every "
        "file's source repository, path, commit and licence). Targets: 0 wrong, 0 crashed.",
        "",
        "References: **exact** = the file read by trimesh's own readers (glTF nodes flattened with their transforms, "
        "3MF objects the specification does not weigh left out), vertices within 1e-11 of the diagonal merged by "
        "trimesh, then integrated exactly in rational arithmetic (`benchmarks/exact.py`); a number is *read right* when "
        f"mass (unit density, file units) and inertia tensor agree to {TOL:g}. *Refused* means the file is broken "
        "or a 3MF Consortium MUSTFAIL sample and the service answered an error code with a sentence. Volume meshes, "
        "CAD files and the files trimesh cannot read "
        f"are compared to a reference file beside them to {REFERENCE_TOL:g}, or to the precision the reference states: "
        "Gmsh's own integration (`quadratic/`), VTK's own readers and cell interpolation (`vtk/`, `vtu/`), Gmsh's "
        "OpenCASCADE mass properties (`step/`), lib3mf's reading (`3mf_production/`, single precision: 1e-06), all "
        "written by `python -m benchmarks.real_references` except `quadratic/` (its README).",
        "",
        "| format | read right | read, no reference | refused with reason | wrong | crashed |",
        "| --- | ---: | ---: | ---: | ---: | ---: |",
    ]
    for fmt in sorted(by_fmt):
        c = by_fmt[fmt]
        lines.append(f"| {fmt} | {c['read right']} | {c['read, no reference']} | {c['refused']} | {c['wrong']} | {c['crashed']} |")
    total = {o: sum(c[o] for c in by_fmt.values()) for o in outcomes}
    lines.append(
        f"| **all** | **{total['read right']}** | **{total['read, no reference']}** | **{total['refused']}** | "
        f"**{total['wrong']}** | "
        f"**{total['crashed']}** |"
    )
    lines += [
        "",
        f"{len(rows)} files in {elapsed:.1f} s.",
        "",
        "Known deviation: MUSTFAIL 3.4.1a (a metadata name outside the well-known list) is read, because "
        "MUSTPASS 3.4.1c requires such a name to be ignored; metadata never changes the solid.",
        "",
        "## Every file",
        "",
        "| file | outcome | what came back | reference |",
        "| --- | --- | --- | --- |",
    ]
    if KNOWN:
        lines[-5:-5] = [
            "",
            "Known wrong (kept in the corpus until fixed):",
            "",
            *(f"- `{rel}`: {why}" for rel, why in sorted(KNOWN.items())),
        ]
    for r in rows:
        detail = r.detail.replace("|", "\\|").replace("\n", " ")
        lines.append(f"| `{r.path}` | {r.outcome} | {detail} | {r.reference} |")
    report.add(*lines)
    return report


if __name__ == "__main__":
    raise SystemExit(main())
