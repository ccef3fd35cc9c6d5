"""The machine's own parallel ceiling: the batch's work in N forked processes, with no pool and no start-up.

    python -m benchmarks.ceiling                          # --workers 1,2,4,8,16, prints a markdown table
    python -m benchmarks.ceiling --workers 1,2 --out /tmp/ceiling.md
    python -m benchmarks.ceiling --pinned                 # adds the pinned probe below

For each job it forks N processes from one that has imported and warmed the
pipeline (as the batch command's forkserver has), lets them go at once, and
times from their release to the last one's exit.  Each process does the same
work, so the speed-up at N is N t(1) / t(N): what N workers reach on this
machine when nothing but the work runs.  ``inertia batch`` cannot scale
better than this; the gap between the two is the pool's start-up and its
per-task costs (docs/scaling.md).

Jobs, each about a second on one core:

- ``python``: a pure-Python float loop, no memory traffic: the cores alone
  (two hardware threads of one core share its execution units);
- ``small files``: ``analyze()`` of one 1,280-triangle STL, repeated (the
  per-file work of the small data set);
- ``large file``: ``analyze()`` of one 327,680-triangle STL, repeated (the
  large data set's);
- ``memory``: numpy ``argsort`` of 4e6 doubles (32 MB), bound by memory
  bandwidth like the weld's sorts.

``--pinned`` adds a probe of what the processors share, with the pure-Python
job pinned by ``sched_setaffinity``: one process alone on CPU 0, then pairs
on CPU 0 and CPU j for every other j (two hardware threads of one core slow
each other, two cores do not), then groups of 1, 2, 4, 8 and all CPUs, each
process on a CPU of its own (a clock that falls as more cores are busy, or
a host that gives its virtual CPUs fewer cores than it shows, slows them).

Numeric libraries run on one thread and the pipeline's block threads are
off, as in each batch worker.  The table's head gives the processor's
topology as the kernel reports it (``/sys/devices/system/cpu``).
"""

from __future__ import annotations

import argparse
import multiprocessing
import multiprocessing.synchronize
import os
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
THREAD_LIMITS = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS")


def _python_job() -> None:
    x = 0.0
    for i in range(4_000_000):
        x += (i & 7) * 0.5
    if x < 0:  # keeps the loop's result live
        print(x)


def _analyze_job(path: str, repeat: int) -> Callable[[], None]:
    from inertia.pipeline import analyze

    def job() -> None:
        for _ in range(repeat):
            analyze(path)

    return job


def _memory_job() -> Callable[[], None]:
    import numpy as np

    values = np.random.default_rng(1).random(4_000_000)

    def job() -> None:
        for _ in range(2):
            np.argsort(values, kind="stable")

    return job


def _worker(
    job: Callable[[], None], gate: multiprocessing.synchronize.Event, times: Any, slot: int, cpu: int | None = None
) -> None:
    if cpu is not None:
        os.sched_setaffinity(0, {cpu})
    gate.wait()
    times[2 * slot] = time.perf_counter()
    job()
    times[2 * slot + 1] = time.perf_counter()


@dataclass
class Timing:
    wall_s: float  # from the release to the end of the last job (process exits not counted)
    own_s: float  # the slowest process's own time for its job


def timed(job: Callable[[], None], n: int, rounds: int, cpus: list[int] | None = None) -> Timing:
    """Best, over ``rounds``, of ``n`` forked processes running ``job`` once each, from their release.

    With ``cpus`` (n of them), process i runs on ``cpus[i]`` alone.
    """
    ctx = multiprocessing.get_context("fork")
    best = Timing(float("inf"), float("inf"))
    for _ in range(rounds):
        gate = ctx.Event()
        times = ctx.Array("d", 2 * n, lock=False)
        procs = [ctx.Process(target=_worker, args=(job, gate, times, i, cpus[i] if cpus else None)) for i in range(n)]
        for p in procs:
            p.start()
        time.sleep(0.2 + 0.02 * n)  # every child is waiting at the gate
        start = time.perf_counter()
        gate.set()
        for p in procs:
            p.join()
        if any(p.exitcode for p in procs):
            raise RuntimeError(f"a worker failed: exit codes {[p.exitcode for p in procs]}")
        wall = max(times[1::2]) - start
        if wall < best.wall_s:
            best = Timing(wall, max(b - a for a, b in zip(times[0::2], times[1::2], strict=True)))
    return best


