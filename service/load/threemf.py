"""3MF packages read as the 3MF Core Specification (1.3) and its Production extension say.

Our own reader (zipfile + lxml) rather than trimesh's, for three reasons: the
object ``type`` decides what is weighed (only ``model`` objects are; ``support``,
``solidsupport``, ``surface`` and ``other`` are listed in a note and left
out), the Production extension places objects in separate model parts
(``p:path``), and a conforming consumer must refuse malformed packages (the 3MF
Consortium's MUSTFAIL samples) rather than guess.

What is checked, with the specification's chapter:

- OPC package (ch. 2): ``[Content_Types].xml`` and ``_rels/.rels`` present;
  exactly one 3D Model start-part relationship whose target exists; no
  relationship to anything outside the package (``TargetMode="External"``);
  thumbnail targets exist; at most one PrintTicket per part.
- XML (ch. 2.3): UTF-8 or UTF-16 only; no document type declaration (DTDs
  are forbidden, and entity expansion is never performed); no ``xml:space``;
  every prefix declared (the parser refuses an undeclared one).
- Model (ch. 3): root ``model`` in the core namespace; a known ``unit``;
  ``requiredextensions`` we can honour (core, production, materials, slice);
  exactly one ``resources`` and one ``build``; metadata with a name, no name
  twice.
- Resources (ch. 4, materials extension ch. 2-6): ids positive integers,
  unique across every resource of a model part; an object's ``type`` one of
  the five; ``pid`` names an earlier property resource and ``pindex`` (and
  triangle ``p1..p3``) lies within it, ``pindex`` never without a ``pid``;
  colours and texture coordinates complete; composite materials name base
  materials; multiproperties mix at most one material and one colour group
  and never another multiproperties.
- Meshes (ch. 4.1): vertex indices in range and distinct per triangle; the
  mesh of a ``model`` object closed, manifold and consistently oriented (every
  edge in exactly two triangles, once in each direction), judged after the
  welding and seam merge of ``seams`` (CAD exporters such as SolidWorks write
  each seam vertex once per face; that is a closed solid, reported as merged).  An object holds a
  mesh or components, not both; components name objects defined before them.
- Build (ch. 3.4): items name existing objects, never of type ``other``;
  transforms are 12 finite numbers with a non-zero determinant.  A mirroring
  transform (negative determinant) reverses the triangles' winding so a part
  stays wound outward.  A placement within 1e-5 of a rotation is that rotation
  written to few digits and is placed by it, with a warning (``_ROTATION_DIGITS``).

Paths are only ever looked up inside the zip: nothing on disk or the network
is opened.
"""

from __future__ import annotations

import io
import math
import zipfile
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import EmptyGeometryError, InvalidParameterError, NotWatertightError, UnreadableFileError, UnsupportedFormatError

__all__ = ["ThreeMF", "read_3mf", "InvalidPackageError"]

CORE = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
DRAFT_093 = "http://schemas.microsoft.com/3dmanufacturing/2013/01"  # 3MF 0.93, before the 1.0 specification
PROD = "http://schemas.microsoft.com/3dmanufacturing/production/2015/06"
MAT = "http://schemas.microsoft.com/3dmanufacturing/material/2015/02"
SLICE = "http://schemas.microsoft.com/3dmanufacturing/slice/2015/07"
BEAM = "http://schemas.microsoft.com/3dmanufacturing/beamlattice/2017/02"
RELS = "http://schemas.openxmlformats.org/package/2006/relationships"
REL_MODEL = "http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"
REL_THUMBNAIL = "http://schemas.openxmlformats.org/package/2006/relationships/metadata/thumbnail"
REL_PRINTTICKET = "http://schemas.microsoft.com/3dmanufacturing/2013/01/printticket"
XML_NS = "http://www.w3.org/XML/1998/namespace"
_SUPPORTED = {CORE, PROD, MAT, SLICE}
_UNITS = {"micron": "um", "millimeter": "mm", "centimeter": "cm", "inch": "in", "foot": "ft", "meter": "m"}
_TYPES = ("model", "support", "solidsupport", "surface", "other")
_PROPERTY_TAGS = {
    f"{{{CORE}}}basematerials": "base",
    f"{{{MAT}}}colorgroup": "color",
    f"{{{MAT}}}texture2dgroup": "tex2coord",
    f"{{{MAT}}}compositematerials": "composite",
    f"{{{MAT}}}multiproperties": "multi",
}
_MAX_DEPTH = 32  # component nesting; deeper is a cycle or a hostile file


class InvalidPackageError(UnreadableFileError):
    """The package breaks a MUST of the 3MF specification (a Consortium MUSTFAIL case)."""


def _invalid(what: str, rule: str) -> InvalidPackageError:
    return InvalidPackageError(
        f"the 3MF file is invalid: {what} ({rule} of the 3MF specification); re-export it from the program that made it",
        format="3mf",
        rule=rule,
    )


@dataclass
class ThreeMF:
    """What a 3MF package holds: weighed parts (name, vertices, triangles), unit, notes."""

    parts: list[tuple[str, NDArray[np.float64], NDArray[np.int64]]]
    unit: str
    notes: list[str] = field(default_factory=list)
    assumed: dict[str, float] = field(default_factory=dict)
    """Per part, the relative error bound of what its notes assume (``body.MeshBody.assumed_error``)."""


