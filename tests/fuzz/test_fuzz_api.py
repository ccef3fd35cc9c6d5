"""Fuzzing the running server: no 500, no hang, no memory past its bound, no temporary file left.

A real server (``python -m inertia serve`` on a loopback port, its own TMPDIR) gets mutated files of
every format from a few concurrent clients for a bounded time (``INERTIA_FUZZ_SECONDS``, default 20 s;
the longer run of docs/reliability.md sets it higher, with ``INERTIA_FUZZ_REPORT`` naming a JSON file
for the counts). Hypothesis adds arbitrary bytes under every format name, arbitrary JSON bodies and
query values, and batches with corrupt members, in process.

Fails on: any status >= 500 other than 503 (timeout, server_busy), a reply that is not the error
envelope, no reply within the time limit plus a margin (a hang), a server or compute process whose
peak memory passes its bound, a file left in the server's TMPDIR, or a server file's content in a reply.
"""

from __future__ import annotations

import json
import os
import random
import threading
import time
import warnings
from collections import Counter
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import httpx
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from inertia.api import Settings, create_app
from inertia.api.compute import MEMORY_FLOOR_BYTES
from tests.support.server import LiveServer

from . import hostile as H
from .corpus import mutate, seeds

with warnings.catch_warnings():
    warnings.filterwarnings("ignore", message="Using `httpx` with `starlette.testclient`")
    from fastapi.testclient import TestClient

FUZZ_SECONDS = float(os.environ.get("INERTIA_FUZZ_SECONDS", "20"))
FUZZ_SEED = int(os.environ.get("INERTIA_FUZZ_SEED", "13"))
REPORT = os.environ.get("INERTIA_FUZZ_REPORT")
CLIENTS = 3
TIMEOUT_S = 10.0  # the server's per-job limit in this run
HANG_MARGIN_S = 20.0  # a reply later than the limit plus this (on a shared machine) is a hang
MAX_UPLOAD = 8 * 1024 * 1024
MIB = 1024 * 1024
# the server's own growth while fuzzing: its uploads are on disk, its small jobs tiny
SERVER_GROWTH_BOUND = 256 * MIB
# a compute process: its baseline (imports, ~400 MiB mapped) plus the largest job allowance in this run
WORKER_PEAK_BOUND = 512 * MIB + MEMORY_FLOOR_BYTES + 256 * MAX_UPLOAD
SECRET = b"root:x:0:0"  # the first line of /etc/passwd, should a reader ever include it


def _peak_rss(pid: int) -> int:
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return 0
    line = next((x for x in status.splitlines() if x.startswith("VmHWM")), "VmHWM: 0 kB")
    return int(line.split()[1]) * 1024


def _descendants(pid: int) -> list[int]:
    parents: dict[int, int] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            parents[int(entry.name)] = int(stat.rsplit(")", 1)[1].split()[1])
    found, frontier = [], [pid]
    while frontier:
        children = [p for p, parent in parents.items() if parent in frontier]
        found += children
        frontier = children
    return found


class FuzzServer(LiveServer):
    """The fuzzing server, with ``tmp`` its own TMPDIR: where the test looks for leftover files."""

    def __init__(self, env: dict[str, str], tmp: Path) -> None:
        self.tmp = tmp
        super().__init__({**env, "TMPDIR": str(tmp)})


@pytest.fixture(scope="module")
def fuzz_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[FuzzServer]:
    tmp = tmp_path_factory.mktemp("fuzz-tmp")
    (Path(__file__).resolve().parents[2] / ".pytest_cache").mkdir(exist_ok=True)
    server = FuzzServer(
        {
            "INERTIA_TIMEOUT_S": str(TIMEOUT_S),
            "INERTIA_COMPUTE_PROCESSES": "2",
            "INERTIA_MAX_UPLOAD_BYTES": str(MAX_UPLOAD),
        },
        tmp,
    )
    try:
        yield server
    finally:
        server.stop()


def _check_reply(response: httpx.Response, counts: Counter[str], name: str) -> str | None:
    """A problem with one reply, or None."""
    status = response.status_code
    counts[str(status)] += 1
    if SECRET in response.content:
        return f"{name}: a server file's content came back"
    if status >= 500 and status != 503:
        return f"{name}: {status} {response.text[:300]}"
    if status >= 400:
        try:
            error = response.json()["error"]
            assert isinstance(error["code"], str) and isinstance(error["message"], str)
        except (ValueError, KeyError, TypeError, AssertionError):
            return f"{name}: {status} without the error envelope: {response.text[:200]}"
        counts[error["code"]] += 1
    return None


