"""Dask workers' frozen glibc heap thresholds: a batch task raises them, and large temporaries stop faulting in."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest

from inertia.batch import workers
from inertia.batch.sources import Source
from inertia.batch.tasks import analyze_rows
from inertia.pipeline import AnalysisOptions

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt and page-fault counts")

# Where an 8 MB array's memory comes from, before and after the thresholds are raised, in a process started
# as Dask's nanny starts a worker (MALLOC_TRIM_THRESHOLD_=65536) with the Dask package loaded: glibc's
# mallinfo2() counts the bytes of chunks it serves by mmap (hblkhd), each of which faults in page by page.
_MMAPPED = textwrap.dedent(
    """
    import ctypes, sys, types
    import numpy as np
    sys.modules.setdefault("distributed", types.ModuleType("distributed"))  # the worker's condition, cheaply
    from inertia.batch import workers

    class Mallinfo2(ctypes.Structure):
        _fields_ = [(name, ctypes.c_size_t) for name in
                    ("arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks", "uordblks", "fordblks", "keepcost")]

    libc = ctypes.CDLL(None)
    libc.mallinfo2.restype = Mallinfo2

    def mmapped_while_held():
        a = np.ones(1 << 20)  # 8 MB: far above the frozen 128 KiB mmap threshold
        held = libc.mallinfo2().hblkhd
        del a
        return held

    frozen = mmapped_while_held()
    relaxed = workers.relax_frozen_heap_thresholds()
    print(frozen, relaxed, mmapped_while_held())
    """
)


def test_a_frozen_heap_maps_every_large_temporary_afresh_until_the_thresholds_are_raised() -> None:
    env = {**os.environ, "MALLOC_TRIM_THRESHOLD_": "65536"}
    try:
        out = subprocess.run([sys.executable, "-c", _MMAPPED], env=env, capture_output=True, text=True, timeout=120, check=True)
    except subprocess.CalledProcessError as exc:
        if "mallinfo2" in exc.stderr:
            pytest.skip("this C library has no mallinfo2 (glibc >= 2.33)")
        raise
    frozen, relaxed, after = out.stdout.split()
    assert relaxed == "True"
    assert int(frozen) >= 8 << 20  # the array is its own mmap
    assert int(after) < 8 << 20  # ... and now a chunk of the heap, which keeps its pages for the next one


def test_a_local_process_keeps_its_users_setting() -> None:
    # no Dask loaded in this check's process: a user's own MALLOC_TRIM_THRESHOLD_ is not overridden
    code = "from inertia.batch import workers; print(workers.relax_frozen_heap_thresholds())"
    env = {**os.environ, "MALLOC_TRIM_THRESHOLD_": "65536"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120, check=True)
    assert out.stdout.strip() == "False"


def _worker_state() -> tuple[str | None, bool | None]:
    return os.environ.get("MALLOC_TRIM_THRESHOLD_"), workers._relaxed


def test_a_task_on_a_dask_worker_raises_the_thresholds_its_nanny_froze(cluster: Any, tmp_path: Path) -> None:
    distributed = pytest.importorskip("distributed")
    mesh = Path(__file__).resolve().parents[2] / "sample_meshes" / "box.stl"
    with distributed.Client(cluster) as client:
        states = client.run(_worker_state)
        assert all(value == "65536" for value, _ in states.values()), states  # Dask's default for its workers
        worker = next(iter(states))
        rows = client.submit(analyze_rows, [Source("box.stl", str(mesh))], AnalysisOptions(), workers=[worker]).result()
        assert len(rows) == 1
        assert client.run(_worker_state, workers=[worker])[worker] == ("65536", True)
