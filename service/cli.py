"""Command line: ``inertia analyze | batch | serve``, a thin front end over the pipeline.

Errors are printed to stderr as a sentence (``error: ... (code)``), or in the API's
envelope with ``--json``; the exit status comes from ``EXIT_CODES``, chosen by the
error's class (its nearest listed base class):

    0  success
    1  an unexpected internal error (a bug: please report it)
    2  a bad option or parameter
    3  a file that cannot be read: unsupported format, unreadable, an external
       reference that did not come with it, no geometry, past a size bound
    4  a body that is not a solid: open mesh, zero volume, insufficient precision,
       an inertia a simulator refuses
    5  a time limit was reached (reserved: the command line sets none)
    6  the environment refused: a port in use, an output that cannot be written
  130  interrupted (Ctrl-C)
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import json
import os
import re
import signal
import sys
import traceback
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from .errors import (
    DegenerateBodyError,
    InputTooLargeError,
    InvalidInertiaError,
    InvalidMeshError,
    InvalidParameterError,
    LoadError,
    ServiceError,
    UnreadableFileError,
)
from .tolerances import DEFAULT_TOLERANCES
from .vocabulary import METHODS, MODELS, ExportFormat, Geometry, Isotopes, Model, MotionMethod, values

if TYPE_CHECKING:
    from .sections import AnalysisDocument, PrecessionSection

__all__ = ["main", "EXIT_CODES", "exit_code"]

TensorRows = Callable[[str, Sequence[Sequence[float]]], list[tuple[str, str]]]

EXIT_INTERNAL = 1
EXIT_CODES: dict[type[ServiceError], int] = {
    InvalidParameterError: 2,  # MotionError too
    LoadError: 3,  # unsupported_format, unreadable_file, external_reference, empty_geometry
    InputTooLargeError: 3,
    InvalidMeshError: 4,  # not_watertight
    DegenerateBodyError: 4,  # zero_volume, insufficient_precision
    InvalidInertiaError: 4,
    ServiceError: EXIT_INTERNAL,
}
EXIT_ENVIRONMENT = 6
EXIT_INTERRUPTED = 130

# Lengths in the table: (label, metres per unit); masses: (label, kilograms per unit).
OUTPUT_UNITS = {
    "si": (("m", 1.0), ("kg", 1.0)),
    "kg-mm": (("mm", 1e-3), ("kg", 1.0)),
    "g-mm": (("mm", 1e-3), ("g", 1e-3)),
    "g-cm": (("cm", 1e-2), ("g", 1e-3)),
}

# A value that starts like a negative number ("-0.1,2,0", "-1e-3"): argparse would take it for an option.
_NEGATIVE_VALUE = re.compile(r"^-(\d|\.\d)")


def _triple(text: str) -> tuple[float, float, float]:
    parts = text.replace(" ", "").split(",")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"expected x,y,z but got {text!r}")
    try:
        return (float(parts[0]), float(parts[1]), float(parts[2]))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected three numbers x,y,z but got {text!r}") from None


def _quaternion(text: str) -> tuple[float, float, float, float]:
    parts = text.replace(" ", "").split(",")
    try:
        values = [float(v) for v in parts]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected four numbers w,x,y,z but got {text!r}") from None
    if len(values) != 4:
        raise argparse.ArgumentTypeError(f"expected a quaternion w,x,y,z but got {text!r}")
    return (values[0], values[1], values[2], values[3])


def add_analysis_options(p: argparse.ArgumentParser) -> None:
    """Options shared by ``analyze`` and ``batch`` (the API's query parameters)."""
    p.add_argument("--format", help="file format; inferred from the name when absent")
    p.add_argument(
        "--units", help="length unit of the file: m, cm, mm, um, in, ft, angstrom (default: the file's; angstrom for .xyz; else m)"
    )
    group = p.add_mutually_exclusive_group()
    group.add_argument("--density", type=float, help="density in kg/m^3 (default 1000)")
    group.add_argument("--mass", type=float, help="total mass in kg (density is derived)")
    p.add_argument("--model", choices=MODELS, default=Model.SOLID.value, help="closed solid or thin shell")
    p.add_argument("--thickness", type=float, help="shell wall thickness, in the file's units")
    p.add_argument("--tolerance", type=float, default=DEFAULT_TOLERANCES.moment_rel, help="relative tolerance for equal moments")
    p.add_argument(
        "--reference",
        type=_triple,
        metavar="X,Y,Z",
        help="point (file units): also report the tensor about it; negative values as written: -1,0,0",
    )
    p.add_argument(
        "--densities",
        help="part name -> density (kg/m^3) for files of several parts: a JSON file, or the object itself '{\"A\": 500}'",
    )
    p.add_argument(
        "--geometry", choices=values(Geometry), help="CAD files: integrate the exact B-rep (default) or a tessellation of it"
    )
    p.add_argument(
        "--deflection",
        type=float,
        help="CAD files: tessellate (implies --geometry mesh) with this chordal deflection relative to "
        "the bounding-box diagonal (default 1e-3)",
    )
    p.add_argument(
        "--frame",
        type=_quaternion,
        metavar="W,X,Y,Z",
        help="unit quaternion carrying a named frame's axes into the file's: also report the centre of "
        "mass and tensors along that frame's axes",
    )
    p.add_argument(
        "--isotopes",
        choices=values(Isotopes),
        default=Isotopes.STANDARD.value,
        help="atoms named by element (.xyz): standard atomic weights or the most abundant isotope",
    )


def _no_constant(name: str) -> float:
    raise ValueError(f"{name} is not a finite number")


def _densities_arg(text: str) -> dict[str, float]:
    """``--densities``: a JSON file, or the JSON object itself (as the API's ``densities`` takes it)."""
    inline = text.lstrip().startswith("{")
    try:
        if inline:
            value = json.loads(text, parse_constant=_no_constant)
        else:
            with open(text, encoding="utf-8") as fh:
                value = json.load(fh, parse_constant=_no_constant)
    except (OSError, ValueError, RecursionError) as exc:
        what = "the JSON object" if inline else "the file"
        raise InvalidParameterError(f"cannot read --densities ({what} {text!r}): {exc}", parameter="densities") from exc
    if not isinstance(value, dict) or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value.values()):
        raise InvalidParameterError(
            '--densities must be a JSON object {"part name": density in kg/m^3}, or a file holding one', parameter="densities"
        )
    return {str(k): float(v) for k, v in value.items()}


