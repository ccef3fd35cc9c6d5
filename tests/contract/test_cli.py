"""The command line: inertia analyze|batch|serve."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from benchmarks.harness import Server
from tests.contract.helpers import ROOT, SAMPLES, analyze, strip_elapsed, two_cube_obj


def run_cli(*args: str, cwd: Path = SAMPLES) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("INERTIA_")}
    return subprocess.run([sys.executable, "-m", "inertia", *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=60)


def test_cli_json_equals_the_http_response(client: TestClient) -> None:
    opts = {
        "units": "mm",
        "density": "7850",
        "reference": "0,0,0",
        "omega": "0.1,2,0.1",
        "duration": "1",
        "samples": "3",
        "tolerance": "1e-8",
    }
    args = ["analyze", "box.stl", "--json"]
    for k, v in opts.items():
        args += [f"--{k}", v]
    p = run_cli(*args)
    assert p.returncode == 0, p.stderr
    cli = json.loads(p.stdout)
    http = analyze(client, "box.stl", None, **opts)
    assert strip_elapsed(cli) == strip_elapsed(http)


def test_cli_table_output_is_readable(client: TestClient) -> None:
    p = run_cli("analyze", "l_bracket.stl")
    assert p.returncode == 0, p.stderr
    out = p.stdout
    assert out.strip()
    with pytest.raises(json.JSONDecodeError):
        json.loads(out)
    assert "12000" in out.replace(",", "").replace(" ", "") or "1.2e+04" in out
    assert "asymmetric" in out


def test_cli_errors_go_to_stderr_with_non_zero_exit() -> None:
    p = run_cli("analyze", "open_box.stl", "--json")
    assert p.returncode != 0
    assert not p.stdout.strip()
    try:
        env = json.loads(p.stderr)
    except json.JSONDecodeError:
        env = json.loads(next(x for x in reversed(p.stderr.splitlines()) if x.startswith("{")))
    assert env["error"]["code"] == "not_watertight" and env["error"]["message"]
    p = run_cli("analyze", "box.stl", "--units", "parsec")
    assert p.returncode != 0 and "invalid_parameter" in p.stderr


def test_cli_batch_writes_one_line_per_file_and_resumes(tmp_path: Path) -> None:
    folder = tmp_path / "in"
    (folder / "sub").mkdir(parents=True)
    (folder / "box.stl").write_bytes((SAMPLES / "box.stl").read_bytes())
    (folder / "sub" / "open_box.stl").write_bytes((SAMPLES / "open_box.stl").read_bytes())
    (folder / "notes.txt").write_text("not a mesh: files of unknown extensions are not read")
    out = tmp_path / "results.jsonl"
    p = run_cli("batch", str(folder), "--out", str(out), cwd=tmp_path)
    assert p.returncode in (0, 1, 2, 3, 4), p.stderr
    lines = [json.loads(x) for x in out.read_text().splitlines() if x.strip()]
    assert len(lines) == 2
    by_name = {Path(line["source"]["filename"]).name: line for line in lines}
    assert by_name["box.stl"]["mass"] == pytest.approx(6000, rel=1e-14, abs=0)
    assert by_name["open_box.stl"]["error"]["code"] == "not_watertight"
    (folder / "tetrahedron.stl").write_bytes((SAMPLES / "tetrahedron.stl").read_bytes())
    p = run_cli("batch", str(folder), "--out", str(out), "--resume", cwd=tmp_path)
    lines = [json.loads(x) for x in out.read_text().splitlines() if x.strip()]
    assert len(lines) == 3, "resume analyses only the new file, error lines included as done"
    names = [Path(line["source"]["filename"]).name for line in lines]
    assert sorted(names) == ["box.stl", "open_box.stl", "tetrahedron.stl"]


def test_inertia_console_script_runs_analyze() -> None:
    import shutil

    exe = shutil.which("inertia", path=str(Path(sys.executable).parent)) or shutil.which("inertia")
    assert exe, "the `inertia` command must be installed"
    p = subprocess.run([exe, "analyze", "tetrahedron.stl", "--json"], cwd=SAMPLES, capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    res = json.loads(p.stdout)
    assert res["mass"] == pytest.approx(1000 / 6, rel=1e-14, abs=0)
    assert res["classification"]["kind"] == "symmetric_top"


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_cli_batch_tabular_outputs_have_one_row_per_file(tmp_path: Path, suffix: str) -> None:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for name in ("box.stl", "open_box.stl", "l_bracket.stl"):
            z.writestr(name, (SAMPLES / name).read_bytes())
    (tmp_path / "m.zip").write_bytes(buf.getvalue())
    out = tmp_path / f"results{suffix}"
    p = run_cli("batch", "m.zip", "--out", str(out), "--workers", "2", cwd=tmp_path)
    assert out.exists(), p.stderr
    if suffix == ".csv":
        import csv

        with out.open(newline="") as fh:
            rows = list(csv.DictReader(fh))
    else:
        import pyarrow.parquet as pq

        rows = pq.read_table(out).to_pylist()
    assert len(rows) == 3
    text = json.dumps(rows, default=str)
    assert "not_watertight" in text
    assert "6000" in text and "12000" in text


def test_inertia_serve_starts_the_http_service(tmp_path: Path) -> None:
    import httpx

    with Server({"INERTIA_COMPUTE_PROCESSES": "1"}, cwd=tmp_path) as server:  # ready once /healthz answers 200
        r = httpx.get(f"{server.url}/healthz", timeout=1)
        assert r.json() == {"status": "ok"}
        r = httpx.post(f"{server.url}/v1/analyze/mesh", files={"file": ("box.stl", (SAMPLES / "box.stl").read_bytes())}, timeout=30)
        assert r.status_code == 200 and r.json()["mass"] == pytest.approx(6000, rel=1e-14, abs=0)


@pytest.mark.filterwarnings("ignore:Port 8787 is already in use")  # a dashboard elsewhere on this machine
# the in-process LocalCluster (distributed's code, not ours: the CLI runs in a subprocess) leaves a
# listening socket to the garbage collector, which warnings-as-errors turns into a failure
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning", "ignore:unclosed:ResourceWarning")
def test_cli_batch_runs_on_an_existing_dask_cluster(tmp_path: Path) -> None:
    from distributed import LocalCluster

    folder = tmp_path / "in"
    folder.mkdir()
    for name in ("box.stl", "open_box.stl", "tetrahedron.stl"):
        (folder / name).write_bytes((SAMPLES / name).read_bytes())
    out = tmp_path / "dask.jsonl"
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None, protocol="tcp://", host="127.0.0.1"
    ) as cluster:
        p = run_cli("batch", str(folder), "--out", str(out), "--scheduler", cluster.scheduler_address, cwd=tmp_path)
    assert out.exists(), p.stderr
    lines = {Path(x["source"]["filename"]).name: x for x in map(json.loads, out.read_text().splitlines())}
    assert set(lines) == {"box.stl", "open_box.stl", "tetrahedron.stl"}
    assert lines["open_box.stl"]["error"]["code"] == "not_watertight"
    assert lines["tetrahedron.stl"]["mass"] == pytest.approx(1000 / 6, rel=1e-14, abs=0)


def test_cli_batch_reads_xyz_files_from_a_folder(tmp_path: Path) -> None:
    folder = tmp_path / "molecules"
    folder.mkdir()
    (folder / "co2.xyz").write_text("3\ncarbon dioxide\nO 0 0 -1.162\nC 0 0 0\nO 0 0 1.162\n")
    out = tmp_path / "out.jsonl"
    run = subprocess.run(
        [sys.executable, "-m", "inertia", "batch", str(folder), "--out", str(out), "--workers", "1", "--no-progress"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    (line,) = [json.loads(x) for x in out.read_text().splitlines()]
    assert line["classification"]["kind"] == "linear_rotator"
    assert len(line["rotational_constants"]["MHz"]) == 1


def test_cli_densities_take_the_json_object_inline_as_the_api_does(client: TestClient, tmp_path: Path) -> None:
    # the API's `densities` is a JSON object; `--densities` takes that object, or a file holding it
    (tmp_path / "pair.obj").write_bytes(two_cube_obj())
    densities = json.dumps({"right": 500})
    p = run_cli("analyze", "pair.obj", "--json", "--densities", densities, cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    http = analyze(client, "pair.obj", two_cube_obj(), densities=densities)
    assert strip_elapsed(json.loads(p.stdout)) == strip_elapsed(http)
    masses = {part["name"]: part["mass"] for part in http["parts"]}
    assert masses == {"left": pytest.approx(1000.0, rel=1e-13, abs=0), "right": pytest.approx(500.0, rel=1e-13, abs=0)}
