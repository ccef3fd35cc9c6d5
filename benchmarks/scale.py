"""Scaling of ``inertia batch`` with the number of workers: local processes and a real Dask cluster.

    python -m benchmarks.scale                                  # writes docs/scaling.md
    python -m benchmarks.scale --workers 1,2,4,8,16 --sets small=4000x1280,large=48x327680 --rounds 3
    python -m benchmarks.scale --quick --out /tmp/scaling.md    # a smoke run

Generates its inputs (binary STL ellipsoids of random size and offset) into a
temporary folder, then times, on the same files, in interleaved rounds (the
best of each contender is kept; every run's output is checked):

- ``trimesh loop``: a fresh ``python -c`` that imports trimesh and reads
  ``trimesh.load(path).mass_properties`` for every file, one after the other;
- ``analyze loop``: the same with ``inertia.pipeline.analyze(path)`` on one
  thread (no block threads, as in each batch worker): our serial pipeline,
  the reference of the speed-ups;
- ``inertia batch --workers N``: the real command on the local default engine
  (a process pool), from launch to exit, start-up included;
- ``inertia batch --scheduler ADDRESS``: the real command against a running
  ``dask scheduler`` and N single-threaded ``dask worker`` processes that this
  benchmark starts on 127.0.0.1 for each N (their start is not timed; each
  has a ``--lifetime`` and is stopped when its runs end);
- ``Dask LocalCluster``: ``run_batch(engine="dask")`` in a fresh process, the
  former local default, at the largest N not above the core count.

For every run it samples the process tree every 50 ms (``/proc``): CPU time
of each process and its peak resident set (``VmHWM``, the kernel's own
high-water mark, so no peak is missed between samples).

Separately it measures the per-task overhead of each engine: empty tasks
through the process pool and through the Dask cluster (tasks per second,
and the client's CPU per task), and from those, the command's start-up and
the serial work it predicts the throughput at 16 workers on a machine with
16 free cores (docs/scaling.md says how).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.batch import ANALYZE_SCRIPT, TRIMESH_SCRIPT, write_stl
from benchmarks.cases import box, uv_sphere
from benchmarks.harness import Report, TreeLog, available_cores, byte_compiled, interleaved, machine, run_process, sampled

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "scaling.md"
SAMPLE_S = 0.05
CLUSTER_LIFETIME_S = 900  # every dask process started here stops by itself after this, whatever happens
DEFAULT_SETS = "small=4000x1280,large=48x327680"
QUICK_SETS = "small=400x1280,large=6x81920"
OVERHEAD_TASKS = 2000


# ---------------------------------------------------------------------------
# inputs


def shape_for(triangles: int) -> tuple[int, int]:
    """(nlat, nlon) of a UV sphere of about ``triangles`` = 2 nlon (nlat - 1) triangles."""
    bands = max(2, round((triangles / 3.2) ** 0.5))
    return bands + 1, max(3, round(triangles / (2 * bands)))


def generate(folder: Path, count: int, triangles: int, seed: int) -> int:
    folder.mkdir(parents=True)
    v, f = uv_sphere(*shape_for(triangles))
    rng = np.random.default_rng(seed)
    for i in range(count):
        scaled = v * rng.uniform(0.01, 0.1, 3) + rng.uniform(-1.0, 1.0, 3)
        write_stl(folder / f"part_{i:05d}.stl", scaled[f])
    return count * len(f)


# ---------------------------------------------------------------------------
# runs


@dataclass
class Run:
    wall_s: float
    cpu_s: float  # all processes of the run's tree (for the cluster: its workers and scheduler too)
    client_cpu_s: float  # the command's own process
    peak_worker_bytes: int


def check_rows(out: Path, count: int) -> None:
    rows = [json.loads(line) for line in out.read_text(encoding="utf-8").splitlines() if line.strip()]
    errors = [row for row in rows if "error" in row]
    if len(rows) != count or errors:
        raise RuntimeError(f"{out}: {len(rows)} rows for {count} files, {len(errors)} errors {errors[:1]}")


def timed(cmd: list[str], extra_roots: list[int] | None = None) -> Run:
    """Run ``cmd`` from launch to exit, sampling its process tree (and ``extra_roots``'s, whose CPU counts from here)."""
    done = run_process(cmd, extra_roots=extra_roots or ())
    workers = [pid for pid in done.tree.seen if pid != done.pid and (not extra_roots or pid not in extra_roots[:1])]
    return Run(done.wall_s, done.cpu_s, done.own_cpu_s, done.tree.peak(workers))


def loop_run(script: str, file_list: Path, count: int) -> Run:
    run = timed([sys.executable, "-c", script, str(file_list)])
    return run


def command_run(folder: Path, out: Path, count: int, workers: int) -> Run:
    out.unlink(missing_ok=True)
    run = timed(
        [sys.executable, "-m", "inertia", "batch", str(folder), "--out", str(out), "--workers", str(workers), "--no-progress"]
    )
    check_rows(out, count)
    return run


LOCALCLUSTER_SCRIPT = """\
import sys
from inertia.batch import run_batch
run_batch([sys.argv[1]], sys.argv[2], workers=int(sys.argv[3]), engine="dask", progress=False)
"""


def localcluster_run(folder: Path, out: Path, count: int, workers: int) -> Run:
    out.unlink(missing_ok=True)
    run = timed([sys.executable, "-c", LOCALCLUSTER_SCRIPT, str(folder), str(out), str(workers)])
    check_rows(out, count)
    return run


class Cluster:
    """A ``dask scheduler`` and ``workers`` single-threaded ``dask worker`` processes on 127.0.0.1."""

    def __init__(self, workers: int, work: Path) -> None:
        self.workers = workers
        scheduler_file = work / f"scheduler-{workers}-{time.monotonic_ns()}.json"
        self.scheduler = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "dask",
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--dashboard-address",
                ":0",
                "--scheduler-file",
                str(scheduler_file),
                "--idle-timeout",
                f"{CLUSTER_LIFETIME_S}s",
            ],
            cwd=ROOT,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        deadline = time.monotonic() + 120
        while not scheduler_file.exists():
            if time.monotonic() > deadline or self.scheduler.poll() is not None:
                self.close()
                raise RuntimeError("the dask scheduler did not start")
            time.sleep(0.1)
        time.sleep(0.2)
        self.address = json.loads(scheduler_file.read_text())["address"]
        env = dict(os.environ, OMP_NUM_THREADS="1", MKL_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
        self.worker = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "dask",
                "worker",
                self.address,
                "--nworkers",
                str(workers),
                "--nthreads",
                "1",
                "--no-dashboard",
                "--lifetime",
                f"{CLUSTER_LIFETIME_S}s",
                "--memory-limit",
                "0",
                "--preload",
                "inertia.batch.tasks",
            ],
            cwd=ROOT,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            env=env,
            start_new_session=True,
        )
        self._wait_for_workers(deadline)

    def _wait_for_workers(self, deadline: float) -> None:
        from distributed import Client

        with Client(self.address, timeout="60s") as client:
            while len(client.nthreads()) < self.workers:
                if time.monotonic() > deadline or self.worker.poll() is not None:
                    self.close()
                    raise RuntimeError(f"only {len(client.nthreads())} of {self.workers} dask workers started")
                time.sleep(0.2)

    @property
    def roots(self) -> list[int]:
        return [self.scheduler.pid, self.worker.pid]

    def close(self) -> None:
        for proc in (self.worker, self.scheduler):
            if proc.poll() is None:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(proc.pid, signal.SIGTERM)
        for proc in (self.worker, self.scheduler):
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()