def options_from_args(args: argparse.Namespace) -> Any:
    from .pipeline import AnalysisOptions

    densities = _densities_arg(args.densities) if getattr(args, "densities", None) else None
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
        method=getattr(args, "method", MotionMethod.EXACT.value),
        densities=densities,
        geometry=getattr(args, "geometry", None) or (Geometry.MESH if getattr(args, "deflection", None) else Geometry.BREP),
        deflection=getattr(args, "deflection", None),
        export=getattr(args, "export", None),
        frame=getattr(args, "frame", None),
        isotopes=getattr(args, "isotopes", Isotopes.STANDARD),
    )


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="inertia", description="Mass properties and free rotation of rigid bodies.")
    parser.add_argument("--version", action=_VersionAction, nargs=0, help="show program's version number and exit")
    sub = parser.add_subparsers(dest="command", required=True)

    a = sub.add_parser("analyze", help="analyse one mesh or points file (.json/.csv/.xyz)")
    a.add_argument(
        "file",
        help="mesh, volume mesh, CAD (.step/.iges, with the 'cad' extra) or points file (.json/.csv/.xyz); "
        "the format from its name or --format",
    )
    add_analysis_options(a)
    a.add_argument(
        "--omega",
        type=_triple,
        metavar="WX,WY,WZ",
        help="initial angular velocity, rad/s, input frame (adds the precession section)",
    )
    a.add_argument("--duration", type=float, help="seconds of motion to predict (with --omega and --samples)")
    a.add_argument("--samples", type=int, help="number of time samples of the trajectory")
    a.add_argument(
        "--method",
        default=MotionMethod.EXACT.value,
        choices=METHODS,
        help="motion method: exact (closed form / elliptic), dop853, rk45 or splitting (default exact)",
    )
    a.add_argument(
        "--json",
        action="store_true",
        help="print the API's JSON instead of a table (an error as JSON too, on standard error, with a non-zero exit status)",
    )
    a.add_argument(
        "--output-units",
        choices=tuple(OUTPUT_UNITS),
        default="si",
        help="units of the table: si (kg, m, kg m^2; default), kg-mm (kg mm^2), g-mm (g mm^2) or g-cm (g cm^2); --json stays SI",
    )
    a.add_argument(
        "--export", choices=values(ExportFormat), help="print only the inertial element of a robot description format (SI units)"
    )

    b = sub.add_parser("batch", help="analyse many files, folders or .zip archives into JSONL/CSV/Parquet")
    b.add_argument("paths", nargs="+", help="files, folders (read recursively) or .zip archives")
    b.add_argument("--out", required=True, help="results file: .jsonl, .csv or .parquet")
    b.add_argument("--resume", action="store_true", help="skip files that already have a line in --out")
    b.add_argument("--workers", type=int, help="local worker processes (default: the number of cores)")
    b.add_argument("--scheduler", help="address of an existing dask.distributed scheduler")
    b.add_argument("--no-progress", action="store_true", help="do not show the progress bar")
    add_analysis_options(b)

    s = sub.add_parser("serve", help="serve the HTTP API under uvicorn")
    s.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1; 0.0.0.0 for all)")
    s.add_argument("--port", type=int, default=8000, help="port to listen on (default 8000)")
    s.add_argument("--workers", type=int, default=1, help="uvicorn worker processes (default 1)")
    s.add_argument(
        "--log-level",
        default="info",
        choices=("critical", "error", "warning", "info", "debug", "trace"),
        help="uvicorn's log level (default info)",
    )
    return parser


