"""Shared fixtures; shared helpers live in ``tests.support`` and ``benchmarks`` (imported, not put on a path)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.support.paths import SAMPLES


@pytest.fixture
def samples() -> Path:
    return SAMPLES


# tests/test_contract.py re-exports the contract suite (tests/contract/) so that it can be run by that one
# path; a plain run collects tests/contract/ itself, so the module is left out to run nothing twice.
collect_ignore = ["test_contract.py"]
