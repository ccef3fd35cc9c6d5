"""bytes -> bodies.  ``load_body`` is the single entry point of the loading stage."""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from urllib.parse import unquote

from ..body import Body, BrepBody, MeshBody, Part, PointBody, VolumeBody, stored_eps
from ..conventions import length_scale
from ..errors import EmptyGeometryError, ExternalReferenceError, ServiceError, UnreadableFileError
from ..vocabulary import Isotopes, MassUnit, SourceKind, UnitsFrom
from .guard import check_upload, plain_name
from .sniff import CAD_FORMATS, FORMATS, POINT_FORMATS, SCENE_FORMATS, SURFACE_FORMATS, VOLUME_FORMATS, VTK_FORMATS, sniff_format
from .upload import pick_model_file, unpack_zip

XYZ_UNIT = "angstrom"  # the XYZ format's length unit (coordinates in angstrom, as chemistry programs write them)

__all__ = ["Loaded", "load_body", "load_points", "FORMATS", "SURFACE_FORMATS", "VOLUME_FORMATS", "SCENE_FORMATS"]

log = logging.getLogger("inertia.load")


@dataclass(frozen=True, slots=True)
class Loaded:
    """What was read: one or more parts and where they came from.

    kind : mesh (surface), volume (volume cells), points or cad (B-rep solids).
    units : the length unit used; units_from : request, file or default.
    warnings : what the loader assumed (besides each body's own).
    """

    parts: tuple[Part, ...]
    filename: str | None
    format: str
    kind: SourceKind
    units: str
    units_from: UnitsFrom
    warnings: tuple[str, ...] = ()

    @property
    def body(self) -> Body | BrepBody:
        """The single body (first part)."""
        return self.parts[0].body

    @property
    def is_assembly(self) -> bool:
        return len(self.parts) > 1


def load_body(
    source: bytes | str | os.PathLike[str] | Sequence[tuple[str, bytes]],
    *,
    filename: str | None = None,
    format: str | None = None,
    units: str | None = None,
    isotopes: str = Isotopes.STANDARD,
    companions_beside: bool = False,
) -> Loaded:
    """Read a mesh or points file into bodies in file units.

    source : the file's bytes, a path, or several files of one upload as
        ``[(name, bytes), ...]`` (a model and its companion files, e.g. a
        ``.gltf`` and its ``.bin``).  Bytes or a path named ``*.zip`` are
        unpacked into such a list.  The model file is the one whose format
        is readable and that is not a companion kind (``.bin``, images,
        ``.mtl``, ``.node``); the others are offered to its reader by name,
        and nothing outside the upload is ever opened.
    isotopes : masses of atoms named by element (XYZ, points files): "standard"
        atomic weights or the most "abundant" isotope.
    companions_beside : for a path, also read the files the model names (a
        glTF's buffers, an XDMF's HDF5 file, an Abaqus include) from the
        model's own folder, where they are named by a plain file name: what a
        user's own files on their own disk need.  Off by default, and never
        set by the server, whose uploads name nothing outside themselves.

    A reader's own failure that no reader translated (a library's exception,
    or its ``sys.exit``) is ``unreadable_file`` naming it, and logged: the
    server, the command line and the library answer it alike.
    """
    try:
        return _load_body(source, filename, format, units, isotopes, companions_beside)
    except (ServiceError, MemoryError):
        raise
    except RecursionError:
        raise UnreadableFileError(
            "the file nests its structure too deeply to read; no mesh file needs that", reason="RecursionError"
        ) from None
    except (Exception, SystemExit) as exc:  # a reader's own failure on this file, untranslated below
        log.warning("unclassified reader failure on %r, reported as unreadable_file", filename, exc_info=exc)
        raise UnreadableFileError(
            f"the file could not be read ({type(exc).__name__}: {_first_line(exc)}); check that it is a valid "
            "file of its format, or export it again",
            reason=type(exc).__name__,
        ) from None


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return (text.splitlines()[0] if text else "no message")[:160]


def _load_body(
    source: bytes | str | os.PathLike[str] | Sequence[tuple[str, bytes]],
    filename: str | None,
    format: str | None,
    units: str | None,
    isotopes: str,
    companions_beside: bool,
) -> Loaded:
    if not isinstance(source, (bytes, bytearray, memoryview, str, os.PathLike)):
        return _load_files(list(source), format, units, isotopes)
    zipped = (format or "").lower().lstrip(".") == "zip"
    inner_format = None if zipped else format
    if isinstance(source, (str, os.PathLike)):
        path = os.fspath(source)
        filename = filename or os.path.basename(path)
        if filename.lower().endswith(".zip") or zipped:
            try:
                with open(path, "rb") as fh:
                    raw = fh.read()
            except OSError as exc:
                raise UnreadableFileError(f"cannot open {path!r}: {exc.strerror}") from exc
            _refuse_lfs_pointer(raw[:64], filename)
            return _load_files(unpack_zip(raw), inner_format, units, isotopes)
        if companions_beside:
            return _load_beside(path, filename, format, units, isotopes)
        return _load_path(path, filename, format, units, isotopes)
    data = source if isinstance(source, bytes) else bytes(source)  # bytearray, memoryview
    if (filename or "").lower().endswith(".zip") or zipped:
        _refuse_lfs_pointer(data[:64], filename)
        return _load_files(unpack_zip(data), inner_format, units, isotopes)
    return _load_bytes(data, filename, format, units, isotopes)


