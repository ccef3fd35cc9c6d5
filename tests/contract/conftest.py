"""The contract suite's client: the ASGI app through fastapi.testclient."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from fastapi.testclient import TestClient


@pytest.fixture(scope="module")
def client() -> Iterator[TestClient]:
    from inertia.app import app

    with TestClient(app) as c:
        yield c
