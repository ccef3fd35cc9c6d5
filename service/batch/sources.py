"""Batch inputs: files, folders and ``.zip`` archives, local or behind fsspec URLs.

Listing (:func:`list_sources`) only reads metadata, on the client; reading
(:func:`read_source`) happens wherever the analysis runs, so a Dask worker
fetches its own bytes from a path or URL it can reach.  A zip member is read
on the worker from the archive's location and the member's name.

Naming, which is also the ``--resume`` key and ``source.filename`` of a result:

- a file given by itself: its base name (as ``inertia analyze`` names it);
- a file found in a folder: its path relative to that folder, ``/``-separated;
- a zip member: ``<archive name>/<member path>``, the archive named by the two
  rules above.

When two different inputs would get the same name, the later one is named by
its full location instead, so names stay unique.

Folders are read recursively; only files of known mesh formats (and ``.zip``
archives, which are opened) are taken, hidden entries (``.name``) and
``__MACOSX/`` are skipped.  A file named explicitly is always taken, whatever
its extension, so a points file (``.json``/``.csv``) can be given by name.

No Dask here (the HTTP layer imports this module); fsspec is imported only for
URLs.
"""

from __future__ import annotations

import os
import posixpath
import zipfile
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from typing import IO, Any

from ..errors import InvalidParameterError, UnreadableFileError
from ..load.sniff import FORMATS

__all__ = [
    "KNOWN_EXTENSIONS",
    "Source",
    "is_known_file",
    "iter_inputs",
    "iter_zip_bytes",
    "list_sources",
    "read_source",
]

# mesh formats, CAD files and XYZ molecules (points files in JSON/CSV are too generic to pick up from a folder)
KNOWN_EXTENSIONS = frozenset(FORMATS) | {"stla", "stlb", "xyz", "extxyz", "stp", "igs"}  # xyz: molecules, a specific enough name
ZIP_EXTENSION = "zip"


@dataclass(frozen=True, slots=True)
class Source:
    """One input file, not yet read.

    name : the file's name in results (see the module docstring).
    location : absolute local path or fsspec URL of the file, or of the archive.
    member : path inside the zip archive at ``location``; None for a plain file.
    size : bytes, when the listing knew it (used to group small files).
    """

    name: str
    location: str
    member: str | None = None
    size: int | None = None

    @property
    def key(self) -> tuple[str, str | None]:
        """Where the bytes are: two sources with one key are the same file."""
        return (self.location, self.member)


def _extension(name: str) -> str:
    base = posixpath.basename(name)
    return base.rsplit(".", 1)[1].lower() if "." in base else ""


def _hidden(name: str) -> bool:
    parts = name.replace("\\", "/").split("/")
    return any(p.startswith(".") or p == "__MACOSX" for p in parts if p)


def is_known_file(name: str) -> bool:
    """Whether a folder or archive entry named ``name`` is a mesh to analyse."""
    return not _hidden(name) and _extension(name) in KNOWN_EXTENSIONS


def _wanted(name: str) -> bool:
    """A folder entry to take: a known mesh file or a zip archive to open."""
    return is_known_file(name) or (not _hidden(name) and _extension(name) == ZIP_EXTENSION)


def _is_url(path: str) -> bool:
    return "://" in path


def _fs(url: str) -> tuple[Any, str]:
    try:
        from fsspec.core import url_to_fs  # type: ignore[import-untyped,unused-ignore]
    except ImportError as exc:
        raise InvalidParameterError(
            f"reading {url!r} needs fsspec: pip install 'inertia-service[batch]'", parameter="paths"
        ) from exc
    fs, path = url_to_fs(url)
    return fs, path


# ---------------------------------------------------------------------------
# listing (client side)


def list_sources(paths: Sequence[str]) -> list[Source]:
    """Every input file under ``paths``, named uniquely, duplicates dropped.

    Raises ``InvalidParameterError`` for a path that does not exist, before any
    work starts.
    """
    seen_keys: set[tuple[str, str | None]] = set()
    seen_names: set[str] = set()
    out: list[Source] = []
    for path in paths:
        for src in _expand(path):
            if src.key in seen_keys:
                continue
            seen_keys.add(src.key)
            if src.name in seen_names:
                full = src.location if src.member is None else f"{src.location}/{src.member}"
                src = Source(full, src.location, src.member, src.size)
            seen_names.add(src.name)
            out.append(src)
    return out