def cluster_run(cluster: Cluster, folder: Path, out: Path, count: int) -> Run:
    out.unlink(missing_ok=True)
    run = timed(
        [sys.executable, "-m", "inertia", "batch", str(folder), "--out", str(out), "--scheduler", cluster.address, "--no-progress"],
        extra_roots=cluster.roots,
    )
    check_rows(out, count)
    # the cluster's processes: peak among its workers (the scheduler is a root of its own tree, excluded)
    return run


# ---------------------------------------------------------------------------
# per-task overhead


OVERHEAD_POOL_SCRIPT = """\
import json, sys, time
from inertia.batch.pool import run_pool
from inertia.batch.workers import start_forkserver
from inertia.pipeline import AnalysisOptions
workers, tasks = int(sys.argv[1]), int(sys.argv[2])
start_forkserver()
def run(n):
    wrote = []
    t, c = time.perf_counter(), time.process_time()
    run_pool(iter([[]] * n), workers, 4 * workers, AnalysisOptions(), "jsonl", wrote.append)
    return time.perf_counter() - t, time.process_time() - c
run(workers * 4)  # start the workers
w0, c0 = run(workers)  # a pool's start and stop with one task per worker
w, c = run(tasks)
print(json.dumps({"wall_s": w, "client_cpu_s": c, "start_s": w0, "tasks": tasks}))
"""

