"""Uploaded files as (name, bytes): plain files, and the members of ``.zip`` archives.

The server only ever reads what the client sent: a file name is used to
guess the format and to label the result, never opened.
"""

from __future__ import annotations

import zipfile
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import PurePosixPath, PureWindowsPath
from typing import BinaryIO

from ..errors import PayloadTooLargeError, ServiceError, UnreadableFileError

__all__ = ["Item", "Upload", "client_name", "expand"]

ZIP_SUFFIX = ".zip"
# resource forks and folder metadata that archivers add; never bodies
_JUNK_PREFIXES = ("__MACOSX/",)
_JUNK_NAMES = (".DS_Store", "Thumbs.db")


@dataclass(frozen=True, slots=True)
class Upload:
    """One uploaded part: the name the client gave and its (spooled) content."""

    filename: str | None
    file: BinaryIO


@dataclass(frozen=True, slots=True)
class Item:
    """One file to analyse, or why it cannot be: exactly one of ``data`` and ``error`` is set."""

    filename: str | None
    data: bytes | None = None
    error: ServiceError | None = None


def client_name(filename: str | None) -> str | None:
    """The last component of a client-given name (no directories, either slash)."""
    if not filename:
        return None
    name = PureWindowsPath(PurePosixPath(filename).name).name
    return name or None


def expand(uploads: Iterable[Upload], limit: int) -> Iterator[Item]:
    """Files in upload order; a ``.zip`` gives its members in archive order.

    Inside an archive, folders and archiver metadata are skipped; every other
    member becomes an item, so a member of unknown type is reported as an
    error line rather than silently dropped. Archives are not opened
    recursively. A member larger than ``limit`` once uncompressed is an error.
    """
    for upload in uploads:
        name = client_name(upload.filename)
        if name and name.lower().endswith(ZIP_SUFFIX):
            yield from _members(name, upload.file, limit)
        else:
            upload.file.seek(0)
            yield Item(name, data=upload.file.read())


def _members(archive: str, file: BinaryIO, limit: int) -> Iterator[Item]:
    try:
        zf = zipfile.ZipFile(file)
    except (zipfile.BadZipFile, OSError, ValueError) as exc:
        yield Item(archive, error=UnreadableFileError(f"{archive} is not a readable zip archive ({exc}); "
                                                      "send a valid .zip or the files themselves"))
        return
    with zf:
        for info in zf.infolist():
            if info.is_dir() or info.filename.startswith(_JUNK_PREFIXES):
                continue
            name = PurePosixPath(info.filename).name
            if name in _JUNK_NAMES or name.startswith("._"):
                continue
            yield _member(zf, info, limit)


def _member(zf: zipfile.ZipFile, info: zipfile.ZipInfo, limit: int) -> Item:
    label = info.filename
    too_large = PayloadTooLargeError(f"{label} is larger than the limit of {limit} bytes once uncompressed; "
                                     "send it separately or raise INERTIA_MAX_UPLOAD_BYTES", limit_bytes=limit)
    if info.file_size > limit:
        return Item(label, error=too_large)
    try:
        with zf.open(info) as fh:
            data = fh.read(limit + 1)  # the declared size may lie: never inflate past the limit
    except (zipfile.BadZipFile, OSError, ValueError, NotImplementedError, RuntimeError, EOFError) as exc:
        return Item(label, error=UnreadableFileError(f"cannot extract {label} from the archive ({exc})"))
    if len(data) > limit:
        return Item(label, error=too_large)
    return Item(label, data=data)