# numpy's BLAS (OpenBLAS; MKL in some builds) starts a thread per core when numpy is imported, and each spins a
# while before it sleeps.  On a 16-core machine `inertia analyze` of a 1e6-triangle STL used 3.8-4.0 s of CPU in
# 1.2-1.4 s of wall time, and 1.8-2.0 s of CPU on one BLAS thread (same wall time, same output): the cores it
# spun on are taken from whatever runs beside it (other commands, a batch, a server).  The command's products are 3x3,
# or a block of rows times a 3x3, too small to gain from BLAS's threads, and the passes over a large mesh have
# threads of their own (``blocks``, which reads OMP_NUM_THREADS: left alone here).  A value the user set wins.
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def one_blas_thread() -> None:
    """Run numpy's BLAS on one thread in this process and its children, unless the environment says otherwise.

    Call it before numpy is imported: the BLAS library reads its variable once, at load.
    """
    for key in BLAS_THREAD_VARIABLES:
        os.environ.setdefault(key, "1")


def console_main() -> int:
    """The ``inertia`` command and ``python -m inertia``: ``main`` in a process that ends next."""
    one_blas_thread()  # numpy is not imported yet (``import inertia.cli`` does not import it)
    code = main(isolate=True)  # a process of its own, with no thread yet: ``analyze`` may fork
    # Nothing is allocated after this: move every object to the permanent
    # generation, so the interpreter's final garbage collections do not walk
    # the objects of every imported module (Dask, tornado, numpy): ~0.15 s
    # of a batch run's exit.
    gc.freeze()
    return code


def _package_version() -> str:
    from . import __version__

    return str(__version__)


class _VersionAction(argparse.Action):
    """``--version``, reading the distribution's metadata only when asked (importlib.metadata costs ~30 ms)."""

    def __call__(
        self, parser: argparse.ArgumentParser, namespace: argparse.Namespace, values: Any, option_string: str | None = None
    ) -> None:
        print(f"{parser.prog} {_package_version()}")
        parser.exit()


def joined_negative_values(argv: Sequence[str]) -> list[str]:
    """``--omega -0.1,2,0`` as ``--omega=-0.1,2,0``, so argparse does not read the value as an option."""
    out: list[str] = []
    for token in argv:
        if out and _NEGATIVE_VALUE.match(token) and out[-1].startswith("--") and "=" not in out[-1]:
            out[-1] = f"{out[-1]}={token}"
        else:
            out.append(token)
    return out


# The service's sentences give advice in the API's words (``pass units=mm``, ``use model=shell``); in a table or
# error line of the command the same advice reads as its options (``--units mm``).  The JSON output keeps the
# API's words, as the API returns them.
ADVICE_OPTIONS = frozenset({"units", "format", "model", "thickness", "density", "mass", "geometry", "deflection"})
_ADVICE = re.compile(r"\b([a-z]+)=([^\s,;()]*[^\s,;().]|\.\.\.)")


def as_options(text: str) -> str:
    """``text`` with each ``name=value`` of an analysis option written as the command's ``--name value``."""
    return _ADVICE.sub(lambda m: f"--{m[1]} {m[2]}" if m[1] in ADVICE_OPTIONS else m[0], text)


