"""The compute pool: a job past its deadline is really stopped, and the pool keeps serving."""

from __future__ import annotations

import asyncio
import multiprocessing
import struct
from typing import Any

import pytest

from inertia.api.compute import ComputePool
from inertia.api.jobs import MeshJob
from inertia.api.transport import ComputeTimeoutError
from inertia.errors import NotWatertightError
from inertia.pipeline import AnalysisOptions
from tests.support.meshes import box_stl, torus_stl


def open_box() -> bytes:
    """The unit box without its last triangle (binary STL: 80-byte header, count, 50-byte records)."""
    data = box_stl(1, 1, 1)
    return data[:80] + struct.pack("<I", 11) + data[84 : 84 + 50 * 11]


def pool_processes(pool: ComputePool) -> list[multiprocessing.process.BaseProcess]:
    """The live processes the pool holds (idle ones; none runs a job between awaits here)."""
    return [w.process for w in pool._idle if w.process.is_alive()]


def test_timed_out_job_is_killed_and_the_pool_recovers() -> None:
    pool = ComputePool(size=1, timeout_s=0.2)

    async def scenario() -> dict[str, Any]:
        await pool.warm_up()
        (warm,) = pool_processes(pool)
        with pytest.raises(ComputeTimeoutError):
            await pool.run(MeshJob(torus_stl(600, 600), "torus.stl", AnalysisOptions()))
        assert not warm.is_alive() and pool_processes(pool) == []  # the job is stopped, not left spinning
        with pytest.raises(NotWatertightError):  # errors cross the process boundary with their class
            await pool.run(MeshJob(open_box(), "open.stl", AnalysisOptions()))
        return await pool.run(MeshJob(box_stl(1, 2, 3), "box.stl", AnalysisOptions()))

    try:
        doc = asyncio.run(scenario())
        mine = pool_processes(pool)
    finally:
        pool.close()
    assert doc["mass"] == pytest.approx(6000, rel=1e-12, abs=0)
    assert all(not p.is_alive() for p in mine)
