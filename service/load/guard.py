"""Checks on an upload's bytes before any reader sees them.

Two kinds of hostile input are refused here, at the one place where bytes
enter the loading stage (``load_body``), so the library and the HTTP API are
protected alike:

- **References to other files.** Several formats can name another file, a
  path or a URL, that their reader would then open on the server: Abaqus
  ``*INCLUDE, INPUT=`` (and ``INPUT=`` on any keyword), Nastran ``INCLUDE``,
  XDMF ``Binary``/``HDF`` data items and XInclude, VTK XML ``<Piece
  Source=...>`` (parallel files), glTF buffer and image URIs, HDF5 external
  links in MED files. Such a file is refused (:class:`ExternalReferenceError`)
  unless the referenced name is a plain file name that came in the same
  upload (``companions``). XML document type declarations are refused in
  every XML format: they are how external entities and entity expansion
  bombs are declared, and no mesh file needs one.
- **Sizes that lie or explode.** Compressed content is measured before it is
  inflated: zip members (3MF) by their declared sizes, which Python's zip
  reader never reads past; VTK XML compressed blocks by their headers, and
  every block is inflated with a bound of its declared size, discarding the
  output, so a block that inflates past what its header says is caught
  without holding it. The total may not exceed :func:`inflate_budget` of
  the upload's size (:class:`InputTooLargeError`). GLB chunk lengths, and
  the element counts in PLY and OFF headers, must fit in the file.

What each reader does with each kind of reference is tabled in
``docs/security.md``.
"""

from __future__ import annotations

import base64
import binascii
import io
import json
import lzma
import re
import struct
import zipfile
import zlib
from collections.abc import Callable, Collection, Iterator
from dataclasses import dataclass
from pathlib import PurePosixPath, PureWindowsPath
from typing import Any
from urllib.parse import unquote

from ..errors import ExternalReferenceError, InputTooLargeError, UnreadableFileError, UnsupportedFormatError

__all__ = [
    "check_upload",
    "own_name",
    "xml_attributes",
    "XDMF_DATA_ITEM",
    "plain_name",
    "refuse_reference",
    "inflate_budget",
    "INFLATE_RATIO",
    "INFLATE_FLOOR_BYTES",
    "MAX_INFLATED_BYTES",
    "MAX_JSON_DEPTH",
]

MIB = 1024 * 1024
# deflate cannot exceed ~1032:1; real mesh files (3MF XML, VTU float blocks) compress 3-20:1,
# so 100:1 leaves room for very regular meshes while a bomb (1000:1 and up) is refused
INFLATE_RATIO = 100
INFLATE_FLOOR_BYTES = 64 * MIB  # a small upload may always inflate to this much
MAX_INFLATED_BYTES = 4096 * MIB  # and no upload past this, whatever its size
MAX_JSON_DEPTH = 64  # glTF documents nest about 6 deep; deeper is hostile, not a model
_CHUNK = 1 * MIB  # inflation step while scanning zip members


def inflate_budget(size: int) -> int:
    """The most bytes an upload of ``size`` bytes may inflate to [bytes]."""
    return min(MAX_INFLATED_BYTES, max(INFLATE_FLOOR_BYTES, INFLATE_RATIO * size))


