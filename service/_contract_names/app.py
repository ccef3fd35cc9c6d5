"""``service.app:app``, the contract's name of the ASGI application: the same object as ``inertia.app:app``."""

from inertia.app import app

__all__ = ["app"]
