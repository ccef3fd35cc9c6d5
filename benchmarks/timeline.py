"""Where the time of one ``inertia batch`` run goes: a timeline of its start-up, its workers' tasks and its end.

    python -m benchmarks.timeline                                   # 16 workers, both sets, docs/scaling-timeline.md
    python -m benchmarks.timeline --workers 2 --sets small=400x1280 --out /tmp/timeline.md

The real command (``python -m inertia batch DIR --workers N``), launched as a
whole process on the data sets of ``benchmarks.scale``, with one addition: its
forkserver also imports this module, which wraps the task the workers run
(``inertia.batch.tasks.render_sources``) so that each task writes one line:
its worker, start, end and number of files (``time.time()``, a line appended
to a file per worker, some 20 µs a task).  Each worker also notes when it
was forked (``/proc/self/stat``, to the kernel's 10 ms tick).  The command,
its start-up and its output are otherwise untouched.

From those it writes the profile of the run: how long until the first
worker existed, until the first task started, until every worker had work;
then how busy the workers were while there was work (the busy share of
N x that span), what they waited between tasks (the per-task cost seen from
a worker), the tail (from the first worker left without work to the last
task's end), and the exit.  A chart shows each worker's tasks over time.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "scaling-timeline.md"
TRACE_ENV = "INERTIA_BENCH_TIMELINE"  # the folder the workers write their task lines to
CHART_COLUMNS = 72


# ---------------------------------------------------------------------------
# in the workers (imported by the forkserver, before any worker is forked)


def _forked_at() -> float:
    """This process's start, as ``time.time()``, from the kernel's start time in clock ticks since boot."""
    with open("/proc/self/stat", encoding="ascii") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    ticks = int(fields[19])  # field 22 of proc(5), counted from the state (field 3)
    since_boot = time.clock_gettime(time.CLOCK_BOOTTIME)
    return time.time() - (since_boot - ticks / os.sysconf("SC_CLK_TCK"))


def _install_trace(folder: str) -> None:
    from inertia.batch import tasks

    plain = tasks.render_sources
    forked: list[float] = []

    def traced(sources: Any, options: Any, fmt: str) -> Any:
        start = time.time()
        rows = plain(sources, options, fmt)
        end = time.time()
        if not forked:
            forked.append(_forked_at())
        with open(os.path.join(folder, f"{os.getpid()}.txt"), "a", encoding="ascii") as f:
            f.write(f"{forked[0]!r} {start!r} {end!r} {len(sources)}\n")
        return rows

    # the client pickles the task by its name; a worker finds this wrapper under it
    traced.__module__, traced.__qualname__ = plain.__module__, plain.__qualname__
    tasks.render_sources = traced


if os.environ.get(TRACE_ENV) and __name__ != "__main__":
    # imported last in the forkserver's preload: its start and the preload's end
    with open(os.path.join(os.environ[TRACE_ENV], "forkserver.txt"), "w", encoding="ascii") as _f:
        _f.write(f"{_forked_at()!r} {time.time()!r}\n")
    _install_trace(os.environ[TRACE_ENV])


# ---------------------------------------------------------------------------
# the command, traced


CHILD = """\
import os, sys, time
start = time.time()
import inertia.batch.workers as workers
workers.WORKER_PRELOAD.append("benchmarks.timeline")
with open(os.path.join(os.environ["{env}"], "client.txt"), "w") as f:
    f.write(repr(start))
