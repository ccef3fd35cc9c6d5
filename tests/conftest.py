"""Shared fixtures: the sample-mesh generator doubles as the exact reference."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ROOT / "sample_meshes"
sys.path.insert(0, str(SAMPLES))


@pytest.fixture
def samples() -> Path:
    return SAMPLES