@dataclass
class _Object:
    id: int
    type: str
    name: str
    vertices: NDArray[np.float64] | None = None
    triangles: NDArray[np.int64] | None = None
    components: list[tuple[str, int, NDArray[np.float64]]] = field(default_factory=list)


@dataclass
class _Part:
    path: str
    objects: dict[int, _Object]
    unit: str
    items: list[tuple[str, int, NDArray[np.float64], str]] = field(default_factory=list)


def read_3mf(data: bytes) -> ThreeMF:
    try:
        archive = zipfile.ZipFile(io.BytesIO(data))
        names = {"/" + n.lstrip("/").lower(): n for n in archive.namelist()}
    except (zipfile.BadZipFile, OSError, ValueError, EOFError, NotImplementedError) as exc:
        raise UnreadableFileError(
            "the 3MF file is not a readable zip package (truncated or not a 3MF file); check the file or re-export it", format="3mf"
        ) from exc
    reader = _Reader(archive, names)
    return reader.read()


class _Reader:
    def __init__(self, archive: zipfile.ZipFile, names: dict[str, str]) -> None:
        self.archive = archive
        self.names = names
        self.parts: dict[str, _Part] = {}

    # --- package ---------------------------------------------------------------------------------
    def member(self, path: str) -> bytes | None:
        key = "/" + path.lstrip("/").lower()
        name = self.names.get(key)
        if name is None:
            return None
        try:
            return self.archive.read(name)
        except (zipfile.BadZipFile, OSError, ValueError, EOFError, NotImplementedError, RuntimeError) as exc:
            raise UnreadableFileError(
                f"the 3MF file's part {path!r} cannot be decompressed (a corrupt or encrypted zip entry); re-export the file",
                format="3mf",
            ) from exc

    def exists(self, path: str) -> bool:
        return "/" + path.lstrip("/").lower() in self.names

    def relationships(self, rels_path: str) -> list[dict[str, str]]:
        raw = self.member(rels_path)
        if raw is None:
            return []
        root = _parse(raw, rels_path)
        out = []
        for rel in root.iter(f"{{{RELS}}}Relationship"):
            attrs = {k: (v or "") for k, v in rel.attrib.items()}
            target = attrs.get("Target", "")
            if attrs.get("TargetMode", "").lower() == "external" or ":" in target.split("/", 1)[0] or target.startswith("//"):
                raise _invalid(f"{rels_path} links to a file outside the package ({attrs.get('Target', '')[:80]!r})", "chapter 2.1")
            out.append(attrs)
        return out

    def read(self) -> ThreeMF:
        if not self.exists("[Content_Types].xml"):
            raise _invalid("the package has no [Content_Types].xml", "chapter 2.1 (OPC)")
        rels = self.relationships("_rels/.rels")
        models = [r for r in rels if r.get("Type") == REL_MODEL]
        if len(models) != 1:
            raise _invalid(f"the package names {len(models)} 3D model start parts; it must name exactly one", "chapter 2.1.1")
        root_path = _absolute(models[0].get("Target", ""), "/")
        for rel in rels:
            if rel.get("Type") == REL_THUMBNAIL and not self.exists(_absolute(rel.get("Target", ""), "/")):
                raise _invalid(f"the thumbnail {rel.get('Target')!r} named by the package is missing", "chapter 2.1.3")
        if not self.exists(root_path):
            raise _invalid(f"the 3D model part {root_path!r} named by the package is missing", "chapter 2.1.1")
        for key, name in self.names.items():
            if key.endswith(".rels"):
                tickets = [r for r in self.relationships(name) if r.get("Type") == REL_PRINTTICKET]
                if len(tickets) > 1:
                    raise _invalid(f"{name} names {len(tickets)} print tickets; at most one is allowed", "chapter 2.1.4")
        root = self.part(root_path, is_root=True)
        notes = self.slicer_volumes(root)
        found = self.flatten(root)
        return ThreeMF(found.parts, found.unit, [*notes, *found.notes]) if notes else found

    # --- slicer projects --------------------------------------------------------------------------
    def slicer_volumes(self, root: _Part) -> list[str]:
        """Leave out the volumes a slicer project marks as no material, and refuse the ones it subtracts.

        PrusaSlicer (``Metadata/Slic3r_PE_model.config``) keeps an object's volumes in one mesh, each a range
        of its triangles with a ``volume_type``; Bambu Studio and OrcaSlicer (``Metadata/model_settings.config``)
        make each volume a component with a ``subtype``.  Modifiers, support blockers and enforcers only
        change print settings in their region, so they are left out, with a note; a negative volume is cut
        out of the part by the slicer, which this reader does not do, so the file is refused.
        """
        notes: list[str] = []
        for config_path, volume_tag in (("Metadata/Slic3r_PE_model.config", "volume"), ("Metadata/model_settings.config", "part")):
            raw = self.member(config_path)
            if raw is None:
                continue
            config = _parse(raw, config_path)
            for entry in config.iter("object"):
                obj = root.objects.get(_slicer_int(entry.get("id"), config_path))
                if obj is None:
                    continue
                left: list[str] = []
                drop = np.zeros(0 if obj.triangles is None else len(obj.triangles), dtype=bool)
                for volume in entry.iter(volume_tag):
                    meta = {m.get("key"): m.get("value") for m in volume.iter("metadata")}
                    kind = _slicer_kind(volume, meta)
                    if kind == "part":
                        continue
                    label = f"{meta.get('name') or kind} ({kind})"
                    if kind == "negative volume":
                        raise UnsupportedFormatError(
                            f"3MF object {obj.name or obj.id!r} has a negative volume {label!r} that the slicer cuts out "
                            "of the part, which this reader does not do; apply it in the slicer (or remove it) and "
                            "export the part again",
                            format="3mf",
                        )
                    if volume_tag == "volume" and len(drop):
                        first = _slicer_int(volume.get("firstid"), config_path)
                        last = _slicer_int(volume.get("lastid"), config_path)
                        drop[max(first, 0) : last + 1] = True
                    elif volume_tag == "part":
                        part_id = _slicer_int(volume.get("id"), config_path)
                        obj.components = [c for c in obj.components if c[1] != part_id]
                    left.append(label)
                if drop.any() and obj.triangles is not None:
                    obj.triangles = obj.triangles[~drop]
                if left:
                    notes.append(
                        f"3MF object {obj.name or obj.id!r}: the slicer project marks {', '.join(left[:8])} as no "
                        "material (they change print settings where they are); they were not weighed"
                    )
        return notes

    # --- model parts ------------------------------------------------------------------------------
    def part(self, path: str, is_root: bool = False) -> _Part:
        key = path.lower()
        if key in self.parts:
            return self.parts[key]
        raw = self.member(path)
        if raw is None:
            raise _invalid(f"the model part {path!r} is missing from the package", "production extension, ch. 3.1")
        model = _parse(raw, path)
        part = _parse_model(model, path, is_root, self)
        self.parts[key] = part
        return part

    def object(self, path: str, object_id: int, where: str) -> _Object:
        part = self.part(path)
        obj = part.objects.get(object_id)
        if obj is None:
            raise _invalid(f"{where} names object {object_id}, which {path} does not define", "chapter 3.4.3")
        return obj

    def flatten(self, root: _Part) -> ThreeMF:
        parts: list[tuple[str, NDArray[np.float64], NDArray[np.int64]]] = []
        notes: list[str] = []
        assumed: dict[str, float] = {}
        counts: dict[str, int] = {}
        for path, object_id, transform, label in root.items:
            obj = self.object(path, object_id, "a build item")
            if obj.type == "other":
                raise _invalid(f"a build item names object {object_id} of type 'other'", "chapter 3.4.3.1")
            name = label or obj.name or f"object {object_id}"  # an item's partnumber names the placed part
            counts[name] = counts.get(name, 0) + 1
            if counts[name] > 1:
                name = f"{name} #{counts[name]}"
            if obj.type != "model":
                notes.append(
                    f"3MF object {name!r} is of type {obj.type!r}: listed but not weighed "
                    "(only objects of type 'model' are the part)"
                )
                continue
            placed: list[tuple[float, float]] = []  # rotations written to few digits, taken as rotations
            left_out: list[str] = []  # components that are supports or other objects, not the part's material
            pieces = list(self.meshes(path, obj, transform, 0, placed, left_out))
            if placed:
                notes.append(_rotation_note(name, placed))
                # as written, a placement M = R (I + E) with entries of E up to about off / 2 scales volumes by
                # det(I + E) (up to 1.5 off) and lengths by up to 1.5 off: moments within 5 off of the rotation's
                assumed[name] = max(assumed.get(name, 0.0), 5 * max(off for off, _ in placed))
            if left_out:
                notes.append(
                    f"3MF object {name!r} has components that are not of type 'model' ({', '.join(left_out[:8])}): "
                    "listed but not weighed (a support or other object is no part of the solid)"
                )
            if not pieces:
                raise EmptyGeometryError(f"the 3MF object {name!r} holds no triangles", format="3mf")
            verts = [v for v, _ in pieces]
            offsets = np.cumsum([0, *[len(v) for v in verts[:-1]]])
            parts.append((name, np.concatenate(verts), np.concatenate([f + o for (_, f), o in zip(pieces, offsets)])))
            if len(pieces) > 1 and _overlapping(pieces):
                notes.append(_overlap_note(f"the components of 3MF object {name!r}"))
                assumed[name] = 1.0  # the overlap's size is not known: the numbers may be off by their own order
        if len(parts) > 1 and _overlapping([(v, f) for _, v, f in parts]):
            notes.append(_overlap_note("the 3MF file's build items"))
            assumed.update((name, 1.0) for name, _, _ in parts)
        if not parts:
            if notes:
                raise EmptyGeometryError(
                    "the 3MF file's build holds no object of type 'model' (only supports or "
                    "other objects), so there is no part to weigh",
                    format="3mf",
                )
            raise EmptyGeometryError("the 3MF file's build holds no objects; add a build item", format="3mf")
        return ThreeMF(parts, root.unit, notes, assumed)

    def meshes(
        self,
        path: str,
        obj: _Object,
        transform: NDArray[np.float64],
        depth: int,
        placed: list[tuple[float, float]],
        left_out: list[str],
    ) -> Iterator[tuple[NDArray[np.float64], NDArray[np.int64]]]:
        """Each mesh under ``obj`` in build coordinates; ``placed`` collects (departure, determinant) of
        each placement taken as the rotation its digits round, ``left_out`` the components that are not
        of type ``model`` (ch. 4.1: a device does not fill a support; the spec suggests attaching supports
        to a part as its components)."""
        if depth > _MAX_DEPTH:
            raise _invalid("components nest more than 32 deep (a cycle?)", "chapter 4.2")
        if obj.vertices is not None and obj.triangles is not None:
            m, off = _rigid(transform[:3, :3])
            if off:
                placed.append((off, float(np.linalg.det(transform[:3, :3]))))
            v = obj.vertices @ m.T + transform[:3, 3]
            f = obj.triangles if np.linalg.det(m) > 0 else obj.triangles[:, [0, 2, 1]]
            yield v, f
        for sub_path, sub_id, sub_transform in obj.components:
            sub = self.object(sub_path or path, sub_id, f"a component of object {obj.id}")
            if sub.type != "model":
                left_out.append(f"{sub.name or f'object {sub_id}'} ({sub.type})")
                continue
            yield from self.meshes(sub_path or path, sub, transform @ sub_transform, depth + 1, placed, left_out)


