"""The API against hostile input and load: each test here fails on a server without the issue-13 defences.

Includes and external references are refused, bombs are 413 in a fraction of a second, a 500 closes its
connection cleanly, a corrupt zip member is one error line of a well-formed batch, no temporary file
outlives its request (timeouts included), concurrent large uploads stay within a memory bound, a full
queue answers 503 with Retry-After, and every reader failure is a 4xx.
"""

from __future__ import annotations

import json
import os
import threading
import time
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any, cast

import httpx
import numpy as np
import pytest

from inertia.api import Settings, create_app
from tests.fuzz import hostile as H
from tests.support.meshes import box_stl, torus_stl
from tests.support.server import free_port

with warnings.catch_warnings():
    warnings.filterwarnings("ignore", message="Using `httpx` with `starlette.testclient`")
    from fastapi.testclient import TestClient

MIB = 1024 * 1024
BOX = box_stl(1, 2, 3)


def post_mesh(client: Any, name: str, data: bytes, **params: Any) -> Any:
    return client.post("/v1/analyze/mesh", files={"file": (name, data)}, params=params)


def error_of(response: Any, status: int, code: str) -> dict[str, Any]:
    assert response.status_code == status, response.text
    body = response.json()
    assert body["error"]["code"] == code, body
    return cast("dict[str, Any]", body["error"])


# --- no file opened on the client's say-so ------------------------------------------------------------


def test_abaqus_include_of_a_server_file_is_refused(client: Any, tmp_path: Path) -> None:
    # a valid deck placed on the server: a reader that follows the include would analyse it
    name, deck = H.abaqus()
    placed = tmp_path / name
    placed.write_bytes(deck)
    for target in (str(placed), "/etc/passwd", "/dev/zero", "../../../etc/passwd"):
        _, data = H.abaqus(include=target)
        error = error_of(post_mesh(client, "deck.inp", data), 422, "external_reference")
        assert "same upload" in error["message"]


def test_every_external_reference_is_refused_over_http(client: Any) -> None:
    for name, data in (
        H.abaqus(keyword_input="/dev/zero"),
        H.gltf(uri="/etc/passwd"),
        H.gltf(image_uri="http://127.0.0.1:9/a.png"),
        H.glb(uri="file:///etc/passwd"),
        H.vtu(piece_source="/etc/passwd"),
        H.vtu(doctype=True),
        H.threemf(doctype=True),
    ):
        assert error_of(post_mesh(client, name, data), 422, "external_reference")["message"]


# --- bombs and lies --------------------------------------------------------------------------------------


@pytest.mark.parametrize("attack", ["3mf", "vtu", "vtu-lie"])
def test_decompression_bomb_is_413(client: Any, attack: str) -> None:
    name, data = {
        "3mf": lambda: H.threemf(bomb=200 * MIB),
        "vtu": lambda: H.vtu(bomb=128 * MIB),
        "vtu-lie": lambda: H.vtu(bomb=16 * MIB, declared=96),
    }[attack]()
    assert len(data) < 1 * MIB
    error = error_of(post_mesh(client, name, data), 413, "payload_too_large")
    assert "inflate" in error["message"]


def test_glb_whose_header_lies_about_its_length_is_422(client: Any) -> None:
    name, data = H.glb(length_lie=10**6)
    assert error_of(post_mesh(client, name, data), 422, "unreadable_file")["message"]


def test_nested_json_in_gltf_and_in_densities_is_422(client: Any) -> None:
    name, data = H.gltf(depth=50_000)
    error_of(post_mesh(client, name, data), 422, "unreadable_file")
    error = error_of(post_mesh(client, "box.stl", BOX, densities=H.deep_json(5_000)), 422, "invalid_parameter")
    assert error["details"]["parameter"] == "densities"


def test_points_file_nested_too_deeply_or_a_bad_csv_is_422(client: Any) -> None:
    assert error_of(post_mesh(client, "p.json", H.deep_json(100_000).encode()), 422, "unreadable_file")["message"]
    huge_field = b'mass,x,y,z\n"' + b"1" * 200_000 + b'",0,0,0\n'  # past csv's field size limit
    assert error_of(post_mesh(client, "p.csv", huge_field), 422, "unreadable_file")["message"]


def test_reader_that_calls_sys_exit_is_422(client: Any) -> None:
    # meshio prints and calls sys.exit(1) when its reader fails on a file given by path
    for name in ("junk.msh", "junk.vtk", "junk.inp", "junk.mesh"):
        response = post_mesh(client, name, b"$MeshFormat\nnot a mesh at all\n" * 3)
        assert 400 <= response.status_code < 500, (name, response.text)