@dataclass(slots=True)
class _Context:
    fmt: str
    companions: frozenset[str]
    budget: int
    inflated: int = 0

    def inflate(self, nbytes: int, what: str) -> None:
        """Count ``nbytes`` more of inflated content; refuse past the budget."""
        self.inflated += nbytes
        if self.inflated > self.budget:
            raise InputTooLargeError(
                f"the {self.fmt.upper()} file would inflate to more than {self.budget} bytes ({what}); "
                f"at most {INFLATE_RATIO} times the upload's size (or {INFLATE_FLOOR_BYTES} bytes) is accepted",
                limit_bytes=self.budget,
                format=self.fmt,
            )

    def reference(self, target: str, what: str) -> None:
        """Accept a referenced file only if it is a plain name that came in the same upload."""
        name = own_name(target.strip().strip("'\""))
        if plain_name(name) and name in self.companions:
            return
        fix = (
            "send the referenced file in the same upload, or a self-contained file"
            if plain_name(name)
            else "it names it by a path, which is never followed (not even within a .zip): name the file by its "
            "plain file name and send it in the same upload, or send a self-contained file"
        )
        raise ExternalReferenceError(
            f"the {self.fmt.upper()} file refers to another file ({what} {name[:120]!r}); the server never "
            f"opens files named by an upload: {fix}",
            format=self.fmt,
            reference=name[:200],
            reference_kind=what,
        )


def refuse_reference(fmt: str, target: str, what: str, companions: Collection[str]) -> None:
    """Refuse ``target`` unless it is a plain file name among ``companions`` (for readers that find references late)."""
    _Context(fmt, frozenset(companions), 0).reference(target, what)


def _relative_within(name: str) -> bool:
    """A relative path that stays below its folder: no scheme or drive, no root, no '..' step."""
    if not name or ":" in name or name.startswith(("/", "\\")):
        return False
    return ".." not in PurePosixPath(name.replace("\\", "/")).parts


def own_name(name: str) -> str:
    """The name without leading ``./`` (the folder itself): ``./mesh.bin`` is ``mesh.bin``."""
    while name.startswith(("./", ".\\")):
        name = name[2:]
    return name


def plain_name(name: str) -> bool:
    """A file's own name: no folder (either separator), no drive or scheme, not '.' or '..'."""
    if not name or ":" in name or name in (".", ".."):
        return False
    return PurePosixPath(name).name == name and PureWindowsPath(name).name == name


def check_upload(data: bytes, fmt: str, companions: Collection[str] = ()) -> None:
    """Refuse ``data`` (format ``fmt``) if it names a file outside ``companions`` or inflates past its budget.

    companions : the plain file names of the other files that came in the same upload.
    Raises ``ExternalReferenceError`` (422), ``InputTooLargeError`` (413) or
    ``UnreadableFileError`` (422, a header that contradicts the file).
    """
    check = _CHECKS.get(fmt)
    if check is not None:
        check(data, _Context(fmt, frozenset(companions), inflate_budget(len(data))))


# --- text formats with include statements ----------------------------------------------------------

# Abaqus: INPUT= on *INCLUDE, and on any keyword that may read its data lines from a file (*NODE, ...);
# a line starting with ** is a comment
_ABAQUS_INPUT = re.compile(rb"^[ \t]*\*(?!\*)[^\n]*?\binput[ \t]*=[ \t]*([^,\r\n]*)", re.IGNORECASE | re.MULTILINE)
_NASTRAN_INCLUDE = re.compile(rb"^[ \t]*include[ \t]+([^\r\n]*)", re.IGNORECASE | re.MULTILINE)


def _check_abaqus(data: bytes, ctx: _Context) -> None:
    for match in _ABAQUS_INPUT.finditer(data):
        ctx.reference(match.group(1).decode("utf-8", "replace"), "INPUT=")


def _check_nastran(data: bytes, ctx: _Context) -> None:
    for match in _NASTRAN_INCLUDE.finditer(data):
        ctx.reference(match.group(1).decode("utf-8", "replace"), "INCLUDE")


# --- XML ---------------------------------------------------------------------------------------------

_DOCTYPE = re.compile(rb"<!(?:DOCTYPE|ENTITY)", re.IGNORECASE)
_ATTR = re.compile(rb"([\w:]+)\s*=\s*(?:\"([^\"]*)\"|'([^']*)')")


def xml_attributes(text: bytes) -> dict[str, str]:
    return {
        m.group(1).decode("ascii", "replace"): (m.group(2) if m.group(2) is not None else m.group(3) or b"").decode(
            "utf-8", "replace"
        )
        for m in _ATTR.finditer(text)
    }


