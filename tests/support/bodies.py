"""Typed access to loaded bodies: the mass code takes meshes, cells and points, never a CAD solid."""

from __future__ import annotations

from inertia.body import Body, BrepBody, VolumeBody

__all__ = ["meshed", "volume"]


def meshed(body: Body | BrepBody) -> Body:
    """``body``, checked to be a mesh, volume or point body (a file read by a mesh reader)."""
    assert not isinstance(body, BrepBody), "expected a meshed body, got a CAD solid"
    return body


def volume(body: Body | BrepBody) -> VolumeBody:
    """``body``, checked to be a volume (cell) body."""
    assert isinstance(body, VolumeBody), f"expected a volume body, got {type(body).__name__}"
    return body