def test_obj_vertex_with_two_coordinates_is_422(client: Any) -> None:
    response = post_mesh(client, "bad.obj", b"v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert 400 <= response.status_code < 500, response.text


def test_subnormal_density_never_gives_mass_zero(client: Any) -> None:
    error = error_of(post_mesh(client, "box.stl", BOX, density="1e-320"), 422, "invalid_parameter")
    assert "density" in error["message"]


def test_error_messages_name_no_server_path(client: Any) -> None:
    for name, data in (("junk.msh", b"garbage"), ("junk.vtu", b"<VTKFile>"), ("x.ele", b"1 4 0\n1 1 2 3 4\n")):
        text = post_mesh(client, name, data).text
        assert "/tmp" not in text and "inertia-" not in text and "upload-" not in text, text


# --- batches ---------------------------------------------------------------------------------------------


def test_corrupt_zip_member_is_one_error_line_of_a_complete_batch(client: Any) -> None:
    members = [("a.stl", BOX), ("b.stl", box_stl(2, 2, 2) + b"\0" * 4000), ("c.stl", box_stl(1, 1, 1))]
    archive = H.zip_of(members, corrupt="b.stl")
    response = client.post("/v1/batch", files={"files": ("parts.zip", archive)})
    assert response.status_code == 200
    assert response.text.endswith("\n")
    lines = [json.loads(line) for line in response.text.splitlines()]
    assert [("error" in line) for line in lines] == [False, True, False]
    assert lines[1]["source"]["filename"] == "b.stl" and lines[1]["error"]["code"] == "unreadable_file"
    assert lines[2]["mass"] == pytest.approx(1000.0, rel=1e-12, abs=0)


def test_zip_bomb_member_is_an_error_line_and_the_batch_goes_on(client: Any) -> None:
    import io
    import zipfile

    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("a.stl", BOX)
        z.writestr("bomb.stl", b"\0" * (200 * MIB))
        z.writestr("c.stl", BOX)
    with TestClient(create_app(Settings(compute_processes=1, max_upload_bytes=64 * MIB))) as c:
        lines = [json.loads(x) for x in c.post("/v1/batch", files={"files": ("z.zip", out.getvalue())}).text.splitlines()]
    assert [line.get("error", {}).get("code") for line in lines] == [None, "payload_too_large", None]


# --- memory ----------------------------------------------------------------------------------------------


def test_job_past_its_memory_allowance_is_413_and_the_worker_serves_on() -> None:
    # a cap below what a 500 x 500 torus needs (>100 MiB of arrays): the job fails in its process only
    settings = Settings(compute_processes=1, max_job_memory_bytes=24 * MIB)
    with TestClient(create_app(settings)) as c:
        error = error_of(post_mesh(c, "torus.stl", torus_stl(500, 500)), 413, "payload_too_large")
        assert "memory" in error["message"]
        ok = post_mesh(c, "box.stl", BOX)
    assert ok.status_code == 200 and ok.json()["mass"] == pytest.approx(6000, rel=1e-12, abs=0)


def test_queue_beyond_its_bound_is_503_with_retry_after() -> None:
    settings = Settings(compute_processes=1, max_waiting=0, timeout_s=60)
    slow = torus_stl(400, 400)
    app = create_app(settings)
    with TestClient(app) as c:
        pool = app.state.pool
        results: list[Any] = []
        runner = threading.Thread(target=lambda: results.append(post_mesh(c, "torus.stl", slow)))
        runner.start()
        deadline = time.monotonic() + 30
        while not (pool._slots and pool._slots[1].locked()) and time.monotonic() < deadline:
            time.sleep(0.01)  # until the slow job holds the only process
        busy = post_mesh(c, "box.stl", BOX)
        runner.join()
    error_of(busy, 503, "server_busy")
    assert int(busy.headers["Retry-After"]) >= 1
    assert results[0].status_code == 200, results[0].text


def test_small_points_requests_run_without_the_compute_pool(client: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    pool = client.app.state.pool

    async def no_pool(job: Any) -> Any:
        raise AssertionError("a 3-point request went to the compute pool")

    monkeypatch.setattr(pool, "run", no_pool)
    body = {"points": [{"mass": 1, "position": [0, 0, 0]}, {"mass": 2, "position": [1, 0, 0]}, {"mass": 1, "position": [0, 1, 0]}]}
    response = client.post("/v1/analyze/points", json=body)
    assert response.status_code == 200 and response.json()["mass"] == 4.0


def test_formats_lists_only_readable_formats(client: Any) -> None:
    import importlib.util

    doc = client.get("/v1/formats").json()
    listed = {f["format"] for f in doc["formats"]}
    if importlib.util.find_spec("h5py") is None:
        assert "xdmf" not in listed and "med" not in listed and "xdmf" not in doc["volume"]
        assert {u["format"] for u in doc["unavailable"]} >= {"xdmf", "med"}
        assert all("hdf5" in u["needs"] for u in doc["unavailable"] if u["format"] in ("xdmf", "med"))
    assert {"stl", "3mf", "msh"} <= listed
    assert ("vtu" in listed) == (importlib.util.find_spec("vtkmodules") is not None)
    # an unknown extension's message offers what /v1/formats lists, and names the others apart
    res = client.post("/v1/analyze/mesh", files={"file": ("part.xyzw", b"x")})
    assert res.status_code == 415
    offered = res.json()["error"]["message"].split("readable formats are ", 1)[1].split(" (", 1)[0]
    assert set(offered.split(", ")) == listed | set(doc["points"])


# --- a real server: connections, temporary files, memory ------------------------------------------------


@pytest.fixture
def buggy_server() -> Iterator[str]:
    """A uvicorn server in this process with one route that fails like a bug."""
    import uvicorn

    app = create_app(Settings(compute_processes=1))

    @app.get("/v1/boom")
    async def boom() -> None:
        raise RuntimeError("a bug")

    port = free_port()
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="critical"))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 30
    while not server.started and time.monotonic() < deadline:
        time.sleep(0.05)
    try:
        yield f"http://127.0.0.1:{port}"
    finally:
        server.should_exit = True
        thread.join(15)