OVERHEAD_DASK_SCRIPT = """\
import json, sys, time
from distributed import Client, as_completed
from inertia.batch.tasks import render_sources
from inertia.pipeline import AnalysisOptions
address, tasks = sys.argv[1], int(sys.argv[2])
with Client(address) as client:
    threads = sum(client.nthreads().values())
    def run(n):
        t, c = time.perf_counter(), time.process_time()
        ac = as_completed()
        left = n
        for _ in range(min(n, 4 * threads)):
            ac.add(client.submit(render_sources, [], AnalysisOptions(), "jsonl", pure=False)); left -= 1
        for f in ac:
            f.result(); f.release()
            if left:
                ac.add(client.submit(render_sources, [], AnalysisOptions(), "jsonl", pure=False)); left -= 1
        return time.perf_counter() - t, time.process_time() - c
    run(4 * threads)
    w, c = run(tasks)
print(json.dumps({"wall_s": w, "client_cpu_s": c, "tasks": tasks}))
"""


def overhead_pool(workers: int, tasks: int) -> dict[str, Any]:
    done = run_process([sys.executable, "-c", OVERHEAD_POOL_SCRIPT, str(workers), str(tasks)])
    return dict(json.loads(done.stdout.splitlines()[-1]))


def overhead_dask(cluster: Cluster, tasks: int) -> dict[str, Any]:
    log = TreeLog()
    log.sample(cluster.roots)
    with sampled(cluster.roots, log):
        done = run_process([sys.executable, "-c", OVERHEAD_DASK_SCRIPT, cluster.address, str(tasks)])
    got = dict(json.loads(done.stdout.splitlines()[-1]))
    got["cluster_cpu_s"] = log.cpu()
    return got


# ---------------------------------------------------------------------------
# report


def _f(x: float, digits: int = 2) -> str:
    return f"{x:,.{digits}f}"


@dataclass
class SetResult:
    name: str
    count: int
    triangles: int
    megabytes: float
    runs: dict[tuple[str, int], Run]