# a document type that names a DTD by a plain file name and declares nothing itself, as XDMF files write
# theirs (<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>): XML parsers do not fetch the DTD, and there is nothing to
# expand; a DTD named by a path, a URL or a PUBLIC identifier is refused as any other declaration
_BARE_DOCTYPE = re.compile(
    rb"<!DOCTYPE[ \t\r\n]+[\w:.-]+(?:[ \t\r\n]+SYSTEM[ \t\r\n]+(?:\"[\w.-]*\"|'[\w.-]*'))?"
    rb"[ \t\r\n]*(?:\[[ \t\r\n]*\])?[ \t\r\n]*>",
    re.IGNORECASE,
)


def _refuse_doctype(xml: bytes, ctx: _Context, bare_allowed: bool = False) -> None:
    """Refuse a document type or entity declarations; with ``bare_allowed``, one that only names a DTD passes."""
    if bare_allowed:
        xml = _BARE_DOCTYPE.sub(b"", xml, count=1)
    if _DOCTYPE.search(xml):
        raise ExternalReferenceError(
            f"the {ctx.fmt.upper()} file declares a document type or entities (<!DOCTYPE>/<!ENTITY>), which can "
            "name files on the server or expand without bound; remove the declaration",
            format=ctx.fmt,
        )


_TAG_ATTRIBUTES = rb"((?:[^>\"']|\"[^\"]*\"|'[^']*')*)"  # a tag's attributes: a '>' inside a quoted value is no end
XDMF_DATA_ITEM = re.compile(rb"<DataItem\b" + _TAG_ATTRIBUTES + rb">([^<]*)", re.IGNORECASE)
_XINCLUDE = re.compile(rb"<[\w]*:?include\b" + _TAG_ATTRIBUTES + rb">", re.IGNORECASE)


def _check_xdmf(data: bytes, ctx: _Context) -> None:
    _refuse_doctype(data, ctx, bare_allowed=True)
    for match in _XINCLUDE.finditer(data):
        href = xml_attributes(match.group(1)).get("href", "")
        if href.strip():  # none: a part of this same document (an xpointer, as time series repeat their mesh)
            ctx.reference(href, "XInclude href")
    for match in XDMF_DATA_ITEM.finditer(data):
        fmt = xml_attributes(match.group(1)).get("Format", "XML")
        if fmt.upper() in ("HDF", "BINARY"):
            text = match.group(2).decode("utf-8", "replace").strip()
            ctx.reference(text.split(":", 1)[0] if fmt.upper() == "HDF" else text, f"{fmt} data item")


# VTK XML (vtu and the other serial XML formats): Piece Source= is how the parallel formats name files
_VTK_ROOT = re.compile(rb"<VTKFile\b([^>]*)>")
_PIECE_SOURCE = re.compile(rb"<Piece\b[^>]*\bSource\s*=\s*[\"']([^\"']*)", re.IGNORECASE)
_DATA_ARRAY = re.compile(rb"<DataArray\b([^>]*?)(/?)>")
_PIECE = re.compile(rb"<Piece\b" + _TAG_ATTRIBUTES + rb">")
_PIECE_COUNTS = ("NumberOfPoints", "NumberOfCells", "NumberOfVerts", "NumberOfLines", "NumberOfStrips", "NumberOfPolys")
_APPENDED = re.compile(rb"<AppendedData\b([^>]*)>")
_HEADER_TYPES = {"UInt32": "I", "UInt64": "Q"}
_BLOCK_COMPRESSORS = ("vtkZLibDataCompressor", "vtkLZMADataCompressor", "vtkLZ4DataCompressor")


