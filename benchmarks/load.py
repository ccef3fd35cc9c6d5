"""Load on the running HTTP server, on loopback only, with a bare FastAPI route as the peer in the same run.

    python -m benchmarks.load                     # writes docs/load.md (about 3 minutes)
    python -m benchmarks.load --seconds 4 --doc /tmp/load.md   # shorter

Starts one server (``create_app`` under uvicorn on 127.0.0.1, a free port, default settings, two compute
processes) with one extra route, ``POST /bench/bare``, an ``async def`` that returns a constant dict:
what FastAPI and the same middleware cost without our work. Then, with a bounded number of concurrent
clients (asyncio + httpx, keep-alive) and a bounded duration per phase, it measures:

- ``bare`` and ``points`` (3 point masses, ``/v1/analyze/points``) in interleaved rounds: requests/s,
  p50/p99 latency, and the ratio points/bare of each round;
- ``small meshes``: the 12-triangle box of ``sample_meshes/`` on ``/v1/analyze/mesh``;
- ``mix``: clients sending points and small meshes while two more send 1,000,000-triangle binary STLs
  (48 MB each), with ``/healthz`` latency.

Every reply is checked (status 200 and a ``mass``, or ``status: ok``); any other status counts as an error.
The server's resident memory and that of its compute processes are sampled every 0.5 s throughout.
The machine may be shared: absolute numbers are noisy, the ratio within a round is what counts.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import statistics
import sys
import tempfile
import threading
import time
from collections.abc import Awaitable, Callable, Iterator
from contextlib import contextmanager, suppress
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import httpx

from benchmarks.cases import stl_bytes, torus
from benchmarks.harness import Report, Server, Stopwatch, descendants, interleaved, load_average, proc_stat

ROOT = Path(__file__).resolve().parents[1]
HOST = "127.0.0.1"  # loopback only
POINTS = {
    "points": [{"mass": 1.0, "position": [0, 0, 0]}, {"mass": 2.0, "position": [1, 0, 0]}, {"mass": 1.0, "position": [0, 1, 0]}]
}
SERVER = """
import sys, uvicorn
from inertia.api import Settings, create_app
app = create_app(Settings())

@app.post("/bench/bare")
async def bare() -> dict[str, str]:
    return {"status": "ok"}

