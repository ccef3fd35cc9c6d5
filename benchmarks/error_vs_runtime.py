"""Work-precision benchmark of the torque-free motion methods, and mesh tessellation error.

Regenerate ``docs/error-vs-runtime.md`` and ``docs/error-vs-runtime.png`` from the repo root with

    python -m benchmarks.error_vs_runtime
    python -m benchmarks.error_vs_runtime --quick --doc /tmp/evr.md --png /tmp/evr.png  # a smoke run

(a few minutes on one core; ``--quick``: T = 10 s and the small meshes only, about a minute).
For a generic asymmetric top (I = 1, 2, 3 kg m^2,
Omega0 = (0.3, 0.2, 1.0) rad/s, period 6.31 s) and horizons T = 10, 1e3, 1e5 s
it measures, for each method and several tolerances or step sizes: the max
error of Omega(t) (relative to |Omega0|) and of R(t) (max matrix entry) at 64
check times, the max relative drift of the energy and of |M| over all samples,
and the wall-clock run time.

Reference: L&L §37 in mpmath at 30 digits, independent of the service's
code paths: Omega(t) from mpmath's Jacobi functions (``mp.ellipfun``), and the
attitude R(t) = E0^T Rz(phi) E(m(t)) with the precession angle phi(t) obtained
by adaptive quadrature (``mp.quad``) of L&L's phi_dot over whole periods plus
the remainder, not from Carlson's R_J as the exact method does.

Mesh section: icospheres and tori of growing triangle count through
``inertia.mass.mass_properties`` against the exact moments of the solids
(sphere 8 pi R^5 / 15 at unit density; torus about its axis
V (R^2 + 3 r^2 / 4), across V (R^2 / 2 + 5 r^2 / 8), V = 2 pi^2 R r^2).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import mpmath as mp
import numpy as np

from benchmarks.cases import torus
from benchmarks.harness import Report, best_of, cpu_model, load_average, timed
from inertia.motion import quaternions as quat
from inertia.motion.integrators import integrate_scipy, integrate_splitting
from inertia.motion.invariants import RigidProblem, invariant_drifts
from inertia.motion.jacobi import AsymmetricTop

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "error-vs-runtime.md"
PNG = ROOT / "docs" / "error-vs-runtime.png"

MOMENTS = np.array([1.0, 2.0, 3.0])
OMEGA0 = np.array([0.3, 0.2, 1.0])
HORIZONS = (10.0, 1e3, 1e5)
CHECKS = 64  # reference times per horizon (mpmath is slow)
SAMPLES = 1025  # output samples of every method (CHECKS divides SAMPLES - 1)
TIMING_SAMPLES = 100_001  # exact method, per-sample cost
BUDGET_S = 60.0  # keeps the whole run to ~4 minutes; skip a configuration whose run time, extrapolated from T = 1e3, exceeds this
DOP853_RTOLS = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-13)
RK45_RTOLS = (1e-4, 1e-6, 1e-8)
SPLITTING_STEPS = (0.1, 0.03, 0.01)
ATOL_REL = 1e-15  # keeps rtol in charge down to 1e-13


@dataclass
class Run:
    method: str
    setting: str
    horizon: float
    seconds: float
    omega_error: float
    attitude_error: float
    energy_drift: float
    momentum_drift: float
    samples: int


# -- reference (mpmath) -------------------------------------------------------------------


def reference(t_checks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Omega(t) (n, 3) and R(t) (n, 3, 3) from L&L §37 at 30 digits (Omega circulates about x3 here)."""
    mp.mp.dps = 30
    I1, I2, I3 = (mp.mpf(float(x)) for x in MOMENTS)
    W = [mp.mpf(float(x)) for x in OMEGA0]
    E2 = I1 * W[0] ** 2 + I2 * W[1] ** 2 + I3 * W[2] ** 2
    M2 = (I1 * W[0]) ** 2 + (I2 * W[1]) ** 2 + (I3 * W[2]) ** 2
    assert M2 > E2 * I2
    A1 = mp.sqrt((E2 * I3 - M2) / (I1 * (I3 - I1)))
    A2 = mp.sqrt((E2 * I3 - M2) / (I2 * (I3 - I2)))
    A3 = mp.sqrt((M2 - E2 * I1) / (I3 * (I3 - I1)))
    rate = mp.sqrt((I3 - I2) * (M2 - E2 * I1) / (I1 * I2 * I3))
    m = (I2 - I1) * (E2 * I3 - M2) / ((I3 - I2) * (M2 - E2 * I1))
    u0 = mp.ellipf(mp.atan2(W[1] / A2, W[0] / A1), m)  # W1, W3 > 0 here: rho = s = +1
    Mabs = mp.sqrt(M2)

    def omega(t: mp.mpf) -> list[mp.mpf]:
        u = rate * t + u0
        return [A1 * mp.ellipfun("cn", u, m=m), A2 * mp.ellipfun("sn", u, m=m), A3 * mp.ellipfun("dn", u, m=m)]

    def phi_dot(t: mp.mpf) -> mp.mpf:  # L&L eq. 37.16 about x1: |M| (M2^2/I2 + M3^2/I3) / (M2^2 + M3^2)
        w = omega(t)
        a, b = (I2 * w[1]) ** 2, (I3 * w[2]) ** 2
        return Mabs * (a / I2 + b / I3) / (a + b)

    period = 4 * mp.ellipk(m) / rate
    per_period = mp.quad(phi_dot, mp.linspace(0, period, 9))

    def frame(w: list[mp.mpf]) -> mp.matrix:
        mv = [I1 * w[0] / Mabs, I2 * w[1] / Mabs, I3 * w[2] / Mabs]
        r1 = [mp.mpf(0), mv[2], -mv[1]]  # m x e1
        n = mp.sqrt(r1[1] ** 2 + r1[2] ** 2)
        r1 = [x / n for x in r1]
        r2 = [mv[1] * r1[2] - mv[2] * r1[1], mv[2] * r1[0] - mv[0] * r1[2], mv[0] * r1[1] - mv[1] * r1[0]]
        return mp.matrix([r1, r2, mv])

    e0 = frame(W)
    omegas, rotations = [], []
    for tf in t_checks:
        t = mp.mpf(float(tf))
        whole = mp.floor(t / period)
        rest = t - whole * period
        phi = whole * per_period + (mp.quad(phi_dot, mp.linspace(0, rest, 5)) if rest > 0 else 0)
        w = omega(t)
        rz = mp.matrix([[mp.cos(phi), -mp.sin(phi), 0], [mp.sin(phi), mp.cos(phi), 0], [0, 0, 1]])
        r = e0.T * rz * frame(w)
        omegas.append([float(x) for x in w])
        rotations.append([[float(r[i, j]) for j in range(3)] for i in range(3)])
    return np.array(omegas), np.array(rotations)