def _check_vtk_xml(data: bytes, ctx: _Context) -> None:
    appended = _APPENDED.search(data)
    xml = data[: appended.end()] if appended else data
    _refuse_doctype(xml, ctx)
    for match in _PIECE_SOURCE.finditer(xml):
        ctx.reference(match.group(1).decode("utf-8", "replace"), "Piece Source")
    root = _VTK_ROOT.search(xml)
    attrs = xml_attributes(root.group(1)) if root else {}
    compressor = attrs.get("compressor")
    _check_vtk_counts(xml, ctx.budget if compressor else len(data), ctx)
    if not compressor:
        return  # uncompressed arrays are no larger than the file
    if compressor not in _BLOCK_COMPRESSORS:
        raise UnreadableFileError(f"the VTK file names an unknown compressor {compressor!r}", format=ctx.fmt)
    order = ">" if attrs.get("byte_order") == "BigEndian" else "<"
    header = order + _HEADER_TYPES.get(attrs.get("header_type", "UInt32"), "I")
    blocks = _Blocks(ctx, header, compressor)
    offsets: list[int] = []
    for match in _DATA_ARRAY.finditer(xml):
        arr = xml_attributes(match.group(1))
        fmt = arr.get("format", "ascii")
        if fmt == "binary" and not match.group(2):
            end = xml.find(b"</DataArray>", match.end())
            blocks.check_base64(xml[match.end() : end if end >= 0 else len(xml)])
        elif fmt == "appended":
            offsets.append(_int(arr.get("offset", "0"), ctx))
    if offsets and appended:
        _check_appended(data, appended, offsets, blocks)


def _check_vtk_counts(xml: bytes, limit: int, ctx: _Context) -> None:
    """Refuse a piece's count or an array's component count that is no count, or more values than the file
    can hold (``limit``: its size, each value taking a byte at least; compressed, the inflation budget).
    VTK's readers trust them: a negative count crashed the process, 1e12 components looped for minutes."""

    def count(text: str, name: str) -> int:
        value = text.strip()
        if not (value.isascii() and value.isdigit()):
            raise UnreadableFileError(f"the VTK file gives {name}={text!r}, which is no count", format=ctx.fmt)
        if int(value) > limit:
            raise UnreadableFileError(
                f"the VTK file gives {name}={value}, more values than its data can hold; it is corrupt", format=ctx.fmt
            )
        return int(value)

    for match in _PIECE.finditer(xml):
        piece = xml_attributes(match.group(1))
        for name in _PIECE_COUNTS:
            if name in piece:
                count(piece[name], name)
    for match in _DATA_ARRAY.finditer(xml):
        array = xml_attributes(match.group(1))
        components = count(array.get("NumberOfComponents", "1"), "NumberOfComponents")
        tuples = count(array["NumberOfTuples"], "NumberOfTuples") if "NumberOfTuples" in array else 1
        if components * tuples > limit:
            raise UnreadableFileError(
                f"the VTK file gives an array of {components} components for {tuples} tuples, more values than its "
                "data can hold; it is corrupt",
                format=ctx.fmt,
            )


# a legacy VTK file's keywords followed by counts (VTK's reader takes its keywords in any case)
_LEGACY_COUNTS = re.compile(
    rb"^[ \t]*(POINTS|CELLS|CELL_TYPES|VERTICES|LINES|POLYGONS|TRIANGLE_STRIPS|POINT_DATA|CELL_DATA"
    rb"|[XYZ]_COORDINATES)[ \t]+([^ \t\r\n]*)(?:[ \t]+([0-9+-][^ \t\r\n]*))?",
    re.IGNORECASE | re.MULTILINE,
)
_LEGACY_SIZES = (b"CELLS", b"VERTICES", b"LINES", b"POLYGONS", b"TRIANGLE_STRIPS")