uvicorn.run(app, host=sys.argv[1], port=int(sys.argv[2]), log_level="warning", access_log=False)
"""


@dataclass
class Phase:
    name: str
    latencies: list[float] = field(default_factory=list)
    errors: int = 0
    seconds: float = 0.0
    cpu_s: float = 0.0  # CPU time the server process used during the phase

    @property
    def cpu_ms_per_request(self) -> float:
        return 1e3 * self.cpu_s / len(self.latencies) if self.latencies else float("nan")

    @property
    def rate(self) -> float:
        return len(self.latencies) / self.seconds if self.seconds else 0.0

    def quantile(self, q: float) -> float:
        if not self.latencies:
            return float("nan")
        ordered = sorted(self.latencies)
        return ordered[min(len(ordered) - 1, int(q * len(ordered)))] * 1e3


def _server_command(host: str, port: int) -> list[str]:
    return [sys.executable, "-c", SERVER, host, str(port)]


def running_server() -> Server:
    """The server (``SERVER``) on a free loopback port, ready; stop it with ``with``."""
    return Server(startup_s=60.0, command=_server_command, host=HOST)


def _rss_mib(pid: int) -> float:
    stat = proc_stat(pid)
    return stat.rss_bytes / 2**20 if stat else 0.0


def _cpu_s(pid: int) -> float:
    """User + system CPU time of one process [s]."""
    stat = proc_stat(pid)
    return stat.cpu_s if stat else 0.0


class MemorySampler(threading.Thread):
    """(seconds since start, phase, server MiB, compute processes MiB) every 0.5 s."""

    def __init__(self, pid: int) -> None:
        super().__init__(daemon=True)
        self.pid, self.phase = pid, "start"
        self.pinning = "not pinned"
        self.samples: list[tuple[float, str, float, float]] = []
        self.done = threading.Event()
        self.start_time = time.monotonic()

    def run(self) -> None:
        while not self.done.wait(0.5):
            workers = sum(_rss_mib(p) for p in descendants(self.pid))
            self.samples.append((time.monotonic() - self.start_time, self.phase, _rss_mib(self.pid), workers))


Request = Callable[[httpx.AsyncClient], Awaitable[bool]]


async def _drive(url: str, phase: Phase, request: Request, clients: int, seconds: float) -> None:
    stop = time.monotonic() + seconds

    async def client() -> None:
        async with httpx.AsyncClient(base_url=url, timeout=120) as c:
            while time.monotonic() < stop:
                start = time.perf_counter()
                try:
                    ok = await request(c)
                except httpx.HTTPError:
                    ok = False
                if ok:
                    phase.latencies.append(time.perf_counter() - start)
                else:
                    phase.errors += 1

    start = time.monotonic()
    await asyncio.gather(*(client() for _ in range(clients)))
    phase.seconds = time.monotonic() - start


async def _points(c: httpx.AsyncClient) -> bool:
    r = await c.post("/v1/analyze/points", json=POINTS)
    return r.status_code == 200 and r.json()["mass"] == 4.0


BOX = (ROOT / "sample_meshes" / "box.stl").read_bytes()


async def _box(c: httpx.AsyncClient) -> bool:
    r = await c.post("/v1/analyze/mesh", files={"file": ("box.stl", BOX)})
    return r.status_code == 200 and "mass" in r.json()


def _cpu_us(fns: dict[str, Callable[[], object]], number: int = 200, repeat: int = 7) -> dict[str, float]:
    """CPU microseconds of one call of each function: the best of ``repeat`` batches, taken in turn (so
    that a busy moment of the shared machine hits every function alike, not one of them)."""

    def batch(fn: Callable[[], object]) -> float:
        clock = Stopwatch()
        for _ in range(number):
            fn()
        return clock.cpu_s / number

    rounds = interleaved([(name, partial(batch, fn)) for name, fn in fns.items()], repeat, lambda _name, t: t, rotate=0)
    return {name: 1e6 * t for name, t in rounds.best.items()}


def in_process_breakdown() -> list[tuple[str, float]]:
    """Where a 3-point request's CPU goes, measured in this process without sockets (hot caches).

    The app is called as an ASGI callable, so uvicorn's HTTP parsing and the socket writes (common to
    both routes) are left out; the access log is off, and what start-up built is frozen out of the
    collector's sight as the server's lifespan does.  The lane's steps are then timed alone.
    """
    import gc
    import logging

    from pydantic_core import to_json

    from inertia.api import Settings, create_app, lane
    from inertia.api.jobs import PointsJob, run_job_json
    from inertia.api.lane import _small_job
    from inertia.api.schemas import PointsRequest
    from inertia.few_points import few_points_document
    from inertia.mass.refine import refine_few_points
    from inertia.tolerances import DEFAULT_TOLERANCES

    app = create_app(Settings())

    @app.post("/bench/bare")
    async def bare() -> dict[str, str]:
        return {"status": "ok"}

    body = json.dumps(POINTS).encode()

    async def call(path: str) -> None:
        scope = {
            "type": "http",
            "asgi": {"version": "3.0"},
            "http_version": "1.1",
            "method": "POST",
            "scheme": "http",
            "path": path,
            "raw_path": path.encode(),
            "query_string": b"",
            "root_path": "",
            "headers": [(b"host", HOST.encode()), (b"content-type", b"application/json"), (b"content-length", b"%d" % len(body))],
            "client": (HOST, 1),
            "server": (HOST, 8000),
        }
        sent = False

        async def receive() -> dict[str, object]:
            nonlocal sent
            if sent:
                await asyncio.sleep(3600)
            sent = True
            return {"type": "http.request", "body": body, "more_body": False}

        async def send(message: object) -> None:
            return None

        await app(scope, receive, send)

    request = PointsRequest.model_validate_json(body)
    records, options = request.records(), request.as_options()
    job = PointsJob(records, options)
    masses = [float(r["mass"]) for r in records]
    positions = [[float(c) for c in r["position"]] for r in records]
    access = logging.getLogger("inertia.api.access")
    disabled, access.disabled = access.disabled, True
    loop = asyncio.new_event_loop()
    reply = run_job_json(job, to_json)

    async def constant_call() -> None:  # the lane's own path, with the analysis's bytes made in advance
        names = vars(lane)
        analysis, names["run_job_json"] = names["run_job_json"], lambda _job, _dumps: reply
        try:
            await call("/v1/analyze/points")
        finally:
            names["run_job_json"] = analysis

    gc.collect()
    gc.freeze()
    try:
        t = _cpu_us(
            {
                "bare": lambda: loop.run_until_complete(call("/bench/bare")),
                "points": lambda: loop.run_until_complete(call("/v1/analyze/points")),
                "constant": lambda: loop.run_until_complete(constant_call()),
                "parse": lambda: _small_job(body),
                "run_job_json": lambda: run_job_json(job, to_json),
                "document": lambda: few_points_document(records, options),
                "refine": lambda: refine_few_points(masses, positions, DEFAULT_TOLERANCES),
            }
        )
    finally:
        gc.unfreeze()
        loop.close()
        access.disabled = disabled
    return [
        ("bare route (ASGI call, no sockets)", t["bare"]),
        ("/v1/analyze/points (ASGI call, no sockets)", t["points"]),
        ("the same with the analysis's reply made in advance (the lane and the middleware alone)", t["constant"]),
        ("of which the body: the route's model from the JSON text, the job (`api.lane`)", t["parse"]),
        ("of which the analysis and its JSON: `run_job_json` (load, mass, frame, class, result, checks)", t["run_job_json"]),
        ("... of it `few_points_document` (the analysis and its document, before the JSON)", t["document"]),
        ("... ... of it `refine_few_points` (the two or three passes)", t["refine"]),
        ("remainder: the analysis running colder inside a request", t["points"] - t["constant"] - t["run_job_json"]),
    ]


def _load(values: tuple[float, float, float]) -> str:
    return ", ".join(f"{v:.1f}" for v in values) + f" on {os.cpu_count()} cores"


def _torus_stl(n: int, m: int) -> bytes:
    """Binary STL of a closed torus (R = 2, r = 0.5) of 2 n m triangles (``benchmarks.cases.torus``)."""
    return stl_bytes(*torus(n, m, 2.0, 0.5))


def _row(p: Phase) -> str:
    return f"| {p.name} | {len(p.latencies)} | {p.rate:.0f} | {p.quantile(0.5):.1f} | {p.quantile(0.99):.1f} | {p.errors} |"


def _raw_request(path: str) -> bytes:
    body = json.dumps(POINTS).encode()
    head = f"POST {path} HTTP/1.1\r\nhost: {HOST}\r\ncontent-type: application/json\r\ncontent-length: {len(body)}\r\n\r\n"
    return head.encode() + body


SMALL_ROUTES = {"bare": ("/bench/bare", b'"status":"ok"'), "points": ("/v1/analyze/points", b'"mass":4.0,')}
"""The two routes of the small-request rounds, and a piece of text each reply must hold."""


async def _drive_raw(url: str, phase: Phase, route: str, clients: int, seconds: float) -> None:
    """``clients`` keep-alive connections sending one prebuilt request after another for ``seconds``.

    A plain asyncio stream client: it writes the request's bytes and reads the reply by its
    Content-Length, a few tens of microseconds per request, so the server's own cost sets the rate
    (httpx spends about as much CPU per request as the bare route itself, and on two shared cores the
    client then limits both routes alike, which hides the difference between them).
    """
    path, expect = SMALL_ROUTES[route]
    request = _raw_request(path)
    host, port = url.rsplit(":", 1)[0].removeprefix("http://"), int(url.rsplit(":", 1)[1])
    stop = time.monotonic() + seconds

    async def client() -> None:
        reader, writer = await asyncio.open_connection(host, port)
        try:
            while time.monotonic() < stop:
                start = time.perf_counter()
                writer.write(request)
                head = await reader.readuntil(b"\r\n\r\n")
                at = head.lower().find(b"content-length:")
                length = int(head[at + 15 : head.index(b"\r\n", at)]) if at >= 0 else 0
                reply = await reader.readexactly(length)
                if head.startswith(b"HTTP/1.1 200") and expect in reply:
                    phase.latencies.append(time.perf_counter() - start)
                else:
                    phase.errors += 1
        finally:
            writer.close()

    start = time.monotonic()
    await asyncio.gather(*(client() for _ in range(clients)))
    phase.seconds = time.monotonic() - start


@contextmanager
def _pinned(server_pid: int) -> Iterator[str]:
    """The server on the last core and this process (the load generator) on the others, where the
    platform allows it and there are at least two cores; yields a sentence saying which."""
    setter = getattr(os, "sched_setaffinity", None)
    cores = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    if setter is None or len(cores) < 2:
        yield "not pinned (fewer than two cores, or no CPU affinity on this platform)"
        return
    mine = set(cores)
    try:
        setter(server_pid, {cores[-1]})
        setter(0, set(cores[:-1]))
    except OSError:
        yield "not pinned (the platform refused CPU affinity)"
        return
    try:
        yield f"the server's process pinned to core {cores[-1]}, the load generator to core(s) {', '.join(map(str, cores[:-1]))}"
    finally:
        setter(0, mine)
        with suppress(OSError):
            setter(server_pid, mine)


async def measure_pairs(url: str, sampler: MemorySampler, seconds: float, rounds: int, clients: int) -> list[tuple[Phase, Phase]]:
    """Interleaved rounds of the bare route and 3-point requests, with the server's CPU time of each phase."""
    pid = sampler.pid
    pairs = []
    with _pinned(pid) as pinning:
        sampler.pinning = pinning
        for k in range(rounds):  # interleaved, order alternating, so drift of the shared machine hits both
            order = ["bare", "points"]
            if k % 2:
                order.reverse()
            got = {}
            for name in order:
                sampler.phase = name
                got[name] = Phase(f"{name} (round {k + 1})")
                cpu = _cpu_s(pid)
                await _drive_raw(url, got[name], name, clients, seconds)
                got[name].cpu_s = _cpu_s(pid) - cpu
            pairs.append((got["bare"], got["points"]))
    return pairs


