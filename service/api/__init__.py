"""HTTP front end (FastAPI) of the pipeline; the only package that imports a web framework."""

from .app import create_app
from .settings import Settings

__all__ = ["Settings", "create_app"]
