"""bytes -> bodies.  ``load_body`` is the single entry point of the loading stage."""

from __future__ import annotations

import os
from dataclasses import dataclass

from ..body import Body, BrepBody, MeshBody, Part, PointBody, VolumeBody
from ..conventions import length_scale
from ..errors import EmptyGeometryError, UnreadableFileError
from .sniff import CAD_FORMATS, FORMATS, POINT_FORMATS, SCENE_FORMATS, SURFACE_FORMATS, VOLUME_FORMATS, sniff_format

__all__ = ["Loaded", "load_body", "load_points", "FORMATS", "SURFACE_FORMATS", "VOLUME_FORMATS", "SCENE_FORMATS"]


@dataclass(frozen=True, slots=True)
class Loaded:
    """What was read: one or more parts and where they came from.

    kind : "mesh" (surface), "volume" (volume cells), "points" or "cad" (B-rep solids).
    units : the length unit used; units_from : "request", "file" or "default".
    warnings : what the loader assumed (besides each body's own).
    """

    parts: tuple[Part, ...]
    filename: str | None
    format: str
    kind: str
    units: str
    units_from: str
    warnings: tuple[str, ...] = ()

    @property
    def body(self) -> Body | BrepBody:
        """The single body (first part)."""
        return self.parts[0].body

    @property
    def is_assembly(self) -> bool:
        return len(self.parts) > 1


def load_body(
    source: bytes | str | os.PathLike[str],
    *,
    filename: str | None = None,
    format: str | None = None,
    units: str | None = None,
) -> Loaded:
    """Read a mesh or points file (bytes or a path) into bodies in file units."""
    if isinstance(source, (str, os.PathLike)):
        path = os.fspath(source)
        filename = filename or os.path.basename(path)
        return _load_path(path, filename, format, units)
    data = source if isinstance(source, bytes) else bytes(source)
    return _load_bytes(data, filename, format, units)


def _load_path(path: str, filename: str, format: str | None, units: str | None) -> Loaded:
    """A file on disk; a binary STL is read in blocks, never held whole beside its vertices."""
    try:
        fh = open(path, "rb")  # noqa: SIM115  (closed by the with below; only opening errors are caught here)
    except OSError as exc:
        raise UnreadableFileError(f"cannot open {path!r}: {exc.strerror}") from exc
    with fh:
        head = fh.read(512)
        fmt = sniff_format(filename, format, head) if head else None
        if fmt != "stl":
            fh.seek(0)
            return _load_bytes(fh.read(), filename, format, units)
        from .stl import read_stl_file

        fh.seek(0)
        vertices, faces = read_stl_file(fh, os.fstat(fh.fileno()).st_size)
    scale = 1.0 if units is None else length_scale(units)
    name = _stem(filename)
    parts = (Part(name, MeshBody(vertices, faces, scale, name, welded=True)),)
    return Loaded(parts, filename, "stl", "mesh", units or "m", "request" if units else "default")


def _load_bytes(data: bytes, filename: str | None, format: str | None, units: str | None) -> Loaded:
    if not len(data):
        raise EmptyGeometryError("the file is empty; send a mesh with geometry", filename=filename)
    fmt = sniff_format(filename, format, bytes(data[:512]))
    if fmt in CAD_FORMATS:
        from ..cad import read_cad_parts

        cad_parts, unit, units_from, warnings = read_cad_parts(data, fmt, units)
        return Loaded(tuple(cad_parts), filename, fmt, "cad", unit, units_from, warnings)
    requested = None if units is None else (units, length_scale(units))
    scale = requested[1] if requested else 1.0

    declared: str | None = None
    if fmt == "stl":
        from .stl import read_stl

        vertices, faces = read_stl(data)
        parts = [Part(_stem(filename), MeshBody(vertices, faces, scale, _stem(filename), welded=True))]
        kind = "mesh"
    elif fmt in POINT_FORMATS:
        from .points import read_points_file

        parts = [Part(_stem(filename), read_points_file(data, fmt, scale))]
        kind = "points"
    elif fmt in VOLUME_FORMATS:
        from .meshes import read_meshio_parts

        parts = read_meshio_parts(data, fmt, scale)
        kind = "volume"
    else:
        from .meshes import read_trimesh_parts

        parts, declared = read_trimesh_parts(data, fmt, scale)
        kind = "mesh"

    if requested:
        unit, units_from = requested[0], "request"
    elif declared:
        unit, units_from = declared, "file"
        parts = [_rescaled(p, length_scale(declared)) for p in parts]
    else:
        unit, units_from = "m", "default"
    return Loaded(tuple(parts), filename, fmt, kind, unit, units_from)


def load_points(records: list[dict[str, object]], units: str | None = None) -> Loaded:
    """Point masses given as records ``{"mass": m, "position": [x, y, z]}``."""
    from .points import points_from_records

    unit = units or "m"
    body = points_from_records(records, length_scale(unit))
    return Loaded((Part("points", body),), None, "points", "points", unit, "request" if units else "default")


def _rescaled(part: Part, scale: float) -> Part:
    body = part.body
    if isinstance(body, MeshBody):
        new: Body = MeshBody(body.vertices, body.faces, scale, body.name, body.warnings, body.welded)
    elif isinstance(body, VolumeBody):
        new = VolumeBody(body.points, body.tets, body.cell_density, scale, body.name, body.warnings)
    else:
        assert isinstance(body, PointBody)
        new = PointBody(body.masses, body.positions, scale, body.name, body.warnings)
    return Part(part.name, new, part.extras)


def _stem(filename: str | None) -> str:
    if not filename:
        return "body"
    base = os.path.basename(filename)
    return base.rsplit(".", 1)[0] if "." in base else base