def _check_legacy_vtk(data: bytes, ctx: _Context) -> None:
    """Refuse a legacy VTK count that is no count or more than the file can hold: VTK's reader trusts them
    (``POINTS -1 double`` crashed the process)."""
    for match in _LEGACY_COUNTS.finditer(data):
        keyword = match.group(1).upper()
        values = [match.group(2)] + ([match.group(3)] if keyword in _LEGACY_SIZES and match.group(3) else [])
        for value in values:
            if not value.isdigit() or int(value) > len(data):
                text = b" ".join(v for v in match.groups() if v).decode("latin-1")[:80]
                raise UnreadableFileError(
                    f"the legacy VTK file's {text!r} gives a count that is no count or more than the file holds; it is corrupt",
                    format=ctx.fmt,
                )


def _check_appended(data: bytes, tag: re.Match[bytes], offsets: list[int], blocks: _Blocks) -> None:
    start = data.find(b"_", tag.end())
    stop = data.rfind(b"</AppendedData>")
    if start < 0:
        raise UnreadableFileError("the VTK file's appended data does not start with '_'", format=blocks.ctx.fmt)
    blob = data[start + 1 : stop if stop > start else len(data)]
    base64_encoded = xml_attributes(tag.group(1)).get("encoding", "raw") == "base64"
    for offset in offsets:
        if base64_encoded:
            blocks.check_base64(blob[offset:], appended=True)
        else:
            blocks.check(blob, offset)


def _int(text: str, ctx: _Context) -> int:
    try:
        value = int(text)
    except ValueError:
        raise UnreadableFileError(f"the {ctx.fmt.upper()} file has a non-integer size or offset {text!r}", format=ctx.fmt) from None
    if value < 0:
        raise UnreadableFileError(f"the {ctx.fmt.upper()} file has a negative size or offset {value}", format=ctx.fmt)
    return value


class _Blocks:
    """VTK's compressed-array layout: [nblocks, block size, last block size, compressed sizes...] then blocks."""

    def __init__(self, ctx: _Context, header: str, compressor: str) -> None:
        self.ctx = ctx
        self.header = header
        self.item = struct.calcsize(header)
        self.compressor = compressor

    def _lie(self, what: str) -> UnreadableFileError:
        return UnreadableFileError(
            f"the VTK file's compressed data header does not match its content ({what}); the file is corrupt or truncated",
            format=self.ctx.fmt,
        )

    def check_base64(self, text: bytes, appended: bool = False) -> None:
        """An array in base64: the header and the blocks are encoded separately (as VTK writes them)."""
        clean = b"".join(text.split())
        first = _b64(clean[: _b64_chars(self.item)])
        if first is None or len(first) < self.item:
            raise self._lie("invalid base64")
        (count,) = struct.unpack_from(self.header, first)
        if count > len(clean):
            raise self._lie(f"{count} blocks declared")
        chars = _b64_chars((3 + count) * self.item)
        head, rest = _b64(clean[:chars]), clean[chars:]
        if appended:  # an appended array runs up to the next one; decode whole quads only
            rest = rest[: len(rest) - len(rest) % 4]
        blocks = _b64(rest)
        if head is None or blocks is None:
            raise self._lie("invalid base64")
        self.check(head[: (3 + count) * self.item] + blocks, 0)

    def check(self, buf: bytes, offset: int) -> None:
        item = self.item
        if offset + item > len(buf):
            raise self._lie("an array starts past the end of the data")
        (count,) = struct.unpack_from(self.header, buf, offset)
        if count > len(buf) // item:
            raise self._lie(f"{count} blocks declared")
        if offset + (3 + count) * item > len(buf):
            raise self._lie("the block table runs past the end of the data")
        fields = struct.unpack_from(self.header[0] + self.header[1] * (3 + count), buf, offset)
        block, last, sizes = fields[1], fields[2], fields[3:]
        declared = (count - 1) * block + (last or block) if count else 0
        self.ctx.inflate(declared, f"compressed blocks declare {declared} bytes")
        position = offset + (3 + count) * item
        if position + sum(sizes) > len(buf):
            raise self._lie("the blocks run past the end of the data")
        for k, size in enumerate(sizes):
            expected = last if (k == count - 1 and last) else block
            self._inflate_one(buf[position : position + size], expected)
            position += size

    def _inflate_one(self, chunk: bytes, expected: int) -> None:
        if self.compressor == "vtkLZ4DataCompressor":
            return  # no lz4 reader here: no reader inflates it either, the declared sizes were counted
        decompressor: Any = zlib.decompressobj() if self.compressor == "vtkZLibDataCompressor" else lzma.LZMADecompressor()
        try:
            out = decompressor.decompress(chunk, expected + 1)
        except (zlib.error, lzma.LZMAError) as exc:
            raise self._lie(f"a block does not inflate: {exc}") from None
        if len(out) > expected:
            raise InputTooLargeError(
                f"a compressed block of the {self.ctx.fmt.upper()} file inflates past the {expected} bytes "
                "its header declares; refused before inflating it",
                format=self.ctx.fmt,
            )


