"""The endpoints of API.md. Each route parses, hands the job to the compute pool, returns."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Depends, File, Query, Request, UploadFile
from fastapi.responses import Response, StreamingResponse
from pydantic_core import to_json
from starlette.background import BackgroundTask
from starlette.concurrency import run_in_threadpool

from ..load.sniff import CAD_FORMATS, POINT_FORMATS, SCENE_FORMATS, SURFACE_FORMATS, VOLUME_FORMATS
from .compute import ComputePool, memory_limit
from .formats import unavailable_formats
from .jobs import Job, MeshJob, PointsJob, PrecessionJob, is_small, run_job, run_job_json
from .ndjson import batch_lines
from .schemas import (
    AnalysisOut,
    FormatOut,
    FormatsOut,
    HealthOut,
    MeshQuery,
    PointsRequest,
    PrecessionRequest,
    PrecessionResponse,
    UnavailableFormatOut,
    error_responses,
)
from .settings import Settings
from .uploads import Upload, Workspace, client_name, expand, save

__all__ = ["health", "v1"]


async def _pool(request: Request) -> ComputePool:  # async: a plain def would cost a thread hop per request
    return request.app.state.pool  # type: ignore[no-any-return]


async def _settings(request: Request) -> Settings:
    return request.app.state.settings  # type: ignore[no-any-return]


async def _workspace(request: Request) -> Workspace:
    return request.app.state.workspace  # type: ignore[no-any-return]


Pool = Annotated[ComputePool, Depends(_pool)]
Config = Annotated[Settings, Depends(_settings)]
Folders = Annotated[Workspace, Depends(_workspace)]
Options = Annotated[MeshQuery, Query()]
MeshFile = Annotated[
    list[UploadFile],
    File(
        description="the mesh file (any format of GET /v1/formats); for a model "
        "with companion files (.gltf + .bin, TetGen .ele + .node), one "
        "'file' part each, or one .zip of them"
    ),
]
MeshFiles = Annotated[list[UploadFile], File(description="mesh files, or one .zip of them")]

health = APIRouter()
v1 = APIRouter(prefix="/v1")

# the error statuses each endpoint can answer (401 is added to every /v1 route when a key is configured)
_ANALYSIS_ERRORS = error_responses(413, 422, 500, 503)
_MESH_ERRORS = error_responses(413, 415, 422, 500, 503)
_CURL = (
    "Example (from the repository root):\n\n"
    "    curl -F file=@sample_meshes/box.stl 'http://localhost:8000/v1/analyze/mesh?units=m&density=1000'"
)


@health.get("/healthz", response_model=HealthOut, tags=["service"], responses=error_responses(500))
async def healthz() -> dict[str, str]:
    """Liveness: answers at once, whatever the compute pool is doing."""
    return {"status": "ok"}


@health.head("/healthz", response_model=HealthOut, tags=["service"], responses=error_responses(500))
async def healthz_head() -> dict[str, str]:
    """Liveness for probes that send HEAD: the status of GET /healthz, without the body."""
    return {"status": "ok"}


@v1.get("/formats", response_model=FormatsOut, tags=["service"], responses=error_responses(500))
async def formats() -> FormatsOut:
    """The formats this installation can read, and which hold surfaces, volume cells, or scenes of several parts.

    A format whose reader needs a package that is not installed is left out of the lists and named under
    ``unavailable`` with the extra that enables it."""
    missing = unavailable_formats()
    surface = [f for f in SURFACE_FORMATS if f not in missing]
    volume = [f for f in VOLUME_FORMATS if f not in missing]
    points = [f for f in POINT_FORMATS if f not in missing]
    cad = [f for f in CAD_FORMATS if f not in missing]
    kinds = [(f, "surface") for f in surface] + [(f, "volume") for f in volume] + [(f, "points") for f in points]
    kinds += [(f, "cad") for f in cad]
    table = [FormatOut(format=f, kind=k, parts=f in SCENE_FORMATS) for f, k in kinds]
    return FormatsOut(
        formats=table,
        surface=surface,
        volume=volume,
        scene=[f for f in SCENE_FORMATS if f not in missing],
        points=points,
        cad=cad,
        unavailable=[UnavailableFormatOut(format=f, needs=n) for f, n in sorted(missing.items())],
    )


@v1.post(
    "/analyze/mesh",
    response_model=AnalysisOut,
    response_model_exclude_none=True,
    responses=_MESH_ERRORS,
    tags=["analysis"],
    description=_CURL,
)
async def analyze_mesh(file: MeshFile, query: Options, pool: Pool, settings: Config, workspace: Folders) -> dict[str, Any]:
    """Mass properties, principal frame and class of one uploaded mesh (and its precession with omega)."""
    options = query.as_options()
    folder = workspace.folder()
    try:  # the upload goes to private files in blocks; the compute process gets their paths
        saved = [await run_in_threadpool(save, part.file, folder, i, settings.max_upload_bytes) for i, part in enumerate(file)]
        names = [client_name(part.filename) for part in file]
        size = sum(s for _, s in saved)
        limit = memory_limit(size, names[0] if len(names) == 1 else ".zip", settings.max_job_memory_bytes)
        source: str | tuple[tuple[str, str], ...] = (
            saved[0][0]
            if len(saved) == 1
            else tuple((name or f"file-{i}", path) for i, (name, (path, _)) in enumerate(zip(names, saved)))
        )
        return await pool.run(MeshJob(source, names[0] if len(saved) == 1 else None, options, folder, limit))
    finally:  # after success, error, timeout or a killed process alike: the job's process has stopped using it
        workspace.remove(folder)


async def _small_or_pooled(job: Job, pool: ComputePool) -> dict[str, Any]:
    # a small job (a few points, no trajectory) costs less than the round trip to a compute process
    return run_job(job) if is_small(job) else await pool.run(job)


@v1.post(
    "/analyze/points", response_model=AnalysisOut, response_model_exclude_none=True, tags=["analysis"], responses=_ANALYSIS_ERRORS
)
async def analyze_points(body: PointsRequest, request: Request) -> Any:
    """Mass properties, principal frame and class of point masses."""
    # the pool is taken from the app, not as a dependency: FastAPI resolving one costs more than the small path's
    # own steps; Request is not a parameter of the API, so the OpenAPI document is unchanged
    job = PointsJob(body.records(), body.as_options())
    if is_small(job):  # the pipeline's dict is the response's JSON: no second validation against AnalysisOut,
        # and its serialisation doubles as the finiteness check (run_job_json)
        return Response(run_job_json(job, to_json), media_type="application/json")
    pool: ComputePool = request.app.state.pool
    return await pool.run(job)


@v1.post(
    "/precession",
    response_model=PrecessionResponse,
    response_model_exclude_none=True,
    tags=["analysis"],
    responses=_ANALYSIS_ERRORS,
)
async def precession(body: PrecessionRequest, pool: Pool) -> dict[str, Any]:
    """Torque-free motion of a body of known inertia."""
    return await _small_or_pooled(PrecessionJob(body.arguments()), pool)


@v1.post(
    "/batch",
    tags=["analysis"],
    responses={
        200: {
            "description": "one line per file, in upload order: an analysis result (AnalysisOut) or "
            '{"source": {"filename": ...}, "error": {...}} (the envelope)',
            "content": {"application/x-ndjson": {"schema": {"type": "string"}}},
        },
        **_ANALYSIS_ERRORS,
    },
)
async def batch(files: MeshFiles, query: Options, pool: Pool, settings: Config, workspace: Folders) -> StreamingResponse:
    """Many meshes (or one .zip of them), streamed as NDJSON lines as each result is ready."""
    options = query.as_options()
    folder = workspace.folder()  # removed by the stream when it ends, and by the task after the response
    items = expand([Upload(f.filename, f.file) for f in files], folder, settings.max_upload_bytes)
    lines = batch_lines(items, options, pool, pool.size + 1, folder, settings.max_job_memory_bytes)
    return StreamingResponse(lines, media_type="application/x-ndjson", background=BackgroundTask(workspace.remove, folder))