async def measure(url: str, sampler: MemorySampler, seconds: float, rounds: int, clients: int, big: bytes) -> dict[str, object]:
    pairs = await measure_pairs(url, sampler, seconds, rounds, clients)
    sampler.phase = "small meshes"
    small = Phase("small meshes (box.stl)")
    await _drive(url, small, _box, clients, seconds)

    sampler.phase = "mix"
    mix_points, mix_small, mix_big, health = (
        Phase("mix: points"),
        Phase("mix: small meshes"),
        Phase("mix: 1e6-triangle meshes"),
        Phase("mix: /healthz"),
    )

    async def _big(c: httpx.AsyncClient) -> bool:
        r = await c.post("/v1/analyze/mesh", files={"file": ("torus.stl", big)})
        return r.status_code == 200 and "mass" in r.json()

    async def _health(c: httpx.AsyncClient) -> bool:
        await asyncio.sleep(0.2)
        return (await c.get("/healthz")).status_code == 200

    mix_seconds = max(3 * seconds, 20.0)
    await asyncio.gather(
        _drive(url, mix_points, _points, max(1, clients // 2), mix_seconds),
        _drive(url, mix_small, _box, max(1, clients // 2), mix_seconds),
        _drive(url, mix_big, _big, 2, mix_seconds),
        _drive(url, health, _health, 1, mix_seconds),
    )
    sampler.phase = "end"
    return {"pairs": pairs, "small": small, "mix": [mix_points, mix_small, mix_big, health]}


def report(result: dict[str, object], sampler: MemorySampler, args: argparse.Namespace, wall: float) -> Report:
    pairs = result["pairs"]
    assert isinstance(pairs, list)
    ratios = [p.rate / b.rate for b, p in pairs]
    cpu_ratios = [b.cpu_ms_per_request / p.cpu_ms_per_request for b, p in pairs]
    bare_ms = statistics.median(b.cpu_ms_per_request for b, _ in pairs)
    points_ms = statistics.median(p.cpu_ms_per_request for _, p in pairs)
    command = (
        "python -m benchmarks.load"
        + (f" --seconds {args.seconds:g}" if args.seconds != 8 else "")
        + (f" --rounds {args.rounds}" if args.rounds != 5 else "")
    )
    out = Report("Load on the HTTP server", command)
    lines = [
        f"Generated by `{command}` "
        f"({time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {wall:.0f} s). One server on 127.0.0.1 with "
        f"default settings ({os.cpu_count()} cores, two compute processes) and an extra `POST /bench/bare` route "
        f"(an `async def` returning a constant, behind the same middleware): the peer in the same run. "
        f"{args.clients} concurrent keep-alive clients in one process on the same machine, "
        f"{args.seconds:g} s per phase. The machine is shared with other work: absolute rates are noisy; "
        "the ratio within each round is the figure that counts. "
        f"Load average (1, 5, 15 min) at the start: {_load(args.load_before)}; at the end: {_load(args.load_after)}.",
        "",
        "## Small requests against the bare route",
        "",
        "| phase | requests | requests/s | p50 [ms] | p99 [ms] | errors | server CPU per request [ms] |",
        "|---|---|---|---|---|---|---|",
    ]
    for b, p in pairs:
        lines += [_row(b) + f" {b.cpu_ms_per_request:.2f} |", _row(p) + f" {p.cpu_ms_per_request:.2f} |"]
    lines += [
        "",
        "Points/bare throughput per round: "
        + ", ".join(f"{r:.2f}" for r in ratios)
        + f"; median **{statistics.median(ratios):.2f}** (goal: at least 0.70).",
        "",
        "The same comparison by the server's own CPU time per request (bare / points: the throughput "
        "ratio one server core would reach, independent of the client's share of the machine): "
        + ", ".join(f"{r:.2f}" for r in cpu_ratios)
        + f"; median **{statistics.median(cpu_ratios):.2f}**.",
        "",
        f"What the goal asks of the analysis: at 0.70 a 3-point request may cost the server at most "
        f"{1 / 0.7:.2f} times the bare route's {bare_ms:.2f} ms (medians), which leaves {0.3 / 0.7 * bare_ms:.2f} ms "
        f"for everything the points route does beyond it; it takes {points_ms - bare_ms:.2f} ms.",
        "",
        "The rounds of one run spread widely on this shared machine (a round's ratio moves by 0.1-0.2 between "
        "rounds of the same build), hence five rounds and their median.",
        "",
        f"The small-request rounds use a plain asyncio stream client (prebuilt request bytes, the reply read by "
        f"its Content-Length and checked for status 200 and its `mass` or `status`), so that the server, not "
        f"the load generator, sets the rate of both routes: {sampler.pinning}. The two ratios then agree; "
        "where they differ, the client or the machine's other work limited a phase.",
        "",
        "Requests of at most 1,000 point masses without a trajectory (and precession without samples) run in the "
        "server process; every other job goes to a compute process. A small, valid JSON points request is "
        "answered by `api.lane`, an ASGI layer behind the access log and the API-key and size guard, in front of "
        "FastAPI's router: the route's own model validates the body (pydantic's JSON parser, one pass) and "
        "`run_job_json` writes the route's own response, without the routing, dependency resolution and request "
        "object (every other request, errors included, goes on to FastAPI). Up to 16 point masses with plain "
        "options (no section beyond the default ones) and no warning are analysed by `few_points.few_points_document`, "
        "the same document byte for byte from the same kernels on Python floats, without the general pipeline's "
        "bodies, sums and result objects. The server freezes what start-up built (`gc.freeze`), so the full "
        "collections that small requests trigger no longer walk every module and schema of the process.",
        "",
        "### Where a 3-point request's CPU goes",
        "",
        "Measured in the benchmark's own process after the server run: the app called as an ASGI callable "
        "(no sockets, no uvicorn, access log off, hot caches), best of 7 batches of 200 calls, the parts "
        "measured in turn. In the server "
        "above every figure is larger (uvicorn's HTTP parsing and the socket writes come on top of both routes, "
        "and caches are shared with the load generator), so read the rows as proportions.",
        "",
        "| part | CPU per request [us] |",
        "|---|---|",
    ]
    breakdown = result.get("breakdown", [])
    assert isinstance(breakdown, list)
    lines += [f"| {name} | {us:.0f} |" for name, us in breakdown]
    if len(breakdown) > 2:
        parts = dict(breakdown)
        lane_us, bare_us = parts[breakdown[2][0]], parts[breakdown[0][0]]
        lines += [
            "",
            f"Without its analysis a points request costs {lane_us:.0f} us here, "
            + ("less than" if lane_us < bare_us else "about as much as")
            + f" the bare route's {bare_us:.0f} us: what separates the two routes is the analysis itself "
            "(the refinement passes, the principal frame, the class, the result document).",
        ]
    lines += [
        "",
        "## Small meshes, and a mix with 1,000,000-triangle meshes",
        "",
        "| phase | requests | requests/s | p50 [ms] | p99 [ms] | errors |",
        "|---|---|---|---|---|---|",
    ]
    small = result["small"]
    mix = result["mix"]
    assert isinstance(small, Phase) and isinstance(mix, list)
    lines += [_row(small)] + [_row(p) for p in mix]
    errors = sum(p.errors for b, q in pairs for p in (b, q)) + small.errors + sum(p.errors for p in mix)
    lines += [
        "",
        f"Errors in the whole run: **{errors}**.",
        "",
        "In the mix, two clients upload 48 MB binary STLs (1,000,000 triangles) back to back while the others "
        "send points and small meshes; `/healthz` is polled every 0.2 s. Small meshes share the two compute "
        "processes with the large ones, so their latency in the mix is bounded by the large jobs' turns.",
        "",
        "## Memory over time",
        "",
        "Resident memory of the server process and of its compute processes together, every 2 s.",
        "",
        "| t [s] | phase | server [MiB] | compute processes [MiB] |",
        "|---|---|---|---|",
    ]
    last = -10.0
    for t, phase, server, workers in sampler.samples:
        if t - last >= 2.0:
            lines.append(f"| {t:.0f} | {phase} | {server:.0f} | {workers:.0f} |")
            last = t
    peak_server = max((s[2] for s in sampler.samples), default=0.0)
    peak_workers = max((s[3] for s in sampler.samples), default=0.0)
    lines += ["", f"Peaks: server {peak_server:.0f} MiB, compute processes together {peak_workers:.0f} MiB."]
    out.add(*lines)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=8.0, help="duration of each phase [s]")
    parser.add_argument("--rounds", type=int, default=5, help="interleaved bare/points rounds")
    parser.add_argument("--clients", type=int, default=8, help="concurrent clients (at most 64)")
    parser.add_argument("--doc", type=Path, default=ROOT / "docs" / "load.md")
    parser.add_argument(
        "--small-only", action="store_true", help="only the bare/points rounds, printed; docs/load.md is not written"
    )
    args = parser.parse_args()
    args.clients = max(1, min(64, args.clients))
    if args.small_only:
        with running_server() as server:
            sampler = MemorySampler(server.process.pid)
            sampler.start()
            try:
                pairs = asyncio.run(measure_pairs(server.url, sampler, args.seconds, args.rounds, args.clients))
            finally:
                sampler.done.set()
                sampler.join()
        for b, p in pairs:
            print(_row(b) + f" {b.cpu_ms_per_request:.2f} |\n" + _row(p) + f" {p.cpu_ms_per_request:.2f} |")
        print("throughput ratios", [round(p.rate / b.rate, 2) for b, p in pairs])
        print("CPU ratios", [round(b.cpu_ms_per_request / p.cpu_ms_per_request, 2) for b, p in pairs])
        print("load average", load_average())
        return
    args.load_before = os.getloadavg()
    big = _torus_stl(707, 707)  # 999,698 triangles
    clock = Stopwatch()
    with running_server() as server:
        sampler = MemorySampler(server.process.pid)
        sampler.start()
        try:
            result = asyncio.run(measure(server.url, sampler, args.seconds, args.rounds, args.clients, big))
        finally:
            sampler.done.set()
            sampler.join()
    args.load_after = os.getloadavg()
    result["breakdown"] = in_process_breakdown()
    doc = report(result, sampler, args, clock.wall_s)
    doc.write(args.doc)
    print(doc.text())


if __name__ == "__main__":
    with tempfile.TemporaryDirectory():
        main()