def _b64_chars(nbytes: int) -> int:
    return -(-nbytes // 3) * 4


def _b64(text: bytes) -> bytes | None:
    try:
        return base64.b64decode(text, validate=False)
    except (binascii.Error, ValueError):
        return None


# --- zip packages (3MF) ------------------------------------------------------------------------------


BARE_3MF_MODEL = (
    "the 3MF file is a bare XML model (the 3D/3dmodel.model part of a package), not the zip package a 3MF "
    "file is (3MF core specification, ch. 2); send the .3mf file the program wrote, or zip the model with "
    "its _rels/.rels and [Content_Types].xml"
)


def _check_zip(data: bytes, ctx: _Context) -> None:
    try:
        archive = zipfile.ZipFile(io.BytesIO(data))
    except (zipfile.BadZipFile, OSError, ValueError, EOFError, NotImplementedError) as exc:
        if ctx.fmt == "3mf" and data.lstrip(b"\xef\xbb\xbf \t\r\n").startswith(b"<"):
            raise UnreadableFileError(BARE_3MF_MODEL, format=ctx.fmt) from None
        raise UnreadableFileError(f"the {ctx.fmt.upper()} file is not a readable zip package ({exc})", format=ctx.fmt) from None
    with archive:
        infos = archive.infolist()
        for info in infos:  # declared sizes first: a bomb is refused before anything is inflated
            ctx.inflate(info.file_size, f"{info.filename} declares {info.file_size} bytes")
        for info in infos:
            if info.filename.lower().endswith((".model", ".rels", ".xml")):
                _scan_member(archive, info, ctx)


def _scan_member(archive: zipfile.ZipFile, info: zipfile.ZipInfo, ctx: _Context) -> None:
    """Inflate one XML member in steps (zipfile stops at the declared size) looking for a DOCTYPE."""
    tail = b""
    try:
        with archive.open(info) as fh:
            for chunk in iter(lambda: fh.read(_CHUNK), b""):
                _refuse_doctype(tail + chunk, ctx)
                tail = chunk[-16:]
    except (
        zipfile.BadZipFile,
        OSError,
        ValueError,
        EOFError,
        NotImplementedError,
        RuntimeError,
        zlib.error,
        lzma.LZMAError,
    ) as exc:
        raise UnreadableFileError(
            f"cannot inflate {info.filename} from the {ctx.fmt.upper()} package ({exc})", format=ctx.fmt
        ) from None


# --- glTF ---------------------------------------------------------------------------------------------


def _json_document(text: bytes, ctx: _Context) -> Any:
    try:
        doc = json.loads(text)
    except (UnicodeDecodeError, ValueError) as exc:
        raise UnreadableFileError(f"the {ctx.fmt.upper()} file's JSON is not valid ({exc})", format=ctx.fmt) from None
    except RecursionError:
        doc = None
    if doc is None or _depth_exceeds(doc, MAX_JSON_DEPTH):
        raise UnreadableFileError(
            f"the {ctx.fmt.upper()} file's JSON nests deeper than {MAX_JSON_DEPTH} levels; no model needs that", format=ctx.fmt
        )
    return doc


def _depth_exceeds(doc: Any, limit: int) -> bool:
    stack: list[tuple[Any, int]] = [(doc, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > limit:
            return True
        children: Iterator[Any] = (
            iter(node.values()) if isinstance(node, dict) else iter(node) if isinstance(node, list) else iter(())
        )
        stack.extend((child, depth + 1) for child in children if isinstance(child, (dict, list)))
    return False


def _check_gltf_uris(doc: Any, ctx: _Context) -> None:
    """Every external buffer must have come in the upload; an image only has to stay below the model's folder.

    Images carry no geometry: the reader skips materials, and its resolver holds only the upload's files,
    so a texture that did not come along (``textures/wood.png``) is neither needed nor looked for.  An image
    named by a URL, an absolute path or one that climbs out with ``..`` is refused all the same, as any
    other reference out of the upload is.
    """
    if not isinstance(doc, dict):
        raise UnreadableFileError(f"the {ctx.fmt.upper()} file's JSON is not an object", format=ctx.fmt)
    for key in ("buffers", "images"):
        entries = doc.get(key)
        for entry in entries if isinstance(entries, list) else ():
            uri = entry.get("uri") if isinstance(entry, dict) else None
            if not isinstance(uri, str) or uri.startswith("data:"):
                continue
            if key == "images" and _relative_within(unquote(uri.strip())):
                continue
            ctx.reference(uri, f"{key[:-1]} uri")


def _check_gltf(data: bytes, ctx: _Context) -> None:
    _check_gltf_uris(_json_document(data, ctx), ctx)


_GLB_JSON = 0x4E4F534A


def _check_glb(data: bytes, ctx: _Context) -> None:
    if len(data) < 12 or data[:4] != b"glTF":
        raise UnreadableFileError("the GLB file does not start with a glTF header", format=ctx.fmt)
    version, length = struct.unpack_from("<II", data, 4)
    if version == 1:
        raise UnsupportedFormatError(
            "the GLB file is binary glTF 1.0, which this service does not read (glTF 2.0 only); convert it to "
            "glTF 2.0, e.g. with gltf-pipeline or by importing and exporting it in Blender",
            format=ctx.fmt,
            version="1.0",
        )
    if version != 2:
        raise UnreadableFileError(
            f"the GLB header gives version {version}; binary glTF 2.0 has version 2 (glTF 2.0 section 4.4.2): the file is "
            "corrupt or not a GLB",
            format=ctx.fmt,
        )
    if length < 20:
        raise UnreadableFileError(
            f"the GLB header declares {length} bytes, too few for its 12-byte header and a chunk: export it again",
            format=ctx.fmt,
        )
    if length > len(data):
        raise UnreadableFileError(
            f"the GLB header declares {length} bytes but the file has {len(data)}; it is truncated or corrupt: export it again",
            format=ctx.fmt,
        )
    # bytes after the declared length are not part of the GLB (the validator's GLB_EXTRA_DATA, a warning):
    # the reader leaves them out with a note (``meshes.read_trimesh_parts``)
    position = 12
    while position + 8 <= length:
        size, kind = struct.unpack_from("<II", data, position)
        if position + 8 + size > length:
            raise UnreadableFileError(f"a GLB chunk declares {size} bytes, past the end its header declares", format=ctx.fmt)
        if kind == _GLB_JSON:
            _check_gltf_uris(_json_document(data[position + 8 : position + 8 + size], ctx), ctx)
        position += 8 + size


# --- headers with element counts -----------------------------------------------------------------------

_PLY_SCALARS = {
    "char": 1,
    "uchar": 1,
    "int8": 1,
    "uint8": 1,
    "short": 2,
    "ushort": 2,
    "int16": 2,
    "uint16": 2,
    "int": 4,
    "uint": 4,
    "int32": 4,
    "uint32": 4,
    "float": 4,
    "float32": 4,
    "double": 8,
    "float64": 8,
}


def _check_ply(data: bytes, ctx: _Context) -> None:
    end = data.find(b"end_header")
    if end < 0:
        return  # the reader reports the missing header
    lines = data[:end].decode("ascii", "replace").splitlines()
    binary = any(line.startswith("format binary") for line in lines)
    elements: list[tuple[int, int]] = []  # (count, least bytes per element)
    for line in lines:
        words = line.split()
        if len(words) == 3 and words[0] == "element":
            elements.append((_int(words[2], ctx), 0))
        elif len(words) >= 3 and words[0] == "property" and elements:
            count, least = elements[-1]
            size = _PLY_SCALARS.get(words[2] if words[1] == "list" else words[1], 1)
            elements[-1] = (count, least + (size if binary else 2))
    body = len(data) - end - len(b"end_header")
    need = sum(count * max(least, 1) for count, least in elements)
    if need > body:
        raise UnreadableFileError(
            f"the PLY header declares elements needing at least {need} bytes, but only {body} "
            "follow it; the header is wrong or the file truncated",
            format=ctx.fmt,
        )


def _check_off(data: bytes, ctx: _Context) -> None:
    words = re.sub(rb"#[^\n]*", b"", data[:4096]).split()
    if not words or not words[0].endswith(b"OFF"):
        return
    counts = words[1:3]
    if len(counts) < 2 or not all(w.isdigit() for w in counts):
        return
    vertices, faces = int(counts[0]), int(counts[1])
    need = 6 * vertices + 8 * faces  # "0 0 0\n" and "3 0 1 2\n" are the shortest lines
    if need > len(data):
        raise UnreadableFileError(
            f"the OFF header declares {vertices} vertices and {faces} faces, needing at least "
            f"{need} bytes, but the file has {len(data)}; the header is wrong or the file "
            "truncated",
            format=ctx.fmt,
        )


# --- HDF5 (MED) ---------------------------------------------------------------------------------------


def _check_hdf5(data: bytes, ctx: _Context) -> None:
    try:
        import h5py
    except ImportError:
        return  # without h5py no reader can open it either
    try:
        with h5py.File(io.BytesIO(data), "r") as f:
            _hdf5_links(f, ctx, h5py)
    except (OSError, ValueError, KeyError) as exc:
        raise UnreadableFileError(f"the {ctx.fmt.upper()} file is not readable HDF5 ({exc})", format=ctx.fmt) from None


def _hdf5_links(group: Any, ctx: _Context, h5py: Any) -> None:
    for name in group:
        link = group.get(name, getlink=True)
        if isinstance(link, h5py.ExternalLink):
            ctx.reference(link.filename, "HDF5 external link")
        elif isinstance(link, h5py.SoftLink):
            continue
        item = group.get(name)
        if isinstance(item, h5py.Group):
            _hdf5_links(item, ctx, h5py)
        elif isinstance(item, h5py.Dataset) and item.external:
            ctx.reference(str(item.external[0][0]), "HDF5 external dataset")


_CHECKS: dict[str, Callable[[bytes, _Context], None]] = {
    "inp": _check_abaqus,
    "bdf": _check_nastran,
    "nas": _check_nastran,
    "fem": _check_nastran,
    "xdmf": _check_xdmf,
    "xmf": _check_xdmf,
    "vtk": _check_legacy_vtk,
    "vtu": _check_vtk_xml,
    "vtp": _check_vtk_xml,
    "vts": _check_vtk_xml,
    "vtr": _check_vtk_xml,
    "vti": _check_vtk_xml,
    "pvtu": _check_vtk_xml,
    "3mf": _check_zip,
    "gltf": _check_gltf,
    "glb": _check_glb,
    "ply": _check_ply,
    "off": _check_off,
    "med": _check_hdf5,
}