def _load_files(files: list[tuple[str, bytes]], format: str | None, units: str | None, isotopes: str = Isotopes.STANDARD) -> Loaded:
    """The model file of a multi-file upload, read with the others as its companions."""
    for name, content in files:  # a companion (a glTF's .bin) left behind by git-lfs is named, not misread
        _refuse_lfs_pointer(bytes(content[:64]), os.path.basename(name))
    main, companions = pick_model_file(files, format)
    data = dict(files)[main]
    return _load_bytes(bytes(data), os.path.basename(main), format, units, isotopes, companions)


MAX_COMPANIONS_BESIDE = 256  # files one model may name from its folder (a glTF's buffers, an Abaqus deck's includes)


def _load_beside(path: str, filename: str, format: str | None, units: str | None, isotopes: str) -> Loaded:
    """A file on disk with the files it names, read from its own folder (plain names only).

    The guard that refuses an upload's references names the first one missing; each is read from the
    model's folder and the model read again, until nothing is missing.
    """
    folder = os.path.dirname(os.path.abspath(path))
    companions: dict[str, bytes] = {}  # by the name as written and as URI-decoded
    read = 0
    while True:
        try:
            if not companions:
                return _load_path(path, filename, format, units, isotopes)
            try:
                with open(path, "rb") as fh:
                    data = fh.read()
            except OSError as exc:
                raise UnreadableFileError(f"cannot open {path!r}: {exc.strerror}") from exc
            return _load_bytes(data, filename, format, units, isotopes, companions)
        except ExternalReferenceError as exc:
            if "reference" not in exc.details:  # not a file that could be beside the model (a <!DOCTYPE>, ...)
                raise
            name = str(exc.details["reference"])
            found = _companion_beside(folder, name) if name not in companions and read < MAX_COMPANIONS_BESIDE else None
            if found is None:
                raise _missing_beside(exc, name, filename) from None
            read += 1
            companions[name] = found
            companions.setdefault(unquote(name), found)


def _companion_beside(folder: str, name: str) -> bytes | None:
    """The bytes of ``name`` in ``folder`` if it is a plain file name (as written, or URI-decoded) of a file there."""
    for candidate in dict.fromkeys((name, unquote(name))):
        if not plain_name(candidate):
            continue
        try:
            with open(os.path.join(folder, candidate), "rb") as fh:
                return fh.read()
        except OSError:
            continue
    return None


def _missing_beside(exc: ExternalReferenceError, name: str, filename: str) -> ExternalReferenceError:
    fmt = str(exc.details.get("format", "")) or "model"
    where = (
        "which is not in the file's folder: keep the files it names beside it (or send the model and its files "
        "together in one .zip)"
        if plain_name(unquote(name))
        else "a path or URL: only files named by a plain file name, beside the model, are read (in a .zip too): "
        "name the file by its plain file name beside the model, or export a self-contained file"
    )
    kind = str(exc.details.get("reference_kind", "")) or "reference"
    return ExternalReferenceError(
        f"{filename!r}, {'an' if fmt.upper()[:1] in 'AEFHILMNORSX' else 'a'} {fmt.upper()} file, refers to another "
        f"file ({kind} {name[:120]!r}), {where}",
        **exc.details,
    )


def _load_path(path: str, filename: str, format: str | None, units: str | None, isotopes: str = Isotopes.STANDARD) -> Loaded:
    """A file on disk; a binary STL is read in blocks, never held whole beside its vertices."""
    try:
        fh = open(path, "rb")  # noqa: SIM115  (closed by the with below; only opening errors are caught here)
    except OSError as exc:
        raise UnreadableFileError(f"cannot open {path!r}: {exc.strerror}") from exc
    with fh:
        head = fh.read(512)
        _refuse_lfs_pointer(head, filename)
        fmt = sniff_format(filename, format, head) if head else None
        if fmt != "stl":
            fh.seek(0)
            return _load_bytes(fh.read(), filename, format, units, isotopes)
        from .stl import read_stl_file

        fh.seek(0)
        vertices, faces, notes = read_stl_file(fh, os.fstat(fh.fileno()).st_size)
    scale = 1.0 if units is None else length_scale(units)
    name = _stem(filename)
    body = MeshBody(vertices, faces, scale, name, welded=True, coordinate_eps=stored_eps(vertices), warnings=notes)
    parts = (Part(name, body),)
    return Loaded(parts, filename, "stl", SourceKind.MESH, units or "m", UnitsFrom.REQUEST if units else UnitsFrom.DEFAULT)


_LFS_POINTER = b"version https://git-lfs.github.com/spec/"