def _expand(path: str) -> Iterator[Source]:
    if _is_url(path):
        yield from _expand_url(path)
        return
    if os.path.isdir(path):
        root = os.path.abspath(path)
        for rel, size in _walk(root):
            yield from _file_or_zip(os.path.join(root, rel), rel.replace(os.sep, "/"), size)
        return
    if not os.path.isfile(path):
        raise InvalidParameterError(f"no such file or folder: {path!r}", parameter="paths")
    yield from _file_or_zip(os.path.abspath(path), os.path.basename(path), os.path.getsize(path))


def _walk(root: str) -> Iterator[tuple[str, int]]:
    """(relative path, size) of known files and zips under ``root``, sorted."""
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d != "__MACOSX")
        for fname in sorted(filenames):
            if fname.startswith("."):
                continue
            if _wanted(fname):
                full = os.path.join(dirpath, fname)
                yield os.path.relpath(full, root), os.path.getsize(full)


def _file_or_zip(location: str, name: str, size: int | None) -> Iterator[Source]:
    if _extension(name) != ZIP_EXTENSION:
        yield Source(name, location, None, size)
        return
    try:
        with _open(location) as fh, zipfile.ZipFile(fh) as zf:
            infos = zf.infolist()
    except (OSError, zipfile.BadZipFile):
        # an unreadable archive becomes one error row, like any unreadable file
        yield Source(name, location, None, size)
        return
    for info in infos:
        if not info.is_dir() and is_known_file(info.filename):
            yield Source(f"{name}/{info.filename}", location, info.filename, info.file_size)


def _expand_url(url: str) -> Iterator[Source]:
    fs, path = _fs(url)
    if not fs.exists(path):
        raise InvalidParameterError(f"no such file or folder: {url!r}", parameter="paths")
    if not fs.isdir(path):
        size = fs.info(path).get("size")
        yield from _file_or_zip(url, posixpath.basename(path.rstrip("/")), size)
        return
    root = path.rstrip("/")
    prefix = url.rstrip("/")
    found = fs.find(root, detail=True)
    for full in sorted(found):
        rel = posixpath.relpath(full, root)
        if _wanted(rel):
            yield from _file_or_zip(f"{prefix}/{rel}", rel, found[full].get("size"))


# ---------------------------------------------------------------------------
# reading (wherever the analysis runs)


def _open(location: str) -> IO[bytes]:
    if _is_url(location):
        fs, path = _fs(location)
        return fs.open(path, "rb")  # type: ignore[no-any-return]
    return open(location, "rb")


class ZipCache:
    """Archives opened while reading a group of sources; close() releases them."""

    def __init__(self) -> None:
        self._open: dict[str, tuple[IO[bytes], zipfile.ZipFile]] = {}

    def get(self, location: str) -> zipfile.ZipFile:
        if location not in self._open:
            fh = _open(location)
            try:
                self._open[location] = (fh, zipfile.ZipFile(fh))
            except BaseException:
                fh.close()
                raise
        return self._open[location][1]

    def close(self) -> None:
        for fh, zf in self._open.values():
            zf.close()
            fh.close()
        self._open.clear()


def read_source(source: Source, zips: ZipCache | None = None) -> bytes:
    """The bytes of one input; ``UnreadableFileError`` when they cannot be read."""
    try:
        if source.member is None:
            with _open(source.location) as fh:
                return fh.read()
        cache = zips or ZipCache()
        try:
            return cache.get(source.location).read(source.member)
        finally:
            if zips is None:
                cache.close()
    except (OSError, zipfile.BadZipFile, KeyError, RuntimeError, EOFError) as exc:
        what = "archive member" if source.member else "file"
        raise UnreadableFileError(
            f"cannot read {what} {source.name!r}: {exc}; check that it exists and is readable here",
            filename=source.name,
        ) from exc


def iter_inputs(paths: Sequence[str]) -> Iterator[tuple[str, bytes]]:
    """(name, bytes) of every input under ``paths``, in listing order.

    Reads one file at a time.  A file that cannot be read raises
    ``UnreadableFileError`` when reached.
    """
    zips = ZipCache()
    try:
        for src in list_sources(paths):
            yield src.name, read_source(src, zips)
    finally:
        zips.close()


def iter_zip_bytes(data: bytes, archive_name: str = "upload.zip") -> Iterator[tuple[str, bytes]]:
    """(``archive_name/member``, bytes) of the known mesh files in a zip held in memory."""
    import io

    try:
        zf = zipfile.ZipFile(io.BytesIO(data))
    except zipfile.BadZipFile as exc:
        raise UnreadableFileError(f"{archive_name!r} is not a readable zip archive", filename=archive_name) from exc
    with zf:
        members: Iterable[zipfile.ZipInfo] = zf.infolist()
        for info in members:
            if not info.is_dir() and is_known_file(info.filename):
                yield f"{archive_name}/{info.filename}", zf.read(info)