def main(argv: Sequence[str] | None = None, *, isolate: bool = False) -> int:
    """The command on ``argv`` (default: the process's arguments); its exit status.

    ``isolate``: analyse a file in a forked child (see ``_analyze_isolated``); only for a process of its own
    that has no thread yet, as ``console_main``'s.
    """
    args = _parser().parse_args(joined_negative_values(sys.argv[1:] if argv is None else argv))
    as_json = bool(getattr(args, "json", False))
    if args.command == "analyze":
        if isolate and hasattr(os, "fork"):
            return _analyze_isolated(args, as_json)
        return _handled(lambda: _analyze(args), as_json)
    if args.command == "batch":
        return _handled(lambda: _batch(args), as_json)
    return _handled(lambda: _serve(args), as_json)


def _handled(command: Callable[[], int], as_json: bool) -> int:
    """Run ``command``; a ``ServiceError`` becomes its envelope on stderr and its exit status."""
    try:
        return command()
    except ServiceError as exc:
        if as_json:
            print(json.dumps(exc.as_dict()), file=sys.stderr)
        else:
            print(f"error: {as_options(exc.message)} ({exc.code})", file=sys.stderr)
        return exit_code(exc)
    except BrokenPipeError:  # output piped into head & co.: not an error of ours
        sys.stderr.close()
        return 0
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


# ``inertia analyze`` as a command (``console_main``) analyses the file in a forked child: a native reader
# (VTK's, OpenCASCADE's) that crashes on a corrupt file takes the child with it, and the command still
# answers with an error, as the HTTP service's compute processes and the batch's workers do.  Not in ``main``
# called in-process (a test, an embedding program), where forking a process with threads is unsafe.
_CRASH_SIGNALS = {signal.SIGSEGV, signal.SIGBUS, signal.SIGILL, signal.SIGFPE, signal.SIGABRT}
_STOP_SIGNALS = (signal.SIGTERM, signal.SIGHUP)


def _analyze_isolated(args: argparse.Namespace, as_json: bool) -> int:
    """``_analyze`` in a forked child; its exit status, or an error where a signal ended it."""
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:  # the child: the whole command, then out without the parent's exit handlers
        code = EXIT_INTERNAL
        try:
            code = _handled(lambda: _analyze(args), as_json)
        except BaseException:
            traceback.print_exc()
        finally:
            with contextlib.suppress(Exception):
                sys.stdout.flush()
                sys.stderr.flush()
            os._exit(code)
    # Ctrl-C reaches the child too (one process group), which says so; a request to stop is passed on
    previous = {
        signal.SIGINT: signal.signal(signal.SIGINT, signal.SIG_IGN),
        **{sig: signal.signal(sig, lambda number, _: os.kill(pid, number)) for sig in _STOP_SIGNALS},
    }
    try:
        _, status = os.waitpid(pid, 0)
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    if not os.WIFSIGNALED(status) or os.WTERMSIG(status) == signal.SIGINT:
        return os.waitstatus_to_exitcode(status) if os.WIFEXITED(status) else EXIT_INTERRUPTED
    sig = signal.Signals(os.WTERMSIG(status))
    if sig in _STOP_SIGNALS:
        return 128 + sig.value  # stopped as asked, as a shell reports it
    if sig in _CRASH_SIGNALS:
        cause = f"a file reader crashed on it ({sig.name}); the file is likely corrupt: check it, or export it again"
    else:
        cause = f"the system stopped the analysis ({sig.name}), as it does when memory runs out; try a smaller file"
    return _handled(lambda: _raise(UnreadableFileError(f"the file {args.file!r} could not be analysed: {cause}")), as_json)


def _raise(exc: ServiceError) -> int:
    raise exc


def exit_code(exc: ServiceError) -> int:
    """The exit status of an error: that of its nearest base class in ``EXIT_CODES``."""
    return next(EXIT_CODES[cls] for cls in type(exc).__mro__ if cls in EXIT_CODES)


def _analyze(args: argparse.Namespace) -> int:
    from .blocks import single_heap
    from .pipeline import analyze

    single_heap()  # a large mesh's passes run on several threads: one heap keeps the peak memory of one

    document = analyze(args.file, options=options_from_args(args)).document()
    if getattr(args, "export", None) and not args.json:
        print(export_text(document))
        for w in document.warnings:
            print(f"warning: {as_options(w)}", file=sys.stderr)
        return 0
    if args.json:
        try:
            text = json.dumps(document.as_dict(), indent=2, allow_nan=False)
        except ValueError as exc:  # a non-finite number is a bug: say so, never print Infinity or NaN
            raise InvalidParameterError(
                "the result holds a number that is not finite, which JSON cannot carry; please report the input"
            ) from exc
        print(text)
    else:
        print(render_table(document, args.output_units))
    return 0