def test_a_500_closes_its_connection_cleanly_and_the_next_requests_succeed(buggy_server: str) -> None:
    with httpx.Client(base_url=buggy_server, timeout=30) as c:
        response = c.get("/v1/boom")
        assert response.status_code == 500 and response.json()["error"]["code"] == "internal_error"
        assert response.headers.get("connection", "").lower() == "close"
        assert all(c.get("/healthz").status_code == 200 for _ in range(20))
        assert all(c.get("/v1/boom").status_code == 500 and c.get("/healthz").status_code == 200 for _ in range(5))


def test_keep_alive_connection_survives_4xx_errors(server: Any) -> None:
    with httpx.Client(base_url=server.url, timeout=30) as c:
        for _ in range(5):
            assert post_mesh(c, "x.inp", H.abaqus(include="/etc/passwd")[1]).status_code == 422
            assert post_mesh(c, "box.stl", BOX).status_code == 200


def _slow_volume_mesh() -> bytes:
    """A legacy ASCII VTK grid of many tetrahedra: meshio parses it for seconds, via a temporary file."""
    n = 40
    grid = np.stack(np.meshgrid(*[np.arange(n + 1.0)] * 3, indexing="ij"), -1).reshape(-1, 3)
    idx = np.arange((n + 1) ** 3).reshape(n + 1, n + 1, n + 1)
    c0 = idx[:-1, :-1, :-1].ravel()
    hexes = np.stack(
        [
            c0,
            c0 + (n + 1) ** 2,
            c0 + (n + 1) ** 2 + n + 1,
            c0 + n + 1,
            c0 + 1,
            c0 + (n + 1) ** 2 + 1,
            c0 + (n + 1) ** 2 + n + 2,
            c0 + n + 2,
        ],
        1,
    )
    lines = ["# vtk DataFile Version 2.0", "grid", "ASCII", "DATASET UNSTRUCTURED_GRID", f"POINTS {len(grid)} double"] + [
        f"{x} {y} {z}" for x, y, z in grid
    ]
    lines += [f"CELLS {len(hexes)} {9 * len(hexes)}"] + ["8 " + " ".join(map(str, h)) for h in hexes]
    lines += [f"CELL_TYPES {len(hexes)}"] + ["12"] * len(hexes)
    return ("\n".join(lines) + "\n").encode()


