"""A real uvicorn server per configuration (``python -m inertia serve`` on a free loopback port),
and an in-process TestClient where that is enough."""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

with warnings.catch_warnings():  # starlette deprecates httpx for TestClient in favour of httpx2
    warnings.filterwarnings("ignore", message="Using `httpx` with `starlette.testclient`")
    from fastapi.testclient import TestClient

from inertia.api import Settings, create_app
from tests.support.server import LiveServer as ServerProcess

ROOT = Path(__file__).resolve().parents[2]
STARTUP_S = 30.0


class LiveServer(ServerProcess):
    """One ``python -m inertia serve`` process with the given ``INERTIA_*`` environment."""

    def __init__(self, env: dict[str, str]) -> None:
        super().__init__(env, startup_s=STARTUP_S)


@pytest.fixture(scope="session")
def live_server() -> Iterator[Callable[..., LiveServer]]:
    """``live_server(INERTIA_API_KEY="k")``: a running server, shared by tests with the same settings."""
    (ROOT / ".pytest_cache").mkdir(exist_ok=True)
    servers: dict[tuple[tuple[str, str], ...], LiveServer] = {}

    def get(**env: str) -> LiveServer:
        key = tuple(sorted(env.items()))
        if key not in servers:
            servers[key] = LiveServer(dict(env))
        return servers[key]

    yield get
    for server in servers.values():
        server.stop()


@pytest.fixture(scope="session")
def server(live_server: Callable[..., LiveServer]) -> LiveServer:
    """The server with default settings."""
    return live_server()


@pytest.fixture(scope="session")
def client() -> Iterator[TestClient]:
    """In-process client of an app with default settings (two compute processes)."""
    with TestClient(create_app(Settings(compute_processes=2))) as c:
        yield c
