"""The benchmarks' one small harness: timing, rounds, memory, the machine, and the report.

Every benchmark under ``benchmarks/`` measures with these and writes its document through them,
so that each one states the same things the same way:

- ``Stopwatch()``: wall and CPU seconds since it was started (for a stretch of code);
- ``timed(call)``: wall and CPU seconds of an in-process call (``time.perf_counter`` and
  ``time.process_time``), and this process's peak resident set after it;
- ``best_of(call, repeat, budget_s)``: the least disturbed of several runs (timeit's rule: the
  minimum wall time), stopping early once ``budget_s`` is spent;
- ``run_process(args)``: a whole process from launch to exit: its wall time, the CPU time and
  peak resident set of it and every process it starts (sampled from ``/proc`` every
  ``SAMPLE_S``; the peak is the kernel's own high-water mark, ``VmHWM``, so no peak is missed
  between samples), its exit status and output;
- ``run_tool(args)``: one process's wall time, CPU time and its own peak resident set, exactly
  (GNU time's ``%M`` where ``/usr/bin/time`` exists: a child's ``ru_maxrss`` would include the
  high-water mark of a large parent it was forked from), for tools compared on memory;
- ``interleaved(contenders, rounds)``: rounds in which every contender runs once, their order
  rotated from round to round, and the best run of each kept: robust to a machine that is
  busy with other work for part of the time;
- ``Server``: a real ``python -m inertia serve`` process on a free loopback port, ready when
  ``/healthz`` answers (the tests' live servers are built on it);
- ``available_cores()`` and ``machine()``: what the run had to work with;
- ``byte_compiled()``: the package's modules compiled to bytecode, as an installation has them, so
  that a whole process of ours is not also timed compiling its sources (the peers' are compiled);
- ``Report``: a markdown document with a title, a header line that names the command that
  regenerates it and the machine, and ``write`` (the whole file, or only the section between
  ``START`` and ``END`` markers of a document that has prose around it).

Nothing here imports the service or the tests.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import platform
import resource
import shlex
import socket
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Callable, Hashable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import IO, Generic, TypeVar

__all__ = [
    "ROOT",
    "SAMPLE_S",
    "START",
    "END",
    "Stopwatch",
    "Timing",
    "timed",
    "best_of",
    "ProcStat",
    "proc_stat",
    "descendants",
    "TreeLog",
    "sampled",
    "ProcessRun",
    "run_process",
    "ToolRun",
    "run_tool",
    "available_memory",
    "Best",
    "interleaved",
    "free_port",
    "Server",
    "peak_rss_bytes",
    "available_cores",
    "load_average",
    "cpu_model",
    "machine",
    "byte_compiled",
    "command_line",
    "Report",
    "write_section",
]

ROOT = Path(__file__).resolve().parents[1]
SAMPLE_S = 0.05  # process-tree sampling period
START, END = "<!-- benchmark:start -->", "<!-- benchmark:end -->"

T = TypeVar("T")
K = TypeVar("K", bound=Hashable)


# ---------------------------------------------------------------------------
# in-process calls


@dataclass(frozen=True)
class Timing:
    """Wall and CPU seconds of one call, and this process's peak resident set after it [bytes]."""

    wall_s: float
    cpu_s: float
    peak_rss_bytes: int


class Stopwatch:
    """Wall seconds (``time.perf_counter``) and CPU seconds of this process (``time.process_time``) since creation."""

    def __init__(self) -> None:
        self._wall0, self._cpu0 = time.perf_counter(), time.process_time()

    @property
    def wall_s(self) -> float:
        return time.perf_counter() - self._wall0

    @property
    def cpu_s(self) -> float:
        return time.process_time() - self._cpu0


def peak_rss_bytes() -> int:
    """This process's peak resident set so far (``ru_maxrss``, KiB on Linux)."""
    return int(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss) * 1024


def timed(call: Callable[[], T]) -> tuple[T, Timing]:
    """``call()`` and its wall time, CPU time (this process, all threads) and the peak RSS after it."""
    clock = Stopwatch()
    out = call()
    wall, cpu = clock.wall_s, clock.cpu_s
    return out, Timing(wall, cpu, peak_rss_bytes())


