"""Fixtures of the batch tests: the generated library and one Dask cluster."""

from __future__ import annotations

import logging
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.batch.batchlib import make_library


@pytest.fixture(scope="session")
def library(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, str | None]]:
    root = tmp_path_factory.mktemp("library") / "lib"
    root.mkdir()
    return root, make_library(root)


@pytest.fixture
def fresh_library(library: tuple[Path, dict[str, str | None]], tmp_path: Path) -> Path:
    """A copy of the library a test may change."""
    dst = tmp_path / "lib"
    shutil.copytree(library[0], dst)
    return dst


@pytest.fixture(scope="session")
def cluster() -> Iterator[Any]:
    """A real scheduler and two worker processes on loopback, started once."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=logging.ERROR
    ) as lc:
        yield lc
