"""The benchmarks' harness (``benchmarks.harness``): what its figures mean is what they measure."""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import pytest

from benchmarks import harness, timeline


def test_best_of_keeps_the_fastest_run_and_its_result() -> None:
    waits = iter([0.2, 0.0, 0.1])
    calls: list[float] = []

    def call() -> float:
        wait = next(waits)
        clock = harness.Stopwatch()
        while clock.wall_s < wait:
            pass
        calls.append(wait)
        return wait

    result, timing = harness.best_of(call, repeat=3)
    assert calls == [0.2, 0.0, 0.1] and result == 0.0
    assert timing.wall_s < 0.1 and timing.peak_rss_bytes > 0  # the others waited at least 0.1 s


def test_best_of_stops_once_its_budget_is_spent() -> None:
    calls: list[int] = []
    harness.best_of(lambda: calls.append(1), repeat=10, budget_s=-1.0)
    assert calls == [1]


def test_timed_counts_cpu_time_of_busy_work() -> None:
    def spin() -> None:
        clock = harness.Stopwatch()
        while clock.wall_s < 0.05:
            pass

    _, timing = harness.timed(spin)
    assert timing.wall_s >= 0.05 and timing.cpu_s > 0


def test_interleaved_rotates_the_order_and_keeps_each_contenders_best() -> None:
    order: list[str] = []
    walls = {"a": iter([3.0, 1.0, 2.0]), "b": iter([5.0, 6.0, 4.0])}

    def run(name: str) -> float:
        order.append(name)
        return next(walls[name])

    rounds: list[int] = []
    out = harness.interleaved(
        [("a", lambda: run("a")), ("b", lambda: run("b"))],
        3,
        lambda _name, wall: wall,
        before_round=rounds.append,
    )
    assert order == ["a", "b", "b", "a", "a", "b"] and rounds == [0, 1, 2]
    assert out.best == {"a": 1.0, "b": 4.0}
    assert out.runs == {"a": [3.0, 1.0, 2.0], "b": [5.0, 6.0, 4.0]}


def test_run_process_reports_output_cpu_and_peak_memory() -> None:
    code = "import time\nb = bytearray(64 * 2**20)\nt = time.process_time()\nwhile time.process_time() - t < 0.3: pass\nprint(1)"
    run = harness.run_process([sys.executable, "-c", code])
    assert run.returncode == 0 and run.stdout.strip() == "1"
    # CPU is sampled every SAMPLE_S: the last sample may miss the child's last moments
    assert run.wall_s >= 0.3 and run.cpu_s >= 0.1 and run.own_cpu_s == run.cpu_s
    assert run.peak_rss_bytes >= 64 * 2**20


def test_run_process_failure_names_the_command_and_its_error() -> None:
    with pytest.raises(RuntimeError, match="exit 3") as err:
        harness.run_process([sys.executable, "-c", "import sys; sys.exit('bad input' and 3)"])
    assert "python" in str(err.value)
    assert harness.run_process([sys.executable, "-c", "raise SystemExit(3)"], check=False).returncode == 3


def test_report_writes_the_title_the_command_and_replaces_only_its_section(tmp_path: Path) -> None:
    report = harness.Report("Speed", "python -m benchmarks.x --quick")
    report.add("| a | b |", "", report.regenerate_line("needs the `batch` extra"))
    regenerate = "Regenerate: `python -m benchmarks.x --quick` (from the repository root; needs the `batch` extra)."
    assert report.text() == f"# Speed\n\n| a | b |\n\n{regenerate}\n"
    doc = tmp_path / "doc.md"
    doc.write_text(f"intro\n{harness.START}\nold\n{harness.END}\noutro\n", encoding="utf-8")
    report.write(doc, section=True)
    text = doc.read_text(encoding="utf-8")
    assert text.startswith("intro\n") and text.endswith("\noutro\n") and "old" not in text and "# Speed" in text
    fresh = tmp_path / "fresh.md"
    report.write(fresh)
    assert fresh.read_text(encoding="utf-8") == report.text()


