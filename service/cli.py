"""Command line: ``inertia analyze | batch | serve``, a thin front end over the pipeline.

Errors are printed to stderr in the API's envelope and the exit status comes
from ``EXIT_CODES``.
"""

from __future__ import annotations

import argparse
import gc
import json
import sys
from collections.abc import Sequence
from typing import Any

from .errors import InvalidParameterError, ServiceError

__all__ = ["main", "EXIT_CODES"]

EXIT_CODES = {
    "invalid_parameter": 2,
    "unsupported_format": 3,
    "unreadable_file": 3,
    "empty_geometry": 3,
    "not_watertight": 4,
    "zero_volume": 4,
    "timeout": 5,
}
EXIT_INTERNAL = 1


def _triple(text: str) -> tuple[float, float, float]:
    parts = text.replace(" ", "").split(",")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"expected x,y,z but got {text!r}")
    try:
        return (float(parts[0]), float(parts[1]), float(parts[2]))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected three numbers x,y,z but got {text!r}") from None


def add_analysis_options(p: argparse.ArgumentParser) -> None:
    """Options shared by ``analyze`` and ``batch`` (the API's query parameters)."""
    p.add_argument("--format", help="file format; inferred from the name when absent")
    p.add_argument("--units", help="length unit of the file: m, cm, mm, um, in, ft (default: the file's, else m)")
    group = p.add_mutually_exclusive_group()
    group.add_argument("--density", type=float, help="density in kg/m^3 (default 1000)")
    group.add_argument("--mass", type=float, help="total mass in kg (density is derived)")
    p.add_argument("--model", choices=("solid", "shell"), default="solid", help="closed solid or thin shell")
    p.add_argument("--thickness", type=float, help="shell wall thickness, in the file's units")
    p.add_argument("--tolerance", type=float, default=1e-6, help="relative tolerance for equal moments")
    p.add_argument("--reference", type=_triple, help="x,y,z point (file units): also report the tensor about it")
    p.add_argument("--densities", help="JSON file: part name -> density (kg/m^3) for files of several parts")
    p.add_argument("--geometry", choices=("brep", "mesh"), default="brep",
                   help="CAD files: integrate the exact B-rep (default) or a tessellation of it")
    p.add_argument("--deflection", type=float,
                   help="with --geometry mesh: chordal deflection relative to the bounding-box diagonal (default 1e-3)")


def options_from_args(args: argparse.Namespace) -> Any:
    from .pipeline import AnalysisOptions

    densities = None
    if getattr(args, "densities", None):
        try:
            with open(args.densities, encoding="utf-8") as fh:
                densities = json.load(fh)
        except (OSError, json.JSONDecodeError) as exc:
            raise InvalidParameterError(f"cannot read --densities {args.densities!r}: {exc}") from exc
        if not isinstance(densities, dict):
            raise InvalidParameterError("--densities must hold a JSON object: part name -> density")
    return AnalysisOptions(
        format=args.format,
        units=args.units,
        density=args.density,
        mass=args.mass,
        model=args.model,
        thickness=args.thickness,
        tolerance=args.tolerance,
        reference=args.reference,
        omega=getattr(args, "omega", None),
        duration=getattr(args, "duration", None),
        samples=getattr(args, "samples", None),
        method=getattr(args, "method", "exact"),
        densities=densities,
        geometry=getattr(args, "geometry", "brep"),
        deflection=getattr(args, "deflection", None),
    )


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="inertia", description="Mass properties and free rotation of rigid bodies.")
    sub = parser.add_subparsers(dest="command", required=True)

    a = sub.add_parser("analyze", help="analyse one mesh or points file (.json/.csv)")
    a.add_argument("file")
    add_analysis_options(a)
    a.add_argument("--omega", type=_triple, help="wx,wy,wz initial angular velocity, rad/s, input frame")
    a.add_argument("--duration", type=float, help="seconds of motion to predict (with --omega and --samples)")
    a.add_argument("--samples", type=int, help="number of time samples of the trajectory")
    a.add_argument("--method", default="exact", choices=("exact", "dop853", "rk45", "splitting"))
    a.add_argument("--json", action="store_true", help="print the API's JSON instead of a table")

    b = sub.add_parser("batch", help="analyse many files, folders or .zip archives into JSONL/CSV/Parquet")
    b.add_argument("paths", nargs="+")
    b.add_argument("--out", required=True, help="results file: .jsonl, .csv or .parquet")
    b.add_argument("--resume", action="store_true", help="skip files that already have a line in --out")
    b.add_argument("--workers", type=int, help="local worker processes (default: the number of cores)")
    b.add_argument("--scheduler", help="address of an existing dask.distributed scheduler")
    b.add_argument("--no-progress", action="store_true", help="do not show the progress bar")
    add_analysis_options(b)

    s = sub.add_parser("serve", help="serve the HTTP API under uvicorn")
    s.add_argument("--host", default="127.0.0.1")
    s.add_argument("--port", type=int, default=8000)
    s.add_argument("--workers", type=int, default=1)
    s.add_argument("--log-level", default="info")
    return parser


