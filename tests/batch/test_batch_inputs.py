"""Inputs and failures of ``inertia batch`` that need no cluster: naming, listing, errors, imports."""

from __future__ import annotations

import io
import json
import multiprocessing
import os
import subprocess
import sys
import zipfile
from pathlib import Path
from typing import Any

import pytest
import trimesh

from inertia.batch import runner, workers
from inertia.batch.rows import Row
from inertia.batch.sources import Source, iter_inputs, iter_zip_bytes, list_sources, read_source
from inertia.batch.tasks import analyze_source, analyze_sources
from inertia.cli import main
from inertia.errors import UnreadableFileError
from inertia.pipeline import AnalysisOptions
from tests.batch.batchlib import N_FILES, box, cli_error, stl_bytes, without_timing

Library = tuple[Path, dict[str, "str | None"]]


def test_a_folder_lists_known_files_by_relative_path(library: Library) -> None:
    names = [s.name for s in list_sources([str(library[0])])]
    assert sorted(names) == sorted(library[1])
    assert len(names) == N_FILES


def test_a_file_given_by_itself_is_named_by_its_base_name(library: Library) -> None:
    (src,) = list_sources([str(library[0] / "b/c/part_02.stl")])
    assert src.name == "part_02.stl" and src.member is None and src.size == 84 + 12 * 50


def test_the_same_file_twice_is_one_input_and_clashing_names_stay_unique(library: Library, tmp_path: Path) -> None:
    other = tmp_path / "part_02.stl"
    other.write_bytes(stl_bytes(box((1.0, 1.0, 1.0), 0.0, (0.0, 0.0, 0.0))))
    first = str(library[0] / "b/c/part_02.stl")
    sources = list_sources([first, first, str(other)])
    assert [s.name for s in sources] == ["part_02.stl", str(other)]


def test_a_missing_path_fails_before_any_work(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["batch", str(tmp_path / "nope"), "--out", str(tmp_path / "o.jsonl"), "--no-progress"])
    assert code == 2
    err = cli_error(capsys.readouterr().err)
    assert err["code"] == "invalid_parameter" and "no such file or folder" in err["message"]


def test_an_unknown_output_extension_is_invalid_parameter(
    library: Library, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["batch", str(library[0]), "--out", str(tmp_path / "o.xlsx"), "--no-progress"])
    assert code == 2
    assert ".jsonl, .csv or .parquet" in cli_error(capsys.readouterr().err)["message"]