def test_machine_names_the_cpu_cores_and_package_versions() -> None:
    m = harness.machine(("numpy", "no-such-package-here"))
    assert m["cpu"] and int(m["cores"]) >= int(m["usable"]) >= 1
    assert m["numpy"][0].isdigit() and m["no-such-package-here"] == "not installed"


def test_run_tool_reports_the_tools_own_peak_memory_and_its_output() -> None:
    code = "b = bytearray(96 * 2**20)\nfor i in range(0, len(b), 4096): b[i] = 1\nprint(len(b))"
    run = harness.run_tool([sys.executable, "-c", code])
    assert run.stdout.strip() == str(96 * 2**20) and run.cpu_s > 0 and run.wall_s > 0
    assert 96 * 2**20 <= run.peak_rss_bytes < 96 * 2**20 + 2**30
    with pytest.raises(RuntimeError, match="failed"):
        harness.run_tool([sys.executable, "-c", "raise SystemExit(2)"])


def test_proc_stat_and_descendants_see_live_processes() -> None:
    import os
    import subprocess

    me = harness.proc_stat(os.getpid())
    assert me is not None and me.rss_bytes > 0 and me.peak_rss_bytes >= me.rss_bytes and "python" in me.command
    child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    try:
        assert child.pid in harness.descendants(os.getpid())
    finally:
        child.kill()
        child.wait()
    assert harness.proc_stat(child.pid) is None