def _table(res: SetResult, workers: list[int]) -> list[str]:
    base = res.runs[("analyze loop", 1)].wall_s
    trimesh = res.runs[("trimesh loop", 1)].wall_s
    lines = [
        f"### {res.name}: {res.count:,} files of {res.triangles // res.count:,} triangles ({res.megabytes:,.0f} MB)",
        "",
        "| contender | workers | wall (s) | files/s | triangles/s | speed-up vs analyze loop | parallel efficiency | "
        "vs trimesh loop | CPU, all processes (s) | CPU, command process (s) | peak RSS per worker (MiB) |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for (label, n), run in res.runs.items():
        speed = base / run.wall_s
        serial = label in ("trimesh loop", "analyze loop")
        one = res.runs.get((label, 1))
        eff = "" if serial or one is None else f"{one.wall_s / run.wall_s / n:.0%}"
        lines.append(
            f"| {label} | {n if not serial else 'serial'} | {_f(run.wall_s)} | {_f(res.count / run.wall_s, 1)} | "
            f"{res.triangles / run.wall_s:,.0f} | {speed:.2f}x | {eff} | {trimesh / run.wall_s:.2f}x | "
            f"{_f(run.cpu_s)} | {_f(run.client_cpu_s)} | "
            f"{'' if serial else f'{run.peak_worker_bytes / 2**20:,.0f}'} |"
        )
    return [*lines, ""]


def predict(res: SetResult, starts: dict[int, Run], target: int = 16) -> dict[str, float]:
    """The command's wall time on ``target`` free cores, from what ran here (see the report's text)."""
    one, empty = res.runs[("inertia batch", 1)], starts[1]
    work = max(one.cpu_s - empty.cpu_s, 0.0)  # CPU of the files themselves, all processes
    client = max(one.client_cpu_s - empty.client_cpu_s, 0.0)  # ... of which in the command (rows, progress)
    # on free cores the start-up's processes (command, forkserver, forks) each run when ready: its wall time is
    # at most their CPU added up; here, on a shared machine, its wall time mostly measures waiting for a core
    start = min(starts[max(n for n in starts if n <= target)].cpu_s, starts[max(n for n in starts if n <= target)].wall_s)
    wall = start + max((work - client) / target, client)
    return {
        "start_s": start,
        "work_s": work,
        "client_s": client,
        "wall_s": wall,
        "speedup_vs_analyze": res.runs[("analyze loop", 1)].wall_s / wall,
        "vs_trimesh": res.runs[("trimesh loop", 1)].wall_s / wall,
    }


def render(
    results: list[SetResult],
    workers: list[int],
    overheads: dict[str, dict[str, Any]],
    starts: dict[int, Run],
    loads: list[float],
    rounds: int,
    command: str,
    compiled: str = "",
) -> Report:
    m = machine(("numpy", "trimesh", "dask", "distributed"))
    report = Report("", command)
    lines = [
        report.regenerate_line("needs the `batch` extra, trimesh and psutil"),
        "",
        f"Machine: {m['cpu']}, **{m['cores']} cores** ({m['usable']} usable by this process), Python {m['python']}, "
        f"numpy {m['numpy']}, trimesh {m['trimesh']}, dask {m['dask']}, distributed {m['distributed']}; "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}.",
        "Cores this run could use, probed before each round by two busy processes (2.00 = an idle 2-core "
        "machine): " + ", ".join(f"{x:.2f}" for x in loads) + ".",
        f"{rounds} interleaved round(s); each figure is the best of them. Every contender is a whole process "
        "from launch to exit (interpreter, imports, start-up and shutdown included); every batch output is "
        "checked (one row per file, no errors)." + (f" Before the runs, {compiled}." if compiled else ""),
        "",
        "- *speed-up* is the serial `analyze()` loop's wall time over the row's; *parallel efficiency* is the "
        "row's files/s over N times the same contender's files/s at 1 worker;",
        "- *CPU, all processes*: every process of the run's tree (for the Dask cluster also its scheduler and "
        "workers); *CPU, command process*: the client alone (listing, rows, progress);",
        "- *peak RSS per worker*: the largest `VmHWM` (the kernel's high-water mark) among the run's processes "
        "other than the command: the worker processes (and for the pool the forkserver they fork from; "
        "for the cluster the nannies and the scheduler).",
        "",
    ]
    for res in results:
        lines += _table(res, workers)
    lines += ["## Per-task overhead", ""]
    pool = overheads.get("pool")
    if pool:
        lines.append(
            f"- **process pool** ({pool['workers']} workers): {pool['tasks']:,} empty tasks in "
            f"{pool['wall_s']:.3f} s: **{pool['wall_s'] / pool['tasks'] * 1e3:.3f} ms per task** of wall time, "
            f"{pool['client_cpu_s'] / pool['tasks'] * 1e3:.3f} ms of the client's CPU per task; a pool's start "
            f"and stop with {pool['workers']} workers (forks from the running forkserver): {pool['start_s']:.3f} s."
        )
    dask = overheads.get("dask")
    if dask:
        lines.append(
            f"- **Dask cluster** ({dask['workers']} workers): {dask['tasks']:,} empty tasks in {dask['wall_s']:.3f} s: "
            f"**{dask['wall_s'] / dask['tasks'] * 1e3:.3f} ms per task** of wall time, "
            f"{dask['client_cpu_s'] / dask['tasks'] * 1e3:.3f} ms of the client's CPU and "
            f"{dask['cluster_cpu_s'] / dask['tasks'] * 1e3:.3f} ms of the scheduler's and workers' CPU per task."
        )
    lines += [""]
    lines += [
        "## Start-up",
        "",
        "The command on N files of 12 triangles with N workers (interpreter, imports, forkserver, N workers forked, shutdown):",
        "",
        "| workers | wall (s) | CPU, all processes (s) | CPU, command process (s) |",
        "|---:|---:|---:|---:|",
    ]
    lines += [f"| {n} | {r.wall_s:.2f} | {r.cpu_s:.2f} | {r.client_cpu_s:.2f} |" for n, r in sorted(starts.items())]
    lines.append("")
    if 1 in starts:
        lines += [
            "## What this predicts for 16 cores",
            "",
            "CPU times are what a busy machine distorts least, so the prediction is built from them: "
            "W = the CPU of all processes of the 1-worker command on the set minus that of its start-up run "
            "(the files' own work, per-task costs included), C = the part of it in the command's own "
            "process (receiving and writing rows, progress), which does not divide among workers, "
            "S(16) = the start-up run with 16 workers measured here: the CPU of all its processes (on free "
            "cores its wall time is at most that; on a shared machine its wall time measures the wait for "
            "a core). On 16 free cores: T(16) = S(16) + max((W - C) / 16, C).",
            "",
            "| data set | S(16) (s) | W (s) | C (s) | predicted T(16) (s) | predicted files/s | "
            "predicted speed-up vs analyze loop | predicted vs trimesh loop |",
            "|---|---:|---:|---:|---:|---:|---:|---:|",
        ]
        for res in results:
            if ("inertia batch", 1) not in res.runs:
                continue
            p = predict(res, starts)
            lines.append(
                f"| {res.name} | {p['start_s']:.2f} | {p['work_s']:.2f} | {p['client_s']:.2f} | "
                f"{p['wall_s']:.2f} | {res.count / p['wall_s']:,.0f} | {p['speedup_vs_analyze']:.1f}x | "
                f"{p['vs_trimesh']:.1f}x |"
            )
        lines.append("")
    report.add(*lines)
    return report


