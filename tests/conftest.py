"""Shared fixtures; shared helpers live in ``tests.support`` and ``benchmarks`` (imported, not put on a path)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.support.paths import SAMPLES


@pytest.fixture
def samples() -> Path:
    return SAMPLES