def test_byte_compiled_writes_each_modules_bytecode_without_importing_it(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import importlib.util

    package = tmp_path / "scratch_pkg_for_bytecode"
    (package / "sub").mkdir(parents=True)
    sources = [package / "__init__.py", package / "sub" / "__init__.py", package / "sub" / "mod.py"]
    for source in sources:
        source.write_text("raise RuntimeError('imported')\n")  # compiling must not run it
    monkeypatch.syspath_prepend(str(tmp_path))
    sentence = harness.byte_compiled("scratch_pkg_for_bytecode")
    assert "compiled to bytecode first" in sentence
    assert all(Path(importlib.util.cache_from_source(str(s))).is_file() for s in sources)
    assert "scratch_pkg_for_bytecode" not in sys.modules


def test_byte_compiled_says_when_the_package_is_missing() -> None:
    assert "was not found" in harness.byte_compiled("no_such_package_for_bytecode_xyz")


def test_a_process_seen_as_a_zombie_keeps_the_peak_it_had_alive(monkeypatch: pytest.MonkeyPatch) -> None:
    # /proc/<pid>/status of an exited, unreaped process lists no VmHWM: the last sample reads a peak of 0
    stats = iter([harness.ProcStat(0.1, 100 * 2**20, "python"), harness.ProcStat(0.4, 0, "python")])
    monkeypatch.setattr(harness, "_tree", lambda roots: list(roots))
    monkeypatch.setattr(harness, "proc_stat", lambda pid: next(stats))
    log = harness.TreeLog()
    log.sample([7])
    log.sample([7])
    assert log.peak() == 100 * 2**20 and log.cpu() == pytest.approx(0.3)


# the benchmark forks warm processes on purpose; Python 3.12 warns of fork() when other tests left threads running
_FORK_OK = pytest.mark.filterwarnings("ignore:This process .* is multi-threaded:DeprecationWarning")


@_FORK_OK
def test_ceiling_times_every_process_from_its_release_to_the_end_of_the_last_job() -> None:
    from benchmarks import ceiling

    def job() -> None:
        time.sleep(0.05)

    got = ceiling.timed(job, 2, rounds=1)
    assert got.wall_s >= 0.05 and got.own_s >= 0.05  # the job ran in each process after the release
    assert got.wall_s >= got.own_s  # the last job ends no earlier than any process's own time


@_FORK_OK
def test_ceiling_runs_each_pinned_process_on_its_own_cpu() -> None:
    import multiprocessing

    from benchmarks import ceiling

    cpu = sorted(os.sched_getaffinity(0))[-1]
    seen = multiprocessing.get_context("fork").Value("i", -1)

    def job() -> None:
        seen.value = next(iter(os.sched_getaffinity(0))) if len(os.sched_getaffinity(0)) == 1 else -2

    ceiling.timed(job, 1, rounds=1, cpus=[cpu])
    assert seen.value == cpu


@_FORK_OK
def test_ceiling_refuses_a_run_where_a_process_failed() -> None:
    from benchmarks import ceiling

    def job() -> None:
        raise SystemExit(3)

    with pytest.raises(RuntimeError, match="exit codes"):
        ceiling.timed(job, 1, rounds=1)


def test_mass_report_names_a_missing_peer_instead_of_failing(monkeypatch: pytest.MonkeyPatch) -> None:
    import importlib.metadata

    from benchmarks import mass

    real = importlib.metadata.version

    def version(name: str) -> str:
        if name == "numpy-stl":
            raise importlib.metadata.PackageNotFoundError(name)
        return real(name)

    monkeypatch.setattr(importlib.metadata, "version", version)
    assert mass.machine_info()["numpy-stl"] == "not installed"


def _timeline(tasks: list[tuple[int, float, float, int]]) -> timeline.Timeline:
    forked = {pid: 0.5 for pid, *_ in tasks}
    return timeline.Timeline(
        launch=100.0,
        main=100.05,
        server=100.1,
        preloaded=100.4,
        exit=102.2,
        forked={pid: 100.0 + t for pid, t in forked.items()},
        tasks=[timeline.Task(pid, 100.0 + s, 100.0 + e, n) for pid, s, e, n in tasks],
    )


def test_timeline_profile_phases_come_from_the_tasks_times() -> None:
    # worker 1: two tasks 0.6-1.0 and 1.1-2.0; worker 2: one task 0.7-1.5; worker 3 never got one
    tl = _timeline([(1, 0.6, 1.0, 3), (1, 1.1, 2.0, 3), (2, 0.7, 1.5, 2)])
    p = timeline.profile(tl, workers=3)
    assert p["first_task"] == pytest.approx(0.6) and p["last_end"] == pytest.approx(2.0)
    assert p["first_idle"] == pytest.approx(1.5)  # worker 2's last task ended first
    assert p["all_busy"] == pytest.approx(2.0)  # one worker never had work: never all busy before the end
    assert p["busy_s"] == pytest.approx(0.4 + 0.9 + 0.8)
    assert p["busy_share"] == pytest.approx(2.1 / (3 * 1.4))
    assert p["gap_sum_s"] == pytest.approx(0.1) and p["gap_mean_ms"] == pytest.approx(100.0)
    assert p["workers_used"] == 2 and p["tasks"] == 3
    assert p["preloaded"] == pytest.approx(0.4) and p["exit"] == pytest.approx(2.2)

    p2 = timeline.profile(tl, workers=2)
    assert p2["all_busy"] == pytest.approx(0.7)  # both workers had started a task


def test_timeline_chart_marks_idle_busy_and_not_yet_forked() -> None:
    tl = _timeline([(1, 1.14, 2.16, 1)])  # forked at 0.5 s of a 2.2 s run
    row = timeline.chart(tl, columns=22)[0]  # 0.1 s a column
    assert row == "....." + " " * 6 + "|" + "#" * 10


def test_timeline_traces_every_task_of_a_real_run(tmp_path: Path) -> None:
    from benchmarks import scale

    scale.generate(tmp_path / "in", 12, 80, seed=1)
    tl = timeline.traced_run(tmp_path / "in", tmp_path / "out.jsonl", workers=2)
    assert sum(t.files for t in tl.tasks) == 12  # every file analysed in a traced task
    assert len((tmp_path / "out.jsonl").read_text().splitlines()) == 12
    assert tl.launch < tl.main < tl.server <= tl.preloaded < min(t.start for t in tl.tasks)
    assert max(t.end for t in tl.tasks) < tl.exit
    assert set(tl.forked) == {t.pid for t in tl.tasks}