# -- methods --------------------------------------------------------------------------------


def _problem() -> RigidProblem:
    return RigidProblem(MOMENTS, OMEGA0, np.eye(3), np.array([1.0, 0.0, 0.0, 0.0]))


Solver = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]


def _measure(method: str, setting: str, horizon: float, solve: Solver, ref: tuple[np.ndarray, np.ndarray]) -> Run:
    t = np.linspace(0.0, horizon, SAMPLES)
    # best of up to 5 runs while they stay short (timeit's rule: the minimum is the least disturbed run)
    (omega, attitude), timing = best_of(lambda: solve(t), repeat=5, budget_s=0.5)
    seconds = timing.wall_s
    idx = np.arange(0, SAMPLES, (SAMPLES - 1) // CHECKS)
    w_ref, r_ref = ref
    omega_error = float(np.max(np.abs(omega[idx] - w_ref)) / np.linalg.norm(OMEGA0))
    attitude_error = float(np.max(np.abs(quat.to_matrices(attitude[idx]) - r_ref)))
    energy, momentum = invariant_drifts(_problem(), omega, attitude)
    return Run(method, setting, horizon, seconds, omega_error, attitude_error, energy, momentum, SAMPLES)


def _exact(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return AsymmetricTop.from_initial(MOMENTS, OMEGA0, 16 * np.finfo(float).eps).propagate(t)


def exact_cost_per_sample(horizon: float) -> float:
    """Best of 3 wall-clock seconds per sample for Omega and attitude at TIMING_SAMPLES samples."""
    t = np.linspace(0.0, horizon, TIMING_SAMPLES)
    _, timing = best_of(lambda: _exact(t), repeat=3)
    return timing.wall_s / TIMING_SAMPLES


def run_all(horizons: Sequence[float] = HORIZONS) -> tuple[list[Run], dict[float, float]]:
    runs: list[Run] = []
    per_sample: dict[float, float] = {}
    cost_at_1e3: dict[tuple[str, str], float] = {}
    problem = _problem()
    integrate_scipy(problem, np.linspace(0.0, 1.0, 3), "dop853", 1e-6, ATOL_REL, 10**9)  # warm-up: import and caches
    for horizon in horizons:
        t_checks = np.linspace(0.0, horizon, SAMPLES)[:: (SAMPLES - 1) // CHECKS]
        ref = reference(t_checks)
        print(f"T = {horizon:g}: reference ready", file=sys.stderr)
        configs: list[tuple[str, str, Solver]] = [("exact", "closed form", _exact)]
        configs += [("dop853", f"rtol {r:.0e}", _scipy("dop853", r, problem)) for r in DOP853_RTOLS]
        configs += [("rk45", f"rtol {r:.0e}", _scipy("rk45", r, problem)) for r in RK45_RTOLS]
        configs += [("splitting", f"h {h:g} s", _split(h, problem)) for h in SPLITTING_STEPS]
        for method, setting, solve in configs:
            key = (method, setting)
            if horizon > 1e3 and key in cost_at_1e3 and cost_at_1e3[key] * horizon / 1e3 > BUDGET_S:
                print(f"  skip {method} {setting}: ~{cost_at_1e3[key] * horizon / 1e3:.0f} s", file=sys.stderr)
                continue
            run = _measure(method, setting, horizon, solve, ref)
            if horizon == 1e3:
                cost_at_1e3[key] = run.seconds
            runs.append(run)
            print(
                f"  {method:9s} {setting:12s} {run.seconds:9.4f} s  dW {run.omega_error:.1e}  dR {run.attitude_error:.1e}",
                file=sys.stderr,
            )
        per_sample[horizon] = exact_cost_per_sample(horizon)
    return runs, per_sample


def _scipy(method: str, rtol: float, problem: RigidProblem) -> Solver:
    return lambda t: integrate_scipy(problem, t, method, rtol, ATOL_REL, 10**9)


def _split(step: float, problem: RigidProblem) -> Solver:
    return lambda t: integrate_splitting(problem, t, step, 10**9)


# -- meshes ----------------------------------------------------------------------------------


def icosphere(level: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit icosphere: the icosahedron with each triangle split in 4, ``level`` times, vertices on the sphere."""
    g = (1 + 5**0.5) / 2
    v = [
        (-1, g, 0),
        (1, g, 0),
        (-1, -g, 0),
        (1, -g, 0),
        (0, -1, g),
        (0, 1, g),
        (0, -1, -g),
        (0, 1, -g),
        (g, 0, -1),
        (g, 0, 1),
        (-g, 0, -1),
        (-g, 0, 1),
    ]
    faces = [
        (0, 11, 5),
        (0, 5, 1),
        (0, 1, 7),
        (0, 7, 10),
        (0, 10, 11),
        (1, 5, 9),
        (5, 11, 4),
        (11, 10, 2),
        (10, 7, 6),
        (7, 1, 8),
        (3, 9, 4),
        (3, 4, 2),
        (3, 2, 6),
        (3, 6, 8),
        (3, 8, 9),
        (4, 9, 5),
        (2, 4, 11),
        (6, 2, 10),
        (8, 6, 7),
        (9, 8, 1),
    ]
    verts = [np.array(p, float) / np.linalg.norm(p) for p in v]
    for _ in range(level):
        cache: dict[tuple[int, int], int] = {}

        def mid(a: int, b: int, cache: dict[tuple[int, int], int] = cache) -> int:
            key = (min(a, b), max(a, b))
            if key not in cache:
                p = verts[a] + verts[b]
                verts.append(p / np.linalg.norm(p))
                cache[key] = len(verts) - 1
            return cache[key]

        new = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new
    return np.array(verts), np.array(faces, dtype=np.int64)


def mesh_moments(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Principal moments at unit density through inertia.mass."""
    from inertia.body import MeshBody
    from inertia.mass import mass_properties

    props = mass_properties(MeshBody(vertices, faces), density=1.0)
    return np.sort(np.asarray(props.principal_moments))


def mesh_rows(
    levels: Sequence[int] = range(7), tori: Sequence[int] = (8, 16, 32, 64, 128, 256, 512)
) -> list[tuple[str, int, float, float]]:
    rows = []
    sphere_exact = 8 * np.pi / 15
    for level in levels:
        v, f = icosphere(level)
        if not _outward(v, f):
            f = f[:, ::-1]
        moments, timing = timed(partial(mesh_moments, v, f))
        rows.append(("sphere", len(f), timing.wall_s, float(np.max(np.abs(moments / sphere_exact - 1)))))
    R, r = 1.0, 0.4
    volume = 2 * np.pi**2 * R * r * r
    torus_exact = np.array([volume * (R**2 / 2 + 5 * r**2 / 8)] * 2 + [volume * (R**2 + 3 * r**2 / 4)])
    for n in tori:
        v, f = torus(2 * n, n, R, r)
        if not _outward(v, f):
            f = f[:, ::-1]
        moments, timing = timed(partial(mesh_moments, v, f))
        rows.append(("torus", len(f), timing.wall_s, float(np.max(np.abs(moments / torus_exact - 1)))))
    return rows


def _outward(v: np.ndarray, f: np.ndarray) -> bool:
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b - a, c - a)).sum()) > 0  # 6 x signed volume about the origin


# -- report ----------------------------------------------------------------------------------


def _horizons(runs: list[Run]) -> list[float]:
    return sorted({r.horizon for r in runs})


def plot(runs: list[Run], meshes: list[tuple[str, int, float, float]], png: Path = PNG) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(16, 5))
    colours = {"exact": "k", "dop853": "tab:blue", "rk45": "tab:orange", "splitting": "tab:green"}
    markers = {10.0: "o", 1e3: "s", 1e5: "^"}
    floor = 1e-17
    for ax, attr, title in (
        (axes[0], "omega_error", "max |Omega - ref| / |Omega0|"),
        (axes[1], "attitude_error", "max |R - R_ref| (matrix entries)"),
    ):
        for method in colours:
            for horizon in _horizons(runs):
                pts = [(r.seconds, max(getattr(r, attr), floor)) for r in runs if r.method == method and r.horizon == horizon]
                if pts:
                    x, y = zip(*sorted(pts))
                    ax.loglog(x, y, marker=markers[horizon], color=colours[method], label=f"{method}, T={horizon:g}")
        ax.set_xlabel(f"run time [s] for {SAMPLES} samples")
        ax.set_ylabel(title)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7, ncol=2)
    axes[0].set_title("Omega(t): error against run time")
    axes[1].set_title("R(t): error against run time")
    for shape, colour in (("sphere", "tab:red"), ("torus", "tab:purple")):
        rows = [(n, e) for s, n, _, e in meshes if s == shape]
        axes[2].loglog(*zip(*rows), marker="o", color=colour, label=shape)
    n = np.array([1e2, 1e6])
    axes[2].loglog(n, 2.0 / n, "k--", lw=0.8, label="~ 1/N (second order in h)")
    axes[2].set_xlabel("triangles")
    axes[2].set_ylabel("max relative error of principal moments")
    axes[2].set_title("Tessellation error of a sphere and a torus")
    axes[2].legend()
    axes[2].grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