def best_of(call: Callable[[], T], repeat: int = 1, budget_s: float = math.inf) -> tuple[T, Timing]:
    """The result and timing of the fastest of ``repeat`` runs of ``call`` (at least one; no new
    run starts once the runs so far took ``budget_s`` together)."""
    best: tuple[T, Timing] | None = None
    spent = 0.0
    for _ in range(max(1, repeat)):
        out, t = timed(call)
        if best is None or t.wall_s < best[1].wall_s:
            best = (out, t)
        spent += t.wall_s
        if spent > budget_s:
            break
    assert best is not None
    return best


# ---------------------------------------------------------------------------
# whole processes and their trees


@dataclass(frozen=True)
class ProcStat:
    """CPU seconds, peak and current resident set [bytes] and command line of one live process (``/proc``)."""

    cpu_s: float
    peak_rss_bytes: int
    command: str
    rss_bytes: int = 0


def _children() -> dict[int, list[int]]:
    kids: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as fh:
                    ppid = int(fh.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            kids.setdefault(ppid, []).append(int(entry))
    return kids


def descendants(pid: int) -> list[int]:
    """The processes started by ``pid``, and theirs, and so on (not ``pid`` itself)."""
    return [p for p in _tree([pid]) if p != pid]


def _tree(roots: Sequence[int]) -> list[int]:
    kids = _children()
    out, todo = [], list(roots)
    while todo:
        pid = todo.pop()
        out.append(pid)
        todo.extend(kids.get(pid, []))
    return out


def proc_stat(pid: int) -> ProcStat | None:
    """What ``/proc`` says of a live process (None once it is gone)."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            fields = fh.read().rsplit(")", 1)[1].split()
        cpu = (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
        hwm = rss = 0
        with open(f"/proc/{pid}/status") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    hwm = int(line.split()[1]) * 1024
                elif line.startswith("VmRSS:"):
                    rss = int(line.split()[1]) * 1024
        with open(f"/proc/{pid}/cmdline", "rb") as fh:
            cmd = fh.read().replace(b"\0", b" ").decode(errors="replace")
        return ProcStat(cpu, hwm, cmd, rss)
    except (OSError, IndexError, ValueError):
        return None


@dataclass
class TreeLog:
    """The last CPU time, peak RSS and command line seen of each process of sampled trees."""

    seen: dict[int, ProcStat] = field(default_factory=dict)
    start_cpu: dict[int, float] = field(default_factory=dict)

    def sample(self, roots: Sequence[int]) -> None:
        for pid in _tree(roots):
            got = proc_stat(pid)
            if got is not None:
                before = self.seen.get(pid)
                if before is not None and before.peak_rss_bytes > got.peak_rss_bytes:
                    # an exited process not yet reaped (a zombie) lists no VmHWM: keep the peak seen alive
                    got = dataclasses.replace(got, peak_rss_bytes=before.peak_rss_bytes)
                self.seen[pid] = got
                self.start_cpu.setdefault(pid, got.cpu_s)

    def cpu(self, pids: Sequence[int] | None = None) -> float:
        """CPU seconds the processes used while sampled (all of them by default)."""
        keys = list(self.seen) if pids is None else [p for p in pids if p in self.seen]
        return sum(self.seen[p].cpu_s - self.start_cpu[p] for p in keys)

    def peak(self, pids: Sequence[int] | None = None) -> int:
        """The largest peak RSS among the processes [bytes] (0 if none was seen)."""
        keys = list(self.seen) if pids is None else [p for p in pids if p in self.seen]
        return max((self.seen[p].peak_rss_bytes for p in keys), default=0)


@contextlib.contextmanager
def sampled(roots: Sequence[int], log: TreeLog, every_s: float = SAMPLE_S) -> Iterator[None]:
    """Sample the process trees under ``roots`` into ``log`` every ``every_s`` while the block runs."""
    stop = threading.Event()

    def loop() -> None:
        while not stop.is_set():
            log.sample(roots)
            stop.wait(every_s)

    thread = threading.Thread(target=loop, daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join()


@dataclass(frozen=True)
class ProcessRun:
    """One whole process, launch to exit: wall time, the CPU and peak RSS of its tree, its output.

    ``tree`` holds what was last seen of each process (the command's own is ``pid``; with
    ``extra_roots`` their trees too), ``cpu_s`` is the CPU time of them all while it ran.
    """

    args: tuple[str, ...]
    pid: int
    returncode: int
    wall_s: float
    cpu_s: float
    stdout: str
    stderr: str
    tree: TreeLog

    @property
    def own_cpu_s(self) -> float:
        """CPU seconds of the command's own process."""
        return self.tree.cpu([self.pid])

    @property
    def peak_rss_bytes(self) -> int:
        """The largest peak RSS of any process of the tree [bytes]."""
        return self.tree.peak()


def run_process(
    args: Sequence[str],
    *,
    cwd: Path = ROOT,
    env: Mapping[str, str] | None = None,
    extra_roots: Sequence[int] = (),
    check: bool = True,
    timeout_s: float | None = None,
) -> ProcessRun:
    """Run ``args`` to its end, sampling its process tree (and ``extra_roots``' trees, whose CPU counts
    from now): a non-zero exit raises ``RuntimeError`` with the end of its stderr when ``check``."""
    log = TreeLog()
    if extra_roots:
        log.sample(extra_roots)
    clock = Stopwatch()
    proc = subprocess.Popen(
        list(args), cwd=cwd, env=None if env is None else dict(env), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    with sampled([proc.pid, *extra_roots], log):
        try:
            out, err = proc.communicate(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            proc.kill()
            out, err = proc.communicate()
            raise RuntimeError(f"`{command_line(args)}` ran past {timeout_s} s:\n{err[-3000:]}") from None
    wall = clock.wall_s
    if check and proc.returncode != 0:
        raise RuntimeError(f"`{command_line(args)}` failed (exit {proc.returncode}):\n{err[-3000:]}")
    return ProcessRun(tuple(args), proc.pid, proc.returncode, wall, log.cpu(), out, err, log)


GNU_TIME = "/usr/bin/time"


@dataclass(frozen=True)
class ToolRun:
    """Wall time, the process's own peak RSS [bytes], its stdout and its CPU time (user + system)."""

    wall_s: float
    peak_rss_bytes: int
    stdout: str
    cpu_s: float


def run_tool(args: Sequence[str]) -> ToolRun:
    """Run ``args`` to its end; a non-zero exit raises ``RuntimeError`` with the end of its stderr.

    Linux carries a process's high-water RSS across fork and exec into the child's ``ru_maxrss``,
    so a child of a large benchmark process would report at least that process's own peak.  GNU
    time, itself tiny, forks the tool and reports the tool's own peak; without it, ``os.wait4``.
    """
    import tempfile

    cmd = list(args)
    wrapped = os.path.exists(GNU_TIME)
    with tempfile.TemporaryFile() as out, tempfile.NamedTemporaryFile("r") as rss_file:
        full = [GNU_TIME, "-f", "%M %U %S", "-o", rss_file.name, *cmd] if wrapped else cmd
        clock = Stopwatch()
        proc = subprocess.Popen(full, stdout=out, stderr=subprocess.PIPE)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = clock.wall_s
        proc.returncode = os.waitstatus_to_exitcode(status)
        err = proc.stderr.read().decode() if proc.stderr else ""
        if proc.stderr:
            proc.stderr.close()
        if proc.returncode != 0:
            raise RuntimeError(f"{cmd[:3]} failed ({proc.returncode}): {err[-2000:]}")
        if wrapped:
            fields = rss_file.read().split()[-3:]
            peak_kb, cpu = int(fields[0]), float(fields[1]) + float(fields[2])
        else:
            peak_kb, cpu = usage.ru_maxrss, usage.ru_utime + usage.ru_stime
        out.seek(0)
        return ToolRun(wall, peak_kb * 1024, out.read().decode(), cpu)


def available_memory() -> int:
    """MemAvailable of /proc/meminfo in bytes (0 where unknown)."""
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return 0


# ---------------------------------------------------------------------------
# rounds


@dataclass
class Best(Generic[K, T]):
    """The best result of each contender over interleaved rounds, and every result of each."""

    best: dict[K, T] = field(default_factory=dict)
    runs: dict[K, list[T]] = field(default_factory=dict)


def interleaved(
    contenders: Sequence[tuple[K, Callable[[], T]]],
    rounds: int,
    wall: Callable[[K, T], float],
    after_round: Callable[[int, dict[K, T]], None] | None = None,
    before_round: Callable[[int], None] | None = None,
    rotate: int = 1,
) -> Best[K, T]:
    """``rounds`` rounds, every contender once in each, the order rotated by ``rotate`` places from
    round to round; the best of each contender is the one with the least ``wall(name, result)``.
    ``before_round(r)`` runs first in each round (e.g. ``available_cores``), ``after_round(r, got)``
    sees each round's results (to print progress)."""
    out: Best[K, T] = Best()
    for r in range(rounds):
        if before_round is not None:
            before_round(r)
        k = (r * rotate) % len(contenders) if contenders else 0
        got: dict[K, T] = {}
        for name, run in [*contenders[k:], *contenders[:k]]:
            got[name] = run()
            out.runs.setdefault(name, []).append(got[name])
            if name not in out.best or wall(name, got[name]) < wall(name, out.best[name]):
                out.best[name] = got[name]
        if after_round is not None:
            after_round(r, got)
    return out


# ---------------------------------------------------------------------------
# a live server


def free_port(host: str = "127.0.0.1") -> int:
    """A port nobody listens on right now."""
    with socket.socket() as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


def serve_command(host: str, port: int) -> list[str]:
    """``python -m inertia serve`` on ``host:port``."""
    return [sys.executable, "-m", "inertia", "serve", "--host", host, "--port", str(port)]


class Server:
    """A server process on a free loopback port, with the given ``INERTIA_*`` environment (the
    caller's own ``INERTIA_*`` variables are dropped), ready once ``/healthz`` answers 200.

    Its output goes to ``log_dir/<log_name>-<port>.log`` (read back by :meth:`output`), or nowhere
    without ``log_dir``. ``command(host, port)`` gives its command line (``python -m inertia serve``
    by default), run in ``cwd`` (the repository root by default). A server that does not come up
    leaves no process or open file behind.
    """

    def __init__(
        self,
        env: Mapping[str, str] | None = None,
        *,
        startup_s: float = 30.0,
        log_dir: Path | None = None,
        log_name: str = "serve",
        command: Callable[[str, int], list[str]] = serve_command,
        host: str = "127.0.0.1",
        cwd: Path = ROOT,
    ) -> None:
        self.port = free_port(host)
        self.url = f"http://{host}:{self.port}"
        full_env = {k: v for k, v in os.environ.items() if not k.startswith("INERTIA_")}
        full_env.update(env or {})
        self.log: IO[bytes] | None = None
        if log_dir is not None:
            log_dir.mkdir(parents=True, exist_ok=True)
            self.log = open(log_dir / f"{log_name}-{self.port}.log", "w+b")  # noqa: SIM115  (open until stop())
        self.process = subprocess.Popen(
            command(host, self.port),
            cwd=cwd,
            env=full_env,
            stdout=self.log if self.log is not None else subprocess.DEVNULL,
            stderr=subprocess.STDOUT,
        )
        try:
            self._wait_ready(startup_s)
        except BaseException:
            self.stop()
            raise

    def _wait_ready(self, startup_s: float) -> None:
        deadline = time.monotonic() + startup_s
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise RuntimeError(f"server exited: {self.output()}")
            try:
                with urllib.request.urlopen(f"{self.url}/healthz", timeout=1.0) as reply:
                    if reply.status == 200:
                        return
            except (urllib.error.URLError, OSError):
                time.sleep(0.1)
        raise RuntimeError(f"server did not start in {startup_s} s: {self.output()}")

    def output(self) -> str:
        """What the server wrote so far (empty without a log)."""
        if self.log is None:
            return ""
        self.log.flush()
        self.log.seek(0)
        return self.log.read().decode(errors="replace")

    def stop(self) -> None:
        self.process.terminate()
        try:
            self.process.wait(10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        if self.log is not None:
            self.log.close()

    def __enter__(self) -> Server:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        self.stop()


# ---------------------------------------------------------------------------
# the machine

_SPIN = "import time\nt = time.perf_counter()\nwhile time.perf_counter() - t < {s}: pass\nprint(time.process_time())"


def available_cores(processes: int = 2, seconds: float = 1.0) -> float:
    """CPU seconds per second that ``processes`` busy processes of this session get right now.

    2.0 on an idle 2-core machine.  With the kernel's autogroup scheduling, a
    busy session elsewhere cuts it towards 1.0, whatever the number of our
    processes: parallel speed-ups are then capped.
    """
    procs = [
        subprocess.Popen([sys.executable, "-c", _SPIN.format(s=seconds)], stdout=subprocess.PIPE, text=True)
        for _ in range(processes)
    ]
    cpu = sum(float(p.communicate()[0]) for p in procs)
    return cpu / seconds


def load_average() -> float:
    """The 1-minute load average (0 where the system has none)."""
    try:
        return os.getloadavg()[0]
    except OSError:
        return 0.0


def cpu_model() -> str:
    """The CPU's model name (``/proc/cpuinfo``), else what ``platform`` knows."""
    with contextlib.suppress(OSError), open("/proc/cpuinfo") as fh:
        for line in fh:
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.processor() or platform.machine()


def machine(packages: Sequence[str] = ()) -> dict[str, str]:
    """CPU model, cores (all, and usable by this process), Python, load average, and the versions of ``packages``."""
    import importlib.metadata as md

    versions = {}
    for pkg in packages:
        try:
            versions[pkg] = md.version(pkg)
        except md.PackageNotFoundError:
            versions[pkg] = "not installed"
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return {
        "cpu": cpu_model(),
        "cores": str(os.cpu_count()),
        "usable": str(usable),
        "python": platform.python_version(),
        "load": f"{load_average():.2f}",
        **versions,
    }


def byte_compiled(package: str = "inertia") -> str:
    """Compile ``package``'s modules to bytecode where they lie, and say so in a sentence for the report.

    ``pip install .`` compiles every module when it installs it, and the peers (trimesh, numpy-stl, Dask) were
    installed that way; a checkout installed in editable mode, in an environment with
    ``PYTHONDONTWRITEBYTECODE`` set, compiles ours from source at every start of every process (some 20-80 ms
    each), which is not what a user's process pays.  The package is located without being imported.
    """
    import compileall
    import importlib.util

    spec = importlib.util.find_spec(package)
    folders = list(spec.submodule_search_locations or []) if spec is not None else []
    if not folders:
        return f"{package} was not found, so its modules were not compiled first"
    ok = all(compileall.compile_dir(folder, quiet=1) for folder in folders)
    return (
        f"{package}'s modules were compiled to bytecode first, as an installation has them"
        if ok
        else f"{package}'s modules could not all be compiled to bytecode; some were compiled at each start"
    )


def command_line(args: Sequence[str]) -> str:
    """``args`` as one shell-quoted line."""
    return shlex.join(list(args))


# ---------------------------------------------------------------------------
# the report


@dataclass
class Report:
    """A markdown document: ``# title``, then the lines added, with ``regenerate`` (the command
    that writes it, run from the repository root) stated where the benchmark puts it."""

    title: str
    regenerate: str
    lines: list[str] = field(default_factory=list)

    def add(self, *lines: str) -> None:
        self.lines.extend(lines)

    def regenerate_line(self, needs: str = "") -> str:
        """``Regenerate: `command` (from the repository root[; needs ...]).``"""
        return f"Regenerate: `{self.regenerate}` (from the repository root{'; ' + needs if needs else ''})."

    def text(self) -> str:
        body = "\n".join(self.lines).rstrip("\n")
        return f"# {self.title}\n\n{body}\n" if self.title else f"{body}\n"

    def write(self, path: Path, section: bool = False) -> None:
        """Write the document to ``path``; with ``section``, only between the markers (see ``write_section``)."""
        if section:
            write_section(path, self.text())
        else:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(self.text(), encoding="utf-8")


def write_section(path: Path, text: str) -> None:
    """Replace the benchmark section of ``path`` (between ``START`` and ``END``), or append it to the file."""
    section = f"{START}\n{text.rstrip()}\n{END}"
    old = path.read_text(encoding="utf-8") if path.exists() else ""
    if START in old and END in old:
        new = old[: old.index(START)] + section + old[old.index(END) + len(END) :]
    else:
        new = old + ("\n" if old else "") + section + "\n"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(new, encoding="utf-8")
