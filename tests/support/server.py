"""A real ``python -m inertia serve`` process on a free loopback port, for the live HTTP and browser tests
(``benchmarks.harness.Server``, with its output kept under ``.pytest_cache``)."""

from __future__ import annotations

from benchmarks.harness import Server, free_port
from tests.support.paths import ROOT

__all__ = ["LiveServer", "free_port"]


class LiveServer(Server):
    """One server with the given ``INERTIA_*`` environment (the caller's own ``INERTIA_*`` variables are dropped);
    its output goes to ``.pytest_cache/<log_name>-<port>.log``, read back by :meth:`output`."""

    def __init__(self, env: dict[str, str], startup_s: float = 30.0, log_name: str = "serve") -> None:
        super().__init__(env, startup_s=startup_s, log_dir=ROOT / ".pytest_cache", log_name=log_name)
