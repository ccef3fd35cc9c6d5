"""analyze(): the one place where the stages meet.

    bytes -> load_body -> mass_properties -> principal_frame -> classify
          [-> predict_motion]                        -> AnalysisResult

Each stage is computed only when the request needs it: no reference tensor
without ``reference``, no motion without ``omega``, no trajectory without
``duration`` and ``samples``, no ``parts`` for a single body.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .body import BrepBody, PointBody
from .classification import Classification, classify
from .conventions import length_scale
from .errors import DegenerateBodyError, InvalidParameterError
from .load import Loaded, load_body, load_points
from .mass import InertiaTensor, MassProperties, Model, assembly_properties, mass_properties
from .options import METHODS, AnalysisOptions
from .principal import PrincipalFrame, principal_frame, tensor_frame
from .results import AnalysisResult, Diagnostics, PartResult, PrecessionResult, Source
from .tolerances import DEFAULT_TOLERANCES, EPS
from .vocabulary import MotionMethod, SourceKind, UnitsFrom

if TYPE_CHECKING:
    from .export import Snippet
    from .motion import FreeMotion

__all__ = [
    "AnalysisOptions",
    "AnalysisResult",
    "PartResult",
    "analyze",
    "analyze_points",
    "analyze_loaded",
    "PrecessionResult",
    "precession",
    "uncertain_class",
    "METHODS",
]


def analyze(
    source: bytes | str | os.PathLike[str] | Any,
    *,
    filename: str | None = None,
    options: AnalysisOptions = AnalysisOptions(),
    companions_beside: bool = True,
) -> AnalysisResult:
    """Analyse a mesh or points file (bytes, or a path), a ``trimesh.Trimesh``, or ``(vertices, faces)`` arrays.

    Arrays and mesh objects are in ``options.units`` (default metres): vertices (n, 3), faces (m, 3) of
    vertex indices, a closed surface wound either way.

    companions_beside : for a path, read the files the model names (a glTF's ``.bin``, an Abaqus include,
        an XDMF's ``.h5``) from the model's own folder, by plain file name, as its own tools do.  Turn it off
        for a file that is not your own, such as an upload saved in a shared folder: then a model reads only
        what is inside it (``load_body``).
    """
    start = time.perf_counter()
    if isinstance(source, (bytearray, memoryview)):
        source = bytes(source)
    if isinstance(source, (bytes, str, os.PathLike)):
        loaded = load_body(
            source,
            filename=filename,
            format=options.format,
            units=options.units,
            isotopes=options.isotopes,
            companions_beside=companions_beside and not isinstance(source, bytes),
        )
    else:
        loaded = _loaded_from_arrays(source, filename, options.units)
    return analyze_loaded(loaded, options, start)


def _loaded_from_arrays(source: Any, filename: str | None, units: str | None) -> Loaded:
    """A surface given in memory: an object with ``vertices`` and ``faces`` (trimesh's Trimesh) or a pair."""
    from .body import MeshBody, Part

    if hasattr(source, "vertices") and hasattr(source, "faces"):
        vertices, faces, fmt = source.vertices, source.faces, type(source).__name__.lower()
    elif isinstance(source, (tuple, list)) and len(source) == 2:
        (vertices, faces), fmt = source, "arrays"
    else:
        raise InvalidParameterError(
            f"cannot analyse a {type(source).__name__}: give a file path, the file's bytes, a trimesh.Trimesh "
            "or a (vertices, faces) pair of arrays",
            parameter="source",
        )
    try:
        v = np.array(vertices, dtype=np.float64)
        f = np.array(faces)
    except (TypeError, ValueError) as exc:
        raise InvalidParameterError(f"vertices and faces must be numeric arrays: {exc}", parameter="source") from exc
    if f.dtype.kind not in "iu" and not (f.dtype.kind == "f" and np.array_equal(f, np.round(f))):
        raise InvalidParameterError("faces must hold whole vertex indices", parameter="source")
    try:
        body = MeshBody(v, f.astype(np.int64), length_scale(units or "m"), filename or "body")
    except ValueError as exc:  # shapes
        raise InvalidParameterError(f"{exc}; got vertices {v.shape} and faces {f.shape}", parameter="source") from exc
    name = filename or "body"
    units_from = UnitsFrom.REQUEST if units else UnitsFrom.DEFAULT
    return Loaded((Part(name, body),), filename, fmt, SourceKind.MESH, units or "m", units_from)


def analyze_points(records: list[dict[str, Any]], options: AnalysisOptions = AnalysisOptions()) -> AnalysisResult:
    """Analyse point masses ``[{"mass": m, "position": [x, y, z]}, ...]`` (or ``"element"`` for ``mass``)."""
    start = time.perf_counter()
    loaded = load_points(records, options.units, isotopes=options.isotopes, mass_unit=options.mass_unit)
    return analyze_loaded(loaded, options, start)


def analyze_loaded(loaded: Loaded, options: AnalysisOptions, start: float | None = None) -> AnalysisResult:
    """The stages after loading."""
    start = time.perf_counter() if start is None else start
    if loaded.kind == "cad" and options.geometry == "mesh":
        return _tessellated_cad(loaded, options, start)
    if loaded.kind == "points" and options.model == Model.SHELL:
        raise InvalidParameterError("model=shell applies to surface meshes, not point masses", parameter="model")
    _check_part_names(loaded, options)
    if loaded.kind == "mesh" and len(loaded.parts) > 1 and options.model == Model.SOLID and not options.densities:
        # open parts that close together become one body (with per-part densities they stay apart, and
        # an open part is refused by name: one body cannot hold two materials)
        from .seams import join_open_parts

        parts_joined, _ = join_open_parts(list(loaded.parts))
        loaded = replace(loaded, parts=tuple(parts_joined))
    single = len(loaded.parts) == 1
    part_results = tuple(_part(p.name, p.body, options, single) for p in loaded.parts)
    factor = 1.0
    if not single and options.mass is not None:
        factor = options.mass / sum(p.props.mass for p in part_results)
        part_results = tuple(_scaled(p, factor) for p in part_results)
    if single:
        props = part_results[0].props
        frame, cls = part_results[0].frame, part_results[0].classification
        parts = None
    else:
        props = _combined(loaded, part_results, options, factor)
        if options.mass is not None:  # the requested total is exact by definition; the scaled sums round it by an ulp
            props = replace(props, mass=float(options.mass))
        frame = principal_frame(props, options.tolerance)
        cls = classify(frame)
        parts = part_results
    warnings = list(loaded.warnings) + list(props.warnings)
    if np.any(props.principal_moments):  # all zero (one point, or all at one place): no margin decided the class
        warnings += uncertain_class(cls, props.relative_error_estimate)
    if loaded.units_from == "file":
        warnings.append(f"length unit {loaded.units!r} taken from the file")
    warnings.extend(_unit_warning(loaded))
    warnings.extend(_overridden_density(loaded, options))
    if options.model == Model.SHELL:
        warnings.extend(_shell_thickness_warning(loaded, options))
    reference = None
    if options.reference is not None:
        reference = props.about(np.asarray(options.reference) * length_scale(loaded.units))
    motion = None
    if options.omega is not None:
        motion = _motion(frame, cls, options, moment_error=props.relative_error_estimate)
        warnings.extend(motion.warnings)
    extra = _v11_sections(loaded, props, frame, cls, reference, parts, options, warnings)
    if parts is not None:
        parts = extra.pop("parts")
    return AnalysisResult(
        source=_source(loaded, part_results),
        props=props,
        frame=frame,
        classification=cls,
        reference=reference,
        motion=motion,
        parts=parts,
        warnings=tuple(dict.fromkeys(warnings)),
        diagnostics=Diagnostics(time.perf_counter() - start, props.relative_error_estimate),
        **extra,
    )


def _tessellated_cad(loaded: Loaded, options: AnalysisOptions, start: float) -> AnalysisResult:
    """geometry=mesh: the tessellation through the polyhedron pipeline, and its difference to the B-rep."""
    from .cad import DEFAULT_DEFLECTION, tessellated, tessellation_error

    exact = analyze_loaded(
        loaded, replace(options, geometry="brep", deflection=None, reference=None, omega=None, duration=None, samples=None)
    )
    deflection = options.deflection or DEFAULT_DEFLECTION
    result = analyze_loaded(tessellated(loaded, deflection), replace(options, geometry="brep", deflection=None), start)
    source = replace(result.source, geometry="mesh", deflection=deflection)
    diagnostics = replace(
        result.diagnostics, elapsed_s=time.perf_counter() - start, tessellation_error=tessellation_error(exact.props, result.props)
    )
    return replace(result, source=source, diagnostics=diagnostics)


def _v11_sections(
    loaded: Loaded,
    props: MassProperties,
    frame: PrincipalFrame,
    cls: Classification,
    reference: InertiaTensor | None,
    parts: tuple[PartResult, ...] | None,
    options: AnalysisOptions,
    warnings: list[str],
) -> dict[str, Any]:
    """surface_area, rotational_constants, frame and export (API.md 1.1), each only when it applies."""
    from .surface import part_surface_area

    areas = [part_surface_area(p) for p in loaded.parts]
    out: dict[str, Any] = {}
    if all(a is not None for a in areas):
        out["surface_area"] = math.fsum(a for a in areas if a is not None)
    if any(p.extras.get("molecule") for p in loaded.parts):
        from .classification import RotorClass
        from .rotational import rotational_constants

        out["rotational_constants"] = rotational_constants(frame.moments, cls.rotor == RotorClass.LINEAR)
        if options.mass is not None:
            warnings.append(
                f"the atoms' masses were scaled to the requested total of {options.mass:g} kg, so the rotational "
                "constants are those of that scaled body, not of the molecule"
            )
        if out["rotational_constants"] is None:
            warnings.append(
                "rotational constants need positive principal moments; a single atom (or atoms all at one place) has none"
            )
    if options.frame is not None:
        from .frames import frame_norm_warning, named_frame

        typed = frame_norm_warning(options.frame)
        if typed is not None:
            warnings.append(typed)

        out["named_frame"] = named_frame(
            options.frame,
            props.center_of_mass,
            props.inertia.matrix,
            None if reference is None else reference.point,
            None if reference is None else reference.matrix,
        )
    if options.export is not None:
        out["export"] = _export(options.export, props, frame, cls, "")
        warnings.extend(out["export"].warnings)
    if parts is not None:
        new_parts = []
        for part, area in zip(parts, areas):
            snippet = (
                None if options.export is None else _export(options.export, part.props, part.frame, part.classification, part.name)
            )
            if snippet is not None:
                warnings.extend(snippet.warnings)
            new_parts.append(replace(part, surface_area=area, export=snippet))
        out["parts"] = tuple(new_parts)
    return out


def _export(fmt: str, props: MassProperties, frame: PrincipalFrame, cls: Classification, name: str) -> Snippet:
    from .classification import RotorClass
    from .export import Inertial, inertial_snippet

    body = Inertial(
        props.mass,
        props.center_of_mass,
        props.inertia.matrix,
        frame.moments,
        frame.axes,
        frame.quaternion,
        linear=cls.rotor == RotorClass.LINEAR,
        relative_error=props.relative_error_estimate,
    )
    return inertial_snippet(fmt, body, name)


def _check_part_names(loaded: Loaded, options: AnalysisOptions) -> None:
    """Every name in ``densities`` must be a part of the file: a typo never falls back to the default."""
    if not options.densities:
        return
    names = [p.name for p in loaded.parts]
    unknown = sorted(set(options.densities) - set(names))
    if unknown:
        listed = ", ".join(repr(n) for n in names[:20]) + (" ..." if len(names) > 20 else "")
        raise InvalidParameterError(
            f"densities names {', '.join(repr(n) for n in unknown)}, which is not a part of this file; its parts are: {listed}",
            parameter="densities",
            unknown=unknown,
            parts=names[:100],
        )


def _extent(body: Any) -> NDArray[np.float64] | None:
    """Bounding-box side lengths of a mesh or volume body [m]; None for point sets."""
    coords = getattr(body, "vertices", None)
    if coords is None:
        coords = getattr(body, "points", None)
    if coords is None or not len(coords):
        return None
    # column by column: numpy reduces an (n, 3) array along axis 0 a few elements at a time, ~10x slower
    columns = range(coords.shape[1])
    extent: NDArray[np.float64] = np.array([coords[:, k].max() - coords[:, k].min() for k in columns]) * body.length_scale
    return extent


def uncertain_class(cls: Classification, estimate: float) -> list[str]:
    """A warning where a margin that decided the class is nearer its tolerance than the moments' error
    allows (each gap is off by at most twice the relative error estimate): the class may differ."""
    margins = cls.margins
    named = (
        ("(I2 - I1) / I3", margins.gap12),
        ("(I3 - I2) / I3", margins.gap23),
        ("I1 / I3", margins.smallest),
        ("|I1 + I2 - I3| / I3", margins.planarity),
    )
    close = [f"{name} = {value:.2g}" for name, value in named if abs(value - cls.tolerance) <= 2 * estimate]
    if not close:
        return []
    return [
        f"classification uncertain: {', '.join(close)} against the tolerance {cls.tolerance:g} is within twice the "
        f"relative error estimate {estimate:.2g}, so the class may differ within that error"
    ]


def _unit_warning(loaded: Loaded) -> list[str]:
    """A file with no length unit, read as metres, that is implausibly large for a part (or atoms named by
    their element that far apart): say so."""
    if loaded.units_from != "default":
        return []
    if loaded.kind == "points":
        return _molecule_unit_warning(loaded)
    sizes = [e for e in (_extent(p.body) for p in loaded.parts) if e is not None]
    if not sizes:
        return []
    diagonal = float(np.linalg.norm(np.max(sizes, axis=0)))
    if diagonal <= DEFAULT_TOLERANCES.metres_plausible:
        return []
    return [
        f"the file declares no length unit and none was given, so it was read in metres: the part is "
        f"{diagonal:.4g} m across; if it was drawn in millimetres, pass units=mm (CLI: --units mm), "
        f"which divides the mass by 1e9"
    ]


MOLECULE_METRES_PLAUSIBLE = 1e-6
"""Atoms named by their element further apart than this [m] were not given in metres (bonds are ~1e-10 m,
and the largest molecules ~1e-7 m across)."""


def _molecule_unit_warning(loaded: Loaded) -> list[str]:
    molecule = [p.body for p in loaded.parts if p.extras.get("molecule") and isinstance(p.body, PointBody)]
    if not molecule:
        return []
    x = molecule[0].positions * molecule[0].length_scale
    span = float(np.linalg.norm(x.max(axis=0) - x.min(axis=0)))
    if span < MOLECULE_METRES_PLAUSIBLE:
        return []
    return [
        f"the points name their elements (a molecule) but no length unit was given, so the positions were read in "
        f"metres: the atoms span {span:.4g} m; if they are in angstrom, pass units=angstrom (CLI: --units angstrom)"
    ]


def _shell_thickness_warning(loaded: Loaded, options: AnalysisOptions) -> list[str]:
    """The thin-shell model needs a wall much thinner than the part: refuse a thicker one, warn near it."""
    assert options.thickness is not None  # AnalysisOptions requires it for shells
    thickness = options.thickness * length_scale(loaded.units)
    out: list[str] = []
    for part in loaded.parts:
        extent = _extent(part.body)
        if extent is None:
            continue
        size = float(np.linalg.norm(extent))
        ratio = thickness / size
        where = f" ({part.name})" if len(loaded.parts) > 1 else ""
        if ratio >= DEFAULT_TOLERANCES.shell_thickness_max:
            raise InvalidParameterError(
                f"thickness {thickness:.4g} m is {ratio:.3g} times the part's size{where} ({size:.4g} m across): "
                f"a thin shell needs a wall much thinner than the part; check thickness and units, or analyse "
                f"it as a solid",
                parameter="thickness",
                thickness_m=thickness,
                size_m=size,
            )
        if ratio >= DEFAULT_TOLERANCES.shell_thickness_warn:
            out.append(
                f"thickness {thickness:.4g} m is {100 * ratio:.2g}% of the part's size{where}: the thin-shell "
                f"model (mass = area x thickness x density) is only approximate for so thick a wall"
            )
    return out


def _overridden_density(loaded: Loaded, options: AnalysisOptions) -> list[str]:
    """Cells with their own densities take precedence over a requested density (API.md): say so, naming it."""
    from .body import VolumeBody

    out = []
    for part in loaded.parts:
        given = _part_density(part.name, options)
        if given is not None and isinstance(part.body, VolumeBody) and part.body.weighted:
            where = f" of {part.name!r}" if len(loaded.parts) > 1 else ""
            out.append(
                f"the cells{where} carry their own 'density' array, which takes precedence: the requested density "
                f"{given:g} kg/m^3 was not used"
            )
    return out


def _part_density(name: str, options: AnalysisOptions) -> float | None:
    """A part's density [kg/m^3]: its own from ``densities``, else the common one (None: the default)."""
    if options.densities and name in options.densities:
        return float(options.densities[name])
    return options.density


def _part(name: str, body: Any, options: AnalysisOptions, single: bool) -> PartResult:
    density = _part_density(name, options)
    # several parts: a total mass is shared out after all parts are integrated
    mass = options.mass if single else None
    if isinstance(body, BrepBody):
        from .cad import brep_mass_properties

        props = brep_mass_properties(body, density=None if mass is not None else density, mass=mass, model=options.model)
    else:
        try:
            props = mass_properties(
                body, density=None if mass is not None else density, mass=mass, model=options.model, thickness=options.thickness
            )
        except DegenerateBodyError as exc:
            if single or "part" in exc.details:
                raise
            # one part of several: say which, or "the mesh encloses no volume" reads as the whole file's fault
            raise type(exc)(f"part {name!r}: {exc.message}", **exc.details, part=name) from exc
    frame = principal_frame(props, options.tolerance)
    return PartResult(name, props, frame, classify(frame))


def _scaled(part: PartResult, factor: float) -> PartResult:
    """The part with every density multiplied by ``factor`` (same geometry)."""
    p = part.props
    props = replace(
        p,
        mass=p.mass * factor,
        inertia=InertiaTensor(p.inertia.matrix * factor, p.inertia.about, p.inertia.point),
        principal_moments=p.principal_moments * factor,
        density=None if p.density is None else p.density * factor,
    )
    frame = principal_frame(props, part.frame.tolerance)
    return PartResult(part.name, props, frame, classify(frame))


def _combined(loaded: Loaded, parts: Sequence[PartResult], options: AnalysisOptions, factor: float) -> MassProperties:
    """The whole assembly, integrated as one body with each part's material."""
    if loaded.kind == "cad" and isinstance(loaded.parts[0].body, BrepBody):
        from .cad import combined_properties

        return combined_properties([p.props for p in parts])
    pairs = [(part.body, _part_density(part.name, options)) for part in loaded.parts if not isinstance(part.body, BrepBody)]
    whole = assembly_properties(pairs, model=options.model, thickness=options.thickness, factor=factor)
    volumes = [p.props.volume for p in parts]
    densities = {p.props.density for p in parts}
    warnings = [f"{p.name}: {w}" for p in parts for w in p.props.warnings]
    return replace(
        whole,
        mass=math.fsum(p.props.mass for p in parts),  # the parts' masses add up to the whole's, to the last digit
        volume=float(sum(v for v in volumes if v is not None)) if None not in volumes else None,
        density=densities.pop() if len(densities) == 1 and None not in densities else None,
        warnings=tuple(warnings),
    )


def _motion(
    frame: PrincipalFrame, cls: Classification, options: AnalysisOptions, exact_moments: bool = False, moment_error: float = 0.0
) -> FreeMotion:
    """The torque-free motion; ``exact_moments``: the moments are the caller's numbers, not computed ones;
    ``moment_error``: the relative error bound of computed ones, which the trajectory's estimate carries."""
    from .motion import predict_motion

    return predict_motion(
        frame,
        cls,
        np.asarray(options.omega, dtype=np.float64),
        duration=options.duration,
        samples=options.samples,
        method=options.method,
        exact_moments=exact_moments,
        moment_error=moment_error,
    )


def _source(loaded: Loaded, parts: Sequence[PartResult]) -> Source:
    """The ``source`` section: what was read, and how many elements it had."""
    from .body import MeshBody, VolumeBody

    out: dict[str, Any] = {"format": loaded.format, "kind": loaded.kind, "units": loaded.units, "units_from": loaded.units_from}
    if loaded.filename is not None:
        out = {"filename": loaded.filename, **out}
    bodies = [p.body for p in loaded.parts]
    if loaded.kind == "cad":
        from .cad import source_counts

        out.update(source_counts(loaded, "brep", None))
    elif loaded.kind == "mesh":
        meshes = [b for b in bodies if isinstance(b, MeshBody)]
        closed = [_surface_counts(b, r.props) for b, r in zip(meshes, parts)]
        out["vertices"] = int(sum(n for n, _ in closed))
        out["triangles"] = int(sum(len(b.faces) for b in meshes))
        out["watertight"] = all(w for _, w in closed)
    elif loaded.kind == "volume":
        vols = [b for b in bodies if isinstance(b, VolumeBody)]
        out["points"] = len(vols[0].points)
        out["tetrahedra"] = int(sum(len(b.tets) for b in vols))  # linear tetrahedra
        out["cells"] = int(sum(b.cell_count for b in vols))  # every 3-D cell, each integrated as its element
    else:
        out["points"] = int(sum(len(b.masses) for b in bodies if isinstance(b, PointBody)))
    if loaded.is_assembly:
        out["parts"] = len(loaded.parts)
    return Source(**out)


def _surface_counts(body: Any, props: MassProperties) -> tuple[int, bool]:
    """Distinct vertices and closedness of a surface.

    A solid was welded and found closed by ``mass_properties``; a shell is
    checked here, since a shell's integral does not need it.
    """
    if props.mesh_vertices is not None:
        return props.mesh_vertices, True
    from .topology import surface_topology, weld

    vertices, faces = weld(body.vertices, body.faces)
    return len(vertices), surface_topology(faces, len(vertices)).closed


def precession(
    omega: Sequence[float],
    *,
    inertia_tensor: NDArray[np.float64] | Sequence[Sequence[float]] | None = None,
    principal_moments: Sequence[float] | None = None,
    tolerance: float = DEFAULT_TOLERANCES.moment_rel,
    duration: float | None = None,
    samples: int | None = None,
    method: MotionMethod | str = MotionMethod.EXACT,
) -> PrecessionResult:
    """Torque-free motion from a known inertia (tensor about the COM, or principal moments)."""
    start = time.perf_counter()
    options = AnalysisOptions(
        tolerance=tolerance,
        omega=tuple(omega) if omega is not None else None,  # type: ignore[arg-type]
        duration=duration,
        samples=samples,
        method=method,
    )
    if options.omega is None:
        raise InvalidParameterError("omega is required", parameter="omega")
    if (inertia_tensor is None) == (principal_moments is None):
        raise InvalidParameterError("give exactly one of inertia_tensor or principal_moments", parameter="inertia_tensor")
    if inertia_tensor is not None:
        try:
            matrix = np.asarray(inertia_tensor, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InvalidParameterError("inertia_tensor must be a 3x3 array of numbers", parameter="inertia_tensor") from exc
        # the estimate comes from the eigenproblem's conditioning: ~17 eps I3 / Ii for moment i
        solved = tensor_frame(matrix, tolerance)
        frame, estimate, notes = solved.frame, solved.relative_error_estimate, solved.warnings
    else:
        try:
            moments = np.asarray(principal_moments, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InvalidParameterError("principal_moments must be three numbers", parameter="principal_moments") from exc
        if moments.shape != (3,) or not np.all(np.isfinite(moments)):
            raise InvalidParameterError("principal_moments must be three finite numbers", parameter="principal_moments")
        frame = PrincipalFrame.from_tensor(np.diag(moments), tolerance)
        estimate, notes = 8 * EPS, ()  # the moments as given: only the motion's own arithmetic
    cls = classify(frame)
    motion = _motion(
        frame,
        cls,
        options,
        exact_moments=principal_moments is not None,
        moment_error=estimate if inertia_tensor is not None else 0.0,
    )
    warnings = tuple(dict.fromkeys((*notes, *motion.warnings)))
    return PrecessionResult(frame, cls, motion, Diagnostics(time.perf_counter() - start, max(estimate, 8 * EPS)), warnings)
