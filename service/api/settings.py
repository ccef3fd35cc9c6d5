"""Server configuration from the environment (``INERTIA_*``), read once per app."""

from __future__ import annotations

import os

from pydantic import Field
from pydantic_settings import BaseSettings, SettingsConfigDict

__all__ = ["Settings", "MIB", "MIN_SAMPLES", "max_samples"]

MIB = 1024 * 1024


def _default_processes() -> int:
    # one compute process per usable core (the container's CPU quota included): the work is CPU-bound numpy
    from ..cpus import available_cpus

    return available_cpus()


class Settings(BaseSettings):
    """Limits and access control of one server process.

    ``timeout_s`` bounds the compute of one request (one file of a batch),
    and separately the wait for a free compute process.
    """

    model_config = SettingsConfigDict(env_prefix="INERTIA_", extra="ignore", frozen=True)

    max_upload_bytes: int = Field(512 * MIB, gt=0, description="largest request body accepted [bytes]")
    timeout_s: float = Field(120.0, gt=0, allow_inf_nan=False, description="compute limit per request [s]")
    api_key: str | None = Field(None, description="when set, /v1/ needs the header X-API-Key with this value")
    compute_processes: int = Field(default_factory=_default_processes, gt=0, description="worker processes that run the analyses")
    max_waiting: int = Field(
        64,
        ge=0,
        description="jobs that may wait for a busy compute pool before more get "
        "503 server_busy (each waits at most timeout_s; its upload is on disk meanwhile)",
    )
    max_job_memory_bytes: int = Field(
        8192 * MIB, gt=0, description="most memory one analysis may add to its compute process, whatever the upload's size [bytes]"
    )


# a trajectory needs a start and an end
MIN_SAMPLES = 2
_MAX_SAMPLES_DEFAULT = 10_000


def max_samples() -> int:
    """The most trajectory samples one HTTP response may carry: ``INERTIA_MAX_SAMPLES`` (default 10000).

    It is read when the API's request models are built (at import), since the number is part of the
    OpenAPI schema those models produce; the same number validates requests and is stated in the docs.
    """
    from ..motion import MAX_SAMPLES as library_max

    text = os.environ.get("INERTIA_MAX_SAMPLES")
    if text is None:
        return _MAX_SAMPLES_DEFAULT
    try:
        value = int(text)
    except ValueError:
        value = 0
    if not MIN_SAMPLES <= value <= library_max:
        raise ValueError(f"INERTIA_MAX_SAMPLES must be a whole number from {MIN_SAMPLES} to {library_max}, got {text!r}")
    return value