@pytest.mark.timeout(FUZZ_SECONDS + 600)
def test_mutated_files_of_every_format_never_break_the_server(fuzz_server: FuzzServer) -> None:
    corpus = seeds()
    problems: list[str] = []
    counts: Counter[str] = Counter()
    pid = fuzz_server.process.pid
    server_before = _peak_rss(pid)
    worker_peak = 0
    stop = time.monotonic() + FUZZ_SECONDS
    lock = threading.Lock()

    def client(index: int) -> int:
        nonlocal worker_peak
        rng = random.Random(FUZZ_SEED * 1000 + index)
        sent = 0
        with httpx.Client(base_url=fuzz_server.url, timeout=TIMEOUT_S + HANG_MARGIN_S) as c:
            while time.monotonic() < stop:
                name, seed = rng.choice(corpus)
                data = mutate(seed, rng, corpus) if rng.random() < 0.9 else seed
                params = {"format": rng.choice(["stl", "obj", "vtu", "3mf", "inp", "gltf"])} if rng.random() < 0.05 else {}
                try:
                    response = c.post("/v1/analyze/mesh", files={"file": (name, data)}, params=params)
                except httpx.TimeoutException:
                    problem: str | None = f"{name}: no reply in {TIMEOUT_S + HANG_MARGIN_S} s (hang)"
                except httpx.TransportError as exc:
                    problem = f"{name}: connection failed ({exc!r})"
                else:
                    with lock:
                        problem = _check_reply(response, counts, name)
                sent += 1
                if problem:
                    with lock:
                        problems.append(problem)
                if sent % 20 == 0:
                    peak = max((_peak_rss(p) for p in _descendants(pid)), default=0)
                    with lock:
                        worker_peak = max(worker_peak, peak)
        return sent

    with ThreadPoolExecutor(CLIENTS) as pool:
        sent = sum(pool.map(client, range(CLIENTS)))
    worker_peak = max([worker_peak] + [_peak_rss(p) for p in _descendants(pid)])
    server_growth = _peak_rss(pid) - server_before
    time.sleep(0.5)
    left = [str(p) for p in fuzz_server.tmp.rglob("*") if p.is_file()]
    summary = {
        "requests": sent,
        "seconds": FUZZ_SECONDS,
        "clients": CLIENTS,
        "seed": FUZZ_SEED,
        "seed_files": len(corpus),
        "statuses_and_codes": dict(sorted(counts.items())),
        "server_peak_growth_mib": round(server_growth / MIB, 1),
        "worker_peak_rss_mib": round(worker_peak / MIB, 1),
        "problems": problems[:50],
        "temp_files_left": left[:20],
    }
    if REPORT:
        Path(REPORT).write_text(json.dumps(summary, indent=2))
    assert sent > 0
    assert problems == [], summary
    assert left == [], summary
    assert server_growth < SERVER_GROWTH_BOUND, summary
    assert worker_peak < WORKER_PEAK_BOUND, summary


# --- in process, hypothesis ------------------------------------------------------------------------------

EXTENSIONS = [
    "stl",
    "obj",
    "ply",
    "off",
    "glb",
    "gltf",
    "3mf",
    "vtu",
    "vtk",
    "msh",
    "mesh",
    "inp",
    "f3grid",
    "dat",
    "ugrid",
    "ele",
    "json",
    "csv",
    "xdmf",
    "med",
    "zip",
    "",
]


@pytest.fixture(scope="module")
def app_client() -> Iterator[TestClient]:
    with TestClient(
        create_app(
            Settings(
                compute_processes=1,
                timeout_s=TIMEOUT_S,
                max_upload_bytes=MAX_UPLOAD,
            )
        )
    ) as c:
        yield c


def _assert_no_500(response: Any) -> None:
    assert response.status_code < 500 or response.status_code == 503, response.text
    if response.status_code >= 400:
        assert set(response.json()["error"]) == {"code", "message", "details"}


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.binary(max_size=2048), ext=st.sampled_from(EXTENSIONS))
def test_arbitrary_bytes_under_any_format_name_are_never_a_500(app_client: TestClient, data: bytes, ext: str) -> None:
    name = f"file.{ext}" if ext else "file"
    _assert_no_500(app_client.post("/v1/analyze/mesh", files={"file": (name, data)}))


JSON = st.recursive(
    st.none() | st.booleans() | st.floats() | st.integers() | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=4),
    max_leaves=20,
)


@settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    body=JSON
    | st.fixed_dictionaries(
        {
            "points": st.lists(
                st.fixed_dictionaries({"mass": st.floats(), "position": st.lists(st.floats(), min_size=3, max_size=3)}), max_size=4
            )
        }
    ),
    depth=st.sampled_from([0, 0, 0, 50, 5000]),
)
def test_arbitrary_json_bodies_and_parameters_are_never_a_500(app_client: TestClient, body: Any, depth: int) -> None:
    text = "[" * depth + json.dumps(body) + "]" * depth
    _assert_no_500(app_client.post("/v1/analyze/points", content=text, headers={"content-type": "application/json"}))
    _assert_no_500(app_client.post("/v1/precession", content=text, headers={"content-type": "application/json"}))
    box = H.off()
    _assert_no_500(app_client.post("/v1/analyze/mesh", files={"file": box}, params={"densities": text[:4000]}))


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(pick=st.lists(st.integers(0, 10_000), min_size=1, max_size=5), corrupt=st.integers(0, 5), seed=st.integers(0, 2**32))
def test_batch_of_a_zip_with_bad_members_ends_well_formed(app_client: TestClient, pick: list[int], corrupt: int, seed: int) -> None:
    rng = random.Random(seed)
    corpus = _small_corpus()
    members = [
        (
            f"{i}-{corpus[k % len(corpus)][0]}",
            mutate(corpus[k % len(corpus)][1], rng, corpus) if rng.random() < 0.5 else corpus[k % len(corpus)][1],
        )
        for i, k in enumerate(pick)
    ]
    bad = members[corrupt][0] if corrupt < len(members) else None
    archive = H.zip_of(members, corrupt=bad)
    response = app_client.post("/v1/batch", files={"files": ("batch.zip", archive)})
    assert response.status_code == 200
    assert response.text.endswith("\n")
    lines = [json.loads(line) for line in response.text.splitlines()]
    assert len(lines) == len(members)
    assert all("error" not in line or line["error"]["code"] != "internal_error" for line in lines)


_SMALL: list[tuple[str, bytes]] = []


def _small_corpus() -> list[tuple[str, bytes]]:
    if not _SMALL:
        _SMALL.extend((n, d) for n, d in seeds() if len(d) < 64 * 1024)
    return _SMALL
