"""``create_app(settings)``: the FastAPI application of API.md."""

from __future__ import annotations

import gc
import logging
import sys
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager

from fastapi import Depends, FastAPI
from fastapi.security import APIKeyHeader

from .compute import ComputePool
from .errors import install_error_handlers
from .lane import SmallPointsLane
from .middleware import AccessLog, Guard, LastResort
from .pages import install_pages
from .routes import health, v1
from .schemas import error_responses
from .settings import Settings
from .uploads import Workspace

__all__ = ["create_app"]

DESCRIPTION = """Mass properties, principal axes, top classification and torque-free precession of
rigid bodies, from meshes or point masses. All numbers are SI. Errors always come as
`{"error": {"code", "message", "details"}}`."""


def _configure_logging() -> None:
    """Give the service's loggers a handler when the host (uvicorn, a test) did not."""
    logger = logging.getLogger("inertia")
    if logger.level == logging.NOTSET:
        logger.setLevel(logging.INFO)
    # the package's own NullHandler (``inertia/__init__``) only keeps a library's logs quiet: not a host's handler
    if all(isinstance(h, logging.NullHandler) for h in logger.handlers) and not logging.getLogger().handlers:
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s %(message)s"))
        logger.addHandler(handler)


def create_app(settings: Settings | None = None) -> FastAPI:
    settings = settings or Settings()
    _configure_logging()
    pool = ComputePool(settings.compute_processes, settings.timeout_s, settings.max_waiting)
    workspace = Workspace()

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        await pool.warm_up()
        # what start-up built (modules, the app, its schemas) lives as long as the server: out of the collector's
        # sight, a full collection no longer walks it, which small requests trigger every few hundred calls
        gc.collect()
        gc.freeze()
        try:
            yield
        finally:
            gc.unfreeze()
            pool.close()
            workspace.close()

    # docs_url/redoc_url off: install_pages serves both with vendored assets (no CDN)
    app = FastAPI(title="inertia", version="1", description=DESCRIPTION, lifespan=lifespan, docs_url=None, redoc_url=None)
    app.state.settings = settings
    app.state.pool = pool
    app.state.workspace = workspace
    install_error_handlers(app)
    # the key is checked by Guard before the body is read; the dependency only documents it (the security
    # scheme that lets /docs "Try it out" send the key) and the 401 every /v1 route may then answer
    app.include_router(health)
    if settings.api_key:
        key = APIKeyHeader(
            name="X-API-Key",
            scheme_name="APIKey",
            auto_error=False,
            description="the server's INERTIA_API_KEY; /healthz needs none",
        )
        app.include_router(v1, dependencies=[Depends(key)], responses=error_responses(401))
    else:
        app.include_router(v1)
    install_pages(app)
    app.add_middleware(SmallPointsLane)  # innermost: behind the guard, in front of the router
    app.add_middleware(LastResort)
    app.add_middleware(Guard, settings=settings)
    app.add_middleware(AccessLog)
    return app
