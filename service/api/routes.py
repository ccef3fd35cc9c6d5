"""The endpoints of API.md. Each route parses, hands the job to the compute pool, returns."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Depends, File, Query, Request, UploadFile
from fastapi.responses import StreamingResponse

from ..load.sniff import CAD_FORMATS, POINT_FORMATS, SCENE_FORMATS, SURFACE_FORMATS, VOLUME_FORMATS
from .compute import ComputePool
from .jobs import MeshJob, PointsJob, PrecessionJob
from .ndjson import batch_lines
from .schemas import (
    AnalysisOut,
    ErrorOut,
    FormatOut,
    FormatsOut,
    HealthOut,
    MeshQuery,
    PointsRequest,
    PrecessionRequest,
    PrecessionResponse,
)
from .settings import Settings
from .uploads import Upload, client_name, expand

__all__ = ["health", "v1"]


def _pool(request: Request) -> ComputePool:
    return request.app.state.pool  # type: ignore[no-any-return]


def _settings(request: Request) -> Settings:
    return request.app.state.settings  # type: ignore[no-any-return]


Pool = Annotated[ComputePool, Depends(_pool)]
Config = Annotated[Settings, Depends(_settings)]
Options = Annotated[MeshQuery, Query()]
MeshFile = Annotated[UploadFile, File(description="the mesh file (any format of GET /v1/formats)")]
MeshFiles = Annotated[list[UploadFile], File(description="mesh files, or one .zip of them")]

health = APIRouter()
v1 = APIRouter(prefix="/v1")

_UNSUPPORTED: dict[int | str, dict[str, Any]] = {415: {"model": ErrorOut, "description": "unsupported_format"}}
_CURL = ("Example (from the repository root):\n\n"
         "    curl -F file=@sample_meshes/box.stl 'http://localhost:8000/v1/analyze/mesh?units=m&density=1000'")


@health.get("/healthz", response_model=HealthOut, tags=["service"])
async def healthz() -> dict[str, str]:
    """Liveness: answers at once, whatever the compute pool is doing."""
    return {"status": "ok"}


@v1.get("/formats", response_model=FormatsOut, tags=["service"])
async def formats() -> FormatsOut:
    """The readable formats, and which hold surfaces, volume cells, or scenes of several parts."""
    kinds = [(f, "surface") for f in SURFACE_FORMATS] + [(f, "volume") for f in VOLUME_FORMATS]
    kinds += [(f, "points") for f in POINT_FORMATS] + [(f, "cad") for f in CAD_FORMATS]
    table = [FormatOut(format=f, kind=k, parts=f in SCENE_FORMATS)  # type: ignore[arg-type]
             for f, k in kinds]
    return FormatsOut(formats=table, surface=list(SURFACE_FORMATS), volume=list(VOLUME_FORMATS), scene=list(SCENE_FORMATS),
                      points=list(POINT_FORMATS), cad=list(CAD_FORMATS))


@v1.post("/analyze/mesh", response_model=AnalysisOut, response_model_exclude_none=True,
         responses=_UNSUPPORTED, tags=["analysis"], description=_CURL)
async def analyze_mesh(file: MeshFile, query: Options, pool: Pool) -> dict[str, Any]:
    """Mass properties, principal frame and class of one uploaded mesh (and its precession with omega)."""
    options = query.as_options()
    return await pool.run(MeshJob(await file.read(), client_name(file.filename), options))


@v1.post("/analyze/points", response_model=AnalysisOut, response_model_exclude_none=True, tags=["analysis"])
async def analyze_points(body: PointsRequest, pool: Pool) -> dict[str, Any]:
    """Mass properties, principal frame and class of point masses."""
    return await pool.run(PointsJob(body.records(), body.as_options()))


@v1.post("/precession", response_model=PrecessionResponse, response_model_exclude_none=True, tags=["analysis"])
async def precession(body: PrecessionRequest, pool: Pool) -> dict[str, Any]:
    """Torque-free motion of a body of known inertia."""
    return await pool.run(PrecessionJob(body.arguments()))


@v1.post("/batch", tags=["analysis"], responses={200: {
    "description": "one line per file, in upload order: an analysis result or {source, error}",
    "content": {"application/x-ndjson": {"schema": {"type": "string"}}}}})
async def batch(files: MeshFiles, query: Options, pool: Pool, settings: Config) -> StreamingResponse:
    """Many meshes (or one .zip of them), streamed as NDJSON lines as each result is ready."""
    options = query.as_options()
    items = expand([Upload(f.filename, f.file) for f in files], settings.max_upload_bytes)
    return StreamingResponse(batch_lines(items, options, pool, window=pool.size + 1),
                             media_type="application/x-ndjson")