def console_main() -> int:
    """The ``inertia`` command and ``python -m inertia``: ``main`` in a process that ends next."""
    code = main()
    # Nothing is allocated after this: move every object to the permanent
    # generation, so the interpreter's final garbage collections do not walk
    # the objects of every imported module (Dask, tornado, numpy): ~0.15 s
    # of a batch run's exit.
    gc.freeze()
    return code


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        if args.command == "analyze":
            return _analyze(args)
        if args.command == "batch":
            from .batch import run_batch_cli

            return run_batch_cli(args)
        return _serve(args)
    except ServiceError as exc:
        print(json.dumps(exc.as_dict()), file=sys.stderr)
        return EXIT_CODES.get(exc.code, EXIT_INTERNAL)
    except BrokenPipeError:  # output piped into head & co.: not an error of ours
        sys.stderr.close()
        return 0


def _analyze(args: argparse.Namespace) -> int:
    from .pipeline import analyze

    result = analyze(args.file, options=options_from_args(args))
    doc = result.as_dict()
    if args.json:
        print(json.dumps(doc, indent=2))
    else:
        print(render_table(doc))
    return 0


def _serve(args: argparse.Namespace) -> int:
    import uvicorn

    # the service writes its own structured access line (inertia.api.access)
    uvicorn.run(f"{__package__}.app:app", host=args.host, port=args.port, workers=args.workers,
                log_level=args.log_level, access_log=False)
    return 0


def _fmt(x: float) -> str:
    return f"{x: .9g}"


def _vec(v: Sequence[float]) -> str:
    return "[" + ", ".join(_fmt(x) for x in v) + "]"


def render_table(doc: dict[str, Any]) -> str:
    """A readable summary of an analysis result (SI units)."""
    src = doc["source"]
    lines = [f"{src.get('filename', 'points')}  ({src['format']}, {src['kind']}, units {src['units']})"]
    rows: list[tuple[str, str]] = [("mass", f"{_fmt(doc['mass'])} kg")]
    if "volume" in doc:
        rows.append(("volume", f"{_fmt(doc['volume'])} m^3"))
    if "density" in doc:
        rows.append(("density", f"{_fmt(doc['density'])} kg/m^3"))
    rows.append(("centre of mass", f"{_vec(doc['center_of_mass'])} m"))
    for i, row in enumerate(doc["inertia_tensor"]):
        rows.append(("inertia tensor" if i == 0 else "", f"{_vec(row)} kg m^2"))
    pr = doc["principal"]
    rows.append(("principal moments", f"{_vec(pr['moments'])} kg m^2"))
    for i, axis in enumerate(pr["axes"]):
        rows.append((f"axis {i + 1}", _vec(axis)))
    cls = doc["classification"]
    kind = cls["kind"] + (f" ({cls['shape']})" if "shape" in cls else "")
    rows.append(("class", kind))
    if "asymmetry" in cls:
        rows.append(("asymmetry kappa", _fmt(cls["asymmetry"])))
    rows.append(("planar", str(cls["planar"]).lower()))
    if "reference_inertia" in doc:
        ref = doc["reference_inertia"]
        for i, row in enumerate(ref["tensor"]):
            rows.append((f"tensor about {_vec(ref['point'])}" if i == 0 else "", f"{_vec(row)} kg m^2"))
    if "precession" in doc:
        pc = doc["precession"]
        rows.append(("precession", pc.get("regime", "")))
        for key in ("angular_momentum_magnitude", "kinetic_energy", "body_precession_rate",
                    "space_precession_rate", "spin_rate", "nutation_angle", "period", "flip_interval"):
            if key in pc:
                rows.append((key.replace("_", " "), _fmt(pc[key])))
    if "parts" in doc:
        for part in doc["parts"]:
            rows.append((f"part {part['name']}", f"mass {_fmt(part['mass'])} kg, "
                         f"moments {_vec(part['principal']['moments'])}"))
    diag = doc["diagnostics"]
    rows.append(("relative error", f"{diag['relative_error_estimate']:.2g}"))
    rows.append(("elapsed", f"{diag['elapsed_s'] * 1e3:.2f} ms"))
    width = max(len(k) for k, _ in rows)
    lines += [f"  {k:<{width}}  {v}" for k, v in rows]
    lines += [f"  warning: {w}" for w in doc.get("warnings", [])]
    return "\n".join(lines)
