"""``inertia batch`` end to end on real Dask clusters: rows, identity with ``analyze``, resume, formats."""

from __future__ import annotations

import csv
import json
import math
import shutil
import zipfile
from pathlib import Path
from typing import Any

import pytest

from inertia.batch.rows import COLUMNS, FLOAT_COLUMNS
from inertia.cli import main
from inertia.errors import ServiceError
from inertia.pipeline import AnalysisOptions, analyze
from tests.batch.batchlib import BROKEN, N_FILES, box, by_name, cli_error, read_jsonl, stl_bytes, without_timing

Library = tuple[Path, dict[str, "str | None"]]


def batch(*args: str) -> int:
    return main(["batch", *args, "--no-progress"])


def reference(path: Path, name: str, options: AnalysisOptions = AnalysisOptions()) -> dict[str, Any]:
    """What the single-file path gives for one input, as a JSON line."""
    try:
        doc = analyze(path.read_bytes(), filename=name, options=options).as_dict()
    except ServiceError as exc:
        doc = {"source": {"filename": name}, **exc.as_dict()}
    return without_timing(doc)


@pytest.fixture(scope="module")
def local_rows(library: Library, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The library through the default engine: a pool of 2 local worker processes."""
    out = tmp_path_factory.mktemp("local") / "rows.jsonl"
    assert batch(str(library[0]), "--out", str(out), "--workers", "2") == 0
    return out


@pytest.fixture(scope="module")
def worker_rows(library: Library, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The same through a Dask LocalCluster (``engine="dask"``) with no head start: every file on a Dask worker."""
    pytest.importorskip("distributed")
    from inertia.batch import runner

    out = tmp_path_factory.mktemp("workers") / "rows.jsonl"
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(runner, "HEAD_START_BYTES", -1)
        runner.run_batch([str(library[0])], str(out), workers=2, engine="dask", progress=False)
    return out


def test_fifty_files_give_fifty_rows_three_of_them_errors(local_rows: Path, library: Library) -> None:
    rows = by_name(read_jsonl(local_rows))
    assert len(rows) == N_FILES
    assert set(rows) == set(library[1])  # hidden files, notes.txt and ._ forks are not inputs
    errors = {name: row["error"]["code"] for name, row in rows.items() if "error" in row}
    assert errors == BROKEN


def test_every_row_equals_the_single_file_analysis(local_rows: Path, library: Library) -> None:
    root = library[0]
    for name, row in by_name(read_jsonl(local_rows)).items():
        assert row == reference(root / name, name), name  # exact: floats survive JSON bit for bit


def test_a_dask_local_cluster_gives_the_rows_of_the_pool(worker_rows: Path, local_rows: Path, library: Library) -> None:
    rows = by_name(read_jsonl(worker_rows))
    assert set(rows) == set(library[1])
    assert rows == by_name(read_jsonl(local_rows))
    for name, row in rows.items():
        assert row == reference(library[0] / name, name), name


def test_numbers_equal_analyze_of_the_path(local_rows: Path, library: Library) -> None:
    # ``inertia analyze FILE`` reads the path and names it by its base name
    row = by_name(read_jsonl(local_rows))["b/c/part_02.stl"]
    doc = without_timing(analyze(library[0] / "b/c/part_02.stl").as_dict())
    doc["source"]["filename"] = row["source"]["filename"]
    assert row == doc


def test_existing_cluster_gives_the_same_rows(local_rows: Path, library: Library, cluster: Any, tmp_path: Path) -> None:
    out = tmp_path / "rows.jsonl"
    assert batch(str(library[0]), "--out", str(out), "--scheduler", cluster.scheduler_address) == 0
    assert by_name(read_jsonl(out)) == by_name(read_jsonl(local_rows))


def test_resume_skips_rows_already_written(
    fresh_library: Path, cluster: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "rows.jsonl"
    address = cluster.scheduler_address
    assert batch(str(fresh_library), "--out", str(out), "--scheduler", address) == 0
    lines = out.read_text().splitlines(keepends=True)
    kept, dropped = lines[:-5], lines[-5:]
    out.write_text("".join(kept))
    # change a kept file: were it analysed again, its row would change
    kept_name = json.loads(kept[0])["source"]["filename"]
    (fresh_library / kept_name).write_bytes(stl_bytes(box((9.0, 9.0, 9.0), 0.0, (0.0, 0.0, 0.0))))
    capsys.readouterr()

    assert batch(str(fresh_library), "--out", str(out), "--scheduler", address, "--resume") == 0

    assert "5 files analysed" in capsys.readouterr().err
    after = out.read_text().splitlines(keepends=True)
    assert after[: len(kept)] == kept  # untouched, byte for byte
    assert by_name([json.loads(x) for x in after[len(kept) :]]) == by_name([json.loads(x) for x in dropped])
    assert len(by_name([json.loads(x) for x in after])) == N_FILES


def test_resume_of_a_complete_output_submits_nothing(
    local_rows: Path, library: Library, cluster: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "rows.jsonl"
    shutil.copy(local_rows, out)
    capsys.readouterr()
    assert batch(str(library[0]), "--out", str(out), "--scheduler", cluster.scheduler_address, "--resume") == 0
    assert "0 files analysed (0 errors), 50 skipped" in capsys.readouterr().err
    assert out.read_bytes() == local_rows.read_bytes()


def test_resume_drops_a_line_cut_short_and_redoes_its_file(
    local_rows: Path, library: Library, cluster: Any, tmp_path: Path
) -> None:
    out = tmp_path / "rows.jsonl"
    text = local_rows.read_text()
    out.write_text(text[: len(text) - 200])  # a crash in the middle of the last line
    assert batch(str(library[0]), "--out", str(out), "--scheduler", cluster.scheduler_address, "--resume") == 0
    assert by_name(read_jsonl(out)) == by_name(read_jsonl(local_rows))


def _csv(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as fh:
        reader = csv.DictReader(fh)
        assert tuple(reader.fieldnames or ()) == COLUMNS
        return list(reader)


def _flat(row: dict[str, Any]) -> dict[str, Any]:
    """The columns of a JSON line, read off it here (the module's docstring is the specification)."""
    if "error" in row:
        error = f"{row['error']['code']}: {row['error']['message']}"
        return {**dict.fromkeys(COLUMNS), "name": row["source"]["filename"], "error": error}
    principal, cls, tensor = row["principal"], row["classification"], row["inertia_tensor"]
    values = [row["source"]["filename"], row["source"]["format"], row["mass"], row.get("volume"), *row["center_of_mass"]]
    values += [tensor[0][0], tensor[1][1], tensor[2][2], tensor[0][1], tensor[0][2], tensor[1][2], *principal["moments"]]
    values += [x for axis in principal["axes"] for x in axis] + principal["quaternion"]
    values += [cls["kind"], cls.get("asymmetry"), "; ".join(row["warnings"]), ""]
    return dict(zip(COLUMNS, values, strict=True))


def _same_flat(got: dict[str, Any], row: dict[str, Any]) -> None:
    want = _flat(row)
    for column in COLUMNS:
        value = got[column]
        if column in FLOAT_COLUMNS and value not in ("", None):
            assert float(value) == want[column], column  # repr() in CSV reads back exactly
        else:
            assert (value if value != "" else None) == (want[column] if want[column] != "" else None), column


def test_csv_rows_flatten_the_json_lines(local_rows: Path, library: Library, cluster: Any, tmp_path: Path) -> None:
    out = tmp_path / "rows.csv"
    assert batch(str(library[0]), "--out", str(out), "--scheduler", cluster.scheduler_address) == 0
    rows = by_name(read_jsonl(local_rows))
    got = _csv(out)
    assert len(got) == N_FILES
    for flat in got:
        _same_flat(flat, rows[flat["name"]])
    errors = {r["name"]: r["error"].split(":")[0] for r in got if r["error"]}
    assert errors == BROKEN
    box_row = next(r for r in got if r["name"] == "a/part_01.stl")
    assert box_row["class"] == "asymmetric_top" and math.isfinite(float(box_row["kappa"]))


def test_csv_resume_appends_the_missing_rows(local_rows: Path, library: Library, cluster: Any, tmp_path: Path) -> None:
    out = tmp_path / "rows.csv"
    address = cluster.scheduler_address
    assert batch(str(library[0]), "--out", str(out), "--scheduler", address) == 0
    lines = out.read_text().splitlines(keepends=True)
    out.write_text("".join(lines[:-7]) + lines[-7][:20])  # header + 42 rows + a cut row
    assert batch(str(library[0]), "--out", str(out), "--scheduler", address, "--resume") == 0
    got = _csv(out)
    assert sorted(r["name"] for r in got) == sorted(by_name(read_jsonl(local_rows)))


def test_parquet_holds_the_same_rows_and_resumes(local_rows: Path, library: Library, cluster: Any, tmp_path: Path) -> None:
    pq = pytest.importorskip("pyarrow.parquet")
    out = tmp_path / "rows.parquet"
    address = cluster.scheduler_address
    assert batch(str(library[0]), "--out", str(out), "--scheduler", address) == 0
    table = pq.read_table(out)
    assert tuple(table.schema.names) == COLUMNS
    rows = by_name(read_jsonl(local_rows))
    for flat in table.to_pylist():
        _same_flat(flat, rows[flat["name"]])
    pq.write_table(table.slice(0, 30), out)
    assert batch(str(library[0]), "--out", str(out), "--scheduler", address, "--resume") == 0
    again = pq.read_table(out)
    assert again.num_rows == N_FILES
    assert again.slice(0, 30).equals(table.slice(0, 30))
    assert not (tmp_path / "rows.parquet.partial").exists()


def test_zip_members_are_named_archive_slash_member(local_rows: Path, library: Library, cluster: Any, tmp_path: Path) -> None:
    archive = tmp_path / "parts.zip"
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as zf:
        for name in library[1]:
            zf.write(library[0] / name, name)
    out = tmp_path / "rows.jsonl"
    assert batch(str(archive), "--out", str(out), "--scheduler", cluster.scheduler_address) == 0
    want = by_name(read_jsonl(local_rows))
    got = by_name(read_jsonl(out))
    assert set(got) == {f"parts.zip/{name}" for name in want}
    for name, row in want.items():
        row["source"]["filename"] = f"parts.zip/{name}"
        assert got[f"parts.zip/{name}"] == row


def test_workers_read_fsspec_urls(local_rows: Path, library: Library, cluster: Any, tmp_path: Path) -> None:
    out = tmp_path / "rows.jsonl"
    url = library[0].as_uri()  # file:///...: a URL the workers can reach
    assert batch(url, "--out", str(out), "--scheduler", cluster.scheduler_address) == 0
    assert by_name(read_jsonl(out)) == by_name(read_jsonl(local_rows))


def test_options_pass_through_unchanged(library: Library, cluster: Any, tmp_path: Path) -> None:
    out = tmp_path / "rows.jsonl"
    densities = tmp_path / "densities.json"
    densities.write_text(json.dumps({"part_00": 2700.0}))
    names = ["part_00.stl", "a/part_01.stl", "objs/part_03.obj"]
    paths = [str(library[0] / n) for n in names]
    args = ["--units", "mm", "--density", "7850", "--reference", "1,2,3", "--tolerance", "1e-9", "--densities", str(densities)]
    assert batch(*paths, "--out", str(out), "--scheduler", cluster.scheduler_address, *args) == 0
    options = AnalysisOptions(units="mm", density=7850.0, reference=(1.0, 2.0, 3.0), tolerance=1e-9, densities={"part_00": 2700.0})
    rows = by_name(read_jsonl(out))
    for path, name in zip(paths, names):
        base = name.rsplit("/", 1)[-1]  # a file given by itself is named by its base name
        assert rows[base] == reference(Path(path), base, options)
    assert "reference_inertia" in rows["part_00.stl"]
    # the other files have no part named part_00: --densities naming it is their error, as in analyze
    assert rows["part_01.stl"]["error"]["details"]["parameter"] == "densities"


def test_progress_bar_shows_rate_on_stderr(
    library: Library, cluster: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "rows.jsonl"
    code = main(["batch", str(library[0] / "a"), "--out", str(out), "--scheduler", cluster.scheduler_address])
    assert code == 0
    captured = capsys.readouterr()
    assert captured.out == ""
    assert "file/s" in captured.err and "100%" in captured.err


class _CountingClient:
    """A real client that records how many tasks are in flight at once.

    In flight at a submission: the futures submitted before it that are not done.  (A done-callback counter
    lags: distributed runs callbacks on its own loop, possibly after ``as_completed`` has handed the future
    back and the runner has submitted the next one, so under load it over-counted.)
    """

    def __init__(self, client: Any) -> None:
        self._client = client
        self._futures: list[Any] = []
        self.most = 0

    @property
    def submitted(self) -> int:
        return len(self._futures)

    def nthreads(self) -> dict[str, int]:
        return dict(self._client.nthreads())

    def submit(self, *args: Any, **kwargs: Any) -> Any:
        in_flight = sum(1 for f in self._futures if not f.done())
        future = self._client.submit(*args, **kwargs)
        self._futures.append(future)
        self.most = max(self.most, in_flight + 1)
        return future


def test_tasks_in_flight_stay_within_the_window(
    library: Library, cluster: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from distributed import Client

    from inertia.batch import runner

    monkeypatch.setattr(runner, "MAX_TASK_BYTES", 1)  # one file per task: 50 tasks through a window of 2 x 2
    monkeypatch.setattr(runner, "WINDOW_PER_THREAD", 2)
    with Client(cluster) as client:
        counting = _CountingClient(client)
        summary = runner.run_batch([str(library[0])], str(tmp_path / "rows.jsonl"), client=counting, progress=False)
    assert summary.analysed == N_FILES and summary.errors == len(BROKEN)
    assert counting.submitted == N_FILES
    assert counting.most <= 2 * 2


def test_workers_and_scheduler_together_are_refused(library: Library, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = batch(str(library[0]), "--out", str(tmp_path / "o.jsonl"), "--workers", "2", "--scheduler", "tcp://x:1")
    assert code == 2
    assert "not both" in cli_error(capsys.readouterr().err)["message"]


def test_a_file_that_kills_its_worker_is_one_error_row_and_the_rest_complete(library: Library, tmp_path: Path) -> None:
    from inertia.batch import runner
    from inertia.batch.pool import run_pool
    from inertia.batch.sources import list_sources
    from tests.batch.batchlib import crashing_task

    folder = tmp_path / "lib"
    shutil.copytree(library[0], folder)
    (folder / "crash_me.stl").write_bytes(stl_bytes(box((1.0, 1.0, 1.0), 0.0, (0.0, 0.0, 0.0))))
    sources = list_sources([str(folder)])
    written: list[tuple[str, bool]] = []
    groups = runner._groups(sources, 2, 0)
    run_pool(groups, 2, 4, AnalysisOptions(), "jsonl", written.extend, task=crashing_task)
    rows = by_name([json.loads(text) for text, _ in written])
    assert set(rows) == set(library[1]) | {"crash_me.stl"}  # every file once, none lost with the pool
    assert rows["crash_me.stl"]["error"]["code"] == "unreadable_file"  # as the HTTP service answers it
    assert "its worker process died" in rows["crash_me.stl"]["error"]["message"]
    errors = {name: row["error"]["code"] for name, row in rows.items() if "error" in row}
    assert errors == {**BROKEN, "crash_me.stl": "unreadable_file"}
    for name in library[1]:
        assert rows[name] == reference(folder / name, name), name


def test_the_pool_writes_each_task_as_it_finishes_within_the_window(
    library: Library, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from inertia.batch import pool, runner

    seen: list[int] = []
    real = pool.run_pool

    def spy(groups: Any, workers: int, window: int, *args: Any, **kwargs: Any) -> None:
        seen.extend([workers, window])
        groups = list(groups)
        seen.append(len(groups))
        real(iter(groups), workers, window, *args, **kwargs)

    monkeypatch.setattr(runner, "run_pool", spy)
    monkeypatch.setattr(runner, "MAX_TASK_BYTES", 1)
    out = tmp_path / "rows.jsonl"
    summary = runner.run_batch([str(library[0])], str(out), workers=2, progress=False)
    assert seen == [2, 2 * runner.WINDOW_PER_THREAD, N_FILES]  # one file per task here
    assert summary.analysed == N_FILES and summary.errors == len(BROKEN)
    assert len(read_jsonl(out)) == N_FILES