sys.argv = ["inertia", *sys.argv[1:]]
from inertia.cli import console_main
raise SystemExit(console_main())
"""


@dataclass
class Task:
    pid: int
    start: float
    end: float
    files: int


@dataclass
class Timeline:
    launch: float
    main: float  # the command's first statement
    server: float  # the forkserver's start
    preloaded: float  # the end of the forkserver's imports
    exit: float
    forked: dict[int, float]
    tasks: list[Task]


def traced_run(folder: Path, out: Path, workers: int) -> Timeline:
    """Run the command on ``folder`` with ``workers`` workers, tracing its tasks."""
    with tempfile.TemporaryDirectory(prefix="inertia-timeline-") as trace:
        env = {**os.environ, TRACE_ENV: trace}
        cmd = [sys.executable, "-c", CHILD.format(env=TRACE_ENV), "batch", str(folder), "--out", str(out)]
        cmd += ["--workers", str(workers), "--no-progress"]
        launch = time.time()
        done = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, check=False)
        end = time.time()
        if done.returncode:
            raise RuntimeError(f"the command failed ({done.returncode}): {done.stderr[-2000:]}")
        main = float(Path(trace, "client.txt").read_text())
        server, preloaded = map(float, Path(trace, "forkserver.txt").read_text().split())
        tasks, forked = [], {}
        for path in Path(trace).glob("[0-9]*.txt"):
            pid = int(path.stem)
            for line in path.read_text(encoding="ascii").splitlines():
                f, s, e, n = line.split()
                forked[pid] = float(f)
                tasks.append(Task(pid, float(s), float(e), int(n)))
    if not tasks:
        raise RuntimeError("no task was traced: the forkserver did not import benchmarks.timeline")
    return Timeline(launch, main, server, preloaded, end, forked, sorted(tasks, key=lambda t: t.start))


def profile(tl: Timeline, workers: int) -> dict[str, float]:
    """The phases of a traced run, in seconds from its launch, and the workers' busy share."""
    first_start = min(t.start for t in tl.tasks)
    last_end = max(t.end for t in tl.tasks)
    per_worker: dict[int, list[Task]] = {}
    for t in tl.tasks:
        per_worker.setdefault(t.pid, []).append(t)
    all_busy = max(ts[0].start for ts in per_worker.values()) if len(per_worker) == workers else last_end
    first_idle = min(ts[-1].end for ts in per_worker.values())
    busy = sum(t.end - t.start for t in tl.tasks)
    gaps = [b.start - a.end for ts in per_worker.values() for a, b in pairwise(ts)]
    return {
        "main": tl.main - tl.launch,
        "server": tl.server - tl.launch,
        "preloaded": tl.preloaded - tl.launch,
        "first_fork": min(tl.forked.values()) - tl.launch,
        "last_fork": max(tl.forked.values()) - tl.launch,
        "first_task": first_start - tl.launch,
        "all_busy": all_busy - tl.launch,
        "first_idle": first_idle - tl.launch,
        "last_end": last_end - tl.launch,
        "exit": tl.exit - tl.launch,
        "busy_s": busy,
        "busy_share": busy / (workers * (last_end - first_start)),
        "workers_used": len(per_worker),
        "tasks": len(tl.tasks),
        "gap_mean_ms": 1000 * sum(gaps) / len(gaps) if gaps else 0.0,
        "gap_sum_s": sum(gaps),
        "task_mean_ms": 1000 * busy / len(tl.tasks),
    }


def chart(tl: Timeline, columns: int = CHART_COLUMNS) -> list[str]:
    """Each worker's row over the run: ``.`` not forked yet, `` `` idle, ``#`` in a task, ``|`` a task's start."""
    span = tl.exit - tl.launch
    step = span / columns
    rows = []
    for pid in sorted(tl.forked, key=lambda p: tl.forked[p]):
        cells = [" "] * columns
        for c in range(columns):
            if tl.launch + (c + 1) * step <= tl.forked[pid]:
                cells[c] = "."
        for t in (t for t in tl.tasks if t.pid == pid):
            a, b = (t.start - tl.launch) / step, (t.end - tl.launch) / step
            for c in range(int(a), min(columns, int(b) + 1)):
                if min(b, c + 1) - max(a, c) >= 0.5 or int(a) == int(b):
                    cells[c] = "#"
            cells[min(columns - 1, int(a))] = "|"
        rows.append("".join(cells))
    ticks = "".join(f"{f'{c * step:.2f}':<12}" for c in range(0, columns, 12))
    return [*rows, "-" * columns, f"{ticks[:columns]} s from launch"]


# ---------------------------------------------------------------------------
# the report


def _row(label: str, s: float, note: str) -> str:
    return f"| {label} | {s:.3f} | {note} |"