def pinned_probe(rounds: int) -> list[str]:
    """Markdown lines: the pure-Python job pinned alone, in pairs with CPU 0, and in groups of distinct CPUs."""
    cpus = sorted(os.sched_getaffinity(0))
    first = timed(_python_job, 1, rounds, [cpus[0]])
    alone = first.own_s
    lines = [
        "",
        f"Pinned pure-Python job (best of {rounds}); alone on CPU {cpus[0]}: {alone:.3f} s. Slowdown = the slower"
        " process's time over that.",
        "",
        f"| CPUs busy with CPU {cpus[0]} | " + " | ".join(str(c) for c in cpus[1:]) + " |",
        "|---|" + "---:|" * (len(cpus) - 1),
        "| slowdown of the pair | "
        + " | ".join(f"{timed(_python_job, 2, rounds, [cpus[0], c]).own_s / alone:.2f}" for c in cpus[1:])
        + " |",
    ]
    sizes = [k for k in (1, 2, 4, 8, 16, 32, 64) if k < len(cpus)] + [len(cpus)]
    groups = {k: first if k == 1 else timed(_python_job, k, rounds, cpus[:k]) for k in sizes}
    lines += [
        "",
        "| processes, each on its own CPU (the first k) | " + " | ".join(str(k) for k in sizes) + " |",
        "|---|" + "---:|" * len(sizes),
        "| slowdown of the slowest | " + " | ".join(f"{groups[k].own_s / alone:.2f}" for k in sizes) + " |",
        "| speed-up (k t(1) / t(k)) | " + " | ".join(f"{k * groups[1].wall_s / groups[k].wall_s:.2f}x" for k in sizes) + " |",
    ]
    return lines


def topology() -> str:
    """'S sockets, C cores, T hardware threads' from sysfs, or what of it is readable."""
    base = Path("/sys/devices/system/cpu")
    cores: set[tuple[str, str]] = set()
    threads = 0
    for cpu in sorted(base.glob("cpu[0-9]*")):
        try:
            package = (cpu / "topology" / "physical_package_id").read_text().strip()
            core = (cpu / "topology" / "core_id").read_text().strip()
        except OSError:
            continue
        cores.add((package, core))
        threads += 1
    if not threads:
        return f"topology not readable; os.cpu_count() = {os.cpu_count()}"
    sockets = len({p for p, _ in cores})
    return f"{sockets} socket(s), {len(cores)} physical core(s), {threads} hardware thread(s)"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--workers", default="1,2,4,8,16", help="comma-separated process counts (default 1,2,4,8,16)")
    parser.add_argument("--rounds", type=int, default=2, help="rounds per count; the best counts")
    parser.add_argument("--out", default="-", help="markdown file to write ('-' for stdout)")
    parser.add_argument("--pinned", action="store_true", help="add the pinned probe: pairs with CPU 0, groups of CPUs")
    args = parser.parse_args(argv)
    counts = [int(w) for w in args.workers.split(",")]
    for key in THREAD_LIMITS:  # before numpy is imported, as the batch command's workers start
        os.environ.setdefault(key, "1")

    from benchmarks.harness import machine
    from benchmarks.scale import generate
    from inertia.blocks import set_block_threads

    set_block_threads(1)
    with tempfile.TemporaryDirectory(prefix="inertia-ceiling-") as tmp:
        generate(Path(tmp) / "small", 1, 1280, seed=1)
        generate(Path(tmp) / "large", 1, 327680, seed=2)
        small, large = (str(next((Path(tmp) / name).glob("*.stl"))) for name in ("small", "large"))
        jobs: dict[str, Callable[[], None]] = {
            "python": _python_job,
            "small files (analyze, 1,280 triangles, x400)": _analyze_job(small, 400),
            "large file (analyze, 327,680 triangles, x3)": _analyze_job(large, 3),
            "memory (argsort of 4e6 doubles, x2)": _memory_job(),
        }
        for job in jobs.values():  # warm: imports, caches, the heap the children inherit
            job()
        rows = []
        for name, job in jobs.items():
            got = {n: timed(job, n, args.rounds) for n in counts}
            print(name, {n: (round(t.wall_s, 3), round(t.own_s, 3)) for n, t in got.items()}, file=sys.stderr, flush=True)
            rows.append((name, got))
    info = machine()
    head, top = counts[0], counts[-1]
    lines = [
        f"Regenerate: `python -m benchmarks.ceiling --workers {args.workers}`.",
        "",
        f"Machine: {info['cpu']}, {topology()}; os.cpu_count() = {os.cpu_count()}; Python {sys.version.split()[0]}.",
        f"Best of {args.rounds} round(s). t(N): from the release of N forked processes, each doing the job once, to the"
        " end of the last job (their exits not counted)."
        + (" Speed-up at N = N t(1) / t(N)." if head == 1 else f" Speed-up at N = N t({head}) / t(N), taking {head} as perfect.")
        + f" *Slowdown*: the slowest process's own time for the job at {top} processes over its time alone.",
        "",
        "| job | "
        + " | ".join(f"t({n}) (s)" for n in counts)
        + " | "
        + " | ".join(f"speed-up {n}" for n in counts)
        + f" | slowdown at {top} |",
        "|---|" + "---:|" * (2 * len(counts) + 1),
    ]
    for name, got in rows:
        t1 = got[head].wall_s
        lines.append(
            f"| {name} | "
            + " | ".join(f"{got[n].wall_s:.3f}" for n in counts)
            + " | "
            + " | ".join(f"{n * t1 / got[n].wall_s:.2f}x" for n in counts)
            + f" | {got[top].own_s / got[head].own_s:.2f} |"
        )
    if args.pinned:
        lines += pinned_probe(args.rounds)
    text = "\n".join(lines) + "\n"
    if args.out == "-":
        sys.stdout.write(text)
    else:
        Path(args.out).write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
