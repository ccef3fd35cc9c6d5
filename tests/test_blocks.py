"""Block passes on several threads: every block once, errors raised, results bit-identical to one thread."""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from benchmarks.cases import torus, triangles_stl_bytes
from inertia import blocks
from inertia.pipeline import analyze


@pytest.fixture
def threads(monkeypatch: pytest.MonkeyPatch) -> object:
    """Each test sets its own thread count; the process's setting comes back afterwards."""
    yield
    blocks.set_block_threads(None)


def test_every_block_runs_once_on_several_threads(threads: object) -> None:
    blocks.set_block_threads(3)
    starts = range(0, 1000, 10)
    seen = np.zeros(len(starts), dtype=np.int64)
    idents: set[int] = set()
    barrier = threading.Barrier(3, timeout=10)  # the first three blocks wait for each other: three threads ran

    def work(start: int) -> None:
        if start < 30:
            barrier.wait()
        idents.add(threading.get_ident())
        seen[start // 10] += 1

    blocks.for_each_block(work, starts)
    assert seen.tolist() == [1] * len(starts)
    assert threading.get_ident() in idents and len(idents) == 3


def test_a_failing_block_raises_after_the_running_ones_and_stops_the_rest(threads: object) -> None:
    blocks.set_block_threads(2)
    done: list[int] = []

    def work(start: int) -> None:
        if start == 4:
            raise ValueError("block 4")
        done.append(start)

    with pytest.raises(ValueError, match="block 4"):
        blocks.for_each_block(work, range(1000))
    assert len(done) < 999  # the blocks after the error were not started


def test_a_block_inside_a_block_runs_on_its_own_thread(threads: object) -> None:
    blocks.set_block_threads(2)
    inner: dict[int, set[int]] = {}

    def outer(start: int) -> None:
        mine: set[int] = set()
        blocks.for_each_block(lambda _s: mine.add(threading.get_ident()), range(8))
        inner[start] = mine

    blocks.for_each_block(outer, range(8))
    assert all(len(ids) == 1 for ids in inner.values())


def test_few_blocks_run_on_the_calling_thread(threads: object) -> None:
    blocks.set_block_threads(4)
    idents: set[int] = set()
    blocks.for_each_block(lambda _s: idents.add(threading.get_ident()), range(3))  # fewer than 2 for each of 2
    assert idents == {threading.get_ident()}


@pytest.mark.parametrize(("count", "most"), [(7, 2), (35, 2), (36, 3), (1000, 8)])
def test_threads_beyond_two_need_blocks_enough(threads: object, count: int, most: int) -> None:
    """One more thread per 12 blocks: the temporaries of the blocks in flight stay small next to the data."""
    blocks.set_block_threads(8)
    running: set[int] = set()
    peak = [0]
    lock = threading.Lock()

    def work(_start: int) -> None:
        with lock:
            running.add(threading.get_ident())
            peak[0] = max(peak[0], len(running))
        time.sleep(0.002)  # long enough for every thread taking part to hold a block at once
        with lock:
            running.discard(threading.get_ident())

    blocks.for_each_block(work, range(count))
    assert peak[0] <= most
    if count >= 1000:
        assert peak[0] >= 2


@pytest.mark.parametrize(
    ("env", "expected"),
    [
        ({"INERTIA_THREADS": "3", "OMP_NUM_THREADS": "1"}, 3),
        ({"OMP_NUM_THREADS": "1"}, 1),  # a Dask or batch worker
        ({"INERTIA_THREADS": "many", "OMP_NUM_THREADS": "2"}, 2),  # not a number: as if unset
        ({"INERTIA_THREADS": "0"}, 1),
        ({"INERTIA_THREADS": "999"}, blocks.MAX_THREADS),
    ],
)
def test_thread_count_from_the_environment(monkeypatch: pytest.MonkeyPatch, env: dict[str, str], expected: int) -> None:
    for name in ("INERTIA_THREADS", "OMP_NUM_THREADS"):
        monkeypatch.delenv(name, raising=False)
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    assert blocks.block_threads() == expected


def test_analysis_on_four_threads_is_bit_identical_to_one(tmp_path: Path, threads: object) -> None:
    """A mesh of many blocks in every pass, far from the origin (the double-double pass does work)."""
    v, f = torus(500, 300, 3.0, 1.0)  # 300,000 triangles: 10 blocks of the integration passes, 2 or more a thread
    far = v + np.array([1000.0, -250.0, 30.0])
    path = tmp_path / "torus.stl"
    path.write_bytes(triangles_stl_bytes(far.astype("<f4")[f], b"blocks".ljust(80, b" ")))
    docs = []
    for n in (1, 4):
        blocks.set_block_threads(n)
        doc = analyze(str(path)).as_dict()
        doc["diagnostics"].pop("elapsed_s")  # the one field that may differ
        docs.append(json.dumps(doc, sort_keys=True))
    assert docs[0] == docs[1]


def test_one_heap_for_every_thread_where_the_c_library_is_glibc() -> None:
    code = "from inertia.blocks import single_heap; print(single_heap())"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=60).stdout
    if platform.libc_ver()[0] == "glibc":
        assert out.strip() == "True"


