"""Several files in one upload: a model and its companions (a ``.gltf`` and its ``.bin``, a ``.ele`` and its ``.node``).

``unpack_zip`` reads a ``.zip`` of such files, bounded before inflating
(declared sizes against ``guard.inflate_budget``; Python's zip reader never
reads past a member's declared size).  ``pick_model_file`` chooses the one
model among them; the rest are its companions, offered to its reader by name.
"""

from __future__ import annotations

import io
import posixpath
import zipfile

from ..errors import InputTooLargeError, UnreadableFileError, UnsupportedFormatError
from .guard import inflate_budget
from .sniff import FORMATS, POINT_FORMATS

__all__ = ["unpack_zip", "pick_model_file", "COMPANION_EXTENSIONS", "MAX_FILES"]

# files that only ever accompany a model: buffers, images, materials, TetGen's node/face/edge lists
COMPANION_EXTENSIONS = frozenset(
    {
        "bin",
        "png",
        "jpg",
        "jpeg",
        "webp",
        "ktx2",
        "dds",
        "mtl",
        "node",
        "face",
        "edge",
        "neigh",
        "h5",
        "hdf5",
        "heavy",
        "txt",
        "md",
        "json_meta",
    }
)
MAX_FILES = 1000  # members of one upload; a model with its companions needs a handful


def unpack_zip(data: bytes) -> list[tuple[str, bytes]]:
    """The files of a zip upload as (relative path, bytes), folders and hidden files left out."""
    try:
        archive = zipfile.ZipFile(io.BytesIO(data))
        infos = [i for i in archive.infolist() if not i.is_dir()]
    except (zipfile.BadZipFile, OSError, ValueError, EOFError, NotImplementedError) as exc:
        raise UnreadableFileError(
            "the upload is not a readable zip archive (truncated or corrupt); check the file", format="zip"
        ) from exc
    infos = [i for i in infos if not any(p.startswith((".", "__MACOSX")) for p in i.filename.split("/"))]
    if len(infos) > MAX_FILES:
        raise InputTooLargeError(f"the zip holds {len(infos)} files; at most {MAX_FILES} are accepted in one upload", format="zip")
    budget = inflate_budget(len(data))
    total = sum(i.file_size for i in infos)
    if total > budget:
        raise InputTooLargeError(
            f"the zip would inflate to {total} bytes, more than the {budget} accepted for an upload of {len(data)} bytes",
            format="zip",
            limit_bytes=budget,
        )
    files = []
    for info in infos:
        name = posixpath.normpath(info.filename.replace("\\", "/")).lstrip("/")
        if name.startswith("..") or not name:
            raise UnreadableFileError(
                f"the zip holds a file named {info.filename[:80]!r} outside its own folder; re-create the archive", format="zip"
            )
        try:
            files.append((name, archive.read(info)))
        except (zipfile.BadZipFile, OSError, ValueError, EOFError, NotImplementedError, RuntimeError) as exc:
            raise UnreadableFileError(
                f"the zip member {name[:80]!r} cannot be decompressed (corrupt or encrypted); re-create the archive", format="zip"
            ) from exc
    if not files:
        raise UnreadableFileError("the zip holds no files; put the model and its companion files in it", format="zip")
    return files


def _ext(name: str) -> str:
    base = posixpath.basename(name)
    return base.rsplit(".", 1)[1].lower() if "." in base else ""


def pick_model_file(files: list[tuple[str, bytes]], format: str | None = None) -> tuple[str, dict[str, bytes]]:
    """(name of the model file, {companion name: bytes}) of a multi-file upload.

    Companions are offered under their path in the upload and under their
    plain file name (a glTF names its buffer ``mesh.bin``, a zip may hold it
    as ``model/mesh.bin``).
    """
    if not files:
        raise UnreadableFileError("the upload holds no files; send a model file")
    names = [n for n, _ in files]
    if len(set(names)) != len(names):
        dup = sorted({n for n in names if names.count(n) > 1})
        raise UnreadableFileError(f"the upload holds two files named {dup[0]!r}; give each file its own name")
    readable = set(FORMATS) | set(POINT_FORMATS)
    if format:
        fmt = format.lower().lstrip(".")
        models = [n for n in names if _ext(n) == fmt] or [n for n in names if _ext(n) not in COMPANION_EXTENSIONS]
    else:
        models = [n for n in names if _ext(n) in readable and _ext(n) not in COMPANION_EXTENSIONS]
    if not models:
        raise UnsupportedFormatError(
            f"the upload holds no model file ({', '.join(n[:60] for n in names[:8])}); include one of the readable "
            f"formats ({', '.join(FORMATS)}) beside its companion files",
            files=names[:50],
        )
    if len(models) > 1:
        models = _not_included(models, dict(files))
    if len(models) > 1:
        raise UnsupportedFormatError(
            f"the upload holds {len(models)} model files ({', '.join(m[:60] for m in models[:8])}); send one model "
            "(with its companion files) per upload, or analyse them one by one with batch",
            files=models[:50],
        )
    main = models[0]
    companions: dict[str, bytes] = {}
    for name, data in files:
        if name == main:
            continue
        companions[name] = data
        companions.setdefault(posixpath.basename(name), data)
    return main, companions


def _not_included(models: list[str], data: dict[str, bytes]) -> list[str]:
    """The candidates no Abaqus deck among them reads: a deck and the files it includes (``.inp``, or a
    CalculiX ``all.msh``) are one model.

    Includes name plain files (``guard.plain_name``), offered under their base name.
    """
    decks = [n for n in models if _ext(n) == "inp"]
    if not decks:
        return models
    from .volume import abaqus_input_names

    read = set().union(*(abaqus_input_names(data[deck]) for deck in decks))
    return [n for n in models if posixpath.basename(n) not in read] or models
