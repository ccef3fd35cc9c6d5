"""The ASGI application: ``uvicorn service.app:app`` (configured by ``INERTIA_*`` variables)."""

from .api import create_app

app = create_app()