@pytest.mark.parametrize("n_threads", [1, 3])
def test_components_on_threads_match_scipy_on_long_chains(threads: object, n_threads: int) -> None:
    """Paths of 50,000 nodes in shuffled order need many pointer jumps, each in blocks on the threads."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from inertia import topology

    rng = np.random.default_rng(5)
    n = 300_000
    perm = rng.permutation(n)
    ends = np.arange(n - 1)
    ends = ends[(ends + 1) % 50_000 != 0]  # six chains
    a, b = perm[ends], perm[ends + 1]
    blocks.set_block_threads(n_threads)
    count, label = topology._components(n, a, b)
    ref_count, ref_label = connected_components(coo_matrix((np.ones(len(a)), (a, b)), shape=(n, n)), directed=False)
    assert count == ref_count == 6
    np.testing.assert_array_equal(label, ref_label)


def _stl_file(tmp_path: Path) -> tuple[Path, bytes]:
    v, f = torus(30, 20, 3.0, 1.0)
    data = triangles_stl_bytes(v.astype("<f4")[f], b"pread".ljust(80, b" "))
    path = tmp_path / "torus.stl"
    path.write_bytes(data)
    return path, data


def test_binary_stl_read_in_blocks_at_their_offsets_equals_the_whole_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, threads: object
) -> None:
    from inertia.load import stl

    path, data = _stl_file(tmp_path)
    monkeypatch.setattr(stl, "_READ_BLOCK", 7)  # 1,200 faces: 172 blocks, the last one short
    real_pread = os.pread
    monkeypatch.setattr(os, "pread", lambda fd, n, at: real_pread(fd, max(1, n // 3), at))  # short reads
    blocks.set_block_threads(3)
    with path.open("rb") as fh:
        vertices, faces, _ = stl.read_stl_file(fh, len(data))
    ref_vertices, ref_faces, _ = stl.read_stl(data)
    np.testing.assert_array_equal(vertices, ref_vertices)
    np.testing.assert_array_equal(faces, ref_faces)


def test_binary_stl_that_shrinks_while_read_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from inertia.errors import UnreadableFileError
    from inertia.load import stl

    path, data = _stl_file(tmp_path)
    monkeypatch.setattr(os, "pread", lambda fd, n, at: b"")  # the file's end came early
    with path.open("rb") as fh, pytest.raises(UnreadableFileError, match="truncated"):
        stl.read_stl_file(fh, len(data))


def test_volume_cell_sums_on_threads_are_bit_identical_to_one(threads: object) -> None:
    """Trilinear hexahedra of a sheared grid: the quadrature runs in many blocks, summed in block order."""
    from inertia.cells import cell_sums

    k = 24
    g = np.arange(k + 1, dtype=np.float64)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    points = np.stack([x + 0.1 * y * z, y + 0.05 * x, z - 0.02 * x * y], axis=-1).reshape(-1, 3) / k
    node = np.arange((k + 1) ** 3).reshape(k + 1, k + 1, k + 1)
    corners = [node[i : k + i, j : k + j, m : k + m] for i, j, m in ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0))]
    corners += [node[i : k + i, j : k + j, 1:] for i, j in ((0, 0), (1, 0), (1, 1), (0, 1))]
    hexes = np.stack([c.reshape(-1) for c in corners], axis=1)  # 13,824 cells
    weight = 1.0 + (np.arange(len(hexes)) % 7) / 7.0
    results = []
    for n in (1, 3):
        blocks.set_block_threads(n)
        s = cell_sums(points, "hexahedron", hexes, weight)
        results.append((s.m0, s.m1.tolist(), s.m2.tolist(), s.abs_m2.tolist(), s.noise, s.blocks))
    assert results[0] == results[1]
    assert results[0][5] >= 6  # enough blocks for the threads to share them


@pytest.mark.parametrize("n_threads", [1, 3])
def test_edge_counts_in_blocks_match_a_count_of_every_edge(threads: object, n_threads: int) -> None:
    """Random faces on few vertices: runs of one to many half-edges, over several blocks of runs."""
    from collections import Counter

    from inertia import topology

    rng = np.random.default_rng(11)
    n_vertices = 600
    faces = np.array([rng.choice(n_vertices, 3, replace=False) for _ in range(60_000)], dtype=np.int64)
    count: Counter[tuple[int, int]] = Counter()
    forward: Counter[tuple[int, int]] = Counter()
    for face in faces.tolist():
        for u, v in zip(face, face[1:] + face[:1], strict=True):
            edge = (min(u, v), max(u, v))
            count[edge] += 1
            forward[edge] += u < v
    blocks.set_block_threads(n_threads)
    topo = topology.surface_topology(faces, n_vertices)
    assert len(count) > 2 * topology.BLOCK  # several blocks of runs
    assert topo.open_edges == sum(1 for c in count.values() if c == 1)
    assert topo.nonmanifold_edges == sum(1 for c in count.values() if c > 2)
    assert topo.unbalanced_edges == sum(1 for e, c in count.items() if 2 * forward[e] != c)
    pairs = {e for e, c in count.items() if c == 2}
    assert len(topo.edge_faces) == len(pairs)
    assert int(np.count_nonzero(topo.edge_same_direction)) == sum(1 for e in pairs if forward[e] != 1)


def test_binary_stl_that_fails_to_read_is_refused_with_the_reason(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import errno

    from inertia.errors import UnreadableFileError
    from inertia.load import stl

    path, data = _stl_file(tmp_path)

    def failing(fd: int, n: int, at: int) -> bytes:
        raise OSError(errno.EIO, os.strerror(errno.EIO))

    monkeypatch.setattr(os, "pread", failing)
    with path.open("rb") as fh, pytest.raises(UnreadableFileError, match="could not be read: Input/output error"):
        stl.read_stl_file(fh, len(data))