def _refuse_lfs_pointer(head: bytes, filename: str | None) -> None:
    """A Git LFS pointer (what a clone without git-lfs holds in place of a large file) is named as such."""
    if head.startswith(_LFS_POINTER):
        raise UnreadableFileError(
            "the file is a Git LFS pointer (a few lines naming the real file's hash), not the mesh itself: "
            "the repository it came from stores the file with Git LFS; fetch it (git lfs pull) and send that",
            filename=filename,
            reason="git-lfs pointer",
        )


def _load_bytes(
    data: bytes,
    filename: str | None,
    format: str | None,
    units: str | None,
    isotopes: str = Isotopes.STANDARD,
    companions: Mapping[str, bytes] | None = None,
) -> Loaded:
    if not len(data):
        raise EmptyGeometryError("the file is empty; send a file with geometry", filename=filename)
    _refuse_lfs_pointer(bytes(data[:64]), filename)
    fmt = sniff_format(filename, format, bytes(data[:512]))
    # includes, external references, inflation bounds: before any reader
    check_upload(data, fmt, companions=tuple(companions or ()))
    if fmt in CAD_FORMATS:
        from ..cad.read import read_cad_parts

        cad_parts, unit, units_from, warnings = read_cad_parts(data, fmt, units)
        return Loaded(tuple(cad_parts), filename, fmt, SourceKind.CAD, unit, units_from, warnings)
    xyz_default = fmt == "xyz" and units is None
    if xyz_default:
        units = XYZ_UNIT
    requested = None if units is None else (units, length_scale(units))
    scale = requested[1] if requested else 1.0

    declared: str | None = None
    if fmt == "stl":
        from .stl import read_stl

        vertices, faces, stl_notes = read_stl(data)
        name = _stem(filename)
        mesh = MeshBody(vertices, faces, scale, name, welded=True, coordinate_eps=stored_eps(vertices), warnings=stl_notes)
        parts = [Part(name, mesh)]
        kind = SourceKind.MESH
    elif fmt in POINT_FORMATS:
        from .points import read_points_document

        body, molecule, declared = read_points_document(data, fmt, scale, isotopes=isotopes)
        parts = [Part(_stem(filename), body, {"molecule": True} if molecule else {})]
        kind = SourceKind.POINTS
    elif fmt in VOLUME_FORMATS or fmt in VTK_FORMATS:
        from .volume import read_volume_parts

        parts = read_volume_parts(data, fmt, scale, filename=filename, companions=companions)
        # a file of 2-D cells only is read as a surface (``volume._surface_part``): weighed as a mesh
        kind = SourceKind.MESH if all(isinstance(p.body, MeshBody) for p in parts) else SourceKind.VOLUME
    else:
        from .meshes import read_surface_parts

        parts, declared, notes = read_surface_parts(data, fmt, scale, companions)
        if notes:  # what the file holds but is not weighed (3MF support objects, ...) travels as warnings
            first = parts[0]
            assert isinstance(first.body, MeshBody)
            parts[0] = Part(first.name, replace(first.body, warnings=(*first.body.warnings, *notes)), first.extras)
        kind = SourceKind.MESH

    if xyz_default:
        unit, units_from = XYZ_UNIT, UnitsFrom.DEFAULT
    elif requested:
        unit, units_from = requested[0], UnitsFrom.REQUEST
    elif declared:
        unit, units_from = declared, UnitsFrom.FILE
        parts = [_rescaled(p, length_scale(declared)) for p in parts]
    else:
        unit, units_from = "m", UnitsFrom.DEFAULT
    return Loaded(tuple(parts), filename, fmt, kind, unit, units_from)


def load_points(
    records: list[dict[str, object]], units: str | None = None, *, isotopes: str = Isotopes.STANDARD, mass_unit: str = MassUnit.KG
) -> Loaded:
    """Point masses given as records ``{"mass": m, "position": [x, y, z]}`` (or ``"element"``)."""
    from .points import names_elements, points_from_records

    unit = units or "m"
    body = points_from_records(records, length_scale(unit), isotopes=isotopes, mass_unit=mass_unit)
    extras: dict[str, object] = {"molecule": True} if names_elements(records) else {}
    units_from = UnitsFrom.REQUEST if units else UnitsFrom.DEFAULT
    return Loaded((Part("points", body, extras),), None, "points", SourceKind.POINTS, unit, units_from)


def _rescaled(part: Part, scale: float) -> Part:
    body = part.body
    if isinstance(body, MeshBody):
        new: Body = replace(body, length_scale=scale)
    elif isinstance(body, VolumeBody):
        new = VolumeBody(body.points, body.tets, body.cell_density, scale, body.name, body.warnings, body.cells, body.tet_cells)
    else:
        assert isinstance(body, PointBody)
        new = PointBody(body.masses, body.positions, scale, body.name, body.warnings)
    return Part(part.name, new, part.extras)


def _stem(filename: str | None) -> str:
    if not filename:
        return "body"
    base = os.path.basename(filename)
    return base.rsplit(".", 1)[0] if "." in base else base
