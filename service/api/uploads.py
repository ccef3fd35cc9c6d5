"""Uploaded files as private temporary files: plain files, and the members of ``.zip`` archives.

The server only ever reads what the client sent: a file name is used to
guess the format and to label the result, never opened. Uploads are copied
in blocks from the framework's spooled file into a folder that only this
server's user can read (:class:`Workspace`), and compute processes get the
path, never the bytes. The server process owns every such folder and
removes it when the request ends, whatever happened to the job (an error, a
timeout, a killed process); the root folder goes when the server stops.
"""

from __future__ import annotations

import contextlib
import logging
import os
import shutil
import tempfile
import zipfile
import zlib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import PurePosixPath, PureWindowsPath
from typing import BinaryIO

from ..errors import ServiceError, UnreadableFileError
from .transport import PayloadTooLargeError

__all__ = ["Item", "Upload", "Workspace", "client_name", "expand", "save"]

log = logging.getLogger("inertia.api")

ZIP_SUFFIX = ".zip"
BLOCK = 1024 * 1024  # copy and inflate in blocks of this size: never a whole file in memory
# resource forks and folder metadata that archivers add; never bodies
_JUNK_PREFIXES = ("__MACOSX/",)
_JUNK_NAMES = (".DS_Store", "Thumbs.db")


class Workspace:
    """One private root folder per server; one sub-folder per request or job, removed by its owner."""

    def __init__(self) -> None:
        self._root: str | None = None

    @property
    def root(self) -> str:
        if self._root is None or not os.path.isdir(self._root):
            self._root = tempfile.mkdtemp(prefix="inertia-")  # mode 0700
        return self._root

    def folder(self) -> str:
        """A new private folder; the caller removes it with :meth:`remove`."""
        return tempfile.mkdtemp(prefix="job-", dir=self.root)

    @staticmethod
    def remove(folder: str) -> None:
        shutil.rmtree(folder, ignore_errors=True)

    def close(self) -> None:
        if self._root is not None:
            shutil.rmtree(self._root, ignore_errors=True)
            self._root = None


@dataclass(frozen=True, slots=True)
class Upload:
    """One uploaded part: the name the client gave and its (spooled) content."""

    filename: str | None
    file: BinaryIO


@dataclass(frozen=True, slots=True)
class Item:
    """One file to analyse, or why it cannot be: exactly one of ``path`` and ``error`` is set."""

    filename: str | None
    path: str | None = None
    error: ServiceError | None = None
    size: int = 0


def client_name(filename: str | None) -> str | None:
    """The last component of a client-given name (no directories, either slash)."""
    if not filename:
        return None
    name = PureWindowsPath(PurePosixPath(filename).name).name
    return name or None


def save(file: BinaryIO, folder: str, index: int, limit: int) -> tuple[str, int]:
    """Copy an upload into ``folder`` in blocks; its path and size. The name is ours, never the client's."""
    path = os.path.join(folder, f"upload-{index}")
    file.seek(0)
    size = _copy(file.read, path, limit)
    if size is None:
        raise PayloadTooLargeError(
            f"the file is larger than the limit of {limit} bytes; send a smaller file or raise INERTIA_MAX_UPLOAD_BYTES",
            limit_bytes=limit,
        )
    return path, size


def _copy(read: object, path: str, limit: int) -> int | None:
    """Write blocks from ``read`` to a new file at ``path``; None if more than ``limit`` bytes come."""
    assert callable(read)
    size = 0
    with open(path, "xb") as out:
        while block := read(BLOCK):
            size += len(block)
            if size > limit:
                return None
            out.write(block)
    return size


def expand(uploads: Iterable[Upload], folder: str, limit: int) -> Iterator[Item]:
    """Files in upload order, saved in ``folder``; a ``.zip`` gives its members in archive order.

    Inside an archive, folders and archiver metadata are skipped; every other
    member becomes an item, so a member of unknown type is reported as an
    error line rather than silently dropped. Archives are not opened
    recursively. A member larger than ``limit`` once uncompressed, or one
    that cannot be inflated, is an error item; the other members go on. All
    members together may not inflate past ``limit`` either.
    """
    counter = iter(range(1 << 62))
    for upload in uploads:
        name = client_name(upload.filename)
        if name and name.lower().endswith(ZIP_SUFFIX):
            yield from _members(name, upload.file, folder, counter, limit)
            continue
        try:
            path, size = save(upload.file, folder, next(counter), limit)
        except ServiceError as exc:
            yield Item(name, error=exc)
        else:
            yield Item(name, path=path, size=size)


def _members(archive: str, file: BinaryIO, folder: str, counter: Iterator[int], limit: int) -> Iterator[Item]:
    try:
        zf = zipfile.ZipFile(file)
    except (zipfile.BadZipFile, OSError, ValueError, EOFError) as exc:
        yield Item(
            archive,
            error=UnreadableFileError(
                f"{archive} is not a readable zip archive ({exc}); send a valid .zip or the files themselves"
            ),
        )
        return
    budget = [limit]  # what all members together may still inflate to
    with zf:
        for info in zf.infolist():
            if info.is_dir() or info.filename.startswith(_JUNK_PREFIXES):
                continue
            name = PurePosixPath(info.filename).name
            if name in _JUNK_NAMES or name.startswith("._"):
                continue
            yield _member(zf, info, folder, next(counter), budget)


def _member(zf: zipfile.ZipFile, info: zipfile.ZipInfo, folder: str, index: int, budget: list[int]) -> Item:
    label = info.filename
    too_large = PayloadTooLargeError(
        f"{label} inflates past the {budget[0]} bytes this archive may still inflate "
        "to; send it separately or raise INERTIA_MAX_UPLOAD_BYTES",
        limit_bytes=budget[0],
    )
    if info.file_size > budget[0]:  # zipfile never inflates past the declared size: refuse before inflating
        return Item(label, error=too_large)
    path = os.path.join(folder, f"upload-{index}")
    try:
        with zf.open(info) as fh:
            size = _copy(fh.read, path, budget[0])
    except (zipfile.BadZipFile, OSError, ValueError, NotImplementedError, RuntimeError, EOFError, zlib.error) as exc:
        _unlink(path)
        return Item(
            label,
            error=UnreadableFileError(
                f"cannot extract {label} from the archive ({exc}); the member is corrupt: send it again or on its own"
            ),
        )
    except Exception as exc:
        _unlink(path)
        log.warning("unclassified failure extracting %r", label, exc_info=exc)
        return Item(
            label,
            error=UnreadableFileError(f"cannot extract {label} from the archive ({type(exc).__name__}); the member is corrupt"),
        )
    if size is None:
        _unlink(path)
        return Item(label, error=too_large)
    budget[0] -= size
    return Item(label, path=path, size=size)


def _unlink(path: str) -> None:
    with contextlib.suppress(OSError):
        os.unlink(path)