def _batch(args: argparse.Namespace) -> int:
    """``inertia batch``: run, print a one-line summary to stderr, exit 0.

    Files that fail are rows of the output, not a failure of the run; a bad
    option or a missing extra raises ``InvalidParameterError`` (exit 2).  The
    output's folder is made when missing; on Ctrl-C the rows written so far
    stay, and one line says how ``--resume`` continues.
    """
    if not _output_folder_ready(args.out):
        return EXIT_ENVIRONMENT
    from .batch.workers import limit_numeric_threads, start_forkserver

    limit_numeric_threads()  # this process computes nothing: no thread per core for numpy (imported next)
    if args.scheduler is None:  # a local cluster: its workers' imports start now, beside this process's
        start_forkserver()
    from .batch import run_batch

    try:
        summary = run_batch(
            args.paths,
            args.out,
            options_from_args(args),
            resume=args.resume,
            workers=args.workers,
            scheduler=args.scheduler,
            progress=not args.no_progress,
        )
    except KeyboardInterrupt:
        print(
            f"\ninterrupted: the rows written so far are kept in {args.out}; run the same command with --resume "
            "to analyse the rest",
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    print(summary.as_text(), file=sys.stderr)
    return 0


def _output_folder_ready(out: str) -> bool:
    """Make the output's folder if it is missing; say why in one sentence when it cannot be written."""
    if "://" in out:  # a remote output: its filesystem says
        return True
    folder = os.path.dirname(os.path.abspath(out))
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError as exc:
        print(f"error: cannot create the output folder {folder!r}: {exc.strerror}; choose another --out", file=sys.stderr)
        return False
    if not os.access(folder, os.W_OK):
        print(f"error: the output folder {folder!r} is not writable; choose another --out", file=sys.stderr)
        return False
    return True


def _port_free(host: str, port: int) -> bool:
    import socket

    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except socket.gaierror:
        return True  # uvicorn reports an unknown host itself
    family, kind, proto, _, address = infos[0]
    with socket.socket(family, kind, proto) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as uvicorn binds
        try:
            probe.bind(address)
        except OSError:
            return False
    return True


def _serve(args: argparse.Namespace) -> int:
    import uvicorn

    if not _port_free(args.host, args.port):
        print(
            f"error: port {args.port} on {args.host} is in use or not available; stop the other server "
            f"or choose another port with --port",
            file=sys.stderr,
        )
        return EXIT_ENVIRONMENT
    # the service writes its own structured access line (inertia.api.access)
    uvicorn.run(
        f"{__package__}.app:app", host=args.host, port=args.port, workers=args.workers, log_level=args.log_level, access_log=False
    )
    return 0


def _fmt(x: float) -> str:
    return f"{x: .9g}"


def _vec(v: Sequence[float]) -> str:
    return "[" + ", ".join(_fmt(x) for x in v) + "]"


def export_text(doc: AnalysisDocument) -> str:
    """The export snippet alone; for several parts, each part's after the whole body's, named in a comment."""
    export = doc.export
    assert export is not None, "the analysis was asked for an export"
    blocks = [export.text]
    for part in export.parts or ():
        blocks.append(f"<!-- part {part.name.replace('--', '- -')} -->\n{part.text}")
    return "\n".join(blocks)


Rows = list[tuple[str, str]]


def _v11_rows(doc: AnalysisDocument, length: Callable[[Sequence[float]], str], tensor_rows: TensorRows) -> Rows:
    """Rows of the API 1.1 sections: rotational constants and the named frame (in the table's units)."""
    rows: Rows = []
    rc = doc.rotational_constants
    if rc is not None:
        names = "B" if len(rc.MHz) == 1 else "A, B, C"
        rows.append((f"rotational {names}", ", ".join(f"{v:.9g}" for v in rc.MHz) + " MHz"))
        rows.append(("", ", ".join(f"{v:.9g}" for v in rc.cm_1) + " cm^-1"))
    fr = doc.frame
    if fr is not None:
        rows.append(("frame (w,x,y,z)", _vec(fr.quaternion)))
        rows.append(("  centre of mass", length(fr.center_of_mass)))
        rows += tensor_rows("  inertia tensor", fr.inertia_tensor)
        if fr.reference_inertia is not None:
            rows += tensor_rows("  about reference", fr.reference_inertia)
    return rows


def render_table(doc: AnalysisDocument, output_units: str = "si") -> str:
    """A readable summary of an analysis result, in ``OUTPUT_UNITS[output_units]`` (SI by default)."""
    (ln, lu), (mn, mu) = OUTPUT_UNITS[output_units]
    inertia_unit = f"{mn} {ln}^2"

    def length(v: Sequence[float]) -> str:
        return f"{_vec([x / lu for x in v])} {ln}"

    def tensor_rows(label: str, tensor: Sequence[Sequence[float]]) -> Rows:
        scale = mu * lu * lu
        return [(label if i == 0 else "", f"{_vec([x / scale for x in row])} {inertia_unit}") for i, row in enumerate(tensor)]

    src = doc.source
    lines = [f"{src.filename if src.filename is not None else 'points'}  ({src.format}, {src.kind}, units {src.units})"]
    rows: Rows = [("mass", f"{_fmt(doc.mass / mu)} {mn}")]
    if doc.volume is not None:
        rows.append(("volume", f"{_fmt(doc.volume / lu**3)} {ln}^3"))
    if doc.density is not None:
        rows.append(("density", f"{_fmt(doc.density / mu * lu**3)} {mn}/{ln}^3"))
    if doc.surface_area is not None:
        rows.append(("surface area", f"{_fmt(doc.surface_area / lu**2)} {ln}^2"))
    rows.append(("centre of mass", length(doc.center_of_mass)))
    rows += tensor_rows("inertia tensor", doc.inertia_tensor)
    pr = doc.principal
    rows.append(("principal moments", f"{_vec([x / (mu * lu * lu) for x in pr.moments])} {inertia_unit}"))
    for i, axis in enumerate(pr.axes):
        rows.append((f"axis {i + 1}", _vec(axis)))
    if pr.radii_of_gyration is not None:
        rows.append(("radii of gyration", length(pr.radii_of_gyration)))
    cls = doc.classification
    rows.append(("class", cls.kind + (f" ({cls.shape})" if cls.shape is not None else "")))
    if cls.asymmetry is not None:
        rows.append(("asymmetry kappa", _fmt(cls.asymmetry)))
    rows.append(("planar", str(cls.planar).lower()))
    rows += _v11_rows(doc, length, tensor_rows)
    if doc.reference_inertia is not None:
        ref = doc.reference_inertia
        rows += tensor_rows(f"tensor about {length(ref.point)}", ref.tensor)
    if doc.precession is not None:
        rows += _motion_rows(doc.precession, inertia_unit, mu * lu * lu)
    for part in doc.parts or ():
        moments = [x / (mu * lu * lu) for x in part.principal.moments]
        rows.append((f"part {part.name}", f"mass {_fmt(part.mass / mu)} {mn}, moments {_vec(moments)} {inertia_unit}"))
    diag = doc.diagnostics
    rows.append(("relative error", f"{diag.relative_error_estimate:.2g}"))
    if diag.tessellation_error is not None:
        rows.append(("tessellation error", f"{diag.tessellation_error:.2g} vs the exact B-rep (deflection {src.deflection})"))
    rows.append(("elapsed", f"{diag.elapsed_s * 1e3:.2f} ms"))
    width = max(len(k) for k, _ in rows)
    lines += [f"  {k:<{width}}  {v}" for k, v in rows]
    lines += [f"  warning: {as_options(w)}" for w in doc.warnings]
    return "\n".join(lines)


# Motion quantities of the table with their units; momentum and energy scale with the inertia unit.
_MOTION_UNITS = {
    "angular_momentum_magnitude": "momentum",
    "kinetic_energy": "energy",
    "body_precession_rate": "rad/s",
    "space_precession_rate": "rad/s",
    "spin_rate": "rad/s",
    "nutation_angle": "rad",
    "period": "s",
    "flip_interval": "s",
}


def _motion_rows(pc: PrecessionSection, inertia_unit: str, inertia_scale: float) -> Rows:
    """|M| in (inertia unit)/s and E in (inertia unit)/s^2 (J in SI); rates, angles and times in SI."""
    scaled = {"momentum": f"{inertia_unit}/s", "energy": "J" if inertia_unit == "kg m^2" else f"{inertia_unit}/s^2"}
    rows = [("precession", pc.regime.value)]
    for key, unit in _MOTION_UNITS.items():
        value: float | None = getattr(pc, key)
        if value is not None:
            shown = value / inertia_scale if unit in scaled else value
            rows.append((key.replace("_", " "), f"{_fmt(shown)} {scaled.get(unit, unit)}"))
    return rows