@pytest.mark.parametrize(
    ("module", "out", "more", "hint"),
    [
        ("distributed", "o.jsonl", ["--scheduler", "tcp://127.0.0.1:9"], "pip install 'inertia-service[batch]'"),
        ("pyarrow", "o.parquet", [], "pip install 'inertia-service[parquet]'"),
    ],
)
def test_a_missing_extra_says_what_to_install(
    module: str,
    out: str,
    more: list[str],
    hint: str,
    library: Library,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.setitem(sys.modules, module, None)  # import raises ImportError
    code = main(["batch", str(library[0]), "--out", str(tmp_path / out), "--no-progress", *more])
    assert code == 2
    err = cli_error(capsys.readouterr().err)
    assert err["code"] == "invalid_parameter" and hint in err["message"]


def test_the_local_pool_needs_no_dask(library: Library, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "distributed", None)  # import raises ImportError
    out = tmp_path / "o.jsonl"
    assert main(["batch", str(library[0]), "--out", str(out), "--no-progress", "--workers", "2"]) == 0
    assert len(out.read_text().splitlines()) == N_FILES


def test_importing_the_service_and_the_sources_imports_no_dask() -> None:
    code = (
        "import sys, inertia, inertia.cli, inertia.batch, inertia.batch.sources; "
        "bad = [m for m in ('dask', 'distributed', 'tqdm', 'pyarrow', 'fsspec') if m in sys.modules]; "
        "assert not bad, bad"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr


def test_iter_inputs_yields_names_and_bytes(library: Library) -> None:
    pairs = dict(iter_inputs([str(library[0])]))
    assert len(pairs) == N_FILES
    assert pairs["a/part_01.stl"] == (library[0] / "a/part_01.stl").read_bytes()


def test_iter_zip_bytes_skips_folders_and_unknown_members() -> None:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("x/box.stl", b"solid")
        zf.writestr("x/readme.md", b"hi")
        zf.writestr("__MACOSX/x/._box.stl", b"fork")
    assert [n for n, _ in iter_zip_bytes(buf.getvalue(), "up.zip")] == ["up.zip/x/box.stl"]
    with pytest.raises(UnreadableFileError):
        list(iter_zip_bytes(b"not a zip"))


def test_a_file_that_vanished_becomes_an_unreadable_row(tmp_path: Path) -> None:
    with pytest.raises(UnreadableFileError):
        read_source(Source("gone.stl", str(tmp_path / "gone.stl")))
    row = analyze_source(Source("gone.stl", str(tmp_path / "gone.stl")), AnalysisOptions())
    assert row["source"] == {"filename": "gone.stl"} and row["error"]["code"] == "unreadable_file"
    assert "readable here" in row["error"]["message"]  # where it was looked for: on a Dask worker, its own disk


def test_a_broken_zip_in_a_folder_is_one_error_row(tmp_path: Path) -> None:
    (tmp_path / "bad.zip").write_bytes(b"PK not really")
    (src,) = list_sources([str(tmp_path)])
    (row,) = analyze_sources([src], AnalysisOptions())
    assert row["error"]["code"] == "unreadable_file" and "zip" in row["error"]["message"]


def test_an_unexpected_exception_is_an_internal_error_row(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    path = tmp_path / "b.stl"
    path.write_bytes(stl_bytes(box((1.0, 1.0, 1.0), 0.0, (0.0, 0.0, 0.0))))

    def boom(*args: Any, **kwargs: Any) -> None:
        raise ZeroDivisionError("oops")

    monkeypatch.setattr("inertia.batch.tasks.analyze", boom)
    rows = analyze_sources([Source("b.stl", str(path)), Source("c.stl", str(path))], AnalysisOptions())
    assert [r["error"]["code"] for r in rows] == ["internal_error", "internal_error"]
    assert "ZeroDivisionError" in rows[0]["error"]["message"]


def test_groups_are_sized_by_bytes_largest_files_first() -> None:
    small = [Source(f"s{i}.stl", f"/s{i}", None, 1000) for i in range(1000)]
    groups = list(runner._groups(small, threads=2, min_bytes=runner.MIN_TASK_BYTES["pool"]))
    assert sorted(s.name for g in groups for s in g) == sorted(s.name for s in small)
    work = [sum(runner._cost(s) for s in g) for g in groups]
    assert len(groups) >= 2 * runner.TASKS_PER_THREAD - 1  # enough tasks to keep both workers busy to the end
    assert all(w >= runner.MIN_TASK_BYTES["pool"] for w in work[:-1])
    # a few files, a larger minimum per task: fewer, bigger tasks
    assert len(list(runner._groups(small, threads=2, min_bytes=runner.MIN_TASK_BYTES["dask"]))) < len(groups)
    mixed = [
        Source("big.stl", "/big", None, 3 * runner.MAX_TASK_BYTES),
        *small[:10],
        Source("mid.stl", "/mid", None, runner.MAX_TASK_BYTES),
    ]
    first, second, *rest = runner._groups(mixed, threads=2, min_bytes=runner.MIN_TASK_BYTES["pool"])
    assert [s.name for s in first] == ["big.stl"] and [s.name for s in second] == ["mid.stl"]
    assert [s.name for g in rest for s in g] == [s.name for s in small[:10]]  # equal sizes keep their order


def test_rendered_rows_are_the_sinks_own_lines(library: Library, tmp_path: Path) -> None:
    from inertia.batch.rows import ErrorRow
    from inertia.batch.sinks import open_sink, render
    from inertia.batch.tasks import analyze_rows, render_sources

    sources = list_sources([str(library[0])])[:6]
    for fmt in ("jsonl", "csv", "parquet"):
        if fmt == "parquet":
            pytest.importorskip("pyarrow")
        rows = analyze_rows(sources, AnalysisOptions())
        rendered = render_sources(sources, AnalysisOptions(), fmt)
        assert [e for _, e in rendered] == [isinstance(r, ErrorRow) for r in rows]
        a, b = tmp_path / f"a.{fmt}", tmp_path / f"b.{fmt}"
        sink_a, sink_b = open_sink(str(a), False), open_sink(str(b), False)
        for row, (text, _) in zip(rows, rendered, strict=True):
            sink_a.write(row)
            sink_b.write_rendered(text)
        sink_a.close()
        sink_b.close()
        if fmt != "parquet":  # the same text, but for the elapsed times
            assert len(a.read_text().splitlines()) == len(b.read_text().splitlines())
        assert render(rows[0], "jsonl").endswith("\n")


class _FailedFuture:
    def result(self) -> None:
        raise RuntimeError("KilledWorker: worker died")


def test_a_task_whose_worker_died_is_split_into_single_files() -> None:
    group = [Source("a.stl", "/a"), Source("b.stl", "/b")]
    again: list[list[Source]] = []
    assert runner._rows(_FailedFuture(), group, again.append) == []
    assert again == [[group[0]], [group[1]]]
    ((text, is_error),) = runner._rows(_FailedFuture(), [group[0]], again.append)
    row = json.loads(text)
    assert is_error and row["source"] == {"filename": "a.stl"} and row["error"]["code"] == "internal_error"
    assert "more memory" in row["error"]["message"]


class KilledWorker(Exception):
    """Named as distributed's: a task whose workers kept dying."""


class _KilledFuture:
    def result(self) -> Any:
        raise KilledWorker("attempted to run task 3 times, and all those workers died")


def test_a_file_that_keeps_killing_dask_workers_is_unreadable_as_on_the_pool() -> None:
    ((text, is_error),) = runner._rows(_KilledFuture(), [Source("a.stl", "/a")], lambda g: None)
    row = json.loads(text)
    assert is_error and row["error"]["code"] == "unreadable_file" and "its worker process died" in row["error"]["message"]


class _Rows:
    """A sink and progress bar that keep the JSON Lines rows written to them."""

    def __init__(self) -> None:
        self.rows: list[dict[str, Any]] = []

    def write(self, row: Row) -> None:
        self.rows.append(row.as_dict())

    def write_rendered(self, rendered: str) -> None:
        self.rows.append(json.loads(rendered))

    def update(self, n: int) -> None:
        pass

    def flush(self) -> None:
        pass

    def close(self) -> None:
        pass


class _Collect(runner._Output):
    """The run's real output, its rows kept in ``rows``."""

    def __init__(self) -> None:
        self._kept = _Rows()
        super().__init__(self._kept, self._kept, "jsonl")

    @property
    def rows(self) -> list[dict[str, Any]]:
        return self._kept.rows


def test_head_start_analyses_small_files_until_the_cluster_is_ready(library: Library) -> None:
    sources = list_sources([str(library[0])])
    big = Source("big.stl", "/not/read/big.stl", None, runner.HEAD_START_BYTES + 1)
    unsized = Source("remote.stl", "https://example.invalid/remote.stl", None, None)
    pending = [sources[0], big, unsized, *sources[1:]]
    answers = iter([False] * 5 + [True])
    out = _Collect()
    rest = runner._head_start(pending, lambda: next(answers), AnalysisOptions(), out)
    # five inputs looked at: three analysed here, the large and the unsized one left for the workers
    assert [r["source"]["filename"] for r in out.rows] == [s.name for s in (sources[0], *sources[1:3])]
    assert rest == [big, unsized, *sources[3:]]
    expected = analyze_sources([sources[0], *sources[1:3]], AnalysisOptions())
    assert [without_timing(r) for r in out.rows] == [without_timing(r) for r in expected]


def test_head_start_hands_everything_over_when_no_file_is_small_enough(library: Library, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(runner, "HEAD_START_BYTES", -1)
    sources = list_sources([str(library[0])])
    out = _Collect()
    assert runner._head_start(sources, lambda: False, AnalysisOptions(), out) == sources
    assert out.rows == []


class _FakeCluster:
    closed = False

    def close(self) -> None:
        self.closed = True


def test_an_interrupted_head_start_still_closes_the_cluster_it_started(library: Library, monkeypatch: pytest.MonkeyPatch) -> None:
    cluster = _FakeCluster()

    def slow_start(workers: int | None) -> _FakeCluster:
        import time

        time.sleep(0.2)  # the interrupt comes while the cluster is still starting
        return cluster

    def interrupted(*args: Any) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(runner, "local_cluster", slow_start)
    monkeypatch.setattr(runner, "render_sources", interrupted)
    before = sys.getswitchinterval()
    with pytest.raises(KeyboardInterrupt):
        runner._run_local(list_sources([str(library[0])]), 2, AnalysisOptions(), _Collect())
    assert cluster.closed
    assert sys.getswitchinterval() == before  # the head start's shorter interval does not outlive it


FORKSERVER_ENV = """
import gc, json, multiprocessing, os
from inertia.batch import workers
workers.start_forkserver()
with multiprocessing.get_context("forkserver").Pool(1) as pool:
    seen = pool.map(os.getenv, workers.WORKER_THREAD_LIMITS)
    frozen = pool.apply(gc.get_freeze_count)
print(json.dumps([seen, [os.getenv(k) for k in workers.WORKER_THREAD_LIMITS], frozen]))
"""


@pytest.mark.skipif("forkserver" not in multiprocessing.get_all_start_methods(), reason="no forkserver")
def test_local_workers_fork_from_a_frozen_server_with_one_thread_per_numeric_library() -> None:
    env = {k: v for k, v in os.environ.items() if k not in workers.WORKER_THREAD_LIMITS}
    env["OMP_NUM_THREADS"] = "3"  # a value the user set wins
    done = subprocess.run([sys.executable, "-c", FORKSERVER_ENV], env=env, capture_output=True, text=True, check=True, timeout=60)
    in_forkserver, in_client, frozen = json.loads(done.stdout)
    assert in_forkserver == ["3", "1", "1"]
    assert in_client == ["3", None, None]  # this process's environment is left as it was
    assert frozen > 10_000  # Dask's and the pipeline's objects, frozen before the fork


BATCH_COMMAND_ENV = """
import json, os, sys
from inertia.batch import workers
from inertia.cli import main
code = main(["batch", sys.argv[1], "--out", sys.argv[2], "--workers", "1", "--no-progress"])
print(json.dumps([code, "numpy" in sys.modules, [os.getenv(k) for k in workers.WORKER_THREAD_LIMITS]]))
"""


def test_the_batch_command_runs_its_own_numeric_libraries_on_one_thread(tmp_path: Path) -> None:
    """The command computes nothing; numpy's OpenBLAS would start (and spin) a thread per core in it."""
    stl = tmp_path / "box.stl"
    stl.write_bytes(stl_bytes(box((1.0, 2.0, 3.0), 0.3, (0.0, 0.0, 0.0))))
    env = {k: v for k, v in os.environ.items() if k not in workers.WORKER_THREAD_LIMITS}
    env["MKL_NUM_THREADS"] = "4"  # a value the user set wins
    done = subprocess.run(
        [sys.executable, "-c", BATCH_COMMAND_ENV, str(stl), str(tmp_path / "out.jsonl")],
        env=env,
        capture_output=True,
        text=True,
        check=True,
        timeout=60,
    )
    code, numpy_loaded, limits = json.loads(done.stdout.splitlines()[-1])
    assert code == 0 and numpy_loaded  # numpy was imported after the limits were set
    assert limits == ["1", "4", "1"]


def test_a_gltf_in_a_folder_is_read_with_its_buffers_beside_it(tmp_path: Path) -> None:
    files = trimesh.creation.box(extents=(1.0, 2.0, 3.0)).export(file_type="gltf")
    for name, content in files.items():
        (tmp_path / ("box.gltf" if name == "model.gltf" else name)).write_bytes(content)
    (src,) = list_sources([str(tmp_path)])  # the .bin files are companions, not inputs
    (row,) = analyze_sources([src], AnalysisOptions())
    assert row["source"]["filename"] == "box.gltf", json.dumps(row)[:300]
    assert row["mass"] == pytest.approx(row["density"] * 6.0, rel=1e-14)