def write_doc(runs: list[Run], per_sample: dict[float, float], meshes: list[tuple[str, int, float, float]]) -> Report:
    import scipy

    exact = {r.horizon: r for r in runs if r.method == "exact"}
    report = Report(
        "Error against run time: torque-free motion methods and mesh tessellation", "python -m benchmarks.error_vs_runtime"
    )
    lines = [
        "Generated by `benchmarks/error_vs_runtime.py`; regenerate from the repo root with",
        "",
        "```",
        report.regenerate,
        "```",
        "",
        f"Machine: {platform.machine()}, {cpu_model()}; Python {platform.python_version()}, "
        f"numpy {np.__version__}, scipy {scipy.__version__}, mpmath {mp.__version__}; single thread, wall clock; "
        f"load average at the end of the run {load_average():.1f} on {os.cpu_count()} cores "
        "(a shared machine inflates every time alike; ratios are from the same run).",
        "",
        "Problem: generic asymmetric top, I = (1, 2, 3) kg m^2, Omega0 = (0.3, 0.2, 1.0) rad/s (period "
        f"{AsymmetricTop.from_initial(MOMENTS, OMEGA0, 1e-15).period:.4f} s). Reference: L&L §37 in mpmath at 30 digits "
        "(Jacobi functions by `mp.ellipfun`, precession angle by `mp.quad` of L&L's phi_dot), independent of the "
        f"service's Landen/Carlson code. Errors at {CHECKS + 1} check times; drifts over all {SAMPLES} samples.",
        "",
        "![work-precision diagram](error-vs-runtime.png)",
        "",
        "## Headline figures",
        "",
    ]
    for horizon in _horizons(runs):
        lines.append(
            f"- Exact method, T = {horizon:g} s: **{per_sample[horizon] * 1e6:.2f} µs per sample** for Omega and attitude "
            f"together at {TIMING_SAMPLES - 1:.0e} samples (best of 3); errors Omega {exact[horizon].omega_error:.1e}, "
            f"R {exact[horizon].attitude_error:.1e}."
        )
    lines += _comparisons(runs, per_sample)
    lines += [
        "",
        "## Table (motion)",
        "",
        "| T [s] | method | setting | run time [s] | per sample [µs] | max Omega error (rel.) | max R error "
        "| energy drift | |M| drift |",
        "|---:|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in runs:
        lines.append(
            f"| {r.horizon:g} | {r.method} | {r.setting} | {r.seconds:.4g} | {r.seconds / r.samples * 1e6:.3g} | "
            f"{r.omega_error:.2e} | {r.attitude_error:.2e} | {r.energy_drift:.2e} | {r.momentum_drift:.2e} |"
        )
    skipped = _skipped(runs)
    if skipped:
        lines += ["", f"Not run at T = 1e5 (run time extrapolated from T = 1e3 above {BUDGET_S:g} s): {skipped}."]
    lines += [
        "",
        "## Meshes: tessellation error against triangle count",
        "",
        "Unit-density icospheres (radius 1, vertices on the sphere) and tori (R = 1, r = 0.4, vertices on the "
        "surface) through `inertia.mass.mass_properties`, against the exact solids. The error is the polyhedron's "
        "departure from the smooth solid (second order in the edge length, ~1/N), not a floating-point error.",
        "",
        "| shape | triangles | run time [s] | max relative error of principal moments |",
        "|---|---:|---:|---:|",
    ]
    lines += [f"| {s} | {n} | {sec:.4g} | {e:.3e} |" for s, n, sec, e in meshes]
    lines += [
        "",
        "## Notes",
        "",
        "- The exact method's cost per sample does not depend on the horizon: the elliptic argument is reduced "
        "modulo the half period before the Landen chain and Carlson's R_J, and whole half periods are added "
        "with the complete integral. Its error grows only as the rounding of the phase, ~EPS x rate x t.",
        f"- Splitting steps are at most h *and* at most the sample spacing (T / {SAMPLES - 1}), so at T = 10 s "
        "all three settings run with the spacing, 0.0098 s, and coincide.",
        "- The exact method's error at T = 1e5 s (~3e-12 in Omega, ~2e-11 in R) is the rounding of its phase, "
        "not of the elliptic functions: u = lambda t ~ 6e4 and phi ~ 3e5 rad carry ~1e-16 relative error "
        "(lambda itself is correctly rounded), i.e. ~1e-11 absolute; the same holds for any double-precision "
        "method at this horizon. Energy and |M| are kept to ~1e-15 at every horizon regardless.",
        "- The integrators' errors grow with the horizon (phase error accumulates); the splitting method keeps "
        "|M| to rounding and the energy bounded, with a phase error ~(h Omega)^2 per unit time.",
        "- DOP853 below rtol ~1e-12 stops improving: its local error control cannot beat the accumulation of "
        "rounding over ~1e4-1e5 steps, so the exact method's accuracy is out of its reach beyond short horizons; "
        "the ratios above compare against DOP853's most accurate run when no run reaches the exact accuracy "
        "(a lower bound on the ratio at equal accuracy).",
    ]
    report.add(*lines)
    return report


def _comparisons(runs: list[Run], per_sample: dict[float, float]) -> list[str]:
    out = []
    for horizon in _horizons(runs):
        ex = next(r for r in runs if r.method == "exact" and r.horizon == horizon)
        dop = [r for r in runs if r.method == "dop853" and r.horizon == horizon]
        six = next((r for r in dop if r.setting == "rtol 1e-06"), None)
        if six is not None:
            out.append(
                f"- T = {horizon:g} s, same {SAMPLES} samples: exact {ex.seconds:.3g} s (Omega error {ex.omega_error:.1e}) "
                f"vs DOP853 rtol 1e-6 {six.seconds:.3g} s (Omega error {six.omega_error:.1e}): "
                f"**{six.seconds / ex.seconds:.0f}x cheaper** per sample."
            )
        if dop:
            reach = [r for r in dop if max(r.omega_error, r.attitude_error) <= max(ex.omega_error, ex.attitude_error)]
            best = min(reach, key=lambda r: r.seconds) if reach else min(dop, key=lambda r: max(r.omega_error, r.attitude_error))
            word = "equal accuracy" if reach else "DOP853's best accuracy (still worse than exact)"
            out.append(
                f"- T = {horizon:g} s, at {word}: DOP853 {best.setting} {best.seconds:.3g} s "
                f"(Omega {best.omega_error:.1e}, R {best.attitude_error:.1e}) vs exact {ex.seconds:.3g} s: "
                f"**{best.seconds / ex.seconds:.0f}x**."
            )
    return out


def _skipped(runs: list[Run]) -> str:
    at_1e3 = {(r.method, r.setting) for r in runs if r.horizon == 1e3}
    at_1e5 = {(r.method, r.setting) for r in runs if r.horizon == 1e5}
    return ", ".join(f"{m} {s}" for m, s in sorted(at_1e3 - at_1e5))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.error_vs_runtime", description=__doc__.split("\n")[0])
    parser.add_argument("--doc", type=Path, default=DOC)
    parser.add_argument("--png", type=Path, default=PNG)
    parser.add_argument("--quick", action="store_true", help="T = 10 s and the small meshes only: a smoke run")
    args = parser.parse_args(argv)
    runs, per_sample = run_all((10.0,) if args.quick else HORIZONS)
    meshes = mesh_rows(range(3), (8, 16)) if args.quick else mesh_rows()
    plot(runs, meshes, args.png)
    write_doc(runs, per_sample, meshes).write(args.doc)
    print(f"wrote {args.doc} and {args.png}", file=sys.stderr)


if __name__ == "__main__":
    main()
