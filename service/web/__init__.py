"""The browser page served at ``GET /``: static HTML, CSS and JavaScript, with vendored libraries.

Only data lives here (no Python logic): ``api.pages`` serves this folder.
``vendor/`` holds three.js, swagger-ui and redoc from the npm registry, with their licences.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["STATIC_DIR"]

STATIC_DIR = Path(__file__).resolve().parent
