"""The CLI as a user runs it, and what each job imports."""

from __future__ import annotations

import gc
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.support.paths import ROOT, SAMPLES


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "inertia", *args], capture_output=True, text=True, cwd=ROOT)


def test_analyze_prints_a_table() -> None:
    out = run("analyze", str(SAMPLES / "l_bracket.stl"))
    assert out.returncode == 0, out.stderr
    assert "asymmetric_top" in out.stdout
    assert "9000" in out.stdout and "25000" in out.stdout


def test_analyze_json_matches_closed_form_box() -> None:
    out = run("analyze", str(SAMPLES / "box.stl"), "--json", "--density", "2", "--reference", "0,0,0")
    doc = json.loads(out.stdout)
    assert doc["mass"] == pytest.approx(12.0, rel=1e-15)
    assert doc["principal"]["moments"] == pytest.approx([5.0, 10.0, 13.0], rel=1e-14)
    assert doc["reference_inertia"]["tensor"][0][0] == pytest.approx(12.0 * (4 + 9) / 3, rel=1e-14)
    assert "precession" not in doc and "parts" not in doc


def test_errors_go_to_stderr_in_the_envelope_with_exit_code() -> None:
    out = run("analyze", str(SAMPLES / "open_box.stl"), "--json")
    assert out.returncode == 4
    assert out.stdout == ""
    err = json.loads(out.stderr)
    assert err["error"]["code"] == "not_watertight"
    assert err["error"]["details"]["open_edges"] == 4


def test_bad_parameter_exit_code() -> None:
    out = run("analyze", str(SAMPLES / "box.stl"), "--density", "-3", "--json")
    assert out.returncode == 2
    assert json.loads(out.stderr)["error"]["code"] == "invalid_parameter"
    table = run("analyze", str(SAMPLES / "box.stl"), "--density", "-3")
    assert table.returncode == 2
    assert table.stderr.startswith("error: ") and table.stderr.rstrip().endswith("(invalid_parameter)")


def test_inverted_box_warns_on_the_table() -> None:
    out = run("analyze", str(SAMPLES / "inverted_box.stl"))
    assert out.returncode == 0 and "inverted winding corrected" in out.stdout


def imported_after(code: str) -> set[str]:
    probe = code + "\nimport sys, json; print(json.dumps(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, cwd=ROOT, check=True)
    return set(json.loads(out.stdout.strip().splitlines()[-1]))


def test_mesh_analysis_imports_no_web_stack_or_ode_solver() -> None:
    mods = imported_after(f"import inertia; inertia.analyze({str(SAMPLES / 'box.stl')!r})")
    assert not {"fastapi", "uvicorn", "scipy.integrate", "pydantic", "dask"} & mods


def test_point_analysis_imports_no_mesh_library() -> None:
    mods = imported_after(
        "import inertia; inertia.analyze_points([{'mass': 1, 'position': [0, 0, 0]}, {'mass': 2, 'position': [1, 1, 0]}])"
    )
    assert not {"trimesh", "meshio", "fastapi", "scipy.integrate"} & mods


def test_cli_mesh_job_imports_no_web_stack() -> None:
    mods = imported_after(f"from inertia.cli import main; main(['analyze', {str(SAMPLES / 'box.stl')!r}, '--json'])")
    assert not {"fastapi", "uvicorn", "scipy.integrate"} & mods


def test_the_cli_and_the_batch_forkserver_start_without_numpy_or_dask() -> None:
    # inertia batch starts its workers' forkserver before it imports either, so the
    # forkserver's imports run beside the command's own
    mods = imported_after("import inertia, inertia.cli, inertia.batch.workers")
    assert not {"numpy", "dask", "distributed"} & mods


def test_result_holds_only_requested_sections() -> None:
    from inertia import analyze

    doc = analyze(SAMPLES / "box.stl").as_dict()
    assert not {"reference_inertia", "precession", "parts"} & set(doc)


def test_the_command_runs_blas_on_one_thread_unless_the_user_chose(monkeypatch: pytest.MonkeyPatch) -> None:
    from inertia import cli

    seen: list[list[str | None]] = []

    def fake_main(isolate: bool = False) -> int:
        assert isolate  # the command's own process: its analysis may fork
        seen.append([os.environ.get(k) for k in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS")])
        return 0

    monkeypatch.setattr(cli, "main", fake_main)
    monkeypatch.setattr(gc, "freeze", lambda: None)  # console_main ends a process; this one goes on
    for key in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
        monkeypatch.delenv(key, raising=False)
    cli.console_main()
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "4")
    cli.console_main()
    # OMP_NUM_THREADS stays unset: the block threads of a large mesh read it
    assert seen == [["1", "1", None], ["4", "1", None]]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="counts the threads in /proc")
def test_numpy_imported_after_the_setting_starts_no_blas_threads() -> None:
    script = (
        "import os\nfrom inertia.cli import one_blas_thread\none_blas_thread()\nimport numpy\n"
        "numpy.ones((300, 300)) @ numpy.ones((300, 300))\nprint(len(os.listdir('/proc/self/task')))"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS")}
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, env=env, check=True)
    assert out.stdout.split() == ["1"]


def test_the_contracts_names_work_outside_the_checkout(tmp_path: Path) -> None:
    # API.md: "The ASGI application is `service.app:app` ... (also `python -m service serve ...`)"; from a folder
    # other than the checkout's root only the installed distribution can answer to these names
    probe = "import inertia.app, service.app; print(service.app.app is inertia.app.app, service.__file__)"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, cwd=tmp_path, check=True)
    same, where = out.stdout.split()
    assert same == "True" and not Path(where).is_relative_to(tmp_path)
    box = str(SAMPLES / "box.stl")
    cli = subprocess.run([sys.executable, "-m", "service", "analyze", box, "--json"], capture_output=True, text=True, cwd=tmp_path)
    assert cli.returncode == 0, cli.stderr
    got, expected = json.loads(cli.stdout), json.loads(run("analyze", box, "--json").stdout)
    for doc in (got, expected):
        del doc["diagnostics"]["elapsed_s"]
    assert got == expected
