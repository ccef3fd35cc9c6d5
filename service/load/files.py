"""Uploads of several files: a mesh and its companions, loose or in a ``.zip``.

Some formats keep one mesh in several files: a TetGen ``.ele`` (cells) needs
its ``.node`` (points), an XDMF file its HDF5 data.  ``split_upload`` picks
the mesh among the files and hands the rest to its reader by name.  This is
the library entry point for multi-file uploads (``load_files``); the HTTP
layer only has to collect the parts.
"""

from __future__ import annotations

import io
import os
import zipfile
from collections.abc import Sequence

from ..errors import PayloadTooLargeError, UnreadableFileError, UnsupportedFormatError
from .sniff import FORMATS, POINT_FORMATS

__all__ = ["split_upload", "unzipped", "COMPANION_EXTENSIONS", "MAX_ZIP_BYTES", "MAX_ZIP_MEMBERS"]

# files that only ever accompany a mesh, never are one
COMPANION_EXTENSIONS = ("node", "face", "edge", "neigh", "bin", "h5", "hdf5", "hdf", "mtl", "png", "jpg", "jpeg",
                        "ktx2", "webp", "sol")
MAX_ZIP_BYTES = 1 << 30  # 1 GiB unpacked: far above a mesh and its companions, far below a decompression bomb
MAX_ZIP_MEMBERS = 64  # a mesh and its companions are a handful of files


def _ext(name: str) -> str:
    base = os.path.basename(name.replace("\\", "/"))
    return base.rsplit(".", 1)[1].lower() if "." in base else ""


def unzipped(data: bytes, filename: str | None = None) -> list[tuple[str, bytes]]:
    """The files of a ``.zip`` upload as (name, bytes) pairs (folders and hidden files skipped)."""
    label = f"the zip file {os.path.basename(filename)!r}" if filename else "the zip file"
    try:
        archive = zipfile.ZipFile(io.BytesIO(data))
        members = [m for m in archive.infolist() if not m.is_dir()
                   and not os.path.basename(m.filename).startswith(".") and "__MACOSX" not in m.filename]
        if len(members) > MAX_ZIP_MEMBERS:
            raise PayloadTooLargeError(f"{label} holds {len(members)} files; one mesh with its companion files "
                                       f"is at most {MAX_ZIP_MEMBERS} (send several meshes to the batch endpoint)")
        if sum(m.file_size for m in members) > MAX_ZIP_BYTES:
            raise PayloadTooLargeError(f"{label} unpacks to more than {MAX_ZIP_BYTES >> 20} MiB; send the mesh itself")
        return [(m.filename, archive.read(m)) for m in members]
    except (zipfile.BadZipFile, zipfile.LargeZipFile, NotImplementedError, EOFError, OSError, ValueError) as exc:
        raise UnreadableFileError(f"could not open {label} ({exc}); send a valid .zip archive") from exc


def split_upload(files: Sequence[tuple[str, bytes]], format: str | None = None
                 ) -> tuple[str, bytes, dict[str, bytes]]:
    """(mesh name, mesh bytes, {companion name: bytes}) of a multi-file upload."""
    if not files:
        raise UnreadableFileError("the upload holds no files; send a mesh (and its companion files)")
    readable = set(FORMATS) | set(POINT_FORMATS)
    wanted = format.lower().lstrip(".") if format else None
    candidates = [(n, d) for n, d in files if (_ext(n) == wanted if wanted else
                                               _ext(n) in readable and _ext(n) not in COMPANION_EXTENSIONS)]
    if not candidates and len(files) == 1:
        candidates = list(files)
    if not candidates:
        names = ", ".join(os.path.basename(n) for n, _ in files)
        raise UnsupportedFormatError(f"none of the uploaded files ({names}) is a mesh we can read; readable formats "
                                     f"are {', '.join(FORMATS)}")
    if len(candidates) > 1:
        names = ", ".join(os.path.basename(n) for n, _ in candidates)
        raise UnsupportedFormatError(f"the upload holds several meshes ({names}); send one mesh (with its companion "
                                     "files) per request, or several meshes to the batch endpoint")
    name, data = candidates[0]
    companions = {os.path.basename(n.replace("\\", "/")): d for n, d in files if n != name}
    return name, data, companions
