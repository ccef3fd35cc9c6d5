"""A real ``python -m inertia serve`` process on a free loopback port, for the live HTTP and browser tests."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time

import httpx

from tests.support.paths import ROOT

__all__ = ["LiveServer", "free_port"]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class LiveServer:
    """One server with the given ``INERTIA_*`` environment (the caller's own ``INERTIA_*`` variables are dropped);
    its output goes to ``.pytest_cache/<log_name>-<port>.log``, read back by :meth:`output`."""

    def __init__(self, env: dict[str, str], startup_s: float = 30.0, log_name: str = "serve") -> None:
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        full_env = {k: v for k, v in os.environ.items() if not k.startswith("INERTIA_")}
        full_env.update(env)
        (ROOT / ".pytest_cache").mkdir(exist_ok=True)
        self.log = open(ROOT / ".pytest_cache" / f"{log_name}-{self.port}.log", "w+b")  # noqa: SIM115  (open until stop())
        self.process = subprocess.Popen(
            [sys.executable, "-m", "inertia", "serve", "--host", "127.0.0.1", "--port", str(self.port)],
            cwd=ROOT,
            env=full_env,
            stdout=self.log,
            stderr=subprocess.STDOUT,
        )
        try:
            self._wait_ready(startup_s)
        except BaseException:
            self.stop()  # a server that did not come up leaves no process or open file behind
            raise

    def _wait_ready(self, startup_s: float) -> None:
        deadline = time.monotonic() + startup_s
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise RuntimeError(f"server exited: {self.output()}")
            try:
                if httpx.get(f"{self.url}/healthz", timeout=1.0).status_code == 200:
                    return
            except httpx.TransportError:
                time.sleep(0.1)
        raise RuntimeError(f"server did not start in {startup_s} s: {self.output()}")

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
