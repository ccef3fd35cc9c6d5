"""A real uvicorn server per configuration (``python -m inertia serve`` on a free loopback port),
and an in-process TestClient where that is enough."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path

import httpx
import pytest

with warnings.catch_warnings():  # starlette deprecates httpx for TestClient in favour of httpx2
    warnings.filterwarnings("ignore", message="Using `httpx` with `starlette.testclient`")
    from fastapi.testclient import TestClient

from inertia.api import Settings, create_app

ROOT = Path(__file__).resolve().parents[2]
STARTUP_S = 30.0


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class LiveServer:
    """One ``python -m inertia serve`` process with the given ``INERTIA_*`` environment."""

    def __init__(self, env: dict[str, str]) -> None:
        self.port = _free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        full_env = {k: v for k, v in os.environ.items() if not k.startswith("INERTIA_")}
        full_env.update(env)
        self.log = open(ROOT / ".pytest_cache" / f"serve-{self.port}.log", "w+b")  # noqa: SIM115  (the server writes to it until stop() closes it)
        self.process = subprocess.Popen(
            [sys.executable, "-m", "inertia", "serve", "--host", "127.0.0.1", "--port", str(self.port)],
            cwd=ROOT, env=full_env, stdout=self.log, stderr=subprocess.STDOUT)
        self._wait_ready()

    def _wait_ready(self) -> None:
        deadline = time.monotonic() + STARTUP_S
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise RuntimeError(f"server exited: {self.output()}")
            try:
                if httpx.get(f"{self.url}/healthz", timeout=1.0).status_code == 200:
                    return
            except httpx.TransportError:
                time.sleep(0.1)
        raise RuntimeError(f"server did not start in {STARTUP_S} s: {self.output()}")

    def output(self) -> str:
        self.log.flush()
        self.log.seek(0)
        return self.log.read().decode(errors="replace")

    def stop(self) -> None:
        self.process.terminate()
        try:
            self.process.wait(10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self.log.close()


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
    with TestClient(create_app(Settings(compute_processes=2))) as c:  # type: ignore[call-arg]  # fields come from INERTIA_* variables
        yield c
