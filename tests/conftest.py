"""Shared fixtures: the sample-mesh generator doubles as the exact reference."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from paths import SAMPLES  # noqa: E402

sys.path.insert(0, str(SAMPLES))


@pytest.fixture
def samples() -> Path:
    return SAMPLES