def test_no_temporary_file_outlives_a_timeout_or_an_error(live_server: Any, tmp_path: Path) -> None:
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    server = live_server(INERTIA_TIMEOUT_S="0.3", TMPDIR=str(tmp), INERTIA_COMPUTE_PROCESSES="1")
    slow = _slow_volume_mesh()
    with httpx.Client(base_url=server.url, timeout=60) as c:
        for _ in range(3):
            error_of(post_mesh(c, "grid.vtk", slow), 503, "timeout")
        post_mesh(c, "junk.msh", b"garbage")
        post_mesh(c, "box.stl", BOX)
        post_mesh(c, "x.inp", H.abaqus(include="/etc/passwd")[1])
    time.sleep(0.5)
    left = [p for p in tmp.rglob("*") if p.is_file()]
    assert left == [], left


def _rss_peak_kib(pid: int) -> int:
    status = Path(f"/proc/{pid}/status").read_text()
    return int(next(line for line in status.splitlines() if line.startswith("VmHWM")).split()[1])


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs /proc")
def test_concurrent_large_uploads_stay_within_a_memory_bound(live_server: Any) -> None:
    # 8 uploads of 12 MiB at once; each is refused by its reader quickly (unknown content), so the
    # server's own memory is what is measured: it must not hold them (the old server grew by 2 x 12 MiB each)
    server = live_server(INERTIA_COMPUTE_PROCESSES="1", INERTIA_MAX_WAITING="64")
    upload = b"\x01" * (12 * MIB)
    before = _rss_peak_kib(server.process.pid)

    def one(_: int) -> int:
        with httpx.Client(base_url=server.url, timeout=120) as c:
            return cast("int", post_mesh(c, "blob.off", upload).status_code)

    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(8) as pool:
        statuses = list(pool.map(one, range(8)))
    grown_mib = (_rss_peak_kib(server.process.pid) - before) / 1024
    assert all(400 <= s < 500 for s in statuses), statuses
    print(f"server grew by {grown_mib:.0f} MiB for 8 x 12 MiB uploads")
    assert grown_mib < 8 * 12 / 2, f"server grew by {grown_mib:.0f} MiB for 8 x 12 MiB uploads"


def test_no_500_from_a_batch_of_hostile_files(client: Any) -> None:
    files = [
        H.abaqus(include="/etc/passwd"),
        H.threemf(bomb=64 * MIB),
        H.gltf(depth=10_000),
        H.glb(chunk_lie=99),
        ("junk.msh", b"garbage"),
        ("bad.obj", b"v 0 0\nf 1 2 3\n"),
        ("box.stl", BOX),
    ]
    response = client.post("/v1/batch", files=[("files", f) for f in files])
    assert response.status_code == 200
    lines = [json.loads(line) for line in response.text.splitlines()]
    assert len(lines) == len(files)
    assert all(line.get("error", {}).get("code") != "internal_error" for line in lines), lines
    assert "mass" in lines[-1]


def test_workspace_is_empty_after_requests(client: Any) -> None:
    post_mesh(client, "box.stl", BOX)
    post_mesh(client, "junk.msh", b"garbage")
    client.post("/v1/batch", files=[("files", ("a.stl", BOX)), ("files", ("b.zip", b"PK broken"))])
    root = client.app.state.workspace.root
    assert os.listdir(root) == []


# --- several files in one upload --------------------------------------------------------------------------


def test_gltf_with_its_buffer_as_a_second_file_part_is_read(client: Any) -> None:
    import base64

    _, embedded = H.gltf()
    doc = json.loads(embedded)
    buffer = base64.b64decode(doc["buffers"][0]["uri"].split(",", 1)[1])
    doc["buffers"][0]["uri"] = "tet.bin"
    files = [("file", ("tet.gltf", json.dumps(doc).encode())), ("file", ("tet.bin", buffer))]
    response = client.post("/v1/analyze/mesh", files=files)
    assert response.status_code == 200, response.text
    assert response.json()["mass"] == pytest.approx(1000 / 6, rel=1e-6, abs=0)  # unit right tetrahedron, float32 corners
    alone = client.post("/v1/analyze/mesh", files=[files[0]])
    error_of(alone, 422, "external_reference")


def test_abaqus_include_that_comes_in_the_same_upload_is_followed(client: Any) -> None:
    _, part = H.abaqus()
    main = b"*HEADING\nassembly\n*INCLUDE, INPUT=part.inc\n"
    files = [("file", ("deck.inp", main)), ("file", ("part.inc", part))]
    response = client.post("/v1/analyze/mesh", files=files)
    assert response.status_code == 200, response.text
    assert response.json()["mass"] == pytest.approx(1000 / 6, rel=1e-12, abs=0)  # the unit right tetrahedron
    error_of(client.post("/v1/analyze/mesh", files=[files[0]]), 422, "external_reference")