# ---------------------------------------------------------------------------


def parse_sets(text: str) -> list[tuple[str, int, int]]:
    out = []
    for item in text.split(","):
        name, spec = item.split("=")
        count, triangles = spec.lower().split("x")
        out.append((name.strip(), int(count), int(triangles)))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.scale", description=__doc__.split("\n")[0])
    parser.add_argument(
        "--workers", default=None, help="comma-separated worker counts (default: 1, 2, 4, ... up to the core count)"
    )
    parser.add_argument("--sets", default=DEFAULT_SETS, help=f"NAME=FILESxTRIANGLES,... (default {DEFAULT_SETS})")
    parser.add_argument("--rounds", type=int, default=2, help="interleaved rounds; the best of each counts")
    parser.add_argument("--quick", action="store_true", help=f"sets {QUICK_SETS}, one round")
    parser.add_argument("--no-cluster", action="store_true", help="skip the dask scheduler + worker cluster")
    parser.add_argument("--out", type=Path, default=DOC, help="report file ('-' for stdout)")
    args = parser.parse_args(argv)
    cores = os.cpu_count() or 1
    workers = [int(x) for x in args.workers.split(",")] if args.workers else [n for n in (1, 2, 4, 8, 16, 32, 64) if n <= cores]
    if 1 not in workers:
        workers = [1, *workers]
    sets = parse_sets(QUICK_SETS if args.quick and args.sets == DEFAULT_SETS else args.sets)
    rounds = 1 if args.quick else args.rounds
    command = "python -m benchmarks.scale" + " ".join(
        [
            "",
            *(["--workers", args.workers] if args.workers else []),
            *(["--sets", args.sets] if args.sets != DEFAULT_SETS else []),
            *(["--rounds", str(args.rounds)] if args.rounds != 2 and not args.quick else []),
            *(["--quick"] if args.quick else []),
            *(["--no-cluster"] if args.no_cluster else []),
            *(["--out", str(args.out)] if args.out != DOC else []),
        ]
    )
    local_n = max(n for n in workers if n <= cores)
    compiled = byte_compiled()
    work = Path(tempfile.mkdtemp(prefix="inertia-scale-"))
    results: list[SetResult] = []
    loads: list[float] = []
    overheads: dict[str, dict[str, Any]] = {}
    starts: dict[int, Run] = {}
    try:
        print(f"overhead: pool, {local_n} workers", file=sys.stderr)
        overheads["pool"] = {**overhead_pool(local_n, OVERHEAD_TASKS), "workers": local_n}
        if not args.no_cluster:
            cluster = Cluster(local_n, work)
            try:
                overheads["dask"] = {**overhead_dask(cluster, OVERHEAD_TASKS // 2), "workers": local_n}
            finally:
                cluster.close()
        print("start-up runs", file=sys.stderr)
        starts = startup(work, sorted({*workers, 16}), rounds + 1)
        for seed, (name, count, triangles) in enumerate(sets):
            folder = work / name
            total = generate(folder, count, triangles, seed)
            files = sorted(folder.glob("*.stl"))
            file_list = work / f"{name}.files"
            file_list.write_text("".join(f"{p}\n" for p in files), encoding="utf-8")
            megabytes = sum(p.stat().st_size for p in files) / 1e6
            print(f"[{name}] {count} files, {total:,} triangles, {megabytes:,.0f} MB", file=sys.stderr)
            out = work / f"{name}.jsonl"
            plan = _plan(workers, local_n, not args.no_cluster, work, folder, file_list, out, count)

            def progress(r: int, got: dict[tuple[str, int], Run], name: str = name) -> None:
                for key, run in got.items():
                    print(
                        f"[{name}] round {r + 1}: {key[0]} x{key[1]}: {run.wall_s:.2f} s, CPU {run.cpu_s:.2f} s "
                        f"(command {run.client_cpu_s:.2f} s), peak worker {run.peak_worker_bytes / 2**20:.0f} MiB",
                        file=sys.stderr,
                    )

            best = interleaved(
                plan,
                rounds,
                lambda _key, run: run.wall_s,
                after_round=progress,
                before_round=lambda _r: loads.append(available_cores()),
                rotate=3,
            ).best
            ordered = {key: best[key] for key, _ in plan}
            results.append(SetResult(name, count, total, megabytes, ordered))
            shutil.rmtree(folder)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    report = render(results, workers, overheads, starts, loads, rounds, command.strip(), compiled)
    if str(args.out) != "-":  # the measured part, between the markers; text around them is kept
        report.write(args.out, section=True)
    print(report.text())
    return 0


def _plan(
    workers: list[int], local_n: int, cluster: bool, work: Path, folder: Path, file_list: Path, out: Path, count: int
) -> list[tuple[tuple[str, int], Callable[[], Run]]]:
    plan: list[tuple[tuple[str, int], Callable[[], Run]]] = [
        (("trimesh loop", 1), lambda: loop_run(TRIMESH_SCRIPT, file_list, count)),
        (("analyze loop", 1), lambda: loop_run(ANALYZE_SCRIPT, file_list, count)),
    ]
    for n in workers:
        plan.append((("inertia batch", n), partial(command_run, folder, out, count, n)))
    plan.append((("Dask LocalCluster", local_n), lambda: localcluster_run(folder, out, count, local_n)))
    if cluster:
        for n in workers:
            plan.append((("dask scheduler + workers", n), partial(_with_cluster, n, work, folder, out, count)))
    return plan


def startup(work: Path, workers: list[int], rounds: int) -> dict[int, Run]:
    """The command on N files of 12 triangles with N workers (best of ``rounds``): its start-up and shutdown."""
    best: dict[int, Run] = {}
    for n in workers:
        folder = work / f"startup-{n}"
        folder.mkdir()
        v, f = box(1.0, 1.0, 1.0)
        for i in range(n):
            write_stl(folder / f"box_{i:03d}.stl", (v * (1.0 + i))[f])
        best[n] = min((command_run(folder, work / "startup.jsonl", n, n) for _ in range(rounds)), key=lambda run: run.wall_s)
        shutil.rmtree(folder)
    return best


def _with_cluster(n: int, work: Path, folder: Path, out: Path, count: int) -> Run:
    cluster = Cluster(n, work)
    try:
        return cluster_run(cluster, folder, out, count)
    finally:
        cluster.close()


if __name__ == "__main__":
    raise SystemExit(main())