_ROTATION_DIGITS = 1e-5
"""A placement whose 3x3 part is within this of orthonormal (largest entry of M M^T - I) is a rotation written
to a few digits: CAD exporters write 0.309017 0.951057 for a turn of 72 degrees, whose determinant is
1.0000009.  It is placed by the nearest rotation (the polar factor U V^T of its SVD), as the exporter meant and
as trimesh's scene graph reads it (``repair_rigid``, the same threshold); a placement further off is a real
scale or shear and is applied as written."""


_ORTHONORMAL = 1e-13
"""Below this departure a matrix is a rotation to its own rounding (full-precision entries): left as written."""


def _rigid(m: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
    """The nearest rotation (or mirror) to ``m`` and how far ``m`` was from it, where ``m`` is a rotation written
    to few digits; else ``m`` itself and 0."""
    off = float(np.abs(m @ m.T - np.eye(3)).max())
    if not _ORTHONORMAL < off < _ROTATION_DIGITS:
        return m, 0.0
    u, _, vt = np.linalg.svd(m)
    return u @ vt, off


_OVERLAP_SAMPLES = 64  # vertices of one piece tested against another
_OVERLAP_TRIANGLES = 200_000  # work bound (samples x triangles of the other piece, over all pairs tested) / samples


def _overlapping(pieces: list[tuple[NDArray[np.float64], NDArray[np.int64]]]) -> bool:
    """Whether two closed pieces of one part (or two parts) share volume, as far as a bounded test finds.

    Pieces whose boxes overlap are tested: the same triangles at the same place, or a vertex or triangle
    centroid of one strictly inside the other (generalised winding number, van Oosterom and Strackee's solid angle).  The test is
    sampled and bounded (``_OVERLAP_SAMPLES``, ``_OVERLAP_TRIANGLES``): an overlap it finds is certain; one it
    misses (no sampled vertex inside) is possible.
    """
    boxes = [(v.min(axis=0), v.max(axis=0)) for v, _ in pieces]
    budget = _OVERLAP_TRIANGLES
    for i, (vi, fi) in enumerate(pieces):
        for j in range(i + 1, len(pieces)):
            lo, hi = np.maximum(boxes[i][0], boxes[j][0]), np.minimum(boxes[i][1], boxes[j][1])
            if np.any(hi <= lo):
                continue
            vj, fj = pieces[j]
            if len(vi) == len(vj) and np.array_equal(np.sort(vi, axis=0), np.sort(vj, axis=0)):
                return True  # the same piece placed twice
            for (va, fa), (vb, fb) in (((vi, fi), (vj, fj)), ((vj, fj), (vi, fi))):
                budget -= len(fb)
                if budget < 0:
                    return False
                candidates = np.concatenate([va, va[fa].mean(axis=1)])  # corners and triangle centroids
                inside = candidates[np.all((candidates >= lo) & (candidates <= hi), axis=1)]
                if len(inside) and _winding(inside[:: max(1, len(inside) // _OVERLAP_SAMPLES)][:_OVERLAP_SAMPLES], vb, fb):
                    return True
    return False


def _winding(points: NDArray[np.float64], v: NDArray[np.float64], f: NDArray[np.int64]) -> bool:
    """Whether any point lies inside the closed mesh (v, f): |winding number| near one, not a half (its surface)."""
    tri = v[f]
    for p in points:
        a, b, c = (tri[:, k] - p for k in range(3))
        la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
        det = np.einsum("ij,ij->i", a, np.cross(b, c))
        den = la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", b, c) * la
        den += np.einsum("ij,ij->i", c, a) * lb
        if abs(float(np.sum(np.arctan2(det, den)))) / (2 * np.pi) > 0.75:  # inside 1, outside 0, on the surface 1/2
            return True
    return False


def _overlap_note(what: str) -> str:
    return (
        f"{what} overlap: the 3MF specification unites overlapping volumes (ch. 4.2 and 3.4.3), but they were "
        "weighed each in full, so the overlap counts twice and the mass is too large (by an amount not measured: "
        "the error estimate is 1)"
    )


def _rotation_note(name: str, placed: list[tuple[float, float]]) -> str:
    off = max(o for o, _ in placed)
    scale = max((d for _, d in placed), key=lambda d: abs(abs(d) - 1.0))
    return (
        f"3MF object {name!r}: {len(placed)} placement(s) are rotations written to few digits (up to {off:.2g} from "
        f"orthonormal); each was placed by the nearest rotation, as its exporter meant (as written, the digits "
        f"would also change a piece's volume by up to {abs(abs(scale) - 1.0):.2g} of it)"
    )


def _absolute(target: str, base: str) -> str:
    if target.startswith("/"):
        return target
    folder = base.rsplit("/", 1)[0]
    return f"{folder}/{target}"


# what a slicer project calls each volume: PrusaSlicer's volume_type (an older file says modifier="1"),
# Bambu Studio's and OrcaSlicer's part subtype
_SLICER_KINDS = {
    "ModelPart": "part",
    "normal_part": "part",
    "ParameterModifier": "modifier",
    "modifier_part": "modifier",
    "SupportBlocker": "support blocker",
    "support_blocker": "support blocker",
    "SupportEnforcer": "support enforcer",
    "support_enforcer": "support enforcer",
    "NegativeVolume": "negative volume",
    "negative_part": "negative volume",
}


def _slicer_kind(volume: Any, meta: dict[str, str | None]) -> str:
    written = volume.get("subtype") or meta.get("volume_type") or ("ParameterModifier" if meta.get("modifier") == "1" else None)
    if written is None:
        return "part"
    kind = _SLICER_KINDS.get(written)
    if kind is None:
        raise UnsupportedFormatError(
            f"the 3MF file's slicer project names a volume of kind {written[:40]!r}, which this reader does not know; "
            "export the parts without the project settings",
            format="3mf",
        )
    return kind


def _slicer_int(text: str | None, path: str) -> int:
    try:
        return int(text or "")
    except ValueError:
        written = (text or "")[:20]
        raise UnreadableFileError(f"the 3MF file's {path} has a number that is not one ({written!r})", format="3mf") from None


def _parse(raw: bytes, path: str) -> Any:
    from lxml import etree

    head = raw[:200].lstrip(b"\xef\xbb\xbf")
    if (
        head.startswith((b"\x00\x00\xfe\xff", b"\xff\xfe\x00\x00"))
        or b'encoding="UTF-32"' in head.upper()
        or b"encoding='UTF-32'" in head.upper().replace(b"\x00", b"")
    ):
        raise _invalid(f"{path} is not encoded in UTF-8 or UTF-16", "chapter 2.3")
    parser = etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        dtd_validation=False,
        huge_tree=False,
        remove_comments=True,
        remove_pis=True,
    )
    try:
        tree = etree.parse(io.BytesIO(raw), parser)
    except etree.XMLSyntaxError as exc:
        raise _invalid(f"{path} is not well-formed XML (line {exc.lineno}: {str(exc.msg)[:100]})", "chapter 2.3") from None
    info = tree.docinfo
    if info.internalDTD is not None or info.externalDTD is not None or info.doctype:
        raise _invalid(f"{path} declares a document type (DTD), which 3MF forbids", "chapter 2.3.2")
    encoding = (info.encoding or "UTF-8").upper()
    if encoding not in ("UTF-8", "UTF-16", "UTF8", "UTF16"):
        raise _invalid(f"{path} is encoded in {encoding}, not UTF-8 or UTF-16", "chapter 2.3")
    root = tree.getroot()
    for el in root.iter():
        if f"{{{XML_NS}}}space" in el.attrib:
            raise _invalid(f"{path} uses xml:space, which 3MF forbids", "chapter 2.3.4")
    return root


def _int(el: Any, attr: str, where: str, required: bool = True) -> int | None:
    text = el.get(attr)
    if text is None:
        if required:
            raise _invalid(f"{where} lacks the required attribute {attr!r}", "chapter 4")
        return None
    try:
        value = int(text)
    except ValueError:
        raise _invalid(f"{where} has {attr}={text[:40]!r}, which is not an integer", "chapter 4") from None
    if value < 0:
        raise _invalid(f"{where} has a negative {attr}", "chapter 4")
    return value


def _transform(text: str | None, where: str) -> NDArray[np.float64]:
    out = np.eye(4)
    if text is None:
        return out
    try:
        values = [float(t) for t in text.split()]
    except ValueError:
        raise _invalid(f"{where} has a transform that is not 12 numbers", "chapter 3.3") from None
    if len(values) != 12 or not all(math.isfinite(x) for x in values):
        raise _invalid(f"{where} has a transform of {len(values)} values; it must be 12 finite numbers", "chapter 3.3")
    m = np.array(values).reshape(4, 3)  # rows: the 3MF matrix is applied to row vectors, last row translation
    out[:3, :3] = m[:3].T
    out[:3, 3] = m[3]
    if abs(np.linalg.det(out[:3, :3])) == 0.0:
        raise _invalid(f"{where} has a singular transform (determinant 0), which flattens the part", "chapter 3.3")
    return out


def _parse_model(model: Any, path: str, is_root: bool, reader: _Reader) -> _Part:
    if model.tag == f"{{{DRAFT_093}}}model":
        raise UnsupportedFormatError(
            f"{path} is written in the namespace of 3MF 0.93 ({DRAFT_093}), a draft from before version 1.0 of "
            "the specification, which this service does not read; re-save it with a current 3MF exporter",
            format="3mf",
            namespace=DRAFT_093,
        )
    if model.tag != f"{{{CORE}}}model":
        raise _invalid(f"{path} does not hold a 3MF model element in the core namespace", "chapter 3")
    unit_name = model.get("unit", "millimeter")
    if unit_name not in _UNITS:
        raise _invalid(f"the model's unit {unit_name!r} is not one of {', '.join(_UNITS)}", "chapter 3.2")
    for prefix in (model.get("requiredextensions") or "").split():
        ns = model.nsmap.get(prefix)
        if ns is None:
            raise _invalid(f"the required extension prefix {prefix!r} is not declared", "chapter 3.4")
        if ns not in _SUPPORTED:
            raise UnsupportedFormatError(
                f"the 3MF file requires the extension {ns}, which this service does not implement"
                + (
                    " (its content is encrypted)"
                    if "securecontent" in ns
                    else " (beam lattices, volumetric or boolean geometry change the solid)"
                )
                + "; export the part as a plain mesh",
                format="3mf",
                extension=ns,
            )
    _check_namespaces(model, path)
    children = list(model)
    metadata = [c for c in children if c.tag == f"{{{CORE}}}metadata"]
    seen: set[str] = set()
    for m in metadata:
        name = m.get("name")
        if not name:
            raise _invalid("a metadata element has no name", "chapter 3.4.1")
        if name in seen:
            raise _invalid(f"the metadata name {name!r} appears twice", "chapter 3.4.1")
        seen.add(name)
    resources = [c for c in children if c.tag == f"{{{CORE}}}resources"]
    builds = [c for c in children if c.tag == f"{{{CORE}}}build"]
    if len(resources) != 1:
        raise _invalid(f"{path} has {len(resources)} resources elements; it must have exactly one", "chapter 3.4")
    if is_root and len(builds) != 1:
        raise _invalid(f"{path} has {len(builds)} build elements; it must have exactly one", "chapter 3.4")
    part = _Part(path, {}, _UNITS[unit_name])
    _parse_resources(resources[0], part, is_root)
    if is_root:
        for item in builds[0]:
            if item.tag != f"{{{CORE}}}item":
                continue
            object_id = _int(item, "objectid", "a build item")
            assert object_id is not None
            item_path = item.get(f"{{{PROD}}}path")
            target = _absolute(item_path, path) if item_path else path
            if item_path and not reader.exists(target):
                raise _invalid(f"a build item's p:path {item_path!r} is not a part of the package", "production extension, ch. 3.1")
            part.items.append((target, object_id, _transform(item.get("transform"), "a build item"), item.get("partnumber") or ""))
    return part


_MC = "http://schemas.openxmlformats.org/markup-compatibility/2006"
_FAMILY = "http://schemas.microsoft.com/3dmanufacturing/"


def _check_namespaces(model: Any, path: str) -> None:
    """Markup in an unknown 3MF-family namespace must be declared ignorable (``mc:Ignorable``) or required.

    Vendor namespaces outside the 3MF family (slicers' own settings) are left
    alone: they carry no geometry this reader would misread.
    """
    known = {CORE, PROD, MAT, SLICE, BEAM, XML_NS, _MC}
    ignorable = {model.nsmap.get(p) for p in (model.get(f"{{{_MC}}}Ignorable") or "").split()}
    required = {model.nsmap.get(p) for p in (model.get("requiredextensions") or "").split()}
    allowed = known | ignorable | required

    def unknown(name: str) -> bool:
        if not name.startswith("{"):
            return False
        ns = name[1:].split("}", 1)[0]
        return ns.startswith(_FAMILY) and ns not in allowed and not _known_extension(ns)

    for el in model.iter():
        if not isinstance(el.tag, str):
            continue
        bad = [el.tag] if unknown(el.tag) else [a for a in el.attrib if unknown(a)]
        if bad:
            raise _invalid(
                f"{path} uses markup of the unknown namespace {bad[0][1:].split('}')[0]!r} without "
                "declaring it ignorable (mc:Ignorable)",
                "chapter 2.3.3",
            )


def _known_extension(ns: str) -> bool:
    """Published 3MF extension namespaces (their markup is understood, or refused where it matters)."""
    return any(
        ns.startswith(_FAMILY + k)
        for k in (
            "material/",
            "production/",
            "slice/",
            "beamlattice/",
            "securecontent/",
            "trianglesets/",
            "volumetric/",
            "displacement/",
            "implicit/",
            "booleanoperations/",
        )
    )


def _parse_resources(resources: Any, part: _Part, is_root: bool) -> None:
    ids: set[int] = set()
    property_sizes: dict[int, tuple[str, int]] = {}
    unclosed: NotWatertightError | None = None  # the first open model object, refused once every resource is read:
    # a later one may say more about the file (a beam lattice whose clipping mesh the open object is)
    for res in resources:
        if not isinstance(res.tag, str):
            continue
        rid = res.get("id")
        where = f"resource {rid}" if rid else "a resource"
        if rid is not None:
            value = _int(res, "id", where)
            assert value is not None
            if value == 0:
                raise _invalid(f"{where} has id 0; resource ids are positive", "chapter 4")
            if value in ids:
                raise _invalid(f"the resource id {value} is used twice", "chapter 4 (resource ids are unique)")
            ids.add(value)
        tag = res.tag
        if tag in _PROPERTY_TAGS:
            property_sizes[int(rid or 0)] = (tag, _check_property(res, tag, where, property_sizes, part, ids))
        elif tag == f"{{{MAT}}}texture2d":
            _check_texture(res, where)
            property_sizes[int(rid or 0)] = (tag, 0)
        elif tag == f"{{{CORE}}}object":
            obj = _parse_object(res, where, property_sizes, part)
            part.objects[obj.id] = obj
            if obj.type == "model" and obj.triangles is not None and unclosed is None:
                try:
                    _check_closed(obj)
                except NotWatertightError as exc:
                    unclosed = exc
    if unclosed is not None:
        raise unclosed


def _check_property(res: Any, tag: str, where: str, sizes: dict[int, tuple[str, int]], part: _Part, ids: set[int]) -> int:
    child = _PROPERTY_TAGS[tag]
    ns = CORE if child == "base" else MAT
    entries = [c for c in res if c.tag == f"{{{ns}}}{child}"]
    astray = [c for c in res if isinstance(c.tag, str) and c.tag.endswith(f"}}{child}") and c.tag != f"{{{ns}}}{child}"]
    if astray and not entries:
        raise _invalid(
            f"the <{child}> elements of {where} are in the namespace {astray[0].tag[1:].split('}')[0]!r}, not in "
            f"{ns!r} where they belong (written without their prefix, e.g. m:{child}), so the group holds no entries",
            "materials extension" if ns == MAT else "chapter 5",
        )
    for entry in entries:
        if child == "base" and (not entry.get("name") or not entry.get("displaycolor")):
            raise _invalid(f"a base material of {where} lacks its name or displaycolor", "chapter 5.1")
        if child == "color" and not entry.get("color"):
            raise _invalid(f"a color of {where} has no color value", "materials extension, ch. 2")
        if child == "tex2coord" and (entry.get("u") is None or entry.get("v") is None):
            raise _invalid(f"a texture coordinate of {where} lacks u or v", "materials extension, ch. 3")
    if child == "tex2coord":
        texid = _int(res, "texid", where)
        if texid not in sizes or sizes[texid][0] != f"{{{MAT}}}texture2d":
            raise _invalid(
                f"{where} names texture {texid}, which is not a texture2d defined before it", "materials extension, ch. 3"
            )
    if child == "composite":
        matid = _int(res, "matid", where)
        if matid not in sizes or sizes[matid][0] != f"{{{CORE}}}basematerials":
            raise _invalid(
                f"{where} names {matid} as its base materials, which is not a basematerials group defined before it",
                "materials extension, ch. 4",
            )
        if res.get("matindices") is None:
            raise _invalid(f"{where} lacks matindices", "materials extension, ch. 4")
        for entry in entries:
            if entry.get("values") is None:
                raise _invalid(f"a composite of {where} lacks its values", "materials extension, ch. 4")
    if child == "multi":
        pids_text = res.get("pids")
        if not pids_text:
            raise _invalid(f"{where} lacks pids", "materials extension, ch. 5")
        kinds: list[str] = []
        for token in pids_text.split():
            try:
                pid = int(token)
            except ValueError:
                raise _invalid(f"{where} has a pid {token!r} that is not an integer", "materials extension, ch. 5") from None
            if pid not in sizes:
                raise _invalid(f"{where} names property group {pid}, which is not defined before it", "materials extension, ch. 5")
            kinds.append(sizes[pid][0])
        materials = sum(k in (f"{{{CORE}}}basematerials", f"{{{MAT}}}compositematerials") for k in kinds)
        if materials > 1 or kinds.count(f"{{{MAT}}}colorgroup") > 1 or f"{{{MAT}}}multiproperties" in kinds:
            raise _invalid(
                f"{where} combines more than one material group or colour group, or another multiproperties",
                "materials extension, ch. 5",
            )
    return len(entries)


def _check_texture(res: Any, where: str) -> None:
    if not res.get("path"):
        raise _invalid(f"the texture {where} has no path", "materials extension, ch. 6")
    if res.get("contenttype") not in ("image/png", "image/jpeg"):
        raise _invalid(
            f"the texture {where} has the content type {res.get('contenttype')!r}; it must be image/png or image/jpeg",
            "materials extension, ch. 6",
        )


def _check_pid(el: Any, where: str, sizes: dict[int, tuple[str, int]], pindex_attrs: tuple[str, ...]) -> int | None:
    pid = _int(el, "pid", where, required=False)
    if pid is None:
        return None
    if pid not in sizes or sizes[pid][0] == f"{{{MAT}}}texture2d":
        raise _invalid(f"{where} names property group {pid}, which is not a property resource defined before it", "chapter 4 (pid)")
    size = sizes[pid][1]
    for attr in pindex_attrs:
        index = _int(el, attr, where, required=False)
        if index is not None and index >= size:
            raise _invalid(f"{where} has {attr}={index}, past the {size} entries of property group {pid}", "chapter 4 (pindex)")
    return pid


def _parse_object(res: Any, where: str, sizes: dict[int, tuple[str, int]], part: _Part) -> _Object:
    oid = _int(res, "id", where)
    assert oid is not None
    kind = res.get("type", "model")
    if kind not in _TYPES:
        raise _invalid(f"object {oid} has type {kind!r}; it must be one of {', '.join(_TYPES)}", "chapter 4")
    if res.get("pindex") is not None and res.get("pid") is None:
        raise _invalid(f"object {oid} has a pindex but no pid", "chapter 4")
    object_pid = _check_pid(res, f"object {oid}", sizes, ("pindex",))
    obj = _Object(oid, kind, res.get("name") or "")
    meshes = [c for c in res if c.tag == f"{{{CORE}}}mesh"]
    comps = [c for c in res if c.tag == f"{{{CORE}}}components"]
    if len(meshes) + len(comps) != 1:
        raise _invalid(f"object {oid} must hold exactly one mesh or one components element", "chapter 4")
    if meshes:
        mesh = meshes[0]
        if any(c.tag.startswith(f"{{{BEAM}}}") for c in mesh if isinstance(c.tag, str)):
            raise UnsupportedFormatError(
                f"object {oid} of the 3MF file carries a beam lattice, whose beams this "
                "service does not integrate; export the part as a plain mesh",
                format="3mf",
            )
        if res.get(f"{{{SLICE}}}meshresolution") == "lowres":
            raise UnsupportedFormatError(
                f"object {oid} of the 3MF file holds only a low-resolution preview mesh "
                "(its slices are the part); export the full-resolution mesh",
                format="3mf",
            )
        obj.vertices, obj.triangles = _parse_mesh(mesh, oid, object_pid, sizes)
    else:
        for comp in comps[0]:
            if comp.tag != f"{{{CORE}}}component":
                continue
            cid = _int(comp, "objectid", f"a component of object {oid}")
            assert cid is not None
            comp_path = comp.get(f"{{{PROD}}}path")
            if not comp_path and cid not in part.objects:
                raise _invalid(f"a component of object {oid} names object {cid}, which is not defined before it", "chapter 4.2")
            obj.components.append(
                (
                    _absolute(comp_path, part.path) if comp_path else "",
                    cid,
                    _transform(comp.get("transform"), f"a component of object {oid}"),
                )
            )
    return obj


def _parse_mesh(
    mesh: Any, oid: int, object_pid: int | None, sizes: dict[int, tuple[str, int]]
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    vertices_el = mesh.find(f"{{{CORE}}}vertices")
    triangles_el = mesh.find(f"{{{CORE}}}triangles")
    if vertices_el is None or triangles_el is None:
        raise _invalid(f"the mesh of object {oid} lacks its vertices or triangles", "chapter 4.1")
    try:
        coords = [(v.attrib["x"], v.attrib["y"], v.attrib["z"]) for v in vertices_el if v.tag == f"{{{CORE}}}vertex"]
        vertices = np.array(coords, dtype=np.float64).reshape(-1, 3)
    except (KeyError, ValueError):
        raise _invalid(f"a vertex of object {oid} lacks a coordinate or has one that is not a number", "chapter 4.1.1") from None
    if not np.all(np.isfinite(vertices)):
        raise InvalidParameterError(
            f"a vertex of 3MF object {oid} has a coordinate that is not finite (NaN or infinity); fix the file",
            field="vertex coordinates",
        )
    tris = [t for t in triangles_el if t.tag == f"{{{CORE}}}triangle"]
    try:
        triangles = np.array([(t.attrib["v1"], t.attrib["v2"], t.attrib["v3"]) for t in tris], dtype=np.int64)
    except (KeyError, ValueError, OverflowError):
        raise _invalid(
            f"a triangle of object {oid} lacks a vertex index or has one that is not an integer", "chapter 4.1.2"
        ) from None
    triangles = triangles.reshape(-1, 3)
    if len(triangles) and (triangles.min() < 0 or triangles.max() >= len(vertices)):
        raise _invalid(f"a triangle of object {oid} names a vertex that does not exist", "chapter 4.1.2")
    if np.any((triangles[:, 0] == triangles[:, 1]) | (triangles[:, 1] == triangles[:, 2]) | (triangles[:, 0] == triangles[:, 2])):
        raise _invalid(f"a triangle of object {oid} uses one vertex twice", "chapter 4.1.2")
    for t in tris:
        if any(t.get(a) is not None for a in ("p1", "p2", "p3")):
            if t.get("pid") is None and object_pid is None:
                raise _invalid(f"a triangle of object {oid} has property indices but no pid", "chapter 4.1.2")
            pid = _check_pid(t, f"a triangle of object {oid}", sizes, ("p1", "p2", "p3")) if t.get("pid") else None
            if pid is None and object_pid is not None:
                size = sizes[object_pid][1]
                for a in ("p1", "p2", "p3"):
                    index = _int(t, a, f"a triangle of object {oid}", required=False)
                    if index is not None and index >= size:
                        raise _invalid(
                            f"a triangle of object {oid} has {a}={index}, past the {size} entries of property group {object_pid}",
                            "chapter 4.1.2",
                        )
        elif t.get("pid") is not None:
            _check_pid(t, f"a triangle of object {oid}", sizes, ())
    return vertices, triangles


def _check_closed(obj: _Object) -> None:
    """A model object's mesh: every edge in exactly two triangles, traversed once each way (ch. 4.1)."""
    from ..topology import surface_topology

    assert obj.triangles is not None and obj.vertices is not None
    if len(obj.triangles) == 0:
        raise EmptyGeometryError(f"the 3MF object {obj.name or obj.id!r} of type model has no triangles", format="3mf")
    topo = surface_topology(obj.triangles, len(obj.vertices))
    if topo.open_edges or topo.unbalanced_edges:
        # a CAD exporter may write a seam's vertex twice (equal, or a rounding apart): judged after the same
        # welding and seam merge the solid stage applies (and reports), not refused for it
        from ..seams import merge_seams
        from ..topology import weld

        v, f = weld(obj.vertices, obj.triangles)
        f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
        topo = surface_topology(merge_seams(v, f).faces, len(v))
    if topo.open_edges or topo.nonmanifold_edges or topo.unbalanced_edges:
        label = obj.name or f"object {obj.id}"
        raise NotWatertightError(
            f"the 3MF object {label!r} is of type model but its mesh is not a closed, consistently oriented "
            f"manifold ({topo.open_edges} open, {topo.nonmanifold_edges} non-manifold, {topo.unbalanced_edges} "
            "inconsistently wound edges), as the 3MF core specification requires (chapter 4.1); repair it in the "
            "program that made it",
            open_edges=topo.open_edges,
            nonmanifold_edges=topo.nonmanifold_edges,
            unbalanced_edges=topo.unbalanced_edges,
            part=label,
        )
