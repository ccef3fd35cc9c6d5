"""Regenerate the sample meshes and the table of their exact values.

    python sample_meshes/generate.py

Every expected value in README.md here comes from a closed formula or from
exact rational integration (``fractions.Fraction``) of the vertices as
written, never from the service itself.
"""

from __future__ import annotations

import json
import struct
from fractions import Fraction
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent

BOX_FACES = [[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
             [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]]


def box(a: float, b: float, c: float, origin=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned box with outward winding; vertex k has bits (x, y, z) = (k&1, k&2, k&4)."""
    o = np.asarray(origin, dtype=float)
    v = np.array([[(k & 1) * a, ((k >> 1) & 1) * b, ((k >> 2) & 1) * c] for k in range(8)]) + o
    return v, np.array(BOX_FACES)


def prism(n: int, radius: float, height: float) -> tuple[np.ndarray, np.ndarray]:
    ang = 2 * np.pi * np.arange(n) / n
    ring = np.stack([radius * np.cos(ang), radius * np.sin(ang)], axis=1)
    v = np.vstack([np.c_[ring, np.zeros(n)], np.c_[ring, np.full(n, height)], [[0, 0, 0], [0, 0, height]]])
    faces = []
    for i in range(n):
        j = (i + 1) % n
        faces += [[i, j, n + j], [i, n + j, n + i], [2 * n, j, i], [2 * n + 1, n + i, n + j]]
    return v, np.array(faces)


def icosahedron(edge: float) -> tuple[np.ndarray, np.ndarray]:
    phi = (1 + 5**0.5) / 2
    s = edge / 2
    v = []
    for a in (-1, 1):
        for b in (-1, 1):
            v += [[0, a * s, b * s * phi], [a * s, b * s * phi, 0], [b * s * phi, 0, a * s]]
    v = np.array(v)
    faces = []
    n = len(v)
    for i in range(n):
        for j in range(i + 1, n):
            for k in range(j + 1, n):
                d = [np.linalg.norm(v[p] - v[q]) for p, q in ((i, j), (j, k), (i, k))]
                if all(abs(x - edge) < 1e-9 * edge for x in d):
                    tri = [i, j, k]
                    if np.dot(np.cross(v[j] - v[i], v[k] - v[i]), v[i]) < 0:
                        tri = [i, k, j]
                    faces.append(tri)
    return v, np.array(faces)


def l_bracket(depth: float) -> tuple[np.ndarray, np.ndarray]:
    """L profile (0,0),(4,0),(4,1),(1,1),(1,3),(0,3) extruded by ``depth`` along z."""
    prof = [(0, 0), (4, 0), (4, 1), (1, 1), (1, 3), (0, 3)]
    n = len(prof)
    v = np.array([[x, y, 0.0] for x, y in prof] + [[x, y, depth] for x, y in prof])
    faces = []
    for i in range(1, n - 1):  # fan from vertex 0 covers the L exactly
        faces += [[0, i + 1, i], [n, n + i, n + i + 1]]
    for i in range(n):
        j = (i + 1) % n
        faces += [[i, j, n + j], [i, n + j, n + i]]
    return v, np.array(faces)


def write_stl(path: Path, v: np.ndarray, f: np.ndarray) -> None:
    rec = np.zeros(len(f), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = v[f].astype("<f4")
    path.write_bytes(b"sample mesh".ljust(80, b" ") + struct.pack("<I", len(f)) + rec.tobytes())


def write_obj(path: Path, v: np.ndarray, f: np.ndarray) -> None:
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in v.tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f.tolist()]
    path.write_text("\n".join(lines) + "\n")


def exact_solid(v: np.ndarray, f: np.ndarray) -> tuple[Fraction, list[Fraction], list[list[Fraction]]]:
    """Volume, centre and inertia tensor (unit density) of the polyhedron, in rationals.

    Signed tetrahedra from the origin (Tonon 2004): int x_i x_j = V/20 (sum p p + S S).
    """
    V = [[Fraction(float(x)) for x in row] for row in v]
    m0 = Fraction(0)
    m1 = [Fraction(0)] * 3
    m2 = [[Fraction(0)] * 3 for _ in range(3)]
    for t in f.tolist():
        a, b, c = V[t[0]], V[t[1]], V[t[2]]
        det = (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
               + a[2] * (b[0] * c[1] - b[1] * c[0]))
        vol = det / 6
        s = [a[i] + b[i] + c[i] for i in range(3)]
        m0 += vol
        for i in range(3):
            m1[i] += vol * s[i] / 4
            for j in range(3):
                m2[i][j] += vol / 20 * (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + s[i] * s[j])
    com = [x / m0 for x in m1]
    cov = [[m2[i][j] - m0 * com[i] * com[j] for j in range(3)] for i in range(3)]
    tr = sum(cov[i][i] for i in range(3))
    tensor = [[(tr if i == j else 0) - cov[i][j] for j in range(3)] for i in range(3)]
    return m0, com, tensor


def write_two_density_vtu(path: Path) -> dict[str, float]:
    """A 2x1x1 box of tetrahedra, density 1000 for x < 1 and 8000 for x > 1."""
    import meshio

    pts = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1, 2)], dtype=float)
    idx = {tuple(p): i for i, p in enumerate(pts.tolist())}
    hex_split = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]
    tets, rho = [], []
    for x0, density in ((0, 1000.0), (1, 8000.0)):
        corners = [(x0, 0, 0), (x0 + 1, 0, 0), (x0 + 1, 1, 0), (x0, 1, 0),
                   (x0, 0, 1), (x0 + 1, 0, 1), (x0 + 1, 1, 1), (x0, 1, 1)]
        hexa = [idx[tuple(float(c) for c in p)] for p in corners]
        for t in hex_split:
            tets.append([hexa[k] for k in t])
            rho.append(density)
    mesh = meshio.Mesh(pts, [("tetra", np.array(tets))], cell_data={"density": [np.array(rho)]})
    mesh.write(path)
    # exact: two unit cubes, masses 1000 and 8000, centres (0.5,.5,.5) and (1.5,.5,.5)
    m1, m2 = 1000.0, 8000.0
    m = m1 + m2
    cx = (m1 * 0.5 + m2 * 1.5) / m
    ixx = m * (1 + 1) / 12
    iyy = izz = m * 2 / 12 + m1 * (0.5 - cx) ** 2 + m2 * (1.5 - cx) ** 2
    return {"mass": m, "com_x": cx, "Ixx": ixx, "Iyy": iyy, "Izz": izz}


def main() -> None:
    rows = []

    def solid(name: str, v: np.ndarray, f: np.ndarray, writer=write_stl, note: str = "") -> None:
        writer(HERE / name, v, f)
        vv = v.astype(np.float32).astype(np.float64) if writer is write_stl else v
        vol, com, tensor = exact_solid(vv, f)
        moments = sorted(np.linalg.eigvalsh(np.array([[float(x) * 1000 for x in r] for r in tensor])))
        rows.append((name, float(vol) * 1000, [float(c) for c in com], moments, note))

    solid("box.stl", *box(1.0, 2.0, 3.0), note="1 x 2 x 3 m; I = m(b²+c²)/12 ...: asymmetric")
    solid("hex_prism.stl", *prism(6, 1.0, 2.0), note="regular hexagonal prism R = 1, h = 2: symmetric (prolate)")
    solid("icosahedron.stl", *icosahedron(1.0), note="edge 1: spherical top, I = m φ² a²/10")
    solid("tetrahedron.stl", np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float),
          np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]), note="unit corner tetrahedron")
    solid("l_bracket.stl", *l_bracket(2.0), note="L profile extruded 2 m: asymmetric")
    solid("needle.obj", *box(1.0, 1e-3, 1e-3, origin=(-0.5, -5e-4, -5e-4)), writer=write_obj,
          note="1 x 1e-3 x 1e-3 m needle (OBJ, float64): prolate symmetric, I1/I3 = 2e-6")
    solid("plate.obj", *box(1.0, 1.0, 1e-3, origin=(-0.5, -0.5, -5e-4)), writer=write_obj,
          note="1 x 1 x 1e-3 m: oblate symmetric, nearly planar")
    v, f = box(1.0, 2.0, 3.0)
    write_stl(HERE / "inverted_box.stl", v, f[:, [0, 2, 1]])
    rows.append(("inverted_box.stl", 6000.0, [0.5, 1.0, 1.5], [2500.0, 5000.0, 6500.0],
                 "box.stl with every face reversed: same numbers plus a warning"))
    write_stl(HERE / "open_box.stl", v, f[:-2])
    rows.append(("open_box.stl", None, None, None, "box without its +x face: error not_watertight (4 open edges)"))
    exact = write_two_density_vtu(HERE / "two_density.vtu")
    rows.append(("two_density.vtu", exact["mass"], [exact["com_x"], 0.5, 0.5],
                 sorted([exact["Ixx"], exact["Iyy"], exact["Izz"]]),
                 "2 x 1 x 1 m of tetrahedra, cell densities 1000 and 8000 kg/m³ (x < 1, x > 1)"))
    # isosceles triatomic (seed notes, example 2b): base atoms m1 at (±a/2, 0, 0), apex m2 at (0, h, 0)
    m1, m2, a, h = 1.0, 16.0, 2.0, 1.0
    atoms = [{"mass": m1, "position": [-a / 2, 0.0, 0.0]}, {"mass": m1, "position": [a / 2, 0.0, 0.0]},
             {"mass": m2, "position": [0.0, h, 0.0]}]
    (HERE / "triatomic.json").write_text(json.dumps({"points": atoms}, indent=1) + "\n")
    mu = 2 * m1 + m2
    i1, i2 = 2 * m1 * m2 * h**2 / mu, m1 * a**2 / 2
    rows.append(("triatomic.json", mu, [0.0, m2 * h / mu, 0.0], [i1, i2, i1 + i2],
                 "isosceles triatomic point masses m1 = 1, m2 = 16 kg, a = 2, h = 1 m: "
                 "I1 = 2 m1 m2 h²/μ, I2 = m1 a²/2, I3 = I1 + I2 (planar)"))
    _write_readme(rows)


def _fmt(x: float | None) -> str:
    return "" if x is None else f"{x:.12g}"


def _write_readme(rows: list) -> None:
    lines = [
        "# Sample meshes",
        "",
        "Small bodies with known answers, used by the tests and the README examples.",
        "Regenerate with `python sample_meshes/generate.py`. Values are SI at the default",
        "density 1000 kg/m³ and units m, computed by exact rational integration of the",
        "vertices as written (float32 for binary STL) or from closed formulas; moments",
        "are ascending principal moments about the centre of mass.",
        "",
        "| file | mass (kg) | centre of mass (m) | principal moments (kg m²) | what it is |",
        "|---|---|---|---|---|",
    ]
    for name, mass, com, moments, note in rows:
        com_s = "" if com is None else "(" + ", ".join(_fmt(c) for c in com) + ")"
        mom_s = "" if moments is None else ", ".join(_fmt(m) for m in moments)
        lines.append(f"| `{name}` | {_fmt(mass)} | {com_s} | {mom_s} | {note} |")
    (HERE / "README.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