def render_set(name: str, count: int, triangles: int, workers: int, tl: Timeline) -> list[str]:
    p = profile(tl, workers)
    span = p["last_end"] - p["first_task"]
    lines = [
        f"### {name}: {count:,} files of {triangles:,} triangles, {workers} workers",
        "",
        f"Wall time {p['exit']:.3f} s; {p['tasks']} tasks ({count / p['tasks']:.1f} files each on average), "
        f"{p['workers_used']} of {workers} workers ran tasks.",
        "",
        "| from launch to | s | what happened before it |",
        "|---|---:|---|",
        _row("the command's first statement", p["main"], "interpreter start-up, `site`"),
        _row("the forkserver started", p["server"], "the CLI's imports, the forkserver's launch (the inputs are listed meanwhile)"),
        _row("the forkserver's imports done", p["preloaded"], "its interpreter, then numpy and the pipeline"),
        _row("the first worker forked", p["first_fork"], "the pool asking the forkserver for its workers"),
        _row("the last worker forked", p["last_fork"], "the pool forking its workers"),
        _row("the first task started", p["first_task"], "a worker's start, the first task's transfer"),
        _row("every worker in a task", p["all_busy"], "ramp: tasks handed to the workers as they start"),
        _row("the first worker out of work", p["first_idle"], "every worker busy"),
        _row("the last task ended", p["last_end"], "tail: the last tasks, other workers idle"),
        _row("the command's exit", p["exit"], "the pool's shutdown, the output closed, interpreter exit"),
        "",
        f"- Busy share of the workers from the first task's start to the last one's end: **{100 * p['busy_share']:.0f} %** "
        f"({p['busy_s']:.2f} s of tasks in {workers} x {span:.3f} s).",
        f"- A task took {p['task_mean_ms']:.1f} ms on average; between two tasks a worker waited "
        f"{p['gap_mean_ms']:.2f} ms on average ({p['gap_sum_s']:.3f} s in all): the pool's per-task cost seen "
        "from a worker.",
        f"- Before the first task: {p['first_task']:.3f} s, {100 * p['first_task'] / p['exit']:.0f} % of the run; "
        f"after the last: {p['exit'] - p['last_end']:.3f} s.",
        "",
        "Each worker's row (`.` not forked yet, blank idle, `#` in a task, `|` a task's start):",
        "",
        "```",
        *chart(tl),
        "```",
        "",
    ]
    return lines


def main(argv: list[str] | None = None) -> int:
    from benchmarks.harness import Report, byte_compiled, machine
    from benchmarks.scale import DEFAULT_SETS, generate, parse_sets

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--workers", type=int, default=16)
    ap.add_argument("--sets", default=DEFAULT_SETS, help="name=COUNTxTRIANGLES,... (default %(default)s)")
    ap.add_argument("--rounds", type=int, default=1, help="runs per set; the fastest is profiled")
    ap.add_argument("--out", type=Path, default=DOC)
    args = ap.parse_args(argv)

    compiled = byte_compiled()
    info = machine(["numpy"])
    regenerate = "python -m benchmarks.timeline" + "".join(
        f" --{name} {value}"
        for name, value, default in (("workers", args.workers, 16), ("sets", args.sets, DEFAULT_SETS), ("rounds", args.rounds, 1))
        if value != default
    )
    report = Report("Timeline of an `inertia batch` run", regenerate)
    report.add(
        "Where the time of one run of the command goes. See [scaling.md](scaling.md) for the throughput and the machine's ceiling.",
        "",
        report.regenerate_line("needs the `batch` extra"),
        "",
        f"Machine: {info['cpu']}, **{info['cores']} cores** ({info['usable']} usable by this process), "
        f"Python {info['python']}, numpy {info['numpy']}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}. "
        f"{compiled}.",
        "",
        "The command is `python -m inertia batch DIR --workers N --no-progress`, a whole process from launch to exit; "
        "its forkserver also imports `benchmarks.timeline`, which makes each task write a line with its times "
        "(the module's docstring says how); a worker's fork is known to the kernel's 10 ms tick, the other times to "
        "the microsecond. Of several runs (`--rounds`), the fastest is shown.",
        "",
    )
    with tempfile.TemporaryDirectory(prefix="inertia-timeline-data-") as work:
        for name, count, triangles in parse_sets(args.sets):
            folder = Path(work, name)
            total = generate(folder, count, triangles, seed=7)
            runs = [traced_run(folder, Path(work, f"{name}.jsonl"), args.workers) for _ in range(args.rounds)]
            best = min(runs, key=lambda tl: tl.exit - tl.launch)
            report.add(*render_set(name, count, total // count, args.workers, best))
            print(f"{name}: {best.exit - best.launch:.3f} s", file=sys.stderr)
    report.write(args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
